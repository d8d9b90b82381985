//! Navigators: a process model, measurement models and a filter put together, fed with
//! [`Measurement`] events as they arrive on the vehicle.
//!
//! Every navigator implements [`Navigator`]: `process` one event, read the
//! [`Estimate`]. Each is written once against [`crate::filter::GaussianFilter`], so it
//! runs with the EKF or the UKF ([`crate::filter::FilterKind`]). The simulator, the log
//! replay and the live stream drive them through this interface alone, and score them
//! with one [`evaluation`].

pub mod capability;
pub mod diagnosis;
pub mod evaluation;
pub mod event;
pub mod fix;
pub mod item;
pub mod iusbl;
#[cfg(test)]
mod iusbl_consistency_tests;
pub mod limits;
pub mod planar;
mod planar_config;
#[cfg(test)]
mod planar_extended_tests;
mod planar_models;
pub mod range_6dof;
pub mod range_calibration;
pub mod restart;
pub mod session;
pub mod single_beacon;
pub mod tracking;
pub mod usbl_track;

pub use event::{BeaconFix, Capture, Kind, Measurement};
pub use iusbl::{IusblConfig, IusblNavigator};
pub use planar::PlanarNavigator;
pub use planar_config::{HeadingOffsetPrior, PlanarConfig, PlanarNoise};

pub use range_6dof::{Range6DofNavigator, SensorNoise};
pub use range_calibration::{CurrentPrior, OffsetPrior, RangeCalibration};
pub use single_beacon::{EkfTuning, SingleBeaconNavigator};
pub use tracking::TrackingNavigator;
pub use usbl_track::{GaussianTracker, MisalignmentPrior, ParticleTracker, TrackerConfig, TrackerNoise};

pub use crate::measure::Robust;

pub use crate::filter::Innovation;

use crate::filter::{AnyFilter, FilterError, Gated, GaussianFilter, MeasurementModel};
use nalgebra::{Matrix2, Matrix3, SVector, Vector3};

/// One update of `filter` with the stacked `models` and their values `z`, gated at
/// `gate` (NIS with the nominal noise), with the noise inflated by `robust` when given:
/// accepted or rejected with its nominal innovation, or failed (the filter left as it
/// was).
pub(crate) fn gated_update<const N: usize, const M: usize, H: MeasurementModel<N, M>>(
    filter: &mut AnyFilter<N>,
    models: &H,
    z: SVector<f64, M>,
    gate: f64,
    robust: Option<Robust>,
) -> Outcome {
    let r = models.covariance(filter.mean());
    let Some(robust) = robust else {
        return match filter.update_gated(models, &z, &r, gate) {
            Ok(Gated::Accepted(i)) => Outcome::Accepted(i),
            Ok(Gated::Rejected(i)) => Outcome::Rejected(i),
            Err(e) => Outcome::Failed(e),
        };
    };
    // the nominal innovation first: a gate of -1 rejects, leaving the state as it was
    let innovation = match filter.update_gated(models, &z, &r, -1.0) {
        Ok(g) => g.innovation(),
        Err(e) => return Outcome::Failed(e),
    };
    if innovation.nis > gate {
        return Outcome::Rejected(innovation);
    }
    match filter.update_gated(models, &z, &(r * robust.inflation(innovation.nis, M)), f64::INFINITY) {
        Ok(_) => Outcome::Accepted(innovation),
        Err(e) => Outcome::Failed(e),
    }
}

/// Consecutive rejections after which a gate takes its navigator for lost: a burst of
/// false measurements shorter than this cannot capture a gated navigator, and a
/// navigator whose error has outgrown its covariance is not shut out for good.
pub const LOST_AFTER_REJECTIONS: u32 = 30;

/// A navigator's NIS gate (infinity: none) with the one rule that keeps it from
/// locking the navigator out: after [`LOST_AFTER_REJECTIONS`] rejections in a row the
/// gate opens, and stays open until a correction falls within it again. A rule per
/// beacon (one beacon shut out while the others are taken) was tried for issue 53 and
/// left out: it lets a beacon whose position is wrong pull the navigator kilometres off;
/// a beacon mostly gated out is named instead ([`diagnosis`]), and a per-beacon offset
/// state (`estimate_beacon_offsets`) carries a steady bias.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Gate {
    nis: f64,
    rejected_in_row: u32,
}

