//! The surface vehicle: 3-DOF kinematics (sousa eq. 4.1-4.2) with speed and turn-rate
//! limits, driven toward a waypoint to be reached at a given time.

use nalgebra::Vector2;
use onebeacon::geo::wrap_angle;

/// ASV truth [N, E, psi].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AsvState {
    pub pos: Vector2<f64>,
    pub psi: f64,
}

/// Limits of the ASV.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AsvLimits {
    pub max_speed_m_s: f64,
    pub max_turn_rate_rad_s: f64,
}

impl AsvState {
    /// Surge and yaw-rate commands toward `waypoint`, to arrive `time_left` seconds from
    /// now: turn toward it at up to the maximum rate (gain 1/s on the heading error),
    /// at the speed that arrives in time, slowed while the heading is far off.
    pub fn command(&self, waypoint: Vector2<f64>, time_left: f64, lim: &AsvLimits) -> (f64, f64) {
        let d = waypoint - self.pos;
        let dist = d.norm();
        if dist < 0.05 {
            return (0.0, 0.0);
        }
        let err = wrap_angle(d.y.atan2(d.x) - self.psi);
        let r = err.clamp(-lim.max_turn_rate_rad_s, lim.max_turn_rate_rad_s);
        let u = (dist / time_left.max(1.0)).min(lim.max_speed_m_s) * err.cos().max(0.0);
        (u, r)
    }

    /// Exact integration over `dt` of eq. 4.1 with constant surge `u` and yaw rate `r`
    /// (no sway): an arc of a circle.
    pub fn step(&self, u: f64, r: f64, dt: f64) -> Self {
        let psi1 = self.psi + r * dt;
        let delta = if r.abs() < 1e-9 {
            Vector2::new(self.psi.cos(), self.psi.sin()) * (u * dt)
        } else {
            Vector2::new(psi1.sin() - self.psi.sin(), self.psi.cos() - psi1.cos()) * (u / r)
        };
        Self { pos: self.pos + delta, psi: wrap_angle(psi1) }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_abs_diff_eq;

    #[test]
    fn arc_step_matches_fine_euler() {
        let s = AsvState { pos: Vector2::new(1.0, 2.0), psi: 0.4 };
        let exact = s.step(1.5, 0.3, 2.0);
        let mut e = s;
        for _ in 0..20_000 {
            e = AsvState {
                pos: e.pos + Vector2::new(e.psi.cos(), e.psi.sin()) * (1.5 * 1e-4),
                psi: e.psi + 0.3 * 1e-4,
            };
        }
        assert_abs_diff_eq!(exact.pos, e.pos, epsilon = 1e-3);
        assert_abs_diff_eq!(exact.psi, e.psi, epsilon = 1e-9);
    }

    #[test]
    fn reaches_a_waypoint_behind_it_within_the_limits() {
        let lim = AsvLimits { max_speed_m_s: 2.0, max_turn_rate_rad_s: 0.5 };
        let mut s = AsvState { pos: Vector2::zeros(), psi: 0.0 };
        let wp = Vector2::new(-10.0, 5.0);
        let dt = 0.1;
        for k in 0..300 {
            let (u, r) = s.command(wp, 30.0 - k as f64 * dt, &lim);
            assert!(u <= 2.0 + 1e-12 && r.abs() <= 0.5 + 1e-12);
            s = s.step(u, r, dt);
        }
        assert!((s.pos - wp).norm() < 0.5, "{:?}", s.pos);
    }
}
