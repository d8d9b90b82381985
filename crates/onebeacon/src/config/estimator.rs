//! One estimator description for every world and every log: the `[[estimators]]`
//! table of scenarios and log descriptions alike. An estimator is its short name
//! (`kind`), the acoustic measurements it uses, its filter (EKF or UKF with its
//! sigma-point parameters, or a particle filter) and its tuning. The process model is
//! the host's: the unicycle with acceleration in `fixed_beacon` worlds (garin2024 eq.
//! 3-7), 6-DOF kinematics in `moving_beacon` worlds (sousa 3.1), the stochastic
//! unicycle of hoff2024 eq. 4 in `passive_usbl` worlds, planar odometry on logs.

pub use super::estimator_defaults::*;
pub use super::estimator_keys::{
    CalibrationKeys, GateKeys, NoiseKeys, ParticleKeys, PlanarKeys, ResamplerName, RobustName, SixDofKeys,
    UnicycleKeys, UsblKeys,
};
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

/// One `[[estimators]]` table. Every key but `kind` is optional; tuning keys are
/// grouped by what they tune ([`super::estimator_keys`]; the table stays flat) and apply
/// to the hosts named beside them (validation refuses the others).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct EstimatorSpec {
    pub kind: EstimatorKind,
    /// Name in outputs (default: the kind, with "-ukf" for the UKF).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub name: Option<String>,
    /// The acoustic measurements used (default: the kind's): `["range"]`,
    /// `["range", "doppler"]`, `[]`...
    #[serde(skip_serializing_if = "Option::is_none")]
    pub measurements: Option<Vec<Acoustic>>,
    /// `"ekf"` (default) or `"ukf"`, with the UKF's sigma-point parameters (1, 2, 0).
    pub filter: FilterName,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub ukf_alpha: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub ukf_beta: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub ukf_kappa: Option<f64>,
    #[serde(flatten)]
    pub noise: NoiseKeys,
    #[serde(flatten)]
    pub gating: GateKeys,
    #[serde(flatten)]
    pub calibration: CalibrationKeys,
    #[serde(flatten)]
    pub unicycle: UnicycleKeys,
    #[serde(flatten)]
    pub six_dof: SixDofKeys,
    #[serde(flatten)]
    pub usbl: UsblKeys,
    #[serde(flatten)]
    pub particle: ParticleKeys,
    #[serde(flatten)]
    pub planar: PlanarKeys,
    /// The seed of the estimator's random draws, any 64-bit integer (a particle
    /// filter's; log; default: the vehicle's `[initial]` seed, else 0).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub seed: Option<i64>,
    /// The iUSBL navigator's settings (kinds iusbl and iusbl-joint on a log).
    #[serde(skip_serializing_if = "Option::is_none")]
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
            noise: NoiseKeys::default(),
            gating: GateKeys::default(),
            calibration: CalibrationKeys::default(),
            unicycle: UnicycleKeys::default(),
            six_dof: SixDofKeys::default(),
            usbl: UsblKeys::default(),
            particle: ParticleKeys::default(),
            planar: PlanarKeys::default(),
            seed: None,
            iusbl: None,
        }
    }

    /// The value of a noise key (those of [`NOISE_KEYS`] and `track_accel_sigma_m_s2`),
    /// to read or set; None for another key.
    pub fn key_mut(&mut self, key: &str) -> Option<&mut Option<f64>> {
        Some(match key {
            "range_sigma_m" => &mut self.noise.range_sigma_m,
            "doppler_sigma_m_s" => &mut self.noise.doppler_sigma_m_s,
            "heading_sigma_deg" => &mut self.noise.heading_sigma_deg,
            "distance_sigma_frac" => &mut self.planar.distance_sigma_frac,
            "heading_change_sigma_frac" => &mut self.planar.heading_change_sigma_frac,
            "heading_walk_deg_per_sqrt_m" => &mut self.planar.heading_walk_deg_per_sqrt_m,
            "speed_sigma_m_s" => &mut self.noise.speed_sigma_m_s,
            "bias_walk_m_per_sqrt_s" => &mut self.calibration.bias_walk_m_per_sqrt_s,
            "position_walk_m_per_sqrt_s" => &mut self.planar.position_walk_m_per_sqrt_s,
            "track_accel_sigma_m_s2" => &mut self.planar.track_accel_sigma_m_s2,
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
            q_diag: self.unicycle.q_diag.unwrap_or(d.q_diag),
            r_range_m2: var(self.noise.range_sigma_m, d.r_range_m2),
            r_doppler_m2_s2: var(self.noise.doppler_sigma_m_s, d.r_doppler_m2_s2),
            r_heading_rad2: var(self.noise.heading_sigma_deg.map(f64::to_radians), d.r_heading_rad2),
            r_yaw_rate_rad2_s2: var(self.unicycle.yaw_rate_sigma_rad_s, d.r_yaw_rate_rad2_s2),
            r_accel_m2_s4: var(self.unicycle.accel_sigma_m_s2, d.r_accel_m2_s4),
        }
    }

    /// The noise the 6-DOF filter assumes (moving_beacon): `sensors`, but for the keys
    /// given (`range_sigma_m`, `depth_sigma_m`, `velocity_sigma_m_s`,
    /// `rate_sigma_rad_s`, `attitude_sigma_deg`).
    pub fn sensor_noise(&self, sensors: SensorNoise) -> SensorNoise {
        SensorNoise {
            velocity_m_s: self.six_dof.velocity_sigma_m_s.unwrap_or(sensors.velocity_m_s),
            rate_rad_s: self.six_dof.rate_sigma_rad_s.unwrap_or(sensors.rate_rad_s),
            depth_m: self.noise.depth_sigma_m.unwrap_or(sensors.depth_m),
            attitude_rad: self.six_dof.attitude_sigma_deg.map_or(sensors.attitude_rad, f64::to_radians),
            range_m: self.noise.range_sigma_m.unwrap_or(sensors.range_m),
        }
    }

    /// The calibration states of garin2024's and the 6-DOF filter (fixed_beacon,
    /// moving_beacon): the offset with its drift, the range scale and the current that
    /// are asked for, with [`PlanarConfig::default`]'s
    /// priors and walk where a key is absent.
    pub fn range_calibration(&self) -> RangeCalibration {
        let c = PlanarConfig::default();
        let drift = self.calibration.estimate_bias_drift == Some(true);
        let offset = (self.calibration.estimate_bias == Some(true) || drift).then(|| OffsetPrior {
            initial_m: self.calibration.bias_m.unwrap_or(c.bias_m),
            sigma_m: self.calibration.bias_sigma_m.unwrap_or(c.bias_sigma_m),
            walk_m_per_sqrt_s: self.calibration.bias_walk_m_per_sqrt_s.unwrap_or(c.noise.bias_walk_m_per_sqrt_s),
            drift_sigma_m_s: drift
                .then(|| self.calibration.bias_drift_sigma_m_s.unwrap_or(DEFAULT_BIAS_DRIFT_SIGMA_M_S)),
        });
        let scale_sigma = (self.calibration.estimate_range_scale == Some(true))
            .then(|| self.calibration.range_scale_sigma.unwrap_or(c.range_scale_sigma));
        let current = (self.calibration.estimate_current == Some(true)).then(|| CurrentPrior {
            sigma_m_s: self.calibration.current_sigma_m_s.unwrap_or(DEFAULT_CURRENT_SIGMA_M_S),
            walk_m_s_per_sqrt_s: self
                .calibration
                .current_walk_m_s_per_sqrt_s
                .unwrap_or(DEFAULT_CURRENT_WALK_M_S_PER_SQRT_S),
        });
        RangeCalibration { offset, scale_sigma, current }
    }

    /// The gate and heavy-tailed update of the navigator [`EstimatorSpec::builder`]
    /// builds on a log or a stream: [`EstimatorSpec::gate`], with the planar family's
    /// ranges and Doppler speeds gated at [`LOG_NIS_GATE`] where `nis_gate` is not given.
    pub fn log_gate(&self) -> (f64, Option<Robust>) {
        let (gate, robust) = self.gate();
        let planar = !self.kind.tracks_bearings() && !self.kind.iusbl();
        (if planar && self.gating.nis_gate.is_none() { LOG_NIS_GATE } else { gate }, robust)
    }

    /// The gate (a NIS; infinity: none) and heavy-tailed update asked for (`nis_gate`,
    /// `robust`), of ranges, Doppler speeds, heading fixes and bearings alike.
    pub fn gate(&self) -> (f64, Option<Robust>) {
        let robust = self.gating.robust.map(|r| match r {
            RobustName::Huber => Robust::Huber { k: self.gating.huber_k.unwrap_or(1.345) },
            RobustName::StudentT => Robust::StudentT { dof: self.gating.student_t_dof.unwrap_or(4.0) },
        });
        (self.gating.nis_gate.unwrap_or(f64::INFINITY), robust)
    }

    /// The trackers' configuration (passive_usbl): the world's noise `n` (a matched
    /// filter) and [`HoffProcess::default`] where a key is absent.
    pub fn tracker_config(&self, n: TrackerNoise) -> TrackerConfig {
        let d = TrackerConfig::default();
        let scale = self.usbl.process_noise_scale.unwrap_or(1.0);
        let (nis_gate, robust) = self.gate();
        TrackerConfig {
            process: HoffProcess {
                sigma: self.usbl.process_sigma.unwrap_or(d.process.sigma).map(|s| s * scale),
                ..d.process
            },
            noise: TrackerNoise {
                usbl_sigma_rad_per_m: self.usbl.usbl_sigma_deg_per_m.map_or(n.usbl_sigma_rad_per_m, f64::to_radians),
                usbl_floor_rad: self.usbl.usbl_floor_deg.map_or(n.usbl_floor_rad, f64::to_radians),
                station_heading_sigma_rad: self
                    .usbl
                    .compass_sigma_deg
                    .map_or(n.station_heading_sigma_rad, f64::to_radians),
                heading_sigma_rad: self.noise.heading_sigma_deg.map_or(n.heading_sigma_rad, f64::to_radians),
                speed_sigma_m_s: self.noise.speed_sigma_m_s.unwrap_or(n.speed_sigma_m_s),
                depth_sigma_m: self.noise.depth_sigma_m.unwrap_or(n.depth_sigma_m),
                usbl_as_printed: self.usbl.usbl_as_printed.unwrap_or(n.usbl_as_printed),
            },
            aiding: self.aiding(Host::PassiveUsbl),
            nis_gate,
            robust,
            misalignment: self.usbl.usbl_misalignment_sigma_deg.map(|sigma| MisalignmentPrior {
                sigma_rad: sigma.to_radians(),
                walk_rad_per_sqrt_s: self
                    .usbl
                    .usbl_misalignment_walk_deg_per_sqrt_s
                    .unwrap_or(DEFAULT_MISALIGNMENT_WALK_DEG_PER_SQRT_S)
                    .to_radians(),
            }),
        }
    }

    /// The particle filter's size and settings (pf).
    pub fn particle_settings(&self) -> (usize, ParticleSettings) {
        let d = ParticleSettings::default();
        let resampler = match self.particle.resampler {
            None => d.resampler,
            Some(ResamplerName::Multinomial) => Resampler::Multinomial,
            Some(ResamplerName::Systematic) => Resampler::Systematic,
            Some(ResamplerName::Stratified) => Resampler::Stratified,
            Some(ResamplerName::Residual) => Resampler::Residual,
        };
        let settings = ParticleSettings {
            resampler,
            ess_fraction: self.particle.ess_fraction.unwrap_or(d.ess_fraction),
            roughening_k: self.particle.roughening_k.or(d.roughening_k),
            min_effective: self.particle.min_effective_particles.unwrap_or(DEFAULT_MIN_EFFECTIVE),
        };
        (self.particle.particles.unwrap_or(DEFAULT_PARTICLES), settings)
    }

    /// The planar navigator's configuration (logs): [`PlanarConfig::default`] where a
    /// key is absent.
    pub fn planar_config(&self) -> PlanarConfig {
        let c = PlanarConfig::default();
        let d = c.noise;
        let noise = PlanarNoise {
            distance_sigma_frac: self.planar.distance_sigma_frac.unwrap_or(d.distance_sigma_frac),
            heading_change_sigma_frac: self.planar.heading_change_sigma_frac.unwrap_or(d.heading_change_sigma_frac),
            heading_walk_rad_per_sqrt_m: self
                .planar
                .heading_walk_deg_per_sqrt_m
                .map_or(d.heading_walk_rad_per_sqrt_m, f64::to_radians),
            speed_sigma_m_s: self.noise.speed_sigma_m_s.unwrap_or(d.speed_sigma_m_s),
            range_sigma_m: self.noise.range_sigma_m.unwrap_or(d.range_sigma_m),
            heading_sigma_rad: self.noise.heading_sigma_deg.map_or(d.heading_sigma_rad, f64::to_radians),
            doppler_sigma_m_s: self.noise.doppler_sigma_m_s.unwrap_or(d.doppler_sigma_m_s),
            bias_walk_m_per_sqrt_s: self.calibration.bias_walk_m_per_sqrt_s.unwrap_or(d.bias_walk_m_per_sqrt_s),
            position_walk_m_per_sqrt_s: self.planar.position_walk_m_per_sqrt_s.unwrap_or(d.position_walk_m_per_sqrt_s),
        };
        PlanarConfig {
            aiding: self.aiding(Host::Log),
            estimate_bias: self.calibration.estimate_bias.unwrap_or(c.estimate_bias),
            estimate_beacon_offsets: self.calibration.estimate_beacon_offsets.unwrap_or(c.estimate_beacon_offsets),
            bias_m: self.calibration.bias_m.unwrap_or(c.bias_m),
            bias_sigma_m: self.calibration.bias_sigma_m.unwrap_or(c.bias_sigma_m),
            estimate_range_scale: self.calibration.estimate_range_scale.unwrap_or(c.estimate_range_scale),
            range_scale_sigma: self.calibration.range_scale_sigma.unwrap_or(c.range_scale_sigma),
            estimate_distance_scale: self.calibration.estimate_distance_scale.unwrap_or(c.estimate_distance_scale),
            distance_scale_sigma: self.calibration.distance_scale_sigma.unwrap_or(c.distance_scale_sigma),
            estimate_turn_scale: self.calibration.estimate_turn_scale.unwrap_or(c.estimate_turn_scale),
            turn_scale_sigma: self.calibration.turn_scale_sigma.unwrap_or(c.turn_scale_sigma),
            nis_gate: Some(self.log_gate().0),
            robust: self.gate().1,
            noise,
            speed_coast_time_s: self.planar.speed_coast_time_s,
            heading_offset: (self.calibration.estimate_heading_offset == Some(true)).then(|| HeadingOffsetPrior {
                sigma_rad: self
                    .calibration
                    .heading_offset_sigma_deg
                    .unwrap_or(DEFAULT_HEADING_OFFSET_SIGMA_DEG)
                    .to_radians(),
                time_s: self.calibration.heading_offset_time_s.unwrap_or(f64::INFINITY),
            }),
            current: self.range_calibration().current,
            track_accel_sigma_m_s2: self.planar.track_accel_sigma_m_s2,
        }
    }
}
