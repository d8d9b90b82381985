//! Range-aided navigation of a 6-DOF underwater vehicle (sousa section 3.2): dead
//! reckoning on measured body velocities (eq. 3.1-3.2), attitude and depth updates
//! (eq. 3.3-3.6), and OWTT range updates to a beacon whose position travels with the
//! measurement (eq. 3.7-3.10).

use super::Calibration;
use super::range_calibration::{Calibrated, CalibratedRange, RangeCalibration};
use super::{Aiding, BeaconFix, Estimate, Kind, Measurement, Navigator, Outcome, Robust};
use crate::filter::{AnyFilter, FilterKind, GaussianFilter, ProcessModel};
use crate::measure::{Range3d, StateComponent};
use crate::models::kinematic6dof::{BodyVelocity, Cov, DIM, Kinematic6Dof, State, idx};
use nalgebra::{SMatrix, SVector, Vector1};

/// Noise of the vehicle's sensors as the filter models them (standard deviations).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SensorNoise {
    /// Body linear velocity (u, v, w), m/s.
    pub velocity_m_s: f64,
    /// Body angular rate (p, q, r), rad/s.
    pub rate_rad_s: f64,
    pub depth_m: f64,
    /// Roll, pitch, heading, rad.
    pub attitude_rad: f64,
    /// Acoustic range, m.
    pub range_m: f64,
}

/// The sensors of sousa's simulated vehicle (scenarios/sousa.toml's `[sensors]`, each
/// with its source there): none of these is stated in the thesis.
impl Default for SensorNoise {
    fn default() -> Self {
        Self {
            // an ROV's body velocity without a DVL (with 0.05 the errors are far below
            // the thesis's 0.5-3.5 m)
            velocity_m_s: 0.2,
            // gyro rates
            rate_rad_s: 0.002,
            // a pressure sensor ("low uncertainty", sec. 3.2)
            depth_m: 0.05,
            // a MEMS AHRS: heading 1-2 deg RMS
            attitude_rad: 1f64.to_radians(),
            // a modem's OWTT range (scenarios/sousa.toml's `[acoustics]`)
            range_m: 1.0,
        }
    }
}

impl SensorNoise {
    /// The process model of body velocities `nu` with this noise.
    pub fn process_model(&self, nu: BodyVelocity) -> Kinematic6Dof {
        Kinematic6Dof { nu, velocity_sigma_m_s: self.velocity_m_s, rate_sigma_rad_s: self.rate_rad_s }
    }

    /// The depth sensor and AHRS models (eq. 3.3-3.6): depth, roll, pitch, heading.
    pub fn depth_attitude_models(&self) -> [StateComponent; 4] {
        let (d2, a2) = (self.depth_m.powi(2), self.attitude_rad.powi(2));
        [
            StateComponent::value(idx::D, d2),
            StateComponent::angle(idx::ROLL, a2),
            StateComponent::angle(idx::PITCH, a2),
            StateComponent::angle(idx::YAW, a2),
        ]
    }

    /// The range model to `beacon` (eq. 3.7-3.10), with the beacon's own position error.
    pub fn range_model(&self, beacon: &BeaconFix) -> Range3d {
        Range3d { beacon: beacon.position_ned_m, sigma_m: self.range_m, beacon_sigma_m: beacon.sigma_m }
    }
}

/// The navigator of sousa section 3.2 over eta = [N, E, D, phi, theta, psi], with an
/// EKF or a UKF: dead reckoning on the held body velocities ([`Kind::BodyVelocity`]),
/// range updates at their receive time ([`Kind::Range`], the beacon's position and GPS
/// error travelling with it), and depth with attitude: a depth is held and fused with
/// the next attitude fix ([`Kind::Attitude`]) in one update (eq. 3.3-3.6).
///
/// With a [`RangeCalibration`] the state has `N` = 6 + its states components: a range
/// offset (a clock offset), its drift (a clock's frequency error) and a range scale (an
/// effective sound speed), read by every range update.
#[derive(Debug, Clone)]
pub struct Range6DofNavigator<const N: usize = DIM> {
    noise: SensorNoise,
    /// The depth sensor and AHRS models, built once.
    depth_attitude: [StateComponent; 4],
    aiding: Aiding,
    /// Where the calibration states are and how they move.
    calibration: Calibrated<(), DIM>,
    /// A range whose NIS exceeds it is rejected; a heavy-tailed range update.
    gate: super::Gate,
    robust: Option<Robust>,
    filter: AnyFilter<N>,
    t_s: f64,
    nu: BodyVelocity,
    depth: Option<f64>,
}

