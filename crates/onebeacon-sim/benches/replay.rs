//! Replaying plaza1 (22 844 items: 9657 odometry increments, 3529 ranges, 9658
//! ground-truth poses) with 3 estimators: dead reckoning, EKF with bias and gating, EKF
//! with calibration states and gating (target: under 50 ms); then with all 8 of
//! plaza1.toml. The CSV files are read as the replay goes, so their parsing is part of
//! it; `Log::load` (the description, the beacons, and each file's header and first row)
//! is measured apart.

use criterion::{Criterion, criterion_group, criterion_main};
use onebeacon_sim::replay::{Log, LogError, replay};
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
}

criterion_group!(benches, bench);
criterion_main!(benches);
