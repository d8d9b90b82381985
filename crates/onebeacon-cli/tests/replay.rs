//! `onebeacon replay` and `onebeacon stream` on the real plaza logs (data/plaza), and
//! their bad input.

use crate::common::{bin, run, scratch, text};
use serde_json::Value;
use std::io::Write;
use std::path::Path;
use std::process::{Output, Stdio};

fn plaza(n: u8) -> String {
    Path::new(env!("CARGO_MANIFEST_DIR")).join(format!("../../data/plaza/plaza{n}.toml")).display().to_string()
}

/// `sea-fit` on plaza2 gives what data/plaza/README.md measured on the files by other
/// means (a least-squares line per beacon, a fit of the whole track's turns): ranges
/// 1.068-1.071 times the distance, a robust residual sigma of 0.51-0.62 m, turns 0.954
/// times the reported; each within what separates the two methods (the scale to 0.005,
/// sigma to 0.05 m, the turn scale to 0.006). And it writes sea.toml and sea-fit.json.
#[test]
fn sea_fit_on_plaza2_finds_what_was_measured_on_its_files() {
    let dir = scratch("sea-fit");
    let out = dir.join("sea");
    let o = run(&["sea-fit", &plaza(2), "--json", "--out", out.to_str().unwrap()]);
    assert!(o.status.success(), "{}", text(&o.stderr));
    let j: Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(j["reference"], "ground truth");
    let ranges = j["ranges"].as_array().unwrap();
    assert_eq!(ranges.len(), 4);
    for r in ranges {
        let k = r["scale"]["value"].as_f64().unwrap();
        assert!((0.063..=0.076).contains(&k), "{r}");
        let s = r["sigma_m"]["value"].as_f64().unwrap();
        assert!((0.46..=0.67).contains(&s), "{r}");
    }
    let turn = j["odometry"]["turn_scale"]["value"].as_f64().unwrap();
    assert!((turn - (0.954 - 1.0)).abs() < 0.006, "{turn}");
    let toml = std::fs::read_to_string(out.join("sea.toml")).unwrap();
    let table: toml::Table = toml::from_str(&toml).unwrap();
    assert!(table["sea"]["link"]["loss_prob"].as_float().is_some(), "{toml}");
    assert!(toml.contains("# fit (") && toml.contains("95 % ["), "{toml}");
    assert!(out.join("sea-fit.json").is_file());
}

/// `twin` of plaza2 with the sea `sea-fit` finds on plaza1: every (beacon set,
/// estimator) cell (dead reckoning once: 9 + 4 x 8), each with its band, the agreement
/// counted, twin.csv and twin.png written; the same JSON on one thread as on two, and
/// from three shards (`--shard I/3`, then `--merge`); a merge short of a shard is refused
/// in one line, exit 2.
#[test]
fn twin_of_plaza2_with_plaza1s_sea() {
    let dir = scratch("twin");
    let sea = dir.join("sea");
    assert!(run(&["sea-fit", &plaza(1), "--json", "--out", sea.to_str().unwrap()]).status.success());
    let sea_toml = sea.join("sea.toml");
    let twin = |threads: &str, out: &str| {
        let out = dir.join(out);
        let args = ["twin", &plaza(2), "--sea", sea_toml.to_str().unwrap(), "--runs", "4", "--json"];
        let o = run(&[&args[..], &["--threads", threads, "--out", out.to_str().unwrap()]].concat());
        assert!(o.status.success(), "{}", text(&o.stderr));
        (serde_json::from_slice::<Value>(&o.stdout).unwrap(), out)
    };
    let (j, out) = twin("1", "one");
    let cells = j["cells"].as_array().unwrap();
    assert_eq!(cells.len(), 9 + 4 * 8, "{j}");
    assert_eq!(cells.iter().filter(|c| c["estimator"] == "dead-reckoning").count(), 1);
    for c in cells {
        let b = &c["twin"]["rmse_m"];
        assert!(b["p5"].as_f64().unwrap() <= b["median"].as_f64().unwrap(), "{c}");
        assert!(b["median"].as_f64().unwrap() <= b["p95"].as_f64().unwrap(), "{c}");
    }
    assert_eq!(j["agreement"]["cells"], 41);
    assert!(out.join("twin.csv").is_file() && out.join("twin.png").is_file());
    let (mut two, _) = twin("2", "two");
    two["wall_s"] = j["wall_s"].clone();
    assert_eq!(two, j);
    let shards = dir.join("shards");
    let base = ["twin", &plaza(2), "--sea", sea_toml.to_str().unwrap()];
    for i in 0..3 {
        let shard = format!("{i}/3");
        let o = run(&[&base[..], &["--runs", "4", "--shard", &shard, "--out", shards.to_str().unwrap()]].concat());
        assert!(o.status.success(), "{}", text(&o.stderr));
    }
    let merged = dir.join("merged");
    let o =
        run(&[&base[..], &["--merge", shards.to_str().unwrap(), "--json", "--out", merged.to_str().unwrap()]].concat());
    assert!(o.status.success(), "{}", text(&o.stderr));
    let mut from_shards: Value = serde_json::from_slice(&o.stdout).unwrap();
    from_shards["wall_s"] = j["wall_s"].clone();
    assert_eq!(from_shards, j);
    assert!(merged.join("twin.csv").is_file() && merged.join("twin.png").is_file());
    let two_of_three: Vec<String> =
        (0..2).map(|i| shards.join(format!("partial-{i}-of-3.json")).display().to_string()).collect();
    let o = run(&[&base[..], &["--merge"], &two_of_three.iter().map(String::as_str).collect::<Vec<_>>()[..]].concat());
    assert_eq!(o.status.code(), Some(2));
    let err = text(&o.stderr);
    assert!(err.contains("missing shard(s) 2 of 3") && err.trim().lines().count() == 1, "{err}");
}

/// `onebeacon stream CONFIG` fed `input` on stdin (from a thread, so a large input
/// cannot block on a full stdout pipe).
fn stream(config: &str, input: Vec<u8>) -> Output {
    let mut child = bin()
        .args(["stream", config])
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let mut stdin = child.stdin.take().unwrap();
    let writer = std::thread::spawn(move || stdin.write_all(&input).unwrap());
    let o = child.wait_with_output().unwrap();
    writer.join().unwrap();
    o
}

