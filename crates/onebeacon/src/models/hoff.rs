//! hoff2024's particle model of an AUV tracked from a surface vehicle: the stochastic
//! unicycle [x, y, z, theta, psi, u, b_theta, b_psi] (NED position, pitch, heading, surge
//! speed, and the pitch and heading rates as biases decaying with time constant T_b),
//! propagated with truncated Gaussian steps (eq. 4); the AUV's INS report (eq. 8) and
//! the USBL bearing (eq. 6-7) that weigh it are [`crate::measure::hoff`].

use crate::filter::ProcessModel;
use crate::filter::lanes;
use crate::filter::particle::ParticleProcess;
use crate::filter::truncated::truncated_normal;
use crate::geo::wrap_angle;
use nalgebra::{SMatrix, SVector};
use rand_pcg::Pcg64;
use std::f64::consts::{FRAC_PI_2, PI, TAU};

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
    /// Block by block: the block's normal draws and its sines and cosines first, eight
    /// lanes at a time ([`crate::filter::lanes`]), then eq. 4's step. A truncated
    /// component takes the plain draw when it falls within its bounds and otherwise a
    /// draw of the truncated law (rejection's first try, then an exact draw: the result
    /// follows the truncated law).
    fn propagate(&self, x: &mut [&mut [f64]], dt: f64, rng: &mut Pcg64) {
        let s = self.sigma.map(|v| v * dt);
        let keep = 1.0 - dt / self.t_b_s;
        let [px, py, pz, pt, pp, pu, pbt, pbp] = x else { panic!("hoff2024's state has {DIM} components") };
        let n = px.len();
        let mut noise = [0.0; DIM * BLOCK];
        let (mut st, mut ct, mut sp, mut cp) = ([0.0; BLOCK], [0.0; BLOCK], [0.0; BLOCK], [0.0; BLOCK]);
        for start in (0..n).step_by(BLOCK) {
            let m = BLOCK.min(n - start);
            let r = start..start + m;
            let (x, y, z, theta, psi) =
                (&mut px[r.clone()], &mut py[r.clone()], &mut pz[r.clone()], &mut pt[r.clone()], &mut pp[r.clone()]);
            let (u, b_theta, b_psi) = (&mut pu[r.clone()], &mut pbt[r.clone()], &mut pbp[r]);
            lanes::standard_normals(rng, &mut noise[..DIM * m]);
            let (st, ct, sp, cp) = (&mut st[..m], &mut ct[..m], &mut sp[..m], &mut cp[..m]);
            lanes::sin_cos(theta, st, ct);
            lanes::sin_cos(psi, sp, cp);
            let e: [&[f64]; DIM] = std::array::from_fn(|k| &noise[k * m..(k + 1) * m]);
            // eq. 4: the mean step f(x) dt, noise sigma dt, truncated on z, theta and u
            for j in 0..m {
                x[j] += u[j] * ct[j] * cp[j] * dt + s[idx::X] * e[idx::X][j];
                y[j] += u[j] * ct[j] * sp[j] * dt + s[idx::Y] * e[idx::Y][j];
                z[j] += -u[j] * st[j] * dt + s[idx::Z] * e[idx::Z][j];
                theta[j] += b_theta[j] * dt + s[idx::THETA] * e[idx::THETA][j];
                // a step of the heading is far below a turn: one add or subtract wraps it
                let p = psi[j] + b_psi[j] * dt + s[idx::PSI] * e[idx::PSI][j];
                psi[j] = if p > PI {
                    p - TAU
                } else if p <= -PI {
                    p + TAU
                } else {
                    p
                };
                u[j] += s[idx::U] * e[idx::U][j];
                b_theta[j] = b_theta[j] * keep + s[idx::B_THETA] * e[idx::B_THETA][j];
                b_psi[j] = b_psi[j] * keep + s[idx::B_PSI] * e[idx::B_PSI][j];
            }
            // the truncations (eq. 4), rarely needed: drawn again from the step's mean
            for j in 0..m {
                if z[j] < self.z_min_m {
                    let mean = z[j] - s[idx::Z] * e[idx::Z][j];
                    z[j] = truncated_normal(rng, mean, s[idx::Z], self.z_min_m, f64::INFINITY);
                }
                if theta[j].abs() > FRAC_PI_2 {
                    let mean = theta[j] - s[idx::THETA] * e[idx::THETA][j];
                    theta[j] = truncated_normal(rng, mean, s[idx::THETA], -FRAC_PI_2, FRAC_PI_2);
                }
                if u[j] < 0.0 {
                    let mean = u[j] - s[idx::U] * e[idx::U][j];
                    u[j] = truncated_normal(rng, mean, s[idx::U], 0.0, f64::INFINITY);
                }
            }
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
    fn propagate(&self, x: &mut [&mut [f64]], dt: f64, rng: &mut Pcg64) {
        ParticleProcess::propagate(&self.process, &mut x[..DIM], dt, rng);
        let [misalignment] = &mut x[DIM..] else { panic!("the misaligned state has {DIM_MISALIGNED} components") };
        let s = self.walk_rad_per_sqrt_s * dt.sqrt();
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
        assert!((m[idx::PSI] - (0.5 + 0.01 * dt)).abs() < 1e-12);
        assert!((m[idx::B_PSI] - 0.01 * (1.0 - dt / 1000.0)).abs() < 1e-12);

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
        let comps: Vec<Vec<f64>> =
            (0..DIM).map(|k| pts.iter().map(|p| if k < 3 { p[k] } else { 0.0 }).collect()).collect();
        let view: Vec<&[f64]> = comps.iter().map(|c| &c[..]).collect();
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
            bearing.add_log_likelihood(&view, &mut got);
            for (i, p) in pts.iter().enumerate() {
                let p = Vector3::new(p[0], p[1], p[2]);
                let (alpha, phi, _) = usbl.angles(&p);
                let (var_a, var_e) = usbl.variances(&p);
                let (var_a, var_e) = if gps == 0.0 { (var_a.max(1e-12), var_e.max(1e-12)) } else { (var_a, var_e) };
                let (da, de) = (wrap_angle(0.2 - alpha), 0.9 - phi);
                let expected = -da * da / (2.0 * var_a) - de * de / (2.0 * var_e) - 0.5 * (var_a * var_e).ln(); // eq. 6
                assert!(
                    (got[i] - expected).abs() < 1e-4 * expected.abs().max(1.0),
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
        let comps: Vec<Vec<f64>> =
            (0..DIM).map(|k| pts.iter().map(|p| if k < 3 { p[k] } else { 0.0 }).collect()).collect();
        let view: Vec<&[f64]> = comps.iter().map(|c| &c[..]).collect();
        for (robust, expected) in [
            (None, 150.0),
            (Some(Robust::Huber { k: 1.345 }), 13.45),
            (Some(Robust::StudentT { dof: 4.0 }), 2.5 * (101.0f64 / 26.0).ln()),
        ] {
            let mut w = vec![0.0; 2];
            UsblBearing { usbl, azimuth_rad: 0.0, elevation_rad: 0.9, robust }.add_log_likelihood(&view, &mut w);
            assert!(((w[0] - w[1]) / expected - 1.0).abs() < 1e-3, "{robust:?}: {} against {expected}", w[0] - w[1]);
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
            // single-precision sines in the particles' step (filter::lanes)
            for i in 0..DIM {
                assert!((mean[i] - n[i]).abs() < 1e-12 + 1e-6 * (n[i] - x[i]).abs(), "{i}");
            }
        }
        let q = ProcessModel::noise_covariance(&m, &SVector::zeros(), 4.0);
        assert!((q[(0, 0)] - 0.16 * 16.0).abs() < 1e-12);
    }
}
