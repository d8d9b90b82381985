//! Twins of logs drawn with a known sea (also what seafit's odometry fit is tested on): the log's own score is one more draw of what
//! its twin simulates, so it falls within the twin's 5-95 % band about 90 % of the
//! time; under a wrong sea it does not.

use super::*;
use crate::acoustics::beacon_ranges::BeaconRanges;
use crate::acoustics::link::Link;
use crate::sensor_errors::OdometryErrors;
use onebeacon::log::testing::{TestLog, write_log};
use rand::SeedableRng;
use rand_pcg::Pcg64Mcg;
use std::fmt::Write;

const BEACONS: [(u32, [f64; 2]); 2] = [(3, [0.0, 0.0]), (4, [120.0, 60.0])];
const DURATION_S: f64 = 600.0;

pub(crate) fn sea() -> Sea {
    let ranges = BeaconRanges {
        beacon: None,
        sigma_m: 0.5,
        offset_m: 0.4,
        scale: 0.02,
        drift_m_s: 0.0,
        multipath_prob: 0.1,
        multipath_excess_m: 2.0,
        false_prob: 0.0,
        false_max_range_m: 0.0,
    };
    let odometry = OdometryErrors {
        distance_scale: 0.01,
        turn_scale: 0.03,
        distance_sigma_m_per_sqrt_m: 0.02,
        turn_sigma_deg_per_sqrt_s: 0.3,
    };
    Sea { ranges: vec![ranges], odometry, ..Sea::default() }
}

/// Ten minutes of a land robot on a 40 m circle at 1 m/s (odometry and ground truth at
/// 5 Hz), ranging each beacon in turn every second, every value drawn by the sea's own
/// models from streams of the test's.
/// `test` names the log's directory apart from other tests' (the tests of one process
/// run at once, and each removes its logs when done).
pub(crate) fn drawn_log(test: &str, seed: u64) -> TestLog {
    log_of(test, seed, true)
}

/// [`drawn_log`], with its ground truth or, without, started at the circle's start.
fn log_of(test: &str, seed: u64, with_truth: bool) -> TestLog {
    let s = sea();
    let stream = |k: u64| Pcg64Mcg::seed_from_u64(seed * 16 + k + 1000);
    let (mut noise, mut odometry, mut link) = (stream(0), stream(1), Link::new(&s.ranges[0].link_errors(), stream(2)));
    let (mut truth, mut rows, mut ranges) = (
        String::from("t_s,x_m,y_m,heading_rad\n"),
        String::from("t_s,distance_m,turn_rad\n"),
        String::from("t_s,beacon_id,range_m\n"),
    );
    let (radius, speed, dt) = (40.0, 1.0, 0.2);
    let at = |t: f64| {
        let a = speed * t / radius;
        ([radius * a.sin(), radius * (1.0 - a.cos())], onebeacon::geo::wrap_angle(a))
    };
    for step in 0..=(DURATION_S / dt) as usize {
        let t = step as f64 * dt;
        let (p, h) = at(t);
        let _ = writeln!(truth, "{t},{},{},{h}", p[0], p[1]);
        if step > 0 {
            let (q, g) = at(t - dt);
            let (d, turn) =
                s.odometry.read((p[0] - q[0]).hypot(p[1] - q[1]), onebeacon::geo::wrap_angle(h - g), dt, &mut odometry);
            let _ = writeln!(rows, "{t},{d},{turn}");
        }
        if step % 5 == 0 {
            let (id, b) = BEACONS[(step / 5) % 2];
            let r = s.ranges[0].hear(t, (p[0] - b[0]).hypot(p[1] - b[1]), &mut link, &mut noise);
            let _ = writeln!(ranges, "{t},{id},{r}");
        }
    }
    let mut toml = String::from(if with_truth {
        "name = \"twin\"\n[initial]\nfrom = \"ground_truth\"\nheading_from = \"column\"\nposition_sigma_m = 0.5\n\
         [[source]]\nkind = \"ground_truth\"\nfile = \"truth.csv\"\ntime = \"t_s\"\nx = \"x_m\"\ny = \"y_m\"\nheading = \"heading_rad\"\n"
    } else {
        "name = \"twin\"\n[initial]\nfrom = \"given\"\nx_m = 0.0\ny_m = 0.0\nheading_deg = 0.0\nposition_sigma_m = 0.5\n"
    });
    toml.push_str(
        "[[source]]\nkind = \"odometry\"\nfile = \"odometry.csv\"\ntime = \"t_s\"\ndistance = \"distance_m\"\nheading_change = \"turn_rad\"\n\
         [[source]]\nkind = \"range\"\nfile = \"ranges.csv\"\ntime = \"t_s\"\nbeacon = \"beacon_id\"\nrange = \"range_m\"\n",
    );
    for (id, b) in BEACONS {
        let _ = writeln!(toml, "[[beacon]]\nid = {id}\nx_m = {}\ny_m = {}", b[0], b[1]);
    }
    toml.push_str(
        "[[estimators]]\nname = \"dr\"\nkind = \"dead-reckoning\"\n\
         [[estimators]]\nname = \"ekf\"\nkind = \"range-ekf\"\n\
         [[estimators]]\nname = \"ekf-bias\"\nkind = \"range-ekf\"\nestimate_bias = true\n",
    );
    let files = [("truth.csv", truth.as_str()), ("odometry.csv", rows.as_str()), ("ranges.csv", ranges.as_str())];
    write_log("twin", &format!("{test}-seed{seed}"), &toml, &files).expect("the drawn log loads")
}

