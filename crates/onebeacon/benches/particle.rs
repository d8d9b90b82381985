//! One hoff2024 particle-filter cycle (propagate over 4 s, weigh by the INS report and
//! the USBL bearing, resample systematically) at N = 1e4 .. 1e6 particles. Issue 13's
//! target: <= 15 ms at N = 5e5 on a 2-core machine.

use criterion::{BenchmarkId, Criterion, criterion_group, criterion_main};
use nalgebra::{SVector, Vector3};
use onebeacon::filter::particle::{ParticleFilter, ParticleSettings, Resampler};
use onebeacon::measure::Usbl;
use onebeacon::models::hoff::{DIM, HoffProcess, InsReport, UsblBearing};
use std::hint::black_box;

fn bench(c: &mut Criterion) {
    let mean = SVector::<f64, DIM>::from([100.0, 50.0, 30.0, 0.0, 0.3, 1.5, 0.0, 0.002]);
    let sigma = SVector::<f64, DIM>::from([10.0, 10.0, 2.0, 0.05, 0.2, 0.3, 0.001, 0.003]);
    let settings = ParticleSettings { resampler: Resampler::Systematic, ess_fraction: 1.0, roughening_k: None };
    let ins = InsReport {
        heading_rad: 0.3,
        speed_m_s: 1.5,
        depth_m: 30.0,
        sigma_heading_rad: 0.15f64.sqrt(),
        sigma_speed_m_s: 0.06f64.sqrt(),
        sigma_depth_m: 0.15f64.sqrt(),
    };
    let usbl = Usbl {
        position_ned_m: Vector3::new(80.0, 30.0, 0.0),
        heading_rad: 0.0,
        sigma_rad_per_m: 0.022f64.to_radians(),
    };
    let bearing = UsblBearing { usbl, azimuth_rad: 0.78, elevation_rad: 0.8 };
    let mut group = c.benchmark_group("hoff2024 particle filter cycle");
    group.sample_size(10);
    for n in [10_000usize, 100_000, 500_000, 1_000_000] {
        let mut pf = ParticleFilter::<DIM>::gaussian(n, &mean, &sigma, settings, 1);
        group.bench_with_input(BenchmarkId::from_parameter(n), &n, |b, _| {
            b.iter(|| {
                pf.predict(&HoffProcess::default(), 4.0);
                black_box(pf.update(&(ins, bearing)));
            })
        });
    }
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
