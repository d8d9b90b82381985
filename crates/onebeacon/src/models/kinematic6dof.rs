//! 6-DOF kinematic model driven by measured body velocities (sousa eq. 3.1-3.2, 4.4-4.5,
//! A.1-A.6; Fossen 2011, eq. 2.40).
//!
//! State eta = [N, E, D, phi, theta, psi]: NED position (m) and roll, pitch, yaw (rad,
//! zyx convention). Input nu = [u, v, w, p, q, r]: body-fixed linear (m/s) and angular
//! (rad/s) velocities, measured on the vehicle (DVL/odometry and gyros). The transition
//! is the Euler step eta + dt J(eta) nu (A.2-A.3). Its Jacobians are derived here from
//! J = diag(R(phi, theta, psi), T(phi, theta)): the thesis's appendix has typos (its
//! third row of R reads -theta c(phi) for c(theta) c(phi)) and is not copied.

use crate::filter::ProcessModel;
use nalgebra::{Matrix3, Rotation3, SMatrix, SVector, Vector3};
use std::ops::AddAssign;

/// Index of each state component.
pub mod idx {
    pub const N: usize = 0;
    pub const E: usize = 1;
    pub const D: usize = 2;
    pub const ROLL: usize = 3;
    pub const PITCH: usize = 4;
    pub const YAW: usize = 5;
}

/// State and input dimension.
pub const DIM: usize = 6;

pub type State = SVector<f64, DIM>;
pub type Cov = SMatrix<f64, DIM, DIM>;
/// Body velocities [u, v, w, p, q, r].
pub type BodyVelocity = SVector<f64, DIM>;

/// The Euler-discretised 6-DOF kinematics for one step's measured body velocities `nu`,
/// with their noise: standard deviations of u, v, w (`velocity_sigma_m_s`) and of p, q,
/// r (`rate_sigma_rad_s`), mapped into the state by dt J(eta) (eq. 3.2).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Kinematic6Dof {
    pub nu: BodyVelocity,
    pub velocity_sigma_m_s: f64,
    pub rate_sigma_rad_s: f64,
}

/// Body-to-NED rotation R = Rz(psi) Ry(theta) Rx(phi) (eq. 4.5, upper-left block).
pub fn rotation(phi: f64, theta: f64, psi: f64) -> Matrix3<f64> {
    Rotation3::from_euler_angles(phi, theta, psi).into_inner()
}

/// Body rates to Euler-angle rates T(phi, theta) (eq. 4.5, lower-right block).
pub fn euler_rate_matrix(phi: f64, theta: f64) -> Matrix3<f64> {
    let (sf, cf) = phi.sin_cos();
    let (st, ct) = theta.sin_cos();
    let tt = st / ct;
    Matrix3::new(1.0, sf * tt, cf * tt, 0.0, cf, -sf, 0.0, sf / ct, cf / ct)
}

fn rx(a: f64) -> Matrix3<f64> {
    let (s, c) = a.sin_cos();
    Matrix3::new(1.0, 0.0, 0.0, 0.0, c, -s, 0.0, s, c)
}
fn ry(a: f64) -> Matrix3<f64> {
    let (s, c) = a.sin_cos();
    Matrix3::new(c, 0.0, s, 0.0, 1.0, 0.0, -s, 0.0, c)
}
fn rz(a: f64) -> Matrix3<f64> {
    let (s, c) = a.sin_cos();
    Matrix3::new(c, -s, 0.0, s, c, 0.0, 0.0, 0.0, 1.0)
}
fn drx(a: f64) -> Matrix3<f64> {
    let (s, c) = a.sin_cos();
    Matrix3::new(0.0, 0.0, 0.0, 0.0, -s, -c, 0.0, c, -s)
}
fn dry(a: f64) -> Matrix3<f64> {
    let (s, c) = a.sin_cos();
    Matrix3::new(-s, 0.0, c, 0.0, 0.0, 0.0, -c, 0.0, -s)
}
fn drz(a: f64) -> Matrix3<f64> {
    let (s, c) = a.sin_cos();
    Matrix3::new(-s, -c, 0.0, c, -s, 0.0, 0.0, 0.0, 0.0)
}

