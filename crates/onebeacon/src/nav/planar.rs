//! Planar navigation for logs and live streams: dead reckoning from odometry increments
//! (wheels, DVL) or a forward speed, corrected by ranges and Doppler speeds to beacons
//! at known positions and by heading fixes. The filter behind `onebeacon replay` and
//! `onebeacon stream`; it runs as measurements arrive, one at a time.
//!
//! State [N, E, psi, b, k_r, k_d, k_t]: horizontal NED position (m), heading from
//! north toward east (rad), the range sensor's offset b (m) and scale error k_r (ranges
//! read (1 + k_r) r + b: a latency, a wrong propagation speed), and the odometry's
//! scale errors: true distance = (1 + k_d) x measured (wheel radius, DVL scale), true
//! heading change = (1 + k_t) x measured (wheel base, gyro scale). The extended state
//! ([`EXTENDED_STATES`]) adds the heading sensor's offset h (heading fixes read psi + h:
//! a compass's bias, an AHRS's slow error; a first-order Gauss-Markov process) and the
//! water's current [c_N, c_E] (a random walk that carries the position: for motion
//! inputs through the water, a propeller's or a DVL's water track). The vehicle's depth is a
//! known input (pressure sensor) that enters slant ranges. A component that is not
//! estimated stays at its configured value with zero variance, so one filter serves
//! every combination. Doppler speeds are not scaled by k_r (acoustic Doppler speeds share
//! the sound-speed error; modelling that is left for when a log needs it).

use super::Calibration;
use super::capability::{BeaconOffsets, Smoothing, Weighing};
pub use super::planar_config::{HeadingOffsetPrior, PlanarConfig, PlanarNoise};
use super::planar_models::{Drift, OdometryStep, OffsetHeading};
use super::range_calibration::CarriedDoppler;
use super::{BeaconFix, Estimate, Innovation, Kind, Measurement, Navigator, Outcome};
use crate::filter::rts::History;
use crate::filter::{AnyFilter, FilterKind, GaussianFilter, ProcessModel};
use crate::geo::wrap_angle;
use crate::measure::{RadialSpeed2d, ScalarModel, SlantRange, StateComponent};
use nalgebra::{Matrix2, SMatrix, SVector, Vector1, Vector2, Vector3};

/// Number of state components.
pub const STATES: usize = 7;
/// The state size with the heading offset and the current ([`idx::HEADING_OFFSET`],
/// [`idx::CURRENT_N`], [`idx::CURRENT_E`]).
pub const EXTENDED_STATES: usize = STATES + 3;
/// Most beacons with an offset of their own ([`PlanarConfig::estimate_beacon_offsets`]):
/// the states after the first [`EXTENDED_STATES`], taken by beacons in the order they
/// are heard.
pub const BEACON_OFFSETS: usize = 8;
/// The state size with per-beacon offsets.
pub const STATES_WITH_OFFSETS: usize = EXTENDED_STATES + BEACON_OFFSETS;
type State<const N: usize> = SVector<f64, N>;
type Cov<const N: usize> = SMatrix<f64, N, N>;

pub use super::planar_models::idx;

/// The navigator: an EKF or UKF over [N, E, psi, b, k_r, k_d, k_t] (with `N` =
/// [`EXTENDED_STATES`], the heading offset and the current too; with
/// [`STATES_WITH_OFFSETS`], an offset per beacon after them) with the held inputs (speed,
/// depth).
#[derive(Debug, Clone, PartialEq)]
pub struct PlanarNavigator<const N: usize = STATES> {
    pub config: PlanarConfig,
    filter: AnyFilter<N>,
    /// The beacon of each offset state after the first [`EXTENDED_STATES`], in the order
    /// heard.
    offset_beacons: Vec<u32>,
    t_s: f64,
    /// Latest forward-speed input, and whether it drives the motion between events.
    speed_m_s: f64,
    coasting: bool,
    /// The last speed input was a stopped propeller's ([`PlanarConfig::speed_coast_time_s`]).
    propeller_stopped: bool,
    /// With a body velocity (a DVL): its starboard speed and yaw rate, held with the
    /// forward speed.
    lateral_m_s: f64,
    yaw_rate_rad_s: f64,
    last_odometry_s: Option<f64>,
    depth_m: f64,
    /// The gate of ranges and Doppler speeds (`config.nis_gate`).
    gate: super::Gate,
    /// The predictions kept for a Rauch-Tung-Striebel pass, with the depth of each
    /// interval between them ([`Navigator::keep_history`]).
    history: Option<(History<N>, Vec<f64>)>,
}

impl PlanarNavigator {
    /// Starts at time `t_s` from position (`north_m`, `east_m`) and `heading_rad`, with
    /// standard deviations `sigma_position_m` (each axis) and `sigma_heading_rad`.
    pub fn new(
        config: PlanarConfig,
        filter: FilterKind,
        t_s: f64,
        pose: (f64, f64, f64),
        sigma_position_m: f64,
        sigma_heading_rad: f64,
    ) -> Self {
        Self::with_layout(config, filter, t_s, pose, (sigma_position_m, sigma_heading_rad))
    }
}

impl<const N: usize> PlanarNavigator<N> {
    /// The heading offset's mean and variance (rad, rad^2; zeros in the core layout).
    pub fn heading_offset(&self) -> (f64, f64) {
        if N < EXTENDED_STATES {
            return (0.0, 0.0);
        }
        let i = idx::HEADING_OFFSET;
        (self.filter.mean()[i], self.filter.covariance()[(i, i)])
    }

    /// The current's mean and covariance (north, east; m/s; zeros in the core layout).
    pub fn current(&self) -> (Vector2<f64>, Matrix2<f64>) {
        if N < EXTENDED_STATES {
            return (Vector2::zeros(), Matrix2::zeros());
        }
        let (x, p) = (self.filter.mean(), self.filter.covariance());
        (
            x.fixed_rows::<2>(idx::CURRENT_N).into_owned(),
            p.fixed_view::<2, 2>(idx::CURRENT_N, idx::CURRENT_N).into_owned(),
        )
    }
}

