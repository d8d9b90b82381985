//! Replaying real logs: a log description maps CSV files and columns to measurement
//! kinds ([`onebeacon::log`]); the onboard [`Session`] runs every configured estimator over the merged,
//! time-ordered stream, as `onebeacon stream` does live; [`replay`] does a whole log
//! and keeps what the outputs need.

pub mod rts;
pub mod tune;

#[cfg(test)]
mod burst_tests;
#[cfg(test)]
mod log_tests;

use onebeacon::log::schema::IncrementFrame;
use onebeacon::log::{Dropped, InitialStart, Log, LogError};
use onebeacon::nav::Kind;
use onebeacon::nav::diagnosis::BeaconStats;
use onebeacon::nav::session::{Input, Session, Start, Step};

use crate::run::{Estimate, StepRecord, TruthRecord};
use nalgebra::{Vector2, Vector3};
use std::collections::BTreeSet;

/// A replayed log: the session with its statistics and rejections, and how many
/// items the log had.
#[derive(Debug)]
pub struct Replay {
    pub session: Session,
    pub items: usize,
    /// Rows dropped and kept by sources with `time_order = "drop"`.
    pub dropped: Vec<Dropped>,
    /// What the sources could not read (a damaged bag), one line each.
    pub damage: Vec<String>,
    /// Where and when the estimators started (`[initial]`: given, the ground truth or a
    /// fix of the first ranges).
    pub start: InitialStart,
    /// Odometry rows read at the mid-step heading that turn more than
    /// [`WIDE_TURN_DEG`] in one row, and all odometry rows.
    pub wide_turns: (usize, usize),
}

/// A turn per odometry row beyond which the two increment conventions (mid-step and
/// start heading) put the row's end apart by more than a fifth of its distance (2
/// sin(dpsi / 4) = 0.2 at 23 deg); a sampled arc rarely turns so far in one row, a
/// pose-graph edge often does: worth a warning when the log reads them at mid-step.
pub const WIDE_TURN_DEG: f64 = 23.0;

/// Fewer ground-truth rows than this make a score that says little (a NEES band of a
/// handful of rows holds almost anything): the replay flags it.
pub const MIN_SCORED_ROWS: usize = 30;

impl Replay {
    /// What makes the replay's scores suspect, one line each: a source that dropped more
    /// rows than it kept, an estimator scored on fewer than [`MIN_SCORED_ROWS`] rows,
    /// and what the innovations say without the truth ([`Session::findings`]).
    pub fn warnings(&self, has_truth: bool) -> Vec<String> {
        let mut w: Vec<String> = self
            .dropped
            .iter()
            .filter(|d| d.lost_most())
            .map(|d| {
                format!(
                    "{}: {} of {} rows dropped out of time order (time_order = \"drop\"): check its time column",
                    d.file,
                    d.dropped,
                    d.dropped + d.kept
                )
            })
            .collect();
        w.extend(self.damage.iter().map(|d| format!("{d}; what came before it was read")));
        if has_truth {
            for (name, st) in self.session.names.iter().zip(&self.session.stats) {
                if st.count < MIN_SCORED_ROWS {
                    w.push(format!(
                        "{name}: scored on {} ground-truth row(s), fewer than {MIN_SCORED_ROWS}: its statistics say little",
                        st.count
                    ));
                }
            }
        }
        let (wide, rows) = self.wide_turns;
        if wide > 0 {
            w.push(format!(
                "{wide} of {rows} odometry rows turn more than {WIDE_TURN_DEG} deg in one row, read at the \
                 mid-step heading: if they are factor-graph edges (the translation, then the turn), set the \
                 source's increment_frame = \"start\" (docs/logs.md, \"Motion models\")"
            ));
        }
        w.extend(self.session.findings());
        w
    }
}

/// The session a log describes, started at its initial pose.
pub fn session_for(log: &Log, beacons: Option<BTreeSet<u32>>) -> Result<Session, LogError> {
    session_and_start(log, beacons).map(|(session, _)| session)
}

/// [`session_for`] with the start it was given.
fn session_and_start(log: &Log, beacons: Option<BTreeSet<u32>>) -> Result<(Session, InitialStart), LogError> {
    if !log.description.tracked.is_empty() {
        return Err(LogError::File {
            file: log.description.name.clone(),
            message: "key `tracked`: a stream's surface vehicle tracking several vehicles; replay runs the one vehicle of `[initial]`".into(),
        });
    }
    let start = log.initial_start(beacons.as_ref())?;
    Ok((session_from(log, beacons, &start), start))
}

/// The session a log describes on `beacons`, started at `start` (its
/// [`Log::initial_start`], read once for many sessions).
pub(crate) fn session_from(log: &Log, beacons: Option<BTreeSet<u32>>, start: &InitialStart) -> Session {
    let d = &log.description;
    let at = Start::At { t0_s: Some(start.t0_s), pose: start.pose };
    d.stream_config(Vec::new()).session(&d.initial, at, beacons).with_position_sigma(start.position_sigma_m)
}

