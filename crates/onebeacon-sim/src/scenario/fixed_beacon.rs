//! Scenarios of kind `fixed_beacon` (garin2024): an AUV on a boustrophedon, a fixed
//! beacon, range and Doppler from communication frames. Unknown keys are errors.

use super::estimator::Host;
use super::validate::*;
use super::{EstimatorKind, EstimatorSpec, World, default_runs, default_seed};
use serde::{Deserialize, Serialize};

/// A complete fixed-beacon scenario: the world, the vehicle, its sensors, the
/// estimators compared on the same runs, and the Monte Carlo sweep.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FixedBeacon {
    /// `fixed_beacon` (the default).
    #[serde(default)]
    pub kind: World,
    /// Short name, used in outputs.
    pub name: String,
    /// One line shown by `onebeacon scenarios`.
    #[serde(default)]
    pub description: String,
    /// Base seed of the runs (the CLI's `--seed` overrides it).
    #[serde(default = "default_seed")]
    pub seed: u64,
    /// Monte Carlo runs per sweep cell (the CLI's `--runs` overrides it).
    #[serde(default = "default_runs::<300>")]
    pub runs: usize,
    #[serde(default)]
    pub mission: Mission,
    #[serde(default)]
    pub path: PathSpec,
    #[serde(default)]
    pub beacon: Beacon,
    #[serde(default)]
    pub comms: Comms,
    #[serde(default)]
    pub sensors: Sensors,
    /// `[sea]`: clocks (off by default).
    #[serde(default)]
    pub sea: super::sea::Sea,
    #[serde(default)]
    pub initial: Initial,
    #[serde(default = "default_estimators")]
    pub estimators: Vec<EstimatorSpec>,
    #[serde(default)]
    pub sweep: Sweep,
}

fn default_estimators() -> Vec<EstimatorSpec> {
    vec![EstimatorSpec::new(EstimatorKind::RangeDoppler), EstimatorSpec::new(EstimatorKind::Rosb)]
}

/// Time step, speed and duration.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct Mission {
    /// Simulation and filter time step, s (garin2024 Table 2: 250 ms).
    pub dt_s: f64,
    /// Speed along the path, m/s (garin2024 section 4.1.1: about 1 m/s).
    pub speed_m_s: f64,
    /// Mission duration, s; absent: the time to travel the whole path.
    pub duration_s: Option<f64>,
}

impl Default for Mission {
    fn default() -> Self {
        Self { dt_s: 0.25, speed_m_s: 1.0, duration_s: None }
    }
}

/// Boustrophedon survey path.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct PathSpec {
    pub start_north_m: f64,
    pub start_east_m: f64,
    /// Direction of the first leg, deg from north toward east.
    pub leg_heading_deg: f64,
    /// Length of each straight leg, m.
    pub leg_length_m: f64,
    /// Distance between legs (diameter of the half-circle turns), m.
    pub leg_spacing_m: f64,
    /// Number of legs.
    pub legs: usize,
    /// Side the legs advance to, seen along the first leg.
    pub turn: Turn,
}

impl Default for PathSpec {
    fn default() -> Self {
        // 6 legs of 235 m, 20 m apart: 1567 m, inside about 100 m x 255 m (garin2024 4.1.1)
        Self {
            start_north_m: 0.0,
            start_east_m: 0.0,
            leg_heading_deg: 90.0,
            leg_length_m: 235.0,
            leg_spacing_m: 20.0,
            legs: 6,
            turn: Turn::Left,
        }
    }
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Turn {
    Left,
    Right,
}

/// The fixed beacon.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct Beacon {
    pub north_m: f64,
    pub east_m: f64,
}

impl Default for Beacon {
    fn default() -> Self {
        Self { north_m: 50.0, east_m: 100.0 } // garin2024 Table 2
    }
}

/// The acoustic communication schedule.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct Comms {
    /// Period between communication frames, s.
    pub t_com_s: f64,
    /// Probability that a frame is not decoded, in [0, 1].
    pub frame_loss_prob: f64,
}

impl Default for Comms {
    fn default() -> Self {
        Self { t_com_s: 3.0, frame_loss_prob: 0.0 }
    }
}

pub use crate::sensors::Sensors;

/// Initial uncertainty: the filters start at the truth plus an error drawn with these
/// standard deviations (the same draw for every estimator), with the matching
/// covariance.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct Initial {
    pub position_sigma_m: f64,
    pub heading_sigma_deg: f64,
    pub speed_sigma_m_s: f64,
    pub yaw_rate_sigma_rad_s: f64,
    pub accel_sigma_m_s2: f64,
}

