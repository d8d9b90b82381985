//! Truth kinematics of the AUV in the plane and its path-following controller
//! (garin2024 eq. 1-4).

use super::path::Reference;
use nalgebra::Vector2;

/// Truth state X = [x, y, psi, v] (eq. 3): NED position, heading, forward speed.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TruthState {
    pub pos: Vector2<f64>,
    pub psi: f64,
    pub v: f64,
}

impl TruthState {
    /// Euler step of eq. 3 with f_t of eq. 4 under command (Omega, a).
    pub fn step(&self, omega: f64, accel: f64, dt: f64) -> Self {
        Self {
            pos: self.pos + Vector2::new(self.psi.cos(), self.psi.sin()) * (self.v * dt),
            psi: self.psi + omega * dt,
            v: self.v + accel * dt,
        }
    }

    /// Velocity over ground, NED.
    pub fn velocity(&self) -> Vector2<f64> {
        Vector2::new(self.psi.cos(), self.psi.sin()) * self.v
    }
}

/// Feedback-linearising command (Omega, a) that makes the vehicle follow `reference`
/// (eq. 2): the error dynamics e'' + 2 e' + e = 0 are critically damped at 1 rad/s.
/// The speed used to invert the decoupling matrix is kept away from zero.
pub fn feedback_linearising_control(x: &TruthState, reference: &Reference) -> (f64, f64) {
    let (s, c) = x.psi.sin_cos();
    let vel = Vector2::new(c, s) * x.v;
    let e = (reference.pos - x.pos) + 2.0 * (reference.vel - vel) + reference.acc;
    // [Omega, a]' = M^-1 e with M = [-v sin psi, cos psi; v cos psi, sin psi], det M = -v
    let v = if x.v.abs() < 0.1 { 0.1_f64.copysign(x.v) } else { x.v };
    let omega = (c * e.y - s * e.x) / v;
    let accel = c * e.x + s * e.y;
    (omega, accel)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::vehicles::path::Path;
    use approx::assert_abs_diff_eq;
    use std::f64::consts::PI;

    #[test]
    fn command_realises_the_desired_acceleration() {
        // with the command applied, the vehicle's acceleration d/dt (v cos psi, v sin psi)
        // equals the feedback-linearised input e of eq. 2
        let x = TruthState { pos: Vector2::new(1.0, 2.0), psi: 0.7, v: 1.2 };
        let r = Reference { pos: Vector2::new(2.0, 1.5), vel: Vector2::new(0.5, 1.0), acc: Vector2::new(0.1, -0.2) };
        let (omega, accel) = feedback_linearising_control(&x, &r);
        let (s, c) = x.psi.sin_cos();
        let acc = Vector2::new(accel * c - x.v * s * omega, accel * s + x.v * c * omega);
        let e = (r.pos - x.pos) + 2.0 * (r.vel - x.velocity()) + r.acc;
        assert_abs_diff_eq!(acc, e, epsilon = 1e-12);
    }

    #[test]
    fn follows_a_boustrophedon_closely() {
        let path = Path::boustrophedon(Vector2::zeros(), PI / 2.0, 100.0, 20.0, 3, true);
        let dt = 0.25;
        let mut x = TruthState { pos: Vector2::new(2.0, 0.0), psi: PI / 2.0, v: 1.0 };
        let mut worst: f64 = 0.0;
        for k in 0..((path.length() / dt) as usize) {
            let r = path.at_time(k as f64 * dt, 1.0);
            if k as f64 * dt > 20.0 {
                worst = worst.max((r.pos - x.pos).norm());
            }
            let (omega, accel) = feedback_linearising_control(&x, &r);
            x = x.step(omega, accel, dt);
        }
        // the initial 2 m offset has died out; turns cost a few decimetres at most
        assert!(worst < 0.5, "tracking error {worst}");
    }
}
