//! The one measurement event: what a simulated world, a replayed log and a live stream
//! all hand to a navigator. SI units, NED frame, radians.

use nalgebra::Vector3;
use std::sync::Arc;

/// A beacon as an acoustic measurement carries it: its id, its position when it
/// transmitted (NED, m; NaN until a tracked beacon's position is resolved), how well it
/// knew that position (standard deviation per horizontal axis, m: an ASV's GPS), and
/// the transmit time when known (OWTT).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BeaconFix {
    pub id: u32,
    pub position_ned_m: Vector3<f64>,
    pub sigma_m: f64,
    pub t_tx_s: Option<f64>,
}

impl BeaconFix {
    /// A beacon at a known, exact position.
    pub fn fixed(id: u32, position_ned_m: Vector3<f64>) -> Self {
        Self { id, position_ned_m, sigma_m: 0.0, t_tx_s: None }
    }
}

/// One ping as the vehicle's own receiving array recorded it (rypkema's inverted USBL,
/// sec. 3.1.2): every element's samples from the transmit epoch (the PPS both ends
/// share) on. The sample rate and the array are the receiver's settings.
#[derive(Debug, Clone, PartialEq)]
pub struct Capture {
    /// The beacon as its GPS logged it at the transmit epoch, `t_tx_s` the epoch.
    pub beacon: BeaconFix,
    /// `samples[m]`: element m's capture.
    pub samples: Vec<Vec<f64>>,
}

/// What was measured. Inputs (odometry, speed, body velocity, a held depth) drive the
/// motion; the rest are corrections. Each navigator uses the kinds its model has and
/// skips the others. Every kind but a [`Kind::Capture`] (shared, not copied) is a few
/// numbers.
#[derive(Debug, Clone, PartialEq)]
pub enum Kind {
    /// Distance travelled and heading change since the previous increment (wheels, DVL).
    Odometry { distance_m: f64, heading_change_rad: f64 },
    /// Body-frame increments since the previous one: forward and lateral distance (body
    /// y: starboard in NED; in an ENU log's items, left) and heading change (an INS's or
    /// DVL's dead reckoning; a crabbing vehicle moves sideways too).
    BodyOdometry { forward_m: f64, lateral_m: f64, heading_change_rad: f64 },
    /// Forward speed, held until the next one (DVL, propeller model).
    Speed { speed_m_s: f64 },
    /// Heading from a compass or AHRS.
    Heading { heading_rad: f64 },
    /// Depth from a pressure sensor.
    Depth { depth_m: f64 },
    /// Roll, pitch and heading from an AHRS.
    Attitude { roll_rad: f64, pitch_rad: f64, heading_rad: f64 },
    /// Body velocities [u, v, w, p, q, r] (DVL and gyros), held until the next sample.
    BodyVelocity { nu: [f64; 6] },
    /// AHRS heading with gyro yaw rate and accelerometer forward acceleration, sampled
    /// together (garin2024 eq. 18, right).
    Inertial { heading_rad: f64, yaw_rate_rad_s: f64, accel_m_s2: f64 },
    /// One-way travel-time (or two-way) range to a beacon, m.
    Range { beacon: BeaconFix, range_m: f64 },
    /// Radial speed toward a beacon from a Doppler shift, positive when closing
    /// (garin2024 eq. 13).
    Doppler { beacon: BeaconFix, radial_speed_m_s: f64 },
    /// A decoded communication frame: range and Doppler radial speed at once
    /// (garin2024 eq. 18, left).
    RangeDoppler { beacon: BeaconFix, range_m: f64, radial_speed_m_s: f64 },
    /// The bearing of the vehicle measured by a USBL on a station (a surface vehicle)
    /// that heard one of its messages: azimuth from the station's heading and elevation
    /// from the vertical (hoff2024 eq. 1-2), with the station's position as its GPS
    /// gives it (`station`, its `sigma_m` the GPS error) and its compass heading.
    Bearing { station: BeaconFix, station_heading_rad: f64, azimuth_rad: f64, elevation_rad: f64 },
    /// What the vehicle reports of itself in an acoustic message: its INS heading,
    /// speed over ground and depth (hoff2024 eq. 8).
    Report { heading_rad: f64, speed_m_s: f64, depth_m: f64 },
    /// The hydrophone data of one ping on the vehicle's own array, for a navigator that
    /// runs the receiver chain itself (rypkema sec. 3.2).
    Capture(Arc<Capture>),
    /// One ping already reduced by the vehicle's receiver: slant range, the direction
    /// toward the beacon in the array frame (azimuth from x toward y, inclination from
    /// +z down, rad, as [`crate::dsp::beamform::direction`]) and the identified command
    /// mode (index into the mode bank).
    ArrayFix { beacon: BeaconFix, range_m: f64, azimuth_rad: f64, inclination_rad: f64, mode: usize },
}

impl Kind {
    /// The beacon an acoustic measurement names.
    pub fn beacon(&self) -> Option<&BeaconFix> {
        match self {
            Kind::Range { beacon, .. } | Kind::Doppler { beacon, .. } | Kind::RangeDoppler { beacon, .. } => {
                Some(beacon)
            }
            Kind::Bearing { station, .. } => Some(station),
            Kind::Capture(c) => Some(&c.beacon),
            Kind::ArrayFix { beacon, .. } => Some(beacon),
            _ => None,
        }
    }

    pub fn beacon_mut(&mut self) -> Option<&mut BeaconFix> {
        match self {
            Kind::Range { beacon, .. } | Kind::Doppler { beacon, .. } | Kind::RangeDoppler { beacon, .. } => {
                Some(beacon)
            }
            Kind::Bearing { station, .. } => Some(station),
            Kind::Capture(c) => Some(&mut Arc::make_mut(c).beacon),
            Kind::ArrayFix { beacon, .. } => Some(beacon),
            _ => None,
        }
    }

    /// Short name (stream lines, rejection lists).
    pub fn name(&self) -> &'static str {
        match self {
            Kind::Odometry { .. } => "odometry",
            Kind::BodyOdometry { .. } => "body_odometry",
            Kind::Speed { .. } => "speed",
            Kind::Heading { .. } => "heading",
            Kind::Depth { .. } => "depth",
            Kind::Attitude { .. } => "attitude",
            Kind::BodyVelocity { .. } => "body_velocity",
            Kind::Inertial { .. } => "inertial",
            Kind::Range { .. } => "range",
            Kind::Doppler { .. } => "doppler",
            Kind::RangeDoppler { .. } => "range_doppler",
            Kind::Bearing { .. } => "bearing",
            Kind::Report { .. } => "report",
            Kind::Capture(_) => "capture",
            Kind::ArrayFix { .. } => "array_fix",
        }
    }
}

/// One measurement: when it was taken (received, for an acoustic one), s, and what.
#[derive(Debug, Clone, PartialEq)]
pub struct Measurement {
    pub t_s: f64,
    pub kind: Kind,
}

impl Measurement {
    pub fn new(t_s: f64, kind: Kind) -> Self {
        Self { t_s, kind }
    }
}