impl<const N: usize> PlanarNavigator<N> {
    /// [`PlanarNavigator::new`] in layout `N`: [`STATES`] (the core), [`EXTENDED_STATES`]
    /// (with the heading offset and the current, [`PlanarConfig::heading_offset`] and
    /// [`PlanarConfig::current`]: either one's states stay at zero with zero variance
    /// when it is None) or [`STATES_WITH_OFFSETS`] (and an offset per beacon,
    /// [`PlanarConfig::estimate_beacon_offsets`], each starting at `bias_m` with
    /// `bias_sigma_m`).
    pub fn with_layout(
        config: PlanarConfig,
        filter: FilterKind,
        t_s: f64,
        (north_m, east_m, heading_rad): (f64, f64, f64),
        (sigma_position_m, sigma_heading_rad): (f64, f64),
    ) -> Self {
        let sigma_if = |on: bool, sigma: f64| if on { sigma } else { 0.0 };
        debug_assert!(N == STATES || N >= EXTENDED_STATES, "the layouts are 7, {EXTENDED_STATES} and more");
        debug_assert!(N > STATES || !config.extended(), "a heading offset or a current needs the extended layout");
        // the core layout has neither ([`builder`] picks the layout a config needs)
        let mut config = config;
        if N < EXTENDED_STATES {
            (config.heading_offset, config.current) = (None, None);
        }
        let offsets = config.estimate_beacon_offsets && N > EXTENDED_STATES;
        let mut sigmas = State::<N>::repeat(sigma_if(offsets, config.bias_sigma_m));
        if N >= EXTENDED_STATES {
            let current = config.current.map_or(0.0, |c| c.sigma_m_s);
            sigmas.fixed_rows_mut::<3>(STATES).copy_from_slice(&[
                config.heading_offset.map_or(0.0, |h| h.sigma_rad),
                current,
                current,
            ]);
        }
        sigmas.fixed_rows_mut::<STATES>(0).copy_from_slice(&[
            sigma_position_m,
            sigma_position_m,
            sigma_heading_rad,
            sigma_if(config.estimate_bias, config.bias_sigma_m),
            sigma_if(config.estimate_range_scale, config.range_scale_sigma),
            sigma_if(config.estimate_distance_scale, config.distance_scale_sigma),
            sigma_if(config.estimate_turn_scale, config.turn_scale_sigma),
        ]);
        let p = Cov::<N>::from_diagonal(&sigmas.component_mul(&sigmas));
        let mut x = State::<N>::repeat(config.bias_m);
        if N >= EXTENDED_STATES {
            x.fixed_rows_mut::<3>(STATES).fill(0.0);
        }
        x.fixed_rows_mut::<STATES>(0).copy_from_slice(&[
            north_m,
            east_m,
            wrap_angle(heading_rad),
            config.bias_m,
            0.0,
            0.0,
            0.0,
        ]);
        Self {
            gate: super::Gate::new(config.nis_gate.unwrap_or(f64::INFINITY)),
            config,
            filter: AnyFilter::new(filter, x, p),
            offset_beacons: Vec::new(),
            t_s,
            speed_m_s: 0.0,
            coasting: false,
            propeller_stopped: false,
            lateral_m_s: 0.0,
            yaw_rate_rad_s: 0.0,
            last_odometry_s: None,
            depth_m: 0.0,
            history: None,
        }
    }

    /// A gated correction (ranges, Doppler speeds), or an ungated one (heading fixes).
    fn correct(&mut self, model: &dyn ScalarModel<N>, z: f64, gated: bool) -> Outcome {
        let z = Vector1::new(z);
        match gated {
            true => self.gate.update(&mut self.filter, &[model], z, self.config.robust),
            false => super::gated_update(&mut self.filter, &[model], z, f64::INFINITY, self.config.robust),
        }
    }

    /// Moves the clock to `t_s`: coasts at the held speed, lets the bias (and, with a
    /// position random walk, the position) wander.
    fn advance_to(&mut self, t_s: f64) {
        let dt = (t_s - self.t_s).max(0.0);
        self.t_s = self.t_s.max(t_s);
        if dt == 0.0 {
            return;
        }
        if self.coasting {
            // the held body velocity over dt: an SE(2) step at the mid heading (exact on
            // a circle), the speed error on each axis
            // a constant body velocity turning at r traces a circle: its chord is the arc
            // (u, v) dt times sinc(r dt / 2), along the mid heading
            let half = self.yaw_rate_rad_s * dt / 2.0;
            let chord = if half.abs() < 1e-9 { 1.0 } else { half.sin() / half };
            let sigma = self.config.noise.speed_sigma_m_s * dt;
            // a stopped propeller: the held speed decays over dt, the mean speed is its
            // integral's
            let (mut u, mut v) = (self.speed_m_s, self.lateral_m_s);
            if let Some(tau) = self.config.speed_coast_time_s.filter(|_| self.propeller_stopped) {
                let keep = (-dt / tau).exp();
                let mean = tau * (1.0 - keep) / dt;
                (u, v) = (u * mean, v * mean);
                (self.speed_m_s, self.lateral_m_s) = (self.speed_m_s * keep, self.lateral_m_s * keep);
            }
            let (d, lat) = (u * dt * chord, v * dt * chord);
            self.motion(d, lat, 2.0 * half, sigma, sigma);
        }
        let n = self.config.noise;
        let q_bias = n.bias_walk_m_per_sqrt_s.powi(2) * dt;
        let mut q = Cov::<N>::zeros();
        if self.config.estimate_bias {
            q[(idx::BIAS, idx::BIAS)] = q_bias;
        }
        for i in EXTENDED_STATES..EXTENDED_STATES + self.offset_beacons.len() {
            q[(i, i)] = q_bias;
        }
        let q_walk = n.position_walk_m_per_sqrt_s.powi(2) * dt;
        (q[(idx::N, idx::N)], q[(idx::E, idx::E)]) = (q_walk, q_walk);
        if !self.config.extended() {
            if q != Cov::<N>::zeros() {
                self.diffuse(&q);
            }
            return;
        }
        // the current carries the position; the heading offset decays toward zero
        let decay = self.config.heading_offset.map_or(1.0, |h| (-dt / h.time_s).exp());
        if let Some(h) = self.config.heading_offset {
            q[(idx::HEADING_OFFSET, idx::HEADING_OFFSET)] = h.sigma_rad.powi(2) * (1.0 - decay * decay);
        }
        if let Some(c) = self.config.current {
            let q_current = c.walk_m_s_per_sqrt_s.powi(2) * dt;
            (q[(idx::CURRENT_N, idx::CURRENT_N)], q[(idx::CURRENT_E, idx::CURRENT_E)]) = (q_current, q_current);
        }
        self.predict(&Drift { dt, decay }, &q);
    }

