//! What a log or a live stream carries, item by item: measurements, beacon positions and
//! ground truth, in the source's frame until [`Input::to_ned`].

use crate::geo::Frame;
use crate::nav::{BeaconFix, Kind};
use nalgebra::Vector3;
use std::collections::{BTreeMap, BTreeSet};

/// A ground-truth pose (heading when the log has one). Items hold SI values in the
/// log's frame (x, y in `north_m`, `east_m` for NED logs) until [`Input::to_ned`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TruthPose {
    pub north_m: f64,
    pub east_m: f64,
    pub heading_rad: Option<f64>,
    /// The reference's own error, a standard deviation on each horizontal axis, m (0:
    /// exact): an LBL or USBL fix used as ground truth has one.
    pub sigma_m: f64,
}

impl TruthPose {
    /// An exact pose.
    pub fn exact(north_m: f64, east_m: f64, heading_rad: Option<f64>) -> Self {
        Self { north_m, east_m, heading_rad, sigma_m: 0.0 }
    }
}

/// One item of the time-ordered stream.
#[derive(Debug, Clone, PartialEq)]
pub enum Input {
    Measurement(Kind),
    /// A beacon's position now (a moving beacon's track; fixes later measurements).
    BeaconPosition {
        beacon_id: u32,
        position: Vector3<f64>,
    },
    Truth(TruthPose),
}

#[derive(Debug, Clone, PartialEq)]
pub struct Item {
    pub t_s: f64,
    pub input: Input,
}

impl Input {
    /// Its kind as logs and streams name it (`range`, `beacon_position`, ...).
    pub fn name(&self) -> &'static str {
        match self {
            Input::Measurement(m) => m.name(),
            Input::BeaconPosition { .. } => "beacon_position",
            Input::Truth(_) => "ground_truth",
        }
    }

    /// This input, given in `frame`, in NED: the one place where logs and streams
    /// change frame.
    pub fn to_ned(self, frame: Frame) -> Input {
        let point = |p: Vector3<f64>| frame.to_ned(p.x, p.y, p.z);
        match self {
            Input::Measurement(mut m) => {
                if let Some(b) = m.beacon_mut() {
                    b.position_ned_m = point(b.position_ned_m);
                }
                Input::Measurement(match m {
                    Kind::Odometry { distance_m, heading_change_rad } => {
                        Kind::Odometry { distance_m, heading_change_rad: frame.turn_to_ned(heading_change_rad) }
                    }
                    // the body y axis flips with the sense of turns: left (FLU) in ENU
                    Kind::BodyOdometry { forward_m, lateral_m, heading_change_rad } => Kind::BodyOdometry {
                        forward_m,
                        lateral_m: frame.turn_to_ned(lateral_m),
                        heading_change_rad: frame.turn_to_ned(heading_change_rad),
                    },
                    // body axes FLU in ENU, FRD in NED: v, w, q and r flip with the sense of turns
                    Kind::BodyVelocity { nu: [u, v, w, p, q, r] } => Kind::BodyVelocity {
                        nu: [
                            u,
                            frame.turn_to_ned(v),
                            frame.turn_to_ned(w),
                            p,
                            frame.turn_to_ned(q),
                            frame.turn_to_ned(r),
                        ],
                    },
                    Kind::Heading { heading_rad } => Kind::Heading { heading_rad: frame.heading_to_ned(heading_rad) },
                    Kind::Attitude { roll_rad, pitch_rad, heading_rad } => {
                        Kind::Attitude { roll_rad, pitch_rad, heading_rad: frame.heading_to_ned(heading_rad) }
                    }
                    // the azimuth turns from the station's heading like a heading change;
                    // the elevation is from the vertical in either frame
                    Kind::Bearing { station, station_heading_rad, azimuth_rad, elevation_rad } => Kind::Bearing {
                        station,
                        station_heading_rad: frame.heading_to_ned(station_heading_rad),
                        azimuth_rad: frame.turn_to_ned(azimuth_rad),
                        elevation_rad,
                    },
                    Kind::Report { heading_rad, speed_m_s, depth_m } => {
                        Kind::Report { heading_rad: frame.heading_to_ned(heading_rad), speed_m_s, depth_m }
                    }
                    other => other,
                })
            }
            Input::BeaconPosition { beacon_id, position } => {
                Input::BeaconPosition { beacon_id, position: point(position) }
            }
            Input::Truth(p) => {
                let n = frame.to_ned(p.north_m, p.east_m, 0.0);
                Input::Truth(TruthPose {
                    north_m: n.x,
                    east_m: n.y,
                    heading_rad: p.heading_rad.map(|h| frame.heading_to_ned(h)),
                    sigma_m: p.sigma_m,
                })
            }
        }
    }
}

/// The position of beacon `id` for a measurement (log or stream): a fixed beacon's, or
/// NaN for a tracked one (the session supplies its latest position); otherwise the
/// message naming the known beacons.
pub fn resolve_beacon(
    id: u32,
    fixed: &BTreeMap<u32, Vector3<f64>>,
    tracked: &BTreeSet<u32>,
) -> Result<BeaconFix, String> {
    match fixed.get(&id) {
        Some(p) => Ok(BeaconFix::fixed(id, *p)),
        None if tracked.contains(&id) => Ok(BeaconFix::fixed(id, Vector3::repeat(f64::NAN))),
        None => {
            let known: Vec<String> = fixed.keys().chain(tracked).map(u32::to_string).collect();
            Err(format!("beacon {id} is not among the beacons ({})", known.join(", ")))
        }
    }
}
