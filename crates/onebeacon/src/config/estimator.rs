//! One estimator description for every world and every log: the `[[estimators]]`
//! table of scenarios and log descriptions alike. An estimator is its short name
//! (`kind`), the acoustic measurements it uses, its filter (EKF or UKF with its
//! sigma-point parameters, or a particle filter) and its tuning. The process model is
//! the host's: the unicycle with acceleration in `fixed_beacon` worlds (garin2024 eq.
//! 3-7), 6-DOF kinematics in `moving_beacon` worlds (sousa 3.1), the stochastic
//! unicycle of hoff2024 eq. 4 in `passive_usbl` worlds, planar odometry on logs.

pub use super::estimator_defaults::*;
pub use super::iusbl::IusblKeys;
use crate::filter::particle::{ParticleSettings, Resampler};
use crate::filter::{FilterKind, UkfParams};
use crate::models::hoff::HoffProcess;
use crate::nav::{
    Aiding, CurrentPrior, EkfTuning, HeadingOffsetPrior, MisalignmentPrior, OffsetPrior, PlanarConfig, PlanarNoise,
    RangeCalibration, Robust, SensorNoise, TrackerConfig, TrackerNoise,
};
use serde::{Deserialize, Serialize};

/// Which filter an estimator runs: the `filter` key of every `[[estimators]]` table.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum FilterName {
    /// Extended Kalman filter.
    #[default]
    Ekf,
    /// Unscented Kalman filter (Merwe sigma points: `ukf_alpha`, `ukf_beta`, `ukf_kappa`).
    Ukf,
}

impl FilterName {
    /// The filter with its parameters; absent UKF keys take [`UkfParams::default`].
    pub fn kind(self, alpha: Option<f64>, beta: Option<f64>, kappa: Option<f64>) -> FilterKind {
        let d = UkfParams::default();
        match self {
            FilterName::Ekf => FilterKind::Ekf,
            FilterName::Ukf => FilterKind::Ukf(UkfParams {
                alpha: alpha.unwrap_or(d.alpha),
                beta: beta.unwrap_or(d.beta),
                kappa: kappa.unwrap_or(d.kappa),
            }),
        }
    }

    /// Suffix of a default estimator name: "" for the EKF, "-ukf".
    pub fn suffix(self) -> &'static str {
        match self {
            FilterName::Ekf => "",
            FilterName::Ukf => "-ukf",
        }
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

/// Where an estimator runs.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Host {
    FixedBeacon,
    MovingBeacon,
    PassiveUsbl,
    Log,
}

impl Host {
    /// How a refusal names the host: a planar stream's estimators take a log's keys, a
    /// 6-DOF stream's (`model = "6dof"`) a moving_beacon world's.
    pub fn label(self) -> &'static str {
        match self {
            Host::FixedBeacon => "fixed_beacon world",
            Host::MovingBeacon => "moving_beacon world or 6-DOF stream",
            Host::PassiveUsbl => "passive_usbl world",
            Host::Log => "log or planar stream",
        }
    }

    /// The acoustic measurements the host gives.
    pub fn acoustic(self) -> Aiding {
        match self {
            Host::FixedBeacon | Host::Log => Aiding::RANGE_DOPPLER,
            Host::MovingBeacon => Aiding::RANGE,
            Host::PassiveUsbl => Aiding::BEARING,
        }
    }
}

/// The short names of estimators.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub enum EstimatorKind {
    /// Ranges and Doppler speeds (garin2024's filter).
    #[serde(rename = "range+doppler")]
    RangeDoppler,
    /// Ranges only (ROSB, garin2024's baseline).
    #[serde(rename = "rosb")]
    Rosb,
    /// Every acoustic measurement the host gives (ranges in a moving-beacon world).
    #[serde(rename = "range-ekf", alias = "range_ekf")]
    RangeEkf,
    /// No acoustic measurement.
    #[serde(rename = "dead-reckoning", alias = "dead_reckoning")]
    DeadReckoning,
    /// hoff2024's particle filter on USBL bearings and the vehicle's reports.
    #[serde(rename = "pf")]
    Particle,
    /// The same models in an EKF or a UKF (`filter`).
    #[serde(rename = "bearing")]
    Bearing,
    /// rypkema's factored iUSBL particle filter on the beacon's pings (fleet worlds,
    /// logs of array fixes; its settings in `iusbl`).
    #[serde(rename = "iusbl")]
    Iusbl,
    /// The same filter updated jointly (no factoring): what the factoring buys.
    #[serde(rename = "iusbl-joint", alias = "iusbl_joint")]
    IusblJoint,
}

