//! sousa's beacon vehicle (sec. 3.3): at each ping it picks where to be at the next, the
//! point of its reaching set where the ranges tell the underwater vehicle the most
//! (approach A, eq. 3.15, or B, eq. 3.16-3.19), from what the vehicle reports of itself;
//! or one of the baselines (hold the start, circle the vehicle).

use super::{Command, Controller, DecideError, Decided, FimSnapshot, GuidanceSnapshot, Situation, need, own_fix};
use crate::guidance::{FimPlanner, Metric, ReachingSet};
use crate::nav::Navigator;
use crate::nav::capability::Capability;
use nalgebra::Vector2;

/// Where the beacon vehicle goes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum FimMode {
    /// The FIM planner with its metric (approach A or B).
    Planner,
    /// Hold the start point (baseline).
    Static,
    /// Circle the vehicle's estimate at `circle_radius_m` (baseline).
    Circle,
}

/// The beacon vehicle's guidance settings.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FimGuidanceConfig {
    pub mode: FimMode,
    /// The planner (its metric is mapped in the snapshots of the baselines too).
    pub planner: FimPlanner,
    /// The ping period (s) and the vehicle's top speed (m/s): the reaching set's radius
    /// is their product.
    pub period_s: f64,
    pub max_speed_m_s: f64,
    pub circle_radius_m: f64,
    /// The point a static beacon vehicle holds.
    pub home_m: Vector2<f64>,
}

/// The controller: decides at each ping (each call), for the first vehicle it serves.
#[derive(Debug, Clone)]
pub struct FimGuidance {
    config: FimGuidanceConfig,
}

impl FimGuidance {
    pub fn new(config: FimGuidanceConfig) -> Self {
        Self { config }
    }
}

impl Controller for FimGuidance {
    /// The waypoint for the next ping, from the vehicle's estimate now and predicted one
    /// period ahead on its last measured body velocity (approach B needs it:
    /// [`DecideError::Lacks`] without; the others predict no motion); the situation's fix
    /// is the beacon's position at this ping.
    fn decide(&mut self, situation: &Situation, beliefs: &[&dyn Navigator]) -> Result<Decided, DecideError> {
        need(beliefs, 1)?;
        let c = &self.config;
        let (t0, here) = (situation.t_s, own_fix(situation)?.position_m);
        let reach = c.max_speed_m_s * c.period_s;
        let report = beliefs[0].estimate();
        let target = report.position_ned_m;
        let lin = match beliefs[0].body_velocity() {
            Some(b) => b.body_velocity_m_s(),
            None if c.mode == FimMode::Planner && c.planner.metric == Metric::ApproachB => {
                return Err(DecideError::Lacks(Capability::BodyVelocity));
            }
            None => nalgebra::Vector3::zeros(),
        };
        let target_next = target + report.body_to_ned() * lin * c.period_s;
        let waypoint = match c.mode {
            FimMode::Planner => {
                c.planner
                    .next_waypoint(&ReachingSet { center: here, radius: reach }, here, &target, &target_next)
                    .waypoint
            }
            FimMode::Static => c.home_m,
            FimMode::Circle => {
                let r = c.circle_radius_m;
                let rel = here - target.xy();
                let angle = rel.y.atan2(rel.x) + (reach / r).min(std::f64::consts::FRAC_PI_2);
                target.xy() + Vector2::new(angle.cos(), angle.sin()) * r
            }
        };
        // the baselines' snapshots map approach A's metric
        let planner =
            if c.mode == FimMode::Planner { c.planner } else { FimPlanner { metric: Metric::ApproachA, ..c.planner } };
        let snapshot = FimSnapshot { t_s: t0, planner, previous: here, reach_m: reach, target, target_next, waypoint };
        Ok(Decided {
            command: Command::Waypoint { waypoint, arrive_s: t0 + c.period_s },
            snapshot: Some(GuidanceSnapshot::Fim(snapshot)),
        })
    }
}
