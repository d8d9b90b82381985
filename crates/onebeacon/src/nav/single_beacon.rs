//! Single fixed beacon navigation with an EKF (garin2024 sections 3.3-3.6).
//!
//! Every time step the vehicle predicts with the unicycle model (eq. 7) and updates with
//! its proprioceptive sensors: heading, yaw rate, acceleration (eq. 18 right, 24). When a
//! communication frame from the beacon is decoded it adds the one-way travel-time range
//! (eq. 19) and the Doppler radial speed (eq. 13-15, 20), stacked into one update
//! (eq. 18 left, 22). [`Aiding::RANGE`] is the ROSB baseline: the same filter without
//! the Doppler speed; [`Aiding::NONE`] is dead reckoning on the inertial sensors.

use super::Calibration;
use super::range_calibration::{Calibrated, CalibratedRange, CarriedDoppler, RangeCalibration};
use super::{Aiding, Estimate, Kind, Measurement, Navigator, Outcome, Robust};
use crate::filter::{AnyFilter, FilterError, FilterKind, Gated, GaussianFilter, MeasurementModel, ProcessModel};
use crate::measure::{RadialSpeed2d, Range2d, ScalarModel, StateComponent};
use crate::models::unicycle::{Cov, DIM, State, UnicycleAccel, idx};
use nalgebra::{SMatrix, SVector, Vector2, Vector3};

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

/// A frame waiting for the next inertial sample: its beacon (NED, m), and the range and
/// Doppler speed the navigator uses from it.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Frame {
    beacon: Vector2<f64>,
    range_m: Option<f64>,
    radial_speed_m_s: Option<f64>,
}

/// The single-beacon navigator of garin2024 (or its range-only ROSB variant) over the
/// unicycle state [x, y, psi, v, Omega, a], with an EKF or a UKF.
///
/// It runs at the rate of its inertial samples ([`Kind::Inertial`]): each predicts from
/// the previous one and updates with heading, yaw rate and acceleration, stacked with
/// the range (and Doppler speed) of a frame decoded since ([`Kind::RangeDoppler`] or
/// [`Kind::Range`]), as in garin2024 eq. 18.
///
/// With a [`RangeCalibration`] the state has `N` = 6 + its states components (a range
/// offset, its drift, a range scale, read by every range; the current, which carries
/// the position and shows in the Doppler speed over ground).
#[derive(Debug, Clone)]
pub struct SingleBeaconNavigator<const N: usize = DIM, P = UnicycleAccel> {
    aiding: Aiding,
    tuning: EkfTuning,
    /// The unicycle model (eq. 7), wrapped with the calibration states' motion when
    /// there are any (the plain model otherwise, at its own speed).
    model: P,
    /// Where the calibration states are and how they move.
    calibration: Calibrated<(), DIM>,
    /// The model's Q per step but the offset's walk (it depends on neither the state
    /// nor dt).
    q: SMatrix<f64, N, N>,
    /// The AHRS heading, gyro and accelerometer models, built once.
    inertial: [StateComponent; 3],
    filter: AnyFilter<N>,
    t_s: f64,
    pending: Option<Frame>,
    /// The last beacon heard, NED, m.
    beacon: Option<Vector2<f64>>,
    /// Reflect a state that drives backwards back through the beacon
    /// ([`Self::with_mirror_recovery`]).
    unmirror: bool,
    /// [`Self::with_min_speed`].
    min_speed_m_s: Option<f64>,
    /// [`Self::with_range_gate`].
    gate: f64,
    robust: Option<Robust>,
}

impl SingleBeaconNavigator {
    /// A navigator at time `t0_s` with state `z0` = [x, y, psi, v, Omega, a] and
    /// covariance `p0`.
    pub fn new(aiding: Aiding, tuning: EkfTuning, filter: FilterKind, t0_s: f64, z0: State, p0: Cov) -> Self {
        let model = UnicycleAccel { q_diag: tuning.q_diag };
        Self::assemble(model, RangeCalibration::default(), aiding, tuning, filter, t0_s, (z0, p0))
    }
}