impl EstimatorKind {
    pub fn label(self) -> &'static str {
        match self {
            EstimatorKind::RangeDoppler => "range+doppler",
            EstimatorKind::Rosb => "rosb",
            EstimatorKind::RangeEkf => "range-ekf",
            EstimatorKind::DeadReckoning => "dead-reckoning",
            EstimatorKind::Particle => "pf",
            EstimatorKind::Bearing => "bearing",
            EstimatorKind::Iusbl => "iusbl",
            EstimatorKind::IusblJoint => "iusbl-joint",
        }
    }

    /// Whether it tracks a vehicle by USBL bearings (hoff2024's trackers).
    pub fn tracks_bearings(self) -> bool {
        matches!(self, EstimatorKind::Particle | EstimatorKind::Bearing)
    }

    /// Whether it is rypkema's iUSBL navigator.
    pub fn iusbl(self) -> bool {
        matches!(self, EstimatorKind::Iusbl | EstimatorKind::IusblJoint)
    }

    /// The acoustic measurements the name stands for in `host`.
    pub fn aiding(self, host: Host) -> Aiding {
        match self {
            EstimatorKind::RangeDoppler => Aiding::RANGE_DOPPLER,
            EstimatorKind::Rosb => Aiding::RANGE,
            EstimatorKind::RangeEkf => host.acoustic(),
            EstimatorKind::DeadReckoning => Aiding::NONE,
            EstimatorKind::Particle | EstimatorKind::Bearing => Aiding::BEARING,
            // array fixes, which no planar filter takes
            EstimatorKind::Iusbl | EstimatorKind::IusblJoint => Aiding::NONE,
        }
    }
}

/// An acoustic measurement an estimator may use.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Acoustic {
    Range,
    Doppler,
    Bearing,
}