impl Range6DofNavigator {
    /// A navigator at `t0_s` from `eta0` with covariance `p0`. It uses ranges when
    /// `aiding.range` (dead reckoning on attitude and depth otherwise); it has no
    /// Doppler model.
    pub fn new(noise: SensorNoise, aiding: Aiding, filter: FilterKind, t0_s: f64, eta0: State, p0: Cov) -> Self {
        Self::calibrated(noise, aiding, filter, t0_s, (eta0, p0), RangeCalibration::default())
    }
}

/// The navigator of `spec`'s calibration states (6 to 11 of them), its ranges gated at
/// `gate` (a NIS; infinity: none) with the update `robust` asks for.
pub fn boxed(
    noise: SensorNoise,
    aiding: Aiding,
    filter: FilterKind,
    t0_s: f64,
    start: (State, Cov),
    calibration: RangeCalibration,
    (gate, robust): (f64, Option<Robust>),
) -> Box<dyn Navigator> {
    fn make<const N: usize>(
        n: SensorNoise,
        a: Aiding,
        f: FilterKind,
        t: f64,
        s: (State, Cov),
        c: RangeCalibration,
        g: (f64, Option<Robust>),
    ) -> Box<dyn Navigator> {
        Box::new(Range6DofNavigator::<N>::calibrated(n, a, f, t, s, c).with_range_gate(g.0, g.1))
    }
    let g = (gate, robust);
    match calibration.states() {
        0 => make::<6>(noise, aiding, filter, t0_s, start, calibration, g),
        1 => make::<7>(noise, aiding, filter, t0_s, start, calibration, g),
        2 => make::<8>(noise, aiding, filter, t0_s, start, calibration, g),
        3 => make::<9>(noise, aiding, filter, t0_s, start, calibration, g),
        4 => make::<10>(noise, aiding, filter, t0_s, start, calibration, g),
        _ => make::<11>(noise, aiding, filter, t0_s, start, calibration, g),
    }
}

impl<const N: usize> Range6DofNavigator<N> {
    /// A navigator with the calibration states of `calibration` behind the pose
    /// `start` = (eta0, p0); `N` must be 6 + `calibration.states()`.
    ///
    /// # Panics
    /// When `N` does not match the calibration.
    pub fn calibrated(
        noise: SensorNoise,
        aiding: Aiding,
        filter: FilterKind,
        t0_s: f64,
        (eta0, p0): (State, Cov),
        calibration: RangeCalibration,
    ) -> Self {
        let (x, p) = calibration.initial(&eta0, &p0);
        Self {
            noise,
            depth_attitude: noise.depth_attitude_models(),
            aiding,
            calibration: calibration.motion(),
            gate: super::Gate::new(f64::INFINITY),
            robust: None,
            filter: AnyFilter::new(filter, x, p),
            t_s: t0_s,
            nu: BodyVelocity::zeros(),
            depth: None,
        }
    }

    /// Ranges whose NIS exceeds `gate` are rejected; `robust` makes the range update
    /// heavy-tailed.
    pub fn with_range_gate(mut self, gate: f64, robust: Option<Robust>) -> Self {
        (self.gate, self.robust) = (super::Gate::new(gate), robust);
        self
    }

    /// The state: eta, then the calibration states.
    pub fn state(&self) -> &SVector<f64, N> {
        self.filter.mean()
    }
    pub fn covariance(&self) -> &SMatrix<f64, N, N> {
        self.filter.covariance()
    }

    /// Dead reckoning to `t_s` on the held body velocities: P = F P F' + G Q G' with
    /// G = dt J (eq. 3.2); the calibration states as [`Calibrated`] moves them.
    fn advance_to(&mut self, t_s: f64) {
        let dt = t_s - self.t_s;
        if dt > 0.0 {
            let model = self.calibration.over(self.noise.process_model(self.nu));
            let q = model.noise_covariance(self.filter.mean(), dt);
            self.filter.predict(&model, dt, &q);
            self.t_s = t_s;
        }
    }
}

impl<const N: usize> super::capability::BodyVelocity for Range6DofNavigator<N> {
    fn body_velocity_m_s(&self) -> nalgebra::Vector3<f64> {
        self.nu.fixed_rows::<3>(0).into_owned()
    }
}

impl<const N: usize> Navigator for Range6DofNavigator<N> {
    fn body_velocity(&self) -> Option<&dyn super::capability::BodyVelocity> {
        Some(self)
    }

