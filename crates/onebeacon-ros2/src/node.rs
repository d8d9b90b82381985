//! The node's loop: its live topics subscribed (best effort, as sensor data go), each
//! message taken as it comes, turned into stream lines (its items, or an own fix) and pushed
//! through the stream's loop ([`onebeacon::io::stream::Lines`]); each output line written
//! (stdout), published ([`crate::publish`]) and, with `record`, its input kept. A bad
//! message is skipped and said, like a bad stream line; nothing stops the node but a
//! signal, `idle_exit_s` or an I/O error.

use crate::publish::Outputs;
use onebeacon::io::jsonl::{Line, line_json};
use onebeacon::io::stream::{Lines, Note};
use onebeacon::log::{Log, LogError};
use onebeacon::nav::session::Input;
use onebeacon::vehicle::unit::Unit;
use ros2_client::dds::rustdds::mio1::{Events, Interest, Poll, Token};
use ros2_client::{Context, ContextOptions, MessageTypeName, Name, NodeName, NodeOptions, QosProfile};
use std::io::Write;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant, SystemTime};

/// Why the node stopped or could not start.
#[derive(Debug, thiserror::Error)]
pub enum NodeError {
    #[error(transparent)]
    Log(#[from] LogError),
    #[error("ROS 2: {0}")]
    Ros(String),
    #[error("{0}")]
    Io(#[from] std::io::Error),
}

/// The node's settings (`onebeacon ros2 --help`).
#[derive(Debug, Clone)]
pub struct Options {
    /// The DDS domain (ROS_DOMAIN_ID).
    pub domain: u16,
    /// Where the outputs are published: `NAMESPACE/ESTIMATOR/odometry`, ...
    pub namespace: String,
    /// The frames of the odometry: the world's (its header) and the vehicle's (its child).
    pub frame_id: String,
    pub child_frame_id: String,
    /// Each input as the stream line it became, in the order taken (a new file).
    pub record: Option<PathBuf>,
    /// Stop when no message came for this long (after the first).
    pub idle_exit_s: Option<f64>,
    /// How long a message is held, s, so that one stamped earlier but come later (an
    /// acoustic range behind the odometry, another writer's) goes in first: every input
    /// waits this long, and what comes later than that, stamped before what went in, is
    /// screened out as on a stream. 0: in time order within what each wake-up finds.
    pub reorder_s: f64,
}

/// What the node did.
#[derive(Debug, Clone, Default)]
pub struct Summary {
    pub messages: u64,
    pub lines: usize,
    pub skipped: u64,
    /// Output messages a slow reader's full writer cache refused.
    pub dropped: u64,
}

/// Inputs: best effort (a sensor's latest matters, a retransmission does not), deep
/// enough for a burst.
const INPUT_QOS: QosProfile =
    QosProfile::subscription_default().history(ros2_client::qos::History::KeepLast { depth: 1000 });

/// How often the loop looks at the stop flag and the idle time.
const TICK: Duration = Duration::from_millis(100);

/// Runs the vehicle's computer `unit` on the live topics of the log description
/// `config` until `stop` is set (a signal), `idle_exit_s` passes without a message, or an
/// I/O error. Each output line goes to `out`; `report` gets the line number and what a
/// skipped line or a note says.
pub fn run(
    config: &Path,
    mut unit: Unit,
    options: &Options,
    mut out: impl Write,
    stop: &AtomicBool,
    mut report: impl FnMut(usize, &str),
) -> Result<Summary, NodeError> {
    let log = Log::load_topics(config)?;
    let mut topics = log.topics()?;
    // a new file: what is there already is not the node's to overwrite
    let mut record = match &options.record {
        Some(p) => Some(std::io::BufWriter::new(std::fs::File::create_new(p).map_err(|e| LogError::File {
            file: p.display().to_string(),
            message: format!("cannot create a new file ({e}); --record writes one"),
        })?)),
        None => None,
    };
    let ros = |what: &str, e: &dyn std::fmt::Debug| NodeError::Ros(format!("{what}: {e:?}"));
    let context =
        Context::with_options(ContextOptions::new().domain_id(options.domain)).map_err(|e| ros("context", &e))?;
    let node_name = NodeName::new("/", "onebeacon").map_err(|e| ros("node name", &e))?;
    let mut node = context.new_node(node_name, NodeOptions::new().enable_rosout(false)).map_err(|e| ros("node", &e))?;
    let mut subscriptions = Vec::new();
    let mut poll = Poll::new()?;
    for (i, t) in topics.iter().enumerate() {
        let name = Name::parse(t.topic()).map_err(|e| ros(&format!("topic name {}", t.topic()), &e))?;
        let (pkg, ty) = t.type_name();
        let topic =
            node.create_topic(&name, MessageTypeName::new(&pkg, &ty), &INPUT_QOS).map_err(|e| ros(t.topic(), &e))?;
        let mut sub = node
            .create_subscription::<onebeacon::log::ros2::live::Message>(&topic, Some(INPUT_QOS))
            .map_err(|e| ros(t.topic(), &e))?;
        poll.registry().register(&mut sub, Token(i), Interest::READABLE)?;
        subscriptions.push((sub, t.seed()));
    }
    let mut outputs = Outputs::new(&mut node, &options.namespace, &options.frame_id, &options.child_frame_id)?;
    let mut lines = Lines::default();
    let mut summary = Summary::default();
    let mut events = Events::with_capacity(64);
    let mut last = None::<Instant>;
    let mut pending = Vec::new();
    loop {
        let idle = matches!((options.idle_exit_s, last), (Some(idle), Some(l)) if l.elapsed().as_secs_f64() > idle);
        // at the end, what is held goes in too
        let ending = stop.load(Ordering::Relaxed) || idle;
        // a wake-up when the first held message is due
        let hold = Duration::from_secs_f64(options.reorder_s);
        let tick = match pending.iter().map(|(came, _, _): &(Instant, usize, _)| *came).min() {
            Some(came) => TICK.min(hold.saturating_sub(came.elapsed())),
            None => TICK,
        };
        events.clear();
        if !ending {
            match poll.poll(&mut events, Some(tick)) {
                Err(e) if e.kind() == std::io::ErrorKind::Interrupted => continue,
                r => r?,
            }
        }
        // everything that has come on every topic, held `reorder_s`, then in time order:
        // topics are read one after the other, their messages sent interleaved
        for event in events.iter() {
            let i = event.token().0;
            let (sub, seed) = &subscriptions[i];
            // edge-triggered: everything that has come
            loop {
                let (message, _) = match sub.take_seed(seed.clone()) {
                    Ok(Some(m)) => m,
                    Ok(None) => break,
                    Err(e) => {
                        summary.messages += 1;
                        outputs.skip(&format!("{}: {e:?}", topics[i].topic()));
                        report(
                            lines.count(),
                            &format!("{}: a message that does not decode ({e:?}); skipped", topics[i].topic()),
                        );
                        continue;
                    }
                };
                summary.messages += 1;
                last = Some(Instant::now());
                let received_s =
                    SystemTime::now().duration_since(SystemTime::UNIX_EPOCH).map_or(0.0, |d| d.as_secs_f64());
                match topics[i].lines(message, received_s) {
                    Ok(lines) => pending.extend(lines.into_iter().map(|line| (Instant::now(), i, line))),
                    Err(e) => {
                        outputs.skip(&e.to_string());
                        report(lines.count(), &format!("{e}; skipped"));
                    }
                }
            }
        }
        // as a log's sources merge: by time, then beacon positions, measurements, the
        // truth, then the sources' order (stable: a topic's own order kept); the own fix
        // a controller decides on last, after what was heard at its time
        let rank = |line: &Line| match line {
            Line::Item { item, .. } => match item.input {
                Input::BeaconPosition { .. } => 0,
                Input::Measurement(_) => 1,
                Input::Truth(_) => 2,
            },
            Line::OwnFix { .. } => 3,
        };
        pending.sort_by(|(_, i, a), (_, j, b)| a.t_s().total_cmp(&b.t_s()).then(rank(a).cmp(&rank(b))).then(i.cmp(j)));
        // what has been held long enough goes, with all that is stamped before it
        let due = match ending {
            true => pending.len(),
            false => pending.iter().rposition(|(came, _, _)| came.elapsed() >= hold).map_or(0, |k| k + 1),
        };
        let batch: Vec<_> = pending.drain(..due).map(|(_, i, item)| (i, item)).collect();
        for (_, line) in batch {
            let line = line_json(&line).to_string();
            if let Some(r) = record.as_mut() {
                writeln!(r, "{line}")?;
            }
            let output = lines.push(&mut unit, line.as_bytes(), false, |n, note| {
                match &note {
                    Note::Skipped(m) => outputs.skip(m),
                    Note::Restarted { estimator, .. } => outputs.restart(estimator),
                    Note::Info(_) => {}
                }
                report(n, note.message());
            });
            if let Some(o) = output {
                writeln!(out, "{o}")?;
                out.flush()?;
                outputs.line(&mut node, &o)?;
            }
        }
        // kept whole, batch by batch, should a signal end the node
        if let Some(r) = record.as_mut() {
            r.flush()?;
        }
        if ending {
            break;
        }
    }
    if let Some(mut r) = record {
        r.flush()?;
    }
    lines.finish(&unit, |n, note| report(n, note.message()));
    summary.lines = lines.count();
    summary.skipped = outputs.skipped;
    summary.dropped = outputs.dropped;
    Ok(summary)
}