/// `replay --json` (files into `out`): estimator name -> summary object.
fn replay_json(log: &str, beacons: Option<&str>, out: &Path) -> Vec<Value> {
    let out = out.display().to_string();
    let mut args = vec!["replay", log, "--json", "--out", &out];
    if let Some(b) = beacons {
        args.extend(["--beacons", b]);
    }
    let o = run(&args);
    assert!(o.status.success(), "{}", text(&o.stderr));
    let v: Value = serde_json::from_slice(&o.stdout).unwrap();
    v["estimators"].as_array().unwrap().clone()
}

/// From `trajectory.csv`'s column `<name>_nees`: its mean over the rows where it is
/// finite, and the percentage of those rows within chi^2(2)'s 95 % quantile (5.991) with
/// the fraction of rows printed too close to the bound to tell.
fn nees_of_rows(csv: &Path, name: &str) -> (f64, (f64, f64)) {
    let text = std::fs::read_to_string(csv).unwrap();
    let mut lines = text.lines();
    let column = format!("{name}_nees");
    let k = lines.next().unwrap().split(',').position(|c| c == column).unwrap_or_else(|| panic!("no {column}"));
    let values: Vec<f64> =
        lines.filter_map(|l| l.split(',').nth(k)?.parse::<f64>().ok()).filter(|v| v.is_finite()).collect();
    let bound = 5.991_464_547_107_979; // -2 ln 0.05
    let within = values.iter().filter(|&&v| v <= bound).count();
    let close = values.iter().filter(|&&v| (v - bound).abs() <= 1e-3 * bound).count();
    let n = values.len() as f64;
    (values.iter().sum::<f64>() / n, (100.0 * within as f64 / n, close.max(1) as f64 / n))
}

fn rmse(estimators: &[Value], name: &str) -> f64 {
    estimators.iter().find(|e| e["name"] == name).unwrap()["rmse_m"].as_f64().unwrap()
}

/// Per-beacon range offsets (`estimate_beacon_offsets`) are in the console table's
/// lines as in `--json`, one line per estimator that has them, every beacon heard.
#[test]
fn beacon_offsets_are_printed_as_in_the_json() {
    let dir = scratch("offsets");
    let est = dir.join("est.toml");
    std::fs::write(&est, "[[estimators]]\nname = \"offsets\"\nkind = \"range-ekf\"\nestimate_beacon_offsets = true\n")
        .unwrap();
    let (out, est) = (dir.join("out").display().to_string(), est.display().to_string());
    let o = run(&["replay", &plaza(1), "--estimators", &est, "--out", &out, "--json"]);
    assert!(o.status.success(), "{}", text(&o.stderr));
    let v: Value = serde_json::from_slice(&o.stdout).unwrap();
    let offsets = v["estimators"][0]["beacon_offsets"].as_object().unwrap().clone();
    let o = run(&["replay", &plaza(1), "--estimators", &est, "--out", &out]);
    let table = text(&o.stdout);
    let line =
        table.lines().find(|l| l.starts_with("offsets: range offsets, m: ")).unwrap_or_else(|| panic!("{table}"));
    assert_eq!(offsets.len(), 4, "{offsets:?}");
    for (b, e) in &offsets {
        let want =
            format!("beacon {b} {:+.3} (sigma {:.3})", e["offset_m"].as_f64().unwrap(), e["sigma_m"].as_f64().unwrap());
        assert!(line.contains(&want), "{want} not in {line}");
    }
}

/// The issue's targets that the data allow (see the closing note for the table): all
/// four beacons within 1.5 m RMSE on both logs, with the bias estimated and with the
/// calibration states; on plaza2, where dead reckoning drifts (32 m RMSE), each single
/// beacon brings the calibrated filter under a fifth of it. In sample: ekf-cal's two
/// noise values were chosen on a grid over these two logs (plaza1.toml), so its bounds
/// here hold on the data they were tuned on; the out-of-sample check is ekf-cal-oos
/// (noise fitted on plaza2, run on plaza1) at the end.
#[test]
fn plaza_all_beacons_and_single_beacons() {
    let dir = scratch("plaza");
    let find = |all: &[Value], name: &str, key: &str| all.iter().find(|e| e["name"] == name).unwrap()[key].clone();
    for n in [1, 2] {
        let all = replay_json(&plaza(n), None, &dir.join(format!("all{n}")));
        for name in ["ekf-bias", "ekf-bias-gated", "ekf-cal", "ekf-cal-gated"] {
            assert!(rmse(&all, name) <= 1.5, "plaza{n} {name}: {all:?}");
        }
        // an offset alone lands near the data's +2.8 m; the calibrated filter finds
        // that the ranges read about 7 % long instead
        let bias = find(&all, "ekf-bias", "range_bias_m").as_f64().unwrap();
        assert!((1.5..4.0).contains(&bias), "plaza{n} bias {bias}");
        let scale = find(&all, "ekf-cal", "range_scale").as_f64().unwrap();
        assert!((0.06..0.08).contains(&scale), "plaza{n} range scale {scale}");
        // without the bias the gate rejects many true ranges; with it, next to none
        let rejected = |name: &str| find(&all, name, "rejected").as_u64().unwrap();
        assert!(rejected("ekf-gated") > 10 * rejected("ekf-bias-gated").max(1));
        // the consistency figures are there; the filter is overconfident on real data
        // (closing note), the plain EKF far more than the calibrated one
        let nees = |name: &str| find(&all, name, "nees_mean").as_f64().unwrap();
        assert!(nees("ekf-cal") > 2.0 && nees("ekf") > 2.0 * nees("ekf-cal"), "plaza{n}");
        // the summary's NEES figures are those of trajectory.csv's rows, counted here
        let (mean, within) = nees_of_rows(&dir.join(format!("all{n}")).join("trajectory.csv"), "ekf-cal");
        assert!(
            (nees("ekf-cal") - mean).abs() <= 1e-3 * mean,
            "plaza{n}: mean NEES {} against the rows' {mean}",
            nees("ekf-cal")
        );
        let reported = find(&all, "ekf-cal", "nees_within_95_pct").as_f64().unwrap();
        // a row printed within rounding of the bound may fall either side of it
        assert!((reported - within.0).abs() <= 100.0 * within.1, "plaza{n}: {reported} % within, rows give {within:?}");
    }
    let dr = rmse(&replay_json(&plaza(2), None, &dir.join("dr")), "dead-reckoning");
    for b in ["0", "1", "5", "6"] {
        let single = replay_json(&plaza(2), Some(b), &dir.join(format!("b{b}")));
        assert!(rmse(&single, "ekf-cal") <= dr / 5.0, "beacon {b}: {single:?} vs {dr}");
        // the turn scale found from one beacon is the plaza2 odometry's (-4.6 % by a
        // least-squares fit of the whole track)
        let turn = find(&single, "ekf-cal", "turn_scale").as_f64().unwrap();
        assert!((-0.06..-0.03).contains(&turn), "beacon {b}: turn scale {turn}");
    }
    // plaza1's filter with noise fitted on plaza2 (ekf-cal-oos): consistent (95 % of its
    // rows within the 95 % NEES bound where 95 % are expected; ekf-cal, fitted on both
    // logs, has 42 %) and better than dead reckoning with every beacon alone
    let all = replay_json(&plaza(1), None, &dir.join("oos"));
    let within = find(&all, "ekf-cal-oos", "nees_within_95_pct").as_f64().unwrap();
    assert!(within >= 90.0, "plaza1 ekf-cal-oos: {within} % of rows within the NEES bound");
    let dr = rmse(&all, "dead-reckoning");
    for b in ["0", "1", "5", "6"] {
        let single = replay_json(&plaza(1), Some(b), &dir.join(format!("oos{b}")));
        assert!(rmse(&single, "ekf-cal-oos") < dr, "plaza1 beacon {b}: {single:?} vs {dr}");
    }
    // the outputs are all there
    for f in ["trajectory.csv", "summary.json", "rejected.csv", "top_view.png", "error.png"] {
        assert!(dir.join("all1").join(f).is_file(), "{f}");
    }
}

