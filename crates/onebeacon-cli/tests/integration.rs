//! The integration tests of the `onebeacon` binary, one test binary (one link); each
//! module is a file of tests/: `cargo test --release -p onebeacon-cli --test integration replay`.

mod common;

mod cli;
mod onboard;
mod replay;
