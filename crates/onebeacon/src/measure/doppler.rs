//! Relative (radial) speed toward a beacon from the Doppler shift of a communication
//! frame (garin2024 eq. 13-15, 20).
//!
//! Sign: positive when the vehicle closes on the beacon. The vehicle moves along its
//! heading at its forward speed (no sideslip): v_r = v cos(omega_b - psi) with
//! omega_b = atan2(y - y_ref, x - x_ref) + pi the bearing from the vehicle to the beacon
//! ([`RadialSpeed2d`], the paper's horizontal geometry, or along the slant line of sight
//! of a vehicle below the beacon). [`LineOfSightSpeed`] is the same slant speed for a
//! state that holds the velocity itself (the smoother's tracks and the interval
//! velocities of its poses): on a log, the filters and the smoother read a Doppler speed
//! alike.

use super::ScalarModel;
use crate::models::unicycle::idx;
use nalgebra::{SMatrix, SVector, Vector2, Vector3};

/// Radial speed of the vehicle toward `beacon` (NED, m), read from the unicycle state
/// layout (position, heading, forward speed), or with the forward speed a known input
/// (`known_speed_m_s`: odometry, DVL), when only position and heading are states; along
/// the slant line of sight of a vehicle `dz_m` below the beacon (0: the paper's
/// horizontal geometry, exactly). Noise variance `var` ((m/s)^2).
#[derive(Debug, Clone, Copy)]
pub struct RadialSpeed2d {
    pub beacon: Vector2<f64>,
    pub known_speed_m_s: Option<f64>,
    pub dz_m: f64,
    pub var: f64,
}

impl<const N: usize> ScalarModel<N> for RadialSpeed2d {
    fn predict(&self, x: &SVector<f64, N>) -> f64 {
        let (dx, dy) = (x[idx::X] - self.beacon.x, x[idx::Y] - self.beacon.y);
        let c = dy.atan2(dx) - x[idx::PSI]; // C of eq. 23
        let horizontal = -self.speed(x) * c.cos(); // eq. 20, second row; equals eq. 13 with eq. 14
        horizontal * self.slant(dx, dy).0 // exactly 1 level with the beacon
    }

    fn jacobian(&self, x: &SVector<f64, N>) -> SMatrix<f64, 1, N> {
        let (dx, dy) = (x[idx::X] - self.beacon.x, x[idx::Y] - self.beacon.y);
        let r2 = dx * dx + dy * dy;
        let v = self.speed(x);
        let c = dy.atan2(dx) - x[idx::PSI];
        let mut h = SMatrix::<f64, 1, N>::zeros();
        if r2 > 1e-18 {
            let b = v * c.sin() / r2; // B of eq. 23
            h[idx::X] = -b * dy; // eq. 22, last row
            h[idx::Y] = b * dx;
        }
        h[idx::PSI] = -v * c.sin();
        if self.known_speed_m_s.is_none() {
            h[idx::V] = -c.cos();
        }
        if self.dz_m != 0.0 {
            // the horizontal speed w times the slant factor f: f dw + w df
            let (f, df) = self.slant(dx, dy);
            let w = -v * c.cos();
            h *= f;
            h[idx::X] += w * df.x;
            h[idx::Y] += w * df.y;
        }
        h
    }

    fn variance(&self, _x: &SVector<f64, N>) -> f64 {
        self.var
    }
}

impl RadialSpeed2d {
    fn speed<const N: usize>(&self, x: &SVector<f64, N>) -> f64 {
        self.known_speed_m_s.unwrap_or_else(|| x[idx::V])
    }

    /// The share of a horizontal speed along the slant line of sight, f = h / sqrt(h^2 +
    /// dz^2) with h the horizontal distance (dx, dy), and its gradient in (dx, dy):
    /// dz^2 (dx, dy) / (h R^3). One at the beacon's depth; zero straight below it.
    pub(crate) fn slant(&self, dx: f64, dy: f64) -> (f64, Vector2<f64>) {
        if self.dz_m == 0.0 {
            return (1.0, Vector2::zeros());
        }
        let h = dx.hypot(dy);
        let r = h.hypot(self.dz_m);
        if h < 1e-9 {
            return (0.0, Vector2::zeros());
        }
        (h / r, Vector2::new(dx, dy) * (self.dz_m * self.dz_m / (h * r * r * r)))
    }
}