/// One `[[estimators]]` table. Every key but `kind` is optional; tuning keys apply to
/// the hosts named beside them (validation refuses the others).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct EstimatorSpec {
    pub kind: EstimatorKind,
    /// Name in outputs (default: the kind, with "-ukf" for the UKF).
    #[serde(default)]
    pub name: Option<String>,
    /// The acoustic measurements used (default: the kind's): `["range"]`,
    /// `["range", "doppler"]`, `[]`...
    #[serde(default)]
    pub measurements: Option<Vec<Acoustic>>,
    /// `"ekf"` (default) or `"ukf"`, with the UKF's sigma-point parameters (1, 2, 0).
    #[serde(default)]
    pub filter: FilterName,
    pub ukf_alpha: Option<f64>,
    pub ukf_beta: Option<f64>,
    pub ukf_kappa: Option<f64>,
    // Measurement noise the filter assumes (standard deviations). Default: garin2024
    // eq. 25 (fixed_beacon), the sensors' (moving_beacon), PlanarNoise (logs).
    /// Range, m (fixed_beacon, moving_beacon, log).
    pub range_sigma_m: Option<f64>,
    /// Doppler radial speed, m/s (fixed_beacon, log).
    pub doppler_sigma_m_s: Option<f64>,
    /// Heading, deg (fixed_beacon, log; passive_usbl: the vehicle's reported heading).
    pub heading_sigma_deg: Option<f64>,
    /// USBL bearings: sigma_USBL, deg per metre of range (passive_usbl).
    pub usbl_sigma_deg_per_m: Option<f64>,
    /// USBL bearings: the angles' noise floor besides sigma_USBL's range-proportional
    /// term, deg (passive_usbl; default 0, the paper's).
    pub usbl_floor_deg: Option<f64>,
    /// Read hoff2024's eq. 6 as printed: sigma_USBL r (eq. 3) as the angles' variance
    /// instead of their standard deviation (passive_usbl; default false).
    pub usbl_as_printed: Option<bool>,
    /// The USBL head's yaw misalignment as a state of the particle filter: its standard
    /// deviation about zero at the start, deg (pf; absent: the head is taken as aligned).
    pub usbl_misalignment_sigma_deg: Option<f64>,
    /// That misalignment's random walk, deg per sqrt(s) (pf; default
    /// [`DEFAULT_MISALIGNMENT_WALK_DEG_PER_SQRT_S`]).
    pub usbl_misalignment_walk_deg_per_sqrt_s: Option<f64>,
    /// The station's compass error, deg (passive_usbl).
    pub compass_sigma_deg: Option<f64>,
    /// The vehicle's reported depth, m (passive_usbl; moving_beacon: its depth sensor).
    pub depth_sigma_m: Option<f64>,
    /// The 6-DOF filter's sensors (moving_beacon): body velocity (u, v, w), m/s; body
    /// rates (p, q, r), rad/s; roll, pitch and heading, deg. Absent: the world's sensors,
    /// or on a stream [`SensorNoise::default`].
    pub velocity_sigma_m_s: Option<f64>,
    pub rate_sigma_rad_s: Option<f64>,
    pub attitude_sigma_deg: Option<f64>,
    /// Scales every process noise standard deviation of hoff2024 eq. 4 (passive_usbl).
    pub process_noise_scale: Option<f64>,
    /// The process noise standard deviations of eq. 4 per second, state order [x, y, z,
    /// theta, psi, u, b_theta, b_psi] (m/s, rad/s, m/s^2, rad/s^2; passive_usbl; default:
    /// hoff2024 sec. 5).
    pub process_sigma: Option<[f64; 8]>,
    /// Particles (pf; default 500000, hoff2024 sec. 5).
    pub particles: Option<usize>,
    /// `"multinomial"` (hoff2024 eq. 9), `"systematic"` (default), `"stratified"` or
    /// `"residual"` (pf).
    pub resampler: Option<ResamplerName>,
    /// Resample when the effective sample size falls below this fraction (pf; default
    /// 0.5; 1: every message).
    pub ess_fraction: Option<f64>,
    /// Roughening after resampling, K of Gordon et al. (pf; default off).
    pub roughening_k: Option<f64>,
    /// The fewest effective particles an update may leave: a sharper measurement is
    /// tempered (pf; default 20; 0: off).
    pub min_effective_particles: Option<f64>,
    /// Yaw rate, rad/s, and forward acceleration, m/s^2 (fixed_beacon).
    pub yaw_rate_sigma_rad_s: Option<f64>,
    pub accel_sigma_m_s2: Option<f64>,
    /// Diagonal of Q per step, state order [x, y, psi, v, Omega, a] (fixed_beacon).
    pub q_diag: Option<[f64; 6]>,
    /// Take a state driving backwards for the mirror image of the vehicle through the
    /// beacon and reflect it back (fixed_beacon; default true, false: garin2024's
    /// filter as published).
    pub mirror_recovery: Option<bool>,
    /// The slowest the vehicle goes ahead, m/s: a speed estimate below it is projected
    /// onto it with the states correlated with it (fixed_beacon; default none).
    pub min_speed_m_s: Option<f64>,
    // Planar odometry model and calibration states (log).
    pub distance_sigma_frac: Option<f64>,
    pub heading_change_sigma_frac: Option<f64>,
    pub heading_walk_deg_per_sqrt_m: Option<f64>,
    pub speed_sigma_m_s: Option<f64>,
    pub bias_walk_m_per_sqrt_s: Option<f64>,
    /// Position random walk, m / sqrt(s): the motion model of a craft without inputs
    /// (log).
    pub position_walk_m_per_sqrt_s: Option<f64>,
    /// Track the craft with a constant-velocity model, white acceleration of this
    /// standard deviation, m/s^2 per sqrt(s); no motion inputs are used (log).
    pub track_accel_sigma_m_s2: Option<f64>,
    pub nis_gate: Option<f64>,
    /// A heavy-tailed update (log): `"huber"` or `"student_t"`, Gaussian when absent.
    pub robust: Option<RobustName>,
    pub huber_k: Option<f64>,
    pub student_t_dof: Option<f64>,
    /// A range offset state (log, moving_beacon: a clock offset, a latency), starting at
    /// `bias_m` with `bias_sigma_m`, walking with `bias_walk_m_per_sqrt_s`.
    pub estimate_bias: Option<bool>,
    /// A drift state of the range offset, m/s (moving_beacon: a clock's frequency error,
    /// 1 ppm at 1500 m/s is 1.5e-3 m/s), prior standard deviation `bias_drift_sigma_m_s`;
    /// implies `estimate_bias`.
    pub estimate_bias_drift: Option<bool>,
    pub bias_drift_sigma_m_s: Option<f64>,
    /// An offset per beacon instead of one shared (log).
    pub estimate_beacon_offsets: Option<bool>,
    pub bias_m: Option<f64>,
    pub bias_sigma_m: Option<f64>,
    pub estimate_range_scale: Option<bool>,
    pub range_scale_sigma: Option<f64>,
    pub estimate_distance_scale: Option<bool>,
    pub distance_scale_sigma: Option<f64>,
    pub estimate_turn_scale: Option<bool>,
    pub turn_scale_sigma: Option<f64>,
    /// The water's current as two states (north, east; fixed_beacon, moving_beacon, log):
    /// zero at the start with `current_sigma_m_s` on each axis, walking with
    /// `current_walk_m_s_per_sqrt_s`.
    pub estimate_current: Option<bool>,
    pub current_sigma_m_s: Option<f64>,
    pub current_walk_m_s_per_sqrt_s: Option<f64>,
    /// The heading sensor's offset as a state (log): heading fixes read the heading plus
    /// it; zero at the start with `heading_offset_sigma_deg`, a first-order Gauss-Markov
    /// process of correlation time `heading_offset_time_s` (none: a constant).
    /// A speed input of zero is a stopped propeller: the vehicle coasts on with this time
    /// constant, s (log; none: it stops at once).
    pub speed_coast_time_s: Option<f64>,
    pub estimate_heading_offset: Option<bool>,
    pub heading_offset_sigma_deg: Option<f64>,
    pub heading_offset_time_s: Option<f64>,
    /// The seed of the estimator's random draws, any 64-bit integer (a particle
    /// filter's; log; default: the vehicle's `[initial]` seed, else 0).
    pub seed: Option<i64>,
    /// The iUSBL navigator's settings (kinds iusbl and iusbl-joint on a log).
    pub iusbl: Option<IusblKeys>,
}

