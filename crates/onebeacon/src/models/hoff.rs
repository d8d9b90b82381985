//! hoff2024's particle model of an AUV tracked from a surface vehicle: the stochastic
//! unicycle [x, y, z, theta, psi, u, b_theta, b_psi] (NED position, pitch, heading, surge
//! speed, and the pitch and heading rates as biases decaying with time constant T_b),
//! propagated with truncated Gaussian steps (eq. 4); the AUV's INS report (eq. 8) and
//! the USBL bearing (eq. 6-7) that weigh it are [`crate::measure::hoff`].

use crate::filter::ProcessModel;
use crate::filter::lanes::{self, lanes, sin_cos1};
use crate::filter::particle::ParticleProcess;
use crate::filter::truncated::truncated_normal;
use crate::geo::wrap_angle;
use nalgebra::{SMatrix, SVector};
use rand_pcg::Pcg64;
use std::f32::consts::TAU;
use std::f64::consts::{FRAC_PI_2, PI};

/// State dimension.
pub const DIM: usize = 8;

/// The tracker's state with the USBL head's yaw misalignment as a ninth component
/// ([`MisalignedProcess`]).
pub const DIM_MISALIGNED: usize = DIM + 1;

/// Index of each state component.
pub mod idx {
    pub const X: usize = 0;
    pub const Y: usize = 1;
    pub const Z: usize = 2;
    pub const THETA: usize = 3;
    pub const PSI: usize = 4;
    pub const U: usize = 5;
    pub const B_THETA: usize = 6;
    pub const B_PSI: usize = 7;
    /// The USBL head's yaw misalignment, rad, in a tracker that estimates it.
    pub const MISALIGNMENT: usize = 8;
}

/// The process model (eq. 4) with its noise: standard deviations per second of each
/// component's step (the covariance of a step over dt is diag(sigma^2) dt^2).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HoffProcess {
    pub sigma: [f64; DIM],
    /// The biases' time constant T_b, s.
    pub t_b_s: f64,
    /// The shallowest depth z_1 (the splash zone is avoided), m.
    pub z_min_m: f64,
}

/// The factor on section 5's bias variances in [`HoffProcess::default`].
pub const BIAS_VARIANCE_SCALE: f64 = 1e-4;

impl HoffProcess {
    /// Section 5 as printed: sigma_x^2 = sigma_y^2 = 0.16 m^2/s^2, sigma_z^2 = 0.03,
    /// sigma_theta^2 = 4e-5 rad^2/s^2, sigma_psi^2 = 1e-4, sigma_u^2 = 2e-3 m^2/s^4,
    /// sigma_b_theta^2 = 5e-4 rad^2/s^4, sigma_b_psi^2 = 1e-3, T_b = 1000 s; z_1 = 1 m (the
    /// paper gives none). Its biases random-walk far: a step of 4 s adds 0.09 and 0.13
    /// rad/s to them, and their stationary standard deviations (sigma_b^2 dt T_b / 2) are
    /// 1.0 and 1.4 rad/s, so that after a few minutes each particle pitches and turns at
    /// random, most of them pinned at +-90 deg of pitch. A filter on it loses the
    /// vehicle (docs/scenarios.md, hoff2024: the consistency study).
    pub fn section_5() -> Self {
        Self {
            sigma: [
                0.16f64.sqrt(),
                0.16f64.sqrt(),
                0.03f64.sqrt(),
                4e-5f64.sqrt(),
                1e-4f64.sqrt(),
                2e-3f64.sqrt(),
                5e-4f64.sqrt(),
                1e-3f64.sqrt(),
            ],
            t_b_s: 1000.0,
            z_min_m: 1.0,
        }
    }
}

impl Default for HoffProcess {
    /// [`HoffProcess::section_5`] with the two bias variances scaled by
    /// [`BIAS_VARIANCE_SCALE`]: at dt = 4 s their stationary standard deviations become
    /// 0.010 and 0.014 rad/s (0.6 and 0.8 deg/s of pitch and turn rate), what an AUV
    /// holds between manoeuvres.
    fn default() -> Self {
        let mut p = Self::section_5();
        for k in [idx::B_THETA, idx::B_PSI] {
            p.sigma[k] *= BIAS_VARIANCE_SCALE.sqrt();
        }
        p
    }
}

