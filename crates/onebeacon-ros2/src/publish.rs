//! The stream's output lines as ROS 2 messages: each estimate a nav_msgs/Odometry on
//! `NAMESPACE/ESTIMATOR/odometry`, a controller's decided waypoint a
//! geometry_msgs/PoseStamped on `NAMESPACE/waypoint`, a decided setpoint an
//! onebeacon_msgs/Setpoint on `NAMESPACE/setpoint`, and once a second of the inputs'
//! time a diagnostic_msgs/DiagnosticArray on `NAMESPACE/diagnostics` (each estimator's
//! updates, rejections, restarts and its NIS against the band of a consistent filter).

use crate::msgs::*;
use crate::node::NodeError;
use ros2_client::{MessageTypeName, Name, Node, Publisher, QosProfile};
use serde_json::Value;
use std::collections::BTreeMap;

/// The outputs are reliable, the last 100 kept for a late reader; a reader too slow to
/// take them does not hold the node up: what finds the writer's cache full of messages
/// not yet acknowledged is dropped and counted (`outputs_dropped` in the diagnostics).
const OUTPUT_QOS: QosProfile = QosProfile::publisher_default()
    .reliability_reliable(ros2_client::qos::WhenFull::Fail)
    .history(ros2_client::qos::History::KeepLast { depth: 100 });

/// NIS values in the diagnostics' window: the band is that of their mean.
const NIS_WINDOW: usize = 50;

/// One estimator's record for the diagnostics.
#[derive(Default)]
struct Record {
    accepted: u64,
    rejected: u64,
    restarts: u64,
    /// The last [`NIS_WINDOW`] NIS values.
    nis: std::collections::VecDeque<f64>,
}

/// The node's publishers and what its diagnostics count.
pub(crate) struct Outputs {
    namespace: String,
    frame_id: String,
    child_frame_id: String,
    odometry: BTreeMap<String, Publisher<Odometry>>,
    waypoint: Publisher<PoseStamped>,
    setpoint: Publisher<Setpoint>,
    diagnostics: Publisher<DiagnosticArray>,
    records: BTreeMap<String, Record>,
    pub(crate) skipped: u64,
    last_skip: String,
    /// Messages a full writer refused (a slow reader), and the last refusal.
    pub(crate) dropped: u64,
    last_drop: String,
    last_diagnostics_s: Option<f64>,
}

/// A ROS name of an estimator's (`ekf-cal` -> `ekf_cal`): letters, digits and single
/// underscores, not starting with a digit.
pub(crate) fn ros_name(name: &str) -> String {
    let mut out = String::new();
    for c in name.chars() {
        let c = if c.is_ascii_alphanumeric() { c } else { '_' };
        if !(c == '_' && out.ends_with('_')) {
            out.push(c);
        }
    }
    let out = out.trim_matches('_').to_string();
    if out.starts_with(|c: char| c.is_ascii_digit()) || out.is_empty() { format!("e_{out}") } else { out }
}

fn publisher<M: serde::Serialize>(node: &mut Node, name: &str, pkg: &str, ty: &str) -> Result<Publisher<M>, NodeError> {
    let ros = |e: String| NodeError::Ros(format!("{name}: {e}"));
    let topic_name = Name::parse(name).map_err(|e| ros(format!("{e:?}")))?;
    let topic = node
        .create_topic(&topic_name, MessageTypeName::new(pkg, ty), &OUTPUT_QOS)
        .map_err(|e| ros(format!("{e:?}")))?;
    node.create_publisher(&topic, Some(OUTPUT_QOS)).map_err(|e| ros(format!("{e:?}")))
}

impl Outputs {
    pub(crate) fn new(
        node: &mut Node,
        namespace: &str,
        frame_id: &str,
        child_frame_id: &str,
    ) -> Result<Self, NodeError> {
        let namespace = namespace.trim_end_matches('/').to_string();
        Ok(Self {
            waypoint: publisher(node, &format!("{namespace}/waypoint"), "geometry_msgs", "PoseStamped")?,
            setpoint: publisher(node, &format!("{namespace}/setpoint"), "onebeacon_msgs", "Setpoint")?,
            diagnostics: publisher(node, &format!("{namespace}/diagnostics"), "diagnostic_msgs", "DiagnosticArray")?,
            namespace,
            frame_id: frame_id.into(),
            child_frame_id: child_frame_id.into(),
            odometry: BTreeMap::new(),
            records: BTreeMap::new(),
            skipped: 0,
            last_skip: String::new(),
            dropped: 0,
            last_drop: String::new(),
            last_diagnostics_s: None,
        })
    }

