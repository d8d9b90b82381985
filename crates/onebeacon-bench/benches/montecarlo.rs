//! One full garin2024 run (1567 s at 4 Hz, both estimators on the same draws), and a
//! 20-run Monte Carlo cell. The 300-run, 6-cell sweep is 1800 such runs (target for
//! the sweep: under 5 s on 2 cores, i.e. about 5.5 ms per run).
//! One sousa mission: 2 h at 10 Hz with ASV guidance (approach A) every 10 s (target:
//! under 1 s).

use criterion::{Criterion, criterion_group, criterion_main};
use onebeacon_sim::montecarlo::monte_carlo;
use onebeacon_sim::run::simulate;
use onebeacon_sim::scenario::{Scenario, builtin, parse};
use std::hint::black_box;

fn bench(c: &mut Criterion) {
    let s = parse(builtin("garin2024").unwrap().toml, "garin2024").unwrap();
    let cell = s.base_cell();
    let Scenario::FixedBeacon(mut one_cell) = s.clone() else { unreachable!() };
    one_cell.sweep.t_com_s = Some(vec![3.0]);
    let one_cell = Scenario::FixedBeacon(one_cell);
    let mut run = 0u64;
    c.bench_function("garin2024 one run (6269 steps, 2 estimators)", |b| {
        b.iter(|| {
            run += 1;
            black_box(simulate(&s, &cell, 1, run, false))
        })
    });
    let mut group = c.benchmark_group("garin2024 monte carlo");
    group.sample_size(10);
    group.bench_function("20 runs, 1 cell, all cores", |b| {
        b.iter(|| black_box(monte_carlo(&one_cell, 20, 1, None, &|| {})))
    });
    group.finish();

    let sousa = parse(builtin("sousa").unwrap().toml, "sousa").unwrap();
    let cell = sousa.base_cell();
    let mut group = c.benchmark_group("sousa");
    group.sample_size(10);
    let mut run = 0u64;
    group.bench_function("one 2 h mission at 10 Hz, approach A, 2 estimators", |b| {
        b.iter(|| {
            run += 1;
            black_box(simulate(&sousa, &cell, 1, run, false))
        })
    });
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
