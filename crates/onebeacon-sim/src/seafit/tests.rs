//! Logs simulated with a known sea, every source on, drawn by the simulator's own sea
//! models (`acoustics::clock`, `acoustics::link`, `sensor_errors`), fitted back.

use super::*;
use crate::acoustics::clock::{Clock, ClockErrors};
use crate::acoustics::link::{Link, LinkErrors};
use crate::seed::gauss;
use crate::sensor_errors::{DriftingSensors, SensorErrors};
use motion::OdometryFit;
use onebeacon::log::testing::{TestLog, write_log};
use rand::SeedableRng;
use rand_pcg::Pcg64Mcg;
use rayon::prelude::*;
use std::fmt::Write;

const SOUND: f64 = NOMINAL_SOUND_SPEED_M_S;
const BEACONS: [(u32, [f64; 3]); 2] = [(1, [0.0, 0.0, 50.0]), (2, [400.0, 300.0, 20.0])];
const DURATION_S: f64 = 7200.0;
const SIGMA_M: f64 = 0.5;
const SCALE: f64 = 0.01;
const LINK: LinkErrors = LinkErrors {
    loss_prob: 0.2,
    loss_burst_mean: Some(3.0),
    multipath_prob: 0.1,
    multipath_excess_m: 5.0,
    false_prob: 0.03,
    false_max_range_m: 800.0,
};
const CLOCKS: ClockErrors = ClockErrors { offset_sigma_s: 1e-3, drift_sigma_ppm: 1.0, walk_s_per_sqrt_s: 0.0 };
const SENSORS: SensorErrors = SensorErrors {
    heading_bias_sigma_deg: 3.0,
    heading_bias_time_constant_s: 600.0,
    heading_deviation_deg: 0.0,
    speed_scale_sigma: 0.03,
    speed_dropout_prob: 0.0,
    speed_dropout_mean_s: 30.0,
};
const CURRENT: [f64; 2] = [0.07, 0.07];

/// What a seed drew: per beacon (bias, drift), and the speed scale k (true = (1 + k)
/// measured).
struct Drawn {
    offsets: Vec<(f64, f64)>,
    speed_k: f64,
}