/// Beacon ids asked for (all when `None`) checked against the log's: the set to use, or
/// "ID: not a beacon of the log (beacons: ...)".
pub fn beacon_filter(ids: Option<Vec<u32>>, known: &BTreeSet<u32>) -> Result<Option<BTreeSet<u32>>, String> {
    let Some(ids) = ids else { return Ok(None) };
    if let Some(id) = ids.iter().find(|id| !known.contains(id)) {
        let list: Vec<String> = known.iter().map(u32::to_string).collect();
        return Err(format!("{id}: not a beacon of the log (beacons: {})", list.join(", ")));
    }
    Ok(Some(ids.into_iter().collect()))
}

/// Each estimator's prediction of beacon `id`'s ranges by a run that never hears them,
/// on the other beacons of `beacons` (the log's when None), started without it:
/// `replay --holdout`, a score that needs no ground truth.
pub fn holdout(log: &Log, beacons: Option<&BTreeSet<u32>>, id: u32) -> Result<Vec<BeaconStats>, LogError> {
    let others: BTreeSet<u32> =
        beacons.cloned().unwrap_or_else(|| log.beacon_ids()).into_iter().filter(|b| *b != id).collect();
    let (session, start) = session_and_start(log, Some(others))?;
    let r = replay_session(log, session.with_held_out(id), start, |_| Ok::<_, LogError>(()))?;
    Ok(r.session.held_out_stats)
}

/// Runs every estimator of `log` over its stream, giving `record` one trajectory row
/// per ground-truth pose (per measurement when the log has no ground truth) as it goes:
/// nothing grows with the log's length but the bounded rejection log.
pub fn replay<E: From<LogError>>(
    log: &Log,
    beacons: Option<BTreeSet<u32>>,
    record: impl FnMut(StepRecord) -> Result<(), E>,
) -> Result<Replay, E> {
    let (session, start) = session_and_start(log, beacons)?;
    replay_session(log, session, start, record)
}

/// [`replay`] with the session given (one that keeps its estimators' histories, say).
fn replay_session<E: From<LogError>>(
    log: &Log,
    mut session: Session,
    start: InitialStart,
    mut record: impl FnMut(StepRecord) -> Result<(), E>,
) -> Result<Replay, E> {
    let has_truth = log.has_truth();
    let mut heard = false;
    let mut items = 0;
    let mut stream = log.items()?;
    let start_frame = log.description.sources.iter().any(|s| s.increment_frame == IncrementFrame::Start);
    let mut wide_turns = (0, 0);
    for item in &mut stream {
        let item = item?;
        items += 1;
        // a turn on the spot has no translation to put at either heading: never wide
        let turn = match item.input {
            Input::Measurement(Kind::Odometry { distance_m: d, heading_change_rad: dpsi }) => Some((d != 0.0, dpsi)),
            Input::Measurement(Kind::BodyOdometry { forward_m: f, lateral_m: l, heading_change_rad: dpsi }) => {
                Some((f != 0.0 || l != 0.0, dpsi))
            }
            _ => None,
        };
        if let Some((moved, dpsi)) = turn
            && !start_frame
        {
            wide_turns.0 += usize::from(moved && dpsi.abs() > WIDE_TURN_DEG.to_radians());
            wide_turns.1 += 1;
        }
        // a screened item is counted and logged by the session; the replay goes on
        let Ok(Some(step)) = session.push(&item) else { continue };
        heard |= step.outcomes.iter().any(|o| matches!(o, Some(onebeacon::nav::Outcome::Accepted(..))));
        if has_truth && step.truth.is_none() || !has_truth && !matches!(item.input, Input::Measurement(_)) {
            continue;
        }
        record(to_record(&step, session.last_beacon, heard))?;
        heard = false;
    }
    Ok(Replay { session, items, dropped: stream.dropped(), damage: stream.damage(), start, wide_turns })
}

/// An estimator's entry in a trajectory row (NED) with its error and NEES (NaN: none).
pub fn row_estimate(e: &onebeacon::nav::Estimate, (error_m, nees): (f64, f64)) -> Estimate {
    Estimate {
        vehicle: 0,
        pos: Vector3::new(e.north_m(), e.east_m(), 0.0),
        psi: e.heading_rad(),
        speed: None,
        sigma_pos: Vector2::new(e.sigma_north_m(), e.sigma_east_m()),
        error_m,
        nees,
    }
}

/// A trajectory row (NED) from a step.
fn to_record(step: &Step, beacon: Option<Vector3<f64>>, heard: bool) -> StepRecord {
    let truth = step.truth;
    let estimates = step
        .estimates
        .iter()
        .enumerate()
        .map(|(i, e)| row_estimate(e, step.errors.as_ref().map_or((f64::NAN, f64::NAN), |errors| errors[i])))
        .collect();
    StepRecord {
        t_s: step.t_s,
        truth: vec![TruthRecord {
            pos: truth.map_or(Vector3::repeat(f64::NAN), |p| Vector3::new(p.north_m, p.east_m, 0.0)),
            heading: truth.and_then(|p| p.heading_rad).unwrap_or(f64::NAN),
            speed: f64::NAN,
            sigma_m: truth.map_or(0.0, |p| p.sigma_m),
        }],
        beacon: beacon.unwrap_or(Vector3::repeat(f64::NAN)),
        frame: heard,
        estimates,
        pilots: Vec::new(),
    }
}
