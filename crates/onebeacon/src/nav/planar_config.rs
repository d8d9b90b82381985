//! What a planar navigator ([`super::planar`]) uses and how: its measurement and
//! motion noise, the calibration and motion states it estimates and their priors.

use super::range_calibration::CurrentPrior;
use super::{Aiding, Robust};

/// Noise of the motion inputs and of the measurements.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PlanarNoise {
    /// Odometry distance error, as a fraction of each increment.
    pub distance_sigma_frac: f64,
    /// Odometry heading-change error, as a fraction of each increment.
    pub heading_change_sigma_frac: f64,
    /// Heading random walk per metre travelled, rad / sqrt(m) (slip, gyro drift).
    pub heading_walk_rad_per_sqrt_m: f64,
    /// Forward-speed input error, m/s (speed logs).
    pub speed_sigma_m_s: f64,
    pub range_sigma_m: f64,
    pub heading_sigma_rad: f64,
    pub doppler_sigma_m_s: f64,
    /// Random walk of the range bias, m / sqrt(s).
    pub bias_walk_m_per_sqrt_s: f64,
    /// Random walk of the position, m / sqrt(s), on each axis: the motion model of a
    /// craft with no inputs (tracked from outside, or whose navigation data is lost),
    /// nearly constant position; 0 without it.
    pub position_walk_m_per_sqrt_s: f64,
}

impl Default for PlanarNoise {
    fn default() -> Self {
        Self {
            distance_sigma_frac: 0.02,
            heading_change_sigma_frac: 0.02,
            heading_walk_rad_per_sqrt_m: 0.005,
            speed_sigma_m_s: 0.05,
            range_sigma_m: 1.5,
            heading_sigma_rad: 2f64.to_radians(),
            doppler_sigma_m_s: 0.1,
            bias_walk_m_per_sqrt_s: 0.005,
            position_walk_m_per_sqrt_s: 0.0,
        }
    }
}

/// What an estimator uses and how.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PlanarConfig {
    /// The beacon measurements used ([`Aiding::NONE`]: dead reckoning, heading fixes
    /// only).
    pub aiding: Aiding,
    /// Estimate the range bias as a state.
    pub estimate_bias: bool,
    /// The range bias, m: the initial value when estimated, the known value otherwise.
    pub bias_m: f64,
    /// Initial standard deviation of an estimated bias, m.
    pub bias_sigma_m: f64,
    /// Estimate an offset per beacon (starting at `bias_m` with `bias_sigma_m`, walking
    /// with `bias_walk_m_per_sqrt_s`) instead of one shared offset: real beacons each
    /// carry their own (cable, turnaround time, position error along the line of sight).
    /// At most [`BEACON_OFFSETS`] beacons; ranges to more use the shared `bias_m`.
    pub estimate_beacon_offsets: bool,
    /// Estimate the range scale error k_r (starts at 0).
    pub estimate_range_scale: bool,
    /// Initial standard deviation of k_r (a fraction: 0.05 is 5 %).
    pub range_scale_sigma: f64,
    /// Estimate the odometry's distance scale error k_d (starts at 0).
    pub estimate_distance_scale: bool,
    /// Initial standard deviation of k_d (a fraction).
    pub distance_scale_sigma: f64,
    /// Estimate the odometry's heading-change scale error k_t (starts at 0).
    pub estimate_turn_scale: bool,
    /// Initial standard deviation of k_t (a fraction).
    pub turn_scale_sigma: f64,
    /// Reject a range or Doppler speed whose NIS exceeds this (chi-square, 1 dof:
    /// 3.84 at 95 %, 6.63 at 99 %, 10.83 at 99.9 %); `None` accepts everything.
    pub nis_gate: Option<f64>,
    /// A heavy-tailed update for ranges, Doppler speeds and heading fixes (under the
    /// gate, if any); `None`: Gaussian.
    pub robust: Option<Robust>,
    pub noise: PlanarNoise,
    /// A forward speed of exactly zero is a stopped propeller (a speed from its RPM):
    /// the vehicle coasts on, its speed decaying from the one held with this time
    /// constant, s; None: it stops at once.
    pub speed_coast_time_s: Option<f64>,
    /// The heading sensor's offset as a state (heading fixes read psi + h); none
    /// without.
    pub heading_offset: Option<HeadingOffsetPrior>,
    /// The water's current as two states that carry the position; none without.
    pub current: Option<CurrentPrior>,
    /// Track a craft without motion inputs with a constant-velocity model driven by
    /// white acceleration of this standard deviation, m/s^2 per sqrt(s)
    /// ([`super::TrackingNavigator`]: position, velocity, range offset and scale); `None`
    /// for this navigator.
    pub track_accel_sigma_m_s2: Option<f64>,
}

impl Default for PlanarConfig {
    fn default() -> Self {
        Self {
            aiding: Aiding::RANGE_DOPPLER,
            estimate_bias: false,
            bias_m: 0.0,
            bias_sigma_m: 5.0,
            estimate_beacon_offsets: false,
            estimate_range_scale: false,
            // the ocean's surface sound speed against an assumed 1500 m/s: -2.8 % (2 C)
            // to +3.0 % (30 C) at 35 ppt (Mackenzie 1981); docs/logs.md, "Choosing
            // range_scale_sigma"
            range_scale_sigma: 0.02,
            estimate_distance_scale: false,
            distance_scale_sigma: 0.05,
            estimate_turn_scale: false,
            turn_scale_sigma: 0.05,
            nis_gate: None,
            robust: None,
            noise: PlanarNoise::default(),
            speed_coast_time_s: None,
            heading_offset: None,
            current: None,
            track_accel_sigma_m_s2: None,
        }
    }
}

impl PlanarConfig {
    /// Whether it needs the [`super::planar::EXTENDED_STATES`] layout (a heading offset or a current).
    pub fn extended(&self) -> bool {
        self.heading_offset.is_some() || self.current.is_some()
    }
}

/// The heading offset's prior and motion: zero mean, `sigma_rad`, a first-order
/// Gauss-Markov process of correlation time `time_s` (infinite: a constant).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HeadingOffsetPrior {
    pub sigma_rad: f64,
    pub time_s: f64,
}