impl EstimatorSpec {
    /// An estimator of `kind` with every other key at its default.
    pub fn new(kind: EstimatorKind) -> Self {
        Self {
            kind,
            name: None,
            measurements: None,
            filter: FilterName::Ekf,
            ukf_alpha: None,
            ukf_beta: None,
            ukf_kappa: None,
            range_sigma_m: None,
            doppler_sigma_m_s: None,
            heading_sigma_deg: None,
            usbl_sigma_deg_per_m: None,
            usbl_floor_deg: None,
            usbl_as_printed: None,
            usbl_misalignment_sigma_deg: None,
            usbl_misalignment_walk_deg_per_sqrt_s: None,
            compass_sigma_deg: None,
            depth_sigma_m: None,
            velocity_sigma_m_s: None,
            rate_sigma_rad_s: None,
            attitude_sigma_deg: None,
            process_noise_scale: None,
            process_sigma: None,
            particles: None,
            resampler: None,
            ess_fraction: None,
            roughening_k: None,
            min_effective_particles: None,
            yaw_rate_sigma_rad_s: None,
            accel_sigma_m_s2: None,
            q_diag: None,
            mirror_recovery: None,
            min_speed_m_s: None,
            distance_sigma_frac: None,
            heading_change_sigma_frac: None,
            heading_walk_deg_per_sqrt_m: None,
            speed_sigma_m_s: None,
            bias_walk_m_per_sqrt_s: None,
            position_walk_m_per_sqrt_s: None,
            track_accel_sigma_m_s2: None,
            nis_gate: None,
            robust: None,
            huber_k: None,
            student_t_dof: None,
            estimate_bias: None,
            estimate_bias_drift: None,
            bias_drift_sigma_m_s: None,
            estimate_beacon_offsets: None,
            bias_m: None,
            bias_sigma_m: None,
            estimate_range_scale: None,
            range_scale_sigma: None,
            estimate_distance_scale: None,
            distance_scale_sigma: None,
            estimate_turn_scale: None,
            turn_scale_sigma: None,
            estimate_current: None,
            current_sigma_m_s: None,
            current_walk_m_s_per_sqrt_s: None,
            speed_coast_time_s: None,
            estimate_heading_offset: None,
            heading_offset_sigma_deg: None,
            heading_offset_time_s: None,
            seed: None,
            iusbl: None,
        }
    }

