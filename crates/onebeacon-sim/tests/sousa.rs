//! Properties of the moving-beacon (sousa) world at Monte Carlo counts and mission
//! lengths small enough for CI. The full reproduction is `onebeacon mc sousa`.

use onebeacon_sim::montecarlo::{CellResult, monte_carlo};
use onebeacon_sim::run::simulate;
use onebeacon_sim::scenario::moving_beacon::{GuidanceKind, PathKind};
use onebeacon_sim::scenario::{Cell, MovingBeacon, Scenario, builtin, parse};
use statrs::distribution::{ChiSquared, ContinuousCDF};

fn sousa() -> MovingBeacon {
    match parse(builtin("sousa").unwrap().toml, "sousa").unwrap() {
        Scenario::MovingBeacon(s) => s,
        _ => unreachable!(),
    }
}

fn with_sweep(
    mut s: MovingBeacon,
    paths: &[PathKind],
    depths: &[f64],
    guidance: &[GuidanceKind],
    seconds: f64,
) -> Scenario {
    s.mission.duration_s = seconds;
    s.sweep.path = Some(paths.to_vec());
    s.sweep.depth_m = Some(depths.to_vec());
    s.sweep.guidance = Some(guidance.to_vec());
    Scenario::MovingBeacon(s)
}

/// Nearly exact sensors, ranges and GPS.
fn nearly_noise_free(mut s: MovingBeacon) -> MovingBeacon {
    s.sensors.velocity_noise_m_s = 1e-5;
    s.sensors.rate_noise_rad_s = 1e-7;
    s.sensors.depth_noise_m = 1e-4;
    s.sensors.attitude_noise_deg = 1e-4;
    s.acoustics.range_noise_m = 1e-3;
    s.asv.gps_noise_m = 0.0;
    s
}

fn range_ekf(c: &CellResult) -> &onebeacon_sim::metrics::CellSummary {
    &c.estimators[0].1
}

/// With (nearly) exact sensors and ranges, a stationary vehicle's position converges
/// to the truth from its 1 m initial error.
#[test]
fn nearly_noise_free_stationary_vehicle_converges() {
    let mut s = nearly_noise_free(sousa());
    s.mission.duration_s = 600.0;
    let scenario = Scenario::MovingBeacon(s);
    let cell = match scenario.base_cell() {
        Cell::MovingBeacon(mut c) => {
            c.path = PathKind::Stationary;
            c.depth_m = 20.0;
            Cell::MovingBeacon(c)
        }
        _ => unreachable!(),
    };
    let out = simulate(&scenario, &cell, 3, 0, false);
    assert!(out.frames_decoded >= 59, "{} ranges", out.frames_decoded);
    let ekf = &out.metrics[0];
    assert!(ekf.final_error_m < 0.01, "final error {}", ekf.final_error_m);
    // dead reckoning keeps its initial error
    assert!(out.metrics[1].final_error_m > 0.05, "{}", out.metrics[1].final_error_m);
}

#[test]
fn results_do_not_depend_on_thread_count() {
    let s = with_sweep(sousa(), &[PathKind::Circular], &[5.0], &[GuidanceKind::ApproachA, GuidanceKind::Circle], 300.0);
    let one = monte_carlo(&s, 3, 5, Some(1), &|| {}).unwrap();
    let two = monte_carlo(&s, 3, 5, Some(2), &|| {}).unwrap();
    assert_eq!(one, two);
    assert_eq!(one.cells.len(), 2);
}