fn options(runs: usize, threads: Option<usize>) -> TwinOptions {
    let each = BEACONS.iter().map(|(id, _)| Some(BTreeSet::from([*id])));
    TwinOptions { runs, seed: 7, threads, sets: std::iter::once(None).chain(each).collect(), shard: Shard::WHOLE }
}

/// Cells within the band, and cells, over `logs` drawn logs.
fn within(logs: u64, sea: &Sea) -> (usize, usize) {
    let mut inside = (0, 0);
    for seed in 0..logs {
        let log = drawn_log("band", seed);
        let t = twin(&log, sea, &options(40, None), &|| {}).unwrap();
        assert_eq!(t.kept.keys().collect::<Vec<_>>(), ["odometry (the first row: no span)"]);
        let ((hit, n), _) = t.agreement();
        inside = (inside.0 + hit, inside.1 + n);
    }
    inside
}

/// Twelve logs, seven cells each (dead reckoning once, two filters on three beacon
/// sets): a log's RMSE is one more draw of its twin's, within the 5-95 % band of 40
/// runs with probability 0.9 x 39/41 = 0.86 (the band's own sampling). At least 60 % of
/// the 84 cells: the cells of one log share its draw, so the count varies more than a
/// binomial's; 12 independent logs at 0.86 per log fall below 0.6 with probability
/// below 1e-2 even if each log's cells all went together (binomial, 12 at 0.86: P(X <=
/// 7) = 0.008); 72 of 84 on record (86 %). Under a wrong sea (the range noise tripled,
/// no offset, scale or odometry errors) the same logs' RMSE leave the band in most
/// cells: at most 40 % within (16 of 84 on record).
#[test]
fn a_log_drawn_from_a_sea_lies_within_its_twins_band() {
    let (hit, n) = within(12, &sea());
    assert!(hit * 10 >= n * 6, "{hit} of {n} cells within the band");
    let mut wrong = sea();
    let r = &mut wrong.ranges[0];
    (r.sigma_m, r.offset_m, r.scale) = (3.0 * r.sigma_m, 0.0, 0.0);
    // no errors of the odometry (a key set so that the twin draws it, not keeps it)
    wrong.odometry = OdometryErrors { distance_sigma_m_per_sqrt_m: 1e-9, ..OdometryErrors::default() };
    let (hit_wrong, n_wrong) = within(12, &wrong);
    assert!(hit_wrong * 10 <= n_wrong * 4, "a wrong sea: {hit_wrong} of {n_wrong} cells within the band");
}