    /// Noise `q` added to the covariance, the mean as it was: a prediction through the
    /// identity, its cross covariance the covariance before.
    fn diffuse(&mut self, q: &Cov<N>) {
        let before = (*self.filter.mean(), *self.filter.covariance());
        *self.filter.covariance_mut() += q;
        let cross = before.1;
        self.keep(before, cross);
    }

    /// A prediction through `model` with noise `q`.
    fn predict(&mut self, model: &impl ProcessModel<N>, q: &Cov<N>) {
        if self.history.is_none() {
            return self.filter.predict(model, 0.0, q);
        }
        let before = (*self.filter.mean(), *self.filter.covariance());
        let cross = self.filter.predict_cross(model, 0.0, q);
        self.keep(before, cross);
    }

    /// The prediction just made from `before`, with its cross covariance, in the
    /// history when one is kept.
    fn keep(&mut self, before: (State<N>, Cov<N>), cross: Cov<N>) {
        if let Some((history, depths)) = &mut self.history {
            history.push(self.t_s, before, (*self.filter.mean(), *self.filter.covariance()), cross);
            depths.push(self.depth_m);
        }
    }

    /// The estimate of mean `x` and covariance `p` at `t_s` and depth `depth_m`.
    fn estimate_of(c: &PlanarConfig, t_s: f64, x: &State<N>, p: &Cov<N>, depth_m: f64) -> Estimate {
        Estimate {
            t_s,
            position_ned_m: Vector3::new(x[idx::N], x[idx::E], depth_m),
            horizontal_cov_m2: p.fixed_view::<2, 2>(0, 0).into_owned(),
            heading_state_rad: x[idx::PSI],
            heading_var_rad2: p[(idx::PSI, idx::PSI)],
            roll_pitch_rad: [0.0; 2],
            speed_m_s: None,
            calibration: Calibration {
                range_bias_m: c.estimate_bias.then_some(x[idx::BIAS]),
                range_scale: c.estimate_range_scale.then_some(x[idx::RANGE_SCALE]),
                distance_scale: c.estimate_distance_scale.then_some(x[idx::DISTANCE_SCALE]),
                turn_scale: c.estimate_turn_scale.then_some(x[idx::TURN_SCALE]),
                usbl_misalignment_rad: None,
                current_ned_m_s: (c.current.is_some() && N >= EXTENDED_STATES)
                    .then(|| [x[idx::CURRENT_N], x[idx::CURRENT_E]]),
            },
        }
    }

    /// An odometry increment at `t_s` (forward `d`, lateral `lat`, turn `dpsi`), each
    /// distance with the configured fraction of itself as its error; the forward speed
    /// it implies is held for Doppler, and coasting stops.
    fn odometry(&mut self, t_s: f64, d: f64, lat: f64, dpsi: f64) -> Outcome {
        if let Some(t0) = self.last_odometry_s.filter(|t0| t_s > *t0) {
            self.speed_m_s = d / (t_s - t0);
        }
        self.last_odometry_s = Some(t_s);
        self.coasting = false;
        let frac = self.config.noise.distance_sigma_frac;
        self.motion(d, lat, dpsi, frac * d.abs(), frac * lat.abs());
        Outcome::Applied
    }

    /// Forward `d` and starboard `lat` increments with a heading change `dpsi` and the
    /// errors of the two increments.
    fn motion(&mut self, d: f64, lat: f64, dpsi: f64, sigma_d: f64, sigma_lat: f64) {
        let step = OdometryStep { d, lat, dpsi, sigma_d, sigma_lat, noise: self.config.noise };
        let q = step.noise_covariance(self.filter.mean(), 0.0);
        self.predict(&step, &q);
    }

    /// The slant-range model to `beacon` with this navigator's offset and scale states:
    /// the beacon's own offset when it has one (a state is taken when a beacon is first
    /// heard, while there are free ones), the shared one otherwise.
    fn range_model(&mut self, beacon: &BeaconFix) -> SlantRange {
        let var = self.config.noise.range_sigma_m * self.config.noise.range_sigma_m;
        let mut bias = idx::BIAS;
        if self.config.estimate_beacon_offsets {
            let slot = self.offset_beacons.iter().position(|&b| b == beacon.id);
            let slot = slot.or_else(|| {
                (EXTENDED_STATES + self.offset_beacons.len() < N).then(|| {
                    self.offset_beacons.push(beacon.id);
                    self.offset_beacons.len() - 1
                })
            });
            bias = slot.map_or(idx::BIAS, |i| EXTENDED_STATES + i);
        }
        let beacon = beacon.position_ned_m;
        SlantRange { beacon, depth_m: self.depth_m, bias: Some(bias), scale: Some(idx::RANGE_SCALE), var }
    }

    /// The radial speed toward `beacon` over ground along the slant line of sight (the
    /// smoother's [`crate::measure::LineOfSightSpeed`]): the held speed along the heading,
    /// plus the current's share when it is a state.
    fn doppler_model(&self, beacon: Vector3<f64>) -> CarriedDoppler {
        let var = self.config.noise.doppler_sigma_m_s * self.config.noise.doppler_sigma_m_s;
        let (known_speed_m_s, dz_m) = (Some(self.speed_m_s), self.depth_m - beacon.z);
        let doppler = RadialSpeed2d { beacon: beacon.xy(), known_speed_m_s, dz_m, var };
        CarriedDoppler { doppler, current: self.config.current.map(|_| idx::CURRENT_N) }
    }
}

