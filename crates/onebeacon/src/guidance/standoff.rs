//! The best initial horizontal distance between beacon vehicle and target (sousa
//! section 4.2.1, Fig. 4.7-4.8): for a target at a given depth and a beacon that moves
//! at most `reach` metres between pings, the distance whose best second ping (found by
//! the approach-A planner) gives the most information.

use super::planner::{FimPlanner, Metric, PolarGrid, ReachingSet};
use nalgebra::{Vector2, Vector3};

/// The answer for one depth.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Standoff {
    pub depth_m: f64,
    /// Best horizontal distance at the first ping, m.
    pub distance_m: f64,
    /// det FIM of the first two ranges at that distance (range variance 1 m^2), 1/m^4.
    pub det_fim: f64,
}

/// The best standoff for a target at `depth_m` (beacon at the surface) when the beacon
/// can move `reach_m` between pings: a scan of distances followed by golden-section
/// refinement around the best one.
pub fn best_standoff(depth_m: f64, reach_m: f64, grid: PolarGrid) -> Standoff {
    let planner = FimPlanner { metric: Metric::ApproachA, grid, range_var_m2: 1.0, beacon_depth_m: 0.0 };
    let target = Vector3::new(0.0, 0.0, depth_m);
    let value = |d: f64| {
        let start = Vector2::new(d, 0.0);
        planner.next_waypoint(&ReachingSet { center: start, radius: reach_m }, start, &target, &target).metric
    };
    let far = 4.0 * (depth_m + reach_m);
    let n = 80;
    let step = far / n as f64;
    let (mut best_d, mut best_v) = (0.0, value(0.0));
    for i in 1..=n {
        let d = i as f64 * step;
        let v = value(d);
        if v > best_v {
            (best_d, best_v) = (d, v);
        }
    }
    // golden section on [best - step, best + step]
    let (d_opt, v_opt) = crate::optim::golden_section_max(value, (best_d - step).max(0.0), best_d + step, 30);
    if v_opt > best_v {
        Standoff { depth_m, distance_m: d_opt, det_fim: v_opt }
    } else {
        Standoff { depth_m, distance_m: best_d, det_fim: best_v }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// sousa Fig. 4.7-4.8: the best distance grows with depth, the information falls.
    #[test]
    fn standoff_grows_with_depth_and_information_falls() {
        let grid = PolarGrid { radial: 20, angular: 36, refinements: 10 };
        let s: Vec<Standoff> = [1.0, 5.0, 20.0, 50.0].iter().map(|&d| best_standoff(d, 20.0, grid)).collect();
        for w in s.windows(2) {
            assert!(w[1].distance_m > w[0].distance_m, "{s:?}");
            assert!(w[1].det_fim < w[0].det_fim, "{s:?}");
        }
        // a deep target is best seen from about its depth away: the slant angle matters
        assert!(s[3].distance_m > 30.0 && s[3].distance_m < 100.0, "{s:?}");
    }

    /// With a reach that allows a quarter turn around a shallow target, the two lines
    /// of sight become perpendicular and nearly horizontal: det approaches 1 / sigma^4.
    #[test]
    fn shallow_target_reaches_the_planar_bound() {
        let s = best_standoff(0.5, 20.0, PolarGrid { radial: 20, angular: 36, refinements: 12 });
        assert!(s.det_fim > 0.9 && s.det_fim <= 1.0 + 1e-9, "{s:?}");
    }
}
