//! The stream loop of a vehicle's computer (feature `stream`): JSON lines in, through
//! its [`Unit`], one JSON line out per line, flushed; a bad line reported and skipped.
//! The line format is [`super::jsonl`]'s.

use super::jsonl::{Line, command_json, parse_line, step_json};
use crate::nav::session::Input;
use crate::vehicle::OwnFix;
use crate::vehicle::unit::Unit;
use serde_json::{Value, json};
use std::collections::BTreeSet;
use std::io::{BufRead, Write};

/// What a stream keeps from line to line: the beacons whose positions it was given, the
/// line count, whether it said that it waits for its start, and the controller's last
/// complaint (said once until it changes).
#[derive(Debug, Clone, Default)]
pub struct Lines {
    tracked: BTreeSet<u32>,
    number: usize,
    waiting_told: bool,
    undecided_told: Option<String>,
}

/// What [`Lines::push`] says of a line besides its output.
#[derive(Debug, Clone, PartialEq)]
pub enum Note {
    /// The line was skipped (not UTF-8, too long, not an item) or screened out by the
    /// session: why.
    Skipped(String),
    /// The line was taken, and something is worth saying (before the start, the
    /// controller cannot decide yet).
    Info(String),
    /// The line was taken, and `estimator` started again from its last sound estimate.
    Restarted { estimator: String, message: String },
}

impl Note {
    /// What it says, in a line.
    pub fn message(&self) -> &str {
        match self {
            Note::Skipped(m) | Note::Info(m) | Note::Restarted { message: m, .. } => m,
        }
    }
}

impl Lines {
    /// The lines so far.
    pub fn count(&self) -> usize {
        self.number
    }

    /// One input line (without its end; `too_long` when the reader cut it), into `unit`:
    /// the output line when there is one: the estimates of the line's session
    /// ([`step_json`], with `vehicle` when the unit estimates several), and with a
    /// controller its current command (`command`, [`command_json`]) and whether this line
    /// made it decide (`decided`). `note` gets the line's number and what there is to
    /// say of it. Nothing a line holds stops the stream or poisons the unit.
    pub fn push(
        &mut self,
        unit: &mut Unit,
        bytes: &[u8],
        too_long: bool,
        mut note: impl FnMut(usize, Note),
    ) -> Option<Value> {
        self.number += 1;
        let number = self.number;
        let mut skip = |m: String| {
            note(number, Note::Skipped(m));
            None
        };
        if too_long {
            let max = unit.session(0).limits().max_line_bytes;
            return skip(format!("longer than {max} bytes (limits.max_line_bytes); skipped"));
        }
        let Ok(line) = std::str::from_utf8(bytes) else { return skip("not UTF-8 text; skipped".into()) };
        if line.trim().is_empty() {
            return None;
        }
        let vehicles = unit.sessions().len();
        let parsed = match parse_line(line, &unit.fixed, &self.tracked, vehicles) {
            Ok(p) => p,
            Err(e) => return skip(format!("{e}; skipped")),
        };
        let (t_s, kind, mut out) = match parsed {
            Line::OwnFix { t_s, fix } => {
                let far = 1e8;
                if fix.position_m.iter().any(|v| v.abs() > far)
                    || fix.heading_rad.abs() > 1e6
                    || fix.speed_m_s.abs() > 1e3
                {
                    return skip("own_fix: a position beyond 1e8 m, a heading beyond 1e6 rad or a speed beyond 1000 m/s; skipped".into());
                }
                let p = unit.frame.to_ned(fix.position_m.x, fix.position_m.y, 0.0);
                let ned = OwnFix { position_m: p.xy(), heading_rad: unit.frame.heading_to_ned(fix.heading_rad), ..fix };
                unit.set_fix(ned);
                (t_s, "own_fix", json!({"line": number, "t_s": t_s}))
            }
            Line::Item { vehicle, item } => {
                let kind = item.input.name();
                let step = match unit.push(vehicle, &item) {
                    Ok(step) => step,
                    Err(screened) => return skip(format!("{screened}; screened out")),
                };
                if let Input::BeaconPosition { beacon_id, .. } = item.input {
                    self.tracked.insert(beacon_id);
                }
                let v = vehicle.unwrap_or(0);
                let session = unit.session(v);
                let out = match step {
                    None => {
                        if !std::mem::replace(&mut self.waiting_told, true) {
                            note(
                                number,
                                Note::Info(format!("before the start: waiting for {}", session.waiting_for())),
                            );
                        }
                        None
                    }
                    Some(step) => {
                        for &i in &step.reinitialised {
                            let name = &session.names[i];
                            note(
                                number,
                                Note::Restarted {
                                    estimator: name.clone(),
                                    message: format!(
                                        "{name}: its state stopped being finite and positive definite; started again from its last sound estimate"
                                    ),
                                },
                            );
                        }
                        let mut out = step_json(number, &step, &session.names, unit.frame);
                        if vehicles > 1 {
                            out["vehicle"] = json!(v);
                        }
                        Some(out)
                    }
                };
                match out {
                    Some(out) => (item.t_s, kind, out),
                    // before the start: a line all the same, saying so (a controller has
                    // nothing to decide on yet)
                    None => (item.t_s, kind, json!({"line": number, "t_s": item.t_s, "started": false})),
                }
            }
        };
        if !unit.has_controller() {
            return Some(out);
        }
        let decided = unit.decides_on(kind).then(|| unit.decide(t_s)).flatten();
        out["decided"] = json!(matches!(decided, Some(Ok(_))));
        match decided {
            Some(Err(e)) => {
                let m = format!("the controller cannot decide: {e}");
                if self.undecided_told.as_ref() != Some(&m) {
                    note(number, Note::Info(m.clone()));
                    self.undecided_told = Some(m);
                }
            }
            Some(Ok(_)) => self.undecided_told = None,
            None => {}
        }
        if let Some(c) = unit.command() {
            out["command"] = command_json(&c, unit.plan(), unit.frame);
        }
        Some(out)
    }

