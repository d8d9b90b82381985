//! Measurement models: h(x), its Jacobian, whether it is an angle, and its noise.
//!
//! A model owns its noise: the filter reads R from it and the simulator draws the
//! measurement from it ([`ScalarModel::sample`]), so no noise formula is written twice.
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
    /// The noise variance of a measurement taken at `x`.
    fn variance(&self, x: &SVector<f64, N>) -> f64;
    /// A draw of the measurement noise at `x`: sqrt(variance) times a standard normal.
    fn noise(&self, x: &SVector<f64, N>, rng: &mut dyn rand::Rng) -> f64 {
        self.variance(x).sqrt() * rand::RngExt::sample::<f64, _>(rng, rand_distr::StandardNormal)
    }
    /// A noisy measurement at `x`: h(x) plus [`ScalarModel::noise`].
    fn sample(&self, x: &SVector<f64, N>, rng: &mut dyn rand::Rng) -> f64 {
        self.predict(x) + self.noise(x, rng)
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
    /// Independent components: R = diag of their variances.
    fn covariance(&self, x: &SVector<f64, N>) -> SMatrix<f64, M, M> {
        SMatrix::from_diagonal(&SVector::from_fn(|i, _| self[i].variance(x)))
    }
    fn sample(&self, x: &SVector<f64, N>, rng: &mut dyn rand::Rng) -> SVector<f64, M> {
        SVector::from_fn(|i, _| self[i].sample(x, rng))
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
