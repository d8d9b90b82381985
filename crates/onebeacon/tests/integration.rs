//! The integration tests of `onebeacon`, one binary (one link); each module is a file of
//! tests/: `cargo test --release -p onebeacon --test integration session_properties`.

mod measurement_properties;
mod session_properties;
#[cfg(all(feature = "serde", feature = "stream"))]
mod vehicle_config;
