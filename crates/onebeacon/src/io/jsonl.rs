//! JSON Lines for the onboard [`Session`] (feature `stream`): one item per input line
//! (SI units, the source's frame), one line of every estimator's estimate out per item.
//! What `onebeacon stream` runs, without the simulator, plotting or CSV machinery;
//! the line format is in docs/logs.md.

use crate::geo::Frame;
use crate::nav::session::{Input, Item, Step, TruthPose, resolve_beacon};
use crate::nav::{BeaconFix, Kind, Outcome};
use crate::vehicle::unit::{Plan, Unit};
use crate::vehicle::{Command, OwnFix, Phase};
use nalgebra::Vector3;
use serde_json::{Map, Value, json};
use std::collections::{BTreeMap, BTreeSet};
use std::io::{BufRead, Write};

/// A line that is not a valid item: what is wrong and what is allowed.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{0}")]
pub struct LineError(String);

/// One stream item as a JSON line (SI units, the log's frame).
pub fn item_json(item: &Item) -> Value {
    let t = item.t_s;
    match &item.input {
        Input::Measurement(m) => {
            let mut v = match m.clone() {
                Kind::Odometry { distance_m, heading_change_rad } => {
                    json!({"distance_m": distance_m, "heading_change_rad": heading_change_rad})
                }
                Kind::BodyOdometry { forward_m, lateral_m, heading_change_rad } => {
                    json!({"forward_m": forward_m, "lateral_m": lateral_m, "heading_change_rad": heading_change_rad})
                }
                Kind::Speed { speed_m_s } => json!({"speed_m_s": speed_m_s}),
                Kind::Heading { heading_rad } => json!({"heading_rad": heading_rad}),
                Kind::Depth { depth_m } => json!({"depth_m": depth_m}),
                Kind::Attitude { roll_rad, pitch_rad, heading_rad } => {
                    json!({"roll_rad": roll_rad, "pitch_rad": pitch_rad, "heading_rad": heading_rad})
                }
                Kind::BodyVelocity { nu } => json!({"nu": nu}),
                Kind::Inertial { heading_rad, yaw_rate_rad_s, accel_m_s2 } => {
                    json!({"heading_rad": heading_rad, "yaw_rate_rad_s": yaw_rate_rad_s, "accel_m_s2": accel_m_s2})
                }
                Kind::Range { range_m, .. } => json!({"range_m": range_m}),
                Kind::Doppler { radial_speed_m_s, .. } => json!({"radial_speed_m_s": radial_speed_m_s}),
                Kind::RangeDoppler { range_m, radial_speed_m_s, .. } => {
                    json!({"range_m": range_m, "radial_speed_m_s": radial_speed_m_s})
                }
                Kind::Bearing { station_heading_rad, azimuth_rad, elevation_rad, .. } => json!({
                    "station_heading_rad": station_heading_rad, "azimuth_rad": azimuth_rad,
                    "elevation_rad": elevation_rad}),
                Kind::Report { heading_rad, speed_m_s, depth_m } => {
                    json!({"heading_rad": heading_rad, "speed_m_s": speed_m_s, "depth_m": depth_m})
                }
                Kind::ArrayFix { range_m, azimuth_rad, inclination_rad, mode, .. } => json!({
                    "range_m": range_m, "azimuth_rad": azimuth_rad, "inclination_rad": inclination_rad, "mode": mode}),
                // raw hydrophone data is not streamed as JSON: its length only
                Kind::Capture(c) => {
                    json!({"elements": c.samples.len(), "samples": c.samples.first().map_or(0, Vec::len)})
                }
            };
            v["t_s"] = json!(t);
            v["kind"] = json!(m.name());
            if let Some(b) = m.beacon() {
                v["beacon"] = json!(b.id);
                if b.sigma_m > 0.0 {
                    v["beacon_sigma_m"] = json!(b.sigma_m);
                }
                if let Some(t_tx) = b.t_tx_s {
                    v["t_tx_s"] = json!(t_tx);
                }
            }
            v
        }
        Input::BeaconPosition { beacon_id, position } => json!({"t_s": t, "kind": "beacon_position",
            "beacon": beacon_id, "x_m": position.x, "y_m": position.y, "z_m": position.z}),
        Input::Truth(p) => {
            let mut v = json!({"t_s": t, "kind": "ground_truth", "x_m": p.north_m, "y_m": p.east_m});
            if let Some(h) = p.heading_rad {
                v["heading_rad"] = json!(h);
            }
            v
        }
    }
}

