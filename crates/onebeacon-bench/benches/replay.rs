//! Replaying plaza1 (22 844 items: 9657 odometry increments, 3529 ranges, 9658
//! ground-truth poses) with 3 estimators: dead reckoning, EKF with bias and gating, EKF
//! with calibration states and gating (target: under 50 ms); then with all 8 of
//! plaza1.toml. The CSV files are read as the replay goes, so their parsing is part of
//! it; `Log::load` (the description, the beacons, and each file's header and first row)
//! is measured apart. Then one stream line through the session of plaza1.toml, as
//! `onebeacon stream` and the Python `Navigator.feed` take it (JSON parse, the session's
//! checks and every estimator's update, the output line): a range, an odometry item.

use criterion::{Criterion, criterion_group, criterion_main};
use onebeacon::log::{Log, LogError, stream_setup};
use onebeacon_sim::replay::replay;
use std::hint::black_box;
use std::path::PathBuf;

/// The record callback: each trajectory row is looked at and dropped.
fn drop_row(r: onebeacon_sim::run::StepRecord) -> Result<(), LogError> {
    black_box(r);
    Ok(())
}

fn bench(c: &mut Criterion) {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../data/plaza/plaza1.toml");
    let full = Log::load(&path).unwrap();
    let mut log = full.clone();
    let keep = ["dead-reckoning", "ekf-bias-gated", "ekf-cal-gated"];
    log.description.estimators.retain(|e| keep.contains(&e.name().as_str()));
    assert_eq!(log.description.estimators.len(), 3);
    c.bench_function("plaza1 replay, 3 estimators", |b| b.iter(|| black_box(replay(&log, None, drop_row).unwrap())));
    let n = full.description.estimators.len();
    c.bench_function(&format!("plaza1 replay, {n} estimators"), |b| {
        b.iter(|| black_box(replay(&full, None, drop_row).unwrap()))
    });
    c.bench_function("plaza1 load (TOML, beacons, CSV headers)", |b| b.iter(|| black_box(Log::load(&path).unwrap())));

    // a started stream: plaza1's first 2000 items
    let mut unit =
        stream_setup(&path, |s| onebeacon_sim::budget::Budget::resolve(None).unwrap().check_stream(s)).unwrap();
    let (mut lines, mut t0) = onebeacon::log::feed_items(&mut unit, &full, 2000).unwrap();
    assert!(unit.session(0).started());
    let names = unit.session(0).names.len();
    for (label, line) in [
        ("range", r#"{"t_s":T,"kind":"range","beacon":1,"range_m":30.0}"#),
        ("odometry", r#"{"t_s":T,"kind":"odometry","distance_m":0.01,"heading_change_rad":0.0}"#),
    ] {
        c.bench_function(&format!("stream line: {label}, {names} estimators (parse, update, output line)"), |b| {
            b.iter_custom(|iters| {
                let batch: Vec<String> =
                    (0..iters).map(|k| line.replace('T', &format!("{}", t0 + 0.01 * (k + 1) as f64))).collect();
                t0 += 0.01 * (iters + 1) as f64;
                let start = std::time::Instant::now();
                for l in &batch {
                    black_box(lines.push(&mut unit, l.as_bytes(), false, |_, _| {}));
                }
                start.elapsed()
            })
        });
    }
}

criterion_group!(benches, bench);
criterion_main!(benches);
