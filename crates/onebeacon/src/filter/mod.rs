//! Estimators: the extended and unscented Kalman filters behind one interface, the
//! particle filters, the Rauch-Tung-Striebel pass, and consistency statistics.
//!
//! [`GaussianFilter`] is what a navigator asks of a filter: predict through a
//! [`ProcessModel`], update with a [`MeasurementModel`] (gated by the NIS), and read or
//! adjust the mean and covariance. The navigators in [`crate::nav`] are written once
//! against it, so [`Ekf`] and [`Ukf`] run in every one of them. Beside them:
//! [`particle`] (hoff2024's filter, generic over its models, with [`truncated`] draws and
//! single-precision [`lanes`]), [`factored`] (rypkema's factored filter), [`rts`] (the
//! backward pass over a Gaussian filter's run) and [`consistency`] (NEES).

pub mod consistency;
pub mod ekf;
pub mod factored;
pub mod lanes;
pub mod particle;
mod resample;
pub mod rts;
pub mod truncated;
pub mod ukf;

pub use ekf::{Ekf, FilterError, Gated, Innovation, MeasurementModel, ProcessModel};
pub use ukf::{Ukf, UkfParams};

use nalgebra::{SMatrix, SVector};
use rand::{Rng, RngExt};

/// A zero-mean Gaussian draw of standard deviation `sigma` (every noise draw of the
/// models and of the simulated world).
pub fn gauss<R: Rng + ?Sized>(rng: &mut R, sigma: f64) -> f64 {
    sigma * rng.sample::<f64, _>(rand_distr::StandardNormal)
}

/// A filter whose belief is a mean and a covariance (EKF, UKF).
pub trait GaussianFilter<const N: usize> {
    fn mean(&self) -> &SVector<f64, N>;
    fn covariance(&self) -> &SMatrix<f64, N, N>;
    fn mean_mut(&mut self) -> &mut SVector<f64, N>;
    fn covariance_mut(&mut self) -> &mut SMatrix<f64, N, N>;
    /// Prediction over `dt` seconds through `model`, with additive process noise `q`.
    fn predict<P: ProcessModel<N>>(&mut self, model: &P, dt: f64, q: &SMatrix<f64, N, N>);
    /// [`GaussianFilter::predict`], returning the cross covariance of the state before
    /// and after it, what a Rauch-Tung-Striebel pass needs ([`rts`]).
    fn predict_cross<P: ProcessModel<N>>(&mut self, model: &P, dt: f64, q: &SMatrix<f64, N, N>) -> SMatrix<f64, N, N>;
    /// Update with measurement `z` of noise covariance `r`; a measurement whose NIS
    /// exceeds `max_nis` is rejected and leaves the state untouched, as does an error.
    fn update_gated<const M: usize, H: MeasurementModel<N, M>>(
        &mut self,
        model: &H,
        z: &SVector<f64, M>,
        r: &SMatrix<f64, M, M>,
        max_nis: f64,
    ) -> Result<Gated, FilterError>;
}

/// Which filter a navigator runs, with its parameters.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub enum FilterKind {
    /// The extended Kalman filter (Joseph-form update).
    #[default]
    Ekf,
    /// The unscented Kalman filter with Merwe's sigma points.
    Ukf(UkfParams),
}

/// The filter a navigator runs, chosen at run time ([`FilterKind`]).
#[derive(Debug, Clone, PartialEq)]
pub enum AnyFilter<const N: usize> {
    Ekf(Ekf<N>),
    Ukf(Ukf<N>),
}

impl<const N: usize> AnyFilter<N> {
    /// A filter of `kind` starting at mean `x` with covariance `p`.
    pub fn new(kind: FilterKind, x: SVector<f64, N>, p: SMatrix<f64, N, N>) -> Self {
        match kind {
            FilterKind::Ekf => AnyFilter::Ekf(Ekf::new(x, p)),
            FilterKind::Ukf(params) => AnyFilter::Ukf(Ukf::new(x, p, params)),
        }
    }
}

impl<const N: usize> GaussianFilter<N> for AnyFilter<N> {
    fn mean(&self) -> &SVector<f64, N> {
        match self {
            AnyFilter::Ekf(f) => &f.x,
            AnyFilter::Ukf(f) => &f.x,
        }
    }
    fn covariance(&self) -> &SMatrix<f64, N, N> {
        match self {
            AnyFilter::Ekf(f) => &f.p,
            AnyFilter::Ukf(f) => &f.p,
        }
    }
    fn mean_mut(&mut self) -> &mut SVector<f64, N> {
        match self {
            AnyFilter::Ekf(f) => &mut f.x,
            AnyFilter::Ukf(f) => &mut f.x,
        }
    }
    fn covariance_mut(&mut self) -> &mut SMatrix<f64, N, N> {
        match self {
            AnyFilter::Ekf(f) => &mut f.p,
            AnyFilter::Ukf(f) => &mut f.p,
        }
    }
    fn predict<P: ProcessModel<N>>(&mut self, model: &P, dt: f64, q: &SMatrix<f64, N, N>) {
        match self {
            AnyFilter::Ekf(f) => f.predict(model, dt, q),
            AnyFilter::Ukf(f) => f.predict(model, dt, q),
        }
    }
    fn predict_cross<P: ProcessModel<N>>(&mut self, model: &P, dt: f64, q: &SMatrix<f64, N, N>) -> SMatrix<f64, N, N> {
        match self {
            AnyFilter::Ekf(f) => f.predict_cross(model, dt, q),
            AnyFilter::Ukf(f) => f.predict_cross(model, dt, q),
        }
    }
    fn update_gated<const M: usize, H: MeasurementModel<N, M>>(
        &mut self,
        model: &H,
        z: &SVector<f64, M>,
        r: &SMatrix<f64, M, M>,
        max_nis: f64,
    ) -> Result<Gated, FilterError> {
        match self {
            AnyFilter::Ekf(f) => f.update_gated(model, z, r, max_nis),
            AnyFilter::Ukf(f) => f.update_gated(model, z, r, max_nis),
        }
    }
}