/// The kinds a line may have.
pub const KINDS: &str = "odometry, body_odometry, speed, heading, depth, attitude, body_velocity, inertial, range, doppler, \
    range_doppler, bearing, report, array_fix, beacon_position, ground_truth, own_fix";

/// The kinds as a list.
pub fn kinds() -> Vec<&'static str> {
    KINDS.split(", ").collect()
}

/// One parsed line: an item for the sessions (about vehicle `vehicle`, when the line
/// names one), or the vehicle's own fix (in the line's frame).
#[derive(Debug, Clone, PartialEq)]
pub enum Line {
    Item { vehicle: Option<usize>, item: Item },
    OwnFix { t_s: f64, fix: OwnFix },
}

/// Parses one JSON line into an item; `fixed` beacons resolve `beacon` ids, `tracked`
/// ones (the ids of the `beacon_position` items the session took so far) are resolved
/// by the session. The error names the key at fault and what is allowed.
pub fn parse_item(line: &str, fixed: &BTreeMap<u32, Vector3<f64>>, tracked: &BTreeSet<u32>) -> Result<Item, LineError> {
    match parse(line, fixed, tracked, 1).map_err(LineError)? {
        Line::Item { item, .. } => Ok(item),
        Line::OwnFix { .. } => Err(LineError("`own_fix` is a vehicle's own fix, not an item of a session".into())),
    }
}

/// Parses one JSON line of a stream whose computer estimates `vehicles` vehicles.
pub fn parse_line(
    line: &str,
    fixed: &BTreeMap<u32, Vector3<f64>>,
    tracked: &BTreeSet<u32>,
    vehicles: usize,
) -> Result<Line, LineError> {
    parse(line, fixed, tracked, vehicles).map_err(LineError)
}

