//! The tuning keys of an `[[estimators]]` table, grouped by what they tune (the
//! measurement noise, the gate, the calibration states, each host's process model, the
//! USBL trackers, the particle filter), each group with its key names and the reader of
//! one key, which [`super::estimator::EstimatorSpec`]'s reader dispatches a flat table's
//! keys to. The TOML keys are the flat ones every scenario, log and stream writes.

use serde::de::MapAccess;
use serde::{Deserialize, Serialize};

/// One group of optional keys: the struct, its key names, and the reader of one key.
macro_rules! key_group {
    ($(#[$m:meta])* $name:ident { $($(#[$fm:meta])* $field:ident: $ty:ty,)* }) => {
        $(#[$m])*
        #[derive(Debug, Clone, Default, PartialEq, Serialize)]
        pub struct $name {
            $($(#[$fm])* #[serde(skip_serializing_if = "Option::is_none")] pub $field: Option<$ty>,)*
        }

        impl $name {
            pub(super) const KEYS: &[&str] = &[$(stringify!($field)),*];

            /// Reads `key`'s value from `map` if the key is this group's.
            pub(super) fn take<'de, A: MapAccess<'de>>(&mut self, key: &str, map: &mut A) -> Result<bool, A::Error> {
                match key {
                    $(stringify!($field) => self.$field = Some(map.next_value()?),)*
                    _ => return Ok(false),
                }
                Ok(true)
            }
        }
    };
}

key_group! {
    /// Measurement noise the filter assumes (standard deviations), read by every host
    /// that has the sensor. Default: garin2024 eq. 25 (fixed_beacon), the sensors'
    /// (moving_beacon, passive_usbl), [`crate::nav::PlanarNoise`] (logs).
    NoiseKeys {
        /// Range, m (fixed_beacon, moving_beacon, log).
        range_sigma_m: f64,
        /// Doppler radial speed, m/s (fixed_beacon, log).
        doppler_sigma_m_s: f64,
        /// Heading, deg (fixed_beacon, log; passive_usbl: the vehicle's reported heading).
        heading_sigma_deg: f64,
        /// The vehicle's reported depth, m (passive_usbl; moving_beacon: its depth sensor).
        depth_sigma_m: f64,
        /// Speed, m/s (passive_usbl: the reported speed; log: a speed input).
        speed_sigma_m_s: f64,
    }
}

key_group! {
    /// The gate and heavy-tailed update of ranges, Doppler speeds, heading fixes and
    /// bearings (every host).
    GateKeys {
        /// A NIS threshold (absent: none, or [`super::estimator::LOG_NIS_GATE`] for a
        /// log's planar family).
        nis_gate: f64,
        /// `"huber"` or `"student_t"`, Gaussian when absent.
        robust: RobustName,
        huber_k: f64,
        student_t_dof: f64,
    }
}

key_group! {
    /// Calibration states and their priors (fixed_beacon, moving_beacon, log; which
    /// apply where: [`super::check_estimators`]).
    CalibrationKeys {
        /// A range offset state (a clock offset, a latency), starting at `bias_m` with
        /// `bias_sigma_m`, walking with `bias_walk_m_per_sqrt_s`.
        estimate_bias: bool,
        /// A drift state of the range offset, m/s (moving_beacon: a clock's frequency
        /// error, 1 ppm at 1500 m/s is 1.5e-3 m/s), prior standard deviation
        /// `bias_drift_sigma_m_s`; implies `estimate_bias`.
        estimate_bias_drift: bool,
        bias_drift_sigma_m_s: f64,
        /// An offset per beacon instead of one shared (log).
        estimate_beacon_offsets: bool,
        bias_m: f64,
        bias_sigma_m: f64,
        bias_walk_m_per_sqrt_s: f64,
        estimate_range_scale: bool,
        range_scale_sigma: f64,
        estimate_distance_scale: bool,
        distance_scale_sigma: f64,
        estimate_turn_scale: bool,
        turn_scale_sigma: f64,
        /// The water's current as two states (north, east): zero at the start with
        /// `current_sigma_m_s` on each axis, walking with `current_walk_m_s_per_sqrt_s`.
        estimate_current: bool,
        current_sigma_m_s: f64,
        current_walk_m_s_per_sqrt_s: f64,
        /// The heading sensor's offset as a state (log): heading fixes read the heading
        /// plus it; zero at the start with `heading_offset_sigma_deg`, a first-order
        /// Gauss-Markov process of correlation time `heading_offset_time_s` (none: a
        /// constant).
        estimate_heading_offset: bool,
        heading_offset_sigma_deg: f64,
        heading_offset_time_s: f64,
    }
}

key_group! {
    /// garin2024's unicycle filter (fixed_beacon).
    UnicycleKeys {
        /// Yaw rate, rad/s, and forward acceleration, m/s^2.
        yaw_rate_sigma_rad_s: f64,
        accel_sigma_m_s2: f64,
        /// Diagonal of Q per step, state order [x, y, psi, v, Omega, a].
        q_diag: [f64; 6],
        /// Take a state driving backwards for the mirror image of the vehicle through
        /// the beacon and reflect it back (default true, false: garin2024's filter as
        /// published).
        mirror_recovery: bool,
        /// The slowest the vehicle goes ahead, m/s: a speed estimate below it is
        /// projected onto it with the states correlated with it (default none).
        min_speed_m_s: f64,
    }
}

key_group! {
    /// sousa's 6-DOF filter's sensors (moving_beacon): body velocity (u, v, w), m/s;
    /// body rates (p, q, r), rad/s; roll, pitch and heading, deg. Absent: the world's
    /// sensors, or on a stream [`crate::nav::SensorNoise::default`].
    SixDofKeys {
        velocity_sigma_m_s: f64,
        rate_sigma_rad_s: f64,
        attitude_sigma_deg: f64,
    }
}

key_group! {
    /// hoff2024's USBL trackers (passive_usbl, logs of bearings).
    UsblKeys {
        /// sigma_USBL, deg per metre of range.
        usbl_sigma_deg_per_m: f64,
        /// The angles' noise floor besides sigma_USBL's range-proportional term, deg
        /// (default 0, the paper's).
        usbl_floor_deg: f64,
        /// Read hoff2024's eq. 6 as printed: sigma_USBL r (eq. 3) as the angles' variance
        /// instead of their standard deviation (default false).
        usbl_as_printed: bool,
        /// The USBL head's yaw misalignment as a state of the particle filter: its
        /// standard deviation about zero at the start, deg (pf; absent: the head is taken
        /// as aligned).
        usbl_misalignment_sigma_deg: f64,
        /// That misalignment's random walk, deg per sqrt(s) (pf; default
        /// [`super::estimator::DEFAULT_MISALIGNMENT_WALK_DEG_PER_SQRT_S`]).
        usbl_misalignment_walk_deg_per_sqrt_s: f64,
        /// The station's compass error, deg.
        compass_sigma_deg: f64,
        /// Scales every process noise standard deviation of hoff2024 eq. 4.
        process_noise_scale: f64,
        /// The process noise standard deviations of eq. 4 per second, state order [x, y,
        /// z, theta, psi, u, b_theta, b_psi] (m/s, rad/s, m/s^2, rad/s^2; default:
        /// hoff2024 sec. 5).
        process_sigma: [f64; 8],
    }
}

key_group! {
    /// The particle filter (kind pf).
    ParticleKeys {
        /// Particles (default 500000, hoff2024 sec. 5).
        particles: usize,
        /// `"multinomial"` (hoff2024 eq. 9), `"systematic"` (default), `"stratified"`
        /// or `"residual"`.
        resampler: ResamplerName,
        /// Resample when the effective sample size falls below this fraction (default
        /// 0.5; 1: every message).
        ess_fraction: f64,
        /// Roughening after resampling, K of Gordon et al. (default off).
        roughening_k: f64,
        /// The fewest effective particles an update may leave: a sharper measurement is
        /// tempered (default 20; 0: off).
        min_effective_particles: f64,
    }
}

key_group! {
    /// The planar navigators' motion model (log).
    PlanarKeys {
        distance_sigma_frac: f64,
        heading_change_sigma_frac: f64,
        heading_walk_deg_per_sqrt_m: f64,
        /// Position random walk, m / sqrt(s): the motion model of a craft without inputs.
        position_walk_m_per_sqrt_s: f64,
        /// Track the craft with a constant-velocity model, white acceleration of this
        /// standard deviation, m/s^2 per sqrt(s); no motion inputs are used.
        track_accel_sigma_m_s2: f64,
        /// A speed input of zero is a stopped propeller: the vehicle coasts on with this
        /// time constant, s (none: it stops at once).
        speed_coast_time_s: f64,
    }
}

/// A heavy-tailed update (`robust` key).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum RobustName {
    /// Huber's weight, threshold `huber_k` standard deviations (default 1.345).
    Huber,
    /// A Student-t likelihood with `student_t_dof` degrees of freedom (default 4).
    StudentT,
}

/// How a particle filter resamples (`resampler` key).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum ResamplerName {
    Multinomial,
    Systematic,
    Stratified,
    Residual,
}