    fn header(&self, t_s: f64) -> Header {
        Header { stamp: Time::of(t_s), frame_id: self.frame_id.clone() }
    }

    /// A line skipped or screened out, and why.
    pub(crate) fn skip(&mut self, why: &str) {
        self.skipped += 1;
        self.last_skip = why.to_string();
    }

    /// An estimator started again.
    pub(crate) fn restart(&mut self, estimator: &str) {
        self.records.entry(estimator.to_string()).or_default().restarts += 1;
    }

    /// Publishes what an output line of the stream holds.
    pub(crate) fn line(&mut self, node: &mut Node, out: &Value) -> Result<(), NodeError> {
        let t_s = out["t_s"].as_f64().unwrap_or(f64::NAN);
        let prefix = match out["vehicle"].as_u64() {
            Some(v) => format!("{}/vehicle{v}", self.namespace),
            None => self.namespace.clone(),
        };
        for e in out["estimates"].as_array().into_iter().flatten() {
            let name = e["name"].as_str().unwrap_or_default().to_string();
            let f = |k: &str| e[k].as_f64().unwrap_or(f64::NAN);
            let record = self.records.entry(name.clone()).or_default();
            match e["outcome"].as_str() {
                Some("accepted") => record.accepted += 1,
                Some("rejected") => record.rejected += 1,
                _ => {}
            }
            if let Some(nis) = e["nis"].as_f64() {
                if record.nis.len() == NIS_WINDOW {
                    record.nis.pop_front();
                }
                record.nis.push_back(nis);
            }
            let topic = format!("{prefix}/{}/odometry", ros_name(&name));
            if !self.odometry.contains_key(&topic) {
                let p = publisher(node, &topic, "nav_msgs", "Odometry")?;
                self.odometry.insert(topic.clone(), p);
            }
            let (sx, sy, sh) = (f("sigma_x_m"), f("sigma_y_m"), f("sigma_heading_rad"));
            // not estimated: z, roll and pitch; the twist (-1: unknown)
            let unknown = 1e6;
            let mut pose_cov = [0.0; 36];
            pose_cov[0] = sx * sx;
            pose_cov[1] = f("cov_xy_m2");
            pose_cov[6] = pose_cov[1];
            pose_cov[7] = sy * sy;
            pose_cov[14] = unknown;
            pose_cov[21] = unknown;
            pose_cov[28] = unknown;
            pose_cov[35] = sh * sh;
            let mut twist_cov = [0.0; 36];
            (0..6).for_each(|i| twist_cov[i * 7] = -1.0);
            let odometry = Odometry {
                header: self.header(t_s),
                child_frame_id: self.child_frame_id.clone(),
                pose: PoseWithCovariance {
                    pose: Pose {
                        position: Point { x: f("x_m"), y: f("y_m"), z: 0.0 },
                        orientation: Quaternion::yaw(f("heading_rad")),
                    },
                    covariance: Cov6(pose_cov),
                },
                twist: TwistWithCovariance { twist: Twist::default(), covariance: Cov6(twist_cov) },
            };
            let sent = self.odometry[&topic].publish(odometry);
            self.sent(&topic, sent);
        }
        if out["decided"].as_bool() == Some(true) {
            let command = &out["command"];
            if let Some(pose) = waypoint(command) {
                let sent = self.waypoint.publish(PoseStamped { header: self.header(t_s), pose });
                self.sent("waypoint", sent);
            } else if command["kind"] == "setpoint" {
                let f = |k: &str| command[k].as_f64().unwrap_or(f64::NAN);
                let msg = Setpoint {
                    header: self.header(t_s),
                    heading: f("heading_rad"),
                    speed: f("speed_m_s"),
                    depth: f("depth_m"),
                    mode: command["mode"].as_i64().and_then(|m| i32::try_from(m).ok()).unwrap_or(-1),
                    phase: command["phase"].as_str().unwrap_or_default().to_string(),
                };
                let sent = self.setpoint.publish(msg);
                self.sent("setpoint", sent);
            }
        }
        if t_s.is_finite() && self.last_diagnostics_s.is_none_or(|last| t_s - last >= 1.0 || t_s < last) {
            self.last_diagnostics_s = Some(t_s);
            let msg = DiagnosticArray { header: self.header(t_s), status: self.statuses() };
            let sent = self.diagnostics.publish(msg);
            self.sent("diagnostics", sent);
        }
        Ok(())
    }

