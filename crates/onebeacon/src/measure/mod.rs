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
//! forward speed of [`crate::models::unicycle`]; [`hoff`] holds the particle likelihoods
//! of [`crate::models::hoff`].

pub mod doppler;
pub mod hoff;
pub mod range;
pub mod robust;
pub mod state;
pub mod usbl;

pub use doppler::{LineOfSightSpeed, RadialSpeed2d};
pub use range::{Range2d, Range3d, SlantRange};
pub use robust::Robust;
pub use state::StateComponent;
pub use usbl::{Usbl, UsblAngle, UsblModel};

use crate::filter::{MeasurementModel, gauss};
use nalgebra::{SMatrix, SVector};
use rand::Rng;

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
    /// The state component measured when the Jacobian is the unit row e_k at every x (a
    /// state measured directly); the filter then picks that component instead of
    /// multiplying by the row, to the same bits.
    fn unit_row(&self) -> Option<usize> {
        None
    }
    /// A draw of the measurement noise at `x`: sqrt(variance) times a standard normal.
    fn noise<R: Rng + ?Sized>(&self, x: &SVector<f64, N>, rng: &mut R) -> f64
    where
        Self: Sized,
    {
        gauss(rng, self.variance(x).sqrt())
    }
    /// A noisy measurement at `x`: h(x) plus [`ScalarModel::noise`].
    fn sample<R: Rng + ?Sized>(&self, x: &SVector<f64, N>, rng: &mut R) -> f64
    where
        Self: Sized,
    {
        self.predict(x) + self.noise(x, rng)
    }
}

/// A reference to a scalar model is that model (so `[&dyn ScalarModel<N>; M]` stacks
/// models of different kinds).
impl<const N: usize, T: ScalarModel<N> + ?Sized> ScalarModel<N> for &T {
    fn predict(&self, x: &SVector<f64, N>) -> f64 {
        (**self).predict(x)
    }
    fn jacobian(&self, x: &SVector<f64, N>) -> SMatrix<f64, 1, N> {
        (**self).jacobian(x)
    }
    fn is_angle(&self) -> bool {
        (**self).is_angle()
    }
    fn variance(&self, x: &SVector<f64, N>) -> f64 {
        (**self).variance(x)
    }
    fn unit_row(&self) -> Option<usize> {
        (**self).unit_row()
    }
}

/// Scalar models stacked into one vector measurement with independent components: h(x)
/// and the Jacobian row by row, R = diag of their variances. Models of one kind by value
/// (`[StateComponent; 3]`) are dispatched statically; `[&dyn ScalarModel<N>; M]` mixes
/// kinds (a range with heading and rates).
impl<const N: usize, const M: usize, T: ScalarModel<N>> MeasurementModel<N, M> for [T; M] {
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
    fn unit_row(&self, i: usize) -> Option<usize> {
        self[i].unit_row()
    }
    fn covariance(&self, x: &SVector<f64, N>) -> SMatrix<f64, M, M> {
        SMatrix::from_diagonal(&SVector::from_fn(|i, _| self[i].variance(x)))
    }
    fn sample<R: Rng + ?Sized>(&self, x: &SVector<f64, N>, rng: &mut R) -> SVector<f64, M> {
        SVector::from_fn(|i, _| self[i].predict(x) + gauss(rng, self[i].variance(x).sqrt()))
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

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::{Vector3, Vector6};
    use rand::SeedableRng;

    /// Measurements drawn from a model have the covariance the filter reads from the
    /// same model: a slant range with a beacon position error (its variance depends on
    /// the geometry) stacked with a heading, 40 000 draws. The sample variances are
    /// within 4 standard errors (sqrt(2 / n) = 0.7 %) of R, the correlation within 4 /
    /// sqrt(n), and the means within 4 standard errors of h(x).
    #[test]
    fn samples_have_the_covariance_the_filter_reads() {
        let range = Range3d { beacon: Vector3::new(30.0, -40.0, 0.0), sigma_m: 0.8, beacon_sigma_m: 1.5 };
        let heading = StateComponent::angle(5, 0.02f64.powi(2));
        let models: [&dyn ScalarModel<6>; 2] = [&range, &heading];
        let x = Vector6::new(0.0, 0.0, 20.0, 0.0, 0.0, 1.0);
        let r = models.covariance(&x);
        let h = models.predict(&x);
        // the range variance grew by the beacon error's horizontal projection
        assert!(r[(0, 0)] > 0.8f64.powi(2) + 1.0);
        let mut rng = rand_pcg::Pcg64Mcg::seed_from_u64(42);
        let n = 40_000;
        let draws: Vec<SVector<f64, 2>> = (0..n).map(|_| models.sample(&x, &mut rng)).collect();
        let mean = draws.iter().sum::<SVector<f64, 2>>() / n as f64;
        let cov =
            draws.iter().map(|d| (d - mean) * (d - mean).transpose()).sum::<SMatrix<f64, 2, 2>>() / (n - 1) as f64;
        let se = (2.0 / n as f64).sqrt();
        for i in 0..2 {
            assert!((cov[(i, i)] / r[(i, i)] - 1.0).abs() < 4.0 * se, "{i}: {} vs {}", cov[(i, i)], r[(i, i)]);
            assert!((mean[i] - h[i]).abs() < 4.0 * (r[(i, i)] / n as f64).sqrt());
        }
        let corr = cov[(0, 1)] / (cov[(0, 0)] * cov[(1, 1)]).sqrt();
        assert!(corr.abs() < 4.0 / (n as f64).sqrt(), "correlation {corr}");
    }
}