/// The merged stream of a log, piped through `stream`, gives the replay's estimates:
/// the same final estimates to the bit, and the same RMSE from the per-line errors.
#[test]
fn streaming_equals_replay() {
    let dir = scratch("stream");
    let log = plaza(1);
    let summary = replay_json(&log, None, &dir.join("out"));
    let items = run(&["replay", &log, "--print-stream"]);
    assert!(items.status.success());
    let o = stream(&log, items.stdout.clone());
    assert!(o.status.success(), "{}", text(&o.stderr));
    let lines: Vec<Value> = text(&o.stdout).lines().map(|l| serde_json::from_str(l).unwrap()).collect();
    assert!(lines.len() > 20_000);
    let last = lines.last().unwrap()["estimates"].as_array().unwrap();
    for (s, e) in summary.iter().zip(last) {
        assert_eq!(s["name"], e["name"]);
        for k in ["x_m", "y_m", "heading_rad"] {
            assert_eq!(s["final"][k].as_f64(), e[k].as_f64(), "{} {k}", s["name"]);
        }
        let errors: Vec<f64> = lines
            .iter()
            .filter_map(|l| l["estimates"].as_array().unwrap().iter().find(|x| x["name"] == s["name"]))
            .filter_map(|x| x["error_m"].as_f64())
            .collect();
        let r = (errors.iter().map(|e| e * e).sum::<f64>() / errors.len() as f64).sqrt();
        assert!((r - s["rmse_m"].as_f64().unwrap()).abs() < 1e-9 * r, "{} {r}", s["name"]);
    }
}

/// A log description in `dir/case` over a CSV of ranges `ranges` (and `extra` keys on
/// its source), plus a clean odometry file.
fn bad_log(dir: &Path, case: &str, ranges: &str, extra: &str) -> String {
    let dir = &dir.join(case.replace(' ', "-"));
    std::fs::create_dir_all(dir).unwrap();
    std::fs::write(dir.join("odo.csv"), "t,d,dh\n1.0,0.1,0.0\n2.0,0.1,0.0\n").unwrap();
    std::fs::write(dir.join("ranges.csv"), ranges).unwrap();
    let toml = format!(
        r#"name = "bad"
frame = "enu"
[[source]]
kind = "odometry"
file = "odo.csv"
time = "t"
distance = "d"
heading_change = "dh"
[[source]]
kind = "range"
file = "ranges.csv"
time = "t"
beacon = "id"
range = "r"
{extra}
[[beacon]]
id = 0
x_m = 10.0
y_m = 0.0
[initial]
from = "given"
x_m = 0.0
y_m = 0.0
heading_deg = 0.0
[[estimator]]
name = "ekf"
kind = "range_ekf"
"#
    );
    let path = dir.join("log.toml");
    std::fs::write(&path, toml).unwrap();
    path.display().to_string()
}

