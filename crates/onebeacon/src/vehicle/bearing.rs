//! hoff2024's surface vehicle (sec. 3): it serves the AUV whose estimate is the least
//! certain, plans the point of a half-annulus around that AUV's belief whose bearing
//! spreads the predicted measurements most (eq. 10-12), and follows straight legs to it
//! (eq. 13-16); or one of the baselines (hold the start, circle or trail the belief).

use super::{BearingSnapshot, Command, Controller, DecideError, Decided, GuidanceSnapshot, Situation, need, own_fix};
use crate::guidance::bearing::{BearingPlanner, Belief, leg_done, leg_target};
use crate::nav::{Estimate, Navigator};
use nalgebra::{Matrix2, Vector2, Vector3};
use std::f64::consts::FRAC_PI_2;

/// Where the surface vehicle goes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum BearingMode {
    /// The planner of eq. 10-12 with its legs (eq. 13-16); the metric is the planner's.
    Planner,
    /// Hold the start point (baseline).
    Static,
    /// Circle the first AUV's estimate at `circle_radius_m` (baseline).
    Circle,
    /// Trail `offset_m` behind the first AUV's estimate, along its course (baseline).
    Offset,
}

/// The surface vehicle's guidance settings.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BearingGuidanceConfig {
    pub mode: BearingMode,
    pub planner: BearingPlanner,
    /// Its nominal speed (m/s) and the message period (s): a leg moves u_nom x period a
    /// period (eq. 15).
    pub nominal_speed_m_s: f64,
    pub period_s: f64,
    /// Particles the planner scores a candidate on (a subsample of the belief's).
    pub planner_particles: usize,
    /// Periods the ASV is assumed to take to the next point: the belief is shifted by the
    /// AUV's estimated velocity over them (sec. 3).
    pub lead_periods: f64,
    pub circle_radius_m: f64,
    pub offset_m: f64,
    /// The point a static ASV holds.
    pub home_m: Vector2<f64>,
}

/// The leg the ASV follows: from the previous waypoint to the current (eq. 13-16).
#[derive(Debug, Clone, Copy)]
struct Leg {
    from: Vector2<f64>,
    to: Vector2<f64>,
}

/// The controller; it keeps its current leg.
#[derive(Debug, Clone)]
pub struct BearingGuidance {
    config: BearingGuidanceConfig,
    leg: Option<Leg>,
}

impl BearingGuidance {
    pub fn new(config: BearingGuidanceConfig) -> Self {
        Self { config, leg: None }
    }

    /// The next waypoint of the planner (eq. 10-12): on the half-annulus of the AUV
    /// whose estimate is the least certain (det of its horizontal covariance), scored on
    /// its belief. With one AUV, the paper's planner.
    fn plan(
        &self,
        t_s: f64,
        asv: Vector2<f64>,
        asv_velocity: Vector2<f64>,
        beliefs: &[&dyn Navigator],
    ) -> BearingSnapshot {
        let c = &self.config;
        let estimates: Vec<Estimate> = beliefs.iter().map(|b| b.estimate()).collect();
        let worst = (0..estimates.len())
            .max_by(|&a, &b| {
                estimates[a].horizontal_cov_m2.determinant().total_cmp(&estimates[b].horizontal_cov_m2.determinant())
            })
            .unwrap_or(0);
        let e = &estimates[worst];
        let positions = beliefs[worst]
            .particles()
            .map_or_else(|| gaussian_sample(e, c.planner_particles), |p| p.position_sample(c.planner_particles));
        let weights = vec![1.0 / positions.len() as f64; positions.len()];
        // the velocity over ground of the estimated heading, pitch and speed
        let velocity = e.body_to_ned() * Vector3::new(e.speed_m_s.unwrap_or(0.0), 0.0, 0.0);
        let belief = Belief {
            positions: &positions,
            weights: &weights,
            velocity_m_s: velocity.xy(),
            lead_s: c.lead_periods * c.period_s,
        };
        let decision = c.planner.decide(&belief, asv, asv_velocity);
        BearingSnapshot {
            t_s,
            vehicle: worst,
            asv,
            belief_mean: belief.shifted_mean(),
            candidates: decision.candidates,
            waypoint: decision.waypoint,
        }
    }
}

