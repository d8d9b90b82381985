//! One simulated run: truth, sensors and every estimator of the scenario on the same
//! truth and the same measurement draws (a paired comparison). A pure function of
//! (scenario, cell, seed, run index).

mod fixed_beacon;
mod moving_beacon;

use crate::metrics::RunMetrics;
use crate::scenario::{Cell, Scenario};
use nalgebra::{Matrix6, Vector2, Vector3};
use onebeacon::guidance::FimPlanner;

/// One estimator's estimate at one step.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Estimate {
    /// NED position, m.
    pub pos: Vector3<f64>,
    /// Heading, rad in (-pi, pi].
    pub psi: f64,
    /// Forward speed, m/s, when the estimator has it as a state.
    pub speed: Option<f64>,
    /// Standard deviations of north and east, m.
    pub sigma_pos: Vector2<f64>,
    /// Horizontal position error, m.
    pub error_m: f64,
    /// NEES of the horizontal position.
    pub nees: f64,
}

impl Estimate {
    /// The record of navigator estimate `e` with its horizontal error and NEES.
    pub fn new(e: &onebeacon::nav::Estimate, error_m: f64, nees: Option<f64>) -> Self {
        Self {
            pos: e.position_ned_m,
            psi: e.heading_rad(),
            speed: e.speed_m_s,
            sigma_pos: Vector2::new(e.sigma_north_m(), e.sigma_east_m()),
            error_m,
            nees: nees.unwrap_or(f64::NAN),
        }
    }
}

/// Truth and all estimates at one step.
#[derive(Debug, Clone, PartialEq)]
pub struct StepRecord {
    pub t_s: f64,
    /// The vehicle's true NED position, heading and forward speed.
    pub truth_pos: Vector3<f64>,
    pub truth_heading: f64,
    pub truth_speed: f64,
    /// The beacon's true position (fixed, or on the surface vehicle).
    pub beacon: Vector3<f64>,
    /// Whether an acoustic measurement was used in this step.
    pub frame: bool,
    pub estimates: Vec<Estimate>,
}

/// What the beacon vehicle's guidance knew and chose at one ping (recorded runs), so
/// that its metric can be mapped over the reaching set (sousa Fig. 3.5, 3.7).
#[derive(Debug, Clone, PartialEq)]
pub struct GuidanceSnapshot {
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

/// The outcome of one run.
#[derive(Debug, Clone, PartialEq)]
pub struct RunOutput {
    /// One entry per estimator, in scenario order.
    pub metrics: Vec<RunMetrics>,
    /// Every step, when recording was asked for; empty otherwise.
    pub trajectory: Vec<StepRecord>,
    pub distance_m: f64,
    /// Acoustic measurements received (frames decoded, ranges heard).
    pub frames_decoded: u64,
    /// For bounds: the Fisher information H' R^-1 H of each range received, with the
    /// step it was received in (moving-beacon runs; empty otherwise).
    pub range_information: Vec<(usize, Matrix6<f64>)>,
    /// The guidance decisions of a recorded moving-beacon run, one per ping.
    pub guidance: Vec<GuidanceSnapshot>,
}

/// Simulates run `run` of `cell` under base seed `seed`; records every step if `record`.
/// A cell of another world than the scenario's is a programming error.
pub fn simulate(s: &Scenario, cell: &Cell, seed: u64, run: u64, record: bool) -> RunOutput {
    match (s, cell) {
        (Scenario::FixedBeacon(s), Cell::FixedBeacon(c)) => fixed_beacon::simulate(s, c, seed, run, record),
        (Scenario::MovingBeacon(s), Cell::MovingBeacon(c)) => moving_beacon::simulate(s, c, seed, run, record),
        _ => panic!("sweep cell {cell:?} does not belong to scenario {}", s.name()),
    }
}

pub use moving_beacon::{initial_asv_position, truth_trajectory};
