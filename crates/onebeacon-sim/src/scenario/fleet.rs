//! Scenarios of kind `fleet` (rypkema): AUVs without DVLs each hear one beacon on a
//! 5-element array, navigate relative to it with the iUSBL particle filter and fly
//! beacon-relative behaviours chosen by the chirp the beacon sends. The beacon rides on
//! a boat along a scripted track; a fixed beacon at the dock can take over (the return
//! of rypkema's missions). Unknown keys are errors.
//!
//! Frames: keys are NED (`north`, `east`), headings from north; the paper's tables give
//! ENU offsets (x east, y north), converted in the built-in files.

use super::validate::*;
use super::{EstimatorKind, EstimatorSpec, World, default_runs, default_seed};
use crate::vehicles::sandshark::SandSharkParams;
use onebeacon::config::builder::VehicleModel;
use onebeacon::nav::capability::Capability;
use serde::{Deserialize, Serialize};

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Fleet {
    /// `fleet`.
    pub kind: World,
    pub name: String,
    #[serde(default)]
    pub description: String,
    #[serde(default = "default_seed")]
    pub seed: u64,
    #[serde(default = "default_runs::<4>")]
    pub runs: usize,
    #[serde(default)]
    pub mission: FleetMission,
    #[serde(default)]
    pub signal: Signal,
    #[serde(default)]
    pub sandshark: SandSharkParams,
    #[serde(default)]
    pub navigation: Navigation,
    /// What the errors are scored against (the truth, or a reference with its own error).
    #[serde(default)]
    pub reference: Reference,
    /// `[sea]`: clocks, the link's losses and outliers, a sound-speed profile (off by
    /// default).
    #[serde(default)]
    pub sea: super::sea::Sea,
    /// The boat's track: the beacon it tows follows it (linear between waypoints, held
    /// after the last).
    pub boat: Vec<Waypoint>,
    #[serde(default)]
    pub dock: Dock,
    /// Which mode is sent from which beacon from when (in time order); mode 0: silent.
    pub schedule: Vec<ScheduleEntry>,
    pub auvs: Vec<FleetAuv>,
    /// The estimators every AUV runs, by kind (the first flies the behaviours): `iusbl`,
    /// `iusbl-joint`, `dead-reckoning`.
    #[serde(default = "default_estimators")]
    pub estimators: Vec<EstimatorKind>,
}

/// `[reference]`: the position the statistics score each estimate against. The paper
/// could score only against its LBL system (rypkema sec. 5.2), whose fixes have a
/// standard deviation of 3.9 m (Rypkema and Schmidt 2019, as the paper cites it; taken
/// here per horizontal axis); scoring against such a reference compares the simulation
/// with Table 3 like for like.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct Reference {
    /// Each step's reference fix is the truth plus an independent Gaussian error of this
    /// standard deviation on north and on east, m (0: the truth itself).
    pub sigma_m: f64,
}

fn default_estimators() -> Vec<EstimatorKind> {
    vec![EstimatorKind::Iusbl, EstimatorKind::IusblJoint, EstimatorKind::DeadReckoning]
}

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct FleetMission {
    pub duration_s: f64,
    /// Vehicle integration and sensor step, s.
    pub dt_s: f64,
    /// The beacon's transmit period (its PPS), s.
    pub ping_period_s: f64,
}

impl Default for FleetMission {
    fn default() -> Self {
        Self { duration_s: 3600.0, dt_s: 0.1, ping_period_s: 1.0 }
    }
}

/// How a ping reaches the filter.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum SignalModel {
    /// The chirp through the channel simulation to every element of each AUV's moving
    /// array, and the receiver chain on board (matched filter, mode bank, SPD-BF).
    #[default]
    Channel,
    /// Range, direction and mode drawn from noise models with multipath outliers.
    Abstract,
}

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct Signal {
    pub model: SignalModel,
    pub sound_speed_m_s: f64,
    /// Channel: water depth, surface and bottom pressure reflection coefficients.
    pub water_depth_m: f64,
    pub surface_coef: f64,
    pub bottom_coef: f64,
    /// Channel: 2E/N0 per element of the direct path at 100 m, dB (spherical spreading
    /// elsewhere: 20 log10 of the range).
    pub snr_db_at_100m: f64,
    /// Abstract: range and angle noise (1 sigma), m and deg.
    pub range_sigma_m: f64,
    pub angle_sigma_deg: f64,
    /// Abstract: a ping is a multipath outlier with this probability: its range a
    /// later arrival (up to `outlier_max_m` longer) and its direction uniform.
    pub outlier_probability: f64,
    pub outlier_max_m: f64,
    /// Abstract: a ping's mode is identified wrongly with this probability.
    pub mode_error_probability: f64,
    /// No ping is heard from farther than this, m (the capture window: 290 m).
    pub max_range_m: f64,
}