    /// At the end of the input: `note` is told when the stream never reached its start.
    pub fn finish(&self, unit: &Unit, mut note: impl FnMut(usize, Note)) {
        if let Some(session) = unit.sessions().iter().find(|s| !s.started()) {
            note(
                self.number,
                Note::Info(format!(
                    "the stream ended before the start ({}); no estimate was given",
                    session.waiting_for()
                )),
            );
        }
    }
}

/// Reads JSON Lines from `input` into `unit`, writing one output line ([`Lines::push`])
/// per line to `output`, flushed after each. Nothing a line holds stops the stream: a
/// line that is not UTF-8, longer than `limits.max_line_bytes`, not an item, or
/// screened out by the session (time order, limits, unknown beacon) is skipped, and
/// `report` gets its line number and why; so do an estimator started again, a
/// controller that cannot decide yet and a stream that never reaches its start. Memory
/// stays flat: one line is held at a time. Only an I/O error stops the stream.
pub fn run(
    unit: &mut Unit,
    mut input: impl BufRead,
    mut output: impl Write,
    mut report: impl FnMut(usize, &str),
) -> std::io::Result<()> {
    let max_line = unit.session(0).limits().max_line_bytes;
    let mut lines = Lines::default();
    let mut buf = Vec::new();
    let mut say = |line: usize, n: Note| report(line, n.message());
    loop {
        let (read, too_long) = read_line(&mut input, &mut buf, max_line)?;
        if read == 0 {
            break;
        }
        if let Some(out) = lines.push(unit, &buf, too_long, &mut say) {
            writeln!(output, "{out}")?;
            output.flush()?;
        }
    }
    lines.finish(unit, say);
    Ok(())
}