fn parse(
    line: &str,
    beacons: &BTreeMap<u32, Vector3<f64>>,
    tracked: &BTreeSet<u32>,
    vehicles: usize,
) -> Result<Line, String> {
    let v: Map<String, Value> = serde_json::from_str(line).map_err(|e| format!("not a JSON object: {e}"))?;
    let finite = |key: &str, x: &Value| -> Result<f64, String> {
        x.as_f64().filter(|x| x.is_finite()).ok_or_else(|| format!("`{key}` = {x} is not a finite number"))
    };
    let num = |key: &str| -> Result<f64, String> {
        v.get(key).map_or_else(|| Err(format!("missing key `{key}`")), |x| finite(key, x))
    };
    let optional = |key: &str| v.get(key).map(|x| finite(key, x)).transpose();
    let kind = v.get("kind").and_then(Value::as_str).ok_or_else(|| format!("missing key `kind` (one of {KINDS})"))?;
    let t_s = num("t_s")?;
    let beacon_id = || -> Result<u32, String> {
        let id = v.get("beacon").and_then(Value::as_u64).and_then(|b| u32::try_from(b).ok());
        id.ok_or_else(|| "`beacon` must be a beacon id (a non-negative integer)".to_string())
    };
    let beacon = |tracked: &BTreeSet<u32>| -> Result<BeaconFix, String> {
        let mut b = resolve_beacon(beacon_id()?, beacons, tracked)?;
        b.sigma_m = optional("beacon_sigma_m")?.unwrap_or(0.0);
        if b.sigma_m < 0.0 {
            return Err(format!("`beacon_sigma_m` = {} must be >= 0", b.sigma_m));
        }
        b.t_tx_s = optional("t_tx_s")?;
        Ok(b)
    };
    let vehicle = match v.get("vehicle") {
        None => None,
        Some(x) => {
            let n = x.as_u64().and_then(|n| usize::try_from(n).ok()).filter(|n| *n < vehicles);
            Some(n.ok_or_else(|| format!("`vehicle` = {x} must be a vehicle index in 0..{vehicles}"))?)
        }
    };
    let m = Input::Measurement;
    let input = match kind {
        "odometry" => {
            m(Kind::Odometry { distance_m: num("distance_m")?, heading_change_rad: num("heading_change_rad")? })
        }
        "body_odometry" => m(Kind::BodyOdometry {
            forward_m: num("forward_m")?,
            lateral_m: num("lateral_m")?,
            heading_change_rad: num("heading_change_rad")?,
        }),
        "speed" => m(Kind::Speed { speed_m_s: num("speed_m_s")? }),
        "heading" => m(Kind::Heading { heading_rad: num("heading_rad")? }),
        "depth" => m(Kind::Depth { depth_m: num("depth_m")? }),
        "attitude" => m(Kind::Attitude {
            roll_rad: num("roll_rad")?,
            pitch_rad: num("pitch_rad")?,
            heading_rad: num("heading_rad")?,
        }),
        "body_velocity" => {
            let nu = v.get("nu").and_then(Value::as_array).filter(|a| a.len() == 6);
            let nu = nu.ok_or("`nu` must be [u, v, w, p, q, r] (m/s, rad/s)")?;
            let mut out = [0.0; 6];
            for (o, x) in out.iter_mut().zip(nu) {
                *o = finite("nu", x)?;
            }
            m(Kind::BodyVelocity { nu: out })
        }
        "inertial" => m(Kind::Inertial {
            heading_rad: num("heading_rad")?,
            yaw_rate_rad_s: num("yaw_rate_rad_s")?,
            accel_m_s2: num("accel_m_s2")?,
        }),
        "range" => m(Kind::Range { beacon: beacon(tracked)?, range_m: num("range_m")? }),
        "doppler" => m(Kind::Doppler { beacon: beacon(tracked)?, radial_speed_m_s: num("radial_speed_m_s")? }),
        "range_doppler" => m(Kind::RangeDoppler {
            beacon: beacon(tracked)?,
            range_m: num("range_m")?,
            radial_speed_m_s: num("radial_speed_m_s")?,
        }),
        "bearing" => m(Kind::Bearing {
            station: beacon(tracked)?,
            station_heading_rad: num("station_heading_rad")?,
            azimuth_rad: num("azimuth_rad")?,
            elevation_rad: num("elevation_rad")?,
        }),
        "report" => {
            m(Kind::Report { heading_rad: num("heading_rad")?, speed_m_s: num("speed_m_s")?, depth_m: num("depth_m")? })
        }
        "array_fix" => {
            let mode = v.get("mode").and_then(Value::as_u64).and_then(|m| usize::try_from(m).ok());
            m(Kind::ArrayFix {
                beacon: beacon(tracked)?,
                range_m: num("range_m")?,
                azimuth_rad: num("azimuth_rad")?,
                inclination_rad: num("inclination_rad")?,
                mode: mode.ok_or("`mode` must be a command mode index (a non-negative integer)")?,
            })
        }
        "own_fix" => {
            let fix = OwnFix {
                position_m: nalgebra::Vector2::new(num("x_m")?, num("y_m")?),
                heading_rad: num("heading_rad")?,
                speed_m_s: num("speed_m_s")?,
            };
            return Ok(Line::OwnFix { t_s, fix });
        }
        "beacon_position" => {
            let beacon_id = beacon_id()?;
            let z = optional("z_m")?.unwrap_or(0.0);
            Input::BeaconPosition { beacon_id, position: Vector3::new(num("x_m")?, num("y_m")?, z) }
        }
        "ground_truth" => {
            let heading_rad = optional("heading_rad")?;
            Input::Truth(TruthPose { north_m: num("x_m")?, east_m: num("y_m")?, heading_rad })
        }
        other => return Err(format!("unknown kind `{other}` (one of {KINDS})")),
    };
    Ok(Line::Item { vehicle, item: Item { t_s, input } })
}

