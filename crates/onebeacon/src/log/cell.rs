//! One cell of a source's row in hand, whatever the source: what a CSV file and a ROS 2
//! topic's message give the rows' reader alike.

/// One cell of the row in hand: text (a CSV cell, a string field) or a number (a bag's
/// numeric field, time or quaternion yaw).
pub(super) enum Cell<'a> {
    Text(&'a str),
    #[cfg_attr(not(feature = "ros2"), allow(dead_code))]
    Number(f64),
}