impl Gate {
    pub(crate) fn new(nis: f64) -> Self {
        Self { nis, rejected_in_row: 0 }
    }

    /// [`gated_update`] at this gate (none while it is open), counting the rejections.
    pub(crate) fn update<const N: usize, const M: usize, H: MeasurementModel<N, M>>(
        &mut self,
        filter: &mut AnyFilter<N>,
        models: &H,
        z: SVector<f64, M>,
        robust: Option<Robust>,
    ) -> Outcome {
        let open = self.rejected_in_row >= LOST_AFTER_REJECTIONS;
        let outcome = gated_update(filter, models, z, if open { f64::INFINITY } else { self.nis }, robust);
        match outcome {
            Outcome::Rejected(..) => self.rejected_in_row += 1,
            Outcome::Accepted(i) if i.nis <= self.nis => self.rejected_in_row = 0,
            _ => {}
        }
        outcome
    }
}

/// Which acoustic measurements a navigator uses: its beacon aiding. Every navigator
/// takes one; a measurement it does not use is [`Outcome::Skipped`].
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct Aiding {
    /// Ranges (one-way travel times).
    pub range: bool,
    /// Doppler radial speeds.
    pub doppler: bool,
    /// USBL bearings (azimuth and elevation from a station).
    pub bearing: bool,
}

impl Aiding {
    /// No beacon: dead reckoning.
    pub const NONE: Aiding = Aiding { range: false, doppler: false, bearing: false };
    /// Ranges only (ROSB, range-only navigation).
    pub const RANGE: Aiding = Aiding { range: true, doppler: false, bearing: false };
    /// Ranges and Doppler speeds (garin2024's filter).
    pub const RANGE_DOPPLER: Aiding = Aiding { range: true, doppler: true, bearing: false };
    /// USBL bearings only (hoff2024's passive tracking).
    pub const BEARING: Aiding = Aiding { range: false, doppler: false, bearing: true };

    /// Whether any beacon measurement is used.
    pub fn any(self) -> bool {
        self.range || self.doppler || self.bearing
    }
}

/// What processing one measurement did.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Outcome {
    /// An input was applied (odometry, speed, body velocity), or a measurement held for
    /// the filter's next tick (a frame fused with the next inertial sample).
    Applied,
    /// A correction was accepted or rejected by the gate, with its innovation (nominal
    /// noise).
    Accepted(Innovation),
    Rejected(Innovation),
    /// Not used by this navigator (dead reckoning and beacons, say).
    Skipped,
    /// The update could not be computed; the state is unchanged.
    Failed(FilterError),
}

impl Outcome {
    /// The innovation of a correction weighed (accepted or rejected).
    pub fn innovation(&self) -> Option<Innovation> {
        match *self {
            Outcome::Accepted(i) | Outcome::Rejected(i) => Some(i),
            _ => None,
        }
    }
}

/// A navigator's estimate at one time: the part every navigator has (position, heading,
/// their uncertainty) and the sensor calibration states some estimate (None where it
/// does not: a state not estimated is absent, not zero).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Estimate {
    pub t_s: f64,
    /// NED position, m (down: the depth state, or the latest known depth).
    pub position_ned_m: Vector3<f64>,
    /// Covariance of north and east, m^2.
    pub horizontal_cov_m2: Matrix2<f64>,
    /// Heading as the state holds it, rad (not wrapped: [`Estimate::heading_rad`] wraps
    /// it, so that scoring every step pays for no wrap), and its variance, rad^2.
    pub(crate) heading_state_rad: f64,
    pub(crate) heading_var_rad2: f64,
    /// Roll and pitch, rad, when they are states (zero otherwise).
    pub(crate) roll_pitch_rad: [f64; 2],
    /// Forward speed, m/s, when it is a state.
    pub speed_m_s: Option<f64>,
    /// The sensor calibration states it estimates.
    pub calibration: Calibration,
}

/// The sensor calibration states a navigator estimates: None where it does not (a state
/// not estimated is absent, not zero).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Calibration {
    /// Range offset b (m) and scale error k_r, odometry distance and turn scale errors.
    pub range_bias_m: Option<f64>,
    pub range_scale: Option<f64>,
    pub distance_scale: Option<f64>,
    pub turn_scale: Option<f64>,
    /// The USBL head's yaw misalignment, rad.
    pub usbl_misalignment_rad: Option<f64>,
    /// The water's current (north, east), m/s.
    pub current_ned_m_s: Option<[f64; 2]>,
}

