//! Where a surface vehicle listening with a USBL should go next (hoff2024 sec. 3): the
//! candidate point on a half-annulus around the belief whose bearing to the vehicle
//! would spread the particles' predicted measurements most (eq. 10-12), and the
//! straight-line waypoint following of eq. 13-16.

use crate::filter::lanes;
use crate::measure::Usbl;
use crate::par::*;
use nalgebra::{Matrix2, Vector2, Vector3};

/// How a candidate's spread of predicted measurements is scored (eq. 10).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SpreadMetric {
    /// The generalised variance, det C.
    Determinant,
    /// The first principal component, the largest eigenvalue of C.
    MaxEigenvalue,
}

/// Candidate-particle scorings one planner decision may take per second of the decision
/// period. Measured: 0.55 ns each on a 2-core AMD EPYC (AVX2): `stream` on hoff2024's
/// surface vehicle with radii = angles = 1000 and 20 000 planner particles took 11 s a
/// decision against a 4 s period. At this bound a decision takes about 6 % of its period
/// there, and fits in a computer ten times slower; hoff2024's own (3 x 19 candidates,
/// 20 000 particles, 4 s) is 350 times below it.
pub const MAX_SCORINGS_PER_PERIOD_S: f64 = 1e8;

/// Why a planner of `radii` x `angles` candidates scored on `particles` particles,
/// deciding every `period_s`, would not keep up ([`MAX_SCORINGS_PER_PERIOD_S`]).
pub fn planner_too_slow(radii: usize, angles: usize, particles: usize, period_s: f64) -> Option<String> {
    let work = radii as f64 * angles as f64 * particles as f64;
    let most = MAX_SCORINGS_PER_PERIOD_S * period_s;
    (work > most).then(|| {
        format!(
            "radii x angles x planner_particles = {work:.3e} scorings a decision; at most {most:.3e} fit a period of \
             {period_s} s (1e8 per second): lower radii, angles or planner_particles"
        )
    })
}

/// The planner's settings.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BearingPlanner {
    pub metric: SpreadMetric,
    /// The half-annulus: radii r1..r2 (m) about the belief, sampled at `radii` radii and
    /// `angles` rotations beta in [0, pi].
    pub r1_m: f64,
    pub r2_m: f64,
    pub radii: usize,
    pub angles: usize,
    /// The USBL's baseline noise, rad per metre of range (eq. 3).
    pub sigma_usbl_rad_per_m: f64,
}

/// The belief the planner scores candidates against.
#[derive(Debug, Clone, Copy)]
pub struct Belief<'a> {
    /// Particle positions (NED) and their normalised weights; a subsample will do.
    pub positions: &'a [Vector3<f64>],
    pub weights: &'a [f64],
    /// The vehicle's estimated velocity over ground (NED, m/s) and the time the surface
    /// vehicle is assumed to take to the next point: the belief is shifted by their
    /// product (the paper's "assumed number of steps").
    pub velocity_m_s: Vector2<f64>,
    pub lead_s: f64,
}

impl Belief<'_> {
    /// The weighted mean of the particles, shifted by the velocity over the lead time.
    pub fn shifted_mean(&self) -> Vector3<f64> {
        let shift = self.velocity_m_s * self.lead_s;
        let mean = self.positions.iter().zip(self.weights).map(|(x, w)| x * *w).sum::<Vector3<f64>>();
        mean + Vector3::new(shift.x, shift.y, 0.0)
    }
}

/// One decision: the chosen point, its score, and every candidate with its score.
#[derive(Debug, Clone, PartialEq)]
pub struct BearingDecision {
    pub waypoint: Vector2<f64>,
    pub score: f64,
    pub candidates: Vec<(Vector2<f64>, f64)>,
}

/// The belief's particles shifted by the lead, relative to their weighted mean, as
/// single-precision columns (north, east, down) with their weights, for the lanes.
struct Columns {
    north: Vec<f32>,
    east: Vec<f32>,
    down: Vec<f32>,
    weights: Vec<f32>,
    /// The single-precision weights' sum.
    total: f64,
    mean: Vector3<f64>,
}

