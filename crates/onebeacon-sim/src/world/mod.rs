//! The worlds the [engine](crate::engine) runs: each moves its truth and says who heard
//! what, when; nothing else.

mod fixed_beacon;
mod moving_beacon;
mod passive_usbl;

pub(crate) use fixed_beacon::FixedBeaconWorld;
pub(crate) use moving_beacon::{MovingBeaconWorld, RangeInformation};
pub use moving_beacon::{TruthPath, initial_asv_position};
pub(crate) use passive_usbl::{BearingInformation, PassiveUsblWorld};