/// Particles a propagation or a likelihood handles at a time: its scratch arrays stay
/// in the first-level cache.
pub(crate) const BLOCK: usize = 256;

impl ParticleProcess for HoffProcess {
    /// Block by block: the block's normal draws, then eq. 4's step ([`hoff_step`]: the
    /// sines and cosines in the same pass, the particles' offsets in single precision).
    /// A truncated component takes the plain draw when it falls within its bounds and
    /// otherwise a draw of the truncated law (rejection's first try, then an exact draw:
    /// the result follows the truncated law).
    fn propagate(&self, x: &mut [&mut [f32]], origin: &[f64], dt: f64, rng: &mut Pcg64) {
        let [px, py, pz, pt, pp, pu, pbt, pbp] = x else { panic!("hoff2024's state has {DIM} components") };
        let o = |k: usize| origin[k];
        let step = self.step(origin, dt);
        // the truncations' bounds (eq. 4) as offsets
        let z_min = (self.z_min_m - o(idx::Z)) as f32;
        let theta_bounds = [-FRAC_PI_2 - o(idx::THETA), FRAC_PI_2 - o(idx::THETA)].map(|v| v as f32);
        let u_min = -o(idx::U) as f32;
        let n = px.len();
        let mut noise = [0.0f32; DIM * BLOCK];
        for start in (0..n).step_by(BLOCK) {
            let m = BLOCK.min(n - start);
            let r = start..start + m;
            let e = &mut noise[..DIM * m];
            lanes::standard_normals(rng, e);
            let mut block = [
                &mut px[r.clone()],
                &mut py[r.clone()],
                &mut pz[r.clone()],
                &mut pt[r.clone()],
                &mut pp[r.clone()],
                &mut pu[r.clone()],
                &mut pbt[r.clone()],
                &mut pbp[r],
            ];
            hoff_step(&mut block, e, &step);
            let [_, _, z, theta, _, u, ..] = block;
            let s = |k: usize| f64::from(step.sigma[k]);
            // the truncations (eq. 4), rarely needed: drawn again from the step's mean
            let mut redraw = |v: &mut f32, k: usize, j: usize, lo: f64, hi: f64| {
                let mean = o(k) + f64::from(*v - step.sigma[k] * e[k * m + j]);
                *v = (truncated_normal(rng, mean, s(k), lo, hi) - o(k)) as f32;
            };
            for j in 0..m {
                if z[j] < z_min {
                    redraw(&mut z[j], idx::Z, j, self.z_min_m, f64::INFINITY);
                }
                if theta[j] < theta_bounds[0] || theta[j] > theta_bounds[1] {
                    redraw(&mut theta[j], idx::THETA, j, -FRAC_PI_2, FRAC_PI_2);
                }
                if u[j] < u_min {
                    redraw(&mut u[j], idx::U, j, 0.0, f64::INFINITY);
                }
            }
        }
    }
}

/// Eq. 4's step as [`hoff_step`] reads it, in single precision: the step, each
/// component's noise over it, the biases' decay, the origin of the angles, speed and
/// biases (whose absolute values the step needs), what the decay takes from a bias's
/// offset, and the bounds a heading's offset wraps within.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Step {
    dt: f32,
    sigma: [f32; DIM],
    keep: f32,
    /// theta, psi, u, b_theta, b_psi.
    origin: [f32; 5],
    decay: [f32; 2],
    psi_bounds: [f32; 2],
}

impl HoffProcess {
    /// Eq. 4's step over `dt` for particles stored from `origin`, as [`hoff_step`]
    /// reads it.
    pub(crate) fn step(&self, origin: &[f64], dt: f64) -> Step {
        let o = |k: usize| origin[k];
        let keep = 1.0 - dt / self.t_b_s;
        Step {
            dt: dt as f32,
            sigma: self.sigma.map(|v| (v * dt) as f32),
            keep: keep as f32,
            origin: [o(idx::THETA), o(idx::PSI), o(idx::U), o(idx::B_THETA), o(idx::B_PSI)].map(|v| v as f32),
            // a bias's offset decays toward minus its origin's share
            decay: [o(idx::B_THETA), o(idx::B_PSI)].map(|b| (b * (1.0 - keep)) as f32),
            psi_bounds: [-PI - o(idx::PSI), PI - o(idx::PSI)].map(|v| v as f32),
        }
    }
}

