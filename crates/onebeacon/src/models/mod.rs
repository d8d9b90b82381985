//! Process models used by the estimators.

pub mod unicycle;

pub use unicycle::UnicycleAccel;