    /// The value of a noise key (those of [`NOISE_KEYS`] and `track_accel_sigma_m_s2`),
    /// to read or set; None for another key.
    pub fn key_mut(&mut self, key: &str) -> Option<&mut Option<f64>> {
        Some(match key {
            "range_sigma_m" => &mut self.range_sigma_m,
            "doppler_sigma_m_s" => &mut self.doppler_sigma_m_s,
            "heading_sigma_deg" => &mut self.heading_sigma_deg,
            "distance_sigma_frac" => &mut self.distance_sigma_frac,
            "heading_change_sigma_frac" => &mut self.heading_change_sigma_frac,
            "heading_walk_deg_per_sqrt_m" => &mut self.heading_walk_deg_per_sqrt_m,
            "speed_sigma_m_s" => &mut self.speed_sigma_m_s,
            "bias_walk_m_per_sqrt_s" => &mut self.bias_walk_m_per_sqrt_s,
            "position_walk_m_per_sqrt_s" => &mut self.position_walk_m_per_sqrt_s,
            "track_accel_sigma_m_s2" => &mut self.track_accel_sigma_m_s2,
            _ => return None,
        })
    }

    /// Name in outputs: `name`, or the kind with "-ukf" for the UKF.
    pub fn name(&self) -> String {
        self.name.clone().unwrap_or_else(|| format!("{}{}", self.kind.label(), self.filter.suffix()))
    }

    pub fn filter_kind(&self) -> FilterKind {
        self.filter.kind(self.ukf_alpha, self.ukf_beta, self.ukf_kappa)
    }

    /// The acoustic measurements used in `host`: `measurements`, or the kind's.
    pub fn aiding(&self, host: Host) -> Aiding {
        match &self.measurements {
            Some(list) => Aiding {
                range: list.contains(&Acoustic::Range),
                doppler: list.contains(&Acoustic::Doppler),
                bearing: list.contains(&Acoustic::Bearing),
            },
            None => self.kind.aiding(host),
        }
    }

    /// garin2024's filter tuning (fixed_beacon): eq. 25 where a key is absent.
    pub fn ekf_tuning(&self) -> EkfTuning {
        let d = EkfTuning::default();
        let var = |sigma: Option<f64>, default: f64| sigma.map_or(default, |s| s * s);
        EkfTuning {
            q_diag: self.q_diag.unwrap_or(d.q_diag),
            r_range_m2: var(self.range_sigma_m, d.r_range_m2),
            r_doppler_m2_s2: var(self.doppler_sigma_m_s, d.r_doppler_m2_s2),
            r_heading_rad2: var(self.heading_sigma_deg.map(f64::to_radians), d.r_heading_rad2),
            r_yaw_rate_rad2_s2: var(self.yaw_rate_sigma_rad_s, d.r_yaw_rate_rad2_s2),
            r_accel_m2_s4: var(self.accel_sigma_m_s2, d.r_accel_m2_s4),
        }
    }

    /// The noise the 6-DOF filter assumes (moving_beacon): `sensors`, but for the keys
    /// given (`range_sigma_m`, `depth_sigma_m`, `velocity_sigma_m_s`,
    /// `rate_sigma_rad_s`, `attitude_sigma_deg`).
    pub fn sensor_noise(&self, sensors: SensorNoise) -> SensorNoise {
        SensorNoise {
            velocity_m_s: self.velocity_sigma_m_s.unwrap_or(sensors.velocity_m_s),
            rate_rad_s: self.rate_sigma_rad_s.unwrap_or(sensors.rate_rad_s),
            depth_m: self.depth_sigma_m.unwrap_or(sensors.depth_m),
            attitude_rad: self.attitude_sigma_deg.map_or(sensors.attitude_rad, f64::to_radians),
            range_m: self.range_sigma_m.unwrap_or(sensors.range_m),
        }
    }