lanes! {
    /// Eq. 4 over a block of particles' offsets: the mean step f(x) dt and the noise
    /// sigma dt e (e: the block's standard normal draws, component by component), the
    /// heading wrapped; the truncations are the caller's.
    pub(crate) fn hoff_step(x: &mut [&mut [f32]; DIM], e: &[f32], p: &Step) {
        let [px, py, pz, pt, pp, pu, pbt, pbp] = x;
        let m = px.len();
        let e: [&[f32]; DIM] = std::array::from_fn(|k| &e[k * m..(k + 1) * m]);
        let (py, pz, pt, pp, pu, pbt, pbp) =
            (&mut py[..m], &mut pz[..m], &mut pt[..m], &mut pp[..m], &mut pu[..m], &mut pbt[..m], &mut pbp[..m]);
        let (s, dt, [t0, p0, u0, bt0, bp0]) = (p.sigma, p.dt, p.origin);
        for j in 0..m {
            let (st, ct) = sin_cos1(t0 + pt[j]);
            let (sp, cp) = sin_cos1(p0 + pp[j]);
            let u = u0 + pu[j];
            // eq. 4: the mean step f(x) dt, noise sigma dt
            px[j] += u * ct * cp * dt + s[idx::X] * e[idx::X][j];
            py[j] += u * ct * sp * dt + s[idx::Y] * e[idx::Y][j];
            pz[j] += -u * st * dt + s[idx::Z] * e[idx::Z][j];
            pt[j] += (bt0 + pbt[j]) * dt + s[idx::THETA] * e[idx::THETA][j];
            // a step of the heading is far below a turn: one add or subtract wraps it
            let h = pp[j] + (bp0 + pbp[j]) * dt + s[idx::PSI] * e[idx::PSI][j];
            pp[j] = if h > p.psi_bounds[1] {
                h - TAU
            } else if h <= p.psi_bounds[0] {
                h + TAU
            } else {
                h
            };
            pu[j] += s[idx::U] * e[idx::U][j];
            // b' = b keep + noise, as an offset: b0 + o' = (b0 + o) keep + noise
            pbt[j] = pbt[j] * p.keep - p.decay[0] + s[idx::B_THETA] * e[idx::B_THETA][j];
            pbp[j] = pbp[j] * p.keep - p.decay[1] + s[idx::B_PSI] * e[idx::B_PSI][j];
        }
    }
}

/// Eq. 4 for a tracker whose state carries the USBL head's yaw misalignment as a ninth
/// component: the vehicle's eight as [`HoffProcess`] moves them, the misalignment a
/// random walk (a mounting is constant; the walk keeps the particles' values diverse
/// after resampling).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MisalignedProcess {
    pub process: HoffProcess,
    /// The misalignment's walk, rad per sqrt(s).
    pub walk_rad_per_sqrt_s: f64,
}

impl ParticleProcess for MisalignedProcess {
    fn propagate(&self, x: &mut [&mut [f32]], origin: &[f64], dt: f64, rng: &mut Pcg64) {
        ParticleProcess::propagate(&self.process, &mut x[..DIM], &origin[..DIM], dt, rng);
        let [misalignment] = &mut x[DIM..] else { panic!("the misaligned state has {DIM_MISALIGNED} components") };
        let s = (self.walk_rad_per_sqrt_s * dt.sqrt()) as f32;
        let mut noise = [0.0; BLOCK];
        for block in misalignment.chunks_mut(BLOCK) {
            lanes::standard_normals(rng, &mut noise[..block.len()]);
            for (m, e) in block.iter_mut().zip(&noise) {
                *m += s * e;
            }
        }
    }
}

/// Eq. 4's mean step and noise as a Gaussian process model, for the EKF and UKF on the
/// same runs as the particle filter (the truncation left out: the Kalman filters cannot
/// hold it).
impl ProcessModel<DIM> for HoffProcess {
    fn propagate(&self, x: &SVector<f64, DIM>, dt: f64) -> SVector<f64, DIM> {
        self.transition(x, dt).0
    }

    fn jacobian(&self, x: &SVector<f64, DIM>, dt: f64) -> SMatrix<f64, DIM, DIM> {
        self.transition(x, dt).1
    }

