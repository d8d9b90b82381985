//! Truth vehicles' dynamics (issue 14): one hour of the Otter under its autopilots,
//! RK4 at 0.05 s (72 000 steps), a heading change every minute. The target is
//! one hour of hoff2024's truth (Otter and REMUS 100) in under 1 s.

use criterion::{Criterion, criterion_group, criterion_main};
use nalgebra::Vector3;
use onebeacon_sim::vehicles::autopilot::{Command, Piloted};
use onebeacon_sim::vehicles::otter::{Otter, OtterPilot};
use onebeacon_sim::vehicles::rigid_body::BodyState;
use std::hint::black_box;

fn bench(c: &mut Criterion) {
    let mut group = c.benchmark_group("vehicles");
    group.sample_size(10);
    group.bench_function("otter, one hour at 0.05 s", |b| {
        b.iter(|| {
            let mut p = OtterPilot::new(Otter::default(), BodyState::at_rest(Vector3::zeros(), 0.0));
            for k in 0..72_000 {
                let psi_d = if (k / 1200) % 2 == 0 { 0.0 } else { 1.0 };
                p.step(&Command { heading_rad: psi_d, speed_m_s: 2.0, depth_m: None }, &Vector3::zeros(), 0.05);
            }
            black_box(p.state)
        })
    });
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
