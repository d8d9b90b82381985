//! What each vehicle's computer heard and decided in a simulated run, as `onebeacon
//! stream` reads and writes it: per computer (a fixed-beacon world's AUV, a
//! passive-USBL world's surface vehicle, a moving-beacon world's beacon vehicle and
//! other vehicles, each fleet AUV), its stream configuration ([`crate::computers`]), its
//! JSON Lines input (its own fixes, the beacon
//! positions and the measurements of the vehicles it estimates) and the commands the
//! simulator's controller gave. Feeding the input to `stream` with the configuration
//! gives the same commands: the simulator and the vehicle run the same code.

use crate::computers::OnBoard;
use crate::engine::{Observer, Step};
use nalgebra::Vector3;
use onebeacon::geo::Frame;
use onebeacon::io::jsonl::{Line, command_json, item_json, line_json};
use onebeacon::nav::session::{Input, Item};
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
    /// Per computer: the vehicles it estimates, and what it heard and decided.
    serves: Vec<Vec<usize>>,
    computers: Vec<Computer>,
    /// The computer of each helm (those with a controller, in order).
    of_helm: Vec<usize>,
    /// Per computer: the beacons' positions its input last gave, and the planner's last
    /// plan.
    beacons: Vec<Vec<(u32, Vector3<f64>)>>,
    plans: Vec<Option<Plan>>,
}

impl Messages {
    /// For a run's `computers` (the engine's helms are those with a controller, in
    /// order).
    pub(crate) fn new(computers: &[OnBoard]) -> Self {
        let n = computers.len();
        Self {
            serves: computers.iter().map(|c| c.starts.iter().map(|s| s.vehicle).collect()).collect(),
            of_helm: (0..n).filter(|&i| computers[i].config.controller.is_some()).collect(),
            computers: computers.iter().map(computer).collect(),
            beacons: vec![Vec::new(); n],
            plans: vec![None; n],
        }
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
                    let item = Item { t_s: m.t_s, input: Input::Measurement(m.kind.clone()) };
                    c.input.push(line_json(&Line::Item { vehicle: several.then_some(i), item }).to_string());
                }
            }
        }
    }

    fn decided(&mut self, helm: usize, situation: &Situation, d: &Decided) {
        let h = self.of_helm[helm];
        let c = &mut self.computers[h];
        if let Some(fix) = &situation.fix {
            c.input.push(line_json(&Line::OwnFix { t_s: situation.t_s, fix: *fix }).to_string());
        }
        if let Some(GuidanceSnapshot::Bearing(b)) = &d.snapshot {
            self.plans[h] = Some(Plan { vehicle: b.vehicle, waypoint: b.waypoint });
        }
        c.decisions.push(json!({"t_s": situation.t_s, "command": command_json(&d.command, self.plans[h], Frame::Ned)}));
    }
}

/// What computer `c` heard and decided, yet to be run: its name and configuration.
fn computer(c: &OnBoard) -> Computer {
    Computer {
        name: c.config.name.clone(),
        config: toml::to_string(&c.config).expect("a stream configuration is TOML"),
        input: Vec::new(),
        decisions: Vec::new(),
    }
}