impl Default for Initial {
    fn default() -> Self {
        Self {
            position_sigma_m: 0.5,
            heading_sigma_deg: 2.0,
            speed_sigma_m_s: 0.05,
            yaw_rate_sigma_rad_s: 0.01,
            accel_sigma_m_s2: 0.01,
        }
    }
}

/// Values swept by `mc`; each combination is one cell. An absent key keeps the
/// scenario's value.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct Sweep {
    /// Communication periods, s.
    pub t_com_s: Option<Vec<f64>>,
}

/// One sweep cell of a fixed-beacon scenario.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FixedBeaconCell {
    pub t_com_s: f64,
}

impl FixedBeacon {
    /// The cell of the base scenario (no sweep).
    pub fn base_cell(&self) -> FixedBeaconCell {
        FixedBeaconCell { t_com_s: self.comms.t_com_s }
    }

    /// All sweep cells, in order.
    pub fn cells(&self) -> Vec<FixedBeaconCell> {
        match &self.sweep.t_com_s {
            Some(v) => v.iter().map(|&t_com_s| FixedBeaconCell { t_com_s }).collect(),
            None => vec![self.base_cell()],
        }
    }

    /// Mission duration, s.
    pub fn duration_s(&self) -> f64 {
        self.mission.duration_s.unwrap_or_else(|| self.path().length() / self.mission.speed_m_s)
    }

    /// Number of filter steps after the initial one.
    pub fn steps(&self) -> usize {
        (self.duration_s() / self.mission.dt_s).round() as usize
    }

    /// The reference path.
    pub fn path(&self) -> crate::vehicles::Path {
        let p = &self.path;
        crate::vehicles::Path::boustrophedon(
            nalgebra::Vector2::new(p.start_north_m, p.start_east_m),
            p.leg_heading_deg.to_radians(),
            p.leg_length_m,
            p.leg_spacing_m,
            p.legs,
            p.turn == Turn::Left,
        )
    }

    /// Beacon position, NED m.
    pub fn beacon_ned_m(&self) -> nalgebra::Vector2<f64> {
        nalgebra::Vector2::new(self.beacon.north_m, self.beacon.east_m)
    }
}

// ---- validation: the range checks of this world's keys

pub(super) fn validate_fixed(s: &FixedBeacon) -> Result<(), Violation> {
    use Rule::*;
    check_file_name("name", &s.name)?;
    check_count("runs", s.runs, 1, 1_000_000)?;
    s.sea.check(s.kind)?;

    let m = &s.mission;
    check_fields!("mission", m, {
        dt_s: Positive,
        speed_m_s: Positive,
    });
    if let Some(d) = m.duration_s {
        check("mission.duration_s", d, Positive)?;
    }

    let p = &s.path;
    check_fields!("path", p, {
        start_north_m: Finite,
        start_east_m: Finite,
        leg_heading_deg: Finite,
        leg_length_m: Positive,
        leg_spacing_m: Positive,
    });
    check_count("path.legs", p.legs, 1, 10_000)?;

    check_fields!("beacon", s.beacon, {
        north_m: Finite,
        east_m: Finite,
    });

    check_fields!("comms", s.comms, {
        t_com_s: Positive,
        frame_loss_prob: Probability,
    });

    let n = &s.sensors;
    check_fields!("sensors", n, {
        range_noise_m: NonNegative,
        doppler_noise_m_s: NonNegative,
        heading_noise_deg: NonNegative,
        heading_bias_deg: NonNegative,
        heading_bias_drift_deg_per_h: NonNegative,
        gyro_noise_rad_s: NonNegative,
        accel_noise_m_s2: NonNegative,
    });

    let i = &s.initial;
    check_fields!("initial", i, {
        position_sigma_m: Positive,
        heading_sigma_deg: Positive,
        speed_sigma_m_s: Positive,
        yaw_rate_sigma_rad_s: Positive,
        accel_sigma_m_s2: Positive,
    });

    check_estimators(&s.estimators, Host::FixedBeacon)?;

    if let Some(v) = &s.sweep.t_com_s {
        if v.is_empty() {
            return Err(Violation {
                key: "sweep.t_com_s".into(),
                value: "[]".into(),
                allowed: "must list at least one value, or be left out".into(),
            });
        }
        for (j, &t) in v.iter().enumerate() {
            check(&format!("sweep.t_com_s[{j}]"), t, Positive)?;
        }
    }

    // the run must be of a workable size
    let duration_key =
        if m.duration_s.is_some() { "mission.duration_s" } else { "mission.speed_m_s (the path's length / speed_m_s)" };
    check_steps(s.duration_s(), m.dt_s, duration_key)
}