impl<const N: usize> BeaconOffsets for PlanarNavigator<N> {
    fn offsets(&self) -> Vec<(u32, f64, f64)> {
        let (x, p) = (self.filter.mean(), self.filter.covariance());
        let slot = |i: usize| EXTENDED_STATES + i;
        self.offset_beacons.iter().enumerate().map(|(i, &b)| (b, x[slot(i)], p[(slot(i), slot(i))].sqrt())).collect()
    }
}

/// Whatever the aiding (dead reckoning's prediction is the baseline of a held-out
/// beacon), with the beacon's own offset state where it would have one.
impl<const N: usize> Weighing for PlanarNavigator<N> {
    fn weigh(&mut self, m: &Measurement) -> Option<Innovation> {
        let Kind::Range { beacon, range_m } = m.kind else { return None };
        self.advance_to(m.t_s);
        let model = self.range_model(&beacon);
        super::gated_update(&mut self.filter, &[&model as &dyn ScalarModel<N>], Vector1::new(range_m), -1.0, None)
            .innovation()
    }
}

impl<const N: usize> Smoothing for PlanarNavigator<N> {
    fn keep_history(&mut self) {
        self.history = Some((History::new(self.t_s), vec![self.depth_m]));
    }

    fn smoothed(&self) -> Vec<Estimate> {
        let Some((history, depths)) = &self.history else { return Vec::new() };
        let last = (*self.filter.mean(), *self.filter.covariance());
        let smoothed = history.smooth(last, |k| k == idx::PSI || (N > STATES && k == idx::HEADING_OFFSET));
        smoothed.iter().zip(depths).map(|((t, (x, p)), d)| Self::estimate_of(&self.config, *t, x, p, *d)).collect()
    }
}

impl<const N: usize> Navigator for PlanarNavigator<N> {
    /// Each beacon heard with its estimated offset and the offset's standard deviation
    /// (with [`PlanarConfig::estimate_beacon_offsets`]).
    fn beacon_offsets(&self) -> Option<&dyn BeaconOffsets> {
        (self.config.estimate_beacon_offsets && N > EXTENDED_STATES).then_some(self as &dyn BeaconOffsets)
    }

    fn weighing(&mut self) -> Option<&mut dyn Weighing> {
        Some(self)
    }

    /// Dead reckoning (no beacon aiding) has no correction to carry back: it keeps none.
    fn smoothing(&mut self) -> Option<&mut dyn Smoothing> {
        self.config.aiding.any().then_some(self as &mut dyn Smoothing)
    }

    /// Processes one measurement (measurements in time order; an earlier time is taken
    /// as now).
    fn process(&mut self, m: &Measurement) -> Outcome {
        let t_s = m.t_s;
        self.advance_to(t_s);
        let noise = self.config.noise;
        let aiding = self.config.aiding;
        match m.kind {
            Kind::Odometry { distance_m, heading_change_rad } => {
                self.odometry(t_s, distance_m, 0.0, heading_change_rad)
            }
            Kind::BodyOdometry { forward_m, lateral_m, heading_change_rad } => {
                self.odometry(t_s, forward_m, lateral_m, heading_change_rad)
            }
            Kind::Speed { speed_m_s } => {
                self.propeller_stopped = speed_m_s == 0.0 && self.config.speed_coast_time_s.is_some();
                if !self.propeller_stopped {
                    (self.speed_m_s, self.lateral_m_s) = (speed_m_s, 0.0);
                }
                self.yaw_rate_rad_s = 0.0;
                self.coasting = true;
                Outcome::Applied
            }
            Kind::BodyVelocity { nu } => {
                (self.speed_m_s, self.lateral_m_s, self.yaw_rate_rad_s) = (nu[0], nu[1], nu[5]);
                (self.coasting, self.propeller_stopped) = (true, false);
                Outcome::Applied
            }
            Kind::Depth { depth_m } => {
                self.depth_m = depth_m;
                Outcome::Applied
            }
            Kind::Heading { heading_rad } | Kind::Attitude { heading_rad, .. } => {
                let var = noise.heading_sigma_rad * noise.heading_sigma_rad;
                match self.config.heading_offset {
                    Some(_) => self.correct(&OffsetHeading { var }, heading_rad, false),
                    None => self.correct(&StateComponent::angle(idx::PSI, var), heading_rad, false),
                }
            }
            Kind::Range { beacon, range_m } if aiding.range => {
                let model = self.range_model(&beacon);
                self.correct(&model, range_m, true)
            }
            Kind::Doppler { beacon, radial_speed_m_s } if aiding.doppler => {
                let model = self.doppler_model(beacon.position_ned_m);
                self.correct(&model, radial_speed_m_s, true)
            }
            Kind::RangeDoppler { beacon, range_m, radial_speed_m_s } if aiding.any() => {
                let range = if aiding.range {
                    let model = self.range_model(&beacon);
                    self.correct(&model, range_m, true)
                } else {
                    Outcome::Skipped
                };
                let doppler = if aiding.doppler {
                    self.correct(&self.doppler_model(beacon.position_ned_m), radial_speed_m_s, true)
                } else {
                    Outcome::Skipped
                };
                // the worse of the two outcomes
                match (range, doppler) {
                    (Outcome::Failed(e), _) | (_, Outcome::Failed(e)) => Outcome::Failed(e),
                    (Outcome::Rejected(i), _) | (_, Outcome::Rejected(i)) => Outcome::Rejected(i),
                    (Outcome::Skipped, b) => b,
                    (a, _) => a,
                }
            }
            _ => Outcome::Skipped,
        }
    }

    fn estimate(&self) -> Estimate {
        Self::estimate_of(&self.config, self.t_s, self.filter.mean(), self.filter.covariance(), self.depth_m)
    }
}