impl Kinematic6Dof {
    /// Noise-free kinematics (truth, Jacobian tests).
    pub fn new(nu: BodyVelocity) -> Self {
        Self { nu, velocity_sigma_m_s: 0.0, rate_sigma_rad_s: 0.0 }
    }

    /// The covariance of the body-velocity input, diag(u, v, w, p, q, r variances).
    pub fn input_covariance(&self) -> Cov {
        let (v2, w2) = (self.velocity_sigma_m_s.powi(2), self.rate_sigma_rad_s.powi(2));
        Cov::from_diagonal(&SVector::from([v2, v2, v2, w2, w2, w2]))
    }

    /// The input as the vehicle's sensors measure it: `nu` plus a draw of their noise
    /// (u, v, w, then p, q, r).
    pub fn sample_input<R: rand::Rng + ?Sized>(&self, rng: &mut R) -> BodyVelocity {
        let mut draw = |sigma: f64| crate::filter::gauss(rng, sigma);
        let (v, w) = (self.velocity_sigma_m_s, self.rate_sigma_rad_s);
        self.nu + SVector::from([draw(v), draw(v), draw(v), draw(w), draw(w), draw(w)])
    }

    fn split(&self) -> (Vector3<f64>, Vector3<f64>) {
        (self.nu.fixed_rows::<3>(0).into_owned(), self.nu.fixed_rows::<3>(3).into_owned())
    }

    /// The Jacobian with respect to the input, dt J(eta): maps body-velocity noise
    /// into state noise (eq. 3.2, second term).
    pub fn input_jacobian(&self, eta: &State, dt: f64) -> Cov {
        let mut g = Cov::zeros();
        g.fixed_view_mut::<3, 3>(0, 0).copy_from(&(rotation(eta[3], eta[4], eta[5]) * dt));
        g.fixed_view_mut::<3, 3>(3, 3).copy_from(&(euler_rate_matrix(eta[3], eta[4]) * dt));
        g
    }
}

impl ProcessModel<DIM> for Kinematic6Dof {
    /// G Q_nu G' with G = dt J(eta) (eq. 3.2, second term).
    fn noise_covariance(&self, eta: &State, dt: f64) -> Cov {
        let g = self.input_jacobian(eta, dt);
        g * self.input_covariance() * g.transpose()
    }

    fn is_angle(&self, i: usize) -> bool {
        i >= idx::ROLL
    }
    fn propagate(&self, eta: &State, dt: f64) -> State {
        let (lin, ang) = self.split();
        let (phi, theta, psi) = (eta[3], eta[4], eta[5]);
        let mut n = *eta;
        let dp = rotation(phi, theta, psi) * lin * dt; // eq. 4.4, A.3: position rows
        let da = euler_rate_matrix(phi, theta) * ang * dt; // eq. 4.4, A.3: attitude rows
        n.fixed_rows_mut::<3>(0).add_assign(&dp);
        n.fixed_rows_mut::<3>(3).add_assign(&da);
        n
    }

