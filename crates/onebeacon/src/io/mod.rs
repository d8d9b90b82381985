//! Input and output formats of the onboard crate.

pub mod file;
#[cfg(feature = "stream")]
pub mod jsonl;
#[cfg(feature = "stream")]
pub mod stream;

/// The kinds a stream line may have.
pub const KINDS: &str = "odometry, body_odometry, speed, heading, depth, attitude, body_velocity, inertial, range, doppler, \
    range_doppler, bearing, report, array_fix, beacon_position, ground_truth, own_fix";

/// The kinds as a list.
pub fn kinds() -> Vec<&'static str> {
    KINDS.split(", ").collect()
}
