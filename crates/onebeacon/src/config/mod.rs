//! What a vehicle's computer is configured with (feature `serde`): the
//! `[[estimators]]` vocabulary shared by scenarios, logs and streams ([`estimator`], its
//! tuning keys grouped by what they tune, the iUSBL navigator's table in [`iusbl`], its
//! checks beside it and each spec's navigator on a log or a stream), the `[controller]`
//! table ([`controller`]), the stream configuration that puts them together into a
//! [`crate::vehicle::unit::Unit`] ([`stream`]), what it holds in memory
//! ([`working_set`]), and the rules a key obeys with the one-line error that names it
//! ([`check`]). A vehicle reads its configuration with this crate alone; the simulator
//! reads its scenarios and logs into the same types.

pub mod builder;
pub mod check;
pub mod controller;
pub mod estimator;
mod estimator_check;
mod estimator_defaults;
mod estimator_keys;
mod estimator_read;
pub mod iusbl;
pub mod stream;
#[cfg(feature = "log")]
pub mod toml_file;
pub mod working_set;

pub use estimator_check::check_estimators;
