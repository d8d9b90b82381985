//! Fuzz targets: each takes arbitrary bytes and must neither panic nor abort, and checks
//! what a valid input promises (finite estimates, samples that are numbers, a ping that
//! is not silence). `fuzz/` runs them under libFuzzer (nightly: `scripts/fuzz.sh`); the
//! regression test (`tests/corpus.rs`) runs every checked-in input on stable.

use nalgebra::Vector3;
use onebeacon::geo::Frame;
use onebeacon::io::stream;
use onebeacon::log::{Log, LogDescription, LogError};
use onebeacon_sim::acoustics::channel::simulate_ping;
use onebeacon_sim::acoustics::wav::Recording;
use onebeacon_sim::replay::replay;
use onebeacon_sim::scenario::ping::PingConfig;
use onebeacon_sim::seed::{Stream, rng};
use std::collections::BTreeMap;
use std::io::Cursor;
use std::path::PathBuf;

/// A fuzz target: arbitrary bytes in, a panic on a finding.
pub type Target = fn(&[u8]);

/// The targets by name, as `fuzz/fuzz_targets/` and the corpus directories name them.
pub const TARGETS: &[(&str, Target)] = &[
    ("scenario", scenario),
    ("log_description", log_description),
    ("log_csv", log_csv),
    ("stream", stream),
    ("wav", wav),
    ("ping_config", ping_config),
    ("partial", partial),
    #[cfg(feature = "ros2")]
    ("log_bag", log_bag),
];

/// Longest scenario the target simulates (steps x vehicles): longer ones are only
/// parsed and checked, to keep each input under a second.
const MAX_SIMULATED_STEPS: usize = 2000;
/// Most particles x steps the target simulates (about a second).
const MAX_PARTICLE_STEPS: usize = 20_000_000;

/// A scenario TOML: parsed and checked; a valid short one is simulated once (its first
/// cell), and every estimator's mean error is a number (finite, or infinite when it
/// diverged, as documented; never NaN).
pub fn scenario(data: &[u8]) {
    let Ok(text) = std::str::from_utf8(data) else { return };
    let Ok(s) = onebeacon_sim::scenario::parse(text, "fuzz") else { return };
    if s.steps().saturating_mul(s.vehicle_names().len()) > MAX_SIMULATED_STEPS {
        return;
    }
    // a particle filter costs its particles at every step
    if let onebeacon_sim::Scenario::PassiveUsbl(p) = &s {
        let particles: usize = p
            .estimators
            .iter()
            .filter(|e| e.kind == onebeacon_sim::scenario::EstimatorKind::Particle)
            .map(|e| e.particle_settings().0)
            .sum();
        if particles.saturating_mul(s.steps()).saturating_mul(s.vehicle_names().len()) > MAX_PARTICLE_STEPS {
            return;
        }
    }
    let cell = &s.cells()[0];
    let out = onebeacon_sim::run::simulate(&s, cell, s.seed(), 0, false);
    for (m, name) in out.metrics.iter().zip(s.track_labels()) {
        assert!(!m.mean_error_m.is_nan(), "{name}: mean error NaN");
    }
}

/// A log description TOML: parsed and checked, nothing more (no file is opened).
pub fn log_description(data: &[u8]) {
    let Ok(text) = std::str::from_utf8(data) else { return };
    let _ = LogDescription::parse(text, "fuzz");
}

/// The description every CSV input is replayed with: odometry, ranges (sorted) to two
/// fixed beacons, ground truth; a gated EKF, an ungated calibrating UKF, dead reckoning.
const LOG: &str = r#"name = "fuzz"
frame = "enu"
[[source]]
kind = "odometry"
file = "odometry.csv"
time = "t"
distance = "d"
heading_change = "dh"
[[source]]
kind = "range"
file = "ranges.csv"
time = "t"
beacon = "id"
range = "r"
sort = true
[[source]]
kind = "ground_truth"
file = "truth.csv"
time = "t"
x = "x"
y = "y"
[[beacon]]
id = 0
x_m = 10.0
y_m = 0.0
[[beacon]]
id = 5
x_m = -20.0
y_m = 30.0
[initial]
from = "ground_truth"
heading_from = "track"
track_m = 0.5
[[estimators]]
name = "ekf"
kind = "range-ekf"
nis_gate = 10.83
[[estimators]]
name = "ukf-cal"
kind = "range-ekf"
filter = "ukf"
estimate_bias = true
estimate_range_scale = true
estimate_turn_scale = true
[[estimators]]
name = "dr"
kind = "dead-reckoning"
"#;

