//! What a vehicle's computer holds in memory, bytes: the upper bounds the memory budget
//! (onebeacon_sim::budget) checks before any filter is built.

use super::controller::ControllerSpec;
use super::estimator::{EstimatorKind, EstimatorSpec, IusblKeys};
use super::stream::StreamConfig;

/// The bytes a particle filter of `n` particles of `d` states holds at most: two copies
/// of its states in single precision (the spare one for resampling), the log-weights and
/// the last update's increments (single), and in double the normalised weights (the
/// cumulative ones in their place), multinomial resampling's sorted draws and the
/// ancestors. Measured: the `stream` of hoff2024's surface vehicle with 2e6 particles
/// peaked at 0.165 GiB resident against 0.179 GiB estimated (onebeacon-cli's test
/// `the_streams_memory_estimate_bounds_its_peak`).
pub fn particle_filter_bytes(n: usize, d: usize) -> f64 {
    n as f64 * (2.0 * 4.0 * d as f64 + 4.0 + 4.0 + 3.0 * 8.0)
}

/// What a Gaussian filter and its navigator hold, bytes: an upper bound for every
/// filter of a few dozen states.
const GAUSSIAN_BYTES: f64 = 1e5;

impl EstimatorSpec {
    /// An upper bound of the bytes this estimator holds for one vehicle: its particles
    /// ([`particle_filter_bytes`]; the iUSBL navigator's factored cloud of 4 double-
    /// precision values a particle, counted as 8 single-precision states), else a
    /// Gaussian filter's.
    pub fn working_set_bytes(&self) -> f64 {
        match self.kind {
            EstimatorKind::Particle => particle_filter_bytes(self.particle_settings().0, crate::models::hoff::DIM),
            EstimatorKind::Iusbl | EstimatorKind::IusblJoint => particle_filter_bytes(
                self.iusbl.as_ref().map_or_else(|| IusblKeys::default().particles, |k| k.particles),
                8,
            ),
            _ => GAUSSIAN_BYTES,
        }
    }
}

impl StreamConfig {
    /// An upper bound of the bytes the vehicle's computer holds: each estimator's
    /// ([`EstimatorSpec::working_set_bytes`]) for each vehicle it estimates (its own, or
    /// each of `[[tracked]]`), and a bearing planner's subsample of 3-d positions per
    /// vehicle and candidate; the bounded logs besides (limits.max_rejections is 0 in a
    /// stream).
    pub fn working_set_bytes(&self) -> f64 {
        let vehicles = self.tracked.len().max(1) as f64;
        let estimators: f64 = self.estimators.iter().map(EstimatorSpec::working_set_bytes).sum();
        let planner = match &self.controller {
            Some(ControllerSpec::Bearing(b)) => 4.0 * 24.0 * b.planner_particles as f64,
            _ => 0.0,
        };
        vehicles * (estimators + planner)
    }
}
