//! The integration tests of `onebeacon-sim`, one binary (one link); each module is a file
//! of tests/: `cargo test --release -p onebeacon-sim --test integration garin2024`.

mod common;
mod docs;
mod dsp_chain;
mod dsp_trials;
mod garin2024;
mod hoff2024;
mod layers;
mod plaza;
mod rypkema;
mod shards;
mod sousa;
