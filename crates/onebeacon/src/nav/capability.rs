//! What some navigators can do beyond processing measurements and giving their estimate,
//! as small traits a navigator hands out through one accessor each on
//! [`super::Navigator`] (None where it cannot): a controller's inputs
//! ([`BeaconRelative`], [`BodyVelocity`], [`ParticleBelief`]), a held-out beacon's
//! prediction ([`Weighing`]), per-beacon offsets ([`BeaconOffsets`]), a smoothing pass
//! ([`Smoothing`]) and a factored filter's sets ([`FactoredBelief`]). A controller that
//! needs one names it ([`Capability`]), and a configuration that gives it a navigator
//! without it is refused when it is read (`onebeacon::config::stream::StreamConfig::check`).

use super::{Estimate, Innovation, Measurement};
use crate::filter::factored::FactoredSets;
use nalgebra::Vector3;

/// rypkema's iUSBL navigator (sec. 4.1-4.2): where the vehicle is relative to the beacon
/// it navigates on, and the command mode the beacon's pings confirmed.
pub trait BeaconRelative {
    /// NED, m (depth as measured).
    fn beacon_relative_ned_m(&self) -> Vector3<f64>;
    /// The mode confirmed last, if any.
    fn command_mode(&self) -> Option<usize>;
}

/// sousa's 6-DOF filter (sec. 3.2): the body-frame linear velocity (u, v, w) it last
/// dead-reckoned on, m/s, for a beacon vehicle predicting where the vehicle will be.
pub trait BodyVelocity {
    fn body_velocity_m_s(&self) -> Vector3<f64>;
}

/// hoff2024's and rypkema's particle filters: equally weighted samples of the position
/// belief, for a planner that scores a belief by its spread (hoff2024 sec. 4; a Gaussian
/// belief has none, and the planner samples its mean and covariance).
pub trait ParticleBelief {
    /// Up to `m` samples (NED, m), drawn in proportion to the particles' weights.
    fn position_sample(&self, m: usize) -> Vec<Vector3<f64>>;
}

/// The Gaussian range navigators: the innovation a range would have, without taking it
/// (the navigator moved to its time first, as any measurement moves it), which is how a
/// beacon held out of a run is predicted.
pub trait Weighing {
    /// None for a measurement other than a range.
    fn weigh(&mut self, m: &Measurement) -> Option<Innovation>;
}

/// The planar navigator with an offset state per beacon: each beacon heard with its
/// estimated range offset and its standard deviation (beacon, m, m).
pub trait BeaconOffsets {
    fn offsets(&self) -> Vec<(u32, f64, f64)>;
}

/// The Gaussian planar family with beacon aiding: a Rauch-Tung-Striebel pass over its run.
pub trait Smoothing {
    /// Keeps, from now on, what the pass needs (memory grows with the run: for a log, not
    /// a stream).
    fn keep_history(&mut self);
    /// The smoothed estimates of the run kept since [`Smoothing::keep_history`]: one per
    /// interval between predictions, each holding from its time `t_s` on, in time order.
    fn smoothed(&self) -> Vec<Estimate>;
}

/// rypkema's factored particle filter (sec. 4.2): the range and angle sets of its last
/// update.
pub trait FactoredBelief {
    fn factored_sets(&self) -> &FactoredSets;
}

/// A capability a controller needs of the navigator it reads.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Capability {
    BeaconRelative,
    BodyVelocity,
}

impl Capability {
    /// What it is, in an error message.
    pub fn label(self) -> &'static str {
        match self {
            Capability::BeaconRelative => "the position relative to the beacon and the confirmed command mode",
            Capability::BodyVelocity => "the body velocity",
        }
    }
}
