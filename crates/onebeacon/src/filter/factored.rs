//! The factored particle filter of rypkema sec. 3.3: particles of the beacon's position
//! relative to the vehicle (the vehicle-carried frame, here NED), an update that weighs
//! a range-domain copy and an angle-domain copy of the set separately and recombines
//! them by rank, and the same update done jointly (every particle weighed by both
//! pseudo-distributions at once), to show what the factoring buys.
//!
//! Frames: the paper's VCF and BFF are ENU and forward-port-up with yaw from east
//! (eq. 15); we keep NED and forward-starboard-down throughout, and
//! [`crate::nav::iusbl::paper_angles`] converts at the boundary.

use nalgebra::{Matrix2, Matrix3, Vector2, Vector3};
use rand::RngExt;
use rand_pcg::Pcg64;
use std::f64::consts::TAU;

/// What one ping says of the beacon: a weight for every range and for every direction
/// in the body frame (the pseudo-distributions of rypkema eq. 5 and of SPD-BF).
pub trait PingLikelihood {
    /// Weight (>= 0) of the beacon at slant range `r_m`.
    fn range_weight(&self, r_m: f64) -> f64;
    /// Weight (>= 0) of the beacon toward unit vector `u` of the body frame (x forward,
    /// y starboard, z down).
    fn direction_weight(&self, u: &Vector3<f64>) -> f64;
}

/// Settings of the filter (rypkema sec. 3.3.2-3.3.4).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FactoredSettings {
    /// Particles (500).
    pub particles: usize,
    /// Largest range of the receiver, m (316: 8000 samples at 37.5 kS/s, 1481 m/s).
    pub max_range_m: f64,
    /// Lowest-weighted particles of each domain drawn again uniformly at each update (50).
    pub reinitialised: usize,
}

impl Default for FactoredSettings {
    fn default() -> Self {
        Self { particles: 500, max_range_m: 316.0, reinitialised: 50 }
    }
}

/// The motion of the set over one prediction (eq. 21): the vehicle's dead-reckoned
/// displacement and depth change, with their noise, and the beacon's own motion.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Motion {
    /// Vehicle displacement over the interval, NED north and east, m.
    pub displacement_m: Vector2<f64>,
    /// Vehicle depth change, m (down positive).
    pub depth_change_m: f64,
    /// Standard deviation of the distance travelled (speed noise x time), m.
    pub sigma_distance_m: f64,
    /// Standard deviation of the heading over the interval, rad.
    pub sigma_heading_rad: f64,
    /// Standard deviation of the beacon's own displacement per horizontal axis, m.
    pub sigma_beacon_m: f64,
}

/// The last factored update's two sets, for pictures (rypkema Fig. 6).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct FactoredSets {
    /// Range-domain particles: range (m) and normalised weight.
    pub ranges: Vec<(f64, f64)>,
    /// Angle-domain particles: body-frame direction and normalised weight.
    pub directions: Vec<(Vector3<f64>, f64)>,
}

/// Particles of the beacon's position relative to the vehicle, NED, with normalised
/// weights.
#[derive(Debug, Clone)]
pub struct FactoredFilter {
    pub settings: FactoredSettings,
    x: Vec<Vector3<f64>>,
    w: Vec<f64>,
    rng: Pcg64,
    sets: FactoredSets,
}

/// A direction drawn uniformly on the unit sphere.
fn uniform_direction(rng: &mut Pcg64) -> Vector3<f64> {
    let z: f64 = rng.random_range(-1.0..=1.0);
    let a: f64 = rng.random_range(0.0..TAU);
    let s = (1.0 - z * z).max(0.0).sqrt();
    Vector3::new(s * a.cos(), s * a.sin(), z)
}

fn normal(rng: &mut Pcg64) -> f64 {
    rng.sample::<f64, _>(rand_distr::StandardNormal)
}

/// Normalises `w` to sum to one; uniform if they sum to zero or less (or not finite).
fn normalise(w: &mut [f64]) {
    let s: f64 = w.iter().sum();
    if s.is_finite() && s > 0.0 {
        w.iter_mut().for_each(|v| *v /= s);
    } else {
        let u = 1.0 / w.len().max(1) as f64;
        w.iter_mut().for_each(|v| *v = u);
    }
}

