//! The next waypoint of the beacon vehicle (sousa section 3.3): the point of its
//! reaching set that maximises a Fisher-information metric.

use super::fim::{det2, range_fim};
use nalgebra::{Vector2, Vector3};
use std::f64::consts::TAU;

/// Which information metric to maximise.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Metric {
    /// det FIM of the previous and the candidate range about the target's current
    /// position (eq. 3.15 with N = 2).
    ApproachA,
    /// det FIM(w1) + det FIM(w2): the same pair of ranges about the target's current
    /// position w1 and its predicted position w2 at the next ping (eq. 3.16-3.19).
    ApproachB,
}

/// Where the ASV can be at the next ping: a disc of radius v_max T around it
/// (holonomic, as in sousa Fig. 3.4).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ReachingSet {
    pub center: Vector2<f64>,
    pub radius: f64,
}

impl ReachingSet {
    /// `p` moved onto the disc if it lies outside.
    fn clamp(&self, p: Vector2<f64>) -> Vector2<f64> {
        let d = p - self.center;
        let n = d.norm();
        if n > self.radius { self.center + d * (self.radius / n) } else { p }
    }
}

/// Polar search grid over the reaching set and local refinement.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct PolarGrid {
    /// Rings between the centre (excluded) and the edge (included).
    pub radial: usize,
    /// Directions per ring.
    pub angular: usize,
    /// Halvings of the pattern-search step after the grid.
    pub refinements: usize,
}

impl Default for PolarGrid {
    fn default() -> Self {
        Self { radial: 100, angular: 72, refinements: 12 }
    }
}

/// The planner's choice.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Decision {
    pub waypoint: Vector2<f64>,
    pub metric: f64,
}

/// Fisher-information guidance of a beacon vehicle at depth `beacon_depth_m` (NED z of
/// its transducer) for a target whose ranges have variance `range_var_m2`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FimPlanner {
    pub metric: Metric,
    pub grid: PolarGrid,
    pub range_var_m2: f64,
    pub beacon_depth_m: f64,
}

impl FimPlanner {
    /// The metric for a candidate next beacon position, given where the beacon was at
    /// the previous ping and the target now (`target`) and at the next ping
    /// (`target_next`, used by approach B).
    pub fn metric_at(
        &self,
        candidate: Vector2<f64>,
        previous: Vector2<f64>,
        target: &Vector3<f64>,
        target_next: &Vector3<f64>,
    ) -> f64 {
        let z = self.beacon_depth_m;
        let sources = [Vector3::new(previous.x, previous.y, z), Vector3::new(candidate.x, candidate.y, z)];
        let a = det2(&range_fim(target, &sources, self.range_var_m2));
        match self.metric {
            Metric::ApproachA => a,                                                              // eq. 3.15
            Metric::ApproachB => a + det2(&range_fim(target_next, &sources, self.range_var_m2)), // eq. 3.19
        }
    }

    /// The best point of `reach`: the maximum over the polar grid (and the centre),
    /// refined by a pattern search whose step halves down to 1/2^refinements of the
    /// ring spacing. Ties keep the first point found, so the result is deterministic.
    pub fn next_waypoint(
        &self,
        reach: &ReachingSet,
        previous: Vector2<f64>,
        target: &Vector3<f64>,
        target_next: &Vector3<f64>,
    ) -> Decision {
        let f = |p: Vector2<f64>| self.metric_at(p, previous, target, target_next);
        let mut best = Decision { waypoint: reach.center, metric: f(reach.center) };
        let (nr, na) = (self.grid.radial.max(1), self.grid.angular.max(1));
        let dirs: Vec<Vector2<f64>> = (0..na)
            .map(|j| {
                let a = TAU * j as f64 / na as f64;
                Vector2::new(a.cos(), a.sin())
            })
            .collect();
        for i in 1..=nr {
            let r = reach.radius * i as f64 / nr as f64;
            for d in &dirs {
                let p = reach.center + d * r;
                let m = f(p);
                if m > best.metric {
                    best = Decision { waypoint: p, metric: m };
                }
            }
        }
        // pattern search on the four axis directions, staying inside the disc
        let mut step = reach.radius / nr as f64;
        for _ in 0..self.grid.refinements {
            let mut moved = true;
            while moved {
                moved = false;
                for d in [
                    Vector2::new(step, 0.0),
                    Vector2::new(-step, 0.0),
                    Vector2::new(0.0, step),
                    Vector2::new(0.0, -step),
                ] {
                    let p = reach.clamp(best.waypoint + d);
                    let m = f(p);
                    if m > best.metric {
                        best = Decision { waypoint: p, metric: m };
                        moved = true;
                    }
                }
            }
            step *= 0.5;
        }
        best
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    fn planner(metric: Metric) -> FimPlanner {
        FimPlanner { metric, grid: PolarGrid::default(), range_var_m2: 1.0, beacon_depth_m: 0.0 }
    }

    /// Shallow target, far beacon, short reach: the best move is the one that turns the
    /// line of sight the most, perpendicular to it, to the edge of the reach.
    #[test]
    fn approach_a_moves_across_the_line_of_sight() {
        let target = Vector3::new(0.0, 0.0, 1.0);
        let previous = Vector2::new(50.0, 0.0);
        let reach = ReachingSet { center: previous, radius: 10.0 };
        let d = planner(Metric::ApproachA).next_waypoint(&reach, previous, &target, &target);
        let step = d.waypoint - previous;
        assert_relative_eq!(step.norm(), 10.0, max_relative = 1e-6);
        // moving across the line of sight (east or west), slightly toward the target
        assert!(step.y.abs() > 9.0 && step.x < 0.0, "{step:?}");
        // nothing on a fine brute-force grid does better
        let mut brute: f64 = 0.0;
        for i in -200..=200 {
            for j in -200..=200 {
                let p = previous + Vector2::new(i as f64, j as f64) * 0.05;
                if (p - previous).norm() <= 10.0 {
                    brute = brute.max(planner(Metric::ApproachA).metric_at(p, previous, &target, &target));
                }
            }
        }
        assert!(d.metric >= brute * (1.0 - 1e-9), "{} < {brute}", d.metric);
    }

    #[test]
    fn approach_b_adds_the_predicted_target() {
        let p = planner(Metric::ApproachB);
        let (target, next) = (Vector3::new(0.0, 0.0, 20.0), Vector3::new(20.0, 0.0, 20.0));
        let (prev, cand) = (Vector2::new(20.0, 0.0), Vector2::new(0.0, 30.0));
        let a = planner(Metric::ApproachA);
        let expected = a.metric_at(cand, prev, &target, &target) + a.metric_at(cand, prev, &next, &next);
        assert_relative_eq!(p.metric_at(cand, prev, &target, &next), expected, max_relative = 1e-12);
        // with a target that does not move, B is twice A and picks the same point
        let reach = ReachingSet { center: prev, radius: 20.0 };
        let (da, db) =
            (a.next_waypoint(&reach, prev, &target, &target), p.next_waypoint(&reach, prev, &target, &target));
        assert_relative_eq!(db.metric, 2.0 * da.metric, max_relative = 1e-9);
        assert!((da.waypoint - db.waypoint).norm() < 1e-6);
    }
}
