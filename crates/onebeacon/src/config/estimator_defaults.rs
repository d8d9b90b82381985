//! The defaults of `[[estimators]]` keys that a spec leaves out, each with its source
//! (or the word that it has none), and the noise keys a log's `[noise]` may give.

/// Particles of a `pf` estimator without `particles` (hoff2024 sec. 5).
pub const DEFAULT_PARTICLES: usize = 500_000;
/// The prior standard deviation of a range offset's drift, m/s, when
/// `bias_drift_sigma_m_s` is not given: 3 ppm of clock drift at 1500 m/s, the spread of
/// an uncompensated crystal (a disciplined or chip-scale clock drifts far less).
pub const DEFAULT_BIAS_DRIFT_SIGMA_M_S: f64 = 4.5e-3;
/// The walk of a USBL misalignment state when `usbl_misalignment_walk_deg_per_sqrt_s` is
/// not given. No source: a mounting is constant, and the walk only keeps the particles'
/// values apart after resampling; at 0.005 the 2e4 particles of the tracker's test
/// collapse onto values 1 deg off, at 0.05 they find the misalignment within 0.1 deg.
pub const DEFAULT_MISALIGNMENT_WALK_DEG_PER_SQRT_S: f64 = 0.05;
/// The NIS gate of a log's or a stream's range, ROSB and Doppler estimators when
/// `nis_gate` is not given: 10 standard deviations of a scalar measurement, a gross
/// error that no Gaussian tail explains (real logs have them: false ranges, a wrong
/// beacon). It rejects nothing on plaza1 or plaza2; with the rule that opens a gate after
/// [`crate::nav::LOST_AFTER_REJECTIONS`] rejections in a row, a burst of false ranges to
/// one beacon cannot capture a filter that hears other beacons meanwhile.
pub const LOG_NIS_GATE: f64 = 100.0;
/// The prior standard deviation of each axis of a current state, m/s, when
/// `current_sigma_m_s` is not given. No source: chosen on garin2024-sea at seed 1001 (300
/// runs a cell, a current of 0.1 m/s), where 0.2 m/s lost more runs (118 against 35 of
/// 300 over 20 m at T_com 20 s, UKF); a current far above 2 sigma (0.2 m/s) needs its own value.
pub const DEFAULT_CURRENT_SIGMA_M_S: f64 = 0.1;
/// The random walk of each axis of a current state, m/s per sqrt(s), when
/// `current_walk_m_s_per_sqrt_s` is not given: that of a first-order Gauss-Markov current
/// of stationary sigma 0.03 m/s and correlation time T = 1800 s, sigma sqrt(2 / T) (the
/// slow variation of garin2024-sea's current, itself unsourced); on garin2024-sea at seed
/// 1001 it did as well as 5e-4 and better than 1.7e-3.
pub const DEFAULT_CURRENT_WALK_M_S_PER_SQRT_S: f64 = 1e-3;
/// The prior standard deviation of a log estimator's heading offset, deg, when
/// `heading_offset_sigma_deg` is not given: a calibrated MEMS AHRS against a dual-antenna
/// GPS, rypkema sec. 2.1 ("one standard deviation of heading error ... approximately
/// 3 deg").
pub const DEFAULT_HEADING_OFFSET_SIGMA_DEG: f64 = 3.0;
/// A `pf` estimator's `min_effective_particles` when not given.
pub const DEFAULT_MIN_EFFECTIVE: f64 = 20.0;

/// The noise keys a log's `[noise]` table may give its estimators, and whether each
/// must be > 0 (else >= 0).
pub const NOISE_KEYS: [(&str, bool); 9] = [
    ("range_sigma_m", true),
    ("doppler_sigma_m_s", true),
    ("heading_sigma_deg", true),
    ("distance_sigma_frac", false),
    ("heading_change_sigma_frac", false),
    ("heading_walk_deg_per_sqrt_m", false),
    ("speed_sigma_m_s", false),
    ("bias_walk_m_per_sqrt_s", false),
    ("position_walk_m_per_sqrt_s", false),
];
