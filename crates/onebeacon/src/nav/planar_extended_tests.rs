//! The planar navigator's extended layout (heading offset, current) and its coasting
//! speed, each against a closed form or a chi-square band.

use super::planar::{EXTENDED_STATES, HeadingOffsetPrior, PlanarConfig, PlanarNavigator, PlanarNoise};
use super::range_calibration::CurrentPrior;
use super::{Aiding, BeaconFix, Kind, Measurement, Navigator};
use crate::filter::{FilterKind, gauss};
use approx::assert_abs_diff_eq;
use nalgebra::{Matrix2, Vector2, Vector3};

fn dead_reckoning(c: PlanarConfig) -> PlanarNavigator<EXTENDED_STATES> {
    PlanarNavigator::<EXTENDED_STATES>::with_layout(
        PlanarConfig { aiding: Aiding::NONE, ..c },
        FilterKind::Ekf,
        0.0,
        (0.0, 0.0, 0.0),
        (0.0, 0.0),
    )
}

/// A compass that reads 3 deg (1 sigma, one draw a run) off, plus 0.5 deg of white
/// noise, on a vehicle driving north at 1 m/s with a speed log of 0.2 m/s white noise:
/// the filter's model is the truth's, so the NEES at the end of 400 s, over 200 runs, is
/// chi-square with 400 degrees of freedom over 200: within [1.73, 2.29] (95 %). (The
/// EKF leaves out the second-order shortening of the track, 200 b^2 m, 0.55 m at 3 deg:
/// beside a 0.05 m/s speed noise, whose along-track sigma is 1 m, it would lift the
/// NEES by about 0.9.) Without the offset state the fixes pin the heading to the biased
/// reading: 21 m of cross-track error against the speed noise's 4 m, a NEES near 25.
#[test]
fn a_heading_offset_carries_a_compass_bias_into_the_covariance() {
    let (sigma_bias, sigma_white, sigma_speed) = (3f64.to_radians(), 0.5f64.to_radians(), 0.2);
    let noise = PlanarNoise {
        speed_sigma_m_s: sigma_speed,
        heading_sigma_rad: sigma_white,
        heading_walk_rad_per_sqrt_m: 0.0,
        heading_change_sigma_frac: 0.0,
        ..PlanarNoise::default()
    };
    let nees = |offset: bool| {
        let mut total = 0.0;
        for run in 0..200u64 {
            let mut rng = rand_pcg::Pcg64::new(u128::from(run) + 11, 5);
            let heading_offset = offset.then_some(HeadingOffsetPrior { sigma_rad: sigma_bias, time_s: f64::INFINITY });
            // the heading unknown at the start (1 rad): the first fix sets it
            let config = PlanarConfig { aiding: Aiding::NONE, heading_offset, noise, ..PlanarConfig::default() };
            let mut nav = PlanarNavigator::<EXTENDED_STATES>::with_layout(
                config,
                FilterKind::Ekf,
                0.0,
                (0.0, 0.0, 0.0),
                (0.0, 1.0),
            );
            let bias = gauss(&mut rng, sigma_bias);
            let mut truth = Vector2::zeros();
            for k in 0..400 {
                let t = k as f64;
                let speed = 1.0 + gauss(&mut rng, sigma_speed);
                nav.process(&Measurement::new(t, Kind::Heading { heading_rad: bias + gauss(&mut rng, sigma_white) }));
                nav.process(&Measurement::new(t, Kind::Speed { speed_m_s: speed }));
                truth.x += 1.0;
            }
            nav.process(&Measurement::new(400.0, Kind::Depth { depth_m: 0.0 }));
            let e = nav.estimate();
            let err = e.position_ned_m.xy() - truth;
            total += (err.transpose() * e.horizontal_cov_m2.try_inverse().expect("positive") * err)[0];
        }
        total / 200.0
    };
    let with = nees(true);
    assert!((1.73..=2.29).contains(&with), "mean NEES {with} with the offset state");
    let without = nees(false);
    assert!(without > 10.0, "mean NEES {without} without it");
}

