//! From an estimator spec to its navigator on a log or a stream (replay, `stream`, the
//! Python `Navigator`): a USBL tracker, the iUSBL navigator or the planar family. The
//! simulator's passive-USBL worlds build their trackers here too; its other worlds
//! build theirs in its factory, on their own process models.

use super::estimator::{EstimatorKind, EstimatorSpec};
use crate::models::hoff::{DIM, idx};
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
            let [depth, pitch, speed, pitch_bias, heading_bias] = start.state;
            let [s_depth, s_pitch, s_speed, s_bias] = start.sigma;
            // the pose and its sigmas are the builder's arguments
            let x0 = SVector::<f64, DIM>::from([0.0, 0.0, depth, pitch, 0.0, speed, pitch_bias, heading_bias]);
            let sigma0 = SVector::<f64, DIM>::from([0.0, 0.0, s_depth, s_pitch, 0.0, s_speed, s_bias, s_bias]);
            return self.tracker_builder(TrackerNoise::default(), x0, sigma0, seed);
        }
        if self.kind.iusbl() {
            let config = self.iusbl.clone().unwrap_or_default().config(self.kind == EstimatorKind::Iusbl);
            return Box::new(move |_, _, _, _| Box::new(IusblNavigator::new(config, None, seed)));
        }
        crate::nav::planar::builder(self.planar_config(), self.filter_kind())
    }

    /// A USBL tracker (kinds pf and bearing: hoff2024's eight states) assuming `noise`
    /// where the spec sets none, starting from `x0` with standard deviations `sigma0`,
    /// their pose (north, east, heading) and its sigmas the builder's arguments; `seed`
    /// seeds a particle filter. Logs, streams and the passive-USBL worlds build theirs
    /// here.
    pub fn tracker_builder(
        &self,
        noise: TrackerNoise,
        x0: SVector<f64, DIM>,
        sigma0: SVector<f64, DIM>,
        seed: u64,
    ) -> Builder {
        let (config, filter) = (self.tracker_config(noise), self.filter_kind());
        let particle = (self.kind == EstimatorKind::Particle).then(|| self.particle_settings());
        Box::new(move |t0, (north, east, heading), sigma_position, sigma_heading| {
            let (mut x, mut sigma) = (x0, sigma0);
            (x[idx::X], x[idx::Y], x[idx::PSI]) = (north, east, heading);
            (sigma[idx::X], sigma[idx::Y], sigma[idx::PSI]) = (sigma_position, sigma_position, sigma_heading);
            match particle {
                Some((n, settings)) => Box::new(ParticleTracker::new(config, settings, n, t0, &x, &sigma, seed)),
                None => Box::new(GaussianTracker::new(config, filter, t0, &x, &sigma)),
            }
        })
    }
}
