//! The underwater vehicle's truth: body velocities that define its path (sousa 4.1.1:
//! "its path is defined by the inputs"), integrated with RK4 through the 6-DOF
//! kinematics (eq. 4.4-4.5).

use onebeacon::models::kinematic6dof::{BodyVelocity, State, euler_rate_matrix, rotation};
use serde::{Deserialize, Serialize};
use std::f64::consts::PI;

/// The underwater vehicle's path, defined by its body velocities (sousa 4.1.1).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum PathKind {
    Stationary,
    Lawnmower,
    Circular,
    Spiral,
}

impl PathKind {
    pub fn label(self) -> &'static str {
        match self {
            PathKind::Stationary => "stationary",
            PathKind::Lawnmower => "lawnmower",
            PathKind::Circular => "circular",
            PathKind::Spiral => "spiral",
        }
    }
}

/// A path by its body velocities: its kind and its dimensions.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BodyPath {
    pub kind: PathKind,
    /// Surge speed on moving paths, m/s.
    pub speed_m_s: f64,
    /// Radius of the circular and spiral paths, m.
    pub circle_radius_m: f64,
    /// Descent rate of the spiral, m/s.
    pub spiral_descent_m_s: f64,
    /// Lawnmower leg length and spacing (diameter of the turns), m.
    pub leg_length_m: f64,
    pub leg_spacing_m: f64,
}

/// True body velocities [u, v, w, p, q, r] at time `t` on path `v`.
pub fn body_velocity(v: &BodyPath, t: f64) -> BodyVelocity {
    let u = v.speed_m_s;
    match v.kind {
        PathKind::Stationary => BodyVelocity::zeros(),
        PathKind::Circular => BodyVelocity::from([u, 0.0, 0.0, 0.0, 0.0, u / v.circle_radius_m]),
        PathKind::Spiral => BodyVelocity::from([u, 0.0, v.spiral_descent_m_s, 0.0, 0.0, u / v.circle_radius_m]),
        PathKind::Lawnmower => {
            if u <= 0.0 {
                return BodyVelocity::zeros();
            }
            // a leg, then a half-circle turn, alternately to the right and to the left
            let radius = v.leg_spacing_m / 2.0;
            let (t_leg, t_turn) = (v.leg_length_m / u, PI * radius / u);
            let period = t_leg + t_turn;
            let k = (t / period).floor();
            let in_period = t - k * period;
            if in_period < t_leg {
                BodyVelocity::from([u, 0.0, 0.0, 0.0, 0.0, 0.0])
            } else {
                let sign = if (k as i64) % 2 == 0 { 1.0 } else { -1.0 };
                BodyVelocity::from([u, 0.0, 0.0, 0.0, 0.0, sign * u / radius])
            }
        }
    }
}

fn derivative(eta: &State, nu: &BodyVelocity) -> State {
    let r = rotation(eta[3], eta[4], eta[5]);
    let t = euler_rate_matrix(eta[3], eta[4]);
    let lin = r * nu.fixed_rows::<3>(0);
    let ang = t * nu.fixed_rows::<3>(3);
    State::from([lin.x, lin.y, lin.z, ang.x, ang.y, ang.z])
}

/// One RK4 step of eta' = J(eta) nu(t) (eq. 4.4) from `t` to `t + dt`.
pub fn rk4_step(eta: &State, t: f64, dt: f64, nu: impl Fn(f64) -> BodyVelocity) -> State {
    let (n0, nh, n1) = (nu(t), nu(t + dt / 2.0), nu(t + dt));
    let k1 = derivative(eta, &n0);
    let k2 = derivative(&(eta + k1 * (dt / 2.0)), &nh);
    let k3 = derivative(&(eta + k2 * (dt / 2.0)), &nh);
    let k4 = derivative(&(eta + k3 * dt), &n1);
    eta + (k1 + k2 * 2.0 + k3 * 2.0 + k4) * (dt / 6.0)
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_abs_diff_eq;

    #[test]
    fn circle_closes_and_spiral_descends() {
        let path = |kind| BodyPath {
            kind,
            speed_m_s: 0.5,
            circle_radius_m: 25.0,
            spiral_descent_m_s: 0.01,
            leg_length_m: 0.0,
            leg_spacing_m: 0.0,
        };
        let period = 2.0 * PI * 25.0 / 0.5;
        let dt = 0.1;
        let steps = (period / dt).round() as usize;
        for (kind, dz) in [(PathKind::Circular, 0.0), (PathKind::Spiral, 0.01 * period)] {
            let mut eta = State::from([0.0, 0.0, 5.0, 0.0, 0.0, 0.0]);
            let mut max_e: f64 = 0.0;
            for k in 0..steps {
                eta = rk4_step(&eta, k as f64 * dt, dt, |t| body_velocity(&path(kind), t));
                max_e = max_e.max(eta[1]);
            }
            assert_abs_diff_eq!(eta[0], 0.0, epsilon = 0.05);
            assert_abs_diff_eq!(eta[1], 0.0, epsilon = 0.05);
            assert_abs_diff_eq!(max_e, 50.0, epsilon = 0.01);
            assert_abs_diff_eq!(eta[2], 5.0 + dz, epsilon = 0.05);
        }
    }

    #[test]
    fn lawnmower_legs_are_parallel_and_spaced() {
        let v = BodyPath {
            kind: PathKind::Lawnmower,
            speed_m_s: 1.0,
            circle_radius_m: 0.0,
            spiral_descent_m_s: 0.0,
            leg_length_m: 100.0,
            leg_spacing_m: 20.0,
        };
        let dt = 0.05;
        let one = 100.0 + PI * 10.0; // a leg and a turn
        let mut eta = State::zeros();
        let mut t = 0.0;
        while t < 2.0 * one - 1e-9 {
            eta = rk4_step(&eta, t, dt, |s| body_velocity(&v, s));
            t += dt;
        }
        // after two legs and two turns (right, then left): back at the start line, 40 m east
        assert_abs_diff_eq!(eta[0], 0.0, epsilon = 0.3);
        assert_abs_diff_eq!(eta[1], 40.0, epsilon = 0.3);
    }
}