/// A Gauss-Markov offset decays as exp(-t / T) and its variance returns to sigma^2:
/// after T with no fix, the mean is e^-1 of a fixed start, and the variance is
/// sigma^2 (1 - e^-2) plus the start's e^-2.
#[test]
fn a_gauss_markov_offset_decays_with_its_time() {
    let h = HeadingOffsetPrior { sigma_rad: 0.05, time_s: 100.0 };
    let mut nav = dead_reckoning(PlanarConfig { heading_offset: Some(h), ..PlanarConfig::default() });
    // a fix of psi + h = 0.1 with a known heading: psi is pinned by its zero start sigma
    nav.process(&Measurement::new(0.0, Kind::Heading { heading_rad: 0.04 }));
    let (h0, v0) = (nav.heading_offset().0, nav.heading_offset().1);
    for k in 1..=100 {
        nav.process(&Measurement::new(k as f64, Kind::Depth { depth_m: 0.0 }));
    }
    let (h1, v1) = nav.heading_offset();
    let e = (-1f64).exp();
    assert_abs_diff_eq!(h1, h0 * e, epsilon = 1e-12);
    assert_abs_diff_eq!(v1, 0.05f64.powi(2) * (1.0 - e * e) + v0 * e * e, epsilon = 1e-12);
}

/// With no motion and no aiding the current alone moves the position's variance: after
/// T steps of 1 s, sigma_c^2 T^2 plus the walk's w^2 sum_{j<T} j^2 (the position moves
/// with the current of the step's start, the walk added after it).
#[test]
fn a_current_carries_the_position_variance() {
    let c = CurrentPrior { sigma_m_s: 0.1, walk_m_s_per_sqrt_s: 0.01 };
    let mut nav = dead_reckoning(PlanarConfig { current: Some(c), ..PlanarConfig::default() });
    let steps = 100;
    for k in 1..=steps {
        nav.process(&Measurement::new(k as f64, Kind::Depth { depth_m: 0.0 }));
    }
    let t = steps as f64;
    let walk: f64 = (1..steps).map(|j| (j * j) as f64).sum();
    let expected = 0.01 * t * t + 1e-4 * walk;
    let p = nav.estimate().horizontal_cov_m2;
    assert_abs_diff_eq!(p, Matrix2::identity() * expected, epsilon = 1e-9 * expected);
}

/// A vehicle at rest whose speed log reads zero, carried 0.1 m/s north-east by the
/// water, ranged from three beacons: the current's states find it (within 1 cm/s) and
/// the position follows it; without them the filter lags behind the drift.
#[test]
fn ranges_find_the_current() {
    let current = Vector2::new(0.07, 0.07);
    let beacons = [Vector3::new(0.0, 0.0, 0.0), Vector3::new(200.0, 0.0, 0.0), Vector3::new(0.0, 200.0, 0.0)];
    let run = |with: bool| {
        let config = PlanarConfig {
            current: with.then_some(CurrentPrior { sigma_m_s: 0.1, walk_m_s_per_sqrt_s: 1e-4 }),
            noise: PlanarNoise { range_sigma_m: 0.5, ..PlanarNoise::default() },
            ..PlanarConfig::default()
        };
        let mut nav = PlanarNavigator::<EXTENDED_STATES>::with_layout(
            config,
            FilterKind::Ekf,
            0.0,
            (50.0, 50.0, 0.0),
            (2.0, 0.01),
        );
        let mut rng = rand_pcg::Pcg64::new(3, 9);
        nav.process(&Measurement::new(0.0, Kind::Speed { speed_m_s: 0.0 }));
        let mut worst: f64 = 0.0;
        for k in 1..=1200 {
            let t = k as f64;
            let truth = Vector2::new(50.0, 50.0) + current * t;
            let b = beacons[k % 3];
            let range_m = (Vector3::new(truth.x, truth.y, 10.0) - b).norm() + gauss(&mut rng, 0.5);
            nav.process(&Measurement::new(t, Kind::Depth { depth_m: 10.0 }));
            nav.process(&Measurement::new(t, Kind::Range { beacon: BeaconFix::fixed((k % 3) as u32, b), range_m }));
            if k > 600 {
                worst = worst.max((nav.estimate().position_ned_m.xy() - truth).norm());
            }
        }
        // the estimate shows the current's states, and no current without them
        let shown = nav.estimate().calibration.current_ned_m_s;
        assert_eq!(shown.is_some(), with);
        assert_eq!(Vector2::from(shown.unwrap_or_default()), nav.current().0);
        (nav.current(), worst)
    };
    let ((c, _), worst) = run(true);
    assert!((c - current).norm() < 0.01, "current {c} against {current}");
    let (_, lagging) = run(false);
    assert!(worst < 1.0 && lagging > 2.0 * worst, "worst error {worst} m with the current, {lagging} m without");
}

