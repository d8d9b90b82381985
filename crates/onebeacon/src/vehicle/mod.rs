//! The vehicle's own computer: what a vehicle decides from what its navigators believe.
//!
//! A [`Controller`] turns the beliefs of navigators (its own vehicle's, or the vehicles
//! it serves) and what the vehicle knows of itself ([`Situation`]: its clock, and at the
//! surface its GPS and compass) into a [`Command`] for its autopilots. The papers'
//! decision logic lives here, so that the same code runs in the simulator, on a log and
//! on a vehicle:
//!
//! - [`bearing::BearingGuidance`]: hoff2024's surface vehicle: which AUV to serve, the
//!   half-annulus planner (eq. 10-12) and its straight legs (eq. 13-16), or a baseline;
//! - [`fim::FimGuidance`]: sousa's beacon vehicle: the waypoint of largest Fisher
//!   information in its reaching set at each ping (eq. 3.15-3.19), or a baseline;
//! - [`behaviours::Behaviours`] on [`autonomy`]: rypkema's AUV: the command mode its navigator confirmed
//!   selects a beacon-relative behaviour (sec. 4.1-4.2) whose setpoint it follows.
//!
//! The simulator's engine runs every step as: each controller decides, the world moves
//! its truth under the commands and says what was heard, the navigators process it.

pub mod autonomy;
pub mod bearing;
pub mod behaviours;
pub mod fim;

use crate::guidance::FimPlanner;
use crate::nav::Navigator;
use nalgebra::{Vector2, Vector3};

/// What a vehicle knows of itself when it decides.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Situation {
    /// Its clock, s.
    pub t_s: f64,
    /// Its own fix, when it has one (a surface vehicle's GPS and compass; an AUV
    /// navigates on its navigators instead).
    pub fix: Option<OwnFix>,
}

/// A vehicle's own position, heading and speed, as its sensors give them.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct OwnFix {
    /// Horizontal NED position, m.
    pub position_m: Vector2<f64>,
    /// Heading, rad, and speed through the water, m/s.
    pub heading_rad: f64,
    pub speed_m_s: f64,
}

/// What a controller asks of its vehicle's autopilots.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Command {
    /// Follow the straight path from `from` to `to` over the next period, timed along it
    /// (hoff2024 eq. 24-26).
    Path { from: Vector2<f64>, to: Vector2<f64> },
    /// Be at `waypoint` at time `arrive_s` (sousa sec. 3.3).
    Waypoint { waypoint: Vector2<f64>, arrive_s: f64 },
    /// Hold a heading, speed and depth: a behaviour's setpoint, with the command mode
    /// that selected it and what the behaviour is doing.
    Setpoint { setpoint: Setpoint, mode: Option<usize>, phase: Phase },
}

/// What the autonomy asks of the vehicle's autopilots.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Setpoint {
    pub heading_rad: f64,
    /// Speed over ground, m/s; 0: propeller off.
    pub speed_m_s: f64,
    pub depth_m: f64,
}

/// What the vehicle is doing, for records and pictures.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Phase {
    /// No mode confirmed yet: holding heading at depth.
    Waiting,
    /// Driving (to a point, along a line, around a circle).
    Driving,
    /// Propeller off at an offset-follow point.
    Drifting,
    /// Propeller off for good: a return's end or an abort.
    Surfacing,
}

/// A guidance decision with what it was taken on, for records and pictures.
#[derive(Debug, Clone, PartialEq)]
pub enum GuidanceSnapshot {
    /// A beacon vehicle's FIM guidance at one ping (sousa).
    Fim(FimSnapshot),
    /// A surface vehicle's bearing planner at one decision (hoff2024).
    Bearing(BearingSnapshot),
}

/// What a surface vehicle's bearing planner knew and chose at one decision
/// (hoff2024 Fig. 3): the candidates on the half-annulus with their scores.
#[derive(Debug, Clone, PartialEq)]
pub struct BearingSnapshot {
    pub t_s: f64,
    /// The AUV the decision served.
    pub vehicle: usize,
    /// The ASV's position, the belief's mean shifted by the lead (NED).
    pub asv: Vector2<f64>,
    pub belief_mean: Vector3<f64>,
    pub candidates: Vec<(Vector2<f64>, f64)>,
    pub waypoint: Vector2<f64>,
}

/// What the beacon vehicle's FIM guidance knew and chose at one ping, so that its
/// metric can be mapped over the reaching set (sousa Fig. 3.5, 3.7).
#[derive(Debug, Clone, PartialEq)]
pub struct FimSnapshot {
    pub t_s: f64,
    /// The planner whose metric is mapped (approach A for the baselines).
    pub planner: FimPlanner,
    /// The beacon's position estimate at this ping, the centre of its reaching set.
    pub previous: Vector2<f64>,
    pub reach_m: f64,
    /// The vehicle's estimate now and predicted at the next ping.
    pub target: Vector3<f64>,
    pub target_next: Vector3<f64>,
    /// The waypoint the guidance chose.
    pub waypoint: Vector2<f64>,
}

/// A decision: the command, and the guidance snapshot when a planner was consulted.
#[derive(Debug, Clone, PartialEq)]
pub struct Decided {
    pub command: Command,
    pub snapshot: Option<GuidanceSnapshot>,
}

impl From<Command> for Decided {
    fn from(command: Command) -> Self {
        Self { command, snapshot: None }
    }
}

/// Why a controller could not decide.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum DecideError {
    /// A surface vehicle's guidance needs its own fix (GPS and compass).
    #[error("no own position fix: a surface vehicle's guidance needs its GPS and compass")]
    NoFix,
    /// The controller reads the beliefs of `needed` vehicles and was given `given`.
    #[error("the controller reads {needed} vehicles' beliefs, {given} given")]
    Beliefs { needed: usize, given: usize },
}

/// What turns beliefs into a command.
pub trait Controller: Send {
    /// Decides from the vehicle's own `situation` and `beliefs`: the first navigator of
    /// each vehicle the controller serves (a surface vehicle's trackers of the AUVs; an
    /// AUV's own navigator), as they stand now.
    fn decide(&mut self, situation: &Situation, beliefs: &[&dyn Navigator]) -> Result<Decided, DecideError>;
}

/// `situation`'s fix, or [`DecideError::NoFix`].
pub(crate) fn own_fix(situation: &Situation) -> Result<&OwnFix, DecideError> {
    situation.fix.as_ref().ok_or(DecideError::NoFix)
}

/// At least `needed` beliefs, or [`DecideError::Beliefs`].
pub(crate) fn need(beliefs: &[&dyn Navigator], needed: usize) -> Result<(), DecideError> {
    if beliefs.len() < needed { Err(DecideError::Beliefs { needed, given: beliefs.len() }) } else { Ok(()) }
}
