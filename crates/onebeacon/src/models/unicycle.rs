//! The 2-D unicycle with turn rate and acceleration as states (garin2024 eq. 6-7, 21).
//!
//! State z = [x, y, psi, v, Omega, a]: NED position (m), heading from north (rad),
//! forward speed (m/s), yaw rate (rad/s), forward acceleration (m/s^2). Turn rate and
//! acceleration are random walks driven by the process noise; the IMU measures them.

use crate::filter::ProcessModel;
use nalgebra::{SMatrix, SVector};

/// Index of each state component.
pub mod idx {
    pub const X: usize = 0;
    pub const Y: usize = 1;
    pub const PSI: usize = 2;
    pub const V: usize = 3;
    pub const OMEGA: usize = 4;
    pub const ACCEL: usize = 5;
}

/// State dimension.
pub const DIM: usize = 6;

pub type State = SVector<f64, DIM>;
pub type Cov = SMatrix<f64, DIM, DIM>;

/// Euler-discretised unicycle with turn rate and acceleration states, and its process
/// noise: the diagonal of Q per step (garin2024 eq. 25 gives Q per step, not per second).
#[derive(Debug, Clone, Copy, Default)]
pub struct UnicycleAccel {
    pub q_diag: [f64; DIM],
}

impl ProcessModel<DIM> for UnicycleAccel {
    fn noise_covariance(&self, _z: &State, _dt: f64) -> Cov {
        Cov::from_diagonal(&State::from(self.q_diag))
    }

    fn is_angle(&self, i: usize) -> bool {
        i == idx::PSI
    }

    fn propagate(&self, z: &State, dt: f64) -> State {
        self.transition(z, dt).0
    }

    fn jacobian(&self, z: &State, dt: f64) -> Cov {
        self.transition(z, dt).1
    }

    fn transition(&self, z: &State, dt: f64) -> (State, Cov) {
        let v = z[idx::V];
        let (s, c) = z[idx::PSI].sin_cos();
        let mut n = *z;
        n[idx::X] += v * dt * c; // eq. 7, row 1
        n[idx::Y] += v * dt * s; // eq. 7, row 2
        n[idx::PSI] += dt * z[idx::OMEGA]; // eq. 7, row 3
        n[idx::V] += dt * z[idx::ACCEL]; // eq. 7, row 4
        let mut f = Cov::identity(); // eq. 21
        f[(idx::X, idx::PSI)] = -v * dt * s;
        f[(idx::X, idx::V)] = dt * c;
        f[(idx::Y, idx::PSI)] = v * dt * c;
        f[(idx::Y, idx::V)] = dt * s;
        f[(idx::PSI, idx::OMEGA)] = dt;
        f[(idx::V, idx::ACCEL)] = dt;
        (n, f)
    }

    /// F P F' + Q with F = I + E, E having the six entries of eq. 21 off the diagonal:
    /// a third of the work of the dense products.
    #[inline]
    fn propagate_covariance(&self, f: &Cov, p: &Cov, q: &Cov) -> Cov {
        use idx::*;
        let e = |i, j| f[(i, j)];
        let mut a = *p; // F P: rows x, y, psi, v gain multiples of other rows
        a.set_row(X, &(p.row(X) + p.row(PSI) * e(X, PSI) + p.row(V) * e(X, V)));
        a.set_row(Y, &(p.row(Y) + p.row(PSI) * e(Y, PSI) + p.row(V) * e(Y, V)));
        a.set_row(PSI, &(p.row(PSI) + p.row(OMEGA) * e(PSI, OMEGA)));
        a.set_row(V, &(p.row(V) + p.row(ACCEL) * e(V, ACCEL)));
        let mut b = a; // (F P) F': the same on columns
        b.set_column(X, &(a.column(X) + a.column(PSI) * e(X, PSI) + a.column(V) * e(X, V)));
        b.set_column(Y, &(a.column(Y) + a.column(PSI) * e(Y, PSI) + a.column(V) * e(Y, V)));
        b.set_column(PSI, &(a.column(PSI) + a.column(OMEGA) * e(PSI, OMEGA)));
        b.set_column(V, &(a.column(V) + a.column(ACCEL) * e(V, ACCEL)));
        b + q
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_abs_diff_eq;

    #[test]
    fn jacobian_matches_finite_differences() {
        let m = UnicycleAccel::default();
        let dt = 0.25;
        for z in [
            State::from([3.0, -2.0, 0.7, 1.2, 0.05, -0.02]),
            State::from([-10.0, 5.0, -2.9, -1.5, -0.1, 0.3]),
            State::from([0.0, 0.0, 3.1, 0.0, 0.0, 0.0]),
        ] {
            let f = m.jacobian(&z, dt);
            let eps = 1e-6;
            for j in 0..DIM {
                let mut zp = z;
                let mut zm = z;
                zp[j] += eps;
                zm[j] -= eps;
                let col = (m.propagate(&zp, dt) - m.propagate(&zm, dt)) / (2.0 * eps);
                for i in 0..DIM {
                    assert_abs_diff_eq!(f[(i, j)], col[i], epsilon = 1e-8);
                }
            }
        }
    }

    #[test]
    fn sparse_covariance_prediction_equals_dense_product() {
        let m = UnicycleAccel::default();
        let z = State::from([3.0, -2.0, 0.7, 1.2, 0.05, -0.02]);
        let f = m.jacobian(&z, 0.25);
        let l = Cov::from_fn(|i, j| if j <= i { 0.1 + (i * 6 + j) as f64 * 0.07 } else { 0.0 });
        let p = l * l.transpose();
        let q = Cov::from_diagonal_element(1e-3);
        let dense = f * p * f.transpose() + q;
        let sparse = m.propagate_covariance(&f, &p, &q);
        for (a, b) in dense.iter().zip(sparse.iter()) {
            assert_abs_diff_eq!(a, b, epsilon = 1e-12);
        }
    }

    #[test]
    fn straight_line_at_constant_speed() {
        // heading east (psi = pi/2) at 2 m/s for 10 steps of 0.5 s: 10 m east
        let mut z = State::from([0.0, 0.0, std::f64::consts::FRAC_PI_2, 2.0, 0.0, 0.0]);
        for _ in 0..10 {
            z = UnicycleAccel::default().propagate(&z, 0.5);
        }
        assert_abs_diff_eq!(z[idx::X], 0.0, epsilon = 1e-12);
        assert_abs_diff_eq!(z[idx::Y], 10.0, epsilon = 1e-12);
    }
}