/// A stopped propeller (speed 0 after 1 m/s for 10 s) with a coast time of 4 s: the
/// vehicle goes on 4 (1 - e^-5) m over the next 20 s, in 0.1 s speed reads of zero; it
/// stops at once without the coast time.
#[test]
fn a_stopped_propeller_coasts_with_its_time_constant() {
    let run = |coast: Option<f64>| {
        let config = PlanarConfig { aiding: Aiding::NONE, speed_coast_time_s: coast, ..PlanarConfig::default() };
        let mut nav = PlanarNavigator::new(config, FilterKind::Ekf, 0.0, (0.0, 0.0, 0.0), 0.0, 0.0);
        nav.process(&Measurement::new(0.0, Kind::Speed { speed_m_s: 1.0 }));
        for k in 100..=300 {
            nav.process(&Measurement::new(k as f64 / 10.0, Kind::Speed { speed_m_s: 0.0 }));
        }
        nav.estimate().position_ned_m.x
    };
    assert_abs_diff_eq!(run(Some(4.0)), 10.0 + 4.0 * (1.0 - (-5f64).exp()), epsilon = 1e-9);
    assert_abs_diff_eq!(run(None), 10.0, epsilon = 1e-12);
}

/// Doppler speeds over ground see the current: a vehicle held at rest (its speed log
/// reading zero, its position known) 100 m from two beacons at right angles, in 0.08
/// m/s toward the north-east, hears radial speeds of -u.c only; the current's states
/// take the value (within 1 mm/s) from them alone.
#[test]
fn doppler_speeds_see_the_current() {
    let current = Vector2::new(0.08, 0.05);
    let config = PlanarConfig {
        current: Some(CurrentPrior { sigma_m_s: 0.1, walk_m_s_per_sqrt_s: 0.0 }),
        noise: PlanarNoise { doppler_sigma_m_s: 0.01, ..PlanarNoise::default() },
        ..PlanarConfig::default()
    };
    let mut nav =
        PlanarNavigator::<EXTENDED_STATES>::with_layout(config, FilterKind::Ekf, 0.0, (0.0, 0.0, 0.0), (0.0, 0.0));
    let beacons = [Vector3::new(-100.0, 0.0, 0.0), Vector3::new(0.0, -100.0, 0.0)];
    nav.process(&Measurement::new(0.0, Kind::Speed { speed_m_s: 0.0 }));
    for k in 0..40 {
        let b = beacons[k % 2];
        let u = -b.xy() / 100.0; // from the beacon toward the vehicle
        let kind = Kind::Doppler { beacon: BeaconFix::fixed((k % 2) as u32, b), radial_speed_m_s: -u.dot(&current) };
        nav.process(&Measurement::new(0.0, kind));
    }
    let (c, _) = nav.current();
    assert!((c - current).norm() < 1e-3, "current {c} against {current}");
}