/// Indices of `w` in ascending order of weight (ties by index).
fn ascending(w: &[f64]) -> Vec<usize> {
    let mut idx: Vec<usize> = (0..w.len()).collect();
    idx.sort_by(|&a, &b| w[a].total_cmp(&w[b]).then(a.cmp(&b)));
    idx
}

impl FactoredFilter {
    /// A filter initialised as in sec. 3.3.2, drawing from `seed`.
    pub fn new(settings: FactoredSettings, seed: u64) -> Self {
        let n = settings.particles.max(1);
        let mut f = Self {
            settings: FactoredSettings { particles: n, ..settings },
            x: vec![Vector3::zeros(); n],
            w: vec![1.0 / n as f64; n],
            rng: Pcg64::new(u128::from(seed) << 64 | 0x1f, 0xda3e_39cb_94b9_5bdb),
            sets: FactoredSets::default(),
        };
        f.initialise();
        f
    }

    /// Particles from explicit positions with equal weights (tests, brute-force
    /// comparisons).
    pub fn from_particles(settings: FactoredSettings, x: Vec<Vector3<f64>>, seed: u64) -> Self {
        let n = x.len().max(1);
        let mut f = Self::new(FactoredSettings { particles: n, ..settings }, seed);
        f.x = x;
        f.w = vec![1.0 / n as f64; n];
        f
    }

    /// Eq. 20: ranges uniform in [0, max range], directions uniform on the sphere, equal
    /// weights (what the paper does at launch and after every surfacing). Note: uniform
    /// ranges put the density as 1 / r^2, not uniform in the sphere's volume as the
    /// paper says.
    pub fn initialise(&mut self) {
        let n = self.x.len();
        for i in 0..n {
            let r = self.rng.random_range(0.0..=self.settings.max_range_m);
            self.x[i] = uniform_direction(&mut self.rng) * r;
        }
        self.w.iter_mut().for_each(|v| *v = 1.0 / n as f64);
    }

    pub fn particles(&self) -> &[Vector3<f64>] {
        &self.x
    }

    pub fn weights(&self) -> &[f64] {
        &self.w
    }

    /// The last factored update's range and angle sets.
    pub fn sets(&self) -> &FactoredSets {
        &self.sets
    }

    /// Eq. 21 with the dead-reckoned displacement of the interval: each particle moves
    /// against the vehicle's displacement, its length and direction perturbed by the
    /// speed and heading noise, plus the beacon's own random motion; z follows the
    /// vehicle's depth change.
    pub fn predict(&mut self, m: &Motion) {
        let d = m.displacement_m;
        let len = d.norm();
        let dir = if len > 0.0 { d / len } else { Vector2::new(1.0, 0.0) };
        for p in &mut self.x {
            let l = len + m.sigma_distance_m * normal(&mut self.rng);
            let (s, c) = (m.sigma_heading_rad * normal(&mut self.rng)).sin_cos();
            let step = Vector2::new(c * dir.x - s * dir.y, s * dir.x + c * dir.y) * l;
            p.x += -step.x + m.sigma_beacon_m * normal(&mut self.rng);
            p.y += -step.y + m.sigma_beacon_m * normal(&mut self.rng);
            p.z -= m.depth_change_m;
        }
    }