    fn transition(&self, x: &SVector<f64, DIM>, dt: f64) -> (SVector<f64, DIM>, SMatrix<f64, DIM, DIM>) {
        let (theta, psi, u) = (x[idx::THETA], x[idx::PSI], x[idx::U]);
        let (st, ct) = theta.sin_cos();
        let (sp, cp) = psi.sin_cos();
        let decay = dt / self.t_b_s;
        let mut n = *x;
        n[idx::X] += u * ct * cp * dt; // eq. 4, the mean step f(x) dt
        n[idx::Y] += u * ct * sp * dt;
        n[idx::Z] -= u * st * dt;
        n[idx::THETA] += x[idx::B_THETA] * dt;
        n[idx::PSI] = wrap_angle(psi + x[idx::B_PSI] * dt);
        n[idx::B_THETA] *= 1.0 - decay;
        n[idx::B_PSI] *= 1.0 - decay;
        let mut f = SMatrix::<f64, DIM, DIM>::identity();
        f[(idx::X, idx::THETA)] = -u * st * cp * dt;
        f[(idx::X, idx::PSI)] = -u * ct * sp * dt;
        f[(idx::X, idx::U)] = ct * cp * dt;
        f[(idx::Y, idx::THETA)] = -u * st * sp * dt;
        f[(idx::Y, idx::PSI)] = u * ct * cp * dt;
        f[(idx::Y, idx::U)] = ct * sp * dt;
        f[(idx::Z, idx::THETA)] = -u * ct * dt;
        f[(idx::Z, idx::U)] = -st * dt;
        f[(idx::THETA, idx::B_THETA)] = dt;
        f[(idx::PSI, idx::B_PSI)] = dt;
        f[(idx::B_THETA, idx::B_THETA)] = 1.0 - decay;
        f[(idx::B_PSI, idx::B_PSI)] = 1.0 - decay;
        (n, f)
    }

    /// diag(sigma^2) dt^2 (eq. 4).
    fn noise_covariance(&self, _x: &SVector<f64, DIM>, dt: f64) -> SMatrix<f64, DIM, DIM> {
        SMatrix::from_diagonal(&SVector::from(self.sigma.map(|s| s * s * dt * dt)))
    }

