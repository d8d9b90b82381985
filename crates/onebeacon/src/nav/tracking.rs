//! Tracking a craft that sends no motion data (topside tracking, the ASV side of
//! hoff2024, a vehicle whose navigation data is lost): a constant-velocity model driven
//! by white acceleration, corrected by ranges to beacons at known positions (with the
//! range offset and scale states of [`super::planar`] when asked for).
//!
//! State [N, E, vN, vE, b, k_r]: horizontal NED position (m) and velocity (m/s), the
//! range offset b (m) and scale error k_r (ranges read (1 + k_r) r + b).

use super::Calibration;
use super::capability::Weighing;
use super::{Estimate, Innovation, Kind, Measurement, Navigator, Outcome, PlanarConfig};
use crate::filter::{AnyFilter, FilterKind, GaussianFilter, ProcessModel};
use crate::measure::{ScalarModel, SlantRange};
use nalgebra::{SMatrix, SVector, Vector1, Vector3};

/// Number of state components.
pub const STATES: usize = 6;
type State = SVector<f64, STATES>;
type Cov = SMatrix<f64, STATES, STATES>;

/// Index of each state component.
pub mod idx {
    pub const N: usize = 0;
    pub const E: usize = 1;
    pub const VN: usize = 2;
    pub const VE: usize = 3;
    pub const BIAS: usize = 4;
    pub const RANGE_SCALE: usize = 5;
}

/// Standard deviation of the initial velocity on each axis, m/s: nothing is known of it.
pub const INITIAL_VELOCITY_SIGMA_M_S: f64 = 1.0;

/// The covariance of (position, velocity) on one axis after `dt` s of white acceleration
/// of spectral density `q` ((m/s^2)^2 s): q [dt^3/3, dt^2/2; dt^2/2, dt] (FilterPy's
/// `Q_continuous_white_noise`; Bar-Shalom, Li and Kirubarajan, sec. 6.2.2). The tracker
/// predicts with it and the smoother's constant-velocity factors weigh with it.
pub fn white_acceleration_noise(q: f64, dt: f64) -> [[f64; 2]; 2] {
    let c = q * dt.powi(2) / 2.0;
    [[q * dt.powi(3) / 3.0, c], [c, q * dt]]
}

/// Constant velocity over `dt` with white acceleration of spectral density `q`
/// ((m/s^2)^2 s): Q = q [dt^3/3, dt^2/2; dt^2/2, dt] on each axis.
#[derive(Debug, Clone, Copy)]
struct ConstantVelocity {
    q: f64,
}

impl ProcessModel<STATES> for ConstantVelocity {
    fn propagate(&self, x: &State, dt: f64) -> State {
        let mut n = *x;
        n[idx::N] += x[idx::VN] * dt;
        n[idx::E] += x[idx::VE] * dt;
        n
    }

    fn jacobian(&self, _x: &State, dt: f64) -> Cov {
        let mut f = Cov::identity();
        f[(idx::N, idx::VN)] = dt;
        f[(idx::E, idx::VE)] = dt;
        f
    }

    fn noise_covariance(&self, _x: &State, dt: f64) -> Cov {
        let mut q = Cov::zeros();
        let axis = white_acceleration_noise(self.q, dt);
        for (p, v) in [(idx::N, idx::VN), (idx::E, idx::VE)] {
            q[(p, p)] = axis[0][0];
            q[(p, v)] = axis[0][1];
            q[(v, p)] = axis[1][0];
            q[(v, v)] = axis[1][1];
        }
        q
    }

    fn is_angle(&self, _i: usize) -> bool {
        false
    }
}

/// The navigator: an EKF or UKF over [N, E, vN, vE, b, k_r].
#[derive(Debug, Clone, PartialEq)]
pub struct TrackingNavigator {
    config: PlanarConfig,
    /// White-acceleration standard deviation, m/s^2 per sqrt(s).
    accel_sigma_m_s2: f64,
    filter: AnyFilter<STATES>,
    gate: super::Gate,
    t_s: f64,
    depth_m: f64,
}