    fn jacobian(&self, eta: &State, dt: f64) -> Cov {
        let (lin, ang) = self.split();
        let (phi, theta, psi) = (eta[3], eta[4], eta[5]);
        let mut f = Cov::identity();
        // d(R v)/d(phi, theta, psi), R = Rz Ry Rx
        let d_phi = rz(psi) * ry(theta) * drx(phi) * lin;
        let d_theta = rz(psi) * dry(theta) * rx(phi) * lin;
        let d_psi = drz(psi) * ry(theta) * rx(phi) * lin;
        for i in 0..3 {
            f[(i, 3)] = dt * d_phi[i];
            f[(i, 4)] = dt * d_theta[i];
            f[(i, 5)] = dt * d_psi[i];
        }
        // d(T w)/d(phi, theta); T does not depend on psi
        let (sf, cf) = phi.sin_cos();
        let (st, ct) = theta.sin_cos();
        let (q, r) = (ang[1], ang[2]);
        let sec2 = 1.0 / (ct * ct);
        f[(3, 3)] += dt * (q * cf - r * sf) * st / ct;
        f[(3, 4)] += dt * (q * sf + r * cf) * sec2;
        f[(4, 3)] += dt * (-q * sf - r * cf);
        f[(5, 3)] += dt * (q * cf - r * sf) / ct;
        f[(5, 4)] += dt * (q * sf + r * cf) * st * sec2;
        f
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_abs_diff_eq;

    fn fd_columns(f: impl Fn(&State) -> State, x: &State) -> Cov {
        let mut j = Cov::zeros();
        for c in 0..DIM {
            let eps = 1e-6 * x[c].abs().max(1.0);
            let (mut a, mut b) = (*x, *x);
            a[c] += eps;
            b[c] -= eps;
            j.set_column(c, &((f(&a) - f(&b)) / (2.0 * eps)));
        }
        j
    }

    #[test]
    fn rotation_is_fossen_zyx() {
        // eq. 4.5, element by element, at a generic attitude
        let (phi, theta, psi) = (0.3_f64, -0.2_f64, 1.1_f64);
        let (c, s) = (f64::cos, f64::sin);
        let expected = Matrix3::new(
            c(psi) * c(theta),
            c(psi) * s(theta) * s(phi) - s(psi) * c(phi),
            s(psi) * s(phi) + c(psi) * c(phi) * s(theta),
            s(psi) * c(theta),
            c(psi) * c(phi) + s(phi) * s(theta) * s(psi),
            s(theta) * s(psi) * c(phi) - c(psi) * s(phi),
            -s(theta),
            c(theta) * s(phi),
            c(theta) * c(phi),
        );
        assert_abs_diff_eq!(rotation(phi, theta, psi), expected, epsilon = 1e-12);
    }

    #[test]
    fn jacobians_match_finite_differences() {
        let nu = BodyVelocity::from([1.2, -0.3, 0.2, 0.05, -0.08, 0.1]);
        let m = Kinematic6Dof::new(nu);
        let dt = 0.1;
        for eta in [State::from([5.0, -3.0, 20.0, 0.2, -0.3, 2.0]), State::from([0.0, 0.0, 1.0, -0.5, 0.6, -2.8])] {
            let f = m.jacobian(&eta, dt);
            let fd = fd_columns(|x| m.propagate(x, dt), &eta);
            assert_abs_diff_eq!(f, fd, epsilon = 1e-8);
            // and with respect to the input
            let g = m.input_jacobian(&eta, dt);
            let gd = fd_columns(|u| Kinematic6Dof::new(*u).propagate(&eta, dt), &nu);
            assert_abs_diff_eq!(g, gd, epsilon = 1e-8);
        }
    }

    #[test]
    fn level_turn_traces_a_circle() {
        // surge 1 m/s, yaw rate 0.1 rad/s: radius 10 m, back at the start after 2 pi / 0.1 s
        let m = Kinematic6Dof::new(BodyVelocity::from([1.0, 0.0, 0.0, 0.0, 0.0, 0.1]));
        let dt = 0.001;
        let mut eta = State::from([0.0, 0.0, 5.0, 0.0, 0.0, 0.0]);
        let steps = (2.0 * std::f64::consts::PI / 0.1 / dt).round() as usize;
        let mut max_east: f64 = 0.0;
        for _ in 0..steps {
            eta = m.propagate(&eta, dt);
            max_east = max_east.max(eta[idx::E]);
        }
        assert_abs_diff_eq!(eta[idx::N], 0.0, epsilon = 0.02);
        assert_abs_diff_eq!(eta[idx::E], 0.0, epsilon = 0.02);
        assert_abs_diff_eq!(max_east, 20.0, epsilon = 0.02);
        assert_abs_diff_eq!(eta[idx::D], 5.0, epsilon = 1e-12);
    }
}