impl Controller for BearingGuidance {
    /// The straight path of this period from p_a to p_t (eq. 24), and the planner's
    /// decision when one was taken.
    fn decide(&mut self, situation: &Situation, beliefs: &[&dyn Navigator]) -> Result<Decided, DecideError> {
        need(beliefs, 1)?;
        let fix = own_fix(situation)?;
        let c = self.config;
        let (u_nom, period) = (c.nominal_speed_m_s, c.period_s);
        let here = fix.position_m;
        // the baselines steer toward a point, at most u_nom x period away this period
        let toward = |target: Vector2<f64>| {
            let d = target - here;
            let reach = u_nom * period;
            let to = if d.norm() > reach { here + d / d.norm() * reach } else { target };
            Decided::from(Command::Path { from: here, to })
        };
        Ok(match c.mode {
            BearingMode::Planner => {
                let mut snapshot = None;
                let need = self.leg.is_none_or(|l| leg_done(l.from, l.to, here, u_nom, period)); // eq. 16
                if need {
                    let velocity = Vector2::new(fix.heading_rad.cos(), fix.heading_rad.sin()) * fix.speed_m_s.max(0.1);
                    let plan = self.plan(situation.t_s, here, velocity, beliefs);
                    let from = self.leg.map_or(here, |l| l.to);
                    self.leg = Some(Leg { from, to: plan.waypoint });
                    snapshot = Some(GuidanceSnapshot::Bearing(plan));
                }
                let leg = self.leg.expect("planned above");
                let (p_a, p_t) = leg_target(leg.from, leg.to, here, u_nom, period); // eq. 13-15
                // a leg shorter than one period ends at its waypoint
                let p_t = if (p_t - p_a).norm() > (leg.to - p_a).norm() { leg.to } else { p_t };
                Decided { command: Command::Path { from: p_a, to: p_t }, snapshot }
            }
            BearingMode::Static => Decided::from(Command::Path { from: here, to: c.home_m }),
            BearingMode::Circle => {
                let centre = beliefs[0].estimate().position_ned_m.xy();
                let r = c.circle_radius_m;
                let rel = here - centre;
                let angle = rel.y.atan2(rel.x) + (u_nom * period / r).min(FRAC_PI_2);
                toward(centre + Vector2::new(angle.cos(), angle.sin()) * r)
            }
            BearingMode::Offset => {
                let e = beliefs[0].estimate();
                let h = e.heading_rad();
                toward(e.position_ned_m.xy() - Vector2::new(h.cos(), h.sin()) * c.offset_m)
            }
        })
    }
}

/// `m` points standing for a Gaussian estimate's horizontal belief at its depth (the
/// planner's fallback when the belief is not a particle filter): a deterministic grid of
/// normal quantiles through the Cholesky factor.
fn gaussian_sample(e: &Estimate, m: usize) -> Vec<Vector3<f64>> {
    let side = (m as f64).sqrt().ceil().max(2.0) as usize;
    let l = e.horizontal_cov_m2.cholesky().map_or(Matrix2::zeros(), |c| c.l());
    let q = |i: usize| {
        statrs::function::erf::erf_inv(2.0 * (i as f64 + 0.5) / side as f64 - 1.0) * std::f64::consts::SQRT_2
    };
    let mut out = Vec::with_capacity(side * side);
    for i in 0..side {
        for j in 0..side {
            let d = l * Vector2::new(q(i), q(j));
            out.push(e.position_ned_m + Vector3::new(d.x, d.y, 0.0));
        }
    }
    out
}