impl Columns {
    fn of(belief: &Belief<'_>) -> Self {
        let mean = belief.shifted_mean();
        let shift = belief.velocity_m_s * belief.lead_s;
        let column = |f: &dyn Fn(&Vector3<f64>) -> f64| belief.positions.iter().map(|x| f(x) as f32).collect();
        let weights: Vec<f32> = belief.weights.iter().map(|&w| w as f32).collect();
        Self {
            north: column(&|x| x.x + shift.x - mean.x),
            east: column(&|x| x.y + shift.y - mean.y),
            down: column(&|x| x.z),
            total: weights.iter().map(|&w| f64::from(w)).sum(),
            weights,
            mean,
        }
    }
}

impl BearingPlanner {
    /// The spread of the belief's predicted USBL measurements from a surface vehicle at
    /// `p` (eq. 10): C = Cov(S (h(x_i, p) - E_i h)), S = diag(sigma_alpha^-2,
    /// sigma_phi^-2) as the paper writes it, sigma from the range to the weighted mean
    /// (eq. 3), scored by the metric. The azimuth is taken relative to the mean's so
    /// that a belief across +-pi is not torn apart.
    pub fn spread(&self, belief: &Belief<'_>, p: Vector2<f64>) -> f64 {
        self.spread_of(&Columns::of(belief), p)
    }

    /// [`BearingPlanner::spread`] on the belief's columns: the angles of eq. 1-2 in the
    /// lanes (single precision, within some 4e-7 rad: far below the spread of a belief
    /// the planner scores), about the mean's.
    fn spread_of(&self, cols: &Columns, p: Vector2<f64>) -> f64 {
        let usbl = Usbl::exact(Vector3::new(p.x, p.y, 0.0), 0.0, self.sigma_usbl_rad_per_m);
        let (azimuth, elevation, sigma) = usbl.angles(&cols.mean);
        let s = 1.0 / (sigma * sigma).max(f64::MIN_POSITIVE);
        let station = [(p.x - cols.mean.x) as f32, (p.y - cols.mean.y) as f32];
        let [ma, me, saa, sae, see] = lanes::angle_moments(
            &cols.north,
            &cols.east,
            &cols.down,
            &cols.weights,
            station,
            [azimuth as f32, elevation as f32],
        );
        let total = cols.total;
        let (ma, me) = (ma / total, me / total);
        let (caa, cae, cee) = (saa / total - ma * ma, sae / total - ma * me, see / total - me * me);
        let c = Matrix2::new(caa, cae, cae, cee) * (s * s); // S C S with S = s I
        match self.metric {
            SpreadMetric::Determinant => c.determinant(),
            SpreadMetric::MaxEigenvalue => c.symmetric_eigenvalues().max(),
        }
    }

    /// The candidates of eq. 11-12: the belief's (shifted) mean plus v = r (p_ASV -
    /// p_AUV) / |...| rotated by beta in [0, pi] about k = v_ASV x (p_AUV - p_ASV) /
    /// |...|, the vertical on the side the surface vehicle is heading to.
    pub fn candidates(
        &self,
        belief_mean: Vector2<f64>,
        asv: Vector2<f64>,
        asv_velocity: Vector2<f64>,
    ) -> Vec<Vector2<f64>> {
        let away = asv - belief_mean;
        let dir = if away.norm() > 1e-9 { away / away.norm() } else { Vector2::new(1.0, 0.0) };
        let to_auv = belief_mean - asv;
        // k is +-z: the sign of the vertical component of v_ASV x (p_AUV - p_ASV)
        let kz = asv_velocity.x * to_auv.y - asv_velocity.y * to_auv.x;
        let sign = if kz < 0.0 { -1.0 } else { 1.0 };
        let mut out = Vec::with_capacity(self.radii * self.angles);
        for ir in 0..self.radii {
            let r = if self.radii == 1 {
                self.r1_m
            } else {
                self.r1_m + (self.r2_m - self.r1_m) * ir as f64 / (self.radii - 1) as f64
            };
            for ib in 0..self.angles {
                let beta =
                    if self.angles == 1 { 0.0 } else { std::f64::consts::PI * ib as f64 / (self.angles - 1) as f64 };
                // Rodrigues about +-z of a horizontal v: v cos b + (k x v) sin b (eq. 11;
                // k . v = 0)
                let v = dir * r;
                let kxv = Vector2::new(-v.y, v.x) * sign;
                out.push(belief_mean + v * beta.cos() + kxv * beta.sin());
            }
        }
        out
    }