/// One output line: every estimator's estimate (estimators `names`) after input line
/// `line`, in `frame` (the input's).
pub fn step_json(line: usize, step: &Step, names: &[String], frame: Frame) -> Value {
    let estimates: Vec<Value> = step
        .estimates
        .iter()
        .enumerate()
        .map(|(i, e)| {
            let (x, y, _) = frame.from_ned(&Vector3::new(e.north_m(), e.east_m(), 0.0));
            let (sx, sy, _) = frame.from_ned(&Vector3::new(e.sigma_north_m(), e.sigma_east_m(), 0.0));
            let mut v = json!({
                "name": names[i],
                "x_m": x,
                "y_m": y,
                "heading_rad": frame.heading_from_ned(e.heading_rad()),
                "sigma_x_m": sx.abs(),
                "sigma_y_m": sy.abs(),
            });
            for (k, x) in e.calibration() {
                v[k] = json!(x);
            }
            if let Some(o) = step.outcomes[i] {
                let (outcome, nis) = match o {
                    Outcome::Applied => ("applied", None),
                    Outcome::Accepted(n, _) => ("accepted", Some(n)),
                    Outcome::Rejected(n, _) => ("rejected", Some(n)),
                    Outcome::Skipped => ("skipped", None),
                    Outcome::Failed(_) => ("failed", None),
                };
                v["outcome"] = json!(outcome);
                if let Some(n) = nis {
                    v["nis"] = json!(n);
                }
            }
            if let Some((err, _)) = step.errors.as_ref().map(|e| e[i]) {
                v["error_m"] = json!(err);
            }
            v
        })
        .collect();
    json!({"line": line, "t_s": step.t_s, "estimates": estimates})
}