    /// The factored update (eq. 22-24): a range-domain copy weighted by the range
    /// pseudo-distribution at each particle's range and an angle-domain copy weighted by
    /// the direction pseudo-distribution at each particle's direction in the body frame
    /// (attitude `body_to_ned` at the time of arrival); the lowest `reinitialised` of each
    /// domain drawn again uniformly over it (weighed like the others, with the mean prior
    /// weight); both normalised and sorted by weight, recombined element-wise by rank;
    /// then systematic resampling.
    pub fn update_factored(&mut self, like: &impl PingLikelihood, body_to_ned: &Matrix3<f64>) {
        let n = self.x.len();
        let to_body = body_to_ned.transpose();
        // eq. 22-23: the two copies
        let mut ranges: Vec<f64> = self.x.iter().map(|p| p.norm()).collect();
        let mut dirs: Vec<Vector3<f64>> =
            self.x.iter().map(|p| (to_body * p).try_normalize(1e-12).unwrap_or_else(Vector3::x)).collect();
        let mut wr: Vec<f64> = ranges.iter().zip(&self.w).map(|(r, w)| w * like.range_weight(*r)).collect();
        let mut wa: Vec<f64> = dirs.iter().zip(&self.w).map(|(u, w)| w * like.direction_weight(u)).collect();
        // the lowest of each domain drawn again uniformly over it
        let prior = 1.0 / n as f64;
        let k = self.settings.reinitialised.min(n);
        for &i in ascending(&wr).iter().take(k) {
            ranges[i] = self.rng.random_range(0.0..=self.settings.max_range_m);
            wr[i] = prior * like.range_weight(ranges[i]);
        }
        for &i in ascending(&wa).iter().take(k) {
            dirs[i] = uniform_direction(&mut self.rng);
            wa[i] = prior * like.direction_weight(&dirs[i]);
        }
        normalise(&mut wr);
        normalise(&mut wa);
        let (or, oa) = (ascending(&wr), ascending(&wa));
        // eq. 24: recombination by rank
        for j in 0..n {
            let (i, a) = (or[j], oa[j]);
            self.x[j] = body_to_ned * (dirs[a] * ranges[i]);
            self.w[j] = wr[i] * wa[a];
        }
        normalise(&mut self.w);
        self.sets.ranges = ranges.into_iter().zip(wr).collect();
        self.sets.directions = dirs.into_iter().zip(wa).collect();
        self.resample();
    }

    /// The joint (non-factored) update: every particle weighted by both
    /// pseudo-distributions at its own range and direction; then systematic
    /// resampling. The same likelihoods as [`FactoredFilter::update_factored`], no
    /// duplication, no recombination, no re-initialisation.
    pub fn update_joint(&mut self, like: &impl PingLikelihood, body_to_ned: &Matrix3<f64>) {
        let to_body = body_to_ned.transpose();
        for (p, w) in self.x.iter().zip(self.w.iter_mut()) {
            let r = p.norm();
            let u = (to_body * p).try_normalize(1e-12).unwrap_or_else(Vector3::x);
            *w *= like.range_weight(r) * like.direction_weight(&u);
        }
        normalise(&mut self.w);
        self.resample();
    }

    /// Systematic resampling (one uniform offset, N evenly spaced points).
    fn resample(&mut self) {
        let n = self.x.len();
        let u0: f64 = self.rng.random_range(0.0..1.0);
        let mut out = Vec::with_capacity(n);
        let (mut cum, mut i) = (self.w[0], 0);
        for j in 0..n {
            let point = (j as f64 + u0) / n as f64;
            while point > cum && i + 1 < n {
                i += 1;
                cum += self.w[i];
            }
            out.push(self.x[i]);
        }
        self.x = out;
        self.w.iter_mut().for_each(|v| *v = 1.0 / n as f64);
    }

