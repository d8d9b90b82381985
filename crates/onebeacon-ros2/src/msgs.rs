//! The messages the node publishes, as their ROS 2 definitions have them (field order is
//! wire order): std_msgs/Header, geometry_msgs, nav_msgs/Odometry, diagnostic_msgs, and
//! onebeacon_msgs/Setpoint (msg/Setpoint.msg).

use serde::Serialize;
use serde::ser::SerializeTuple;

#[derive(Debug, Clone, Serialize)]
pub(crate) struct Time {
    pub(crate) sec: i32,
    pub(crate) nanosec: u32,
}

impl Time {
    /// A stamp of `t_s` seconds (the input's), to the nanosecond.
    pub(crate) fn of(t_s: f64) -> Self {
        let sec = t_s.floor();
        let nanosec = ((t_s - sec) * 1e9).round().clamp(0.0, 999_999_999.0);
        Self { sec: sec.clamp(f64::from(i32::MIN), f64::from(i32::MAX)) as i32, nanosec: nanosec as u32 }
    }
}

#[derive(Debug, Clone, Serialize)]
pub(crate) struct Header {
    pub(crate) stamp: Time,
    pub(crate) frame_id: String,
}

#[derive(Debug, Clone, Default, Serialize)]
pub(crate) struct Point {
    pub(crate) x: f64,
    pub(crate) y: f64,
    pub(crate) z: f64,
}

#[derive(Debug, Clone, Serialize)]
pub(crate) struct Quaternion {
    pub(crate) x: f64,
    pub(crate) y: f64,
    pub(crate) z: f64,
    pub(crate) w: f64,
}

impl Quaternion {
    /// A rotation of `yaw` about z.
    pub(crate) fn yaw(yaw: f64) -> Self {
        let (s, c) = (yaw / 2.0).sin_cos();
        Self { x: 0.0, y: 0.0, z: s, w: c }
    }
}

#[derive(Debug, Clone, Serialize)]
pub(crate) struct Pose {
    pub(crate) position: Point,
    pub(crate) orientation: Quaternion,
}

/// A row-major 6 x 6 covariance (x, y, z, rotation about x, y, z): `float64[36]`, a
/// fixed array (no length on the wire).
#[derive(Debug, Clone)]
pub(crate) struct Cov6(pub(crate) [f64; 36]);

impl Serialize for Cov6 {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        let mut t = s.serialize_tuple(36)?;
        for v in &self.0 {
            t.serialize_element(v)?;
        }
        t.end()
    }
}

#[derive(Debug, Clone, Serialize)]
pub(crate) struct PoseWithCovariance {
    pub(crate) pose: Pose,
    pub(crate) covariance: Cov6,
}

#[derive(Debug, Clone, Default, Serialize)]
pub(crate) struct Twist {
    pub(crate) linear: Point,
    pub(crate) angular: Point,
}

#[derive(Debug, Clone, Serialize)]
pub(crate) struct TwistWithCovariance {
    pub(crate) twist: Twist,
    pub(crate) covariance: Cov6,
}

/// nav_msgs/Odometry.
#[derive(Debug, Clone, Serialize)]
pub(crate) struct Odometry {
    pub(crate) header: Header,
    pub(crate) child_frame_id: String,
    pub(crate) pose: PoseWithCovariance,
    pub(crate) twist: TwistWithCovariance,
}

/// geometry_msgs/PoseStamped.
#[derive(Debug, Clone, Serialize)]
pub(crate) struct PoseStamped {
    pub(crate) header: Header,
    pub(crate) pose: Pose,
}

/// diagnostic_msgs/KeyValue.
#[derive(Debug, Clone, Serialize)]
pub(crate) struct KeyValue {
    pub(crate) key: String,
    pub(crate) value: String,
}

/// diagnostic_msgs/DiagnosticStatus: `level` OK 0, WARN 1, ERROR 2, STALE 3.
#[derive(Debug, Clone, Serialize)]
pub(crate) struct DiagnosticStatus {
    pub(crate) level: u8,
    pub(crate) name: String,
    pub(crate) message: String,
    pub(crate) hardware_id: String,
    pub(crate) values: Vec<KeyValue>,
}

/// diagnostic_msgs/DiagnosticArray.
#[derive(Debug, Clone, Serialize)]
pub(crate) struct DiagnosticArray {
    pub(crate) header: Header,
    pub(crate) status: Vec<DiagnosticStatus>,
}

/// onebeacon_msgs/Setpoint (msg/Setpoint.msg): a controller's heading, speed and depth,
/// its confirmed mode (-1: none yet) and phase.
#[derive(Debug, Clone, Serialize)]
pub(crate) struct Setpoint {
    pub(crate) header: Header,
    pub(crate) heading: f64,
    pub(crate) speed: f64,
    pub(crate) depth: f64,
    pub(crate) mode: i32,
    pub(crate) phase: String,
}