/// The closing speed along the slant line of sight of a vehicle at depth `depth_m` whose
/// horizontal position and velocity are the state's components 0, 1 (N, E) and 2, 3
/// (vN, vE) toward `beacon` (NED, m): -(d . v) / |d| with d the vehicle's offset from the
/// beacon (garin2024 eq. 13 with the line of sight in 3-D; with the beacon at the
/// vehicle's depth it is [`RadialSpeed2d`] with v cos(psi), v sin(psi) for the velocity).
/// Noise variance `var` ((m/s)^2).
#[derive(Debug, Clone, Copy)]
pub struct LineOfSightSpeed {
    pub beacon: Vector3<f64>,
    pub depth_m: f64,
    pub var: f64,
}

impl LineOfSightSpeed {
    /// The offset from the beacon and its length (at least 1e-6 m).
    fn offset<const N: usize>(&self, x: &SVector<f64, N>) -> (Vector3<f64>, f64) {
        let d = Vector3::new(x[0], x[1], self.depth_m) - self.beacon;
        (d, d.norm().max(1e-6))
    }
}

impl<const N: usize> ScalarModel<N> for LineOfSightSpeed {
    fn predict(&self, x: &SVector<f64, N>) -> f64 {
        let (d, r) = self.offset(x);
        -(d.x * x[2] + d.y * x[3]) / r // eq. 13: closing positive
    }

    fn jacobian(&self, x: &SVector<f64, N>) -> SMatrix<f64, 1, N> {
        let (d, r) = self.offset(x);
        let along = (d.x * x[2] + d.y * x[3]) / (r * r * r);
        let mut h = SMatrix::<f64, 1, N>::zeros();
        h[0] = -x[2] / r + along * d.x;
        h[1] = -x[3] / r + along * d.y;
        h[2] = -d.x / r;
        h[3] = -d.y / r;
        h
    }