impl TrackingNavigator {
    /// Starts at time `t_s` at (`north_m`, `east_m`) with `sigma_position_m` on each axis
    /// and an unknown velocity; `accel_sigma_m_s2` drives the velocity's random walk.
    pub fn new(
        config: PlanarConfig,
        accel_sigma_m_s2: f64,
        filter: FilterKind,
        t_s: f64,
        (north_m, east_m): (f64, f64),
        sigma_position_m: f64,
    ) -> Self {
        let sigma_if = |on: bool, sigma: f64| if on { sigma } else { 0.0 };
        let v = INITIAL_VELOCITY_SIGMA_M_S;
        let sigmas = State::from([
            sigma_position_m,
            sigma_position_m,
            v,
            v,
            sigma_if(config.estimate_bias, config.bias_sigma_m),
            sigma_if(config.estimate_range_scale, config.range_scale_sigma),
        ]);
        let p = Cov::from_diagonal(&sigmas.component_mul(&sigmas));
        let x = State::from([north_m, east_m, 0.0, 0.0, config.bias_m, 0.0]);
        let gate = super::Gate::new(config.nis_gate.unwrap_or(f64::INFINITY));
        Self { config, accel_sigma_m_s2, filter: AnyFilter::new(filter, x, p), gate, t_s, depth_m: 0.0 }
    }

    /// Predicts to `t_s`; the bias wanders meanwhile.
    /// The slant-range model to a beacon at `beacon` (NED, m).
    fn range(&self, beacon: Vector3<f64>) -> SlantRange {
        let var = self.config.noise.range_sigma_m.powi(2);
        SlantRange { beacon, depth_m: self.depth_m, bias: Some(idx::BIAS), scale: Some(idx::RANGE_SCALE), var }
    }

    fn advance_to(&mut self, t_s: f64) {
        let dt = (t_s - self.t_s).max(0.0);
        self.t_s = self.t_s.max(t_s);
        if dt == 0.0 {
            return;
        }
        let model = ConstantVelocity { q: self.accel_sigma_m_s2.powi(2) };
        let q = model.noise_covariance(self.filter.mean(), dt);
        self.filter.predict(&model, dt, &q);
        if self.config.estimate_bias {
            self.filter.covariance_mut()[(idx::BIAS, idx::BIAS)] +=
                self.config.noise.bias_walk_m_per_sqrt_s.powi(2) * dt;
        }
    }
}

impl Weighing for TrackingNavigator {
    fn weigh(&mut self, m: &Measurement) -> Option<Innovation> {
        let Kind::Range { beacon, range_m } = m.kind else { return None };
        self.advance_to(m.t_s);
        let model: [&dyn ScalarModel<STATES>; 1] = [&self.range(beacon.position_ned_m)];
        super::gated_update(&mut self.filter, &model, Vector1::new(range_m), -1.0, None).innovation()
    }
}

/// Ranges correct the track and depths enter slant ranges; a craft tracked from
/// outside gives no other measurement this model uses.
impl Navigator for TrackingNavigator {
    fn weighing(&mut self) -> Option<&mut dyn Weighing> {
        Some(self)
    }

    fn process(&mut self, m: &Measurement) -> Outcome {
        self.advance_to(m.t_s);
        match m.kind {
            Kind::Depth { depth_m } => {
                self.depth_m = depth_m;
                Outcome::Applied
            }
            Kind::Range { beacon, range_m } | Kind::RangeDoppler { beacon, range_m, .. }
                if self.config.aiding.range =>
            {
                let model: [&dyn ScalarModel<STATES>; 1] = [&self.range(beacon.position_ned_m)];
                self.gate.update(&mut self.filter, &model, Vector1::new(range_m), self.config.robust)
            }
            _ => Outcome::Skipped,
        }
    }