    /// The best candidate (eq. 10-12) for a surface vehicle at `asv` moving at
    /// `asv_velocity`.
    pub fn decide(&self, belief: &Belief<'_>, asv: Vector2<f64>, asv_velocity: Vector2<f64>) -> BearingDecision {
        let cols = Columns::of(belief);
        // candidates scored in parallel, collected in order: the same whatever the threads
        let candidates: Vec<(Vector2<f64>, f64)> = self
            .candidates(cols.mean.xy(), asv, asv_velocity)
            .into_par_iter()
            .map(|p| (p, self.spread_of(&cols, p)))
            .collect();
        let (waypoint, score) =
            candidates.iter().copied().fold((asv, f64::NEG_INFINITY), |best, c| if c.1 > best.1 { c } else { best });
        BearingDecision { waypoint, score, candidates }
    }
}

/// The along-track point of `asv` on the leg from `from` to `to` (eq. 13, with the
/// projection (a . b) / |a|^2 a: eq. 14 as printed divides by |a| |b|, which is not a
/// projection), and the target of this cycle `u_nom` x `dt` further along (eq. 15).
pub fn leg_target(
    from: Vector2<f64>,
    to: Vector2<f64>,
    asv: Vector2<f64>,
    u_nom_m_s: f64,
    dt_s: f64,
) -> (Vector2<f64>, Vector2<f64>) {
    let a = to - from;
    let len2 = a.norm_squared();
    if len2 < 1e-18 {
        return (to, to);
    }
    let along = from + a * (a.dot(&(asv - from)) / len2); // eq. 13-14
    (along, along + a / len2.sqrt() * u_nom_m_s * dt_s) // eq. 15
}

