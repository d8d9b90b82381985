//! hoff2024's particle model of an AUV tracked from a surface vehicle: the stochastic
//! unicycle [x, y, z, theta, psi, u, b_theta, b_psi] (NED position, pitch, heading, surge
//! speed, and the pitch and heading rates as biases decaying with time constant T_b),
//! propagated with truncated Gaussian steps (eq. 4), weighed by the AUV's INS report
//! (eq. 8) and by the USBL bearing (eq. 6-7).

use crate::filter::ProcessModel;
use crate::filter::particle::{ParticleLikelihood, ParticleProcess};
use crate::filter::truncated::truncated_normal;
use crate::geo::{wrap_angle, wrap_near};
use crate::measure::Usbl;
use nalgebra::{SMatrix, SVector, Vector3};
use rand::RngExt;
use rand_pcg::Pcg64;
use std::f64::consts::{FRAC_PI_2, PI, TAU};

/// State dimension.
pub const DIM: usize = 8;

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

impl ParticleProcess for HoffProcess {
    fn propagate(&self, x: &mut [&mut [f64]], dt: f64, rng: &mut Pcg64) {
        let s = self.sigma.map(|v| v * dt);
        let decay = dt / self.t_b_s;
        let inf = f64::INFINITY;
        for i in 0..x[0].len() {
            let (theta, psi, u) = (x[idx::THETA][i], x[idx::PSI][i], x[idx::U][i]);
            let (b_theta, b_psi) = (x[idx::B_THETA][i], x[idx::B_PSI][i]);
            let (st, ct) = theta.sin_cos();
            let (sp, cp) = psi.sin_cos();
            let gauss = |rng: &mut Pcg64, sd: f64| sd * rng.sample::<f64, _>(rand_distr::StandardNormal);
            // eq. 4: the mean step f(x) dt, noise sigma dt, truncated on z, theta and u
            x[idx::X][i] += u * ct * cp * dt + gauss(rng, s[idx::X]);
            x[idx::Y][i] += u * ct * sp * dt + gauss(rng, s[idx::Y]);
            let z = x[idx::Z][i] - u * st * dt;
            x[idx::Z][i] = truncated_normal(rng, z, s[idx::Z], self.z_min_m, inf);
            x[idx::THETA][i] = truncated_normal(rng, theta + b_theta * dt, s[idx::THETA], -FRAC_PI_2, FRAC_PI_2);
            // a step of the heading is far below a turn: one add or subtract wraps it
            let p = psi + b_psi * dt + gauss(rng, s[idx::PSI]);
            x[idx::PSI][i] = if p > PI {
                p - TAU
            } else if p <= -PI {
                p + TAU
            } else {
                p
            };
            x[idx::U][i] = truncated_normal(rng, u, s[idx::U], 0.0, inf);
            x[idx::B_THETA][i] = b_theta * (1.0 - decay) + gauss(rng, s[idx::B_THETA]);
            x[idx::B_PSI][i] = b_psi * (1.0 - decay) + gauss(rng, s[idx::B_PSI]);
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

/// The AUV's INS report (eq. 8): heading, speed and depth with the filter's assumed
/// standard deviations.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct InsReport {
    pub heading_rad: f64,
    pub speed_m_s: f64,
    pub depth_m: f64,
    pub sigma_heading_rad: f64,
    pub sigma_speed_m_s: f64,
    pub sigma_depth_m: f64,
}

impl ParticleLikelihood for InsReport {
    fn add_log_likelihood(&self, x: &[&[f64]], log_w: &mut [f64]) {
        let (kh, ku, kz) = (
            -0.5 / (self.sigma_heading_rad * self.sigma_heading_rad),
            -0.5 / (self.sigma_speed_m_s * self.sigma_speed_m_s),
            -0.5 / (self.sigma_depth_m * self.sigma_depth_m),
        );
        // particles' headings are in (-pi, pi] (after a first step; within 3 pi at the
        // start): a difference from a wrapped heading wraps with one add or subtract
        let heading = wrap_angle(self.heading_rad);
        for (i, lw) in log_w.iter_mut().enumerate() {
            let dh = wrap_near(x[idx::PSI][i] - heading);
            let du = x[idx::U][i] - self.speed_m_s;
            let dz = x[idx::Z][i] - self.depth_m;
            *lw += kh * dh * dh + ku * du * du + kz * dz * dz; // eq. 8
        }
    }
}

/// A USBL bearing (azimuth, elevation) measured by the surface vehicle (eq. 6-7). The
/// noise grows with each particle's range (eq. 3), so the normalising term ln sigma^2
/// differs between particles and is kept.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct UsblBearing {
    pub usbl: Usbl,
    pub azimuth_rad: f64,
    pub elevation_rad: f64,
}

impl ParticleLikelihood for UsblBearing {
    fn add_log_likelihood(&self, x: &[&[f64]], log_w: &mut [f64]) {
        let azimuth = wrap_angle(self.azimuth_rad);
        if self.usbl.position_sigma_m > 0.0 || self.usbl.heading_sigma_rad > 0.0 {
            // the station's pose errors make the two angles' variances differ
            for (i, lw) in log_w.iter_mut().enumerate() {
                let p = Vector3::new(x[idx::X][i], x[idx::Y][i], x[idx::Z][i]);
                let (alpha, phi, _) = self.usbl.angles(&p);
                let (var_a, var_p) = self.usbl.variances(&p);
                let (da, dp) = (wrap_near(azimuth - alpha), self.elevation_rad - phi);
                *lw += -da * da / (2.0 * var_a) - dp * dp / (2.0 * var_p) - 0.5 * (var_a * var_p).ln(); // eq. 6
            }
            return;
        }
        for (i, lw) in log_w.iter_mut().enumerate() {
            let p = Vector3::new(x[idx::X][i], x[idx::Y][i], x[idx::Z][i]);
            let (alpha, phi, sigma) = self.usbl.angles(&p);
            let (da, dp) = (wrap_near(azimuth - alpha), self.elevation_rad - phi);
            let var = (sigma * sigma).max(1e-12);
            *lw += -(da * da + dp * dp) / (2.0 * var) - var.ln(); // eq. 6, two angles
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::filter::particle::{ParticleFilter, ParticleSettings};
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
        assert!((m[idx::X] - u * 0.1f64.cos() * 0.5f64.cos() * dt).abs() < 1e-9);
        assert!((m[idx::Y] - u * 0.1f64.cos() * 0.5f64.sin() * dt).abs() < 1e-9);
        assert!((m[idx::Z] - (30.0 - u * 0.1f64.sin() * dt)).abs() < 1e-9);
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
            for i in 0..DIM {
                assert!((mean[i] - n[i]).abs() < 1e-12, "{i}");
            }
        }
        let q = ProcessModel::noise_covariance(&m, &SVector::zeros(), 4.0);
        assert!((q[(0, 0)] - 0.16 * 16.0).abs() < 1e-12);
    }
}