    fn estimate(&self) -> Estimate {
        let (x, p) = (self.filter.mean(), self.filter.covariance());
        let speed = x[idx::VN].hypot(x[idx::VE]);
        Estimate {
            t_s: self.t_s,
            position_ned_m: Vector3::new(x[idx::N], x[idx::E], self.depth_m),
            horizontal_cov_m2: p.fixed_view::<2, 2>(0, 0).into_owned(),
            // the course over ground; its variance from the velocity's, to first order
            heading_state_rad: x[idx::VE].atan2(x[idx::VN]),
            heading_var_rad2: (p[(idx::VN, idx::VN)] + p[(idx::VE, idx::VE)]) / speed.max(0.1).powi(2),
            roll_pitch_rad: [0.0; 2],
            speed_m_s: Some(speed),
            calibration: Calibration {
                range_bias_m: self.config.estimate_bias.then_some(x[idx::BIAS]),
                range_scale: self.config.estimate_range_scale.then_some(x[idx::RANGE_SCALE]),
                distance_scale: None,
                turn_scale: None,
                usbl_misalignment_rad: None,
                current_ned_m_s: None,
            },
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::nav::BeaconFix;
    use approx::assert_abs_diff_eq;

    /// Q of the white-acceleration model against its integral, evaluated by the
    /// rectangle rule: Q = q int_0^dt [t^2, t; t, 1] dt.
    #[test]
    fn process_noise_is_the_integrated_white_acceleration() {
        let (q, dt) = (0.04, 2.5);
        let model = ConstantVelocity { q };
        let qm = model.noise_covariance(&State::zeros(), dt);
        let k = 100_000;
        let h = dt / k as f64;
        let (mut a, mut b, mut c) = (0.0, 0.0, 0.0);
        for i in 0..k {
            let t = (i as f64 + 0.5) * h;
            a += t * t * h;
            b += t * h;
            c += h;
        }
        assert_abs_diff_eq!(qm[(idx::N, idx::N)], q * a, epsilon = 1e-9);
        assert_abs_diff_eq!(qm[(idx::E, idx::VE)], q * b, epsilon = 1e-9);
        assert_abs_diff_eq!(qm[(idx::VN, idx::VN)], q * c, epsilon = 1e-12);
    }

    /// A craft at a steady 1 m/s toward north-east, ranged from three beacons once a
    /// second without noise: the track converges on its position and velocity.
    #[test]
    fn ranges_alone_track_a_steady_craft() {
        let beacons = [Vector3::new(0.0, 0.0, 0.0), Vector3::new(80.0, 0.0, 0.0), Vector3::new(0.0, 80.0, 0.0)];
        let v = Vector3::new(1.0, 1.0, 0.0) / 2f64.sqrt();
        let start = Vector3::new(10.0, 20.0, 0.0);
        let mut config = PlanarConfig::default();
        config.noise.range_sigma_m = 0.5;
        let mut nav = TrackingNavigator::new(config, 0.05, FilterKind::Ekf, 0.0, (12.0, 17.0), 5.0);
        for k in 1..=300 {
            let t = k as f64 / 3.0;
            let b = beacons[k % 3];
            let truth = start + v * t;
            let fix = BeaconFix::fixed(k as u32 % 3, b);
            nav.process(&Measurement::new(t, Kind::Range { beacon: fix, range_m: (truth - b).norm() }));
        }
        let e = nav.estimate();
        let truth = start + v * 100.0;
        assert_abs_diff_eq!(e.north_m(), truth.x, epsilon = 0.05);
        assert_abs_diff_eq!(e.east_m(), truth.y, epsilon = 0.05);
        assert_abs_diff_eq!(e.speed_m_s.unwrap(), 1.0, epsilon = 0.01);
        assert_abs_diff_eq!(e.heading_state_rad, std::f64::consts::FRAC_PI_4, epsilon = 0.01);
    }
}