impl<const N: usize> SingleBeaconNavigator<N, Calibrated<UnicycleAccel, DIM>> {
    /// A navigator with the calibration states of `calibration` behind the pose
    /// `start` = (z0, p0); `N` must be 6 + `calibration.states()`.
    ///
    /// # Panics
    /// When `N` does not match the calibration.
    pub(crate) fn calibrated(
        aiding: Aiding,
        tuning: EkfTuning,
        filter: FilterKind,
        t0_s: f64,
        start: (State, Cov),
        calibration: RangeCalibration,
    ) -> Self {
        let model = calibration.motion().over(UnicycleAccel { q_diag: tuning.q_diag });
        Self::assemble(model, calibration, aiding, tuning, filter, t0_s, start)
    }
}

/// What keeps the navigator on the vehicle besides its model: [`SingleBeaconNavigator::with_min_speed`],
/// [`SingleBeaconNavigator::with_mirror_recovery`] and [`SingleBeaconNavigator::with_range_gate`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Guards {
    pub min_speed_m_s: Option<f64>,
    pub mirror: bool,
    pub gate: f64,
    pub robust: Option<Robust>,
}

/// The navigator of `calibration`'s states (6 to 11 of them), with its guards.
pub fn boxed(
    aiding: Aiding,
    tuning: EkfTuning,
    filter: FilterKind,
    t0_s: f64,
    start: (State, Cov),
    calibration: RangeCalibration,
    guards: Guards,
) -> Box<dyn Navigator> {
    fn make<const N: usize>(
        a: Aiding,
        t: EkfTuning,
        f: FilterKind,
        t0: f64,
        s: (State, Cov),
        c: RangeCalibration,
        g: Guards,
    ) -> Box<dyn Navigator> {
        let nav = SingleBeaconNavigator::<N, _>::calibrated(a, t, f, t0, s, c);
        Box::new(nav.with_mirror_recovery(g.mirror).with_min_speed(g.min_speed_m_s).with_range_gate(g.gate, g.robust))
    }
    let g = guards;
    match calibration.states() {
        0 => {
            let nav = SingleBeaconNavigator::new(aiding, tuning, filter, t0_s, start.0, start.1);
            Box::new(
                nav.with_mirror_recovery(g.mirror).with_min_speed(g.min_speed_m_s).with_range_gate(g.gate, g.robust),
            )
        }
        1 => make::<7>(aiding, tuning, filter, t0_s, start, calibration, g),
        2 => make::<8>(aiding, tuning, filter, t0_s, start, calibration, g),
        3 => make::<9>(aiding, tuning, filter, t0_s, start, calibration, g),
        4 => make::<10>(aiding, tuning, filter, t0_s, start, calibration, g),
        _ => make::<11>(aiding, tuning, filter, t0_s, start, calibration, g),
    }
}

impl<const N: usize, P: ProcessModel<N>> SingleBeaconNavigator<N, P> {
    /// A navigator on `model` (the unicycle's, with `calibration`'s states if any).
    fn assemble(
        model: P,
        calibration: RangeCalibration,
        aiding: Aiding,
        tuning: EkfTuning,
        filter: FilterKind,
        t0_s: f64,
        (z0, p0): (State, Cov),
    ) -> Self {
        let (x, p) = calibration.initial(&z0, &p0);
        let q = model.noise_covariance(&x, 0.0);
        let inertial = [
            StateComponent::angle(idx::PSI, tuning.r_heading_rad2),
            StateComponent::value(idx::OMEGA, tuning.r_yaw_rate_rad2_s2),
            StateComponent::value(idx::ACCEL, tuning.r_accel_m2_s4),
        ];
        let filter = AnyFilter::new(filter, x, p);
        Self {
            aiding,
            tuning,
            model,
            calibration: calibration.motion(),
            q,
            inertial,
            filter,
            t_s: t0_s,
            pending: None,
            beacon: None,
            unmirror: true,
            min_speed_m_s: None,
            gate: f64::INFINITY,
            robust: None,
        }
    }

    /// A range whose own NIS (at the prediction, with the nominal noise) exceeds `gate`
    /// is left out of its frame's update; `robust` inflates the noise of the others.
    pub fn with_range_gate(mut self, gate: f64, robust: Option<Robust>) -> Self {
        (self.gate, self.robust) = (gate, robust);
        self
    }

