//! Scenario files: schema, defaults, loading, validation and the built-in scenarios.
//!
//! A scenario is a TOML file whose `kind` names the world it describes:
//! `fixed_beacon` (the default; garin2024), `moving_beacon` (sousa), `passive_usbl`
//! (hoff2024) or `fleet` (rypkema). Every key is
//! optional except `name` and has a documented default (the built-in files in
//! `scenarios/` spell every key out with where its value comes from). Keys carry their
//! unit in their name; angles in config are degrees (`*_deg`), radians inside.

mod builtin;
pub mod fixed_beacon;
pub mod fleet;
pub(crate) mod load;
pub mod moving_beacon;
pub mod passive_usbl;
pub mod ping;
pub mod sea;
pub(crate) mod validate;

pub use builtin::{BUILTINS, Builtin, builtin};
pub use estimator::{EstimatorKind, EstimatorSpec, FilterName, Host};
pub use fixed_beacon::{FixedBeacon, FixedBeaconCell};
pub use fleet::Fleet;
pub use load::{ScenarioError, load, load_builtin, load_file, parse};
pub use moving_beacon::{MovingBeacon, MovingBeaconCell};
/// The `[[estimators]]` vocabulary is the onboard crate's: a vehicle reads it too.
pub use onebeacon::config::{estimator, iusbl};
pub use passive_usbl::{PassiveUsbl, PassiveUsblCell};

use serde::{Deserialize, Serialize};

/// Which world a scenario describes.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum World {
    /// An AUV and a fixed beacon (garin2024).
    #[default]
    FixedBeacon,
    /// An underwater vehicle and a beacon on a guided surface vehicle (sousa).
    MovingBeacon,
    /// AUVs sending messages and a surface vehicle listening with a USBL (hoff2024).
    PassiveUsbl,
    /// AUVs navigating on one beacon with inverted USBLs, commanded by its chirps
    /// (rypkema).
    Fleet,
}

impl World {
    /// The world's `kind` as a scenario names it.
    pub fn label(self) -> &'static str {
        match self {
            World::FixedBeacon => "fixed_beacon",
            World::MovingBeacon => "moving_beacon",
            World::PassiveUsbl => "passive_usbl",
            World::Fleet => "fleet",
        }
    }
}

pub(crate) fn default_seed() -> u64 {
    1
}
pub(crate) fn default_runs<const N: usize>() -> usize {
    N
}

/// One estimator on one vehicle: what a row of metrics is about.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Track {
    pub vehicle: String,
    pub vehicle_index: usize,
    pub estimator: String,
    /// The estimator's name, or `vehicle/estimator` when the world has several vehicles.
    pub label: String,
}

/// A parsed, validated scenario.
#[derive(Debug, Clone, PartialEq)]
pub enum Scenario {
    FixedBeacon(FixedBeacon),
    MovingBeacon(MovingBeacon),
    PassiveUsbl(PassiveUsbl),
    Fleet(Fleet),
}

/// One value of a swept key.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum SweepValue {
    Number(f64),
    Text(&'static str),
}

impl std::fmt::Display for SweepValue {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            SweepValue::Number(v) => write!(f, "{v}"),
            SweepValue::Text(t) => f.write_str(t),
        }
    }
}

/// One sweep cell: the values the cell's runs use for the swept keys.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Cell {
    FixedBeacon(FixedBeaconCell),
    MovingBeacon(MovingBeaconCell),
    PassiveUsbl(PassiveUsblCell),
    /// A fleet scenario has no sweep.
    Fleet,
}

impl Cell {
    /// The swept keys and values, for tables and JSON.
    pub fn values(&self) -> Vec<(&'static str, SweepValue)> {
        match self {
            Cell::FixedBeacon(c) => vec![("t_com_s", SweepValue::Number(c.t_com_s))],
            Cell::MovingBeacon(c) => vec![
                ("path", SweepValue::Text(c.path.label())),
                ("depth_m", SweepValue::Number(c.depth_m)),
                ("guidance", SweepValue::Text(c.guidance.label())),
            ],
            Cell::PassiveUsbl(c) => vec![("guidance", SweepValue::Text(c.guidance.label()))],
            Cell::Fleet => Vec::new(),
        }
    }

    /// `key=value` pairs joined by spaces.
    pub fn label(&self) -> String {
        self.values().iter().map(|(k, v)| format!("{k}={v}")).collect::<Vec<_>>().join(" ")
    }
}

impl Scenario {
    /// Its checks: each world's are beside its schema.
    pub(crate) fn validate(&self) -> Result<(), validate::Violation> {
        match self {
            Scenario::FixedBeacon(s) => fixed_beacon::validate_fixed(s),
            Scenario::MovingBeacon(s) => moving_beacon::validate_moving(s),
            Scenario::PassiveUsbl(s) => passive_usbl::validate_passive(s),
            Scenario::Fleet(s) => fleet::validate_fleet(s),
        }
    }

