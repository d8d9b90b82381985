//! A SandShark-like miniature AUV (rypkema sec. 3.1.3), kinematic: heading, speed and
//! depth follow the autonomy's setpoint through rate limits and first-order lags; with
//! the propeller off it coasts to a stop and, slightly positively buoyant, floats up.
//! Its sensors as the paper describes them: an AHRS whose heading error is about 3 deg
//! (1 sigma) and not zero-mean (a slowly varying error here), speed over ground from
//! the propeller's RPM (eq. 1, with a scale error), a pressure sensor.

use crate::seed::gauss;
use nalgebra::{Matrix3, Vector3};
use onebeacon::geo::wrap_angle;
use onebeacon::vehicle::Setpoint;
use serde::{Deserialize, Serialize};

/// The vehicle's response and its sensors' errors (`[sandshark]` of a fleet scenario).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct SandSharkParams {
    /// Largest turn rate, deg/s, and the heading loop's gain, 1/s.
    pub max_turn_rate_deg_s: f64,
    pub heading_gain_per_s: f64,
    /// Time constant of the speed with the propeller on, and of the coast with it off, s.
    pub speed_time_constant_s: f64,
    pub coast_time_constant_s: f64,
    /// Largest depth rate under way, m/s, and the depth loop's gain, 1/s.
    pub max_depth_rate_m_s: f64,
    pub depth_gain_per_s: f64,
    /// Rise rate with the propeller off (slight positive buoyancy), m/s.
    pub rise_rate_m_s: f64,
    /// AHRS heading error: a first-order Gauss-Markov process of this stationary
    /// standard deviation and correlation time, plus white noise.
    pub heading_error_deg: f64,
    pub heading_error_time_s: f64,
    pub heading_white_deg: f64,
    /// Roll and pitch white noise, deg.
    pub attitude_white_deg: f64,
    /// RPM-to-speed scale error (one draw per vehicle and run, 1 sigma, fraction) and
    /// white noise of the speed, m/s.
    pub speed_scale_sigma: f64,
    pub speed_white_m_s: f64,
    /// Pressure-sensor depth noise, m.
    pub depth_white_m: f64,
}

impl Default for SandSharkParams {
    fn default() -> Self {
        Self {
            max_turn_rate_deg_s: 12.0,
            heading_gain_per_s: 0.8,
            speed_time_constant_s: 2.0,
            coast_time_constant_s: 4.0,
            max_depth_rate_m_s: 0.3,
            depth_gain_per_s: 0.5,
            rise_rate_m_s: 0.03,
            heading_error_deg: 3.0,
            heading_error_time_s: 600.0,
            heading_white_deg: 0.5,
            attitude_white_deg: 0.5,
            speed_scale_sigma: 0.03,
            speed_white_m_s: 0.03,
            depth_white_m: 0.03,
        }
    }
}

/// The truth of one vehicle.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SandShark {
    /// NED position, m.
    pub position_ned_m: Vector3<f64>,
    /// Heading (rad, not wrapped), speed through the water along the body (m/s), pitch
    /// (rad, nose up).
    pub heading_rad: f64,
    pub speed_m_s: f64,
    pub pitch_rad: f64,
    /// Whether the propeller turns.
    pub thrusting: bool,
}

impl SandShark {
    pub fn new(position_ned_m: Vector3<f64>, heading_rad: f64) -> Self {
        Self { position_ned_m, heading_rad, speed_m_s: 0.0, pitch_rad: 0.0, thrusting: false }
    }

    /// One step of `dt` s toward `sp`.
    pub fn step(&mut self, p: &SandSharkParams, sp: &Setpoint, dt: f64) {
        self.thrusting = sp.speed_m_s > 0.0;
        let depth = self.position_ned_m.z;
        // under way the vehicle climbs and dives along its axis (pitched); coasting it
        // floats up level, by its buoyancy
        let (depth_rate, pitch) = if self.thrusting {
            let turn = (p.heading_gain_per_s * wrap_angle(sp.heading_rad - self.heading_rad))
                .clamp(-p.max_turn_rate_deg_s.to_radians(), p.max_turn_rate_deg_s.to_radians());
            self.heading_rad += turn * dt;
            self.speed_m_s += (sp.speed_m_s - self.speed_m_s) * (dt / p.speed_time_constant_s).min(1.0);
            // the fins need way on: the depth rate is limited by the speed too
            let most = p.max_depth_rate_m_s.min(self.speed_m_s * 0.35);
            let rate = (p.depth_gain_per_s * (sp.depth_m - depth)).clamp(-most, most);
            let pitch = if self.speed_m_s > 0.0 { (-rate / self.speed_m_s).asin() } else { 0.0 };
            (rate, pitch)
        } else {
            self.speed_m_s -= self.speed_m_s * (dt / p.coast_time_constant_s).min(1.0);
            (-p.rise_rate_m_s, 0.0)
        };
        self.position_ned_m.z = (depth + depth_rate * dt).max(0.0);
        self.pitch_rad = if self.position_ned_m.z > 0.0 { pitch } else { 0.0 };
        let (s, c) = self.heading_rad.sin_cos();
        self.position_ned_m += Vector3::new(c, s, 0.0) * (self.speed_m_s * self.pitch_rad.cos() * dt);
    }