/// Reads one line (without its end) into `buf`, keeping at most `max` bytes: the bytes
/// read (0 at the end of the input) and whether the line was longer than `max`.
fn read_line(input: &mut impl BufRead, buf: &mut Vec<u8>, max: usize) -> std::io::Result<(usize, bool)> {
    buf.clear();
    let (mut read, mut too_long) = (0, false);
    loop {
        let available = match input.fill_buf() {
            Ok(a) => a,
            Err(e) if e.kind() == std::io::ErrorKind::Interrupted => continue,
            Err(e) => return Err(e),
        };
        if available.is_empty() {
            return Ok((read, too_long));
        }
        let end = available.iter().position(|&b| b == b'\n');
        let chunk = &available[..end.unwrap_or(available.len())];
        if too_long || buf.len() + chunk.len() > max {
            too_long = true;
            buf.clear();
        } else {
            buf.extend_from_slice(chunk);
        }
        let used = end.map_or(available.len(), |i| i + 1);
        read += used;
        input.consume(used);
        if end.is_some() {
            return Ok((read, too_long));
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::filter::FilterKind;
    use crate::geo::Frame;
    use crate::nav::PlanarConfig;
    use crate::nav::planar::builder;
    use crate::nav::session::{Session, Start};
    use nalgebra::Vector3;
    use std::collections::BTreeMap;

    fn fixed() -> BTreeMap<u32, Vector3<f64>> {
        BTreeMap::from([(3, Vector3::new(10.0, -20.0, 5.0))])
    }

    fn unit(session: Session) -> Unit {
        Unit::new(vec![session], fixed(), Frame::Ned, None)
    }

    /// A stream goes on past bad lines and lines out of time order, one output line per
    /// good item.
    #[test]
    fn run_skips_bad_lines_and_answers_every_good_one() {
        let config = PlanarConfig { aiding: crate::nav::Aiding::NONE, ..PlanarConfig::default() };
        let start = Start::At { t0_s: None, pose: (0.0, 0.0, 0.0) };
        let mut u = unit(Session::new(
            Frame::Ned,
            vec![("dr".into(), builder(config, FilterKind::Ekf))],
            start,
            (1.0, 0.1),
            None,
        ));
        let input = [
            r#"{"t_s": 0, "kind": "heading", "heading_rad": 0}"#,
            "not json",
            r#"{"t_s": 1, "kind": "odometry", "distance_m": 1.0, "heading_change_rad": 0}"#,
            "",
            r#"{"t_s": 0.5, "kind": "speed", "speed_m_s": 1}"#,
            r#"{"t_s": 2, "kind": "odometry", "distance_m": 1.0, "heading_change_rad": 0}"#,
        ]
        .join("\n");
        let mut out = Vec::new();
        let mut bad = Vec::new();
        run(&mut u, input.as_bytes(), &mut out, |n, e| bad.push((n, e.to_string()))).unwrap();
        assert_eq!(bad.iter().map(|b| b.0).collect::<Vec<_>>(), [2, 5]);
        assert!(bad[1].1.contains("before the previous item's; screened out"), "{}", bad[1].1);
        let lines: Vec<Value> =
            String::from_utf8(out).unwrap().lines().map(|l| serde_json::from_str(l).unwrap()).collect();
        assert_eq!(lines.len(), 3);
        assert_eq!(lines[2]["line"], 6);
        // two metres of odometry north
        let x = lines[2]["estimates"][0]["x_m"].as_f64().unwrap();
        assert!((x - 2.0).abs() < 1e-9, "{x}");
    }

    /// Every fault a line can carry is skipped with its reason, and the estimators end
    /// exactly where the stream without the faulty lines ends.
    #[test]
    fn faulty_lines_change_nothing() {
        let session = || {
            let start = Start::At { t0_s: None, pose: (0.0, 0.0, 0.0) };
            let config = PlanarConfig::default();
            Session::new(Frame::Ned, vec![("ekf".into(), builder(config, FilterKind::Ekf))], start, (1.0, 0.1), None)
        };
        let mut good: Vec<Vec<u8>> = Vec::new();
        for k in 0..40 {
            let t = k as f64;
            good.push(
                format!(r#"{{"t_s": {t}, "kind": "odometry", "distance_m": 1.0, "heading_change_rad": 0.0}}"#).into(),
            );
            if k % 5 == 4 {
                let r = ((10.0 - (k + 1) as f64).powi(2) + 20.0f64.powi(2) + 25.0).sqrt();
                good.push(format!(r#"{{"t_s": {t}, "kind": "range", "beacon": 3, "range_m": {r}}}"#).into());
            }
        }
        let faults: Vec<(Vec<u8>, &str)> = vec![
            (b"{\"t_s\": 20.5, \"kind\": \"speed\", \"speed_m_s\": \xff1}".to_vec(), "not UTF-8"),
            (vec![b'x'; 70_000], "longer than 65536 bytes"),
            (br#"{"t_s": 1e15, "kind": "speed", "speed_m_s": 1}"#.to_vec(), "jumps"),
            (br#"{"t_s": 20.5, "kind": "speed", "speed_m_s": 1e308}"#.to_vec(), "speed_m_s 1e308 is outside"),
            (br#"{"t_s": 20.5, "kind": "range", "beacon": 3, "range_m": 1e308}"#.to_vec(), "range 1e308 m"),
            (br#"{"t_s": 20.5, "kind": "doppler", "beacon": 3, "radial_speed_m_s": 1e308}"#.to_vec(), "outside"),
            (br#"{"t_s": 20.5, "kind": "beacon_position", "beacon": 8, "x_m": "far", "y_m": 0}"#.to_vec(), "`x_m`"),
            (br#"{"t_s": 20.5, "kind": "range", "beacon": 8, "range_m": 10}"#.to_vec(), "beacon 8"),
            (br#"{"t_s": 1.0, "kind": "speed", "speed_m_s": 1}"#.to_vec(), "before the previous"),
        ];
        let run_on = |lines: &[Vec<u8>]| {
            let mut u = unit(session());
            let (mut out, mut told) = (Vec::new(), Vec::new());
            let input = lines.join(&b'\n');
            run(&mut u, input.as_slice(), &mut out, |_, m| told.push(m.to_string())).unwrap();
            (u.session(0).final_estimates()[0], String::from_utf8(out).unwrap().lines().count(), told)
        };
        let (clean, clean_lines, clean_told) = run_on(&good);
        assert!(clean_told.is_empty(), "{clean_told:?}");
        let mut faulty = good.clone();
        let at = faulty.iter().position(|l| l.starts_with(br#"{"t_s": 20,"#)).unwrap() + 1;
        for (i, (line, _)) in faults.iter().enumerate() {
            faulty.insert(at + i, line.clone());
        }
        let (end, lines, told) = run_on(&faulty);
        assert_eq!(lines, clean_lines);
        assert_eq!(told.len(), faults.len(), "{told:?}");
        for ((_, expected), message) in faults.iter().zip(&told) {
            assert!(message.contains(expected), "{message:?} should say {expected:?}");
        }
        assert_eq!(end, clean);
        // the ranges pulled the estimate onto the truth (40 m north, beacon at 10, -20, 5)
        assert!((end.north_m() - 40.0).abs() < 1.0 && end.east_m().abs() < 1.0, "{:?}", end.position_ned_m);
    }

    /// A stream that starts from ground truth and never gets one says so.
    #[test]
    fn a_stream_that_never_starts_says_so() {
        let mut u = unit(Session::new(Frame::Ned, vec![], Start::FirstTruth, (1.0, 0.1), None));
        let input = r#"{"t_s": 0, "kind": "speed", "speed_m_s": 1}
{"t_s": 1, "kind": "speed", "speed_m_s": 1}"#;
        let mut told = Vec::new();
        run(&mut u, input.as_bytes(), std::io::sink(), |n, m| told.push((n, m.to_string()))).unwrap();
        assert_eq!(told.len(), 2, "{told:?}");
        assert!(told[0].1.contains("waiting for the first ground_truth item"));
        assert!(told[1].1.contains("ended before the start"));
    }
}
