//! One hoff2024 particle-filter cycle (resample systematically and propagate over 4 s in
//! one pass, weigh by the INS report and the USBL bearing) at N = 1e4 .. 1e6 particles,
//! and the cycle's stages apart at N = 5e5 (each from a clone, so with cold caches: they
//! add up to more than the cycle). Issue 13's
//! target: <= 15 ms at N = 5e5 on a 2-core machine.

use criterion::{BenchmarkId, Criterion, criterion_group, criterion_main};
use nalgebra::{SVector, Vector3};
use onebeacon::filter::particle::{ParticleFilter, ParticleSettings, Resampler};
use onebeacon::measure::Usbl;
use onebeacon::measure::hoff::{InsReport, UsblBearing};
use onebeacon::models::hoff::{DIM, HoffProcess};
use std::hint::black_box;

fn bench(c: &mut Criterion) {
    let mean = SVector::<f64, DIM>::from([100.0, 50.0, 30.0, 0.0, 0.3, 1.5, 0.0, 0.002]);
    let sigma = SVector::<f64, DIM>::from([10.0, 10.0, 2.0, 0.05, 0.2, 0.3, 0.001, 0.003]);
    let settings = ParticleSettings {
        resampler: Resampler::Systematic,
        ess_fraction: 1.0,
        roughening_k: None,
        min_effective: 0.0,
    };
    let ins = InsReport {
        heading_rad: 0.3,
        speed_m_s: 1.5,
        depth_m: 30.0,
        sigma_heading_rad: 0.15f64.sqrt(),
        sigma_speed_m_s: 0.06f64.sqrt(),
        sigma_depth_m: 0.15f64.sqrt(),
    };
    let usbl = Usbl::exact(Vector3::new(80.0, 30.0, 0.0), 0.0, 0.022f64.to_radians());
    let bearing = UsblBearing { usbl, azimuth_rad: 0.78, elevation_rad: 0.8, robust: None };
    let mut group = c.benchmark_group("hoff2024 particle filter cycle");
    group.sample_size(10);
    for n in [10_000usize, 100_000, 500_000, 1_000_000] {
        let mut pf = ParticleFilter::<DIM>::gaussian(n, &mean, &sigma, settings, 1);
        group.bench_with_input(BenchmarkId::from_parameter(n), &n, |b, _| {
            b.iter(|| {
                // as ParticleTracker runs it: resampled just before the prediction
                pf.predict_resampled(&HoffProcess::default(), 4.0);
                black_box(pf.reweight(&(ins, bearing)));
            })
        });
    }
    group.finish();
    // the cycle's stages apart, at N = 5e5
    let mut group = c.benchmark_group("hoff2024 particle filter stages, 500000");
    group.sample_size(10);
    // each from the state a cycle leaves it in (setup not timed)
    use criterion::BatchSize::LargeInput;
    let fresh = ParticleFilter::<DIM>::gaussian(500_000, &mean, &sigma, settings, 1);
    let mut predicted = fresh.clone();
    predicted.predict(&HoffProcess::default(), 4.0);
    let mut weighed = predicted.clone();
    weighed.reweight(&(ins, bearing));
    group.bench_function("predict", |b| {
        b.iter_batched_ref(|| fresh.clone(), |pf| pf.predict(&HoffProcess::default(), 4.0), LargeInput)
    });
    group.bench_function("reweight", |b| {
        b.iter_batched_ref(|| predicted.clone(), |pf| black_box(pf.reweight(&(ins, bearing))), LargeInput)
    });
    group.bench_function("resample", |b| b.iter_batched_ref(|| weighed.clone(), |pf| pf.resample(), LargeInput));
    // the estimate the tracker reports after every step: mean and covariance, the heading
    // an angle
    group.bench_function("mean and covariance", |b| b.iter(|| black_box(weighed.mean_covariance_with_angle(Some(4)))));
    group.finish();
}

/// One planner decision (3 radii x 19 angles, hoff2024.toml's) on a belief of n
/// particles, every one scored; and what the world does at N = 5e5: a systematic
/// subsample of 2e4 drawn from the filter's weights, then scored. Issue 31's target:
/// <= 5 ms at N = 5e5 (issue 13's was 50 ms).
fn planner(c: &mut Criterion) {
    use nalgebra::Vector2;
    use onebeacon::guidance::bearing::{BearingPlanner, Belief, SpreadMetric};
    let p = BearingPlanner {
        metric: SpreadMetric::Determinant,
        r1_m: 16.0,
        r2_m: 26.0,
        radii: 3,
        angles: 19,
        sigma_usbl_rad_per_m: 0.022f64.to_radians(),
    };
    let (asv, heading) = (Vector2::new(60.0, 40.0), Vector2::new(0.0, 2.0));
    let mut group = c.benchmark_group("hoff2024 planner decision, 57 candidates");
    group.sample_size(10);
    for n in [20_000usize, 100_000, 500_000] {
        let positions: Vec<Vector3<f64>> = (0..n)
            .map(|i| {
                let t = i as f64;
                Vector3::new(100.0 + 5.0 * (t * 0.7).sin(), 50.0 + 5.0 * (t * 1.3).cos(), 30.0 + (t * 0.4).sin())
            })
            .collect();
        let weights = vec![1.0 / n as f64; n];
        let belief =
            Belief { positions: &positions, weights: &weights, velocity_m_s: Vector2::new(1.0, 0.5), lead_s: 8.0 };
        group.bench_with_input(BenchmarkId::new("all", n), &n, |b, _| {
            b.iter(|| black_box(p.decide(&belief, asv, heading)))
        });
    }
    let mean = SVector::<f64, DIM>::from([100.0, 50.0, 30.0, 0.0, 0.3, 1.5, 0.0, 0.0]);
    let sigma = SVector::<f64, DIM>::from([3.0, 3.0, 0.5, 0.02, 0.1, 0.1, 0.001, 0.001]);
    let pf = ParticleFilter::<DIM>::gaussian(500_000, &mean, &sigma, ParticleSettings::default(), 1);
    group.bench_function("subsample 20000 of 500000", |b| {
        b.iter(|| {
            let picked = pf.subsample(20_000, [0, 1, 2]);
            let positions: Vec<Vector3<f64>> = picked.into_iter().map(Vector3::from).collect();
            let weights = vec![1.0 / positions.len() as f64; positions.len()];
            let belief =
                Belief { positions: &positions, weights: &weights, velocity_m_s: Vector2::new(1.0, 0.5), lead_s: 8.0 };
            black_box(p.decide(&belief, asv, heading))
        })
    });
    group.finish();
}

criterion_group!(benches, bench, planner);
criterion_main!(benches);