/// A scratch directory of this process for the CSV files.
fn scratch() -> PathBuf {
    let dir = std::env::temp_dir().join(format!("onebeacon-fuzz-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("a writable temporary directory");
    dir
}

/// Three CSV files (odometry, ranges, ground truth: the input split at its first two
/// NUL bytes) replayed through [`LOG`]: an error or a trajectory, every row of which
/// has finite estimates.
pub fn log_csv(data: &[u8]) {
    let mut parts = data.splitn(3, |b| *b == 0);
    let dir = scratch();
    for name in ["odometry.csv", "ranges.csv", "truth.csv"] {
        std::fs::write(dir.join(name), parts.next().unwrap_or_default()).expect("writable");
    }
    let path = dir.join("log.toml");
    std::fs::write(&path, LOG).expect("writable");
    if let Ok(log) = Log::load(&path) {
        let _ = replay(&log, None, |r| {
            for (e, name) in r.estimates.iter().zip(["ekf", "ukf-cal", "dr"]) {
                assert!(e.pos.iter().all(|v| v.is_finite()), "{name} at t = {}: {:?}", r.t_s, e.pos);
                assert!(e.sigma_pos.iter().all(|v| v.is_finite() && *v >= 0.0), "{name}: sigma {:?}", e.sigma_pos);
            }
            Ok::<_, LogError>(())
        });
    }
    // kept when a check fails (the panic skips this): the files of the failing input
    let _ = std::fs::remove_dir_all(&dir);
}

/// The description a bag input is replayed with: plaza's topics as `scripts/ros2_bags.py`
/// writes them (odometry increments, ranges with the beacon in the frame id, a 2-D pose),
/// its four beacons; a gated EKF and dead reckoning.
#[cfg(feature = "ros2")]
const LOG_BAG: &str = r#"name = "fuzz-bag"
frame = "enu"
[[source]]
kind = "odometry"
bag = "BAG"
topic = "/wheel/increment"
distance = "distance"
heading_change = "heading_change"
[[source]]
kind = "range"
bag = "BAG"
topic = "/radio/range"
beacon = "header.frame_id"
range = "range"
time_order = "drop"
[[source]]
kind = "ground_truth"
bag = "BAG"
topic = "/rtk/pose2d"
x = "x"
y = "y"
heading = "heading"
time_order = "sort"
[beacons]
file = "beacons.csv"
id = "id"
x = "x"
y = "y"
[initial]
from = "ground_truth"
[[estimators]]
name = "ekf"
kind = "range-ekf"
nis_gate = 10.83
[[estimators]]
name = "dr"
kind = "dead-reckoning"
"#;

/// A ROS 2 bag (SQLite3 when it starts as one, MCAP otherwise) replayed through
/// [`LOG_BAG`]: an error or a trajectory with finite estimates; never a panic, whatever
/// the damage.
#[cfg(feature = "ros2")]
pub fn log_bag(data: &[u8]) {
    let dir = scratch();
    let bag = if data.starts_with(b"SQLite format 3\0") { "bag.db3" } else { "bag.mcap" };
    std::fs::write(dir.join(bag), data).expect("writable");
    // plaza1's beacons (data/plaza/plaza1_beacons.csv)
    let beacons =
        "id,x,y\n0,-46.623234,11.025549\n1,11.036124,-6.958689\n6,22.053129,23.848482\n5,-17.664893,59.009181\n";
    std::fs::write(dir.join("beacons.csv"), beacons).expect("writable");
    let path = dir.join("log.toml");
    std::fs::write(&path, LOG_BAG.replace("BAG", bag)).expect("writable");
    if let Ok(log) = Log::load(&path) {
        let _ = replay(&log, None, |r| {
            for e in &r.estimates {
                assert!(e.pos.iter().all(|v| v.is_finite()), "at t = {}: {:?}", r.t_s, e.pos);
            }
            Ok::<_, LogError>(())
        });
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// Bytes on a stream's stdin ([`stream::run`] with [`LOG`]'s estimators and beacons,
/// starting at a given pose): it reads to the end, every output line is one JSON
/// object, and the final estimates are finite.
pub fn stream(data: &[u8]) {
    let d = LogDescription::parse(LOG, "fuzz").expect("the fuzz log description is valid");
    let fixed: BTreeMap<u32, Vector3<f64>> =
        [(0, Vector3::new(10.0, 0.0, 0.0)), (5, Vector3::new(-20.0, 30.0, 0.0))].into_iter().collect();
    let start = onebeacon::nav::session::Start::At { t0_s: None, pose: (0.0, 0.0, 0.0) };
    let session = d.stream_config(Vec::new()).session(&d.initial, start, None);
    let mut unit = onebeacon::vehicle::unit::Unit::new(vec![session], fixed, Frame::Enu, None);
    let mut out = Vec::new();
    stream::run(&mut unit, Cursor::new(data), &mut out, |_, _| {}).expect("in-memory I/O");
    let text = std::str::from_utf8(&out).expect("the output is UTF-8");
    for line in text.lines() {
        assert!(line.starts_with('{') && line.ends_with('}'), "not a JSON object: {line}");
    }
    for e in unit.session(0).final_estimates() {
        assert!(e.north_m().is_finite() && e.east_m().is_finite(), "{e:?}");
    }
}

/// A WAV file for a 5-element array at 37.5 kHz: refused, or read a capture at a time
/// to the same number of frames its check counted, every sample a number.
pub fn wav(data: &[u8]) {
    let Ok(r) = Recording::new(Cursor::new(data), 5, 37_500.0) else { return };
    let Ok(frames) = r.check() else { return };
    let mut r = Recording::new(Cursor::new(data), 5, 37_500.0).expect("it opened once");
    loop {
        let capture = r.next_capture(4096).expect("it was read once");
        assert!(capture.iter().flatten().all(|v| v.is_finite()));
        if capture[0].is_empty() {
            break;
        }
    }
    assert_eq!(r.frames_read(), frames);
}

/// A ping configuration (`dsp --config`): refused, or (up to 20 000 samples) a
/// simulated ping whose samples are numbers and not all zero, as the validation
/// promises.
pub fn ping_config(data: &[u8]) {
    let Ok(text) = std::str::from_utf8(data) else { return };
    let Ok(c) = PingConfig::parse(text, "fuzz") else { return };
    if c.capture.samples > 20_000 {
        return;
    }
    let elements = c.elements();
    let mut noise = rng(c.seed, 0, Stream::Acoustic);
    let caps =
        simulate_ping(&c.signal(), &c.source(), &c.receiver(), &c.attitude(), &elements, &c.channel(), &mut noise);
    assert!(caps.iter().flatten().all(|v| v.is_finite()), "a sample is not a number");
    assert!(caps.iter().flatten().any(|v| *v != 0.0), "a silent capture");
}

/// An `mc --shard` partial file: read and, when it reads, merged on its own (a one-share
/// campaign, or a share of one whose other shares are missing). Every count in it is
/// the file's word: the merge must check each before it allocates by it, and a merged
/// result holds only the runs the file gave.
pub fn partial(data: &[u8]) {
    use onebeacon_sim::partial::{Partial, merge};
    let Ok(text) = std::str::from_utf8(data) else { return };
    let Ok(p) = Partial::from_json(text, "fuzz") else { return };
    let records = p.results.len();
    if let Ok(merged) = merge(vec![("fuzz".into(), p)]) {
        let runs: usize = merged.result.cells.len() * merged.result.runs;
        assert_eq!(runs, records, "a merged campaign of {runs} runs from {records} records");
    }
}