impl Calibration {
    /// The states estimated, as output keys (those not estimated left out).
    pub fn keys(&self) -> impl Iterator<Item = (&'static str, f64)> + use<> {
        let current = self.current_ned_m_s;
        [
            ("range_bias_m", self.range_bias_m),
            ("range_scale", self.range_scale),
            ("distance_scale", self.distance_scale),
            ("turn_scale", self.turn_scale),
            ("usbl_misalignment_rad", self.usbl_misalignment_rad),
            ("current_north_m_s", current.map(|c| c[0])),
            ("current_east_m_s", current.map(|c| c[1])),
        ]
        .into_iter()
        .filter_map(|(k, v)| Some((k, v?)))
    }
}

impl Estimate {
    pub fn north_m(&self) -> f64 {
        self.position_ned_m.x
    }
    pub fn east_m(&self) -> f64 {
        self.position_ned_m.y
    }
    pub fn sigma_north_m(&self) -> f64 {
        self.horizontal_cov_m2[(0, 0)].max(0.0).sqrt()
    }
    pub fn sigma_east_m(&self) -> f64 {
        self.horizontal_cov_m2[(1, 1)].max(0.0).sqrt()
    }
    /// Heading, rad in (-pi, pi].
    pub fn heading_rad(&self) -> f64 {
        crate::geo::wrap_angle(self.heading_state_rad)
    }
    pub fn sigma_heading_rad(&self) -> f64 {
        self.heading_var_rad2.max(0.0).sqrt()
    }
    /// Body-to-NED rotation of the estimated attitude (roll and pitch zero where they
    /// are not states).
    pub fn body_to_ned(&self) -> Matrix3<f64> {
        let [roll, pitch] = self.roll_pitch_rad;
        crate::models::kinematic6dof::rotation(roll, pitch, self.heading_state_rad)
    }
}