/// The navigator a [`PlanarConfig`] describes, as a session builds it
/// ([`super::restart::Builder`]): the constant-velocity tracker of a craft without motion
/// inputs (`track_accel_sigma_m_s2`), the planar navigator with an offset per beacon, or
/// the planar navigator.
pub fn builder(c: PlanarConfig, f: FilterKind) -> super::restart::Builder {
    Box::new(move |t0, pose, sigma_position_m, sigma_heading_rad| match c.track_accel_sigma_m_s2 {
        Some(a) => Box::new(super::TrackingNavigator::new(c, a, f, t0, (pose.0, pose.1), sigma_position_m)),
        None if c.estimate_beacon_offsets => Box::new(PlanarNavigator::<STATES_WITH_OFFSETS>::with_layout(
            c,
            f,
            t0,
            pose,
            (sigma_position_m, sigma_heading_rad),
        )),
        None if c.extended() => Box::new(PlanarNavigator::<EXTENDED_STATES>::with_layout(
            c,
            f,
            t0,
            pose,
            (sigma_position_m, sigma_heading_rad),
        )),
        None => Box::new(PlanarNavigator::new(c, f, t0, pose, sigma_position_m, sigma_heading_rad)),
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::nav::session::Input;
    use crate::nav::{Aiding, BeaconFix};
    use approx::assert_abs_diff_eq;
    use std::f64::consts::FRAC_PI_2;

    fn start(config: PlanarConfig) -> PlanarNavigator {
        PlanarNavigator::new(config, FilterKind::Ekf, 0.0, (0.0, 0.0, 0.0), 0.0, 0.0)
    }

    #[test]
    fn odometry_integrates_a_quarter_circle() {
        // 100 increments along a quarter circle of radius 10 m: chord steps at the
        // mid-increment heading land exactly on the arc's end (10, 10)
        let mut nav = start(PlanarConfig::default());
        let (k, r) = (100, 10.0);
        let dpsi = FRAC_PI_2 / k as f64;
        let chord = 2.0 * r * (dpsi / 2.0).sin();
        for i in 0..k {
            assert_eq!(
                nav.process(&Measurement::new(
                    i as f64,
                    Kind::Odometry { distance_m: chord, heading_change_rad: dpsi }
                )),
                Outcome::Applied
            );
        }
        let e = nav.estimate();
        assert_abs_diff_eq!(e.north_m(), 10.0, epsilon = 1e-9);
        assert_abs_diff_eq!(e.east_m(), 10.0, epsilon = 1e-9);
        assert_abs_diff_eq!(e.heading_rad(), FRAC_PI_2, epsilon = 1e-12);
        // uncertainty grew with distance, the bias stayed known
        assert!(e.sigma_north_m() > 0.0 && e.sigma_east_m() > 0.0);
        assert_eq!(nav.filter.covariance()[(idx::BIAS, idx::BIAS)], 0.0);
    }

    /// The covariance step equals the Jacobians (F, G) of the motion taken by finite
    /// differences, with every state estimated and nonzero scale errors.
    #[test]
    fn motion_covariance_matches_finite_differences() {
        let config = PlanarConfig {
            estimate_bias: true,
            estimate_range_scale: true,
            estimate_distance_scale: true,
            estimate_turn_scale: true,
            ..PlanarConfig::default()
        };
        let mut nav = PlanarNavigator::new(config, FilterKind::Ekf, 0.0, (3.0, -2.0, 0.8), 1.0, 0.1);
        nav.filter.mean_mut()[idx::RANGE_SCALE] = 0.07;
        nav.filter.mean_mut()[idx::DISTANCE_SCALE] = 0.03;
        nav.filter.mean_mut()[idx::TURN_SCALE] = -0.05;
        let p0 = *nav.filter.covariance();
        let x0 = *nav.filter.mean();
        // forward, lateral (starboard) and turn increments, with their errors
        let u0 = Vector3::new(1.7, -0.4, 0.3);
        nav.motion(u0[0], u0[1], u0[2], 0.1, 0.05);
        // the step written out on its own: the increment rotated by the mid heading
        let step = |x: State<STATES>, u: Vector3<f64>| {
            let (d, lat, dpsi) = ((1.0 + x[5]) * u[0], (1.0 + x[5]) * u[1], (1.0 + x[6]) * u[2]);
            let m = x[2] + dpsi / 2.0;
            let (n, e) = (d * m.cos() - lat * m.sin(), d * m.sin() + lat * m.cos());
            State::<STATES>::from([x[0] + n, x[1] + e, x[2] + dpsi, x[3], x[4], x[5], x[6]])
        };
        let eps = 1e-6;
        let f = Cov::<STATES>::from_fn(|i, j| {
            let mut e = State::<STATES>::zeros();
            e[j] = eps;
            (step(x0 + e, u0)[i] - step(x0 - e, u0)[i]) / (2.0 * eps)
        });
        let g = SMatrix::<f64, STATES, 3>::from_fn(|i, j| {
            let mut du = Vector3::zeros();
            du[j] = eps;
            (step(x0, u0 + du)[i] - step(x0, u0 - du)[i]) / (2.0 * eps)
        });
        let n = config.noise;
        let q = SMatrix::<f64, 3, 3>::from_diagonal(&Vector3::new(
            0.01,
            0.0025,
            (n.heading_change_sigma_frac * u0[2]).powi(2) + n.heading_walk_rad_per_sqrt_m.powi(2) * u0[0].hypot(u0[1]),
        ));
        let expected = f * p0 * f.transpose() + g * q * g.transpose();
        assert_abs_diff_eq!(*nav.filter.covariance(), expected, epsilon = 1e-8);
        assert_abs_diff_eq!(*nav.filter.mean(), step(x0, u0), epsilon = 1e-12);
    }

    /// With no inputs at all, the position variance grows as sigma^2 t per axis under a
    /// position random walk (a closed form), and stays put without one.
    #[test]
    fn a_position_random_walk_grows_the_variance_with_time() {
        let mut config = PlanarConfig::default();
        config.noise.position_walk_m_per_sqrt_s = 0.3;
        let mut walk = PlanarNavigator::new(config, FilterKind::Ekf, 0.0, (0.0, 0.0, 0.0), 1.0, 0.1);
        let mut still = start(PlanarConfig::default());
        for nav in [&mut walk, &mut still] {
            nav.process(&Measurement::new(100.0, Kind::Depth { depth_m: 5.0 }));
        }
        let (w, s) = (walk.estimate(), still.estimate());
        assert_abs_diff_eq!(w.sigma_north_m().powi(2), 1.0 + 0.09 * 100.0, epsilon = 1e-9);
        assert_abs_diff_eq!(w.sigma_east_m().powi(2), 1.0 + 0.09 * 100.0, epsilon = 1e-9);
        assert_eq!(s.horizontal_cov_m2, start(PlanarConfig::default()).estimate().horizontal_cov_m2);
    }

    /// A vehicle heading east that crabs: body increments of 1 m forward and 0.2 m to
    /// starboard per step move it east and south (NED); distance-only odometry of the
    /// same forward increments loses the 0.2 m per step.
    #[test]
    fn body_odometry_keeps_the_sideways_part() {
        let east = (0.0, 0.0, FRAC_PI_2);
        let mut body = PlanarNavigator::new(PlanarConfig::default(), FilterKind::Ekf, 0.0, east, 1.0, 0.1);
        let mut distance = body.clone();
        for k in 1..=10 {
            let t = k as f64;
            body.process(&Measurement::new(
                t,
                Kind::BodyOdometry { forward_m: 1.0, lateral_m: 0.2, heading_change_rad: 0.0 },
            ));
            distance.process(&Measurement::new(t, Kind::Odometry { distance_m: 1.0, heading_change_rad: 0.0 }));
        }
        let (b, d) = (body.estimate(), distance.estimate());
        assert_abs_diff_eq!(b.east_m(), 10.0, epsilon = 1e-12);
        assert_abs_diff_eq!(b.north_m(), -2.0, epsilon = 1e-12);
        assert_abs_diff_eq!(d.north_m(), 0.0, epsilon = 1e-12);
        // and an ENU item (lateral to the left, turns counter-clockwise) converts to it
        let enu = Input::Measurement(Kind::BodyOdometry { forward_m: 1.0, lateral_m: -0.2, heading_change_rad: 0.1 });
        assert_eq!(
            enu.to_ned(crate::geo::Frame::Enu),
            Input::Measurement(Kind::BodyOdometry { forward_m: 1.0, lateral_m: 0.2, heading_change_rad: -0.1 })
        );
    }

    #[test]
    fn speed_input_coasts_between_events() {
        let mut nav = start(PlanarConfig::default());
        nav.process(&Measurement::new(0.0, Kind::Heading { heading_rad: 0.0 }));
        nav.process(&Measurement::new(0.0, Kind::Speed { speed_m_s: 1.5 }));
        nav.process(&Measurement::new(10.0, Kind::Depth { depth_m: 20.0 }));
        assert_abs_diff_eq!(nav.estimate().north_m(), 15.0, epsilon = 1e-12);
        assert_abs_diff_eq!(nav.estimate().t_s, 10.0);
        // coasting goes on until an odometry increment arrives, which ends it
        nav.process(&Measurement::new(11.0, Kind::Odometry { distance_m: 1.0, heading_change_rad: 0.0 }));
        nav.process(&Measurement::new(20.0, Kind::Depth { depth_m: 20.0 }));
        assert_abs_diff_eq!(nav.estimate().north_m(), 15.0 + 1.5 + 1.0, epsilon = 1e-12);
    }

    /// A static vehicle with unknown position and a biased range sensor, ranged from
    /// three beacons: the filter recovers position and bias; gating rejects an
    /// outlier; dead reckoning skips ranges.
    #[test]
    fn ranges_fix_position_and_bias_and_gate_outliers() {
        let truth = Vector3::new(12.0, -7.0, 30.0);
        let bias = 2.8;
        let beacons = [Vector3::new(0.0, 0.0, 0.0), Vector3::new(60.0, 10.0, 0.0), Vector3::new(-20.0, 50.0, 0.0)];
        let config = PlanarConfig { estimate_bias: true, nis_gate: Some(10.83), ..PlanarConfig::default() };
        let mut nav = PlanarNavigator::new(config, FilterKind::Ekf, 0.0, (0.0, 0.0, 0.3), 20.0, 0.1);
        nav.process(&Measurement::new(0.0, Kind::Depth { depth_m: truth.z }));
        let mut t = 0.0;
        for k in 0..600 {
            let b = beacons[k % 3];
            t += 1.0;
            let range_m = (truth - b).norm() + bias;
            let out =
                nav.process(&Measurement::new(t, Kind::Range { beacon: BeaconFix::fixed((k % 3) as u32, b), range_m }));
            assert!(matches!(out, Outcome::Accepted(..)), "{out:?}");
        }
        let e = nav.estimate();
        assert_abs_diff_eq!(e.north_m(), truth.x, epsilon = 0.1);
        assert_abs_diff_eq!(e.east_m(), truth.y, epsilon = 0.1);
        assert_abs_diff_eq!(e.calibration.range_bias_m.expect("estimated"), bias, epsilon = 0.1);
        let outlier = Kind::Range { beacon: BeaconFix::fixed(0, beacons[0]), range_m: truth.norm() + bias + 20.0 };
        let before = nav.estimate();
        assert!(matches!(nav.process(&Measurement::new(t, outlier.clone())), Outcome::Rejected(i) if i.nis > 10.83));
        assert_eq!(nav.estimate(), before);
        let mut dr = start(PlanarConfig { aiding: Aiding::NONE, ..PlanarConfig::default() });
        assert_eq!(dr.process(&Measurement::new(1.0, outlier)), Outcome::Skipped);
    }

    /// A vehicle whose odometry over-reports turns (true turn = 0.96 x measured,
    /// k_t = -0.04) and a range sensor that reads 7 % long plus 0.5 m, ranged from one
    /// beacon, noise-free: the calibrated filter recovers both scales, the offset and
    /// the track (2.8 cm worst error over the second half); without calibration states
    /// the error reaches 14 m.
    #[test]
    fn calibration_states_recover_turn_and_range_scale() {
        let (k_t, k_r, offset) = (-0.04, 0.07, 0.5);
        let beacon = Vector3::new(0.0, 0.0, 0.0);
        let run = |config: PlanarConfig| {
            let mut nav = PlanarNavigator::new(config, FilterKind::Ekf, 0.0, (-40.0, 0.0, 0.0), 0.5, 0.02);
            let (mut n, mut e, mut psi) = (-40.0_f64, 0.0_f64, 0.0_f64);
            let mut worst = 0.0_f64;
            for k in 1..=3000 {
                let t = k as f64 * 0.5;
                // weaving loops: 0.5 m steps, turn rate varying slowly
                let measured_dpsi = 0.03 * (k as f64 / 150.0).sin() + 0.01;
                let true_dpsi = (1.0 + k_t) * measured_dpsi;
                n += 0.5 * (psi + true_dpsi / 2.0).cos();
                e += 0.5 * (psi + true_dpsi / 2.0).sin();
                psi += true_dpsi;
                nav.process(&Measurement::new(
                    t,
                    Kind::Odometry { distance_m: 0.5, heading_change_rad: measured_dpsi },
                ));
                if k % 4 == 0 {
                    let range_m = (1.0 + k_r) * (Vector3::new(n, e, 0.0) - beacon).norm() + offset;
                    nav.process(&Measurement::new(t, Kind::Range { beacon: BeaconFix::fixed(0, beacon), range_m }));
                }
                let est = nav.estimate();
                if k > 1500 {
                    worst = worst.max((est.north_m() - n).hypot(est.east_m() - e));
                }
            }
            (nav.estimate(), worst)
        };
        let calibrated = PlanarConfig {
            estimate_bias: true,
            estimate_range_scale: true,
            estimate_turn_scale: true,
            noise: PlanarNoise {
                heading_walk_rad_per_sqrt_m: 1e-4,
                heading_change_sigma_frac: 0.005,
                ..PlanarNoise::default()
            },
            ..PlanarConfig::default()
        };
        let (est, worst) = run(calibrated);
        assert_abs_diff_eq!(est.calibration.turn_scale.expect("estimated"), k_t, epsilon = 0.001);
        assert_abs_diff_eq!(est.calibration.range_scale.expect("estimated"), k_r, epsilon = 0.002);
        assert_abs_diff_eq!(est.calibration.range_bias_m.expect("estimated"), offset, epsilon = 0.1);
        assert!(worst < 0.1, "calibrated: worst error over the second half {worst} m");
        let (_, worst_plain) = run(PlanarConfig { estimate_bias: true, ..PlanarConfig::default() });
        assert!(worst_plain > 5.0, "uncalibrated: {worst_plain} m");
    }

    /// Three beacons whose ranges carry offsets of their own (+3, +7.6 and -8.5 m, as on
    /// a real log), noise-free, a vehicle weaving among them on exact odometry:
    /// per-beacon offset states recover each offset to 0.1 m and hold the track to
    /// 0.3 m over the second half (7.8 cm measured); one shared offset cannot fit three
    /// and is pulled tens of metres off (43 m measured). A beacon heard after the slots
    /// are full uses the shared offset.
    #[test]
    fn per_beacon_offsets_recover_each_beacons_offset() {
        let beacons = [
            (0, Vector3::new(50.0, 0.0, 0.0), 3.0),
            (1, Vector3::new(-30.0, 40.0, 0.0), 7.6),
            (2, Vector3::new(-20.0, -45.0, 0.0), -8.5),
        ];
        let run = |nav: &mut dyn Navigator| {
            let (mut n, mut e, mut psi) = (0.0_f64, 0.0_f64, 0.0_f64);
            let mut worst = 0.0_f64;
            for k in 1..=4000 {
                let t = k as f64 * 0.5;
                let measured_dpsi = 0.02 * (k as f64 / 200.0).sin() + 0.012;
                let true_dpsi = measured_dpsi;
                n += 0.5 * (psi + true_dpsi / 2.0).cos();
                e += 0.5 * (psi + true_dpsi / 2.0).sin();
                psi += true_dpsi;
                nav.process(&Measurement::new(
                    t,
                    Kind::Odometry { distance_m: 0.5, heading_change_rad: measured_dpsi },
                ));
                if k % 3 == 0 {
                    let (id, b, offset) = beacons[(k / 3) % 3];
                    let range_m = (Vector3::new(n, e, 0.0) - b).norm() + offset;
                    nav.process(&Measurement::new(t, Kind::Range { beacon: BeaconFix::fixed(id, b), range_m }));
                }
                let est = nav.estimate();
                if k > 2000 {
                    worst = worst.max((est.north_m() - n).hypot(est.east_m() - e));
                }
            }
            worst
        };
        let noise = PlanarNoise::default();
        let per_beacon = PlanarConfig { estimate_beacon_offsets: true, noise, ..PlanarConfig::default() };
        let mut nav = PlanarNavigator::<STATES_WITH_OFFSETS>::with_layout(
            per_beacon,
            FilterKind::Ekf,
            0.0,
            (0.0, 0.0, 0.0),
            (0.5, 0.02),
        );
        let worst = run(&mut nav);
        let offsets = nav.offsets();
        assert_eq!(offsets.len(), 3);
        assert_eq!(offsets.iter().map(|o| o.0).collect::<Vec<_>>(), [1, 2, 0]); // the order heard
        for (id, offset, sigma) in offsets {
            let truth = beacons.iter().find(|b| b.0 == id).unwrap().2;
            assert_abs_diff_eq!(offset, truth, epsilon = 0.1);
            assert!(sigma < 0.5, "beacon {id}: sigma {sigma}");
        }
        assert!(worst < 0.3, "per-beacon offsets: worst error over the second half {worst} m");
        let shared = PlanarConfig { estimate_bias: true, noise, ..PlanarConfig::default() };
        let mut one = PlanarNavigator::new(shared, FilterKind::Ekf, 0.0, (0.0, 0.0, 0.0), 0.5, 0.02);
        let worst_shared = run(&mut one);
        assert!(worst_shared > 2.0, "one shared offset: {worst_shared} m");
        // slots full: a ninth beacon's range uses the shared offset state (fixed at bias_m)
        let mut full = PlanarNavigator::<STATES_WITH_OFFSETS>::with_layout(
            per_beacon,
            FilterKind::Ekf,
            0.0,
            (0.0, 0.0, 0.0),
            (1.0, 0.02),
        );
        for id in 0..=BEACON_OFFSETS as u32 {
            let b = Vector3::new(100.0 * f64::from(id + 1), 0.0, 0.0);
            full.process(&Measurement::new(1.0, Kind::Range { beacon: BeaconFix::fixed(id, b), range_m: b.norm() }));
        }
        assert_eq!(full.offsets().len(), BEACON_OFFSETS);
        assert_eq!(full.filter.covariance()[(idx::BIAS, idx::BIAS)], 0.0);
    }

    /// A DVL's body velocity held between events: heading east at 1 m/s forward and
    /// 0.2 m/s to starboard for 10 s ends at (-2, 10) (NED: starboard of east is south);
    /// with a yaw rate of 0.1 rad/s from heading north, the track is the circle of radius
    /// 10 m: after 10 s at (10 sin 1, 10 (1 - cos 1)), heading 1 rad (closed forms). The
    /// position variance grows by the speed error on each axis.
    #[test]
    fn body_velocity_is_integrated_on_se2() {
        let events = |nav: &mut PlanarNavigator, nu: [f64; 6]| {
            nav.process(&Measurement::new(0.0, Kind::BodyVelocity { nu }));
            for k in 1..=10 {
                nav.process(&Measurement::new(k as f64, Kind::Depth { depth_m: 0.0 }));
            }
            nav.estimate()
        };
        // without heading noise the heading stays exact and the position variance is the
        // speed error's alone
        let mut still_heading = PlanarConfig::default();
        (still_heading.noise.heading_walk_rad_per_sqrt_m, still_heading.noise.heading_change_sigma_frac) = (0.0, 0.0);
        let mut crab = PlanarNavigator::new(still_heading, FilterKind::Ekf, 0.0, (0.0, 0.0, FRAC_PI_2), 0.0, 0.0);
        let e = events(&mut crab, [1.0, 0.2, 0.0, 0.0, 0.0, 0.0]);
        assert_abs_diff_eq!(e.north_m(), -2.0, epsilon = 1e-9);
        assert_abs_diff_eq!(e.east_m(), 10.0, epsilon = 1e-9);
        let sigma = PlanarNoise::default().speed_sigma_m_s;
        // ten steps of 1 s, each adding sigma^2 on both axes (heading exact, rotation-invariant)
        assert_abs_diff_eq!(e.horizontal_cov_m2.trace(), 2.0 * 10.0 * sigma * sigma, epsilon = 1e-9);
        let mut turn = start(PlanarConfig::default());
        let e = events(&mut turn, [1.0, 0.0, 0.0, 0.0, 0.0, 0.1]);
        assert_abs_diff_eq!(e.north_m(), 10.0 * 1f64.sin(), epsilon = 1e-9);
        assert_abs_diff_eq!(e.east_m(), 10.0 * (1.0 - 1f64.cos()), epsilon = 1e-9);
        assert_abs_diff_eq!(e.heading_rad(), 1.0, epsilon = 1e-12);
    }

    #[test]
    fn doppler_and_heading_corrections() {
        // heading fix pulls the heading; a Doppler speed with the known odometry speed
        // is accepted and consistent with the geometry
        let mut nav = PlanarNavigator::new(PlanarConfig::default(), FilterKind::Ekf, 0.0, (10.0, 0.0, 0.2), 1.0, 0.3);
        assert!(matches!(
            nav.process(&Measurement::new(0.0, Kind::Heading { heading_rad: 0.0 })),
            Outcome::Accepted(..)
        ));
        assert!(nav.estimate().heading_rad().abs() < 0.2);
        nav.process(&Measurement::new(1.0, Kind::Odometry { distance_m: 0.0, heading_change_rad: 0.0 }));
        nav.process(&Measurement::new(2.0, Kind::Odometry { distance_m: 1.5, heading_change_rad: 0.0 }));
        let beacon = Vector3::zeros();
        // heading north, away from a beacon to the south: opening at the odometry speed
        let out = nav.process(&Measurement::new(
            2.0,
            Kind::Doppler { beacon: BeaconFix::fixed(0, beacon), radial_speed_m_s: -1.5 },
        ));
        assert!(matches!(out, Outcome::Accepted(i) if i.nis < 1.0), "{out:?}");
    }

    /// A Doppler speed heard 30 m below a surface beacon 40 m off reads along the slant
    /// line of sight: closing at 1.5 m/s horizontally is 1.2 m/s (4/5, a closed form),
    /// as the smoother's line-of-sight speed reads it.
    #[test]
    fn a_doppler_speed_from_below_the_beacon_is_read_along_the_slant_line() {
        let innovation = |depth_m: f64, radial_speed_m_s: f64| {
            let mut nav = start(PlanarConfig { aiding: Aiding::RANGE_DOPPLER, ..PlanarConfig::default() });
            nav.process(&Measurement::new(0.0, Kind::Depth { depth_m }));
            nav.process(&Measurement::new(0.0, Kind::Speed { speed_m_s: 1.5 }));
            // heading north from 40 m south of the beacon: closing
            let beacon = BeaconFix::fixed(0, Vector3::new(40.0, 0.0, 0.0));
            match nav.process(&Measurement::new(0.0, Kind::Doppler { beacon, radial_speed_m_s })) {
                Outcome::Accepted(i) | Outcome::Rejected(i) => i.residual,
                other => panic!("{other:?}"),
            }
        };
        assert_abs_diff_eq!(innovation(30.0, 1.2), 0.0, epsilon = 1e-12);
        assert_abs_diff_eq!(innovation(0.0, 1.5), 0.0, epsilon = 1e-12);
        assert_abs_diff_eq!(innovation(30.0, 1.5), 0.3, epsilon = 1e-12);
    }
}