/// sousa Tables 4.1/4.2 properties at CI scale: FIM guidance beats a static beacon on
/// moving paths; on the circle the error stays bounded (second half within 1.5x the
/// first); ranges beat dead reckoning; the EKF's RMSE is that of an efficient filter,
/// its PCRB, up to the sampling of its runs: with R inlier runs whose steps may be
/// correlated to the point of one independent 2-D error per run, R MSE / PCRB^2 is at
/// least as spread as chi^2(2R) / 2, so RMSE / PCRB lies in sqrt of chi^2(2R)'s 0.5 %
/// and 99.5 % quantiles over 2R (R = 4: 0.41-1.66).
#[test]
fn fim_guidance_beats_a_static_beacon_and_stays_bounded() {
    let s = with_sweep(
        sousa(),
        &[PathKind::Lawnmower, PathKind::Circular],
        &[20.0],
        &[GuidanceKind::ApproachA, GuidanceKind::ApproachB, GuidanceKind::Static],
        1800.0,
    );
    let r = monte_carlo(&s, 4, 11, None, &|| {}).unwrap();
    for path in r.cells.chunks(3) {
        let (a, b, st) = (range_ekf(&path[0]), range_ekf(&path[1]), range_ekf(&path[2]));
        eprintln!(
            "{}: A {:.3} B {:.3} static {:.3}",
            path[0].cell.label(),
            a.mean_error_m,
            b.mean_error_m,
            st.mean_error_m
        );
        assert!(a.mean_error_m < st.mean_error_m && b.mean_error_m < st.mean_error_m);
        for c in path {
            let e = range_ekf(c);
            let dr = &c.estimators[1].1;
            assert!(e.mean_error_m < dr.mean_error_m, "{}", c.cell.label());
            let ratio = e.rmse_m / c.pcrb(0).unwrap();
            let dof = 2.0 * (e.runs - e.outliers) as f64;
            let chi2 = ChiSquared::new(dof).unwrap();
            let (lo, hi) = ((chi2.inverse_cdf(0.005) / dof).sqrt(), (chi2.inverse_cdf(0.995) / dof).sqrt());
            assert!((lo..=hi).contains(&ratio), "{}: RMSE/PCRB {ratio:.3} outside {lo:.2}-{hi:.2}", c.cell.label());
        }
    }
    let circle_a = range_ekf(&r.cells[3]);
    assert!(circle_a.mean_error_second_half_m < 1.5 * circle_a.mean_error_first_half_m, "{circle_a:?}");
}

fn pair() -> MovingBeacon {
    match parse(builtin("sousa-pair").unwrap().toml, "sousa-pair").unwrap() {
        Scenario::MovingBeacon(s) => s,
        _ => unreachable!(),
    }
}

/// A second vehicle in the water changes no draw and no decision of the first: the
/// first vehicle's metrics are those of the same world without the second, bit for bit.
#[test]
fn a_second_vehicle_changes_nothing_for_the_first() {
    let mut two = pair();
    two.mission.duration_s = 300.0;
    let mut one = two.clone();
    one.other_vehicles.clear();
    let (two, one) = (Scenario::MovingBeacon(two), Scenario::MovingBeacon(one));
    assert_eq!(two.tracks().len(), 4);
    assert_eq!(two.tracks()[2].label, "auv2/range-ekf");
    let a = simulate(&two, &two.base_cell(), 7, 2, true);
    let b = simulate(&one, &one.base_cell(), 7, 2, true);
    assert_eq!(a.metrics[..2], b.metrics[..]);
    assert_eq!(a.distance_m[0], b.distance_m[0]);
    assert_eq!(a.guidance, b.guidance);
    // 30 pings, each heard by both vehicles
    assert_eq!(b.frames_decoded, 30);
    assert_eq!(a.frames_decoded, 60);
    // the second vehicle's truth is its own spiral: 0.8 m/s around, 0.005 m/s down
    let along = 300.0 * (0.8f64.powi(2) + 0.005f64.powi(2)).sqrt();
    assert!((a.distance_m[1] - along).abs() < 0.01, "{} against {along}", a.distance_m[1]);
    let last = a.trajectory.last().unwrap();
    assert_eq!(last.truth.len(), 2);
    assert!((last.truth[1].pos.z - (20.0 + 0.005 * 300.0)).abs() < 1e-6, "{}", last.truth[1].pos.z);
}

