//! One EKF step of garin2024's filter: predict and update (target: under 1 us).

use criterion::{Criterion, criterion_group, criterion_main};
use nalgebra::{SVector, Vector2};
use onebeacon::models::unicycle::{Cov, State};
use onebeacon::nav::{Aiding, CommFrame, EkfTuning, Proprioceptive, SingleBeaconEkf};
use std::hint::black_box;

fn filter(aiding: Aiding) -> SingleBeaconEkf {
    let z0 = State::from([10.0, 20.0, 1.0, 1.0, 0.01, 0.0]);
    let p0 = Cov::from_diagonal(&SVector::from([1.0, 1.0, 0.01, 0.01, 1e-4, 1e-4]));
    SingleBeaconEkf::new(aiding, EkfTuning::default(), z0, p0)
}

fn bench(c: &mut Criterion) {
    let sample = Proprioceptive { heading_rad: 1.0, yaw_rate_rad_s: 0.01, accel_m_s2: 0.0 };
    let frame = CommFrame { beacon_ned_m: Vector2::new(50.0, 100.0), range_m: 89.0, radial_speed_m_s: 0.8 };

    let mut f = filter(Aiding::RangeDoppler);
    c.bench_function("ekf predict + proprioceptive update (M=3)", |b| {
        b.iter(|| black_box(f.step(0.25, black_box(&sample), None)))
    });
    let mut f = filter(Aiding::RangeDoppler);
    c.bench_function("ekf predict + comm frame update (M=5)", |b| {
        b.iter(|| {
            let r = f.step(0.25, black_box(&sample), Some(black_box(&frame)));
            // keep the filter near its operating point
            f = filter(Aiding::RangeDoppler);
            black_box(r)
        })
    });
}

criterion_group!(benches, bench);
criterion_main!(benches);