/// A twin is a function of (log, sea, seed): the same cells on one thread or two.
#[test]
fn a_twin_does_not_depend_on_the_threads() {
    let log = drawn_log("threads", 1);
    let one = twin(&log, &sea(), &options(6, Some(1)), &|| {}).unwrap();
    let two = twin(&log, &sea(), &options(6, Some(2)), &|| {}).unwrap();
    assert_eq!(one.cells, two.cells);
    assert_eq!(one.cells.len(), 7);
    assert!(one.cells.iter().all(|c| c.runs.len() == 6));
}

/// The shares of a twin's runs (`--shard I/N`), each written and read back as a partial
/// file, merge into the unsharded twin bit for bit, in any order; a missing share, one
/// of another sea and one of another log are refused by name.
#[test]
fn a_twins_shards_merge_into_the_unsharded_twin() {
    use partial::{MergedTwin, TwinPartial, merge_twin};
    let log = drawn_log("shards", 1);
    let whole = twin(&log, &sea(), &options(7, None), &|| {}).unwrap();
    let share = |sea: &Sea, log: &Log, index| {
        let opts = TwinOptions { shard: Shard { index, count: 3 }, ..options(7, None) };
        let t = twin(log, sea, &opts, &|| {}).unwrap();
        let p = TwinPartial::new("shards", sea, &t, 7, 7, opts.shard, 1.0);
        let name = crate::partial::file_name(opts.shard);
        (name.clone(), TwinPartial::from_json(&p.to_json(), &name).unwrap())
    };
    let real = || twin(&log, &sea(), &options(0, None), &|| {}).unwrap();
    let shares: Vec<_> = [2, 0, 1].into_iter().map(|i| share(&sea(), &log, i)).collect();
    let MergedTwin { twin: merged, runs, seed, wall_s } = merge_twin("shards", real(), &sea(), shares.clone()).unwrap();
    assert_eq!((runs, seed, wall_s), (7, 7, 3.0));
    assert_eq!(merged.cells, whole.cells);
    assert_eq!(merged.run_indices, (0..7).collect::<Vec<u64>>());
    let err = |shares| merge_twin("shards", real(), &sea(), shares).unwrap_err().to_string();
    assert!(err(shares[..2].to_vec()).contains("missing shard(s) 1 of 3"), "{}", err(shares[..2].to_vec()));
    let mut other_sea = sea();
    other_sea.ranges[0].sigma_m = 0.6;
    let foreign = vec![shares[0].clone(), shares[1].clone(), share(&other_sea, &log, 2)];
    assert!(err(foreign).contains("differ in the sea"));
    let other_log = drawn_log("shards", 2);
    let foreign = vec![shares[0].clone(), shares[1].clone(), share(&sea(), &other_log, 2)];
    assert!(err(foreign).contains("differ in the log or its beacon sets"));
}

/// Without ground truth the twin's truth is the smoother's trajectory: the runs are
/// scored against it, the log against nothing (no cell counts toward the agreement), and
/// the twin says so; the filter that estimates the sea's range offset keeps its
/// simulated RMSE about the smoothed circle within ten times the range noise (5 m).
#[test]
fn without_ground_truth_the_smoother_is_the_twins_truth() {
    let log = log_of("no-truth", 2, false);
    let t = twin(&log, &sea(), &options(4, None), &|| {}).unwrap();
    assert_eq!(t.reference, "smoother");
    assert!(t.notes.iter().any(|n| n.contains("no ground truth")), "{:?}", t.notes);
    assert_eq!(t.agreement(), ((0, 0), (0, 0)));
    for c in &t.cells {
        assert!(c.real.rmse_m.is_nan(), "{c:?}");
        assert!(c.runs.iter().all(|r| r.rmse_m.is_finite()), "{c:?}");
        if c.estimator == "ekf-bias" {
            assert!(c.rmse().median < 5.0, "{c:?}");
        }
    }
}