    /// Body-to-NED rotation (level in roll).
    pub fn attitude(&self) -> Matrix3<f64> {
        onebeacon::models::kinematic6dof::rotation(0.0, self.pitch_rad, self.heading_rad)
    }

    /// Speed over ground (horizontal), m/s: the speed along the body times the cosine
    /// of the pitch (rypkema eq. 1).
    pub fn speed_over_ground(&self) -> f64 {
        self.speed_m_s * self.pitch_rad.cos()
    }
}

/// The slowly varying errors of one vehicle's sensors.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SensorErrors {
    /// The AHRS heading error now, rad.
    pub heading_rad: f64,
    /// The RPM-to-speed scale error, fraction.
    pub speed_scale: f64,
}

impl SensorErrors {
    pub fn draw<R: rand::Rng>(p: &SandSharkParams, rng: &mut R) -> Self {
        Self { heading_rad: gauss(rng, p.heading_error_deg.to_radians()), speed_scale: gauss(rng, p.speed_scale_sigma) }
    }

    /// The heading error's Gauss-Markov step over `dt`.
    pub fn advance<R: rand::Rng>(&mut self, p: &SandSharkParams, dt: f64, rng: &mut R) {
        let a = (-dt / p.heading_error_time_s).exp();
        self.heading_rad = a * self.heading_rad + gauss(rng, p.heading_error_deg.to_radians() * (1.0 - a * a).sqrt());
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Propeller off: the vehicle rises at the rise rate and coasts down as
    /// exp(-t / tau); on: it reaches the setpoint's speed and depth.
    #[test]
    fn drift_and_drive() {
        let p = SandSharkParams::default();
        let mut v = SandShark::new(Vector3::new(0.0, 0.0, 2.5), 0.0);
        v.speed_m_s = 1.0;
        let stop = Setpoint { heading_rad: 0.0, speed_m_s: 0.0, depth_m: 0.0 };
        for _ in 0..200 {
            v.step(&p, &stop, 0.1);
        }
        assert!((v.position_ned_m.z - (2.5 - 20.0 * p.rise_rate_m_s)).abs() < 1e-9);
        let expected = (1.0f64 - 0.1 / p.coast_time_constant_s).powi(200);
        assert!((v.speed_m_s - expected).abs() < 1e-12);
        let go = Setpoint { heading_rad: 1.0, speed_m_s: 1.0, depth_m: 2.5 };
        for _ in 0..600 {
            v.step(&p, &go, 0.1);
        }
        assert!((v.speed_m_s - 1.0).abs() < 1e-3 && (v.position_ned_m.z - 2.5).abs() < 0.01);
        assert!((wrap_angle(v.heading_rad) - 1.0).abs() < 1e-3);
    }

    /// Under way the vehicle dives along its axis: each step covers speed x dt in three
    /// dimensions, and eq. 1 (speed x cos(pitch)) is the horizontal distance over dt.
    /// Coasting, it floats up level: the horizontal step is the whole speed's.
    #[test]
    fn diving_moves_along_the_body_axis() {
        let p = SandSharkParams::default();
        let mut v = SandShark::new(Vector3::new(0.0, 0.0, 2.5), 0.3);
        v.speed_m_s = 1.0;
        let dive = Setpoint { heading_rad: 0.3, speed_m_s: 1.0, depth_m: 10.0 };
        for _ in 0..50 {
            let before = v.position_ned_m;
            v.step(&p, &dive, 0.1);
            let step = v.position_ned_m - before;
            assert!((step.norm() - 0.1).abs() < 1e-12, "{}", step.norm());
            assert!((step.xy().norm() - v.speed_over_ground() * 0.1).abs() < 1e-12);
        }
        assert!((v.pitch_rad + (p.max_depth_rate_m_s).asin()).abs() < 1e-12, "nose down at the largest rate");
        let stop = Setpoint { speed_m_s: 0.0, ..dive };
        let (before, speed) = (v.position_ned_m, v.speed_m_s);
        v.step(&p, &stop, 0.1);
        assert_eq!(v.pitch_rad, 0.0);
        let coasted = speed * (1.0 - 0.1 / p.coast_time_constant_s);
        assert!(((v.position_ned_m - before).xy().norm() - coasted * 0.1).abs() < 1e-12);
    }
}
