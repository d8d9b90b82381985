//! Single fixed beacon navigation with an EKF (garin2024 sections 3.3-3.6).
//!
//! Every time step the vehicle predicts with the unicycle model (eq. 7) and updates with
//! its proprioceptive sensors: heading, yaw rate, acceleration (eq. 18 right, 24). When a
//! communication frame from the beacon is decoded it adds the one-way travel-time range
//! (eq. 19) and, for [`Aiding::RangeDoppler`], the Doppler radial speed (eq. 13-15, 20),
//! stacked into one update (eq. 18 left, 22). [`Aiding::RangeOnly`] is the ROSB baseline:
//! the same filter without the Doppler speed.

use crate::filter::{Ekf, FilterError};
use crate::measure::{RadialSpeed2d, Range2d, ScalarModel, StateComponent};
use crate::models::unicycle::{Cov, DIM, State, UnicycleAccel, idx};
use nalgebra::{Matrix2, SMatrix, SVector, Vector2};

/// Which beacon measurements the filter uses.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Aiding {
    /// Range and Doppler radial speed (garin2024's proposed filter).
    RangeDoppler,
    /// Range only (ROSB, the state-of-the-art baseline of garin2024 Table 4).
    RangeOnly,
}

/// Process and measurement noise of the filter. [`Default`] is garin2024 eq. 25.
///
/// The paper gives R = diag(1, 0.005, 0.005, 12, 0.2) without naming the order. It is
/// read here in the row order of the observation matrices of eq. 22 and 24, (psi,
/// Omega, a, d, v_r): heading 1 rad^2 (the magnetic heading is "subject to strong
/// errors", 3.5.3), yaw rate 0.005 (rad/s)^2 and acceleration 0.005 (m/s^2)^2 (the IMU
/// noise "within +-0.1" of 4.1.1), range 12 m^2, Doppler speed 0.2 (m/s)^2. Read in the
/// order of eq. 18 instead, the gyro would get 12 (rad/s)^2, and in simulation the
/// range-only filter then diverges in most runs, unlike the paper's Table 4.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EkfTuning {
    /// Diagonal of Q, per step, in state order [x, y, psi, v, Omega, a].
    pub q_diag: [f64; DIM],
    /// Range variance (m^2).
    pub r_range_m2: f64,
    /// Doppler radial speed variance ((m/s)^2).
    pub r_doppler_m2_s2: f64,
    /// Heading variance (rad^2).
    pub r_heading_rad2: f64,
    /// Yaw rate variance ((rad/s)^2).
    pub r_yaw_rate_rad2_s2: f64,
    /// Acceleration variance ((m/s^2)^2).
    pub r_accel_m2_s4: f64,
}

impl Default for EkfTuning {
    fn default() -> Self {
        let q = 0.25_f64.powi(8); // eq. 25: Q = diag(dt^8) with dt = 0.25 s
        Self {
            q_diag: [q; DIM],
            // eq. 25: R = diag(1, 0.005, 0.005, 12, 0.2) in the order (psi, Omega, a, d, v_r)
            r_heading_rad2: 1.0,
            r_yaw_rate_rad2_s2: 0.005,
            r_accel_m2_s4: 0.005,
            r_range_m2: 12.0,
            r_doppler_m2_s2: 0.2,
        }
    }
}

/// Proprioceptive sample of one time step: AHRS heading and IMU rate and acceleration.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Proprioceptive {
    pub heading_rad: f64,
    pub yaw_rate_rad_s: f64,
    pub accel_m_s2: f64,
}

/// What a decoded communication frame gives: the beacon's position (it travels with the
/// frame), the one-way travel-time range and the Doppler radial speed (positive closing).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CommFrame {
    pub beacon_ned_m: Vector2<f64>,
    pub range_m: f64,
    pub radial_speed_m_s: f64,
}

/// The single-beacon EKF of garin2024 (or its range-only ROSB variant).
#[derive(Debug, Clone)]
pub struct SingleBeaconEkf {
    aiding: Aiding,
    tuning: EkfTuning,
    q: Cov,
    ekf: Ekf<DIM>,
}

const HEADING: StateComponent = StateComponent::angle(idx::PSI);
const YAW_RATE: StateComponent = StateComponent::value(idx::OMEGA);
const ACCEL: StateComponent = StateComponent::value(idx::ACCEL);

impl SingleBeaconEkf {
    /// A filter starting at state `z0` = [x, y, psi, v, Omega, a] with covariance `p0`.
    pub fn new(aiding: Aiding, tuning: EkfTuning, z0: State, p0: Cov) -> Self {
        Self { aiding, q: Cov::from_diagonal(&SVector::from(tuning.q_diag)), tuning, ekf: Ekf::new(z0, p0) }
    }

    pub fn aiding(&self) -> Aiding {
        self.aiding
    }