    /// The slowest the vehicle goes ahead, m/s: a speed estimate below it is projected
    /// onto it (default: none, as published).
    pub fn with_min_speed(mut self, min_speed_m_s: Option<f64>) -> Self {
        self.min_speed_m_s = min_speed_m_s;
        self
    }

    /// A survey vehicle keeps going: a speed estimate below the floor is projected onto
    /// it, and the states correlated with the speed (the along-track position above all)
    /// move with it, x -> x - P e_v (v - v_min) / P_vv (estimate projection for an
    /// active inequality constraint; P is kept, so the filter can still move v).
    fn floor_speed(&mut self) {
        let Some(floor) = self.min_speed_m_s else { return };
        let (x, p) = (self.filter.mean(), self.filter.covariance());
        let (v, p_vv) = (x[idx::V], p[(idx::V, idx::V)]);
        // a speed clearly negative is the mirror's, left to `unmirror` (and NaN is neither)
        let under = v < floor && v >= -0.25;
        let projectable = under && p_vv.is_finite() && p_vv > 0.0;
        if !projectable {
            return;
        }
        let shift = p.column(idx::V) * ((v - floor) / p_vv);
        *self.filter.mean_mut() -= shift;
        self.filter.mean_mut()[idx::V] = floor;
    }

    /// Whether a state that drives backwards is taken for the mirror image of the
    /// vehicle through the beacon and reflected back (default: yes; garin2024's filter
    /// as published: no).
    pub fn with_mirror_recovery(mut self, on: bool) -> Self {
        self.unmirror = on;
        self
    }

    /// Range, Doppler speed and heading from one beacon cannot tell the vehicle from its
    /// point reflection through the beacon driving backwards (same ranges, same radial
    /// speeds, same heading): the EKF sometimes locks onto that mirror. A survey vehicle
    /// does not drive backwards, so a speed estimate clearly negative (below -0.25 m/s
    /// and 3 sigma) means the mirror: the state is reflected back, x -> 2b - x, v -> -v
    /// (and a current c -> -c), P -> J P J' with J = diag(-1, -1, 1, -1, 1, 1, ..., -1, -1).
    fn unmirror(&mut self) {
        let Some(b) = self.beacon.filter(|_| self.unmirror) else { return };
        let (x, p) = (self.filter.mean(), self.filter.covariance());
        let v = x[idx::V];
        if !(v < -0.25 && v < -3.0 * p[(idx::V, idx::V)].max(0.0).sqrt()) {
            return;
        }
        // the current, a velocity over ground, is reflected with the speed
        let current = self.calibration.layout.current.map(|c| [c, c + 1]);
        let reflected = |i: usize| matches!(i, idx::X | idx::Y | idx::V) || current.is_some_and(|c| c.contains(&i));
        let j = SMatrix::<f64, N, N>::from_diagonal(&SVector::from_fn(|i, _| if reflected(i) { -1.0 } else { 1.0 }));
        let p = j * p * j;
        let x = self.filter.mean_mut();
        x[idx::X] = 2.0 * b.x - x[idx::X];
        x[idx::Y] = 2.0 * b.y - x[idx::Y];
        x[idx::V] = -v;
        for c in current.into_iter().flatten() {
            x[c] = -x[c];
        }
        *self.filter.covariance_mut() = p;
    }

    /// Holds a frame's range and Doppler speed (those the aiding uses) for the next
    /// inertial sample.
    fn hold(&mut self, beacon: Vector2<f64>, range_m: Option<f64>, radial_speed_m_s: Option<f64>) -> Outcome {
        let range_m = range_m.filter(|_| self.aiding.range);
        let radial_speed_m_s = radial_speed_m_s.filter(|_| self.aiding.doppler);
        self.pending = Some(Frame { beacon, range_m, radial_speed_m_s });
        Outcome::Applied
    }

    /// The state estimate [x, y, psi, v, Omega, a], then the calibration states.
    pub fn state(&self) -> &SVector<f64, N> {
        self.filter.mean()
    }