    fn variance(&self, _x: &SVector<f64, N>) -> f64 {
        self.var
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::measure::finite_difference;
    use approx::assert_abs_diff_eq;
    use std::f64::consts::{FRAC_PI_2, PI};

    fn state(x: f64, y: f64, psi: f64, v: f64) -> SVector<f64, 6> {
        SVector::<f64, 6>::from([x, y, psi, v, 0.0, 0.0])
    }

    #[test]
    fn sign_is_positive_when_closing() {
        let m = RadialSpeed2d { beacon: Vector2::new(0.0, 0.0), known_speed_m_s: None, dz_m: 0.0, var: 0.1 };
        // vehicle 10 m north of the beacon heading south at 1.5 m/s: closing at 1.5
        assert_abs_diff_eq!(ScalarModel::<6>::predict(&m, &state(10.0, 0.0, PI, 1.5)), 1.5, epsilon = 1e-12);
        // heading north: opening
        assert_abs_diff_eq!(ScalarModel::<6>::predict(&m, &state(10.0, 0.0, 0.0, 1.5)), -1.5, epsilon = 1e-12);
        // heading east, abeam: zero
        assert_abs_diff_eq!(ScalarModel::<6>::predict(&m, &state(10.0, 0.0, FRAC_PI_2, 1.5)), 0.0, epsilon = 1e-12);
        // 45 deg off the line of sight
        let v = ScalarModel::<6>::predict(&m, &state(10.0, 10.0, -FRAC_PI_2, 2.0));
        assert_abs_diff_eq!(v, 2.0 * (PI / 4.0).cos(), epsilon = 1e-12);
    }

    /// The line-of-sight speed: its Jacobian against central differences, and with the
    /// beacon at the vehicle's depth, the horizontal model's speed (closed form).
    #[test]
    fn line_of_sight_speed_is_the_horizontal_one_at_the_beacons_depth() {
        let m = LineOfSightSpeed { beacon: Vector3::new(50.0, 100.0, 3.0), depth_m: 40.0, var: 0.1 };
        for x in [[10.0, 20.0, 0.4, 1.1], [80.0, 230.0, -2.5, 0.9], [49.0, 101.0, 3.0, -1.2]] {
            let x = SVector::<f64, 4>::from(x);
            let (h, fd) = (ScalarModel::<4>::jacobian(&m, &x), finite_difference::<4>(&m, &x));
            assert_abs_diff_eq!(h, fd, epsilon = 1e-7);
        }
        let level = LineOfSightSpeed { beacon: Vector3::new(0.0, 0.0, 0.0), depth_m: 0.0, var: 0.1 };
        let flat = RadialSpeed2d { beacon: Vector2::new(0.0, 0.0), known_speed_m_s: None, dz_m: 0.0, var: 0.1 };
        for (n, e, psi, v) in [(10.0, 10.0, -FRAC_PI_2, 2.0), (-30.0, 4.0, 0.3, 1.1)] {
            let x = SVector::<f64, 4>::from([n, e, v * f64::cos(psi), v * f64::sin(psi)]);
            let horizontal = ScalarModel::<6>::predict(&flat, &state(n, e, psi, v));
            assert_abs_diff_eq!(ScalarModel::<4>::predict(&level, &x), horizontal, epsilon = 1e-12);
        }
        // 30 m above a vehicle 40 m away horizontally, closing at 1 m/s horizontally: 4/5
        let above = LineOfSightSpeed { beacon: Vector3::new(0.0, 0.0, 0.0), depth_m: 30.0, var: 0.1 };
        let x = SVector::<f64, 4>::from([40.0, 0.0, -1.0, 0.0]);
        assert_abs_diff_eq!(ScalarModel::<4>::predict(&above, &x), 0.8, epsilon = 1e-12);
        // the heading-and-speed layout below the beacon reads the same slant speed, and its
        // Jacobian (the slant factor's gradient included) the central differences
        let below = RadialSpeed2d { dz_m: 37.0, ..flat };
        let deep = LineOfSightSpeed { depth_m: 37.0, ..level };
        for (n, e, psi, v) in [(10.0, 10.0, -FRAC_PI_2, 2.0), (-30.0, 4.0, 0.3, 1.1), (60.0, -80.0, 2.9, 1.6)] {
            let x = SVector::<f64, 4>::from([n, e, v * f64::cos(psi), v * f64::sin(psi)]);
            let slant = ScalarModel::<6>::predict(&below, &state(n, e, psi, v));
            assert_abs_diff_eq!(ScalarModel::<4>::predict(&deep, &x), slant, epsilon = 1e-12);
            let (h, fd) = (
                ScalarModel::<6>::jacobian(&below, &state(n, e, psi, v)),
                finite_difference::<6>(&below, &state(n, e, psi, v)),
            );
            assert_abs_diff_eq!(h, fd, epsilon = 1e-7);
        }
    }

    #[test]
    fn jacobian_matches_finite_differences() {
        let m = RadialSpeed2d { beacon: Vector2::new(50.0, 100.0), known_speed_m_s: None, dz_m: 0.0, var: 0.1 };
        let known = RadialSpeed2d { known_speed_m_s: Some(1.3), ..m };
        for x in [state(10.0, 20.0, 0.4, 1.1), state(80.0, 230.0, -2.5, 0.9), state(49.0, 101.0, 3.0, -1.2)] {
            for m in [m, known] {
                let h = ScalarModel::<6>::jacobian(&m, &x);
                let fd = finite_difference::<6>(&m, &x);
                for j in 0..6 {
                    assert_abs_diff_eq!(h[j], fd[j], epsilon = 1e-7);
                }
            }
        }
        // a known speed is the input, whatever the state holds
        let (x, x_at_known) = (state(10.0, 0.0, 0.7, 9.0), state(10.0, 0.0, 0.7, 1.3));
        assert_abs_diff_eq!(
            ScalarModel::<6>::predict(&known, &x),
            ScalarModel::<6>::predict(&m, &x_at_known),
            epsilon = 1e-12
        );
    }
}
