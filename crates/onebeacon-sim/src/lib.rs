//! onebeacon-sim: the world around the onboard library.
//!
//! - [`vehicles`]: truth dynamics, paths and their controllers;
//! - [`sensors`]: what the vehicle's sensors and modem report, with their errors;
//! - [`acoustics`]: pings propagating between moving ends;
//! - [`chain`]: the receiver chain on recorded captures, as a ping configuration sets it;
//! - [`pcrb`]: the posterior Cramer-Rao bound of the range-only moving-beacon case;
//! - [`scenario`]: the TOML scenario schema, its validation and the built-in scenarios;
//! - [`engine`](crate::engine): the one simulation loop, its worlds and its observers;
//! - `computers`: each vehicle's computer in a world as the stream configuration a
//!   vehicle reads, the one description the engine's tracks and helms and
//!   `run --messages` come from (the vehicles' decisions are the onboard crate's
//!   [`onebeacon::vehicle`]; the worlds move the truth under them);
//! - `factory`: where each vehicle's estimators start in a run, and the navigators no
//!   stream configuration describes (garin2024's fixed-beacon filters, a receiver);
//! - [`run`]: one simulated run, a pure function of (scenario, sweep cell, seed, run);
//! - [`metrics`]: per-run error statistics and their Monte Carlo aggregation;
//! - [`montecarlo`]: many runs over a sweep, in parallel, independent of thread count;
//! - [`partial`]: one share of a sharded sweep as a file, and the merge of the shares;
//! - [`json`]: the JSON forms of results, for the CLI and the Python package;
//! - [`replay`]: real logs (CSV files described by a TOML file) through the estimators.

pub mod acoustics;
pub mod budget;
pub mod chain;
mod computers;
mod engine;
mod factory;
pub mod fleet;
mod information;
pub mod json;
pub mod messages;
pub mod metrics;
pub mod montecarlo;
pub mod partial;
pub mod pcrb;
pub mod replay;
pub mod run;
pub mod scenario;
pub mod seafit;
pub mod seed;
pub mod sensor_errors;
pub mod sensors;
pub mod smooth;
pub mod twin;
pub mod vehicles;
pub mod water;
mod world;

pub use scenario::{Scenario, ScenarioError};