    /// The calibration states of garin2024's and the 6-DOF filter (fixed_beacon,
    /// moving_beacon): the offset with its drift, the range scale and the current that
    /// are asked for, with [`PlanarConfig::default`]'s
    /// priors and walk where a key is absent.
    pub fn range_calibration(&self) -> RangeCalibration {
        let c = PlanarConfig::default();
        let drift = self.estimate_bias_drift == Some(true);
        let offset = (self.estimate_bias == Some(true) || drift).then(|| OffsetPrior {
            initial_m: self.bias_m.unwrap_or(c.bias_m),
            sigma_m: self.bias_sigma_m.unwrap_or(c.bias_sigma_m),
            walk_m_per_sqrt_s: self.bias_walk_m_per_sqrt_s.unwrap_or(c.noise.bias_walk_m_per_sqrt_s),
            drift_sigma_m_s: drift.then(|| self.bias_drift_sigma_m_s.unwrap_or(DEFAULT_BIAS_DRIFT_SIGMA_M_S)),
        });
        let scale_sigma =
            (self.estimate_range_scale == Some(true)).then(|| self.range_scale_sigma.unwrap_or(c.range_scale_sigma));
        let current = (self.estimate_current == Some(true)).then(|| CurrentPrior {
            sigma_m_s: self.current_sigma_m_s.unwrap_or(DEFAULT_CURRENT_SIGMA_M_S),
            walk_m_s_per_sqrt_s: self.current_walk_m_s_per_sqrt_s.unwrap_or(DEFAULT_CURRENT_WALK_M_S_PER_SQRT_S),
        });
        RangeCalibration { offset, scale_sigma, current }
    }

    /// The gate and heavy-tailed update of the navigator [`EstimatorSpec::builder`]
    /// builds on a log or a stream: [`EstimatorSpec::gate`], with the planar family's
    /// ranges and Doppler speeds gated at [`LOG_NIS_GATE`] where `nis_gate` is not given.
    pub fn log_gate(&self) -> (f64, Option<Robust>) {
        let (gate, robust) = self.gate();
        let planar = !self.kind.tracks_bearings() && !self.kind.iusbl();
        (if planar && self.nis_gate.is_none() { LOG_NIS_GATE } else { gate }, robust)
    }

    /// The gate (a NIS; infinity: none) and heavy-tailed update asked for (`nis_gate`,
    /// `robust`), of ranges, Doppler speeds, heading fixes and bearings alike.
    pub fn gate(&self) -> (f64, Option<Robust>) {
        let robust = self.robust.map(|r| match r {
            RobustName::Huber => Robust::Huber { k: self.huber_k.unwrap_or(1.345) },
            RobustName::StudentT => Robust::StudentT { dof: self.student_t_dof.unwrap_or(4.0) },
        });
        (self.nis_gate.unwrap_or(f64::INFINITY), robust)
    }

    /// The trackers' configuration (passive_usbl): the world's noise `n` (a matched
    /// filter) and [`HoffProcess::default`] where a key is absent.
    pub fn tracker_config(&self, n: TrackerNoise) -> TrackerConfig {
        let d = TrackerConfig::default();
        let scale = self.process_noise_scale.unwrap_or(1.0);
        let (nis_gate, robust) = self.gate();
        TrackerConfig {
            process: HoffProcess {
                sigma: self.process_sigma.unwrap_or(d.process.sigma).map(|s| s * scale),
                ..d.process
            },
            noise: TrackerNoise {
                usbl_sigma_rad_per_m: self.usbl_sigma_deg_per_m.map_or(n.usbl_sigma_rad_per_m, f64::to_radians),
                usbl_floor_rad: self.usbl_floor_deg.map_or(n.usbl_floor_rad, f64::to_radians),
                station_heading_sigma_rad: self.compass_sigma_deg.map_or(n.station_heading_sigma_rad, f64::to_radians),
                heading_sigma_rad: self.heading_sigma_deg.map_or(n.heading_sigma_rad, f64::to_radians),
                speed_sigma_m_s: self.speed_sigma_m_s.unwrap_or(n.speed_sigma_m_s),
                depth_sigma_m: self.depth_sigma_m.unwrap_or(n.depth_sigma_m),
                usbl_as_printed: self.usbl_as_printed.unwrap_or(n.usbl_as_printed),
            },
            aiding: self.aiding(Host::PassiveUsbl),
            nis_gate,
            robust,
            misalignment: self.usbl_misalignment_sigma_deg.map(|sigma| MisalignmentPrior {
                sigma_rad: sigma.to_radians(),
                walk_rad_per_sqrt_s: self
                    .usbl_misalignment_walk_deg_per_sqrt_s
                    .unwrap_or(DEFAULT_MISALIGNMENT_WALK_DEG_PER_SQRT_S)
                    .to_radians(),
            }),
        }
    }