/// With (nearly) exact sensors and ranges, both vehicles converge from their 1 m initial
/// error to within centimetres of their truths (measured: 2.7 and 4.9 cm after 15 min):
/// the second's ranges are the travel times to its own position (one computed from the
/// first vehicle's arrival would be tens of metres off).
#[test]
fn nearly_noise_free_pair_converges() {
    let mut s = nearly_noise_free(pair());
    s.mission.duration_s = 900.0;
    let scenario = Scenario::MovingBeacon(s);
    let out = simulate(&scenario, &scenario.base_cell(), 3, 0, false);
    for (track, m) in scenario.tracks().iter().zip(&out.metrics) {
        if track.estimator == "range-ekf" {
            assert!(m.final_error_m < 0.1, "{}: final error {}", track.label, m.final_error_m);
        } else {
            // dead reckoning keeps (a part of) its 1-sigma initial error
            assert!(m.final_error_m > 0.05, "{}: final error {}", track.label, m.final_error_m);
        }
    }
}

/// sousa's beacon on an Otter (`asv.vehicle = "otter"`): under approach A on the circular
/// path at 5 m, 30 min. The FIM planner asks at each ping for a point anywhere within its
/// reach (2 m/s x 10 s = 20 m), often behind the ASV; the Otter, its heading reference
/// limited to 10 deg/s, cannot turn round in a period as the kinematic ASV (30 deg/s)
/// nearly does, and arrives farther from it by the next ping (printed), yet within three
/// quarters of the reach on average; the run records its autopilots; and the range EKF's
/// mean error over 2 runs stays within 20 % of the kinematic ASV's on the same draws.
#[test]
fn an_otter_carries_the_beacon_where_the_guidance_asks() {
    use onebeacon_sim::run::GuidanceSnapshot;
    use onebeacon_sim::scenario::passive_usbl::AsvVehicle;
    let scenario = |vehicle: AsvVehicle| {
        let mut s = sousa();
        s.asv.vehicle = vehicle;
        with_sweep(s, &[PathKind::Circular], &[5.0], &[GuidanceKind::ApproachA], 1800.0)
    };
    let (otter, kinematic) = (scenario(AsvVehicle::Otter), scenario(AsvVehicle::Kinematic));
    let misses = |s: &Scenario| {
        let out = simulate(s, &s.cells()[0], 1, 0, true);
        let period = 10.0;
        let misses: Vec<f64> = out
            .guidance
            .iter()
            .filter_map(|g| match g {
                GuidanceSnapshot::Fim(f) => Some(f),
                _ => None,
            })
            .filter_map(|f| {
                let at = out.trajectory.iter().find(|r| (r.t_s - (f.t_s + period)).abs() < 1e-6)?;
                Some((at.beacon.xy() - f.waypoint).norm())
            })
            .collect();
        let mean_miss = misses.iter().sum::<f64>() / misses.len() as f64;
        (mean_miss, misses.len(), out.trajectory.last().unwrap().pilots.iter().any(|p| p.vehicle.is_none()))
    };
    let (mean_miss, n, piloted) = misses(&otter);
    let (kinematic_miss, _, _) = misses(&kinematic);
    assert!(piloted);
    let error = |s: &Scenario| monte_carlo(s, 2, 1, None, &|| {}).unwrap().cells[0].estimators[0].1.mean_error_m;
    let (e_otter, e_kinematic) = (error(&otter), error(&kinematic));
    eprintln!(
        "sousa, Otter-borne beacon: misses its waypoints by {mean_miss:.2} m on average ({n} pings; kinematic {kinematic_miss:.2} m); range EKF {e_otter:.3} m against {e_kinematic:.3} m kinematic"
    );
    assert!(n > 150 && mean_miss < 15.0 && kinematic_miss < mean_miss, "{mean_miss} {kinematic_miss}");
    assert!((e_otter / e_kinematic - 1.0).abs() < 0.2, "{e_otter} against {e_kinematic}");
}