    fn process(&mut self, m: &Measurement) -> Outcome {
        match m.kind {
            Kind::BodyVelocity { nu } => {
                self.advance_to(m.t_s);
                self.nu = SVector::from(nu);
                Outcome::Applied
            }
            Kind::Depth { depth_m } => {
                self.depth = Some(depth_m);
                Outcome::Applied
            }
            Kind::Attitude { roll_rad, pitch_rad, heading_rad } => {
                self.advance_to(m.t_s);
                let (f, models) = (&mut self.filter, &self.depth_attitude);
                let ungated = f64::INFINITY;
                match self.depth.take() {
                    Some(depth) => {
                        let z = SVector::from([depth, roll_rad, pitch_rad, heading_rad]);
                        super::gated_update(f, models, z, ungated, None)
                    }
                    None => {
                        let [_, roll, pitch, yaw] = models;
                        let z = SVector::from([roll_rad, pitch_rad, heading_rad]);
                        super::gated_update(f, &[roll, pitch, yaw], z, ungated, None)
                    }
                }
            }
            Kind::Range { beacon, range_m } | Kind::RangeDoppler { beacon, range_m, .. } if self.aiding.range => {
                // range update (eq. 3.7-3.10) at the receive time
                self.advance_to(m.t_s);
                let model = CalibratedRange { range: self.noise.range_model(&beacon), layout: self.calibration.layout };
                self.gate.update(&mut self.filter, &[model], Vector1::new(range_m), self.robust)
            }
            _ => Outcome::Skipped,
        }
    }