    /// The particle filter's size and settings (pf).
    pub fn particle_settings(&self) -> (usize, ParticleSettings) {
        let d = ParticleSettings::default();
        let resampler = match self.resampler {
            None => d.resampler,
            Some(ResamplerName::Multinomial) => Resampler::Multinomial,
            Some(ResamplerName::Systematic) => Resampler::Systematic,
            Some(ResamplerName::Stratified) => Resampler::Stratified,
            Some(ResamplerName::Residual) => Resampler::Residual,
        };
        let settings = ParticleSettings {
            resampler,
            ess_fraction: self.ess_fraction.unwrap_or(d.ess_fraction),
            roughening_k: self.roughening_k.or(d.roughening_k),
            min_effective: self.min_effective_particles.unwrap_or(DEFAULT_MIN_EFFECTIVE),
        };
        (self.particles.unwrap_or(DEFAULT_PARTICLES), settings)
    }

    /// The planar navigator's configuration (logs): [`PlanarConfig::default`] where a
    /// key is absent.
    pub fn planar_config(&self) -> PlanarConfig {
        let c = PlanarConfig::default();
        let d = c.noise;
        let noise = PlanarNoise {
            distance_sigma_frac: self.distance_sigma_frac.unwrap_or(d.distance_sigma_frac),
            heading_change_sigma_frac: self.heading_change_sigma_frac.unwrap_or(d.heading_change_sigma_frac),
            heading_walk_rad_per_sqrt_m: self
                .heading_walk_deg_per_sqrt_m
                .map_or(d.heading_walk_rad_per_sqrt_m, f64::to_radians),
            speed_sigma_m_s: self.speed_sigma_m_s.unwrap_or(d.speed_sigma_m_s),
            range_sigma_m: self.range_sigma_m.unwrap_or(d.range_sigma_m),
            heading_sigma_rad: self.heading_sigma_deg.map_or(d.heading_sigma_rad, f64::to_radians),
            doppler_sigma_m_s: self.doppler_sigma_m_s.unwrap_or(d.doppler_sigma_m_s),
            bias_walk_m_per_sqrt_s: self.bias_walk_m_per_sqrt_s.unwrap_or(d.bias_walk_m_per_sqrt_s),
            position_walk_m_per_sqrt_s: self.position_walk_m_per_sqrt_s.unwrap_or(d.position_walk_m_per_sqrt_s),
        };
        PlanarConfig {
            aiding: self.aiding(Host::Log),
            estimate_bias: self.estimate_bias.unwrap_or(c.estimate_bias),
            estimate_beacon_offsets: self.estimate_beacon_offsets.unwrap_or(c.estimate_beacon_offsets),
            bias_m: self.bias_m.unwrap_or(c.bias_m),
            bias_sigma_m: self.bias_sigma_m.unwrap_or(c.bias_sigma_m),
            estimate_range_scale: self.estimate_range_scale.unwrap_or(c.estimate_range_scale),
            range_scale_sigma: self.range_scale_sigma.unwrap_or(c.range_scale_sigma),
            estimate_distance_scale: self.estimate_distance_scale.unwrap_or(c.estimate_distance_scale),
            distance_scale_sigma: self.distance_scale_sigma.unwrap_or(c.distance_scale_sigma),
            estimate_turn_scale: self.estimate_turn_scale.unwrap_or(c.estimate_turn_scale),
            turn_scale_sigma: self.turn_scale_sigma.unwrap_or(c.turn_scale_sigma),
            nis_gate: Some(self.log_gate().0),
            robust: self.gate().1,
            noise,
            speed_coast_time_s: self.speed_coast_time_s,
            heading_offset: (self.estimate_heading_offset == Some(true)).then(|| HeadingOffsetPrior {
                sigma_rad: self.heading_offset_sigma_deg.unwrap_or(DEFAULT_HEADING_OFFSET_SIGMA_DEG).to_radians(),
                time_s: self.heading_offset_time_s.unwrap_or(f64::INFINITY),
            }),
            current: self.range_calibration().current,
            track_accel_sigma_m_s2: self.track_accel_sigma_m_s2,
        }
    }
}
