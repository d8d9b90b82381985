//! The acoustic world: pings propagating between moving ends, and the signal-level
//! channel from a transducer to the elements of a receiving array.

pub mod channel;
pub mod propagation;

pub use propagation::Ping;