    /// One time step of `dt` seconds: predict, then update with the proprioceptive
    /// sample and, if one was decoded during the step, the communication frame.
    /// Returns the NIS of the update.
    pub fn step(&mut self, dt: f64, sample: &Proprioceptive, frame: Option<&CommFrame>) -> Result<f64, FilterError> {
        self.ekf.predict(&UnicycleAccel, dt, &self.q);
        let t = &self.tuning;
        let proprio = [sample.heading_rad, sample.yaw_rate_rad_s, sample.accel_m_s2];
        let proprio_r = [t.r_heading_rad2, t.r_yaw_rate_rad2_s2, t.r_accel_m2_s4];
        match (frame, self.aiding) {
            (None, _) => self.update([&HEADING, &YAW_RATE, &ACCEL], proprio, proprio_r),
            (Some(f), Aiding::RangeOnly) => {
                let range = Range2d { beacon: f.beacon_ned_m };
                self.update(
                    [&range, &HEADING, &YAW_RATE, &ACCEL],
                    [f.range_m, proprio[0], proprio[1], proprio[2]],
                    [t.r_range_m2, proprio_r[0], proprio_r[1], proprio_r[2]],
                )
            }
            (Some(f), Aiding::RangeDoppler) => {
                let range = Range2d { beacon: f.beacon_ned_m };
                let doppler = RadialSpeed2d { beacon: f.beacon_ned_m, known_speed_m_s: None };
                self.update(
                    [&range, &doppler, &HEADING, &YAW_RATE, &ACCEL], // eq. 18, 20
                    [f.range_m, f.radial_speed_m_s, proprio[0], proprio[1], proprio[2]],
                    [t.r_range_m2, t.r_doppler_m2_s2, proprio_r[0], proprio_r[1], proprio_r[2]],
                )
            }
        }
    }

    fn update<const M: usize>(
        &mut self,
        models: [&dyn ScalarModel<DIM>; M],
        z: [f64; M],
        r_diag: [f64; M],
    ) -> Result<f64, FilterError> {
        let r = SMatrix::<f64, M, M>::from_diagonal(&SVector::from(r_diag));
        self.ekf.update(&models, &SVector::from(z), &r)
    }

    /// The state estimate [x, y, psi, v, Omega, a].
    pub fn state(&self) -> &State {
        &self.ekf.x
    }

    /// The state covariance.
    pub fn covariance(&self) -> &Cov {
        &self.ekf.p
    }

    /// Estimated horizontal position (north, east), m.
    pub fn position(&self) -> Vector2<f64> {
        Vector2::new(self.ekf.x[idx::X], self.ekf.x[idx::Y])
    }

    /// Covariance of the horizontal position.
    pub fn position_covariance(&self) -> Matrix2<f64> {
        self.ekf.p.fixed_view::<2, 2>(0, 0).into_owned()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::filter::ProcessModel;
    use approx::assert_abs_diff_eq;
    use std::f64::consts::FRAC_PI_2;

    /// A vehicle heading east at 1 m/s from a wrong start position is pulled onto the
    /// truth by ranges and Doppler speeds from a beacon, faster than by ranges alone.
    #[test]
    fn range_doppler_corrects_a_speed_error_that_range_only_keeps_longer() {
        let beacon = Vector2::new(40.0, 0.0);
        let dt = 0.25;
        let tuning = EkfTuning {
            q_diag: [1e-4, 1e-4, 1e-6, 1e-4, 1e-6, 1e-6],
            r_range_m2: 1.0,
            r_doppler_m2_s2: 0.005,
            r_heading_rad2: 1e-3,
            r_yaw_rate_rad2_s2: 1e-3,
            r_accel_m2_s4: 1e-3,
        };
        let truth0 = State::from([0.0, 0.0, FRAC_PI_2, 1.0, 0.0, 0.0]);
        let mut start = truth0;
        start[idx::V] = 0.7; // 30 % speed error
        let p0 = Cov::from_diagonal(&SVector::from([1.0, 1.0, 1e-3, 0.1, 1e-4, 1e-4]));
        let mut filters = [
            SingleBeaconEkf::new(Aiding::RangeDoppler, tuning, start, p0),
            SingleBeaconEkf::new(Aiding::RangeOnly, tuning, start, p0),
        ];
        let mut truth = truth0;
        let mut speed_err = [0.0; 2];
        for k in 1..=120 {
            truth = UnicycleAccel.propagate(&truth, dt);
            let sample = Proprioceptive { heading_rad: FRAC_PI_2, yaw_rate_rad_s: 0.0, accel_m_s2: 0.0 };
            let frame = (k % 12 == 0).then(|| CommFrame {
                beacon_ned_m: beacon,
                range_m: Range2d { beacon }.predict(&truth),
                radial_speed_m_s: RadialSpeed2d { beacon, known_speed_m_s: None }.predict(&truth),
            });
            for (f, e) in filters.iter_mut().zip(speed_err.iter_mut()) {
                f.step(dt, &sample, frame.as_ref()).unwrap();
                *e = (f.state()[idx::V] - 1.0).abs();
            }
        }
        assert!(speed_err[0] < 0.01, "range+doppler speed error {}", speed_err[0]);
        assert!(speed_err[0] < speed_err[1]);
        assert_abs_diff_eq!(filters[0].position(), Vector2::new(truth[0], truth[1]), epsilon = 0.5);
    }
}