impl Default for Signal {
    fn default() -> Self {
        Self {
            model: SignalModel::Channel,
            sound_speed_m_s: 1481.0,
            water_depth_m: 5.3,
            surface_coef: -0.9,
            bottom_coef: 0.3,
            snr_db_at_100m: 30.0,
            range_sigma_m: 0.3,
            angle_sigma_deg: 3.0,
            outlier_probability: 0.1,
            outlier_max_m: 30.0,
            mode_error_probability: 0.02,
            max_range_m: 290.0,
        }
    }
}

/// The iUSBL navigator's tuning (defaults of `onebeacon::nav::IusblConfig`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct Navigation {
    pub particles: usize,
    pub reinitialised: usize,
    pub max_range_m: f64,
    pub sigma_speed_m_s: f64,
    pub sigma_heading_deg: f64,
    pub beacon_speed_m_s: f64,
    pub floor: f64,
    pub beam_exponent: f64,
    pub confirmations: usize,
    /// Dead reckoning's belief in a current: its prior standard deviation per axis, m/s,
    /// and its random walk, m/s per sqrt(s) (0: no current state).
    pub current_sigma_m_s: f64,
    pub current_walk_m_s_per_sqrt_s: f64,
}

impl Default for Navigation {
    fn default() -> Self {
        // the iUSBL navigator's defaults, as a log's `[estimators.iusbl]` has them
        let k = super::iusbl::IusblKeys::default();
        Self {
            particles: k.particles,
            reinitialised: k.reinitialised,
            max_range_m: k.max_range_m,
            sigma_speed_m_s: k.sigma_speed_m_s,
            sigma_heading_deg: k.sigma_heading_deg,
            beacon_speed_m_s: k.beacon_speed_m_s,
            floor: k.floor,
            beam_exponent: k.beam_exponent,
            confirmations: k.confirmations,
            current_sigma_m_s: 0.0,
            current_walk_m_s_per_sqrt_s: 0.0,
        }
    }
}

/// One point of the boat's track.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Waypoint {
    pub t_s: f64,
    pub north_m: f64,
    pub east_m: f64,
}

/// The beacons' depth and GPS, and the fixed beacon at the dock.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct Dock {
    pub north_m: f64,
    pub east_m: f64,
    /// Depth of both beacons (the towed one and the dock's), m.
    pub beacon_depth_m: f64,
    /// The boat's GPS error per axis, m.
    pub gps_sigma_m: f64,
}

impl Default for Dock {
    fn default() -> Self {
        Self { north_m: 0.0, east_m: 0.0, beacon_depth_m: 1.0, gps_sigma_m: 0.1 }
    }
}

/// Which beacon transmits.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Transmitter {
    #[default]
    Boat,
    Dock,
}

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ScheduleEntry {
    pub t_s: f64,
    /// 1 to 4 (rypkema's chirps 7-9, 10-8, 8-6, 9-11 kHz); 0: silent.
    pub mode: usize,
    #[serde(default)]
    pub from: Transmitter,
}

/// One AUV: where it is launched, when, and what it does in each mode.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FleetAuv {
    pub name: String,
    #[serde(default)]
    pub start_north_m: f64,
    #[serde(default)]
    pub start_east_m: f64,
    #[serde(default)]
    pub start_heading_deg: f64,
    /// When it is put in the water (at the surface until then), s.
    #[serde(default)]
    pub launch_s: f64,
    #[serde(default = "default_speed")]
    pub speed_m_s: f64,
    #[serde(default = "default_depth")]
    pub depth_m: f64,
    pub modes: Vec<ModeBehaviour>,
}

fn default_speed() -> f64 {
    1.0
}
fn default_depth() -> f64 {
    2.5
}

/// The behaviours by mode: the onboard crate's configuration types.
pub use onebeacon::config::controller::{BehaviourName, MODES, ModeBehaviour};

impl Fleet {
    pub fn steps(&self) -> usize {
        (self.mission.duration_s / self.mission.dt_s).round() as usize
    }

