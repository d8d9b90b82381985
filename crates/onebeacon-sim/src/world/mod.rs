//! The worlds the [engine](crate::engine) runs: each moves its truth and says who heard
//! what, when; nothing else.

mod fixed_beacon;
mod fleet;
mod moving_beacon;
mod passive_usbl;

pub(crate) use fixed_beacon::FixedBeaconWorld;
pub(crate) use fleet::FleetWorld;
pub(crate) use moving_beacon::MovingBeaconWorld;
pub use moving_beacon::TruthPath;
pub(crate) use passive_usbl::PassiveUsblWorld;