    /// Predicts to `t_s`, then one stacked update of the inertial sample and the
    /// pending frame. Returns the NIS.
    fn tick(&mut self, t_s: f64, heading: f64, yaw_rate: f64, accel: f64) -> Result<Gated, FilterError> {
        let dt = t_s - self.t_s;
        if dt > 0.0 {
            let mut q = self.q;
            self.calibration.walk(&mut q, dt);
            self.filter.predict(&self.model, dt, &q);
            self.t_s = t_s;
        }
        let (t, f) = (&self.tuning, &mut self.filter);
        let [heading_m, yaw_rate_m, accel_m] = &self.inertial;
        let Some(fr) = self.pending.take() else { return update(f, &self.inertial, [heading, yaw_rate, accel]) };
        self.beacon = Some(fr.beacon);
        let layout = self.calibration.layout;
        let range_model = |var: f64| CalibratedRange { range: Range2d { beacon: fr.beacon, var }, layout };
        // the range's own NIS at the prediction: gated out above the gate, its noise
        // inflated by a heavy-tailed update
        let mut r_range = t.r_range_m2;
        let mut range_m = fr.range_m;
        if let Some(r) = range_m.filter(|_| self.gate.is_finite() || self.robust.is_some()) {
            let (m, x) = (range_model(r_range), f.mean());
            let h = ScalarModel::<N>::jacobian(&m, x);
            let s = (h * f.covariance() * h.transpose())[(0, 0)] + r_range;
            let nis = (r - ScalarModel::<N>::predict(&m, x)).powi(2) / s;
            if nis > self.gate {
                range_m = None;
            } else if let Some(robust) = self.robust {
                r_range *= robust.inflation(nis, 1);
            }
        }
        let range = range_model(r_range);
        let doppler = RadialSpeed2d { beacon: fr.beacon, known_speed_m_s: None, dz_m: 0.0, var: t.r_doppler_m2_s2 };
        let doppler = CarriedDoppler { doppler, current: layout.current };
        match (range_m, fr.radial_speed_m_s) {
            (None, None) => update(f, &self.inertial, [heading, yaw_rate, accel]),
            (Some(r), None) => {
                let models: [&dyn ScalarModel<N>; 4] = [&range, heading_m, yaw_rate_m, accel_m];
                update(f, &models, [r, heading, yaw_rate, accel])
            }
            (None, Some(v)) => {
                let models: [&dyn ScalarModel<N>; 4] = [&doppler, heading_m, yaw_rate_m, accel_m];
                update(f, &models, [v, heading, yaw_rate, accel])
            }
            (Some(r), Some(v)) => {
                let models: [&dyn ScalarModel<N>; 5] = [&range, &doppler, heading_m, yaw_rate_m, accel_m]; // eq. 18, 20
                update(f, &models, [r, v, heading, yaw_rate, accel])
            }
        }
    }
}

/// One update of `filter` with the stacked `models` and their values `z`.
fn update<const N: usize, const M: usize, H: MeasurementModel<N, M>>(
    filter: &mut AnyFilter<N>,
    models: &H,
    z: [f64; M],
) -> Result<Gated, FilterError> {
    let r = models.covariance(filter.mean());
    filter.update_gated(models, &SVector::from(z), &r, f64::INFINITY)
}

impl<const N: usize, P: ProcessModel<N> + Send> Navigator for SingleBeaconNavigator<N, P> {
    fn process(&mut self, m: &Measurement) -> Outcome {
        match m.kind {
            Kind::Inertial { heading_rad, yaw_rate_rad_s, accel_m_s2 } => {
                let nis = self.tick(m.t_s, heading_rad, yaw_rate_rad_s, accel_m_s2);
                self.unmirror();
                self.floor_speed();
                match nis {
                    Ok(g) => Outcome::Accepted(g.innovation()),
                    Err(e) => Outcome::Failed(e),
                }
            }
            Kind::Range { beacon, range_m } if self.aiding.range => {
                self.hold(beacon.position_ned_m.xy(), Some(range_m), None)
            }
            Kind::Doppler { beacon, radial_speed_m_s } if self.aiding.doppler => {
                self.hold(beacon.position_ned_m.xy(), None, Some(radial_speed_m_s))
            }
            Kind::RangeDoppler { beacon, range_m, radial_speed_m_s } if self.aiding.any() => {
                self.hold(beacon.position_ned_m.xy(), Some(range_m), Some(radial_speed_m_s))
            }
            _ => Outcome::Skipped,
        }
    }