    /// The boat's position at `t` (NED, m; at the beacon's depth).
    pub fn boat_at(&self, t: f64) -> nalgebra::Vector3<f64> {
        let z = self.dock.beacon_depth_m;
        let w = &self.boat;
        let at = |p: &Waypoint| nalgebra::Vector3::new(p.north_m, p.east_m, z);
        match w.iter().position(|p| p.t_s > t) {
            Some(0) => at(&w[0]),
            None => at(&w[w.len() - 1]),
            Some(i) => {
                let (a, b) = (&w[i - 1], &w[i]);
                let f = (t - a.t_s) / (b.t_s - a.t_s);
                at(a) + (at(b) - at(a)) * f
            }
        }
    }

    /// The schedule entry in force at `t`, if any.
    pub fn scheduled(&self, t: f64) -> Option<&ScheduleEntry> {
        self.schedule.iter().rev().find(|e| e.t_s <= t)
    }
}

// ---- validation: the range checks of this world's keys

pub(super) fn validate_fleet(s: &Fleet) -> Result<(), Violation> {
    check_file_name("name", &s.name)?;
    check_count("runs", s.runs, 1, 1_000_000)?;
    check_fields!("mission", s.mission, { duration_s: Positive, dt_s: Positive, ping_period_s: Positive });
    check_fields!("reference", s.reference, { sigma_m: NonNegative });
    s.sea.check(s.kind)?;
    // the channel simulation has its own reflections and straight rays
    if s.signal.model == SignalModel::Channel {
        let l = &s.sea.link;
        for (key, set) in [
            ("sea.link.multipath_prob", l.multipath_prob > 0.0),
            ("sea.link.false_prob", l.false_prob > 0.0),
            ("sea.sound_speed", s.sea.sound_speed.is_some()),
        ] {
            if set {
                return Err(Violation {
                    key: key.into(),
                    value: "(set)".into(),
                    allowed: "applies to signal.model = \"abstract\" (the channel simulation reflects off the surface and bottom itself, along straight rays)".into(),
                });
            }
        }
    }
    if s.mission.dt_s > s.mission.ping_period_s {
        return Err(violation("mission.dt_s", s.mission.dt_s, "must be at most mission.ping_period_s"));
    }
    check_steps(s.mission.duration_s, s.mission.dt_s, "mission.duration_s")?;
    check_fields!("signal", s.signal, {
        sound_speed_m_s: Positive,
        water_depth_m: Positive,
        snr_db_at_100m: Finite,
        range_sigma_m: NonNegative,
        angle_sigma_deg: NonNegative,
        outlier_probability: Probability,
        outlier_max_m: NonNegative,
        mode_error_probability: Probability,
        max_range_m: Positive,
    });
    for (key, v) in [("signal.surface_coef", s.signal.surface_coef), ("signal.bottom_coef", s.signal.bottom_coef)] {
        if !(-1.0..=1.0).contains(&v) {
            return Err(violation(key, v, "must be a reflection coefficient in [-1, 1]"));
        }
    }
    check_fields!("sandshark", s.sandshark, {
        max_turn_rate_deg_s: Positive,
        heading_gain_per_s: Positive,
        speed_time_constant_s: Positive,
        coast_time_constant_s: Positive,
        max_depth_rate_m_s: Positive,
        depth_gain_per_s: Positive,
        rise_rate_m_s: NonNegative,
        heading_error_deg: NonNegative,
        heading_error_time_s: Positive,
        heading_white_deg: NonNegative,
        attitude_white_deg: NonNegative,
        speed_scale_sigma: NonNegative,
        speed_white_m_s: NonNegative,
        depth_white_m: NonNegative,
    });
    let n = &s.navigation;
    check_count("navigation.particles", n.particles, 10, 100_000)?;
    check_count("navigation.reinitialised", n.reinitialised, 0, n.particles - 1)?;
    check_count("navigation.confirmations", n.confirmations, 1, 100)?;
    check_fields!("navigation", s.navigation, {
        max_range_m: Positive,
        sigma_speed_m_s: NonNegative,
        sigma_heading_deg: NonNegative,
        beacon_speed_m_s: NonNegative,
        floor: Probability,
        beam_exponent: Positive,
        current_sigma_m_s: NonNegative,
        current_walk_m_s_per_sqrt_s: NonNegative,
    });
    check_fields!("dock", s.dock, { north_m: Finite, east_m: Finite, beacon_depth_m: NonNegative, gps_sigma_m: NonNegative });
    check_count("boat (waypoints)", s.boat.len(), 1, 100_000)?;
    for (i, w) in s.boat.iter().enumerate() {
        for (k, v) in [("t_s", w.t_s), ("north_m", w.north_m), ("east_m", w.east_m)] {
            check(&format!("boat[{i}].{k}"), v, Rule::Finite)?;
        }
        if i > 0 && w.t_s <= s.boat[i - 1].t_s {
            return Err(violation(format!("boat[{i}].t_s"), w.t_s, "must be later than the waypoint before"));
        }
    }
    check_count("schedule (entries)", s.schedule.len(), 1, 100_000)?;
    for (i, e) in s.schedule.iter().enumerate() {
        check(&format!("schedule[{i}].t_s"), e.t_s, Rule::NonNegative)?;
        if i > 0 && e.t_s < s.schedule[i - 1].t_s {
            return Err(violation(format!("schedule[{i}].t_s"), e.t_s, "must not be earlier than the entry before"));
        }
        if e.mode > MODES {
            return Err(violation(format!("schedule[{i}].mode"), e.mode, format!("must be 0 (silent) to {MODES}")));
        }
    }
    check_count("auvs (count)", s.auvs.len(), 1, 16)?;
    let names: Vec<String> = s.auvs.iter().map(|a| a.name.clone()).collect();
    check_names("auvs", &names)?;
    for (i, a) in s.auvs.iter().enumerate() {
        let at = |k: &str| format!("auvs[{i}].{k}");
        for (k, v, rule) in [
            ("start_north_m", a.start_north_m, Rule::Finite),
            ("start_east_m", a.start_east_m, Rule::Finite),
            ("start_heading_deg", a.start_heading_deg, Rule::Finite),
            ("launch_s", a.launch_s, Rule::NonNegative),
            ("speed_m_s", a.speed_m_s, Rule::Positive),
            ("depth_m", a.depth_m, Rule::Positive),
        ] {
            check(&at(k), v, rule)?;
        }
        let water = s.signal.water_depth_m;
        if a.depth_m >= water {
            return Err(violation(
                at("depth_m"),
                a.depth_m,
                format!("must be above the bed: less than signal.water_depth_m = {water} m"),
            ));
        }
        for (j, m) in a.modes.iter().enumerate() {
            let at = |k: &str| format!("auvs[{i}].modes[{j}].{k}");
            if !(1..=MODES).contains(&m.mode) {
                return Err(violation(at("mode"), m.mode, format!("must be 1 to {MODES}")));
            }
            if a.modes[..j].iter().any(|o| o.mode == m.mode) {
                return Err(violation(at("mode"), m.mode, "must differ from this AUV's other modes"));
            }
            check(&at("offset_north_m"), m.offset_north_m, Rule::Finite)?;
            check(&at("offset_east_m"), m.offset_east_m, Rule::Finite)?;
            for key in m.required() {
                let Some(v) = m.value(key) else {
                    return Err(violation(at(key), "missing", format!("is needed by a {:?} behaviour", m.behaviour)));
                };
                check(&at(key), v, if *key == "heading_deg" { Rule::Finite } else { Rule::Positive })?;
            }
            if let Some(c) = m.ceiling_m.filter(|c| *c >= water) {
                return Err(violation(
                    at("ceiling_m"),
                    c,
                    format!("must be above the bed: less than signal.water_depth_m = {water} m"),
                ));
            }
        }
    }
    if let Some(e) = s.estimators.iter().find(|e| !e.iusbl() && **e != EstimatorKind::DeadReckoning) {
        return Err(violation(
            "estimators",
            e.label(),
            "a fleet world runs `iusbl`, `iusbl-joint` and `dead-reckoning` (the others need what it does not give)",
        ));
    }
    // the behaviours read the first navigator's beacon-relative position (as a stream checks it)
    let flies = |e: &EstimatorKind| EstimatorSpec::new(*e).provides(Capability::BeaconRelative, VehicleModel::Planar);
    match s.estimators.first() {
        Some(e) if flies(e) => {}
        other => {
            return Err(violation(
                "estimators",
                other.map(|e| e.label()),
                "the first estimator flies the behaviours: it must be `iusbl` or `iusbl-joint`",
            ));
        }
    }
    if s.estimators.iter().enumerate().any(|(i, e)| s.estimators[..i].contains(e)) {
        return Err(violation(
            "estimators",
            s.estimators.iter().map(|e| e.label()).collect::<Vec<_>>(),
            "must all differ",
        ));
    }
    Ok(())
}