    /// Weighted mean and covariance of the horizontal position (eq. 25, with the usual
    /// weighted covariance: the paper's 1/499 in front of normalised weights would shrink
    /// it 499 times).
    pub fn mean_covariance(&self) -> (Vector2<f64>, Matrix2<f64>) {
        let mean: Vector2<f64> = self.x.iter().zip(&self.w).map(|(p, w)| p.xy() * *w).sum();
        let cov: Matrix2<f64> = self
            .x
            .iter()
            .zip(&self.w)
            .map(|(p, w)| {
                let d = p.xy() - mean;
                d * d.transpose() * *w
            })
            .sum();
        (mean, cov)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::models::kinematic6dof::rotation;

    /// A Gaussian range and a von Mises-Fisher direction.
    struct Bell {
        range_m: f64,
        sigma_r: f64,
        toward: Vector3<f64>,
        sigma_a: f64,
    }

    impl PingLikelihood for Bell {
        fn range_weight(&self, r: f64) -> f64 {
            (-0.5 * ((r - self.range_m) / self.sigma_r).powi(2)).exp()
        }
        fn direction_weight(&self, u: &Vector3<f64>) -> f64 {
            ((u.dot(&self.toward) - 1.0) / self.sigma_a.powi(2)).exp()
        }
    }

    /// The posterior mean of the beacon's horizontal position under `like` with a prior
    /// uniform over the horizontal disc of radius `rmax` at depth offset `dz`, by brute
    /// force: a 0.05 m grid around the likelihood's peak (the prior is flat there).
    fn brute_force_mean(like: &Bell, att: &Matrix3<f64>, dz: f64) -> Vector2<f64> {
        let peak = att * like.toward * like.range_m;
        let (mut s, mut sw) = (Vector2::zeros(), 0.0);
        let h = 0.05;
        for i in -400..=400 {
            for j in -400..=400 {
                let p = Vector3::new(peak.x + i as f64 * h, peak.y + j as f64 * h, dz);
                let u = (att.transpose() * p).normalize();
                let w = like.range_weight(p.norm()) * like.direction_weight(&u);
                s += p.xy() * w;
                sw += w;
            }
        }
        s / sw
    }

    /// The factored update against a brute-force joint posterior on a small case: 500
    /// particles uniform over a 150 m disc (about 0.3 of them inside the likelihood's
    /// 2-sigma box), one ping 60 m away (0.5 m, 3 deg). Recombination by rank builds
    /// particles at the best range and the best direction although no prior particle
    /// was near both: the factored mean lands within 1.5 m of the brute-force
    /// posterior mean, where the joint update on the same particles can only pick the
    /// least bad prior particle (metres away).
    #[test]
    fn factored_update_against_a_brute_force_joint_posterior() {
        let att = rotation(0.05, -0.1, 0.8);
        let dz = 1.5;
        let truth_body = (att.transpose() * Vector3::new(40.0, -44.0, dz)).normalize();
        let truth_r = Vector3::new(40.0, -44.0, dz).norm();
        let like = Bell { range_m: truth_r, sigma_r: 0.5, toward: truth_body, sigma_a: 3f64.to_radians() };
        let expected = brute_force_mean(&like, &att, dz);
        let (mut factored_err, mut joint_err) = (Vec::new(), Vec::new());
        for seed in 0..20u64 {
            let mut rng = Pcg64::new(u128::from(seed) + 7, 3);
            let prior: Vec<Vector3<f64>> = (0..500)
                .map(|_| {
                    let r = 150.0 * rng.random_range(0.0f64..1.0).sqrt();
                    let a = rng.random_range(0.0..TAU);
                    Vector3::new(r * a.cos(), r * a.sin(), dz)
                })
                .collect();
            let settings = FactoredSettings { particles: 500, max_range_m: 150.0, reinitialised: 50 };
            let mut f = FactoredFilter::from_particles(settings, prior.clone(), seed);
            f.update_factored(&like, &att);
            factored_err.push((f.mean_covariance().0 - expected).norm());
            let mut j = FactoredFilter::from_particles(settings, prior, seed);
            j.update_joint(&like, &att);
            joint_err.push((j.mean_covariance().0 - expected).norm());
        }
        let median = |v: &mut Vec<f64>| {
            v.sort_by(f64::total_cmp);
            v[v.len() / 2]
        };
        let (fe, je) = (median(&mut factored_err), median(&mut joint_err));
        assert!(fe < 1.5, "factored: median distance to the brute-force mean {fe} m");
        assert!(je > 2.0 * fe, "joint {je} m against factored {fe} m");
    }

    /// Prediction alone: the mean moves against the vehicle's displacement, and the
    /// spread grows as the noise says (distance and heading noise along and across the
    /// track, beacon noise on both axes): variance along = s_d^2 + s_b^2, across =
    /// (L s_h)^2 + s_b^2 to first order.
    #[test]
    fn prediction_moves_and_spreads_as_eq_21() {
        let settings = FactoredSettings { particles: 20_000, max_range_m: 1.0, reinitialised: 0 };
        let mut f = FactoredFilter::from_particles(settings, vec![Vector3::new(10.0, 5.0, 1.0); 20_000], 4);
        let m = Motion {
            displacement_m: Vector2::new(0.0, 20.0),
            depth_change_m: 0.5,
            sigma_distance_m: 0.5,
            sigma_heading_rad: 0.02,
            sigma_beacon_m: 0.3,
        };
        f.predict(&m);
        let (mean, cov) = f.mean_covariance();
        assert!((mean - Vector2::new(10.0, -15.0)).norm() < 0.05, "{mean}");
        let along = 0.5f64.powi(2) + 0.09;
        let across = (20.0f64 * 0.02).powi(2) + 0.09;
        assert!((cov[(1, 1)] / along - 1.0).abs() < 0.05, "{} {along}", cov[(1, 1)]);
        assert!((cov[(0, 0)] / across - 1.0).abs() < 0.05, "{} {across}", cov[(0, 0)]);
        assert!((f.particles()[0].z - 0.5).abs() < 1e-12);
    }
}