/// One estimator on a vehicle: fed measurements in time order, asked for its estimate.
pub trait Navigator: Send {
    /// Processes one measurement (an earlier time than the last is taken as now).
    fn process(&mut self, m: &Measurement) -> Outcome;
    /// The current estimate.
    fn estimate(&self) -> Estimate;
    /// Moves the estimate on to `t_s` without a measurement: a step no message reached
    /// a navigator that moves only on messages (the trackers). Navigators kept current by
    /// their dead-reckoning inputs do nothing.
    fn predict_to(&mut self, _t_s: f64) {}
    /// Samples of a particle belief; None for a Gaussian one.
    fn particles(&self) -> Option<&dyn capability::ParticleBelief> {
        None
    }
    /// Its position relative to the beacon it navigates on and the confirmed command
    /// mode, for beacon-relative behaviours; None for an absolute navigator.
    fn beacon_relative(&self) -> Option<&dyn capability::BeaconRelative> {
        None
    }
    /// The body velocity it dead-reckons on; None if it has none.
    fn body_velocity(&self) -> Option<&dyn capability::BodyVelocity> {
        None
    }
    /// The prediction of a held-out range; None for a navigator that cannot say.
    fn weighing(&mut self) -> Option<&mut dyn capability::Weighing> {
        None
    }
    /// Per-beacon range offsets; None for a navigator that estimates none.
    fn beacon_offsets(&self) -> Option<&dyn capability::BeaconOffsets> {
        None
    }
    /// A Rauch-Tung-Striebel pass over its run; None for a navigator that has none.
    fn smoothing(&mut self) -> Option<&mut dyn capability::Smoothing> {
        None
    }
    /// A factored particle filter's range and angle sets.
    fn factored(&self) -> Option<&dyn capability::FactoredBelief> {
        None
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::filter::FilterKind;
    use crate::measure::StateComponent;
    use approx::assert_abs_diff_eq;
    use nalgebra::{Matrix1, Vector1};

    /// A scalar state N(0, 4) measured directly with noise variance 1: the posterior
    /// mean against the closed forms. A residual of 1 (NIS 0.2) is a Gaussian update for
    /// every choice (0.8); one of 100 (NIS 2000) moves a Gaussian filter to 80, Huber
    /// (k = 1.345: R / w with w = k / sqrt(2000)) to 10.7 and a Student-t with 4 degrees of
    /// freedom (w = 5 / 2004) to 0.99. The gate sees the nominal NIS.
    #[test]
    fn heavy_tailed_updates_against_closed_forms() {
        let (p, r) = (4.0, 1.0);
        let posterior = |z: f64, robust: Option<Robust>, gate: f64| {
            let mut f = AnyFilter::new(FilterKind::Ekf, Vector1::new(0.0), Matrix1::new(p));
            let outcome = gated_update(&mut f, &[StateComponent::value(0, r)], Vector1::new(z), gate, robust);
            (f.mean()[0], outcome)
        };
        let gauss = |z: f64, r_eff: f64| p / (p + r_eff) * z;
        let (huber, student) = (Robust::Huber { k: 1.345 }, Robust::StudentT { dof: 4.0 });
        for robust in [None, Some(huber), Some(student)] {
            assert_abs_diff_eq!(posterior(1.0, robust, f64::INFINITY).0, gauss(1.0, r), epsilon = 1e-12);
        }
        let nis = 100.0f64.powi(2) / (p + r);
        assert_abs_diff_eq!(posterior(100.0, None, f64::INFINITY).0, 80.0, epsilon = 1e-9);
        let w_huber = 1.345 / nis.sqrt();
        let (x, outcome) = posterior(100.0, Some(huber), f64::INFINITY);
        assert_abs_diff_eq!(x, gauss(100.0, r / w_huber), epsilon = 1e-9);
        assert_abs_diff_eq!(x, 10.74, epsilon = 0.01);
        let Outcome::Accepted(i) = outcome else { panic!("{outcome:?}") };
        assert_abs_diff_eq!(i.nis, nis, epsilon = 1e-9);
        assert_abs_diff_eq!(i.det_s, p + r, epsilon = 1e-12);
        assert_abs_diff_eq!(i.residual, 100.0, epsilon = 1e-12);
        assert_abs_diff_eq!(i.sigma, (p + r).sqrt(), epsilon = 1e-12);
        let w_t = 5.0 / (4.0 + nis);
        assert_abs_diff_eq!(posterior(100.0, Some(student), f64::INFINITY).0, gauss(100.0, r / w_t), epsilon = 1e-9);
        assert_abs_diff_eq!(posterior(100.0, Some(student), f64::INFINITY).0, 0.988, epsilon = 0.001);
        // gated on the nominal NIS: rejected, the state untouched
        let (x, outcome) = posterior(100.0, Some(student), 10.83);
        assert_eq!(x, 0.0);
        assert!(matches!(outcome, Outcome::Rejected(i) if (i.nis - nis).abs() < 1e-9), "{outcome:?}");
    }

    /// The lost rule against the closed form of repeated scalar updates: x ~ N(0, 1),
    /// z = 50 with r = 1, gate 100 (NIS 1250). The first [`LOST_AFTER_REJECTIONS`] are
    /// rejected, the state untouched; then the gate is open: before the k-th accepted
    /// update the NIS is 2500 / (k (k + 1)), over 100 for k < 5, accepted all the same;
    /// the fifth (NIS 83.3) falls within the gate and closes it, the mean 50 k / (k + 1)
    /// = 41.7; a gross residual is rejected again at once.
    #[test]
    fn a_gate_opens_after_a_run_of_rejections_and_closes_when_one_fits() {
        let mut f = AnyFilter::new(FilterKind::Ekf, Vector1::new(0.0), Matrix1::new(1.0));
        let model = [StateComponent::value(0, 1.0)];
        let mut gate = Gate::new(100.0);
        for _ in 0..LOST_AFTER_REJECTIONS {
            assert!(matches!(gate.update(&mut f, &model, Vector1::new(50.0), None), Outcome::Rejected(..)));
        }
        assert_eq!(f.mean()[0], 0.0);
        for k in 1..=5 {
            let Outcome::Accepted(Innovation { nis, .. }) = gate.update(&mut f, &model, Vector1::new(50.0), None)
            else {
                panic!()
            };
            assert_abs_diff_eq!(nis, 2500.0 / (k * (k + 1)) as f64, epsilon = 1e-9);
            assert_abs_diff_eq!(f.mean()[0], 50.0 * k as f64 / (k + 1) as f64, epsilon = 1e-9);
        }
        assert!(matches!(gate.update(&mut f, &model, Vector1::new(-1000.0), None), Outcome::Rejected(..)));
        assert_abs_diff_eq!(f.mean()[0], 50.0 * 5.0 / 6.0, epsilon = 1e-9);
    }
}