/// Two hours on circles of 300 m at 1.5 m/s through the water at 30 m, in a current;
/// two beacons pinging every 4 s in turn; heading and speed at 1 Hz.
fn simulated_log(seed: u64, with_truth: bool) -> (TestLog, Drawn) {
    let stream = |k: u64| Pcg64Mcg::seed_from_u64(seed * 16 + k);
    let mut vehicle_clock = Clock::new(&CLOCKS, stream(0));
    let mut sensors = DriftingSensors::new(&SENSORS, stream(1));
    let mut noise = stream(2);
    let (mut truth, mut ranges, mut nav) = (
        String::from("t_s,x_m,y_m,heading_rad\n"),
        String::from("t_s,beacon_id,range_m\n"),
        String::from("t_s,speed_m_s,heading_rad\n"),
    );
    let mut clocks: Vec<Clock> = (0..BEACONS.len()).map(|i| Clock::new(&CLOCKS, stream(3 + i as u64))).collect();
    let mut links: Vec<Link> = (0..BEACONS.len()).map(|i| Link::new(&LINK, stream(8 + i as u64))).collect();
    let (speed, radius) = (1.5, 300.0);
    let (mut p, mut heading) = ([200.0 - radius, 100.0], std::f64::consts::FRAC_PI_2);
    let dt = 0.5;
    let mut speed_k = 0.0;
    for step in 0..=(DURATION_S / dt) as usize {
        let t = step as f64 * dt;
        if step % 2 == 0 {
            let _ = writeln!(truth, "{t},{},{},{heading}", p[0], p[1]);
            let measured = sensors.speed(t, speed) + gauss(&mut noise, 0.02);
            if step == 0 {
                speed_k = speed / sensors.speed(t, speed) - 1.0;
            }
            let h = sensors.heading(t, heading) + gauss(&mut noise, 0.5f64.to_radians());
            let _ = writeln!(nav, "{t},{measured},{}", onebeacon::geo::wrap_angle(h));
        }
        if step % 4 == 0 {
            let i = (step / 4) % BEACONS.len();
            let (id, b) = BEACONS[i];
            let d = ((p[0] - b[0]).powi(2) + (p[1] - b[1]).powi(2) + (30.0 - b[2]).powi(2)).sqrt();
            let clock_m = SOUND * (vehicle_clock.error_s(t) - clocks[i].error_s(t));
            let r = (1.0 + SCALE) * d + clock_m + gauss(&mut noise, SIGMA_M);
            if let Some(r) = links[i].hear(r) {
                let _ = writeln!(ranges, "{t},{id},{r}");
            }
        }
        let v = [speed * heading.cos() + CURRENT[0], speed * heading.sin() + CURRENT[1]];
        p = [p[0] + v[0] * dt, p[1] + v[1] * dt];
        heading = onebeacon::geo::wrap_angle(heading + speed / radius * dt);
    }
    let offsets = clocks
        .iter_mut()
        .map(|c| {
            let at = |c: &mut Clock, v: &mut Clock, t: f64| SOUND * (v.error_s(t) - c.error_s(t));
            let (b, end) = (at(c, &mut vehicle_clock, 0.0), at(c, &mut vehicle_clock, DURATION_S));
            (b, (end - b) / DURATION_S)
        })
        .collect();
    let mut toml = String::from("name = \"sea\"\n");
    if with_truth {
        toml.push_str("[[source]]\nkind = \"ground_truth\"\nfile = \"truth.csv\"\ntime = \"t_s\"\nx = \"x_m\"\ny = \"y_m\"\nheading = \"heading_rad\"\n");
    } else {
        let _ = write!(toml, "[initial]\nfrom = \"given\"\nx_m = {}\ny_m = 100.0\nheading_deg = 90.0\n", 200.0 - 300.0);
    }
    toml.push_str(
        "[[source]]\nkind = \"range\"\nfile = \"ranges.csv\"\ntime = \"t_s\"\nbeacon = \"beacon_id\"\nrange = \"range_m\"\n\
         [[source]]\nkind = \"speed_heading\"\nfile = \"nav.csv\"\ntime = \"t_s\"\nspeed = \"speed_m_s\"\nheading = \"heading_rad\"\n\
         [[source]]\nkind = \"depth\"\nfile = \"depth.csv\"\ntime = \"t_s\"\ndepth = \"depth_m\"\n",
    );
    for (id, b) in BEACONS {
        let _ = writeln!(toml, "[[beacon]]\nid = {id}\nx_m = {}\ny_m = {}\nz_m = {}", b[0], b[1], b[2]);
    }
    toml.push_str("[[estimators]]\nname = \"dr\"\nkind = \"dead-reckoning\"\n");
    let depth = format!("t_s,depth_m\n0,30\n{DURATION_S},30\n");
    let files = [
        ("truth.csv", truth.as_str()),
        ("ranges.csv", ranges.as_str()),
        ("nav.csv", nav.as_str()),
        ("depth.csv", depth.as_str()),
    ];
    let log = write_log("seafit", &format!("seed{seed}"), &toml, &files).expect("the simulated log loads");
    (log, Drawn { offsets, speed_k })
}

