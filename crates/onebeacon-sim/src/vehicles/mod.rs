//! Truth vehicles: paths to follow, controllers, and the dynamics that move them.

pub mod asv;
pub mod autopilot;
pub mod ilos;
pub mod otter;
pub mod path;
pub mod remus100;
pub mod rigid_body;
pub mod rov;
pub mod sandshark;
pub mod unicycle;

pub use path::{Path, Reference};
pub use unicycle::{TruthState, feedback_linearising_control};