    fn estimate(&self) -> Estimate {
        let (x, p) = (self.filter.mean(), self.filter.covariance());
        Estimate {
            t_s: self.t_s,
            position_ned_m: Vector3::new(x[idx::X], x[idx::Y], 0.0),
            horizontal_cov_m2: p.fixed_view::<2, 2>(0, 0).into_owned(),
            heading_state_rad: x[idx::PSI],
            heading_var_rad2: p[(idx::PSI, idx::PSI)],
            roll_pitch_rad: [0.0; 2],
            speed_m_s: Some(x[idx::V]),
            calibration: Calibration {
                range_bias_m: self.calibration.layout.offset.map(|i| x[i]),
                range_scale: self.calibration.layout.scale.map(|i| x[i]),
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
    use crate::nav::BeaconFix;
    use approx::assert_abs_diff_eq;
    use std::f64::consts::FRAC_PI_2;

    /// A vehicle heading east at 1 m/s from a wrong start position is pulled onto the
    /// truth by ranges and Doppler speeds from a beacon, faster than by ranges alone;
    /// with the EKF and with the UKF.
    #[test]
    fn range_doppler_corrects_a_speed_error_that_range_only_keeps_longer() {
        let beacon = Vector2::new(40.0, 0.0);
        let fix = BeaconFix::fixed(0, Vector3::new(beacon.x, beacon.y, 0.0));
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
        for kind in [FilterKind::Ekf, FilterKind::Ukf(UkfParams::default())] {
            let mut filters = [
                SingleBeaconNavigator::new(Aiding::RANGE_DOPPLER, tuning, kind, 0.0, start, p0),
                SingleBeaconNavigator::new(Aiding::RANGE, tuning, kind, 0.0, start, p0),
                SingleBeaconNavigator::new(
                    Aiding { range: false, doppler: true, bearing: false },
                    tuning,
                    kind,
                    0.0,
                    start,
                    p0,
                ),
            ];
            let mut truth = truth0;
            let (mut speed_err, mut speed_err_sum) = ([0.0; 3], [0.0; 3]);
            let truth_model = UnicycleAccel::default();
            for k in 1..=120 {
                let t = k as f64 * dt;
                truth = truth_model.propagate(&truth, dt);
                let frame = (k % 12 == 0).then(|| Kind::RangeDoppler {
                    beacon: fix,
                    range_m: ScalarModel::<DIM>::predict(&Range2d { beacon, var: 0.0 }, &truth),
                    radial_speed_m_s: RadialSpeed2d { beacon, known_speed_m_s: None, dz_m: 0.0, var: 0.0 }
                        .predict(&truth),
                });
                let inertial = Kind::Inertial { heading_rad: FRAC_PI_2, yaw_rate_rad_s: 0.0, accel_m_s2: 0.0 };
                for (f, e) in filters.iter_mut().zip(speed_err.iter_mut()) {
                    if let Some(frame) = &frame {
                        assert_eq!(f.process(&Measurement::new(t, frame.clone())), Outcome::Applied);
                    }
                    assert!(matches!(f.process(&Measurement::new(t, inertial.clone())), Outcome::Accepted(..)));
                    *e = (f.state()[idx::V] - 1.0).abs();
                }
                for (sum, e) in speed_err_sum.iter_mut().zip(speed_err) {
                    *sum += e;
                }
            }
            assert!(speed_err[0] < 0.01, "{kind:?}: range+doppler speed error {}", speed_err[0]);
            // range-only keeps the speed error longer: a larger mean over the run
            assert!(speed_err_sum[0] < speed_err_sum[1], "{kind:?}: {speed_err_sum:?}");
            // Doppler alone observes the speed too
            assert!(speed_err[2] < 0.01, "{kind:?}: doppler-only speed error {}", speed_err[2]);
            let e = filters[0].estimate();
            assert_abs_diff_eq!(e.north_m(), truth[0], epsilon = 0.5);
            assert_abs_diff_eq!(e.east_m(), truth[1], epsilon = 0.5);
        }
    }

    /// Started on the mirror image of the truth through the beacon (driving backwards),
    /// the published filter stays there: ranges, Doppler speeds and heading agree with
    /// it. With mirror recovery it is reflected back onto the truth.
    #[test]
    fn a_state_driving_backwards_is_reflected_back_through_the_beacon() {
        let beacon = Vector2::new(40.0, 0.0);
        let fix = BeaconFix::fixed(0, Vector3::new(beacon.x, beacon.y, 0.0));
        let truth0 = State::from([0.0, 0.0, FRAC_PI_2, 1.0, 0.0, 0.0]);
        let mut mirror = truth0;
        mirror[idx::X] = 2.0 * beacon.x;
        mirror[idx::V] = -1.0;
        let p0 = Cov::from_diagonal(&SVector::from([1.0, 1.0, 1e-3, 0.01, 1e-4, 1e-4]));
        let tuning = EkfTuning { q_diag: [1e-4, 1e-4, 1e-6, 1e-4, 1e-6, 1e-6], ..EkfTuning::default() };
        let ends: Vec<f64> = [false, true]
            .into_iter()
            .map(|recover| {
                let mut nav =
                    SingleBeaconNavigator::new(Aiding::RANGE_DOPPLER, tuning, FilterKind::Ekf, 0.0, mirror, p0)
                        .with_mirror_recovery(recover);
                let model = UnicycleAccel::default();
                let mut truth = truth0;
                for k in 1..=80 {
                    let t = k as f64 * 0.25;
                    truth = model.propagate(&truth, 0.25);
                    if k % 12 == 0 {
                        let frame = Kind::RangeDoppler {
                            beacon: fix,
                            range_m: ScalarModel::<DIM>::predict(&Range2d { beacon, var: 0.0 }, &truth),
                            radial_speed_m_s: RadialSpeed2d { beacon, known_speed_m_s: None, dz_m: 0.0, var: 0.0 }
                                .predict(&truth),
                        };
                        nav.process(&Measurement::new(t, frame));
                    }
                    let inertial = Kind::Inertial { heading_rad: FRAC_PI_2, yaw_rate_rad_s: 0.0, accel_m_s2: 0.0 };
                    nav.process(&Measurement::new(t, inertial));
                }
                let e = nav.estimate();
                (e.position_ned_m.xy() - truth.fixed_rows::<2>(0)).norm()
            })
            .collect();
        assert!(ends[0] > 50.0, "the published filter stays on the mirror: {} m", ends[0]);
        assert!(ends[1] < 0.5, "recovered: {} m", ends[1]);
    }

    /// A speed under the floor is projected onto it, the correlated states moving by
    /// P e_v (v_min - v) / P_vv (the closed form of the projection), P unchanged; a
    /// speed above the floor, or clearly negative (the mirror's), is left alone.
    #[test]
    fn a_speed_under_the_floor_is_projected_with_its_correlated_states() {
        let x0 = State::from([3.0, -2.0, 0.4, 0.2, 0.01, 0.0]);
        let mut p0 = Cov::from_diagonal(&SVector::from([4.0, 9.0, 0.01, 0.04, 1e-4, 1e-4]));
        // along-track position and speed correlated (rho 0.5), heading a little
        p0[(idx::X, idx::V)] = 0.2;
        p0[(idx::V, idx::X)] = 0.2;
        p0[(idx::PSI, idx::V)] = -0.005;
        p0[(idx::V, idx::PSI)] = -0.005;
        let nav = |x: State| {
            SingleBeaconNavigator::new(Aiding::RANGE_DOPPLER, EkfTuning::default(), FilterKind::Ekf, 0.0, x, p0)
                .with_min_speed(Some(0.5))
        };
        let mut n = nav(x0);
        n.floor_speed();
        let x = n.state();
        // (0.5 - 0.2) / 0.04 = 7.5 per unit of P's v column
        assert_abs_diff_eq!(x[idx::V], 0.5, epsilon = 1e-12);
        assert_abs_diff_eq!(x[idx::X], 3.0 + 0.2 * 7.5, epsilon = 1e-12);
        assert_abs_diff_eq!(x[idx::Y], -2.0, epsilon = 1e-12);
        assert_abs_diff_eq!(x[idx::PSI], 0.4 - 0.005 * 7.5, epsilon = 1e-12);
        assert_eq!(*n.filter.covariance(), p0);
        for v in [0.7, -0.3] {
            let mut x = x0;
            x[idx::V] = v;
            let mut n = nav(x);
            n.floor_speed();
            assert_eq!(*n.state(), x, "v = {v}");
        }
    }
}