/// The range scale state against the truth's effective speed. A still vehicle 50 m deep
/// under a beacon circling 40 m around a point 50 m north of it, for an hour, in the
/// tropical cast of docs/scenarios.md (1541 m/s mixed to 30 m, 1522 at 60 m); ranges are
/// 1500 m/s times the eigenray's travel time, plus 0.5 m of noise. Each ping's
/// truth is k = 1500 T / D - 1 (D the straight distance); the filter's scale ends within
/// 3 of its sigmas of the pings' mean k (a ray spends nearly the same share of its
/// length in each layer whatever its angle, so k hardly depends on the geometry), and
/// its position within 3 sigmas of the truth, where the plain filter's is off by more
/// than 1 m. Measured: truth -0.02529, filter -0.02594; 0.11 m against 3.27 m.
#[test]
fn the_range_scale_state_finds_the_effective_speed() {
    use nalgebra::{SVector, Vector3};
    use onebeacon::filter::FilterKind;
    use onebeacon::nav::{Aiding, BeaconFix, Kind, Measurement, RangeCalibration, SensorNoise, range_6dof};
    use onebeacon_sim::acoustics::profile::Profile;
    use rand::SeedableRng;
    use rand_distr::{Distribution, Normal};

    let speed = |t: f64, d: f64| onebeacon::dsp::sound_speed::mackenzie(t, 35.0, d);
    let profile = Profile::new(
        vec![0.0, 30.0, 60.0, 200.0],
        vec![speed(28.0, 0.0), speed(28.0, 30.0), speed(20.0, 60.0), speed(15.0, 200.0)],
    );
    let truth = Vector3::new(0.0, 0.0, 50.0);
    let noise = SensorNoise { velocity_m_s: 1e-3, rate_rad_s: 1e-4, depth_m: 0.05, attitude_rad: 0.01, range_m: 0.5 };
    let eta = SVector::<f64, 6>::from([0.0, 0.0, 50.0, 0.0, 0.0, 0.0]);
    let p0 = SVector::<f64, 6>::from([4.0, 4.0, 0.01, 1e-4, 1e-4, 1e-4]);
    let start = (eta, nalgebra::SMatrix::<f64, 6, 6>::from_diagonal(&p0));
    let scale = RangeCalibration { offset: None, scale_sigma: Some(0.05), current: None };
    let ungated = (f64::INFINITY, None);
    let mut scaled = range_6dof::boxed(noise, Aiding::RANGE, FilterKind::Ekf, 0.0, start, scale, ungated);
    let mut plain =
        range_6dof::boxed(noise, Aiding::RANGE, FilterKind::Ekf, 0.0, start, RangeCalibration::default(), ungated);
    let mut rng = rand_pcg::Pcg64Mcg::seed_from_u64(7);
    let range_noise = Normal::new(0.0, 0.5).unwrap();
    let mut k_truth = Vec::new();
    for i in 1..=3600 {
        let t = i as f64;
        let mut events = vec![
            Kind::BodyVelocity { nu: [0.0; 6] },
            Kind::Depth { depth_m: 50.0 },
            Kind::Attitude { roll_rad: 0.0, pitch_rad: 0.0, heading_rad: 0.0 },
        ];
        if i % 10 == 0 {
            let a = t * 2.0 * std::f64::consts::PI / 900.0;
            let beacon = Vector3::new(50.0 + 40.0 * a.cos(), 40.0 * a.sin(), 0.0);
            let d = truth - beacon;
            let travel_s = profile.travel_time(d.xy().norm(), 0.0, 50.0);
            k_truth.push(1500.0 * travel_s / d.norm() - 1.0);
            let range_m = 1500.0 * travel_s + range_noise.sample(&mut rng);
            events.push(Kind::Range { beacon: BeaconFix::fixed(0, beacon), range_m });
        }
        for e in events {
            let m = Measurement::new(t, e);
            scaled.process(&m);
            plain.process(&m);
        }
    }
    let mean_k = k_truth.iter().sum::<f64>() / k_truth.len() as f64;
    let spread = k_truth.iter().map(|k| (k - mean_k).abs()).fold(0.0, f64::max);
    let (e, ep) = (scaled.estimate(), plain.estimate());
    let k = e.calibration.range_scale.expect("the scale is estimated");
    // the scale's sigma is not in the estimate: its bound from the ranges, 0.5 m over
    // 360 ranges of about 80 m, 0.5 / (80 sqrt(360)) = 3.3e-4, times 3
    let bound = 3.0 * 0.5 / (80.0 * 360f64.sqrt()) + spread;
    println!(
        "effective scale: truth {mean_k:.5} (spread {spread:.5}), filter {:.5}; position error {:.3} m with the scale, {:.3} m without",
        k,
        e.position_ned_m.xy().norm(),
        ep.position_ned_m.xy().norm()
    );
    assert!((k - mean_k).abs() < bound, "scale {k} against {mean_k} (bound {bound})");
    let sigma = e.horizontal_cov_m2.trace().sqrt();
    assert!(
        e.position_ned_m.xy().norm() < 3.0 * sigma,
        "with the scale: {} m, sigma {sigma}",
        e.position_ned_m.xy().norm()
    );
    assert!(ep.position_ned_m.xy().norm() > 1.0, "without: {} m", ep.position_ned_m.xy().norm());
}

