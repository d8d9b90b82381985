//! Truth vehicles' dynamics (issue 14), RK4 at 0.05 s (72 000 steps an hour): one hour
//! of the Otter under its autopilots, a heading change every minute; one hour of the
//! REMUS 100 following hoff2024's 500 m circle by ILOS under its autopilots; and one hour
//! of hoff2024's truth, both together (the target: under 1 s).

use criterion::{Criterion, criterion_group, criterion_main};
use nalgebra::Vector2;
use nalgebra::Vector3;
use onebeacon_sim::vehicles::autopilot::{Command, Piloted};
use onebeacon_sim::vehicles::ilos::{Circle, CircleFollower, Ilos};
use onebeacon_sim::vehicles::otter::{Otter, OtterPilot};
use onebeacon_sim::vehicles::remus100::{Remus100, Remus100Pilot};
use onebeacon_sim::vehicles::rigid_body::BodyState;
use std::f64::consts::FRAC_PI_2;
use std::hint::black_box;

const STEPS: usize = 72_000;
const H: f64 = 0.05;

fn otter_hour(p: &mut OtterPilot, k: usize) {
    let psi_d = if (k / 1200).is_multiple_of(2) { 0.0 } else { 1.0 };
    p.step(&Command { heading_rad: psi_d, speed_m_s: 2.0, depth_m: None }, &Vector3::zeros(), H);
}

fn remus_on_the_circle() -> (Remus100Pilot, CircleFollower) {
    let circle = Circle { centre: Vector2::zeros(), radius_m: 500.0, clockwise: true };
    let follower =
        CircleFollower { circle, ilos: Ilos::new(10.0, 0.1), s: 0.0, mu: 0.01, speed_m_s: 1.5, depth_m: Some(30.0) };
    let pilot = Remus100Pilot::cruising(Remus100::default(), Vector3::new(500.0, 0.0, 30.0), FRAC_PI_2, 1.5);
    (pilot, follower)
}

fn remus_step(p: &mut Remus100Pilot, f: &mut CircleFollower) {
    let (command, _) = f.command(&p.state.position_ned_m.xy(), H);
    p.step(&command, &Vector3::zeros(), H);
}

fn bench(c: &mut Criterion) {
    let mut group = c.benchmark_group("vehicles");
    group.sample_size(10);
    group.bench_function("otter, one hour at 0.05 s", |b| {
        b.iter(|| {
            let mut p = OtterPilot::new(Otter::default(), BodyState::at_rest(Vector3::zeros(), 0.0));
            (0..STEPS).for_each(|k| otter_hour(&mut p, k));
            black_box(p.state)
        })
    });
    group.bench_function("remus100 on the circle by ILOS, one hour at 0.05 s", |b| {
        b.iter(|| {
            let (mut p, mut f) = remus_on_the_circle();
            (0..STEPS).for_each(|_| remus_step(&mut p, &mut f));
            black_box(p.state)
        })
    });
    group.bench_function("hoff2024 truth (otter + remus100), one hour", |b| {
        b.iter(|| {
            let mut o = OtterPilot::new(Otter::default(), BodyState::at_rest(Vector3::zeros(), 0.0));
            let (mut p, mut f) = remus_on_the_circle();
            for k in 0..STEPS {
                otter_hour(&mut o, k);
                remus_step(&mut p, &mut f);
            }
            black_box((o.state, p.state))
        })
    });
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
