//! Scenario files: schema, defaults, loading, validation and the built-in scenarios.
//!
//! A scenario is a TOML file; every key is optional except `name` and has a documented
//! default (see the built-in `scenarios/garin2024.toml`, which spells every key out with
//! where its value comes from). Keys carry their unit in their name; angles in config
//! are degrees (`*_deg`), radians inside.

mod builtin;
mod load;
mod schema;
mod validate;

pub use builtin::{BUILTINS, Builtin, builtin};
pub use load::{ScenarioError, load, parse};
pub use schema::*;
