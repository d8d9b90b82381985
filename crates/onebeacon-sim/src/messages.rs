//! What each vehicle's computer heard and decided in a simulated run, as `onebeacon
//! stream` reads and writes it: per controller (a passive-USBL world's surface vehicle,
//! a moving-beacon world's beacon vehicle, each fleet AUV), its stream configuration (the scenario's estimators and controller,
//! the run's initial states and seeds), its JSON Lines input (its own fixes, the beacon
//! positions and the measurements of the vehicles it estimates) and the commands the
//! simulator's controller gave. Feeding the input to `stream` with the configuration
//! gives the same commands: the simulator and the vehicle run the same code.

use crate::engine::{Observer, Step};
use crate::scenario::fleet::{Fleet, SignalModel};
use crate::scenario::{MovingBeacon, MovingBeaconCell, PassiveUsbl, PassiveUsblCell};
use crate::{factory, helms};
use nalgebra::{Vector2, Vector3};
use onebeacon::config::builder::VehicleModel;
use onebeacon::config::controller::ControllerSpec;
use onebeacon::config::estimator::EstimatorSpec;
use onebeacon::config::stream::{FrameKey, Initial, InitialFrom, StreamConfig};
use onebeacon::geo::Frame;
use onebeacon::io::jsonl::{command_json, item_json, own_fix_json};
use onebeacon::models::hoff::idx;
use onebeacon::models::kinematic6dof::State as Eta;
use onebeacon::nav::session::{Input, Item};
use onebeacon::nav::usbl_track::TrackState;
use onebeacon::vehicle::unit::Plan;
use onebeacon::vehicle::{Decided, GuidanceSnapshot, Situation};
use serde_json::{Value, json};

/// One vehicle computer's side of a run.
#[derive(Debug, Clone, PartialEq)]
pub struct Computer {
    /// The vehicle (`asv`, or the AUV's name).
    pub name: String,
    /// Its stream configuration (TOML).
    pub config: String,
    /// The JSON lines it heard, in order.
    pub input: Vec<String>,
    /// Each decision of the simulator's controller: `{"t_s", "command"}`, the command as
    /// `stream` writes it.
    pub decisions: Vec<Value>,
}

/// The observer that writes each computer's input and decisions.
pub(crate) struct Messages {
    /// Per helm: the vehicles it serves, and what it heard and decided.
    serves: Vec<Vec<usize>>,
    computers: Vec<Computer>,
    /// Per helm: the beacons' positions its input last gave, and the planner's last plan.
    beacons: Vec<Vec<(u32, Vector3<f64>)>>,
    plans: Vec<Option<Plan>>,
}

impl Messages {
    /// For computers `computers` (their names and configurations), helm `h` serving
    /// `serves[h]`.
    pub(crate) fn new(computers: Vec<Computer>, serves: Vec<Vec<usize>>) -> Self {
        let n = computers.len();
        Self { serves, computers, beacons: vec![Vec::new(); n], plans: vec![None; n] }
    }

    pub(crate) fn into_inner(self) -> Vec<Computer> {
        self.computers
    }
}

impl Observer for Messages {
    fn step(&mut self, s: &Step<'_>) {
        for (h, c) in self.computers.iter_mut().enumerate() {
            let several = self.serves[h].len() > 1;
            for (i, &v) in self.serves[h].iter().enumerate() {
                for m in &s.heard[v] {
                    // the beacon's position before a measurement that names it
                    if let Some(b) = m.kind.beacon() {
                        let known = &mut self.beacons[h];
                        if !known.contains(&(b.id, b.position_ned_m)) {
                            known.retain(|(id, _)| *id != b.id);
                            known.push((b.id, b.position_ned_m));
                            let input = Input::BeaconPosition { beacon_id: b.id, position: b.position_ned_m };
                            c.input.push(item_json(&Item { t_s: m.t_s, input }).to_string());
                        }
                    }
                    let mut line = item_json(&Item { t_s: m.t_s, input: Input::Measurement(m.kind.clone()) });
                    if several {
                        line["vehicle"] = json!(i);
                    }
                    c.input.push(line.to_string());
                }
            }
        }
    }

    fn decided(&mut self, h: usize, situation: &Situation, d: &Decided) {
        let c = &mut self.computers[h];
        if let Some(fix) = &situation.fix {
            c.input.push(own_fix_json(situation.t_s, fix).to_string());
        }
        if let Some(GuidanceSnapshot::Bearing(b)) = &d.snapshot {
            self.plans[h] = Some(Plan { vehicle: b.vehicle, waypoint: b.waypoint });
        }
        c.decisions.push(json!({"t_s": situation.t_s, "command": command_json(&d.command, self.plans[h], Frame::Ned)}));
    }
}

/// A stream configuration of `estimators` and `controller`, NED, planar, its vehicles
/// yet to be given.
fn config(name: &str, description: String, estimators: Vec<EstimatorSpec>, controller: ControllerSpec) -> StreamConfig {
    StreamConfig {
        name: name.into(),
        description,
        frame: FrameKey::Ned,
        model: VehicleModel::Planar,
        beacons: Vec::new(),
        initial: Initial::default(),
        tracked: Vec::new(),
        estimators,
        noise: Default::default(),
        limits: Default::default(),
        controller: Some(controller),
    }
}