    pub fn name(&self) -> &str {
        match self {
            Scenario::FixedBeacon(s) => &s.name,
            Scenario::MovingBeacon(s) => &s.name,
            Scenario::PassiveUsbl(s) => &s.name,
            Scenario::Fleet(s) => &s.name,
        }
    }
    pub fn description(&self) -> &str {
        match self {
            Scenario::FixedBeacon(s) => &s.description,
            Scenario::MovingBeacon(s) => &s.description,
            Scenario::PassiveUsbl(s) => &s.description,
            Scenario::Fleet(s) => &s.description,
        }
    }
    pub fn seed(&self) -> u64 {
        match self {
            Scenario::FixedBeacon(s) => s.seed,
            Scenario::MovingBeacon(s) => s.seed,
            Scenario::PassiveUsbl(s) => s.seed,
            Scenario::Fleet(s) => s.seed,
        }
    }
    pub fn runs(&self) -> usize {
        match self {
            Scenario::FixedBeacon(s) => s.runs,
            Scenario::MovingBeacon(s) => s.runs,
            Scenario::PassiveUsbl(s) => s.runs,
            Scenario::Fleet(s) => s.runs,
        }
    }
    /// The (vehicle, estimator) tracks, in the order of every run's metrics and
    /// records: each vehicle's estimators in scenario order, vehicle after vehicle.
    pub fn tracks(&self) -> Vec<Track> {
        let vehicles = self.vehicle_names();
        let estimators: Vec<String> = match self {
            Scenario::FixedBeacon(s) => s.estimators.iter().map(|e| e.name()).collect(),
            Scenario::MovingBeacon(s) => s.estimators.iter().map(|e| e.name()).collect(),
            Scenario::PassiveUsbl(s) => s.estimators.iter().map(|e| e.name()).collect(),
            Scenario::Fleet(s) => s.estimators.iter().map(|e| e.label().to_string()).collect(),
        };
        let several = vehicles.len() > 1;
        let mut tracks = Vec::new();
        for (index, vehicle) in vehicles.iter().enumerate() {
            for estimator in &estimators {
                let label = if several { format!("{vehicle}/{estimator}") } else { estimator.clone() };
                tracks.push(Track {
                    vehicle: vehicle.clone(),
                    vehicle_index: index,
                    estimator: estimator.clone(),
                    label,
                });
            }
        }
        tracks
    }

    /// The track labels, in order.
    pub fn track_labels(&self) -> Vec<String> {
        self.tracks().into_iter().map(|t| t.label).collect()
    }

    /// The underwater vehicles' names, in order.
    pub fn vehicle_names(&self) -> Vec<String> {
        match self {
            Scenario::FixedBeacon(_) => vec!["auv".into()],
            Scenario::MovingBeacon(s) => s.vehicles(&s.base_cell()).into_iter().filter_map(|v| v.name).collect(),
            Scenario::PassiveUsbl(s) => s.auvs().into_iter().filter_map(|a| a.name).collect(),
            Scenario::Fleet(s) => s.auvs.iter().map(|a| a.name.clone()).collect(),
        }
    }
    /// The cell `run` simulates: the scenario's own values, no sweep.
    pub fn base_cell(&self) -> Cell {
        match self {
            Scenario::FixedBeacon(s) => Cell::FixedBeacon(s.base_cell()),
            Scenario::MovingBeacon(s) => Cell::MovingBeacon(s.base_cell()),
            Scenario::PassiveUsbl(s) => Cell::PassiveUsbl(s.base_cell()),
            Scenario::Fleet(_) => Cell::Fleet,
        }
    }
    /// The scenario as TOML, every key written out: [`parse`] gives it back equal,
    /// whatever file or built-in it came from (what a shard's partial records).
    pub fn to_toml(&self) -> String {
        let text = match self {
            Scenario::FixedBeacon(s) => toml::to_string(s),
            Scenario::MovingBeacon(s) => toml::to_string(s),
            Scenario::PassiveUsbl(s) => toml::to_string(s),
            Scenario::Fleet(s) => toml::to_string(s),
        };
        text.expect("a parsed scenario is representable in TOML")
    }
    /// The sweep cells of `mc`, in order.
    pub fn cells(&self) -> Vec<Cell> {
        match self {
            Scenario::FixedBeacon(s) => s.cells().into_iter().map(Cell::FixedBeacon).collect(),
            Scenario::MovingBeacon(s) => s.cells().into_iter().map(Cell::MovingBeacon).collect(),
            Scenario::PassiveUsbl(s) => s.cells().into_iter().map(Cell::PassiveUsbl).collect(),
            Scenario::Fleet(_) => vec![Cell::Fleet],
        }
    }
    /// Steps of one run after the start.
    pub fn steps(&self) -> usize {
        match self {
            Scenario::FixedBeacon(s) => s.steps(),
            Scenario::MovingBeacon(s) => s.steps(),
            Scenario::PassiveUsbl(s) => s.steps(),
            Scenario::Fleet(s) => s.steps(),
        }
    }
    /// Mission duration, s.
    pub fn duration_s(&self) -> f64 {
        match self {
            Scenario::FixedBeacon(s) => s.duration_s(),
            Scenario::MovingBeacon(s) => s.mission.duration_s,
            Scenario::PassiveUsbl(s) => s.mission.duration_s,
            Scenario::Fleet(s) => s.mission.duration_s,
        }
    }
}
