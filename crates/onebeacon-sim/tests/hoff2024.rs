//! hoff2024 (passive USBL) at small sizes: the planners against the static ASV, the
//! particle filter's consistency, and results that do not depend on the thread count.
//! The full reproduction is `onebeacon mc hoff2024` (5e5 particles, 1 h, 20 runs).

use crate::common::t_interval_99;
use onebeacon_sim::montecarlo::monte_carlo;
use onebeacon_sim::scenario::passive_usbl::GuidanceKind;
use onebeacon_sim::scenario::{Scenario, builtin, parse};

/// hoff2024 with `particles` particles over `duration_s`, with the given guidance
/// sweep.
fn small(particles: usize, duration_s: f64, guidance: &[GuidanceKind]) -> Scenario {
    let Scenario::PassiveUsbl(mut s) = parse(builtin("hoff2024").unwrap().toml, "hoff2024").unwrap() else {
        unreachable!()
    };
    s.mission.duration_s = duration_s;
    s.estimators[0].particle.particles = Some(particles);
    s.guidance.planner_particles = 1000;
    s.sweep.guidance = Some(guidance.to_vec());
    Scenario::PassiveUsbl(s)
}

/// Ten minutes, two runs: under the det planner the particle filter stays within five
/// times what one bearing resolves (at 35 m with 0.01 deg per metre: 35 m x 0.35 deg =
/// 0.21 m), while from a static ASV the AUV, 900 m around its 500 m circle from where
/// it started, is about 780 m away, where one bearing resolves (780 / 35)^2 = 500 times
/// less (eq. 3: the noise grows with range): at least 3 times worse is a wide margin.
#[test]
fn the_planner_beats_a_static_asv() {
    let s = small(20_000, 600.0, &[GuidanceKind::Determinant, GuidanceKind::Static]);
    let r = monte_carlo(&s, 2, 1, None, &|| {}).unwrap();
    let pf = |cell: usize| &r.cells[cell].estimators[0].1;
    let (det, fixed) = (pf(0), pf(1));
    let one_bearing_m = 35.0 * 0.35f64.to_radians();
    assert!(det.mean_error_m < 5.0 * one_bearing_m, "det: {det:?}");
    assert!(
        fixed.mean_error_m > 3.0 * det.mean_error_m,
        "static {} against det {}",
        fixed.mean_error_m,
        det.mean_error_m
    );
    // the bound is reported beside the error
    assert!(r.cells[0].pcrb(0).is_some_and(|b| b > 0.0 && b < 1.0), "{:?}", r.cells[0].pcrb_rmse_m);
}

/// The particle filter under the det planner is consistent: the mean position NEES of
/// each of 8 independent ten-minute runs (each run's steps are correlated, the runs are
/// not), and 2, a consistent filter's, within the 99 % t interval of their mean (7
/// degrees of freedom: +-3.50 standard errors).
#[test]
fn the_filter_is_consistent() {
    const RUNS: u64 = 8;
    let s = small(20_000, 600.0, &[GuidanceKind::Determinant]);
    let nees: Vec<f64> = (0..RUNS)
        .map(|seed| monte_carlo(&s, 1, 100 + seed, None, &|| {}).unwrap().cells[0].estimators[0].1.nees_mean_all_runs)
        .collect();
    let (lo, hi) = t_interval_99(&nees);
    eprintln!("per-run NEES {nees:.2?}: {lo:.2}-{hi:.2}");
    assert!((lo..=hi).contains(&2.0), "NEES interval {lo:.2}-{hi:.2} (runs {nees:.2?})");
}

/// The same cells with one and two worker threads, bit for bit (the particle filter
/// draws from streams of (seed, step, chunk), the planner scores in order).
#[test]
fn results_do_not_depend_on_the_thread_count() {
    let s = small(3000, 120.0, &[GuidanceKind::MaxEigenvalue, GuidanceKind::Circle]);
    let one = monte_carlo(&s, 2, 7, Some(1), &|| {}).unwrap();
    let two = monte_carlo(&s, 2, 7, Some(2), &|| {}).unwrap();
    assert_eq!(one, two);
}
