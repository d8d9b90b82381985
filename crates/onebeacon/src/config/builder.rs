//! From an estimator spec to its navigator on a log or a stream (replay, `stream`, the
//! Python `Navigator`): a USBL tracker, the iUSBL navigator or the planar family. The
//! simulator's worlds build theirs in its factory, on their own process models.

use super::estimator::{EstimatorKind, EstimatorSpec};
use crate::models::hoff::DIM;
use crate::nav::restart::Builder;
use crate::nav::{GaussianTracker, IusblNavigator, ParticleTracker, TrackerNoise};
use nalgebra::SVector;

/// What a log's or a stream's USBL tracker starts from besides its pose (hoff2024's
/// state order): depth, pitch, speed and the two rate biases (m, rad, m/s, rad/s), the
/// standard deviations of depth, pitch, speed and biases, and the seed of the vehicle's
/// particle filters.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TrackerStart {
    pub state: [f64; 5],
    pub sigma: [f64; 4],
    pub seed: Option<i64>,
}

impl EstimatorSpec {
    /// The estimator on a log or a stream, on a vehicle whose trackers start as `start`
    /// says, built by the session at its start and again from its last sound pose: a USBL
    /// tracker (pf, bearing: hoff2024's eight states), the iUSBL navigator (which starts
    /// from its first fix), or the planar family.
    pub fn builder(&self, start: TrackerStart) -> Builder {
        // the seed's 64 bits (TOML integers are signed)
        let seed = self.seed.or(start.seed).unwrap_or(0) as u64;
        if self.kind.tracks_bearings() {
            let config = self.tracker_config(TrackerNoise::default());
            let (particles, settings) = self.particle_settings();
            let filter = self.filter_kind();
            let particle = self.kind == EstimatorKind::Particle;
            let ([depth, pitch, speed, pitch_bias, heading_bias], [s_depth, s_pitch, s_speed, s_bias]) =
                (start.state, start.sigma);
            return Box::new(move |t0, (north, east, heading), sigma_position, sigma_heading| {
                let x0 =
                    SVector::<f64, DIM>::from([north, east, depth, pitch, heading, speed, pitch_bias, heading_bias]);
                let sigma0 = SVector::<f64, DIM>::from([
                    sigma_position,
                    sigma_position,
                    s_depth,
                    s_pitch,
                    sigma_heading,
                    s_speed,
                    s_bias,
                    s_bias,
                ]);
                if particle {
                    Box::new(ParticleTracker::new(config, settings, particles, t0, &x0, &sigma0, seed))
                } else {
                    Box::new(GaussianTracker::new(config, filter, t0, &x0, &sigma0))
                }
            });
        }
        if self.kind.iusbl() {
            let config = self.iusbl.clone().unwrap_or_default().config(self.kind == EstimatorKind::Iusbl);
            return Box::new(move |_, _, _, _| Box::new(IusblNavigator::new(config, None, seed)));
        }
        crate::nav::planar::builder(self.planar_config(), self.filter_kind())
    }
}
