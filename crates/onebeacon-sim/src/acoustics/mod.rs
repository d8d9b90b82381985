//! The acoustic world: pings propagating between moving ends, the clocks that time them,
//! and the signal-level channel from a transducer to the elements of a receiving array;
//! multichannel WAV recordings read a capture at a time. The truth of sound, configured by no scenario type
//! (the receiver chain that processes recordings is [`crate::chain`]).

pub mod beacon_ranges;
pub mod channel;
pub mod clock;
pub mod link;
pub mod profile;
pub mod propagation;
pub mod usbl_head;
pub mod wav;

pub use propagation::Ping;
