//! onebeacon on a ROS 2 graph: the vehicle's computer of a log description (its
//! estimators, its controller) as a node that subscribes to the description's live
//! topics and publishes, per estimator, a nav_msgs/Odometry with its covariance, the
//! controller's waypoint and a diagnostic_msgs/DiagnosticArray. Every message goes the
//! way a `stream` line goes (it becomes the line `replay --print-stream` would write, and
//! the stream's loop takes it), so the node's estimates are `stream`'s on the same
//! inputs; `--record FILE` keeps those lines to show it.

mod msgs;
mod node;
mod publish;

pub use node::{NodeError, Options, Summary, run};
