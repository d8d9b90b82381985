//! One filter step of garin2024's navigator, predict and update, with the EKF (target:
//! under 1 us) and the UKF.

use criterion::{Criterion, criterion_group, criterion_main};
use nalgebra::{SVector, Vector3};
use onebeacon::filter::{FilterKind, UkfParams};
use onebeacon::models::unicycle::{Cov, State};
use onebeacon::nav::{Aiding, BeaconFix, EkfTuning, Kind, Measurement, Navigator, SingleBeaconNavigator};
use std::hint::black_box;

fn navigator(filter: FilterKind) -> SingleBeaconNavigator {
    let z0 = State::from([10.0, 20.0, 1.0, 1.0, 0.01, 0.0]);
    let p0 = Cov::from_diagonal(&SVector::from([1.0, 1.0, 0.01, 0.01, 1e-4, 1e-4]));
    SingleBeaconNavigator::new(Aiding::RANGE_DOPPLER, EkfTuning::default(), filter, 0.0, z0, p0)
}

fn bench(c: &mut Criterion) {
    let inertial = Kind::Inertial { heading_rad: 1.0, yaw_rate_rad_s: 0.01, accel_m_s2: 0.0 };
    let beacon = BeaconFix::fixed(0, Vector3::new(50.0, 100.0, 0.0));
    let frame = Kind::RangeDoppler { beacon, range_m: 89.0, radial_speed_m_s: 0.8 };
    for (name, kind) in [("ekf", FilterKind::Ekf), ("ukf", FilterKind::Ukf(UkfParams::default()))] {
        let mut f = navigator(kind);
        let mut t = 0.0;
        c.bench_function(&format!("{name} predict + proprioceptive update (M=3)"), |b| {
            b.iter(|| {
                t += 0.25;
                black_box(f.process(black_box(&Measurement::new(t, inertial.clone()))))
            })
        });
        c.bench_function(&format!("{name} predict + comm frame update (M=5)"), |b| {
            b.iter(|| {
                // from the same operating point every time
                let mut f = navigator(kind);
                f.process(&Measurement::new(0.25, frame.clone()));
                black_box(f.process(black_box(&Measurement::new(0.25, inertial.clone()))))
            })
        });
    }
}

criterion_group!(benches, bench);
criterion_main!(benches);