/// Whether the surface vehicle is done with the leg from `from` to `to`, so that the
/// next waypoint is to be planned: it will reach `to` within the next cycle (eq. 16), or
/// it has passed it (its along-track point beyond `to`: a vehicle that cannot turn on
/// the spot may pass a waypoint wider than eq. 16's radius, and would orbit it).
pub fn leg_done(from: Vector2<f64>, to: Vector2<f64>, asv: Vector2<f64>, u_nom_m_s: f64, dt_s: f64) -> bool {
    let a = to - from;
    (to - asv).norm() < u_nom_m_s * dt_s || a.dot(&(asv - to)) > 0.0
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_abs_diff_eq;

    fn planner(metric: SpreadMetric) -> BearingPlanner {
        BearingPlanner {
            metric,
            r1_m: 16.0,
            r2_m: 26.0,
            radii: 3,
            angles: 13,
            sigma_usbl_rad_per_m: 0.022f64.to_radians(),
        }
    }

    /// The spread of eq. 10 against a brute force written out separately: the angles of
    /// every particle by acos and atan2 in double precision, their weighted mean and
    /// covariance by sums, the Mahalanobis scaling by sigma^-2; det and largest
    /// eigenvalue of the 2 x 2 closed form. The planner's angles are the lanes' (within
    /// eps = 4e-7 rad, their own test): a covariance entry then moves by at most
    /// 2 eps (E|a - mean a| + E|b - mean b|) + 4 eps^2, and the determinant and the
    /// eigenvalue by what that bound carries through their closed forms.
    #[test]
    fn spread_matches_a_brute_force() {
        let positions: Vec<Vector3<f64>> = (0..40)
            .map(|i| {
                let t = i as f64;
                Vector3::new(100.0 + 3.0 * (t * 0.7).sin(), 50.0 + 2.0 * (t * 1.3).cos(), 30.0 + 0.5 * (t * 0.4).sin())
            })
            .collect();
        let raw: Vec<f64> = (0..40).map(|i| 1.0 + (i % 5) as f64).collect();
        let total: f64 = raw.iter().sum();
        let weights: Vec<f64> = raw.iter().map(|w| w / total).collect();
        let belief =
            Belief { positions: &positions, weights: &weights, velocity_m_s: Vector2::new(1.0, 0.5), lead_s: 8.0 };
        let p = Vector2::new(80.0, 70.0);
        // brute force
        let shift = Vector2::new(8.0, 4.0);
        let mut mean = Vector3::zeros();
        for (x, w) in positions.iter().zip(&weights) {
            mean += Vector3::new(x.x + shift.x, x.y + shift.y, x.z) * *w;
        }
        let range = (mean - Vector3::new(p.x, p.y, 0.0)).norm();
        let sigma = range * 0.022f64.to_radians();
        let angles: Vec<(f64, f64)> = positions
            .iter()
            .map(|x| {
                let (dx, dy, dz) = (x.x + shift.x - p.x, x.y + shift.y - p.y, x.z);
                (dy.atan2(dx), (dz / (dx * dx + dy * dy + dz * dz).sqrt()).acos())
            })
            .collect();
        let ma: f64 = angles.iter().zip(&weights).map(|(a, w)| a.0 * w).sum();
        let mp: f64 = angles.iter().zip(&weights).map(|(a, w)| a.1 * w).sum();
        let (mut caa, mut cap, mut cpp) = (0.0, 0.0, 0.0);
        for (a, w) in angles.iter().zip(&weights) {
            caa += w * (a.0 - ma) * (a.0 - ma);
            cap += w * (a.0 - ma) * (a.1 - mp);
            cpp += w * (a.1 - mp) * (a.1 - mp);
        }
        let k = sigma.powi(-4);
        let (caa, cap, cpp) = (caa * k, cap * k, cpp * k);
        let det = caa * cpp - cap * cap;
        let max_eig = (caa + cpp) / 2.0 + (((caa - cpp) / 2.0).powi(2) + cap * cap).sqrt();
        let eps = 4e-7;
        let spread = |f: &dyn Fn(&(f64, f64)) -> f64| angles.iter().zip(&weights).map(|(a, w)| w * f(a)).sum::<f64>();
        let (da, dp) = (spread(&|a| (a.0 - ma).abs()), spread(&|a| (a.1 - mp).abs()));
        let bound = |x: f64, y: f64| k * (2.0 * eps * (x + y) + 4.0 * eps * eps);
        let (eaa, eap, epp) = (bound(da, da), bound(da, dp), bound(dp, dp));
        let det_bound = eaa * (cpp + epp) + caa * epp + 2.0 * cap.abs() * eap + eap * eap;
        let eig_bound = (eaa * eaa + 2.0 * eap * eap + epp * epp).sqrt();
        assert!(det_bound < 1e-3 * det && eig_bound < 1e-3 * max_eig, "a test that can tell: {det_bound} / {det}");
        assert_abs_diff_eq!(planner(SpreadMetric::Determinant).spread(&belief, p), det, epsilon = det_bound);
        assert_abs_diff_eq!(planner(SpreadMetric::MaxEigenvalue).spread(&belief, p), max_eig, epsilon = eig_bound);
    }

    /// Candidates lie on the half-annulus r1..r2 about the belief, from the direction of
    /// the surface vehicle round the side it is heading to; the decision is the
    /// candidate of highest score.
    #[test]
    fn candidates_sweep_the_half_annulus_on_the_heading_side() {
        let p = planner(SpreadMetric::Determinant);
        let (belief, asv) = (Vector2::new(0.0, 0.0), Vector2::new(-40.0, 0.0));
        // heading east-north... velocity north: v x (p_AUV - p_ASV) = (0,1) x (40,0) < 0
        let c = p.candidates(belief, asv, Vector2::new(0.0, 1.0));
        assert_eq!(c.len(), 39);
        for q in &c {
            let r = (q - belief).norm();
            assert!((16.0 - 1e-9..=26.0 + 1e-9).contains(&r), "{r}");
        }
        // beta = 0: toward the ASV; beta = pi/2: on the side it heads to (north, y > 0 ...)
        assert_abs_diff_eq!(c[0], Vector2::new(-16.0, 0.0), epsilon = 1e-9);
        assert_abs_diff_eq!(c[6], Vector2::new(0.0, 16.0), epsilon = 1e-9);
        assert_abs_diff_eq!(c[12], Vector2::new(16.0, 0.0), epsilon = 1e-9);
        let flipped = p.candidates(belief, asv, Vector2::new(0.0, -1.0));
        assert_abs_diff_eq!(flipped[6], Vector2::new(0.0, -16.0), epsilon = 1e-9);

        let positions = vec![Vector3::new(0.0, 0.0, 30.0), Vector3::new(3.0, 1.0, 31.0), Vector3::new(-2.0, 2.0, 29.0)];
        let weights = vec![0.5, 0.25, 0.25];
        let belief = Belief { positions: &positions, weights: &weights, velocity_m_s: Vector2::zeros(), lead_s: 0.0 };
        let d = p.decide(&belief, asv, Vector2::new(0.0, 1.0));
        let best = d.candidates.iter().map(|c| c.1).fold(f64::NEG_INFINITY, f64::max);
        assert_eq!(d.score, best);
        assert!(d.candidates.iter().any(|c| c.0 == d.waypoint && c.1 == best));
    }

    /// Eq. 13-16: the along-track point is the projection on the leg; the target is
    /// u_nom dt further along; a waypoint closer than u_nom dt is done, and so is one
    /// passed however wide.
    #[test]
    fn legs_follow_eq_13_to_16() {
        let (from, to) = (Vector2::new(0.0, 0.0), Vector2::new(100.0, 0.0));
        let (along, target) = leg_target(from, to, Vector2::new(30.0, 7.0), 2.2, 4.0);
        assert_abs_diff_eq!(along, Vector2::new(30.0, 0.0), epsilon = 1e-12);
        assert_abs_diff_eq!(target, Vector2::new(38.8, 0.0), epsilon = 1e-12);
        assert!(leg_done(from, to, Vector2::new(92.0, 0.0), 2.2, 4.0));
        assert!(!leg_done(from, to, Vector2::new(90.0, 0.0), 2.2, 4.0));
        // passed wide of the waypoint: done; as wide but short of it: not yet
        assert!(leg_done(from, to, Vector2::new(100.5, 12.0), 2.2, 4.0));
        assert!(!leg_done(from, to, Vector2::new(99.5, 12.0), 2.2, 4.0));
    }

    /// The planner on a subsample of a particle cloud against the planner on all of it:
    /// a banana-shaped belief of 1e5 particles (a bearing-only fix: spread along the
    /// line of sight). The choice on 2e4, 5e3 and 1e3 systematically drawn particles,
    /// scored on the whole cloud, keeps at least 90 % of the best score.
    #[test]
    fn a_subsample_chooses_nearly_as_well() {
        use crate::filter::particle::{ParticleFilter, ParticleSettings};
        use nalgebra::SVector;
        let mean = SVector::<f64, 3>::new(100.0, 50.0, 30.0);
        let mut pf = ParticleFilter::<3>::gaussian(
            100_000,
            &mean,
            &SVector::<f64, 3>::new(15.0, 15.0, 2.0),
            ParticleSettings::default(),
            9,
        );
        // one bearing from an ASV at (60, 20): weights by azimuth only
        struct Azimuth;
        impl crate::filter::particle::ParticleLikelihood for Azimuth {
            fn add_log_likelihood(&self, x: &[&[f32]], origin: &[f64], log_w: &mut [f32]) {
                for (i, lw) in log_w.iter_mut().enumerate() {
                    let (n, e) = (origin[0] + f64::from(x[0][i]), origin[1] + f64::from(x[1][i]));
                    let a = (e - 20.0).atan2(n - 60.0);
                    let d = a - (30.0f64).atan2(40.0);
                    *lw -= (d * d / (2.0 * 0.03 * 0.03)) as f32;
                }
            }
        }
        pf.update(&Azimuth);
        let all: Vec<Vector3<f64>> = pf.subsample(pf.len(), [0, 1, 2]).into_iter().map(Vector3::from).collect();
        let uniform = |n: usize| vec![1.0 / n as f64; n];
        let w_all = uniform(all.len());
        let full = Belief { positions: &all, weights: &w_all, velocity_m_s: Vector2::zeros(), lead_s: 0.0 };
        let (asv, v) = (Vector2::new(60.0, 20.0), Vector2::new(2.0, 0.0));
        for metric in [SpreadMetric::Determinant, SpreadMetric::MaxEigenvalue] {
            let p = planner(metric);
            let best = p.decide(&full, asv, v);
            for m in [20_000, 5_000, 1_000] {
                let sub: Vec<Vector3<f64>> = pf.subsample(m, [0, 1, 2]).into_iter().map(Vector3::from).collect();
                let w = uniform(m);
                let choice = p.decide(
                    &Belief { positions: &sub, weights: &w, velocity_m_s: Vector2::zeros(), lead_s: 0.0 },
                    asv,
                    v,
                );
                let kept = p.spread(&full, choice.waypoint) / best.score;
                eprintln!(
                    "{metric:?} subsample {m}: {:.1} m from the full choice, {:.1} % of its score",
                    (choice.waypoint - best.waypoint).norm(),
                    100.0 * kept
                );
                assert!(kept >= 0.9, "{metric:?}, {m}: {kept}");
            }
        }
    }
}
