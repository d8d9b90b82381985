//! Smoothing plaza1 (9658 poses, 3529 ranges to 4 beacons): reading the log and
//! building the graph, then Levenberg-Marquardt to convergence with the marginal
//! covariance of every pose; with the range scale as a variable (GTSAM's LM on the same
//! poses and ranges, its built-in factors with the scale fitted beforehand, solves in
//! 0.36-0.37 s on the 2-core machine of docs/smooth.md: the target is 10x faster, 37 ms),
//! then with the default calibration (range and turn scale) and Huber kernel.

use criterion::{Criterion, criterion_group, criterion_main};
use onebeacon::log::Log;
use onebeacon_sim::smooth::{Calibrate, SmoothConfig, smooth};
use std::hint::black_box;
use std::path::PathBuf;

fn bench(c: &mut Criterion) {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../data/plaza/plaza1.toml");
    let log = Log::load(&path).unwrap();
    let scale_only = SmoothConfig {
        calibrate: Calibrate { range_scale: true, ..Calibrate::NONE },
        kernel: None,
        ..SmoothConfig::default()
    };
    c.bench_function("plaza1 smooth, range scale", |b| b.iter(|| black_box(smooth(&log, None, &scale_only).unwrap())));
    let default = SmoothConfig::default();
    c.bench_function("plaza1 smooth, default", |b| b.iter(|| black_box(smooth(&log, None, &default).unwrap())));
}

criterion_group! {
    name = benches;
    config = Criterion::default().sample_size(10);
    targets = bench
}
criterion_main!(benches);
