//! What the vehicle's sensors and modem report: the truth plus errors, drawn from the
//! run's seeded random streams (garin2024 sections 3.5, 4.1.1). Each white-noise error
//! is drawn from the measurement model the filters use ([`ScalarModel::noise`]), built
//! with the world's noise.

use crate::seed::{Stream, gauss, rng};
use crate::vehicles::TruthState;
use nalgebra::Vector2;
use onebeacon::geo::wrap_angle;
use onebeacon::measure::{RadialSpeed2d, Range2d, ScalarModel, StateComponent};
use onebeacon::models::unicycle::{State, idx};
use onebeacon::nav::{BeaconFix, Kind};
use rand::RngExt;
use rand_pcg::Pcg64Mcg;
use serde::{Deserialize, Serialize};

/// The truth in the unicycle state layout [x, y, psi, v, Omega, a] the models read (the
/// commanded rates do not enter any measurement model's noise).
fn state(truth: &TruthState) -> State {
    State::from([truth.pos.x, truth.pos.y, truth.psi, truth.v, 0.0, 0.0])
}

/// Sensor errors of the simulated vehicle (standard deviations).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct Sensors {
    /// OWTT range noise, m.
    pub range_noise_m: f64,
    /// Doppler radial speed noise, m/s.
    pub doppler_noise_m_s: f64,
    /// AHRS heading white noise, deg.
    pub heading_noise_deg: f64,
    /// Standard deviation of the heading bias at the start, deg.
    pub heading_bias_deg: f64,
    /// Standard deviation of the heading bias drift rate, deg/h (constant in a run).
    pub heading_bias_drift_deg_per_h: f64,
    /// Gyro (yaw rate) white noise, rad/s.
    pub gyro_noise_rad_s: f64,
    /// Accelerometer (forward) white noise, m/s^2.
    pub accel_noise_m_s2: f64,
}

impl Default for Sensors {
    fn default() -> Self {
        Self {
            range_noise_m: 3.464,
            doppler_noise_m_s: 0.447,
            heading_noise_deg: 2.0,
            heading_bias_deg: 0.0,
            heading_bias_drift_deg_per_h: 5.0,
            gyro_noise_rad_s: 0.05,
            accel_noise_m_s2: 0.05,
        }
    }
}

impl Sensors {
    /// All errors zero: a noise-free world.
    pub fn noise_free() -> Self {
        Self {
            range_noise_m: 0.0,
            doppler_noise_m_s: 0.0,
            heading_noise_deg: 0.0,
            heading_bias_deg: 0.0,
            heading_bias_drift_deg_per_h: 0.0,
            gyro_noise_rad_s: 0.0,
            accel_noise_m_s2: 0.0,
        }
    }
}

/// The sensor suite of one run.
pub struct SensorSuite {
    noise: Sensors,
    frame_loss_prob: f64,
    imu: Pcg64Mcg,
    heading: Pcg64Mcg,
    acoustic: Pcg64Mcg,
    bias0_rad: f64,
    bias_rate_rad_s: f64,
    /// The AHRS heading, gyro and accelerometer models with the world's noise.
    inertial: [StateComponent; 3],
}

impl SensorSuite {
    pub fn new(noise: &Sensors, frame_loss_prob: f64, seed: u64, run: u64) -> Self {
        let mut heading = rng(seed, run, Stream::Heading);
        let bias0_rad = gauss(&mut heading, noise.heading_bias_deg.to_radians());
        let bias_rate_rad_s = gauss(&mut heading, noise.heading_bias_drift_deg_per_h.to_radians() / 3600.0);
        Self {
            noise: noise.clone(),
            frame_loss_prob,
            imu: rng(seed, run, Stream::Imu),
            heading,
            acoustic: rng(seed, run, Stream::Acoustic),
            bias0_rad,
            bias_rate_rad_s,
            inertial: [
                StateComponent::angle(idx::PSI, noise.heading_noise_deg.to_radians().powi(2)),
                StateComponent::value(idx::OMEGA, noise.gyro_noise_rad_s.powi(2)),
                StateComponent::value(idx::ACCEL, noise.accel_noise_m_s2.powi(2)),
            ],
        }
    }

