//! Input and output formats of the onboard crate.

#[cfg(feature = "stream")]
pub mod jsonl;
#[cfg(feature = "stream")]
pub mod stream;