/// (name, truth, fitted) of one seed: every value the fit gives an interval for.
fn recovered(seed: u64) -> Vec<(String, f64, Value)> {
    let (log, drawn) = simulated_log(seed, true);
    let f = fit(&log, &SeaFitOptions::default(), |_| {}).unwrap();
    assert_eq!(f.reference, "ground truth");
    let mut out = Vec::new();
    for (r, (bias, drift)) in f.ranges.iter().zip(&drawn.offsets) {
        let b = r.beacon;
        out.push((format!("beacon {b} bias_m"), *bias, r.bias_m));
        out.push((format!("beacon {b} scale"), SCALE, r.scale));
        out.push((format!("beacon {b} drift_m_per_s"), *drift, r.drift_m_per_s));
        out.push((format!("beacon {b} sigma_m"), SIGMA_M, r.sigma_m));
        out.push((format!("beacon {b} multipath_prob"), LINK.multipath_prob, r.multipath_prob));
        out.push((format!("beacon {b} multipath_excess_m"), LINK.multipath_excess_m, r.multipath_excess_m));
        // the share of false detections among the heard: the mixture's weight
        out.push((format!("beacon {b} false_prob"), LINK.false_prob, r.false_prob));
    }
    let l = f.loss_pooled.expect("a schedule");
    out.push(("loss_prob".into(), LINK.loss_prob, l.loss_prob));
    out.push(("loss_burst_mean".into(), LINK.loss_burst_mean.unwrap(), l.loss_burst_mean));
    out.push(("drift_sigma_ppm".into(), CLOCKS.drift_sigma_ppm, f.drift_sigma_ppm.unwrap()));
    let h = f.heading.expect("headings");
    out.push(("heading_bias_sigma_deg".into(), SENSORS.heading_bias_sigma_deg, h.bias_sigma_deg));
    out.push(("heading_bias_time_constant_s".into(), SENSORS.heading_bias_time_constant_s, h.time_constant_s));
    out.push(("heading white_deg".into(), 0.5, h.white_deg));
    let s = f.speed.expect("speeds");
    out.push(("speed scale".into(), drawn.speed_k, s.scale));
    out.push(("current_north_m_s".into(), CURRENT[0], s.current_north_m_s));
    out.push(("current_east_m_s".into(), CURRENT[1], s.current_east_m_s));
    out
}

fn covers(v: &Value, truth: f64) -> bool {
    v.interval.is_some_and(|[lo, hi]| lo <= truth && truth <= hi)
}

/// Over 40 seeds each value's 95 % interval covers the truth in at least 33 (a true
/// 95 % coverage falls below 33 of 40 with probability 3e-4, binomial), except the
/// clocks' drift sigma, which two beacons sharing one vehicle clock read with about
/// one degree of freedom (its interval is on record, not held to 95 %). The full
/// table, at more seeds: `ONEBEACON_SEAFIT_SEEDS=200 cargo test --release -p
/// onebeacon-sim seafit::tests::coverage -- --ignored --nocapture`.
#[test]
fn a_simulated_sea_is_fitted_back_within_its_intervals() {
    let table = coverage(40);
    let failing: Vec<&(String, usize, usize, f64)> =
        table.iter().filter(|(name, hit, n, _)| name != "drift_sigma_ppm" && *hit * 40 < 33 * *n).collect();
    assert!(failing.is_empty(), "coverage below 33 of 40: {failing:?}\n{}", show(&table));
}

/// What sea-fit writes is a `[sea]` table the scenario format reads (its keys known,
/// its values of the right types) and a twin takes.
#[test]
fn the_written_table_is_a_scenarios_sea() {
    let (log, _) = simulated_log(5, true);
    let text = fit(&log, &SeaFitOptions::default(), |_| {}).unwrap().to_toml("onebeacon sea-fit log.toml");
    #[derive(serde::Deserialize)]
    struct Scenario {
        sea: crate::scenario::sea::Sea,
    }
    let s: Scenario = toml::from_str(&text).unwrap_or_else(|e| panic!("{e}\n{text}"));
    assert!((s.sea.link.loss_prob - LINK.loss_prob).abs() < 0.05, "{text}");
    assert!(s.sea.sensors.heading_bias_sigma_deg > 0.0 && s.sea.current.speed_m_s > 0.0, "{text}");
    assert!(s.sea.link.false_max_range_m > 0.0 && s.sea.clocks.drift_sigma_ppm > 0.0, "{text}");
    // a twin reads it whole: each beacon's ranges, and one entry for every other beacon
    s.sea.check_twin().unwrap_or_else(|e| panic!("{e}\n{text}"));
    let ids: Vec<Option<u32>> = s.sea.ranges.iter().map(|r| r.beacon).collect();
    assert_eq!(ids, [Some(1), Some(2), None], "{text}");
}

