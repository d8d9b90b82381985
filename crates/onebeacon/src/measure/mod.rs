//! Measurement models: h(x), its Jacobian, and whether it is an angle.
//!
//! Each physical measurement is a [`ScalarModel`]; a filter update stacks any number of
//! them into one vector measurement (an array `[&dyn ScalarModel<N>; M]` is a
//! [`MeasurementModel`]), as garin2024 eq. 18 and 20 stack range, Doppler speed, heading,
//! yaw rate and acceleration when a communication frame arrives.
//!
//! States put the NED position first; the Doppler model also reads the heading and
//! forward speed of [`crate::models::unicycle`].

pub mod doppler;
pub mod range;
pub mod state;

pub use doppler::RadialSpeed2d;
pub use range::{Range2d, Range3d, SlantRange};
pub use state::StateComponent;

use crate::filter::MeasurementModel;
use nalgebra::{SMatrix, SVector};

/// One scalar measurement z = h(x) + v.
pub trait ScalarModel<const N: usize> {
    /// The predicted measurement h(x).
    fn predict(&self, x: &SVector<f64, N>) -> f64;
    /// The Jacobian dh/dx at `x`, a row.
    fn jacobian(&self, x: &SVector<f64, N>) -> SMatrix<f64, 1, N>;
    /// Whether the measurement is an angle (innovation wrapped to (-pi, pi]).
    fn is_angle(&self) -> bool {
        false
    }
}

impl<const N: usize, const M: usize> MeasurementModel<N, M> for [&dyn ScalarModel<N>; M] {
    fn predict(&self, x: &SVector<f64, N>) -> SVector<f64, M> {
        SVector::from_fn(|i, _| self[i].predict(x))
    }
    fn jacobian(&self, x: &SVector<f64, N>) -> SMatrix<f64, M, N> {
        let mut h = SMatrix::<f64, M, N>::zeros();
        for (i, m) in self.iter().enumerate() {
            h.set_row(i, &m.jacobian(x));
        }
        h
    }
    fn is_angle(&self, i: usize) -> bool {
        self[i].is_angle()
    }
}

/// Central finite-difference Jacobian of a scalar model, for tests.
#[cfg(test)]
pub(crate) fn finite_difference<const N: usize>(m: &dyn ScalarModel<N>, x: &SVector<f64, N>) -> SMatrix<f64, 1, N> {
    SMatrix::from_fn(|_, j| {
        let eps = 1e-6 * x[j].abs().max(1.0);
        let mut xp = *x;
        let mut xm = *x;
        xp[j] += eps;
        xm[j] -= eps;
        (m.predict(&xp) - m.predict(&xm)) / (2.0 * eps)
    })
}
