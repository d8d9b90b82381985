//! onebeacon: the onboard part of single-beacon underwater navigation.
//!
//! What runs on a vehicle lives here, with lean dependencies (nalgebra, thiserror):
//!
//! - [`geo`]: NED frame conventions and angle wrapping;
//! - [`dsp`]: receiver signal processing: matched filter, beamforming, modes;
//! - [`models`]: process models used by the estimators;
//! - [`measure`]: measurement models `h(x)` with their Jacobians;
//! - [`filter`]: the Gaussian filters (EKF, UKF) behind one trait, consistency statistics;
//! - [`guidance`]: where a beacon vehicle should go next (Fisher information);
//! - [`nav`]: the navigator interface, measurement events, the papers' navigators and
//!   the onboard [`nav::session`] that a vehicle's computer runs;
//! - [`vehicle`]: the vehicle's own decisions: controllers that turn the navigators'
//!   beliefs into commands (hoff's planner, sousa's FIM guidance, rypkema's behaviours);
//! - [`config`]: what a vehicle's computer is configured with: estimators, controller,
//!   stream (feature `serde`);
//! - [`io`]: the JSON Lines codec of the session (feature `stream`, adds serde_json).
//!
//! Conventions: NED frame (x north, y east, z down), SI units, radians, heading from
//! north toward east. Equation numbers in comments refer to the source papers.

#[cfg(feature = "serde")]
pub mod config;
pub mod dsp;
pub mod filter;
pub mod geo;
pub mod guidance;
pub mod io;
pub mod measure;
pub mod models;
pub mod nav;
pub mod optim;
mod par;
pub mod vehicle;
