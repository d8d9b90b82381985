//! The bits of a particle tracker and a planner decision, for comparing builds: hoff2024's
//! tracker (1e5 particles, tempered updates, residual resampling with roughening) on 30
//! messages of an AUV on a circle, then the bearing planner's waypoint. `.ci/run` runs it
//! with and without the feature `parallel` and requires the same output.
//!
//!     cargo run --release -p onebeacon --example pf_digest [--no-default-features]

use nalgebra::{Vector2, Vector3};
use onebeacon::filter::particle::{ParticleSettings, Resampler};
use onebeacon::guidance::bearing::{BearingPlanner, Belief, SpreadMetric};
use onebeacon::models::hoff::DIM;
use onebeacon::nav::{BeaconFix, Kind, Measurement, Navigator, ParticleTracker, TrackerConfig};

fn main() {
    let settings = ParticleSettings {
        resampler: Resampler::Residual,
        ess_fraction: 0.5,
        roughening_k: Some(0.2),
        min_effective: 50.0,
    };
    let x0 = nalgebra::SVector::<f64, DIM>::from([30.0, 0.0, 20.0, 0.0, 1.6, 1.5, 0.0, 0.0]);
    let sigma0 = nalgebra::SVector::<f64, DIM>::from([5.0, 5.0, 1.0, 0.05, 0.2, 0.3, 0.01, 0.01]);
    let mut pf = ParticleTracker::new(TrackerConfig::default(), settings, 100_000, 0.0, &x0, &sigma0, 7);
    let station = BeaconFix { id: 0, position_ned_m: Vector3::new(0.0, -10.0, 0.5), sigma_m: 0.5, t_tx_s: None };
    for k in 1..=30 {
        let t = 4.0 * k as f64;
        let angle = 1.5 * t / 30.0;
        let p = Vector3::new(30.0 * angle.cos(), 30.0 * angle.sin(), 20.0);
        let report = Kind::Report { heading_rad: angle + std::f64::consts::FRAC_PI_2, speed_m_s: 1.5, depth_m: 20.0 };
        pf.process(&Measurement::new(t, report));
        let d = p - station.position_ned_m;
        let bearing = Kind::Bearing {
            station,
            station_heading_rad: 0.0,
            azimuth_rad: d.y.atan2(d.x) + 0.01,
            elevation_rad: d.z.atan2(d.xy().norm()),
        };
        pf.process(&Measurement::new(t, bearing));
    }
    let e = pf.estimate();
    let positions = pf.particles().expect("a particle belief").position_sample(20_000);
    let weights = vec![1.0 / positions.len() as f64; positions.len()];
    let belief = Belief { positions: &positions, weights: &weights, velocity_m_s: Vector2::new(0.0, 1.5), lead_s: 8.0 };
    let planner = BearingPlanner {
        metric: SpreadMetric::Determinant,
        r1_m: 16.0,
        r2_m: 26.0,
        radii: 3,
        angles: 19,
        sigma_usbl_rad_per_m: 0.022f64.to_radians(),
    };
    let decision = planner.decide(&belief, Vector2::new(0.0, -10.0), Vector2::new(1.0, 0.0));
    let bits = |v: f64| format!("{:016x}", v.to_bits());
    println!(
        "estimate {} {} cov {} waypoint {} {} score {}",
        bits(e.north_m()),
        bits(e.east_m()),
        bits(e.horizontal_cov_m2[(0, 1)]),
        bits(decision.waypoint.x),
        bits(decision.waypoint.y),
        bits(decision.score)
    );
}
