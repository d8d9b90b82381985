//! Replaying plaza1 (22 844 items: 9657 odometry increments, 3529 ranges, 9658
//! ground-truth poses) with 3 estimators: dead reckoning, EKF with bias, EKF with bias
//! and gating (target: under 50 ms). Loading the CSV files is measured apart.

use criterion::{Criterion, criterion_group, criterion_main};
use onebeacon_sim::replay::{Log, replay};
use std::hint::black_box;
use std::path::PathBuf;

fn bench(c: &mut Criterion) {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../data/plaza/plaza1.toml");
    let mut log = Log::load(&path).unwrap();
    let keep = ["dead-reckoning", "ekf-bias", "ekf-bias-gated"];
    log.description.estimators.retain(|e| keep.contains(&e.name.as_str()));
    assert_eq!(log.description.estimators.len(), 3);
    c.bench_function("plaza1 replay, 3 estimators", |b| b.iter(|| black_box(replay(&log, None).unwrap())));
    c.bench_function("plaza1 load (TOML + 4 CSV files)", |b| b.iter(|| black_box(Log::load(&path).unwrap())));
}

criterion_group!(benches, bench);
criterion_main!(benches);