/// Per value: name, seeds whose interval covered the truth, seeds, median fitted.
fn coverage(seeds: u64) -> Vec<(String, usize, usize, f64)> {
    let runs: Vec<Vec<(String, f64, Value)>> = (1..=seeds).into_par_iter().map(recovered).collect();
    let mut table: Vec<(String, usize, usize, f64)> = Vec::new();
    for (i, (name, _, _)) in runs[0].iter().enumerate() {
        let hit = runs.iter().filter(|r| covers(&r[i].2, r[i].1)).count();
        let mut fitted: Vec<f64> = runs.iter().map(|r| r[i].2.value).collect();
        fitted.sort_by(f64::total_cmp);
        table.push((name.clone(), hit, runs.len(), fitted[fitted.len() / 2]));
    }
    table
}

fn show(table: &[(String, usize, usize, f64)]) -> String {
    let mut s = String::from("| value | covered | median fitted |\n|---|---|---|\n");
    for (name, hit, n, median) in table {
        let _ = writeln!(s, "| {name} | {hit} / {n} ({:.0} %) | {median:.4} |", 100.0 * *hit as f64 / *n as f64);
    }
    s
}

/// The coverage table at `ONEBEACON_SEAFIT_SEEDS` seeds (default 200).
#[test]
#[ignore]
fn coverage_table() {
    let seeds = std::env::var("ONEBEACON_SEAFIT_SEEDS").ok().and_then(|s| s.parse().ok()).unwrap_or(200);
    println!("{}", show(&coverage(seeds)));
}

/// Without ground truth the smoother's trajectory is the reference, and the output says
/// so; the noise it reads against that reference is still within a factor of 2 of the
/// truth (the smoother, made from the same ranges, follows them: no tighter claim).
#[test]
fn without_ground_truth_the_smoother_is_the_reference() {
    let (log, _) = simulated_log(3, false);
    let f = fit(&log, &SeaFitOptions::default(), |_| {}).unwrap();
    assert_eq!(f.reference, "smoother");
    assert!(f.notes.iter().any(|n| n.contains("no ground truth")), "{:?}", f.notes);
    assert!(f.to_toml("onebeacon sea-fit log.toml").contains("read against the smoother's trajectory"));
    for r in &f.ranges {
        assert!(r.sigma_m.value > SIGMA_M / 2.0 && r.sigma_m.value < SIGMA_M * 2.0, "{r:?}");
    }
}

/// A land robot's odometry (the twin's drawn logs: `OdometryErrors::read`, every error
/// on) fitted back over 40 seeds in windows of 30 s: each of the two scales and two
/// noises covered by its 95 % interval in at least 33 of 40 (as above). The fit reads
/// true = (1 + k) measured, the simulator measured = (1 + scale) true: k = 1 / (1 +
/// scale) - 1.
#[test]
fn a_drawn_odometry_is_fitted_back_within_its_intervals() {
    let o = crate::twin::tests::sea().odometry;
    let k = |scale: f64| 1.0 / (1.0 + scale) - 1.0;
    let fits: Vec<OdometryFit> = (0..40u64)
        .into_par_iter()
        .map(|seed| {
            let log = crate::twin::tests::drawn_log("odometry", seed);
            fit(&log, &SeaFitOptions { window_s: 30.0, ..SeaFitOptions::default() }, |_| {}).unwrap().odometry.unwrap()
        })
        .collect();
    type Of = fn(&OdometryFit) -> Option<Value>;
    let cases: [(&str, f64, Of); 4] = [
        ("distance_scale", k(o.distance_scale), |f| Some(f.distance_scale)),
        ("turn_scale", k(o.turn_scale), |f| f.turn_scale),
        ("distance_sigma", o.distance_sigma_m_per_sqrt_m, |f| Some(f.distance_sigma)),
        ("turn_sigma", o.turn_sigma_deg_per_sqrt_s.to_radians(), |f| f.turn_sigma),
    ];
    for (name, truth, of) in cases {
        let hit = fits.iter().filter(|f| of(f).is_some_and(|v| covers(&v, truth))).count();
        let values: Vec<f64> = fits.iter().filter_map(|f| of(f).map(|v| v.value)).collect();
        assert!(hit >= 33, "{name}: {hit} of 40 covered {truth}; fitted {values:?}");
    }
}