/// A command as a JSON object, in `frame` (the stream's): a path (`from`, `to`, and the
/// planner's waypoint and the vehicle it serves when `plan` is given), a waypoint, or a
/// setpoint with the confirmed mode (index into the bank, null before one) and phase.
pub fn command_json(command: &Command, plan: Option<Plan>, frame: Frame) -> Value {
    let point = |p: nalgebra::Vector2<f64>| {
        let (x, y, _) = frame.from_ned(&Vector3::new(p.x, p.y, 0.0));
        (x, y)
    };
    match *command {
        Command::Path { from, to } => {
            let ((fx, fy), (tx, ty)) = (point(from), point(to));
            let mut v = json!({"kind": "path", "from_x_m": fx, "from_y_m": fy, "to_x_m": tx, "to_y_m": ty});
            if let Some(p) = plan {
                let (wx, wy) = point(p.waypoint);
                v["waypoint_x_m"] = json!(wx);
                v["waypoint_y_m"] = json!(wy);
                v["serving"] = json!(p.vehicle);
            }
            v
        }
        Command::Waypoint { waypoint, arrive_s } => {
            let (x, y) = point(waypoint);
            json!({"kind": "waypoint", "x_m": x, "y_m": y, "arrive_s": arrive_s})
        }
        Command::Setpoint { setpoint, mode, phase } => json!({
            "kind": "setpoint",
            "heading_rad": frame.heading_from_ned(setpoint.heading_rad),
            "speed_m_s": setpoint.speed_m_s,
            "depth_m": setpoint.depth_m,
            "mode": mode,
            "phase": match phase {
                Phase::Waiting => "waiting",
                Phase::Driving => "driving",
                Phase::Drifting => "drifting",
                Phase::Surfacing => "surfacing",
            },
        }),
    }
}

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
    /// The line was taken, and something is worth saying (before the start, an
    /// estimator started again, the controller cannot decide yet).
    Info(String),
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
                let kind = match &item.input {
                    Input::Measurement(m) => m.name(),
                    Input::BeaconPosition { .. } => "beacon_position",
                    Input::Truth(_) => "ground_truth",
                };
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
                                Note::Info(format!(
                                    "{name}: its state stopped being finite and positive definite; started again from its last sound estimate"
                                )),
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
                    // before the start a controller has nothing to decide on
                    None if !unit.has_controller() => return None,
                    None => (item.t_s, kind, json!({"line": number, "t_s": item.t_s})),
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
    let mut say = |line: usize, n: Note| match n {
        Note::Skipped(m) | Note::Info(m) => report(line, &m),
    };
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
    use crate::nav::PlanarConfig;
    use crate::nav::planar::builder;
    use crate::nav::session::{Session, Start};

    fn unit(session: Session) -> Unit {
        Unit::new(vec![session], fixed(), Frame::Ned, None)
    }

    fn fixed() -> BTreeMap<u32, Vector3<f64>> {
        BTreeMap::from([(3, Vector3::new(10.0, -20.0, 5.0))])
    }

    /// Every kind written by `item_json` reads back as the same item.
    #[test]
    fn items_round_trip() {
        let b = BeaconFix { id: 3, position_ned_m: fixed()[&3], sigma_m: 0.5, t_tx_s: Some(1.25) };
        let kinds = [
            Kind::Odometry { distance_m: 0.3, heading_change_rad: -0.01 },
            Kind::Speed { speed_m_s: 1.2 },
            Kind::Heading { heading_rad: 0.7 },
            Kind::Depth { depth_m: 12.0 },
            Kind::Attitude { roll_rad: 0.01, pitch_rad: -0.02, heading_rad: 2.0 },
            Kind::BodyVelocity { nu: [1.0, 0.1, 0.0, 0.0, 0.0, 0.02] },
            Kind::Inertial { heading_rad: 1.0, yaw_rate_rad_s: 0.01, accel_m_s2: 0.001 },
            Kind::Range { beacon: b, range_m: 42.5 },
            Kind::Doppler { beacon: b, radial_speed_m_s: -0.4 },
            Kind::RangeDoppler { beacon: b, range_m: 42.5, radial_speed_m_s: -0.4 },
            Kind::Bearing { station: b, station_heading_rad: 0.3, azimuth_rad: -1.2, elevation_rad: 0.6 },
            Kind::Report { heading_rad: 1.1, speed_m_s: 1.5, depth_m: 30.0 },
            Kind::ArrayFix { beacon: b, range_m: 80.0, azimuth_rad: 0.4, inclination_rad: 1.7, mode: 2 },
        ];
        let mut items: Vec<Item> =
            kinds.iter().map(|k| Item { t_s: 2.5, input: Input::Measurement(k.clone()) }).collect();
        items.push(Item {
            t_s: 3.0,
            input: Input::BeaconPosition { beacon_id: 7, position: Vector3::new(1.0, 2.0, 0.5) },
        });
        items.push(Item {
            t_s: 3.5,
            input: Input::Truth(TruthPose { north_m: 4.0, east_m: 5.0, heading_rad: Some(0.25) }),
        });
        let tracked = BTreeSet::new();
        for item in &items {
            let line = item_json(item).to_string();
            assert_eq!(parse_item(&line, &fixed(), &tracked).as_ref(), Ok(item), "{line}");
        }
    }

    #[test]
    fn bad_lines_name_the_key_and_what_is_allowed() {
        let err = |line: &str| parse_item(line, &fixed(), &BTreeSet::new()).unwrap_err().to_string();
        assert!(err("{\"t_s\": 1, \"kind\": \"sonar\"}").contains("unknown kind `sonar` (one of odometry"));
        assert!(err("{\"t_s\": 1, \"kind\": \"speed\"}").contains("missing key `speed_m_s`"));
        assert!(err("{\"t_s\": 1, \"kind\": \"range\", \"beacon\": 9, \"range_m\": 3}").contains("beacon 9"));
        assert!(err("{\"t_s\": 1, \"kind\": \"depth\", \"depth_m\": \"deep\"}").contains("`depth_m`"));
        assert!(err("[1, 2]").contains("not a JSON object"));
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