/// The link of `[sea.link]` loses pings in the moving_beacon world: an hour of pings
/// every 10 s to a still vehicle (about 360), half lost in bursts of 4. The count heard
/// is within 5 standard errors of half the clean world's (a Markov chain's variance, n p
/// (1 - p) (1 + rho) / (1 - rho) with rho = 0.5).
#[test]
fn the_link_loses_pings() {
    let mut s = sousa();
    s.mission.duration_s = 3600.0;
    let base = Scenario::MovingBeacon(s.clone());
    s.sea.link.loss_prob = 0.5;
    s.sea.link.loss_burst_mean = Some(4.0);
    let lossy = Scenario::MovingBeacon(s);
    let cell = match base.base_cell() {
        Cell::MovingBeacon(mut c) => {
            c.path = PathKind::Stationary;
            Cell::MovingBeacon(c)
        }
        _ => unreachable!(),
    };
    let clean = simulate(&base, &cell, 1, 0, false).frames_decoded as f64;
    let heard = simulate(&lossy, &cell, 1, 0, false).frames_decoded as f64;
    let se = (clean * 0.25 * 3.0).sqrt();
    assert!(clean >= 355.0, "{clean} pings on a clean link");
    assert!((heard - clean / 2.0).abs() < 5.0 * se, "{heard} of {clean} pings heard");
}

/// sousa-sea at CI scale (a circling vehicle at 5 m under the circling ASV, 6 runs of
/// 30 min): in every run the filter with clock, scale and Student-t ranges ends below
/// both the thesis's filter and dead reckoning, and its NEES lies in the chi-square band
/// of its inlier runs (a consistent filter's 95 % band).
#[test]
fn sousa_sea_the_augmented_filter_holds_where_the_thesis_filter_fails() {
    let mut s = match parse(builtin("sousa-sea").unwrap().toml, "sousa-sea").unwrap() {
        Scenario::MovingBeacon(s) => s,
        _ => unreachable!(),
    };
    assert!(s.sea.sound_speed.is_some() && s.sea.link.false_prob > 0.0 && s.sea.clocks.drift_sigma_ppm > 0.0);
    s.mission.duration_s = 1800.0;
    s.sweep.path = Some(vec![PathKind::Circular]);
    s.sweep.depth_m = Some(vec![5.0]);
    s.sweep.guidance = Some(vec![GuidanceKind::Circle]);
    let r = monte_carlo(&Scenario::MovingBeacon(s), 6, 1, None, &|| {}).unwrap();
    let names: Vec<&str> = r.cells[0].estimators.iter().map(|(t, _)| t.estimator.as_str()).collect();
    assert_eq!(names, ["range-ekf-sea", "range-ekf", "dead-reckoning"]);
    let [sea, paper, dr] = [0, 1, 2].map(|i| &r.cells[0].estimators[i].1);
    eprintln!(
        "sea {:.3} (NEES {:.2}), paper {:.3}, dead reckoning {:.3}",
        sea.mean_error_m, sea.nees_mean, paper.mean_error_m, dr.mean_error_m
    );
    for ((a, p), d) in sea.run_mean_errors_m.iter().zip(&paper.run_mean_errors_m).zip(&dr.run_mean_errors_m) {
        assert!(a < p && a < d, "run errors: augmented {a}, thesis {p}, dead reckoning {d}");
    }
    let [lo, hi] = sea.nees_band;
    assert!((lo..=hi).contains(&sea.nees_mean), "NEES {} outside [{lo}, {hi}]", sea.nees_mean);
}