    /// A publication's outcome: a refusal is counted, never an error of the node's.
    fn sent<E: std::fmt::Debug>(&mut self, topic: &str, r: Result<(), E>) {
        if let Err(e) = r {
            self.dropped += 1;
            let e = format!("{e:?}");
            // the kind of error, without the message it carries
            self.last_drop = format!("{topic}: {}", e.split([' ', '(', '{']).next().unwrap_or_default());
        }
    }

    /// Each estimator's status, and the node's (lines skipped, outputs dropped).
    fn statuses(&self) -> Vec<DiagnosticStatus> {
        let kv = |k: &str, v: String| KeyValue { key: k.into(), value: v };
        let mut out: Vec<DiagnosticStatus> = self
            .records
            .iter()
            .map(|(name, r)| {
                let n = r.nis.len();
                let mean = if n == 0 { f64::NAN } else { r.nis.iter().sum::<f64>() / n as f64 };
                let (low, high) = nis_band(n);
                let overconfident = n >= 10 && mean > high;
                let message = if overconfident {
                    format!("overconfident: mean NIS {mean:.2} of its last {n} updates above {high:.2}, the 97.5 % point of a consistent filter's")
                } else {
                    "ok".to_string()
                };
                DiagnosticStatus {
                    level: u8::from(overconfident),
                    name: format!("onebeacon: {name}"),
                    message,
                    hardware_id: String::new(),
                    values: vec![
                        kv("accepted", r.accepted.to_string()),
                        kv("rejected", r.rejected.to_string()),
                        kv("restarts", r.restarts.to_string()),
                        kv("nis_mean", format!("{mean}")),
                        kv("nis_band_95", format!("[{low}, {high}]")),
                        kv("nis_count", n.to_string()),
                    ],
                }
            })
            .collect();
        out.push(DiagnosticStatus {
            level: u8::from(self.skipped > 0),
            name: "onebeacon: inputs".into(),
            message: if self.skipped == 0 { "ok".into() } else { format!("last skipped: {}", self.last_skip) },
            hardware_id: String::new(),
            values: vec![kv("skipped", self.skipped.to_string())],
        });
        out.push(DiagnosticStatus {
            level: u8::from(self.dropped > 0),
            name: "onebeacon: outputs".into(),
            message: if self.dropped == 0 { "ok".into() } else { format!("last dropped: {}", self.last_drop) },
            hardware_id: String::new(),
            values: vec![kv("outputs_dropped", self.dropped.to_string())],
        });
        out
    }
}

/// The 95 % band (2.5 % and 97.5 % points) of the mean of `n` NIS values of one degree
/// of freedom each: chi-square with n dof over n, by Wilson and Hilferty's cube-root
/// normal approximation (within 1 % of the exact points from n = 10 on).
pub(crate) fn nis_band(n: usize) -> (f64, f64) {
    if n == 0 {
        return (f64::NAN, f64::NAN);
    }
    let n = n as f64;
    let q = |z: f64| (1.0 - 2.0 / (9.0 * n) + z * (2.0 / (9.0 * n)).sqrt()).powi(3);
    (q(-1.959_964), q(1.959_964))
}

/// A command's waypoint as a pose: a planner's waypoint (facing it from the path's
/// start), a path's end, or a waypoint; None for a setpoint (heading, speed, depth).
fn waypoint(command: &Value) -> Option<Pose> {
    let f = |k: &str| command[k].as_f64();
    let (x, y, yaw) = match command["kind"].as_str()? {
        "waypoint" => (f("x_m")?, f("y_m")?, 0.0),
        "path" => {
            let (x, y) = (f("waypoint_x_m").or(f("to_x_m"))?, f("waypoint_y_m").or(f("to_y_m"))?);
            (x, y, (y - f("from_y_m")?).atan2(x - f("from_x_m")?))
        }
        _ => return None,
    };
    Some(Pose { position: Point { x, y, z: 0.0 }, orientation: Quaternion::yaw(yaw) })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn estimator_names_become_ros_names() {
        assert_eq!(ros_name("ekf-cal-gated"), "ekf_cal_gated");
        assert_eq!(ros_name("pf (told)"), "pf_told");
        assert_eq!(ros_name("2nd"), "e_2nd");
    }

    /// The band against the exact chi-square points (scipy.stats.chi2.ppf(q, n) / n):
    /// n = 10: 0.3247, 2.0483; n = 50: 0.6471, 1.4284.
    #[test]
    fn the_nis_band_is_chi_squares() {
        for (n, lo, hi) in [(10, 0.3247, 2.0483), (50, 0.6471, 1.4284)] {
            let (l, h) = nis_band(n);
            assert!((l / lo - 1.0).abs() < 0.01 && (h / hi - 1.0).abs() < 0.01, "{n}: {l} {h}");
        }
    }
}
