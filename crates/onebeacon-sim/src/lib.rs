//! onebeacon-sim: the world around the onboard library.
//!
//! - [`vehicles`]: truth dynamics, paths and their controllers;
//! - [`sensors`]: what the vehicle's sensors and modem report, with their errors;
//! - [`acoustics`]: pings propagating between moving ends;
//! - [`chain`]: the receiver chain on recorded captures, as a ping configuration sets it;
//! - [`pcrb`]: the posterior Cramer-Rao bound of the range-only moving-beacon case;
//! - [`scenario`]: the TOML scenario schema, its validation and the built-in scenarios;
//! - [`engine`](crate::engine): the one simulation loop, its worlds and its observers;
//! - `factory`: every estimator spec to its navigator, the one place that builds them;
//! - `helms`: each scenario's onboard controllers (the vehicles' decisions are the
//!   onboard crate's [`onebeacon::vehicle`]; the worlds move the truth under them);
//! - [`run`]: one simulated run, a pure function of (scenario, sweep cell, seed, run);
//! - [`metrics`]: per-run error statistics and their Monte Carlo aggregation;
//! - [`montecarlo`]: many runs over a sweep, in parallel, independent of thread count;
//! - [`partial`]: one share of a sharded sweep as a file, and the merge of the shares;
//! - [`json`]: the JSON forms of results, for the CLI and the Python package;
//! - [`input_file`]: the one bounded reader of the files a user names;
//! - [`replay`]: real logs (CSV files described by a TOML file) through the estimators.

pub mod acoustics;
pub mod budget;
pub mod chain;
mod engine;
mod factory;
pub mod fleet;
mod helms;
mod information;
pub mod input_file;
pub mod json;
pub mod messages;
pub mod metrics;
pub mod montecarlo;
pub mod partial;
pub mod pcrb;
pub mod replay;
pub mod run;
pub mod scenario;
pub mod seed;
pub mod sensor_errors;
pub mod sensors;
pub mod smooth;
pub mod vehicles;
pub mod water;
mod world;

pub use scenario::{Scenario, ScenarioError};
