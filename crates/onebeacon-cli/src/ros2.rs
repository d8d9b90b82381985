//! `onebeacon ros2 CONFIG`: the vehicle's computer of a log description as a ROS 2 node
//! (crate onebeacon-ros2; a build with `--features ros2`).

use anyhow::Result;
use std::path::PathBuf;

#[derive(Debug, clap::Args)]
pub(crate) struct Ros2Args {
    /// Log description whose [[source]] tables name live topics (`topic`, `type`) and
    /// its estimators, beacons, start and controller, as `stream` reads them.
    config: PathBuf,
    /// DDS domain (default: $ROS_DOMAIN_ID, else 0).
    #[arg(long)]
    domain: Option<u16>,
    /// Namespace of the outputs: NAMESPACE/ESTIMATOR/odometry, NAMESPACE/waypoint,
    /// NAMESPACE/diagnostics.
    #[arg(long, default_value = "/onebeacon")]
    namespace: String,
    /// frame_id of the odometry's header (the world frame of the estimates).
    #[arg(long, default_value = "map")]
    frame_id: String,
    /// child_frame_id of the odometry (the vehicle's body frame).
    #[arg(long, default_value = "base_link")]
    child_frame_id: String,
    /// Write each input as the stream line it became, in the order taken:
    /// `onebeacon stream CONFIG < FILE` then gives the node's outputs again.
    #[arg(long)]
    record: Option<PathBuf>,
    /// Stop once no message has come for this many seconds (after the first).
    #[arg(long)]
    idle_exit_s: Option<f64>,
    /// Hold each message this long, so that one stamped earlier that comes later (an
    /// acoustic range behind the odometry) goes in first; later than that, it is screened
    /// out as `stream` screens an item before the previous one. Adds to every latency.
    #[arg(long, default_value_t = 0.0)]
    reorder_s: f64,
}

/// Runs the node until a signal (or `--idle-exit-s`); its output lines (those of
/// `stream`) on stdout, what it skips on stderr.
pub(crate) fn run(a: Ros2Args) -> Result<()> {
    let unit = onebeacon::log::stream_setup(&a.config, |s| crate::budget().check_stream(s))?;
    let domain = match a.domain {
        Some(d) => d,
        None => match std::env::var("ROS_DOMAIN_ID") {
            Ok(v) => v
                .trim()
                .parse()
                .map_err(|_| crate::BadInput(format!("ROS_DOMAIN_ID = {v:?}: a DDS domain is an integer 0 to 232")))?,
            Err(_) => 0,
        },
    };
    if let Some(s) = a.idle_exit_s.filter(|s| !(s.is_finite() && *s > 0.0)) {
        return Err(crate::BadInput(format!("--idle-exit-s {s}: a duration above 0 s")).into());
    }
    if !(a.reorder_s.is_finite() && (0.0..=60.0).contains(&a.reorder_s)) {
        return Err(crate::BadInput(format!("--reorder-s {}: 0 to 60 s", a.reorder_s)).into());
    }
    let options = onebeacon_ros2::Options {
        reorder_s: a.reorder_s,
        domain,
        namespace: a.namespace,
        frame_id: a.frame_id,
        child_frame_id: a.child_frame_id,
        record: a.record,
        idle_exit_s: a.idle_exit_s,
    };
    let stop = std::sync::atomic::AtomicBool::new(false);
    let summary = onebeacon_ros2::run(&a.config, unit, &options, std::io::stdout().lock(), &stop, |line, m| {
        eprintln!("input line {line}: {m}")
    })
    .map_err(|e| match e {
        // a bad description or topic: one line, exit status 2
        onebeacon_ros2::NodeError::Log(e) => anyhow::Error::from(e),
        e => anyhow::Error::from(e),
    })?;
    eprintln!(
        "{} messages, {} lines, {} skipped, {} outputs dropped (a reader too slow)",
        summary.messages, summary.lines, summary.skipped, summary.dropped
    );
    Ok(())
}
