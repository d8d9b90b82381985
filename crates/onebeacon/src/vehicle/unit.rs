//! One vehicle's computer: the sessions of navigators it runs (one per vehicle whose
//! position it estimates: its own, or the AUVs a surface vehicle tracks) and an optional
//! [`Controller`] that turns their beliefs into a command. What `onebeacon stream` and
//! the Python `Navigator` run, and what the simulator's engine runs for every vehicle
//! with a computer ([`crate::config::stream::StreamConfig::unit_of`]).

use super::{Command, Controller, DecideError, Decided, GuidanceSnapshot, OwnFix, Situation};
use crate::geo::Frame;
use crate::nav::Estimate;
use crate::nav::Navigator;
use crate::nav::session::{Item, Screened, Session, Step, Taken};
use nalgebra::{Vector2, Vector3};
use std::collections::BTreeMap;

/// When a controller decides: after each line of this kind (`"own_fix"`, or a
/// measurement kind such as `"depth"`).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct DecideOn(pub String);

/// A controller with the line kind that makes it decide.
pub struct Helm {
    pub controller: Box<dyn Controller>,
    pub decide_on: DecideOn,
}

/// The last plan of a surface vehicle's planner: the AUV it serves and the waypoint of
/// its leg (NED).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Plan {
    pub vehicle: usize,
    pub waypoint: Vector2<f64>,
}

/// A vehicle's computer.
pub struct Unit {
    /// One session per vehicle estimated (index = the `vehicle` of a line).
    sessions: Vec<Session>,
    /// The fixed beacons (NED) measurements may name.
    pub fixed: BTreeMap<u32, Vector3<f64>>,
    /// The frame of the lines in and out.
    pub frame: Frame,
    helm: Option<Helm>,
    fix: Option<OwnFix>,
    command: Option<Command>,
    plan: Option<Plan>,
}

impl std::fmt::Debug for Unit {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Unit")
            .field("sessions", &self.sessions)
            .field("controller", &self.helm.as_ref().map(|h| &h.decide_on))
            .finish_non_exhaustive()
    }
}

impl Unit {
    /// A computer of `sessions` (at least one) on lines in `frame` naming the `fixed`
    /// beacons, with its controller when it has one.
    pub fn new(sessions: Vec<Session>, fixed: BTreeMap<u32, Vector3<f64>>, frame: Frame, helm: Option<Helm>) -> Self {
        assert!(!sessions.is_empty(), "a vehicle's computer runs at least one session");
        Self { sessions, fixed, frame, helm, fix: None, command: None, plan: None }
    }

    /// The sessions, one per vehicle estimated.
    pub fn sessions(&self) -> &[Session] {
        &self.sessions
    }

    /// The session of vehicle `v`.
    pub fn session(&self, v: usize) -> &Session {
        &self.sessions[v]
    }

    pub fn has_controller(&self) -> bool {
        self.helm.is_some()
    }

    /// Whether a line of `kind` makes the controller decide.
    pub fn decides_on(&self, kind: &str) -> bool {
        self.helm.as_ref().is_some_and(|h| h.decide_on.0 == kind)
    }

    /// The command decided last, and the planner's last plan.
    pub fn command(&self) -> Option<Command> {
        self.command
    }

    pub fn plan(&self) -> Option<Plan> {
        self.plan
    }

    /// Pushes an item about vehicle `vehicle` (None: vehicle 0, or every vehicle for a
    /// beacon position) into its session.
    pub fn push(&mut self, vehicle: Option<usize>, item: &Item) -> Result<Option<Step>, Screened> {
        match (vehicle, &item.input) {
            (None, crate::nav::session::Input::BeaconPosition { .. }) => {
                let (last, others) = self.sessions.split_last_mut().expect("at least one session");
                for s in others {
                    s.push(item)?;
                }
                last.push(item)
            }
            (v, _) => self.sessions[v.unwrap_or(0)].push(item),
        }
    }

    /// Starts every session whose start is a given pose due by `t_s`; whether all run.
    pub fn start_by(&mut self, t_s: f64) -> bool {
        // every session tried, not only up to the first that waits
        let mut all = true;
        for s in &mut self.sessions {
            all &= s.start_by(t_s);
        }
        all
    }

    /// Predicts every session's estimators to `t_s` ([`Session::predict_to`]), session
    /// by session, their estimates written into `estimates` in that order (one per
    /// estimator of every session): the estimators started again, counted across the
    /// sessions in the same order, or `None` when a session has not started.
    pub fn predict_to(&mut self, t_s: f64, estimates: &mut [Estimate]) -> Option<Vec<usize>> {
        let mut restarted = Vec::new();
        let mut first = 0;
        for s in &mut self.sessions {
            let n = s.names.len();
            let again = s.predict_to(t_s, &mut estimates[first..first + n])?;
            restarted.extend(again.into_iter().map(|j| first + j));
            first += n;
        }
        Some(restarted)
    }

    /// Takes a measurement or truth item about vehicle `vehicle` into its session
    /// without scoring it ([`Session::take`]; the simulator, which scores at its steps
    /// through [`Unit::predict_to`]).
    pub fn take(&mut self, vehicle: usize, item: &Item) -> Result<Option<Taken<'_>>, Screened> {
        self.sessions[vehicle].take(item)
    }

    /// The vehicle's own fix (NED), as its GPS and compass give it.
    pub fn set_fix(&mut self, fix: OwnFix) {
        self.fix = Some(fix);
    }

    /// The controller's decision at `t_s` on the first navigator of every session (None
    /// without a controller); the command is kept.
    pub fn decide(&mut self, t_s: f64) -> Option<Result<Decided, DecideError>> {
        self.helm.as_ref()?;
        self.start_by(t_s);
        let helm = self.helm.as_mut()?;
        let beliefs: Option<Vec<&dyn Navigator>> = self.sessions.iter().map(|s| s.navigator(0)).collect();
        let Some(beliefs) = beliefs else { return Some(Err(DecideError::NotStarted)) };
        let decided = helm.controller.decide(&Situation { t_s, fix: self.fix }, &beliefs);
        if let Ok(d) = &decided {
            self.command = Some(d.command);
            if let Some(GuidanceSnapshot::Bearing(b)) = &d.snapshot {
                self.plan = Some(Plan { vehicle: b.vehicle, waypoint: b.waypoint });
            }
        }
        Some(decided)
    }
}
