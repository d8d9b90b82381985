//! What some navigators can tell a controller beyond their estimate, as small traits a
//! navigator hands out ([`super::Navigator::beacon_relative`],
//! [`super::Navigator::body_velocity`]). A controller that needs one names it
//! ([`Capability`]), and a configuration that gives it a navigator without it is refused
//! when it is read (`onebeacon::config::stream::StreamConfig::check`).

use nalgebra::Vector3;

/// rypkema's iUSBL navigator (sec. 4.1-4.2): where the vehicle is relative to the beacon
/// it navigates on, and the command mode the beacon's pings confirmed.
pub trait BeaconRelative {
    /// NED, m (depth as measured).
    fn beacon_relative_ned_m(&self) -> Vector3<f64>;
    /// The mode confirmed last, if any.
    fn command_mode(&self) -> Option<usize>;
}

/// sousa's 6-DOF filter (sec. 3.2): the body-frame linear velocity (u, v, w) it last
/// dead-reckoned on, m/s, for a beacon vehicle predicting where the vehicle will be.
pub trait BodyVelocity {
    fn body_velocity_m_s(&self) -> Vector3<f64>;
}

/// A capability a controller needs of the navigator it reads.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Capability {
    BeaconRelative,
    BodyVelocity,
}

impl Capability {
    /// What it is, in an error message.
    pub fn label(self) -> &'static str {
        match self {
            Capability::BeaconRelative => "the position relative to the beacon and the confirmed command mode",
            Capability::BodyVelocity => "the body velocity",
        }
    }
}