    fn is_angle(&self, i: usize) -> bool {
        i == idx::PSI
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::filter::particle::ParticleLikelihood;
    use crate::filter::particle::{ParticleFilter, ParticleSettings};
    use crate::measure::Usbl;
    use crate::measure::hoff::UsblBearing;
    use nalgebra::SVector;

    /// The mean step of eq. 4 against its closed form (no noise: every sigma 0): 10 s at
    /// 2 m/s, pitch 0.1 rad, heading 0.5 rad, heading bias 0.01 rad/s; and with noise, every
    /// particle stays within the truncation bounds.
    #[test]
    fn steps_follow_eq_4_within_bounds() {
        let still = HoffProcess { sigma: [0.0; DIM], ..HoffProcess::default() };
        let mean = SVector::<f64, DIM>::from([0.0, 0.0, 30.0, 0.1, 0.5, 2.0, 0.0, 0.01]);
        let mut pf = ParticleFilter::<DIM>::gaussian(4, &mean, &SVector::zeros(), ParticleSettings::default(), 1);
        pf.predict(&still, 10.0);
        let (m, _) = pf.mean_covariance();
        let (u, dt) = (2.0, 10.0);
        // the particles' sines are single precision (filter::lanes): 1e-7 of the 20 m step
        assert!((m[idx::X] - u * 0.1f64.cos() * 0.5f64.cos() * dt).abs() < 4e-6);
        assert!((m[idx::Y] - u * 0.1f64.cos() * 0.5f64.sin() * dt).abs() < 4e-6);
        assert!((m[idx::Z] - (30.0 - u * 0.1f64.sin() * dt)).abs() < 4e-6);
        // single precision: 6e-8 of the heading, of the bias's offset from its origin
        assert!((m[idx::PSI] - (0.5 + 0.01 * dt)).abs() < 1e-6);
        assert!((m[idx::B_PSI] - 0.01 * (1.0 - dt / 1000.0)).abs() < 1e-9);

        let shallow = SVector::<f64, DIM>::from([0.0, 0.0, 1.5, 1.5, 0.0, 0.05, 0.0, 0.0]);
        let mut pf =
            ParticleFilter::<DIM>::gaussian(50_000, &shallow, &SVector::zeros(), ParticleSettings::default(), 2);
        pf.predict(&HoffProcess::default(), 4.0);
        let (z, theta, u) = (pf.component(idx::Z), pf.component(idx::THETA), pf.component(idx::U));
        assert!(z.iter().all(|v| *v >= 1.0));
        assert!(theta.iter().all(|v| v.abs() <= FRAC_PI_2));
        assert!(u.iter().all(|v| *v >= 0.0));
    }

    /// The USBL likelihood (residuals as atan2 of cross and dot products, in single-
    /// precision lanes) against eq. 6 written with `Usbl::angles` and
    /// `Usbl::variances` in f64, particle by particle: around the station, across the
    /// azimuth's +-pi, almost overhead, with and without the station's pose errors, and
    /// with eq. 6 read as printed; within 1e-4 relative (single precision's share).
    #[test]
    fn usbl_likelihood_matches_eq_6() {
        use nalgebra::Vector3;
        let n = 1000;
        let pts: Vec<[f64; 3]> = (0..n)
            .map(|i| {
                let t = i as f64;
                let (r, a) = (0.3 + 60.0 * ((t * 0.37).sin() * 0.5 + 0.5), t * 2.399);
                [10.0 + r * a.cos(), -4.0 + r * a.sin(), 30.0 + 5.0 * (t * 0.11).sin()]
            })
            .collect();
        // the particles as offsets from an origin near them, and their positions as the
        // offsets hold them
        let origin = [12.0, -3.0, 28.0, 0.0, 0.0, 0.0, 0.0, 0.0];
        let comps: Vec<Vec<f32>> = (0..DIM)
            .map(|k| pts.iter().map(|p| if k < 3 { (p[k] - origin[k]) as f32 } else { 0.0 }).collect())
            .collect();
        let pts: Vec<[f64; 3]> = (0..n).map(|i| std::array::from_fn(|k| origin[k] + f64::from(comps[k][i]))).collect();
        let view: Vec<&[f32]> = comps.iter().map(|c| &c[..]).collect();
        for (gps, compass, as_printed) in [(0.0, 0.0, false), (1.0, 0.02, false), (0.0, 0.0, true)] {
            let usbl = Usbl {
                position_ned_m: Vector3::new(10.0, -4.0, 0.5),
                heading_rad: 3.0,
                sigma_rad_per_m: 0.01f64.to_radians(),
                position_sigma_m: gps,
                heading_sigma_rad: compass,
                floor_rad: 0.0,
                as_printed,
            };
            let bearing = UsblBearing { usbl, azimuth_rad: 0.2, elevation_rad: 0.9, robust: None };
            let mut got = vec![0.0; n];
            bearing.add_log_likelihood(&view, &origin, &mut got);
            for (i, p) in pts.iter().enumerate() {
                let p = Vector3::new(p[0], p[1], p[2]);
                let (alpha, phi, _) = usbl.angles(&p);
                let (var_a, var_e) = usbl.variances(&p);
                let (var_a, var_e) = if gps == 0.0 { (var_a.max(1e-12), var_e.max(1e-12)) } else { (var_a, var_e) };
                let (da, de) = (wrap_angle(0.2 - alpha), 0.9 - phi);
                let expected = -da * da / (2.0 * var_a) - de * de / (2.0 * var_e) - 0.5 * (var_a * var_e).ln(); // eq. 6
                assert!(
                    (f64::from(got[i]) - expected).abs() < 1e-4 * expected.abs().max(1.0),
                    "{i}: {} against {expected}",
                    got[i]
                );
            }
        }
    }

    /// A heavy-tailed bearing weighs outliers by hand-computed densities: two particles
    /// 10 and 20 standard deviations off in azimuth (a 1 deg floor, no range term) differ
    /// in log-weight by 150 with eq. 6, by k (20 - 10) = 13.45 with Huber's k = 1.345, and
    /// by (4 + 1) / 2 ln((1 + 400 / 4) / (1 + 100 / 4)) = 3.3925 with Student's t at 4
    /// degrees of freedom (1e-3: the lanes' single-precision atan2).
    #[test]
    fn robust_bearings_weigh_outliers_by_their_tails() {
        use crate::nav::Robust;
        use nalgebra::Vector3;
        let usbl = Usbl { floor_rad: 1f64.to_radians(), ..Usbl::exact(Vector3::zeros(), 0.0, 0.0) };
        let at = |az_deg: f64| {
            let (a, e) = (az_deg.to_radians(), 0.9f64);
            [50.0 * e.sin() * a.cos(), 50.0 * e.sin() * a.sin(), 50.0 * e.cos()]
        };
        let pts = [at(10.0), at(20.0)];
        let comps: Vec<Vec<f32>> =
            (0..DIM).map(|k| pts.iter().map(|p| if k < 3 { p[k] as f32 } else { 0.0 }).collect()).collect();
        let view: Vec<&[f32]> = comps.iter().map(|c| &c[..]).collect();
        for (robust, expected) in [
            (None, 150.0),
            (Some(Robust::Huber { k: 1.345 }), 13.45),
            (Some(Robust::StudentT { dof: 4.0 }), 2.5 * (101.0f64 / 26.0).ln()),
        ] {
            let mut w = vec![0.0; 2];
            UsblBearing { usbl, azimuth_rad: 0.0, elevation_rad: 0.9, robust }.add_log_likelihood(
                &view,
                &[0.0; DIM],
                &mut w,
            );
            let d = f64::from(w[0] - w[1]);
            assert!((d / expected - 1.0).abs() < 1e-3, "{robust:?}: {d} against {expected}");
        }
    }

    /// The precision argument of particles stored as single-precision offsets from a
    /// double-precision origin that follows the cloud: the same cloud, model and
    /// measurements at the frame's origin and translated to a UTM northing of 5e6 m (and
    /// an easting of 5e5 m, the station with it) hold the same offsets, bit for bit, over
    /// 30 cycles in which the AUV travels 180 m and the origin moves after it (origins
    /// on the 2^-10 m grid add exactly below 2^42 m). The estimates then differ by the
    /// last addition of the origin to the mean alone: half a unit in the last place of
    /// 5e6 in double precision, 2^-31 m, plus that of 100 m, 2^-47 m; the bound asserted
    /// is 2^-30 m (4.7e-10 m). Stored whole in single precision, positions near 5e6 m
    /// would be 0.5 m apart.
    #[test]
    fn a_cloud_far_from_the_frame_origin_is_held_as_finely_as_one_near_it() {
        use crate::filter::particle::ParticleSettings;
        use crate::measure::hoff::InsReport;
        use nalgebra::Vector3;
        let run = |north: f64, east: f64| {
            let mean = SVector::<f64, DIM>::from([north + 100.25, east + 50.5, 30.0, 0.0, 0.3, 1.5, 0.0, 0.002]);
            let sigma = SVector::<f64, DIM>::from([10.0, 10.0, 2.0, 0.05, 0.2, 0.3, 0.001, 0.003]);
            let settings = ParticleSettings {
                resampler: crate::filter::particle::Resampler::Multinomial,
                ..ParticleSettings::default()
            };
            let mut pf = ParticleFilter::<DIM>::gaussian(20_000, &mean, &sigma, settings, 11);
            let usbl = Usbl::exact(Vector3::new(north + 80.0, east + 30.0, 0.0), 0.0, 0.022f64.to_radians());
            let mut estimates = Vec::new();
            for k in 0..30 {
                let t = 4.0 * k as f64;
                pf.predict_resampled(&HoffProcess::default(), 4.0);
                let ins = InsReport::example();
                // the truth moves along the heading; its bearing from the station
                let p = Vector3::new(north + 100.25 + 1.43 * t, east + 50.5 + 0.44 * t, 30.0);
                let (azimuth_rad, elevation_rad, _) = usbl.angles(&p);
                pf.reweight(&(ins, UsblBearing { usbl, azimuth_rad, elevation_rad, robust: None }));
                estimates.push(pf.mean_covariance_with_angle(Some(idx::PSI)));
            }
            (estimates, pf.origin())
        };
        let (near, near_origin) = run(0.0, 0.0);
        let (far, far_origin) = run(5e6, 5e5);
        assert!(near_origin[idx::X] > 150.0, "the origin followed the cloud: {near_origin}");
        assert_eq!((far_origin[idx::X] - 5e6, far_origin[idx::Y] - 5e5), (near_origin[idx::X], near_origin[idx::Y]));
        let bound = 2f64.powi(-30);
        for ((m, c), (fm, fc)) in near.iter().zip(&far) {
            assert!((fm[idx::X] - 5e6 - m[idx::X]).abs() <= bound, "{} against {}", fm[idx::X] - 5e6, m[idx::X]);
            assert!((fm[idx::Y] - 5e5 - m[idx::Y]).abs() <= bound, "{} against {}", fm[idx::Y] - 5e5, m[idx::Y]);
            for k in 2..DIM {
                assert_eq!(fm[k].to_bits(), m[k].to_bits(), "component {k}");
            }
            assert_eq!(fc, c);
        }
    }

    /// The model's own kernels (eq. 4's step, eq. 8, eq. 6-7 plain, robust and with a
    /// misalignment) at each level the processor runs give the bits of the scalar
    /// kernels called one particle at a time (through `black_box`, so not vectorised):
    /// no result depends on the vector width. A block of 203 particles (vector bodies
    /// and a tail) spread over headings across +-pi, pitches, speeds and depths.
    #[test]
    fn every_level_matches_the_scalar_kernels_bit_for_bit() {
        use crate::filter::lanes::Level;
        use crate::measure::hoff::{InsReport, bearing_terms, ins_report, usbl_bearing};
        use crate::measure::{Robust, Usbl};
        use nalgebra::Vector3;
        use std::hint::black_box;
        let n = 203;
        let col = |f: &dyn Fn(f32) -> f32| (0..n).map(|i| f(i as f32)).collect::<Vec<f32>>();
        let state: [Vec<f32>; DIM] = [
            col(&|t| 40.0 * (t * 0.37).sin()),
            col(&|t| 30.0 * (t * 0.71).cos()),
            col(&|t| 2.0 * (t * 0.13).sin()),
            col(&|t| 0.3 * (t * 0.23).sin()),
            col(&|t| 3.1 * (t * 0.51).sin()),
            col(&|t| 0.5 * (t * 0.29).cos()),
            col(&|t| 0.01 * (t * 0.17).sin()),
            col(&|t| 0.01 * (t * 0.19).cos()),
        ];
        let noise = col(&|t| (t * 1.618).sin() * 2.0);
        let noise: Vec<f32> = (0..DIM).flat_map(|k| noise.iter().map(move |e| e * (k as f32 + 1.0) * 0.3)).collect();
        let origin = [1000.0, -200.0, 30.0, 0.05, 0.0, 1.5, 0.0, 0.002];
        let step = HoffProcess::default().step(&origin, 4.0);
        let usbl = Usbl {
            floor_rad: 0.002,
            position_sigma_m: 1.0,
            heading_sigma_rad: 0.01,
            ..Usbl::exact(Vector3::new(990.0, -180.0, 0.5), 0.7, 0.0004)
        };
        let bearing = |robust| UsblBearing { usbl, azimuth_rad: 2.9, elevation_rad: 0.8, robust };
        let mut origin9 = origin.to_vec();
        origin9.push(0.01);
        let misalignment = col(&|t| 0.02 * (t * 0.41).sin());
        let ins = InsReport {
            heading_rad: 3.0,
            speed_m_s: 1.4,
            depth_m: 31.0,
            sigma_heading_rad: 0.1,
            sigma_speed_m_s: 0.2,
            sigma_depth_m: 0.3,
        };
        let ins_terms = ins.terms(&origin);
        let bits = |v: &[f32]| v.iter().map(|x| x.to_bits()).collect::<Vec<u32>>();
        for level in Level::available() {
            // eq. 4's step
            let mut x = state.clone();
            let [a, b, c, d, e, f, g, h] = &mut x;
            hoff_step::at(level, &mut [a, b, c, d, e, f, g, h], &noise, &step);
            for i in 0..n {
                let mut one: [Vec<f32>; DIM] = std::array::from_fn(|k| vec![state[k][i]]);
                let e: Vec<f32> = (0..DIM).map(|k| noise[k * n + i]).collect();
                let [a, b, c, d, f, g, h, j] = &mut one;
                hoff_step::at(Level::Baseline, black_box(&mut [a, b, c, d, f, g, h, j]), black_box(&e), &step);
                for k in 0..DIM {
                    assert_eq!(x[k][i].to_bits(), one[k][0].to_bits(), "{level:?} step {k} {i}");
                }
            }
            // eq. 8 and eq. 6-7
            let mut w = vec![0.5f32; n];
            ins_report::at(level, &state[idx::PSI], &state[idx::U], &state[idx::Z], ins_terms, &mut w);
            let cases = [
                (bearing(None), &[][..], &origin[..]),
                (bearing(Some(Robust::Huber { k: 1.345 })), &[][..], &origin[..]),
                (bearing(None), &misalignment[..], &origin9[..]),
            ];
            let mut got = Vec::new();
            for (b, mis, o) in cases {
                let mut w = vec![0.25f32; n];
                let t = bearing_terms(&b, o);
                for start in (0..n).step_by(BLOCK) {
                    let r = start..(start + BLOCK).min(n);
                    let m = if mis.is_empty() { mis } else { &mis[r.clone()] };
                    usbl_bearing::at(
                        level,
                        &state[0][r.clone()],
                        &state[1][r.clone()],
                        &state[2][r.clone()],
                        m,
                        &t,
                        &mut w[r],
                    );
                }
                for i in 0..n {
                    let mut one = [0.25f32];
                    let m = if mis.is_empty() { mis } else { &mis[i..i + 1] };
                    let p = |k: usize| black_box(&state[k][i..i + 1]);
                    usbl_bearing::at(Level::Baseline, p(0), p(1), p(2), m, &t, &mut one);
                    assert_eq!(w[i].to_bits(), one[0].to_bits(), "{level:?} bearing {i}");
                }
                got.push(bits(&w));
            }
            for i in 0..n {
                let mut one = [0.5f32];
                let p = |k: usize| black_box(&state[k][i..i + 1]);
                ins_report::at(Level::Baseline, p(idx::PSI), p(idx::U), p(idx::Z), ins_terms, &mut one);
                assert_eq!(w[i].to_bits(), one[0].to_bits(), "{level:?} report {i}");
            }
            assert_ne!(got[0], got[1], "the robust form weighs differently");
            assert_ne!(got[0], got[2], "the misalignment counts");
        }
    }

    /// The Gaussian form's Jacobian against finite differences, and its mean step
    /// against the particles' noise-free step.
    #[test]
    fn gaussian_form_jacobian_and_mean() {
        let m = HoffProcess::default();
        for x in [[1.0, 2.0, 30.0, 0.1, 0.5, 2.0, 0.001, 0.01], [-5.0, 7.0, 12.0, -0.4, -2.9, 0.3, -0.002, 0.0]] {
            let x = SVector::<f64, DIM>::from(x);
            let f = ProcessModel::jacobian(&m, &x, 4.0);
            for j in 0..DIM {
                let eps = 1e-6;
                let (mut xp, mut xm) = (x, x);
                xp[j] += eps;
                xm[j] -= eps;
                let col = (ProcessModel::propagate(&m, &xp, 4.0) - ProcessModel::propagate(&m, &xm, 4.0)) / (2.0 * eps);
                for i in 0..DIM {
                    assert!((f[(i, j)] - col[i]).abs() < 1e-7, "({i}, {j}): {} against {}", f[(i, j)], col[i]);
                }
            }
            let still = HoffProcess { sigma: [0.0; DIM], ..m };
            let mut pf = ParticleFilter::<DIM>::gaussian(1, &x, &SVector::zeros(), ParticleSettings::default(), 1);
            pf.predict(&still, 4.0);
            let (mean, _) = pf.mean_covariance();
            let n = ProcessModel::propagate(&m, &x, 4.0);
            // the state's offset from its origin (under 2^-11, the origin's grid's half)
            // held in single precision (2^-35), twice, and single precision in the step
            // (its sines, filter::lanes): 1e-6 of it
            for i in 0..DIM {
                assert!((mean[i] - n[i]).abs() < 2f64.powi(-34) + 1e-6 * (n[i] - x[i]).abs(), "{i}");
            }
        }
        let q = ProcessModel::noise_covariance(&m, &SVector::zeros(), 4.0);
        assert!((q[(0, 0)] - 0.16 * 16.0).abs() < 1e-12);
    }
}
