//! One full garin2024 run (1567 s at 4 Hz, both estimators on the same draws), and a
//! 20-run Monte Carlo cell. The 300-run, 6-cell sweep is 3600 such runs (target for
//! the sweep: under 5 s on 2 cores, i.e. about 2.8 ms per run).

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
}

criterion_group!(benches, bench);
criterion_main!(benches);