/// A vehicle given at time 0 at (`x_m`, `y_m`, `heading_deg`).
fn given(x_m: f64, y_m: f64, heading_deg: f64) -> Initial {
    Initial {
        from: InitialFrom::Given,
        t0_s: Some(0.0),
        x_m: Some(x_m),
        y_m: Some(y_m),
        heading_deg: Some(heading_deg),
        ..Initial::default()
    }
}

/// The surface vehicle's computer of a passive-USBL run: its trackers of every AUV
/// started where the simulator started them (`x0`, with their particle filters' seeds),
/// its planner, starting at `home`.
pub(crate) fn passive_usbl_computer(
    s: &PassiveUsbl,
    cell: &PassiveUsblCell,
    home: Vector2<f64>,
    starts: &[(TrackState, u64)],
) -> Computer {
    let i = &s.initial;
    let tracked = starts
        .iter()
        .map(|(x0, seed)| Initial {
            // the seed's 64 bits as TOML's signed integer
            seed: Some(*seed as i64),
            depth_m: x0[idx::Z],
            pitch_deg: x0[idx::THETA].to_degrees(),
            speed_m_s: x0[idx::U],
            pitch_rate_bias_deg_s: x0[idx::B_THETA].to_degrees(),
            heading_rate_bias_deg_s: x0[idx::B_PSI].to_degrees(),
            position_sigma_m: i.position_sigma_m,
            heading_sigma_deg: i.heading_sigma_deg,
            depth_sigma_m: i.depth_sigma_m,
            pitch_sigma_deg: i.pitch_sigma_deg,
            speed_sigma_m_s: i.speed_sigma_m_s,
            rate_bias_sigma_deg_s: i.rate_bias_sigma_deg_s,
            ..given(x0[idx::X], x0[idx::Y], x0[idx::PSI].to_degrees())
        })
        .collect();
    let estimators = factory::passive_usbl_estimators(s);
    let description =
        format!("The surface vehicle's computer of a simulated {} run (onebeacon run --messages)", s.name);
    let config =
        StreamConfig { tracked, ..config("asv", description, estimators, helms::passive_usbl_spec(s, cell, home)) };
    computer("asv", &config)
}

/// The beacon vehicle's computer of a moving-beacon run: the estimators of the vehicle
/// it serves (the first) as the simulator builds them, fed what that vehicle measures,
/// started at `eta0` as the simulator started them; its FIM guidance, starting at `home`.
pub(crate) fn moving_beacon_computer(
    s: &MovingBeacon,
    cell: &MovingBeaconCell,
    home: Vector2<f64>,
    eta0: &Eta,
) -> Computer {
    let i = &s.initial;
    let initial = Initial {
        depth_m: eta0[2],
        roll_deg: eta0[3].to_degrees(),
        pitch_deg: eta0[4].to_degrees(),
        position_sigma_m: i.position_sigma_m,
        heading_sigma_deg: i.attitude_sigma_deg,
        depth_sigma_m: i.depth_sigma_m,
        pitch_sigma_deg: i.attitude_sigma_deg,
        ..given(eta0[0], eta0[1], eta0[5].to_degrees())
    };
    let estimators = factory::moving_beacon_estimators(s);
    let description = format!("The beacon vehicle's computer of a simulated {} run (onebeacon run --messages)", s.name);
    let controller = helms::moving_beacon_spec(s, cell, home);
    let config = StreamConfig {
        initial,
        model: VehicleModel::Kinematic6Dof,
        ..config("asv", description, estimators, controller)
    };
    computer("asv", &config)
}

/// Each AUV's computer of a fleet run: its estimators with the run's seeds, as the
/// simulator builds them ([`factory::fleet_estimators`]), its behaviours. The channel model's captures are not JSON lines: None.
pub(crate) fn fleet_computers(s: &Fleet, seed: u64, run: u64) -> Option<Vec<Computer>> {
    if s.signal.model == SignalModel::Channel {
        return None;
    }
    let seeds = factory::fleet_seeds(s, seed, run);
    Some(
        s.auvs
            .iter()
            .enumerate()
            .map(|(v, a)| {
                let estimators = factory::fleet_estimators(s, &seeds[v]);
                let description =
                    format!("{}'s computer in a simulated {} run (onebeacon run --messages)", a.name, s.name);
                let config = StreamConfig {
                    // the dead reckoning's start
                    initial: Initial {
                        position_sigma_m: 1.0,
                        heading_sigma_deg: 0.05f64.to_degrees(),
                        ..given(a.start_north_m, a.start_east_m, a.start_heading_deg)
                    },
                    ..config(&a.name, description, estimators, helms::fleet_spec(s, v))
                };
                computer(&a.name, &config)
            })
            .collect(),
    )
}

fn computer(name: &str, config: &StreamConfig) -> Computer {
    Computer {
        name: name.into(),
        config: toml::to_string(config).expect("a stream configuration is TOML"),
        input: Vec::new(),
        decisions: Vec::new(),
    }
}
