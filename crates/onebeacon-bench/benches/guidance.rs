//! One guidance decision on a 100 x 72 polar grid with local refinement (target: under
//! 1 ms).

use criterion::{Criterion, criterion_group, criterion_main};
use nalgebra::{Vector2, Vector3};
use onebeacon::guidance::{FimPlanner, Metric, PolarGrid, ReachingSet};
use std::hint::black_box;

fn bench(c: &mut Criterion) {
    let previous = Vector2::new(30.0, 10.0);
    let reach = ReachingSet { center: previous, radius: 20.0 };
    let (target, next) = (Vector3::new(0.0, 0.0, 20.0), Vector3::new(5.0, 2.0, 20.0));
    for metric in [Metric::ApproachA, Metric::ApproachB] {
        let p = FimPlanner { metric, grid: PolarGrid::default(), range_var_m2: 1.0, beacon_depth_m: 0.0 };
        c.bench_function(&format!("guidance decision {metric:?}, 100 x 72 grid + refinement"), |b| {
            b.iter(|| black_box(p.next_waypoint(black_box(&reach), previous, &target, &next)))
        });
    }
}

criterion_group!(benches, bench);
criterion_main!(benches);
