//! JSON Lines for the onboard session (feature `stream`): one item per input line
//! (SI units, the source's frame), one line of every estimator's estimate out per item.
//! What `onebeacon stream` runs, without the simulator, plotting or CSV machinery;
//! the line format is in docs/logs.md.

use crate::geo::Frame;
use crate::nav::session::{Input, Item, Step, TruthPose, resolve_beacon};
use crate::nav::{BeaconFix, Kind, Outcome};
use crate::vehicle::unit::Plan;
use crate::vehicle::{Command, OwnFix, Phase};
use nalgebra::Vector3;
use serde_json::{Map, Value, json};
use std::collections::{BTreeMap, BTreeSet};

/// A line that is not a valid item: what is wrong and what is allowed.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{0}")]
pub struct LineError(String);

/// A vehicle's own fix at `t_s` as a JSON line (`own_fix`; its frame as given).
fn own_fix_json(t_s: f64, fix: &OwnFix) -> Value {
    let p = fix.position_m;
    json!({"t_s": t_s, "kind": "own_fix", "x_m": p.x, "y_m": p.y, "heading_rad": fix.heading_rad,
        "speed_m_s": fix.speed_m_s})
}

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
            if p.sigma_m > 0.0 {
                v["sigma_m"] = json!(p.sigma_m);
            }
            v
        }
    }
}

pub use super::{KINDS, kinds};

/// One parsed line: an item for the sessions (about vehicle `vehicle`, when the line
/// names one), or the vehicle's own fix (in the line's frame).
#[derive(Debug, Clone, PartialEq)]
pub enum Line {
    Item { vehicle: Option<usize>, item: Item },
    OwnFix { t_s: f64, fix: OwnFix },
}

impl Line {
    /// Its time, s.
    pub fn t_s(&self) -> f64 {
        match self {
            Line::Item { item, .. } => item.t_s,
            Line::OwnFix { t_s, .. } => *t_s,
        }
    }
}

/// A line as JSON: an item with the vehicle it is about (when it names one), or an own
/// fix.
pub fn line_json(line: &Line) -> Value {
    match line {
        Line::Item { vehicle, item } => {
            let mut v = item_json(item);
            if let Some(i) = vehicle {
                v["vehicle"] = json!(i);
            }
            v
        }
        Line::OwnFix { t_s, fix } => own_fix_json(*t_s, fix),
    }
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
            let sigma_m = optional("sigma_m")?.unwrap_or(0.0);
            if !(sigma_m >= 0.0 && sigma_m.is_finite()) {
                return Err(format!("`sigma_m` is {sigma_m}: a reference's error, m, finite and >= 0"));
            }
            Input::Truth(TruthPose { north_m: num("x_m")?, east_m: num("y_m")?, heading_rad, sigma_m })
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
                // north-east covariance is x-y covariance in either frame (ENU swaps both axes)
                "cov_xy_m2": e.horizontal_cov_m2[(0, 1)],
                "sigma_heading_rad": e.heading_var_rad2.max(0.0).sqrt(),
            });
            for (k, x) in e.calibration.keys() {
                v[k] = json!(x);
            }
            if let Some(o) = step.outcomes[i] {
                let (outcome, nis) = match o {
                    Outcome::Applied => ("applied", None),
                    Outcome::Accepted(i) => ("accepted", Some(i.nis)),
                    Outcome::Rejected(i) => ("rejected", Some(i.nis)),
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

#[cfg(test)]
mod tests {
    use super::*;

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
        items.push(Item { t_s: 3.5, input: Input::Truth(TruthPose::exact(4.0, 5.0, Some(0.25))) });
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
}