    /// AHRS heading with white noise and a linearly drifting bias (3.5.3), and IMU yaw
    /// rate and forward acceleration with white noise (4.1.1), at time `t`, given the
    /// commanded (true) yaw rate and acceleration.
    pub fn proprioceptive(&mut self, t: f64, truth: &TruthState, omega: f64, accel: f64) -> Kind {
        let x = state(truth);
        let bias = self.bias0_rad + self.bias_rate_rad_s * t;
        let [heading, gyro, accelerometer] = &self.inertial;
        let heading_noise = heading.noise(&x, &mut self.heading);
        Kind::Inertial {
            heading_rad: wrap_angle(truth.psi + bias + heading_noise),
            yaw_rate_rad_s: omega + gyro.noise(&x, &mut self.imu),
            accel_m_s2: accel + accelerometer.noise(&x, &mut self.imu),
        }
    }

    /// A communication frame from `beacon` (None if lost): OWTT range (eq. 19) and
    /// Doppler radial speed (eq. 13-14), each with white noise; the range also carries
    /// `clock_m`, what the two ends' clocks add to it.
    pub fn comm_frame(&mut self, truth: &TruthState, beacon: Vector2<f64>, clock_m: f64) -> Option<Kind> {
        // always draw all three numbers so that a loss does not shift later draws
        let lost = self.acoustic.random::<f64>() < self.frame_loss_prob;
        let (n, x) = (&self.noise, state(truth));
        let range_noise = Range2d { beacon, var: n.range_noise_m.powi(2) }.noise(&x, &mut self.acoustic);
        let doppler = RadialSpeed2d { beacon, known_speed_m_s: None, dz_m: 0.0, var: n.doppler_noise_m_s.powi(2) };
        let doppler_noise = doppler.noise(&x, &mut self.acoustic);
        if lost {
            return None;
        }
        let d = truth.pos - beacon;
        let bearing_to_beacon = d.y.atan2(d.x) + std::f64::consts::PI; // eq. 14
        Some(Kind::RangeDoppler {
            beacon: BeaconFix::fixed(0, nalgebra::Vector3::new(beacon.x, beacon.y, 0.0)),
            range_m: d.norm() + range_noise + clock_m,
            radial_speed_m_s: truth.v * (bearing_to_beacon - truth.psi).cos() + doppler_noise, // eq. 13
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_abs_diff_eq;

    #[test]
    fn noise_free_measurements_equal_the_truth() {
        let mut s = SensorSuite::new(&Sensors::noise_free(), 0.0, 3, 0);
        let truth = TruthState { pos: Vector2::new(10.0, 0.0), psi: std::f64::consts::PI, v: 1.5 };
        let Some(Kind::RangeDoppler { range_m, radial_speed_m_s, .. }) = s.comm_frame(&truth, Vector2::zeros(), 0.0)
        else {
            panic!("a frame")
        };
        assert_abs_diff_eq!(range_m, 10.0, epsilon = 1e-12);
        assert_abs_diff_eq!(radial_speed_m_s, 1.5, epsilon = 1e-12); // heading at the beacon
        let Kind::Inertial { heading_rad, yaw_rate_rad_s, accel_m_s2 } = s.proprioceptive(100.0, &truth, 0.02, -0.01)
        else {
            panic!("an inertial sample")
        };
        assert_abs_diff_eq!(heading_rad.abs(), std::f64::consts::PI, epsilon = 1e-12);
        assert_eq!((yaw_rate_rad_s, accel_m_s2), (0.02, -0.01));
    }

    #[test]
    fn noise_has_the_configured_spread_and_losses_their_rate() {
        let noise = Sensors { range_noise_m: 2.0, ..Sensors::noise_free() };
        let mut s = SensorSuite::new(&noise, 0.25, 9, 4);
        let truth = TruthState { pos: Vector2::new(30.0, 40.0), psi: 0.0, v: 1.0 };
        let (mut n, mut sum2, mut lost) = (0, 0.0, 0);
        for _ in 0..20_000 {
            match s.comm_frame(&truth, Vector2::zeros(), 0.0) {
                Some(Kind::RangeDoppler { range_m, .. }) => {
                    n += 1;
                    sum2 += (range_m - 50.0).powi(2);
                }
                _ => lost += 1,
            }
        }
        let sigma = (sum2 / n as f64).sqrt();
        assert!((sigma - 2.0).abs() < 0.05, "sigma {sigma}");
        let rate = lost as f64 / 20_000.0;
        assert!((rate - 0.25).abs() < 0.015, "loss rate {rate}");
    }
}
