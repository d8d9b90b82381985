//! `onebeacon replay` (a log through every estimator, scored against its ground truth)
//! and `onebeacon stream` (JSON Lines in, one estimate line out per line, flushed).

use crate::BadInput;
use crate::output::Staging;
use crate::{plot, report};
use anyhow::{Context, Result};
use onebeacon::nav::{BeaconFix, Estimate, Kind, Outcome};
use onebeacon_sim::replay::log::HeadingFrom;
use onebeacon_sim::replay::{
    Input, Item, Log, LogDescription, Session, Start, Step, TruthPose, new_session, replay as run_replay,
    resolve_beacon,
};
use serde_json::{Map, Value, json};
use std::collections::{BTreeMap, BTreeSet};
use std::io::{BufRead, Write};
use std::path::{Path, PathBuf};

/// One stream item as a JSON line (SI units, the log's frame).
pub fn item_json(item: &Item) -> Value {
    let t = item.t_s;
    match item.input {
        Input::Measurement(m) => {
            let mut v = match m {
                Kind::Odometry { distance_m, heading_change_rad } => {
                    json!({"distance_m": distance_m, "heading_change_rad": heading_change_rad})
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

const KINDS: &str = "odometry, speed, heading, depth, attitude, body_velocity, inertial, range, doppler, \
    range_doppler, beacon_position, ground_truth";

/// Parses one JSON line into an item; fixed beacons resolve `beacon` ids, tracked ones
/// (`beacon_position` lines seen so far) are resolved by the session.
fn parse_item(
    line: &str,
    beacons: &BTreeMap<u32, nalgebra::Vector3<f64>>,
    tracked: &mut BTreeSet<u32>,
) -> Result<Item, String> {
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
    let m = Input::Measurement;
    let input = match kind {
        "odometry" => {
            m(Kind::Odometry { distance_m: num("distance_m")?, heading_change_rad: num("heading_change_rad")? })
        }
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
        "beacon_position" => {
            let beacon_id = beacon_id()?;
            tracked.insert(beacon_id);
            let z = optional("z_m")?.unwrap_or(0.0);
            Input::BeaconPosition { beacon_id, position: nalgebra::Vector3::new(num("x_m")?, num("y_m")?, z) }
        }
        "ground_truth" => {
            let heading_rad = optional("heading_rad")?;
            Input::Truth(TruthPose { north_m: num("x_m")?, east_m: num("y_m")?, heading_rad })
        }
        other => return Err(format!("unknown kind `{other}` (one of {KINDS})")),
    };
    Ok(Item { t_s, input })
}

/// `--beacons` checked against the log's beacons.
fn beacon_filter(ids: Option<Vec<u32>>, known: &BTreeSet<u32>) -> Result<Option<BTreeSet<u32>>> {
    let Some(ids) = ids else { return Ok(None) };
    for id in &ids {
        if !known.contains(id) {
            let list: Vec<String> = known.iter().map(u32::to_string).collect();
            return Err(
                BadInput(format!("--beacons {id}: not a beacon of the log (beacons: {})", list.join(", "))).into()
            );
        }
    }
    Ok(Some(ids.into_iter().collect()))
}

/// `onebeacon replay LOG.toml [--out DIR] [--beacons 0,5] [--json] [--print-stream]`
pub fn replay(
    path: &Path,
    out: Option<PathBuf>,
    beacons: Option<Vec<u32>>,
    as_json: bool,
    print_stream: bool,
) -> Result<()> {
    let log = Log::load(path)?;
    if print_stream {
        let mut stdout = std::io::stdout().lock();
        for item in &log.items {
            writeln!(stdout, "{}", item_json(item))?;
        }
        return Ok(());
    }
    let known = log.beacon_ids();
    let filter = beacon_filter(beacons, &known)?;
    let used: Vec<u32> = filter.clone().map_or_else(|| known.iter().copied().collect(), |f| f.into_iter().collect());
    let suffix =
        filter.as_ref().map(|f| format!("-beacons-{}", f.iter().map(u32::to_string).collect::<Vec<_>>().join("-")));
    let name = &log.description.name;
    let dir = out.unwrap_or_else(|| PathBuf::from("out").join(format!("{name}-replay{}", suffix.unwrap_or_default())));
    let staging = Staging::new(&dir)?;

    let started = std::time::Instant::now();
    let r = run_replay(&log, filter)?;
    let wall_s = started.elapsed().as_secs_f64();
    let s = &r.session;
    let summary = summary_json(&log, &used, s, wall_s);

    staging.write("trajectory.csv", &report::trajectory_csv(&["auv".into()], &s.names, &r.trajectory)?)?;
    staging.write("summary.json", serde_json::to_string_pretty(&summary)?.as_bytes())?;
    staging.write("rejected.csv", &rejected_csv(s)?)?;
    let fixed: Vec<_> =
        used.iter().filter_map(|b| log.beacons.get(b)).map(|p| log.frame.to_ned(p.x, p.y, p.z)).collect();
    let title = format!("{name}, beacons {}", used.iter().map(u32::to_string).collect::<Vec<_>>().join(", "));
    plot::top_view(&staging.file("top_view.png"), &["auv".into()], &s.names, &title, &r.trajectory, Some(&fixed))
        .context("cannot draw top_view.png")?;
    plot::error_vs_time(&staging.file("error.png"), &s.names, &title, &r.trajectory)
        .context("cannot draw error.png")?;
    let files = staging.commit()?;

    if as_json {
        println!("{summary}");
        return Ok(());
    }
    println!("{title}: {} measurements, replayed in {:.1} ms", log.items.len(), wall_s * 1e3);
    // (header, summary key, decimals)
    const COLUMNS: [(&str, &str, usize); 11] = [
        ("rmse_m", "rmse_m", 3),
        ("mean_m", "mean_error_m", 3),
        ("final_m", "final_error_m", 3),
        ("max_m", "max_error_m", 3),
        ("rejected", "rejected", 0),
        ("bias_m", "range_bias_m", 3),
        ("k_range", "range_scale", 3),
        ("k_dist", "distance_scale", 3),
        ("k_turn", "turn_scale", 3),
        ("nees", "nees_mean", 1),
        ("in95_%", "nees_within_95_pct", 0),
    ];
    let header: String = COLUMNS.iter().map(|(h, _, _)| format!(" {h:>9}")).collect();
    println!("{:<20}{header}", "estimator");
    for e in summary["estimators"].as_array().into_iter().flatten() {
        let cells: String = COLUMNS
            .iter()
            .map(|(_, k, d)| e[*k].as_f64().map_or(format!(" {:>9}", "-"), |v| format!(" {v:>9.d$}", d = *d)))
            .collect();
        println!("{:<20}{cells}", e["name"].as_str().unwrap_or(""));
    }
    println!("wrote:");
    for f in files {
        println!("  {}", f.display());
    }
    Ok(())
}

/// The range and odometry calibration states of an estimate, as output keys.
fn calibration(e: &Estimate) -> [(&'static str, f64); 4] {
    [
        ("range_bias_m", e.range_bias_m),
        ("range_scale", e.range_scale),
        ("distance_scale", e.distance_scale),
        ("turn_scale", e.turn_scale),
    ]
}

fn summary_json(log: &Log, used: &[u32], s: &Session, wall_s: f64) -> Value {
    let num = |v: f64| if v.is_finite() { json!(v) } else { Value::Null };
    let finals = s.final_estimates();
    let estimators: Vec<Value> = s
        .names
        .iter()
        .zip(&s.stats)
        .zip(&finals)
        .map(|((name, st), e)| {
            let (x, y, _) = log.frame.from_ned(&nalgebra::Vector3::new(e.north_m(), e.east_m(), 0.0));
            let mut v = json!({
                "name": name,
                "rmse_m": num(st.rmse_m()),
                "mean_error_m": num(st.mean_m()),
                "final_error_m": if st.count > 0 { num(st.final_m) } else { Value::Null },
                "max_error_m": if st.count > 0 { num(st.max_m) } else { Value::Null },
                "rejected": st.rejected,
                "failed_updates": st.failed,
                "nees_mean": num(st.nees_mean()),
                "nees_within_95_pct": num(100.0 * st.nees_within_95_fraction()),
                "final": {"t_s": e.t_s, "x_m": x, "y_m": y, "heading_rad": log.frame.heading_from_ned(e.heading_rad())},
            });
            for (k, x) in calibration(e) {
                v[k] = num(x);
            }
            v
        })
        .collect();
    json!({
        "log": log.description.name,
        "beacons": used,
        "items": log.items.len(),
        "skipped_before_start": s.before_start,
        "left_out": s.left_out,
        "wall_s": wall_s,
        "estimators": estimators,
    })
}

fn rejected_csv(s: &Session) -> Result<Vec<u8>> {
    let mut w = csv::Writer::from_writer(Vec::new());
    w.write_record(["estimator", "t_s", "kind", "beacon", "value", "nis"])?;
    for r in &s.rejected {
        w.write_record([
            s.names[r.estimator].clone(),
            format!("{:.6}", r.t_s),
            r.kind.to_string(),
            r.beacon_id.to_string(),
            format!("{:.6}", r.value),
            format!("{:.3}", r.nis),
        ])?;
    }
    Ok(w.into_inner()?)
}

/// One output line: every estimator's estimate after an input line (the log's frame).
fn step_json(line: usize, step: &Step, s: &Session, frame: onebeacon::geo::Frame) -> Value {
    let estimates: Vec<Value> = step
        .estimates
        .iter()
        .enumerate()
        .map(|(i, e)| {
            let (x, y, _) = frame.from_ned(&nalgebra::Vector3::new(e.north_m(), e.east_m(), 0.0));
            let (sx, sy, _) = frame.from_ned(&nalgebra::Vector3::new(e.sigma_north_m(), e.sigma_east_m(), 0.0));
            let mut v = json!({
                "name": s.names[i],
                "x_m": x,
                "y_m": y,
                "heading_rad": frame.heading_from_ned(e.heading_rad()),
                "sigma_x_m": sx.abs(),
                "sigma_y_m": sy.abs(),
            });
            for (k, x) in calibration(e) {
                v[k] = json!(x);
            }
            if let Some(o) = step.outcomes[i] {
                let (outcome, nis) = match o {
                    Outcome::Applied => ("applied", None),
                    Outcome::Accepted(n) => ("accepted", Some(n)),
                    Outcome::Rejected(n) => ("rejected", Some(n)),
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

/// `onebeacon stream CONFIG.toml`: JSON Lines on stdin, one JSON line per estimate on
/// stdout, flushed after each; bad lines are reported on stderr and skipped.
pub fn stream(config: &Path) -> Result<()> {
    let d = LogDescription::load(config)?;
    let base = config.parent().unwrap_or(Path::new("."));
    let beacons = d.fixed_beacons(base)?;
    let frame = onebeacon::geo::Frame::from(d.frame);
    let init = &d.initial;
    let start = match init.given_pose(frame) {
        Some(pose) => Start::At { t0_s: None, pose },
        None if init.heading_from == HeadingFrom::Track => {
            return Err(BadInput(format!(
                "{}: key `initial.heading_from` = \"track\": needs the whole log; a stream starts from the first ground_truth line's heading (\"column\") or a given pose",
                config.display()
            ))
            .into());
        }
        None => Start::FirstTruth,
    };
    let mut session = new_session(&d, start, None);
    let mut tracked = BTreeSet::new();
    let stdin = std::io::stdin().lock();
    let mut stdout = std::io::stdout().lock();
    let mut last_t = f64::NEG_INFINITY;
    for (n, line) in stdin.lines().enumerate() {
        let number = n + 1;
        let line = line.context("cannot read stdin")?;
        if line.trim().is_empty() {
            continue;
        }
        let item = match parse_item(&line, &beacons, &mut tracked) {
            Ok(item) if item.t_s < last_t => Err(format!("time {} is before {last_t} on an earlier line", item.t_s)),
            other => other,
        };
        let item = match item {
            Ok(item) => item,
            Err(e) => {
                eprintln!("stdin line {number}: {e}; skipped");
                continue;
            }
        };
        last_t = item.t_s;
        if let Some(step) = session.push(&item) {
            writeln!(stdout, "{}", step_json(number, &step, &session, frame))?;
            stdout.flush()?;
        }
    }
    Ok(())
}