#[test]
fn bad_logs_exit_2_with_one_line_naming_file_line_and_column() {
    let dir = scratch("bad");
    let good = "t,id,r\n1.5,0,10.0\n";
    let cases: Vec<(&str, String, &str)> = vec![
        ("missing column", bad_log(&dir, "missing column", "t,beacon,r\n1.5,0,10.0\n", ""), "no column `id`"),
        (
            "not a number",
            bad_log(&dir, "not a number", "t,id,r\n1.5,0,ten\n", ""),
            "line 2, column `r`: `ten` is not a number",
        ),
        (
            // found while replaying, not when loading: the files are read as streams
            "bad row late in the file",
            bad_log(&dir, "late row", "t,id,r\n1.5,0,10.0\n1.7,0,10.0\n1.9,0,ten\n", ""),
            "line 4, column `r`: `ten` is not a number",
        ),
        ("NaN cell", bad_log(&dir, "NaN cell", "t,id,r\n1.5,0,NaN\n", ""), "line 2, column `r`: `NaN` is not finite"),
        (
            "time backwards",
            bad_log(&dir, "time backwards", "t,id,r\n1.5,0,10.0\n1.2,0,10.0\n", ""),
            "line 3, column `t`: time 1.2 is before 1.5",
        ),
        (
            "unknown beacon",
            bad_log(&dir, "unknown beacon", "t,id,r\n1.5,7,10.0\n", ""),
            "line 2, column `id`: beacon 7 is not among the beacons (0)",
        ),
        ("missing file", bad_log(&dir, "missing file", good, "").replace("log.toml", "nope.toml"), "nope.toml"),
        (
            "not a CSV",
            bad_log(&dir, "not a CSV", &format!("t,id,r\n1.5,0,{}\n", "9".repeat(2 << 20)), ""),
            "a line longer than 1048576 bytes: not a CSV file",
        ),
    ];
    for (label, path, expected) in cases {
        let o = run(&["replay", &path, "--out", &dir.join("out").display().to_string()]);
        let err = text(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{label}: {err}");
        assert_eq!(err.trim().lines().count(), 1, "{label}: {err}");
        assert!(err.contains(expected), "{label}: {err}");
        assert!(!dir.join("out").exists(), "{label}: nothing half-written");
    }
    // unknown measurement kind and a key of another kind, in the description
    let path = bad_log(&dir, "kind", good, "");
    let text_toml = std::fs::read_to_string(&path).unwrap();
    std::fs::write(&path, text_toml.replace("kind = \"range\"", "kind = \"sonar\"")).unwrap();
    let o = run(&["replay", &path]);
    assert_eq!(o.status.code(), Some(2));
    assert!(text(&o.stderr).contains("unknown variant `sonar`"), "{}", text(&o.stderr));
    let path = bad_log(&dir, "key", good, "speed = \"v\"");
    let o = run(&["replay", &path]);
    assert_eq!(o.status.code(), Some(2));
    assert!(text(&o.stderr).contains("source[1].speed"), "{}", text(&o.stderr));
    // a beacon the log does not have
    let o = run(&["replay", &plaza(1), "--beacons", "3"]);
    assert_eq!(o.status.code(), Some(2));
    assert!(text(&o.stderr).contains("--beacons 3: not a beacon of the log (beacons: 0, 1, 5, 6)"));
}

#[test]
fn stream_reports_bad_lines_and_goes_on() {
    let dir = scratch("stream-bad");
    let path = bad_log(&dir, "stream", "t,id,r\n1.5,0,10.0\n", "");
    let input = [
        r#"{"t_s": 1.0, "kind": "odometry", "distance_m": 0.5, "heading_change_rad": 0.0}"#,
        r#"{"t_s": 1.1, "kind": "sonar"}"#,
        r#"not json"#,
        r#"{"t_s": 1.2, "kind": "range", "beacon": 4, "range_m": 9.0}"#,
        r#"{"t_s": 0.5, "kind": "range", "beacon": 0, "range_m": 9.0}"#,
        r#"{"t_s": 1.3, "kind": "range", "beacon": 0, "range_m": "x"}"#,
        r#"{"t_s": 2.0, "kind": "range", "beacon": 0, "range_m": 9.6}"#,
    ]
    .join("\n");
    let o = stream(&path, input.into_bytes());
    assert!(o.status.success());
    let err = text(&o.stderr);
    for (line, what) in
        [(2, "unknown kind `sonar`"), (3, "not a JSON object"), (4, "beacon 4"), (5, "before"), (6, "`range_m`")]
    {
        assert!(err.contains(&format!("stdin line {line}: ")) && err.contains(what), "{line}: {err}");
    }
    let out: Vec<Value> = text(&o.stdout).lines().map(|l| serde_json::from_str(l).unwrap()).collect();
    assert_eq!(out.iter().map(|l| l["line"].as_u64().unwrap()).collect::<Vec<_>>(), vec![1, 7]);
    assert_eq!(out[1]["estimates"][0]["outcome"], "accepted");
}

/// A reader that quits early (`| head`) ends the command quietly: no panic, no error
/// message, for the printed table and for the printed stream alike.
#[test]
fn closed_pipe_ends_quietly() {
    let dir = scratch("pipe");
    let out = dir.join("out").display().to_string();
    for args in [vec!["replay", &plaza(1), "--out", &out], vec!["replay", &plaza(1), "--print-stream"]] {
        let mut child = bin().args(&args).stdout(Stdio::piped()).stderr(Stdio::piped()).spawn().unwrap();
        drop(child.stdout.take()); // the reader is gone before the first line
        let o = child.wait_with_output().unwrap();
        // what the replay finds of the log (its warnings), nothing of the pipe
        let err = text(&o.stderr);
        assert!(err.lines().all(|l| l.starts_with("warning: ")), "{args:?}: {err}");
        assert!(o.status.success() || o.status.code().is_none(), "{args:?}: {:?}", o.status);
    }
}

/// Plaza 1 as loggers write it: odometry stamped with the UTC time of day (and a date),
/// ranges in UNIX milliseconds, the ground truth in ISO 8601, truth and beacons in
/// latitude and longitude about a point near Pittsburgh (converted with WGS-84 by
/// `map_3d`, the reverse of what the reader does). Every estimator's figures and final
/// position agree with the metric log to 1 cm.
#[test]
fn plaza_with_clock_times_and_latitudes_replays_as_the_metric_log() {
    let dir = scratch("latlon");
    let data = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../data/plaza");
    let (lat0, lon0) = (40.4433f64, -79.9436f64);
    let day_s = 1_623_628_800.0; // 2021-06-14 00:00:00 UTC
    let to_latlon = |x: f64, y: f64| {
        let (lat, lon, _) =
            map_3d::ned2geodetic(y, x, 0.0, lat0.to_radians(), lon0.to_radians(), 0.0, map_3d::Ellipsoid::WGS84);
        (lat.to_degrees(), lon.to_degrees())
    };
    let clock = |t: f64| {
        let (whole, frac) = (t.floor(), t - t.floor());
        let w = whole as u64;
        format!("{:02}:{:02}:{:02}.{:06}", w / 3600, w / 60 % 60, w % 60, (frac * 1e6).round() as u64)
    };
    let rows = |file: &str| -> Vec<Vec<f64>> {
        let text = std::fs::read_to_string(data.join(file)).unwrap();
        text.lines().skip(1).map(|l| l.split(',').map(|c| c.trim().parse().unwrap()).collect()).collect()
    };
    let mut odo = String::from("utc,d,dh\n");
    for r in rows("plaza1_odometry.csv") {
        odo += &format!("{},{},{}\n", clock(r[0]), r[1], r[2]);
    }
    let mut ranges = String::from("unix_ms,id,r\n");
    for r in rows("plaza1_ranges.csv") {
        ranges += &format!("{},{},{}\n", ((day_s + r[0]) * 1e3).round() as u64, r[1], r[2]);
    }
    let mut truth = String::from("time,lat,lon,yaw\n");
    for r in rows("plaza1_ground_truth.csv") {
        let (lat, lon) = to_latlon(r[1], r[2]);
        truth += &format!("2021-06-14T{}Z,{lat:.11},{lon:.11},{}\n", clock(r[0]), r[3]);
    }
    let mut beacons = String::from("id,lat,lon\n");
    for r in rows("plaza1_beacons.csv") {
        let (lat, lon) = to_latlon(r[1], r[2]);
        beacons += &format!("{},{lat:.11},{lon:.11}\n", r[0]);
    }
    for (f, t) in [("odo.csv", odo), ("ranges.csv", ranges), ("truth.csv", truth), ("beacons.csv", beacons)] {
        std::fs::write(dir.join(f), t).unwrap();
    }
    let metric = std::fs::read_to_string(plaza(1)).unwrap();
    let rest = &metric[metric.find("[initial]").unwrap()..];
    let toml = format!(
        r#"name = "plaza1-latlon"
frame = "enu"
[origin]
lat_deg = {lat0}
lon_deg = {lon0}
[[source]]
kind = "odometry"
file = "odo.csv"
time = "utc"
time_format = "%H:%M:%S%.f"
date = "2021-06-14"
distance = "d"
heading_change = "dh"
[[source]]
kind = "range"
file = "ranges.csv"
time = "unix_ms"
time_unit = "ms"
beacon = "id"
range = "r"
time_order = "sort"
[[source]]
kind = "ground_truth"
file = "truth.csv"
time = "time"
time_format = "%Y-%m-%dT%H:%M:%S%.fZ"
lat = "lat"
lon = "lon"
heading = "yaw"
[beacons]
file = "beacons.csv"
id = "id"
lat = "lat"
lon = "lon"
{rest}"#
    );
    let log = dir.join("plaza1-latlon.toml");
    std::fs::write(&log, toml).unwrap();
    let a = replay_json(&plaza(1), None, &dir.join("metric"));
    let b = replay_json(&log.display().to_string(), None, &dir.join("latlon"));
    assert_eq!(a.len(), b.len());
    let mut worst: f64 = 0.0;
    for (a, b) in a.iter().zip(&b) {
        assert_eq!(a["name"], b["name"]);
        let pairs = [
            (&a["rmse_m"], &b["rmse_m"]),
            (&a["final_error_m"], &b["final_error_m"]),
            (&a["max_error_m"], &b["max_error_m"]),
            (&a["final"]["x_m"], &b["final"]["x_m"]),
            (&a["final"]["y_m"], &b["final"]["y_m"]),
        ];
        for (x, y) in pairs {
            let d = (x.as_f64().unwrap() - y.as_f64().unwrap()).abs();
            assert!(d < 0.01, "{}: {x} against {y}", a["name"]);
            worst = worst.max(d);
        }
    }
    eprintln!("plaza1 metric against clock times and latitudes: largest difference {worst:.2e} m");

    // a row that is no place on Earth is refused with its file, line and column, exit 2
    let truth = std::fs::read_to_string(dir.join("truth.csv")).unwrap();
    let mut lines: Vec<String> = truth.lines().map(String::from).collect();
    let good = lines[40].clone();
    for bad in ["95.0", "1e9"] {
        let mut cells: Vec<&str> = good.split(',').collect();
        let column = if bad == "95.0" { 1 } else { 2 };
        cells[column] = bad;
        lines[40] = cells.join(",");
        std::fs::write(dir.join("truth.csv"), lines.join("\n") + "\n").unwrap();
        let o = run(&["replay", &log.display().to_string(), "--out", &dir.join("bad").display().to_string()]);
        let err = text(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{bad}: {err}");
        assert_eq!(err.trim().lines().count(), 1, "{err}");
        assert!(err.contains("truth.csv line 41") && err.contains("no place on Earth"), "{bad}: {err}");
        assert!(!dir.join("bad").exists());
    }

    // a ground truth whose rows run backwards, dropped out of time order but one: the
    // scores of a handful of rows are flagged, on stderr and in the summary
    let mut backwards: Vec<&str> = truth.lines().skip(1).collect();
    backwards.reverse();
    std::fs::write(dir.join("truth.csv"), format!("time,lat,lon,yaw\n{}\n", backwards.join("\n"))).unwrap();
    let dropping = std::fs::read_to_string(&log)
        .unwrap()
        .replace("file = \"truth.csv\"\n", "file = \"truth.csv\"\ntime_order = \"drop\"\n");
    std::fs::write(&log, dropping).unwrap();
    let o = run(&["replay", &log.display().to_string(), "--json", "--out", &dir.join("drop").display().to_string()]);
    let err = text(&o.stderr);
    assert!(o.status.success(), "{err}");
    assert!(err.contains("truth.csv") && err.contains("rows dropped out of time order"), "{err}");
    assert!(err.contains("fewer than 30"), "{err}");
    let v: Value = serde_json::from_slice(&o.stdout).unwrap();
    let warnings = v["warnings"].as_array().unwrap();
    let scored = warnings.iter().filter(|w| w.as_str().unwrap().contains("fewer than 30")).count();
    let dropped = warnings.iter().filter(|w| w.as_str().unwrap().contains("rows dropped")).count();
    assert_eq!((dropped, scored), (1, v["estimators"].as_array().unwrap().len()), "{warnings:?}");
}

/// `onebeacon smooth` on plaza2 with the range scale as a variable lands within 10 % of
/// GTSAM's LM on the same graph (0.266 m: `../shared/bench/gtsam_smooth.py plaza2 --scale
/// est`, docs/smooth.md), writes replay's files with a smoother column, and its table
/// line is the JSON's; a bad flag exits 2 with one line and writes nothing.
#[test]
fn smooth_matches_gtsam_on_plaza2_and_refuses_bad_flags() {
    let dir = scratch("smooth");
    let out = dir.join("s");
    let args = ["smooth", &plaza(2), "--calibrate", "range_scale", "--kernel", "none", "--out"];
    let o = run(&[&args[..], &[out.to_str().unwrap(), "--json"]].concat());
    assert!(o.status.success(), "{}", text(&o.stderr));
    let summary: Value = serde_json::from_slice(&o.stdout).unwrap();
    let estimators = summary["estimators"].as_array().unwrap();
    let smoother = rmse(estimators, "smoother");
    assert!(smoother < 1.1 * 0.266, "smoother RMSE {smoother} m");
    let header = std::fs::read_to_string(out.join("trajectory.csv")).unwrap();
    assert!(header.lines().next().unwrap().contains("smoother_sigma_north_m"));
    for f in ["summary.json", "top_view.png", "error.png"] {
        assert!(out.join(f).exists(), "{f}");
    }
    let bad = dir.join("bad");
    let o = run(&["smooth", &plaza(2), "--kernel", "gauss", "--out", bad.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(2));
    let err = text(&o.stderr);
    assert_eq!(err.lines().count(), 1, "{err}");
    assert!(err.contains("--kernel gauss: not a kernel (allowed: none, huber, cauchy, student_t)"), "{err}");
    assert!(!bad.exists());
    // a log with a bad cell past its first row (read by the smoother): one line naming file, line and column, exit 2, nothing written
    let log = bad_log(&dir, "smooth-cell", "t,id,r\n1.0,0,5.0\n2.0,0,abc\n", "");
    let o = run(&["smooth", &log, "--out", bad.to_str().unwrap()]);
    let err = text(&o.stderr);
    assert_eq!((o.status.code(), err.lines().count()), (Some(2), 1), "{err}");
    assert!(err.contains("line 3, column `r`"), "{err}");
    assert!(!bad.exists());
}

/// plaza1 without its odometry (ranges and truth only): `smooth` refuses it in one line
/// that names the constant-velocity model, exit 2, nothing written; `--track-accel 0.3`
/// smooths it with nodes at the ranges (docs/smooth.md: RMSE 3.8 m with offset and scale
/// as variables; here under the 4.4 m of the tracker, `plaza-no-odometry`); a track
/// acceleration of 0 is refused.
#[test]
fn smooth_tracks_a_craft_without_motion_rows() {
    let dir = scratch("smooth-track");
    let data = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../data/plaza");
    let toml = std::fs::read_to_string(data.join("plaza1.toml")).unwrap();
    let (odometry, range) =
        (toml.find("[[source]]\nkind = \"odometry\"").unwrap(), toml.find("[[source]]\nkind = \"range\"").unwrap());
    let toml = format!("{}{}", &toml[..odometry], &toml[range..])
        .replace("file = \"", &format!("file = \"{}/", data.display()));
    let log = dir.join("plaza1-no-odometry.toml");
    std::fs::write(&log, toml).unwrap();
    let log = log.to_str().unwrap();
    let bad = dir.join("bad");
    let o = run(&["smooth", log, "--out", bad.to_str().unwrap()]);
    let err = text(&o.stderr);
    assert_eq!((o.status.code(), err.lines().count()), (Some(2), 1), "{err}");
    assert!(err.contains("no motion to smooth") && err.contains("--track-accel SIGMA"), "{err}");
    assert!(!bad.exists());
    let o = run(&["smooth", log, "--track-accel=0", "--out", bad.to_str().unwrap()]);
    let err = text(&o.stderr);
    assert_eq!((o.status.code(), err.lines().count()), (Some(2), 1), "{err}");
    assert!(err.contains("--track-accel 0: the white acceleration must be a positive number"), "{err}");
    let out = dir.join("s");
    let args = ["smooth", log, "--track-accel", "0.3", "--calibrate", "range_scale,shared_offset", "--json", "--out"];
    let o = run(&[&args[..], &[out.to_str().unwrap()]].concat());
    assert!(o.status.success(), "{}", text(&o.stderr));
    let summary: Value = serde_json::from_slice(&o.stdout).unwrap();
    let smoother = rmse(summary["estimators"].as_array().unwrap(), "smoother");
    assert!(smoother < 4.4, "smoother RMSE {smoother} m");
    assert_eq!(summary["smoother_noise"]["keys"]["track_accel_sigma_m_s2"], 0.3);
}

/// `onebeacon smooth` with the factors of GTSAM's bench (range scale 1, no kernel) takes
/// at most 1.5 times the LM iterations GTSAM 4.3.0 takes on plaza2, all beacons and each
/// of 0, 1 and 6 alone (6, 8, 7 and 9: `../shared/bench/gtsam_smooth.py plaza2 --beacons
/// B`, measured 2026-12-04; scripts/smooth_vs_gtsam.py). Before the SE(2) retraction and
/// GTSAM's damping schedule (21170a3) it took 15, 98, 25 and 34.
#[test]
fn smooth_converges_in_gtsams_iterations_on_plaza2() {
    let dir = scratch("smooth-iterations");
    let log = plaza(2);
    for (beacons, gtsam) in [(None, 6.0), (Some("0"), 8.0), (Some("1"), 7.0), (Some("6"), 9.0)] {
        let out = dir.join(format!("s-{}", beacons.unwrap_or("all")));
        let mut args = vec!["smooth", &log, "--calibrate", "none", "--kernel", "none", "--json"];
        args.extend(beacons.map(|b| ["--beacons", b]).iter().flatten());
        args.extend(["--out", out.to_str().unwrap()]);
        let o = run(&args);
        assert!(o.status.success(), "{}", text(&o.stderr));
        let summary: Value = serde_json::from_slice(&o.stdout).unwrap();
        let smoother = summary["estimators"].as_array().unwrap().iter().find(|e| e["name"] == "smoother").unwrap();
        let iterations = smoother["iterations"].as_f64().unwrap();
        assert!(iterations <= 1.5 * gtsam, "beacons {beacons:?}: {iterations} iterations against GTSAM's {gtsam}");
    }
}

/// plaza2 with beacon 0's position multiplied by 100 (a units slip): the smoother
/// warns, on stderr and in summary.json, that its range scale stopped at its bound and
/// that its RMSE is far above the filters' (cfb7f93: nothing said, 899 m on plaza1).
#[test]
fn smooth_says_when_it_fails() {
    let dir = scratch("smooth-slip");
    let data = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../data/plaza");
    for f in ["plaza2.toml", "plaza2_odometry.csv", "plaza2_ranges.csv", "plaza2_ground_truth.csv"] {
        std::fs::copy(data.join(f), dir.join(f)).unwrap();
    }
    let beacons = std::fs::read_to_string(data.join("plaza2_beacons.csv")).unwrap();
    let mut lines: Vec<String> = beacons.lines().map(String::from).collect();
    let f: Vec<String> = lines[1].split(',').map(String::from).collect();
    let scaled = |v: &str| (v.parse::<f64>().unwrap() * 100.0).to_string();
    lines[1] = format!("{},{},{}", f[0], scaled(&f[1]), scaled(&f[2]));
    std::fs::write(dir.join("plaza2_beacons.csv"), lines.join("\n") + "\n").unwrap();
    let log = dir.join("plaza2.toml");
    let out = dir.join("s");
    let o = run(&["smooth", log.to_str().unwrap(), "--out", out.to_str().unwrap(), "--json"]);
    assert!(o.status.success(), "{}", text(&o.stderr));
    let err = text(&o.stderr);
    assert!(err.contains("warning: the smoother's range_scale ended at its bound"), "{err}");
    assert!(err.contains("times the best filter's"), "{err}");
    let summary: Value = serde_json::from_slice(&o.stdout).unwrap();
    let warnings = summary["warnings"].as_array().unwrap();
    assert!(warnings.iter().any(|w| w.as_str().unwrap().contains("do not use its track")), "{warnings:?}");
    // the log as it is: no such warning
    let o = run(&["smooth", &plaza(2), "--out", dir.join("ok").to_str().unwrap(), "--json"]);
    assert!(!text(&o.stderr).contains("smoother"), "{}", text(&o.stderr));
}

/// README's "Your own log": its TOML block, word for word, replays a synthetic dive
/// (1 m/s due east from its given start, for 10 min; exact speed, heading and ranges
/// to the beacon, so each estimator ends on the truth, 600 m east of the start, within
/// the ranges' and the speed's rounding); and its "On a vehicle" line streams through
/// it. A README whose keys no longer parse fails here.
#[test]
fn the_readme_log_description_runs_as_written() {
    let readme = std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("../../README.md")).unwrap();
    let block = |after: &str, fence: &str| -> String {
        let rest = &readme[readme.find(after).unwrap_or_else(|| panic!("README has no {after}"))..];
        let start = rest.find(fence).unwrap() + fence.len();
        rest[start..start + rest[start..].find("```").unwrap()].to_string()
    };
    let dir = scratch("readme");
    std::fs::write(dir.join("my-dive.toml"), block("## Your own log", "```toml\n")).unwrap();
    let (start, speed) = ((120.0, -40.0), 1.0);
    let mut nav = String::from("t_s,speed_m_s,heading_deg\n");
    let mut ranges = String::from("t_s,beacon,range_m\n");
    for i in 0..=600 {
        let t = f64::from(i);
        nav.push_str(&format!("{t},{speed},90\n"));
        if i % 5 == 0 && i > 0 {
            let (north, east) = (start.0, start.1 + speed * t);
            ranges.push_str(&format!("{t},1,{:.3}\n", f64::hypot(north, east)));
        }
    }
    std::fs::write(dir.join("nav.csv"), nav).unwrap();
    std::fs::write(dir.join("ranges.csv"), ranges).unwrap();
    let config = dir.join("my-dive.toml").display().to_string();
    let out = dir.join("out").display().to_string();
    let o = run(&["replay", &config, "--out", &out, "--json"]);
    assert!(o.status.success(), "{}", text(&o.stderr));
    let trajectory = std::fs::read_to_string(dir.join("out").join("trajectory.csv")).unwrap();
    let mut lines = trajectory.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    let last: Vec<f64> = lines.last().unwrap().split(',').map(|v| v.parse().unwrap_or(f64::NAN)).collect();
    for name in ["dead-reckoning", "ekf"] {
        let at = |c: &str| last[header.iter().position(|h| *h == format!("{name}_{c}")).unwrap()];
        let (north, east) = (at("north_m"), at("east_m"));
        let off = (north - start.0).hypot(east - (start.1 + 600.0 * speed));
        assert!(off < 0.5, "{name} ends at ({north}, {east}), {off} m off");
    }
    // the JSON lines the README's shell block quotes, one estimate line out for each
    let shell = block("## On a vehicle", "```sh\n");
    let lines: Vec<&str> = shell.split('\'').filter(|q| q.starts_with('{')).collect();
    assert_eq!(lines.len(), 3, "{lines:?}");
    let o = stream(&config, (lines.join("\n") + "\n").into_bytes());
    assert!(o.status.success() && o.stderr.is_empty(), "{}", text(&o.stderr));
    let out: Vec<Value> = text(&o.stdout).lines().map(|l| serde_json::from_str(l).unwrap()).collect();
    assert_eq!(out.len(), 3, "{out:?}");
    let ekf = &out[2]["estimates"][1];
    assert_eq!(ekf["name"], "ekf");
    assert_eq!(ekf["outcome"], "accepted", "{ekf}");
}

/// `replay --holdout all` on plaza2: every beacon held out in turn, its ranges predicted
/// by each estimator (a score without ground truth), in the table, holdout.csv and the
/// summary; the calibrated filters predict every beacon better than dead reckoning does.
/// A beacon not run, or a run with one beacon, is refused with one line, exit 2.
#[test]
fn holdout_scores_each_beacon_without_the_truth() {
    let dir = scratch("holdout");
    let out = dir.join("h").display().to_string();
    let o = run(&["replay", &plaza(2), "--holdout", "all", "--json", "--out", &out]);
    assert!(o.status.success(), "{}", text(&o.stderr));
    let v: Value = serde_json::from_slice(&o.stdout).unwrap();
    let rms = |b: &str, e: &str| v["holdout"][b][e]["residual_rms_m"].as_f64().unwrap();
    for b in ["0", "1", "5", "6"] {
        for e in ["ekf-cal", "ekf-cal-oos"] {
            assert!(rms(b, e) < rms(b, "dead-reckoning"), "beacon {b}: {e} {} m", rms(b, e));
        }
    }
    let csv = std::fs::read_to_string(dir.join("h").join("holdout.csv")).unwrap();
    assert_eq!(csv.lines().count(), 1 + 4 * 9, "{csv}");
    for (args, says) in [
        (vec!["--holdout", "3"], "--holdout 3: not a beacon of this run (beacons: 0, 1, 5, 6; or `all`)"),
        (vec!["--holdout", "all", "--beacons", "5"], "--holdout all: one beacon (5) leaves none to run on"),
    ] {
        let log = plaza(2);
        let mut a = vec!["replay", &log, "--out", &out];
        a.extend(args);
        let o = run(&a);
        assert_eq!(o.status.code(), Some(2));
        assert_eq!(text(&o.stderr).trim(), format!("error: {says}"));
    }
}

/// A log's `[noise]` reaches every estimator and the smoother: `replay --estimators FILE`
/// gives the file's estimators the keys they do not set (its `ekf` then replays as the
/// log's own), and `smooth` without `--like` weighs with them, saying so. Before issue
/// 53 both ignored the table: the smoother was bit-identical with and without it.
#[test]
fn the_logs_noise_reaches_estimators_files_and_the_smoother() {
    let dir = scratch("noise");
    let data = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../data/plaza");
    for f in ["plaza2_odometry.csv", "plaza2_ranges.csv", "plaza2_ground_truth.csv", "plaza2_beacons.csv"] {
        std::fs::copy(data.join(f), dir.join(f)).unwrap();
    }
    let toml = std::fs::read_to_string(data.join("plaza2.toml")).unwrap();
    let noisy = dir.join("plaza2.toml");
    std::fs::write(&noisy, format!("{toml}\n[noise]\nrange_sigma_m = 3.0\n")).unwrap();
    let file = dir.join("ekf.toml");
    std::fs::write(&file, "[[estimators]]\nname = \"ekf\"\nkind = \"range-ekf\"\n").unwrap();
    let ekf = |args: &[&str], out: &str| {
        let (log, out) = (noisy.display().to_string(), dir.join(out).display().to_string());
        let mut a = vec!["replay", &log, "--json", "--out", &out];
        a.extend(args);
        let o = run(&a);
        assert!(o.status.success(), "{}", text(&o.stderr));
        let v: Value = serde_json::from_slice(&o.stdout).unwrap();
        let e = v["estimators"].as_array().unwrap().iter().find(|e| e["name"] == "ekf").unwrap().clone();
        (e["rmse_m"].as_f64().unwrap(), v["noise"]["range_sigma_m"].as_f64())
    };
    let own = ekf(&[], "own");
    let file = file.display().to_string();
    assert_eq!(ekf(&["--estimators", &file], "file"), own);
    assert_eq!(own.1, Some(3.0));
    let smoother = |log: &str, out: &str| {
        let o = run(&["smooth", log, "--json", "--out", &dir.join(out).display().to_string()]);
        assert!(o.status.success(), "{}", text(&o.stderr));
        let v: Value = serde_json::from_slice(&o.stdout).unwrap();
        let s = v["estimators"].as_array().unwrap().iter().find(|e| e["name"] == "smoother").unwrap().clone();
        (s["rmse_m"].as_f64().unwrap(), v["smoother_noise"].clone())
    };
    let (with, noise) = smoother(&noisy.display().to_string(), "s-noise");
    let (without, default) = smoother(&plaza(2), "s-default");
    assert_eq!(noise["keys"]["range_sigma_m"].as_f64(), Some(3.0));
    assert_eq!(noise["from"], "the log's [noise], the defaults for the rest");
    assert_eq!(
        (default["keys"]["range_sigma_m"].as_f64(), default["from"].as_str()),
        (Some(1.5), Some("the defaults"))
    );
    assert!((with - without).abs() > 0.05, "smoother RMSE {with} m with [noise], {without} m without");
}

/// plaza2 starts from the ground truth's track (`heading_from = "track"`): `stream`, which
/// cannot read ahead, writes one line per input line, `"started": false` until the truth's
/// track is 2 m long, and starts at that row (computed here from the truth file), where
/// `replay` starts at the first truth row, with the heading of the track ahead. Before
/// issue 53 the lines before the start had no output line.
#[test]
fn a_track_start_streams_a_line_per_input_line() {
    let dir = scratch("track-start");
    let items = run(&["replay", &plaza(2), "--print-stream"]);
    assert!(items.status.success());
    let input = text(&items.stdout);
    let o = stream(&plaza(2), items.stdout.clone());
    assert!(o.status.success(), "{}", text(&o.stderr));
    let out: Vec<Value> = text(&o.stdout).lines().map(|l| serde_json::from_str(l).unwrap()).collect();
    assert_eq!(out.len(), input.lines().count());
    let first = out.iter().position(|l| l.get("estimates").is_some()).unwrap();
    assert!(out[..first].iter().all(|l| l["started"] == false), "lines before the start");
    // the first truth row 2 m from the first one
    let truth =
        std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("../../data/plaza/plaza2_ground_truth.csv"))
            .unwrap();
    let rows: Vec<Vec<f64>> =
        truth.lines().skip(1).map(|l| l.split(',').take(3).map(|c| c.parse().unwrap()).collect()).collect();
    let t_track = rows.iter().find(|r| (r[1] - rows[0][1]).hypot(r[2] - rows[0][2]) >= 2.0).unwrap()[0];
    assert_eq!(out[first]["t_s"].as_f64().unwrap(), t_track);
    replay_json(&plaza(2), None, &dir.join("r"));
    let summary: Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("r").join("summary.json")).unwrap()).unwrap();
    let t_replay = summary["start"]["t_s"].as_f64().unwrap();
    assert_eq!(t_replay, rows[0][0]);
    assert!(t_track - t_replay > 10.0, "stream starts at {t_track} s, replay at {t_replay} s");
}
