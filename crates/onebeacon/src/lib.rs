//! onebeacon: the onboard part of single-beacon underwater navigation.
//!
//! What runs on a vehicle lives here, with the dependencies of its numbers (nalgebra,
//! rand and its distributions, rustfft and realfft for the receiver, statrs for one
//! quantile, thiserror; rayon, serde and serde_json behind features):
//!
//! - [`geo`]: NED frame conventions and angle wrapping;
//! - [`dsp`]: receiver signal processing: matched filter, beamforming, modes;
//! - [`models`]: process models used by the estimators;
//! - [`measure`]: measurement models `h(x)` with their Jacobians;
//! - [`filter`]: the Gaussian filters (EKF, UKF) behind one trait, the particle filters
//!   (hoff2024's, rypkema's factored one), the RTS pass, consistency statistics;
//! - [`guidance`]: where a surface vehicle should go next: sousa's beacon vehicle by
//!   Fisher information, hoff2024's listening vehicle by the spread of its bearings;
//! - [`nav`]: the navigator interface, measurement events, the papers' navigators and
//!   the onboard [`nav::session`] that a vehicle's computer runs;
//! - [`vehicle`]: the vehicle's own decisions: controllers that turn the navigators'
//!   beliefs into commands (hoff's planner, sousa's FIM guidance, rypkema's behaviours);
//! - [`config`]: what a vehicle's computer is configured with: estimators, controller,
//!   stream (feature `serde`);
//! - [`io`]: the files a user names, read one way ([`io::file`]), and the JSON Lines
//!   codec of the session (feature `stream`, adds serde_json);
//! - [`log`]: a log description (TOML) and its CSV files read into the session's items,
//!   and the computer `onebeacon stream` sets up from one (feature `log`, adds toml,
//!   csv, chrono for clock times, map_3d for latitudes and longitudes).
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
#[cfg(feature = "log")]
pub mod log;
pub mod measure;
pub mod models;
pub mod nav;
pub mod optim;
mod par;
pub mod vehicle;
