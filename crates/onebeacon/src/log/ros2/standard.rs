//! The standard ROS 2 messages onebeacon reads by name: their definitions (for a bag
//! that does not carry them, such as a `.db3` older than rosbag2's Iron) and the fields
//! each source kind takes from them when the source does not name its own.

use crate::log::schema::SourceKind;

/// The `ros2msg` definition of a standard type (`pkg/Name`), as rosidl ships it
/// (constants left out: they are not on the wire).
pub(crate) fn definition(name: &str) -> Option<&'static str> {
    Some(match name {
        "builtin_interfaces/Time" | "builtin_interfaces/Duration" => "int32 sec\nuint32 nanosec\n",
        "std_msgs/Header" => "builtin_interfaces/Time stamp\nstring frame_id\n",
        "geometry_msgs/Vector3" | "geometry_msgs/Point" => "float64 x\nfloat64 y\nfloat64 z\n",
        "geometry_msgs/Quaternion" => "float64 x 0\nfloat64 y 0\nfloat64 z 0\nfloat64 w 1\n",
        "geometry_msgs/Pose" => "Point position\nQuaternion orientation\n",
        "geometry_msgs/PoseStamped" => "std_msgs/Header header\nPose pose\n",
        "geometry_msgs/PoseWithCovariance" => "Pose pose\nfloat64[36] covariance\n",
        "geometry_msgs/PoseWithCovarianceStamped" => "std_msgs/Header header\nPoseWithCovariance pose\n",
        "geometry_msgs/PointStamped" => "std_msgs/Header header\nPoint point\n",
        "geometry_msgs/Twist" => "Vector3 linear\nVector3 angular\n",
        "geometry_msgs/TwistStamped" => "std_msgs/Header header\nTwist twist\n",
        "geometry_msgs/TwistWithCovariance" => "Twist twist\nfloat64[36] covariance\n",
        "geometry_msgs/TwistWithCovarianceStamped" => "std_msgs/Header header\nTwistWithCovariance twist\n",
        "nav_msgs/Odometry" => {
            "std_msgs/Header header\nstring child_frame_id\ngeometry_msgs/PoseWithCovariance pose\n\
             geometry_msgs/TwistWithCovariance twist\n"
        }
        "sensor_msgs/Imu" => {
            "std_msgs/Header header\ngeometry_msgs/Quaternion orientation\nfloat64[9] orientation_covariance\n\
             geometry_msgs/Vector3 angular_velocity\nfloat64[9] angular_velocity_covariance\n\
             geometry_msgs/Vector3 linear_acceleration\nfloat64[9] linear_acceleration_covariance\n"
        }
        "sensor_msgs/NavSatStatus" => "int8 status\nuint16 service\n",
        "sensor_msgs/NavSatFix" => {
            "std_msgs/Header header\nNavSatStatus status\nfloat64 latitude\nfloat64 longitude\nfloat64 altitude\n\
             float64[9] position_covariance\nuint8 position_covariance_type\n"
        }
        // Humble's: Jazzy's ends with `float32 variance`, after what is read here
        "sensor_msgs/Range" => {
            "std_msgs/Header header\nuint8 radiation_type\nfloat32 field_of_view\nfloat32 min_range\n\
             float32 max_range\nfloat32 range\n"
        }
        _ => return None,
    })
}

/// The field a source of `kind` reads for its column key `key` from a standard type
/// (`pkg/Name`) when the source names none: REP 103's axes as the type defines them.
pub(crate) fn default_field(type_name: &str, kind: SourceKind, key: &str) -> Option<&'static str> {
    use SourceKind::*;
    let pose = |prefix: &'static [&'static str; 4]| match key {
        "x" => Some(prefix[0]),
        "y" => Some(prefix[1]),
        "z" => Some(prefix[2]),
        "heading" => Some(prefix[3]),
        _ => None,
    };
    let twist = |prefix: &'static [&'static str; 3]| match key {
        "forward_speed" => Some(prefix[0]),
        "lateral_speed" => Some(prefix[1]),
        "yaw_rate" => Some(prefix[2]),
        _ => None,
    };
    const POSE: [&str; 4] = ["pose.position.x", "pose.position.y", "pose.position.z", "pose.orientation"];
    const POSE_COV: [&str; 4] =
        ["pose.pose.position.x", "pose.pose.position.y", "pose.pose.position.z", "pose.pose.orientation"];
    const TWIST: [&str; 3] = ["twist.linear.x", "twist.linear.y", "twist.angular.z"];
    const TWIST_COV: [&str; 3] = ["twist.twist.linear.x", "twist.twist.linear.y", "twist.twist.angular.z"];
    const POINT: [&str; 4] = ["point.x", "point.y", "point.z", ""];
    let field = match (type_name, kind) {
        // an own fix's speed: the odometry's forward speed in the child (body) frame
        ("nav_msgs/Odometry", OwnFix) if key == "speed" => Some(TWIST_COV[0]),
        (
            "nav_msgs/Odometry" | "geometry_msgs/PoseWithCovarianceStamped",
            GroundTruth | BeaconTrack | Heading | OwnFix,
        ) => pose(&POSE_COV),
        ("geometry_msgs/PoseStamped", GroundTruth | BeaconTrack | Heading | OwnFix) => pose(&POSE),
        ("geometry_msgs/PointStamped", GroundTruth | BeaconTrack | OwnFix) => pose(&POINT),
        ("nav_msgs/Odometry" | "geometry_msgs/TwistWithCovarianceStamped", BodyVelocity) => twist(&TWIST_COV),
        ("geometry_msgs/TwistStamped", BodyVelocity) => twist(&TWIST),
        ("sensor_msgs/Imu", Heading) => (key == "heading").then_some("orientation"),
        ("sensor_msgs/Imu", Attitude) => match key {
            "roll" => Some("orientation.roll"),
            "pitch" => Some("orientation.pitch"),
            "heading" => Some("orientation"),
            _ => None,
        },
        ("sensor_msgs/NavSatFix", GroundTruth | BeaconTrack | OwnFix) => match key {
            "lat" => Some("latitude"),
            "lon" => Some("longitude"),
            _ => None,
        },
        ("sensor_msgs/Range", Range) => match key {
            "range" => Some("range"),
            "beacon" => Some("header.frame_id"),
            _ => None,
        },
        _ => None,
    };
    field.filter(|f| !f.is_empty())
}