    fn estimate(&self) -> Estimate {
        let (x, p) = (self.filter.mean(), self.filter.covariance());
        let state = |i: Option<usize>| i.map(|i| x[i]);
        Estimate {
            t_s: self.t_s,
            position_ned_m: x.fixed_rows::<3>(0).into_owned(),
            horizontal_cov_m2: p.fixed_view::<2, 2>(0, 0).into_owned(),
            heading_state_rad: x[idx::YAW],
            heading_var_rad2: p[(idx::YAW, idx::YAW)],
            roll_pitch_rad: [x[idx::ROLL], x[idx::PITCH]],
            speed_m_s: None,
            calibration: Calibration {
                range_bias_m: state(self.calibration.layout.offset),
                range_scale: state(self.calibration.layout.scale),
                distance_scale: None,
                turn_scale: None,
                usbl_misalignment_rad: None,
                current_ned_m_s: self.calibration.layout.current.map(|i| [x[i], x[i + 1]]),
            },
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::filter::UkfParams;
    use crate::nav::{BeaconFix, OffsetPrior};
    use nalgebra::Vector3;

    fn noise() -> SensorNoise {
        SensorNoise { velocity_m_s: 0.05, rate_rad_s: 0.002, depth_m: 0.05, attitude_rad: 0.02, range_m: 0.1 }
    }

    /// A stationary vehicle 20 m deep, ranges from a beacon circling it at 30 m with no
    /// noise: the horizontal position converges from a 5 m error to centimetres, while
    /// dead reckoning alone keeps the error; with the EKF and with the UKF.
    #[test]
    fn ranges_from_a_circling_beacon_fix_the_position() {
        let truth = State::from([0.0, 0.0, 20.0, 0.0, 0.0, 0.3]);
        let mut start = truth;
        start[idx::N] += 3.0;
        start[idx::E] -= 4.0;
        let p0 = Cov::from_diagonal(&SVector::from([25.0, 25.0, 0.01, 1e-3, 1e-3, 1e-3]));
        for kind in [FilterKind::Ekf, FilterKind::Ukf(UkfParams::default())] {
            let mut f = Range6DofNavigator::new(noise(), Aiding::RANGE, kind, 0.0, start, p0);
            let mut dr = Range6DofNavigator::new(noise(), Aiding::NONE, kind, 0.0, start, p0);
            for k in 0..600 {
                let t = (k + 1) as f64 * 0.1;
                let mut events = vec![
                    Kind::BodyVelocity { nu: [0.0; 6] },
                    Kind::Depth { depth_m: 20.0 },
                    Kind::Attitude { roll_rad: 0.0, pitch_rad: 0.0, heading_rad: 0.3 },
                ];
                if k % 50 == 0 {
                    let a = k as f64 * 0.02;
                    let beacon = Vector3::new(30.0 * a.cos(), 30.0 * a.sin(), 0.0);
                    let range_m = (truth.fixed_rows::<3>(0) - beacon).norm();
                    events.push(Kind::Range { beacon: BeaconFix::fixed(0, beacon), range_m });
                }
                for e in events {
                    let m = Measurement::new(t, e);
                    assert!(!matches!(f.process(&m), Outcome::Failed(_)));
                    dr.process(&m);
                }
            }
            let err = |e: &Range6DofNavigator| (e.state().fixed_rows::<3>(0) - truth.fixed_rows::<3>(0)).xy().norm();
            assert!(err(&f) < 0.05, "{kind:?}: range-aided error {}", err(&f));
            assert!(err(&dr) > 4.9, "{kind:?}: dead-reckoning error {}", err(&dr));
            // the covariance shrank accordingly
            assert!(f.estimate().horizontal_cov_m2.trace() < 0.05);
        }
    }

    /// A still vehicle 20 m deep hears a beacon circling 30 m around a point 60 m north
    /// of it for an hour; the vehicle's clock runs 1 ppm fast after a 1 ms offset, so
    /// every range reads 1.5 + 1.5e-3 t m long (1500 m/s), with no other noise. The
    /// navigator with an offset and a drift state ends on the truth (within 3 of its
    /// sigmas and 5 cm) with the drift it was given; the one without them ends about the
    /// final offset (6.9 m) off.
    #[test]
    fn a_clock_state_takes_up_a_drifting_clock() {
        let truth = State::from([0.0, 0.0, 20.0, 0.0, 0.0, 0.3]);
        let p0 = Cov::from_diagonal(&SVector::from([1.0, 1.0, 0.01, 1e-4, 1e-4, 1e-4]));
        let (offset_m, drift_m_s) = (1.5, 1.5e-3);
        let still = SensorNoise { velocity_m_s: 1e-3, ..noise() };
        let prior = OffsetPrior { initial_m: 0.0, sigma_m: 5.0, walk_m_per_sqrt_s: 0.0, drift_sigma_m_s: Some(4.5e-3) };
        let clock = RangeCalibration { offset: Some(prior), scale_sigma: None, current: None };
        let mut plain = Range6DofNavigator::new(still, Aiding::RANGE, FilterKind::Ekf, 0.0, truth, p0);
        let mut clocked =
            Range6DofNavigator::<8>::calibrated(still, Aiding::RANGE, FilterKind::Ekf, 0.0, (truth, p0), clock);
        for k in 1..=3600 {
            let t = k as f64;
            let mut events = vec![
                Kind::BodyVelocity { nu: [0.0; 6] },
                Kind::Depth { depth_m: 20.0 },
                Kind::Attitude { roll_rad: 0.0, pitch_rad: 0.0, heading_rad: 0.3 },
            ];
            if k % 10 == 0 {
                let a = t * 2.0 * std::f64::consts::PI / 600.0;
                let beacon = Vector3::new(60.0 + 30.0 * a.cos(), 30.0 * a.sin(), 0.0);
                let range_m = (truth.fixed_rows::<3>(0) - beacon).norm() + offset_m + drift_m_s * t;
                events.push(Kind::Range { beacon: BeaconFix::fixed(0, beacon), range_m });
            }
            for e in events {
                let m = Measurement::new(t, e);
                assert!(!matches!(clocked.process(&m), Outcome::Failed(_)));
                plain.process(&m);
            }
        }
        let err = |x: &SVector<f64, 2>| (x - truth.fixed_rows::<2>(0)).norm();
        let (x, p) = (clocked.state(), clocked.covariance());
        let e = err(&x.fixed_rows::<2>(0).into_owned());
        assert!(e < 0.05 && e < 3.0 * p.fixed_view::<2, 2>(0, 0).trace().sqrt(), "with the clock: {e} m");
        assert!((x[7] - drift_m_s).abs() < 3.0 * p[(7, 7)].sqrt() + 1e-6, "drift {} against {drift_m_s}", x[7]);
        let bias = clocked.estimate().calibration.range_bias_m.expect("estimated");
        assert!((bias - (offset_m + drift_m_s * 3600.0)).abs() < 0.05);
        assert_eq!(plain.estimate().calibration.range_bias_m, None, "not estimated: absent");
        let e_plain = err(&plain.state().fixed_rows::<2>(0).into_owned());
        assert!(e_plain > 3.0, "without the clock: {e_plain} m");
    }

    /// Prediction agrees with the model and inflates P by the mapped input noise.
    #[test]
    fn prediction_maps_input_noise() {
        let eta = State::from([1.0, 2.0, 3.0, 0.1, -0.1, 1.0]);
        let mut f = Range6DofNavigator::new(noise(), Aiding::RANGE, FilterKind::Ekf, 0.0, eta, Cov::zeros());
        let nu = [1.0, 0.0, 0.1, 0.0, 0.0, 0.05];
        f.process(&Measurement::new(0.0, Kind::BodyVelocity { nu }));
        f.process(&Measurement::new(0.5, Kind::Depth { depth_m: 3.0 })); // held, no motion
        assert_eq!(f.state(), &eta);
        f.process(&Measurement::new(0.5, Kind::BodyVelocity { nu }));
        let m = Kinematic6Dof::new(SVector::from(nu));
        assert!((f.state() - m.propagate(&eta, 0.5)).norm() < 1e-12);
        let g = m.input_jacobian(&eta, 0.5);
        let (v2, w2) = (0.05f64.powi(2), 0.002f64.powi(2));
        let q_nu = Cov::from_diagonal(&SVector::from([v2, v2, v2, w2, w2, w2]));
        assert!((f.covariance() - g * q_nu * g.transpose()).norm() < 1e-15);
    }
}
