//! Process models used by the estimators.

pub mod hoff;
pub mod kinematic6dof;
pub mod unicycle;

pub use kinematic6dof::Kinematic6Dof;
pub use unicycle::UnicycleAccel;
