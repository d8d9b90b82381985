//! Properties of the garin2024 reproduction at Monte Carlo counts small enough for CI.
//! The full reproduction is `onebeacon mc garin2024` (300 runs).

use crate::common::t_interval_99;
use onebeacon_sim::metrics::CellSummary;
use onebeacon_sim::montecarlo::monte_carlo;
use onebeacon_sim::scenario::{Scenario, builtin, parse};

fn garin(t_com: &[f64]) -> Scenario {
    let Scenario::FixedBeacon(mut s) = parse(builtin("garin2024").unwrap().toml, "garin2024").unwrap() else {
        unreachable!()
    };
    s.sweep.t_com_s = Some(t_com.to_vec());
    Scenario::FixedBeacon(s)
}

fn cell<'a>(r: &'a onebeacon_sim::montecarlo::McResult, cell: usize, name: &str) -> &'a CellSummary {
    &r.cells[cell].estimators.iter().find(|(n, _)| n.label == name).unwrap().1
}

/// The runs whose mean error lies within q1 - 1.5 IQR .. q3 + 1.5 IQR of all of them
/// (quartiles by linear interpolation).
fn inliers(runs: &[f64]) -> Vec<f64> {
    let mut sorted = runs.to_vec();
    sorted.sort_by(f64::total_cmp);
    let q = |p: f64| {
        let x = p * (sorted.len() - 1) as f64;
        let (i, f) = (x.floor() as usize, x.fract());
        sorted[i] + f * (sorted[(i + 1).min(sorted.len() - 1)] - sorted[i])
    };
    let (q1, q3) = (q(0.25), q(0.75));
    let fence = 1.5 * (q3 - q1);
    runs.iter().copied().filter(|&v| v >= q1 - fence && v <= q3 + fence).collect()
}

/// range+doppler beats range-only at short and long T_com; error grows with T_com; at
/// T_com = 3 s the mean error is within 10 % of the paper's 3.61 m (Table 3, what
/// docs/reproductions/garin2024.md claims), up to the sampling of these 40 runs: the 99 % t
/// interval of the inlier runs' mean (section 4.1.1's 1.5 IQR rule, applied here by
/// hand) must reach within 10 % of 3.61 m.
#[test]
fn range_doppler_beats_rosb_and_error_grows_with_t_com() {
    let s = garin(&[3.0, 20.0]);
    let r = monte_carlo(&s, 40, 2024, None, &|| {}).unwrap();
    let (rd3, rosb3) = (cell(&r, 0, "range+doppler"), cell(&r, 0, "rosb"));
    let (rd20, rosb20) = (cell(&r, 1, "range+doppler"), cell(&r, 1, "rosb"));
    eprintln!(
        "T_com 3: {:.3} vs {:.3}; T_com 20: {:.3} vs {:.3}",
        rd3.mean_error_m, rosb3.mean_error_m, rd20.mean_error_m, rosb20.mean_error_m
    );
    let (lo, hi) = t_interval_99(&inliers(&rd3.run_mean_errors_m));
    let (paper, within) = (3.61, 0.1 * 3.61);
    assert!(lo <= paper + within && hi >= paper - within, "range+doppler at 3 s: {lo:.3}-{hi:.3} m against {paper} m");
    assert!(rd3.mean_error_m < rosb3.mean_error_m);
    assert!(rd20.mean_error_m < rosb20.mean_error_m);
    assert!(rd20.mean_error_m > rd3.mean_error_m + 1.0);
    assert!(rosb20.mean_error_m > rosb3.mean_error_m + 1.0);
}

/// Consistency of the paper's tuning (eq. 25), as measured: on the runs that do not
/// diverge the filter is conservative (mean NEES below the chi-square band: R gives the
/// heading 1 rad^2, far more than the simulated 2 deg). The filter as published
/// sometimes locks onto the point reflection of the truth through the beacon driving
/// backwards (an exact ambiguity of range + Doppler + heading), which pushes its all-run
/// NEES far above the band; mirror recovery reflects those runs back, on the same draws.
#[test]
fn mirror_recovery_removes_the_reflected_divergences() {
    let Scenario::FixedBeacon(mut s) = garin(&[3.0]) else { unreachable!() };
    let mut published = s.estimators[0].clone();
    published.name = Some("published".into());
    published.unicycle.mirror_recovery = Some(false);
    s.estimators.push(published);
    let r = monte_carlo(&Scenario::FixedBeacon(s), 100, 7, None, &|| {}).unwrap();
    let (rd, published) = (cell(&r, 0, "range+doppler"), cell(&r, 0, "published"));
    eprintln!(
        "recovered: NEES {:.3} band {:?}, all runs {:.1}, outliers {}; published: all runs {:.1}, outliers {}",
        rd.nees_mean,
        rd.nees_band,
        rd.nees_mean_all_runs,
        rd.outliers,
        published.nees_mean_all_runs,
        published.outliers
    );
    assert!(rd.nees_mean > 0.8 && rd.nees_mean < rd.nees_band[0], "{rd:?}");
    assert!(published.nees_mean_all_runs > 10.0 * rd.nees_mean_all_runs, "{published:?} against {rd:?}");
    assert!(rd.outliers <= published.outliers);
}

/// The robust filter (compass noise as simulated, speed floor) keeps every run under
/// 10 m of mean error at short and long T_com, on runs where the filter as published
/// (no mirror recovery, eq. 25's heading noise, no floor) loses some: passing the
/// beacon, its speed estimate sinks to zero and it stops while the vehicle goes on.
#[test]
fn the_robust_filter_keeps_every_run() {
    let mut lost = 0;
    for t_com in [3.0, 20.0] {
        let Scenario::FixedBeacon(mut s) = garin(&[t_com]) else { unreachable!() };
        let mut published = s.estimators[0].clone();
        published.name = Some("published".into());
        published.unicycle.mirror_recovery = Some(false);
        s.estimators.push(published);
        let s = Scenario::FixedBeacon(s);
        let labels: Vec<String> = s.track_labels();
        let (robust, published) = (
            labels.iter().position(|l| l == "range+doppler-robust").unwrap(),
            labels.iter().position(|l| l == "published").unwrap(),
        );
        let cell = &s.cells()[0];
        let mut worst = 0.0f64;
        for run in 0..60 {
            let out = onebeacon_sim::run::simulate(&s, cell, 11, run, false);
            worst = worst.max(out.metrics[robust].mean_error_m);
            lost += usize::from(out.metrics[published].mean_error_m > 10.0);
        }
        eprintln!("T_com {t_com}: robust worst run {worst:.2} m; published runs over 10 m so far: {lost}");
        assert!(worst < 10.0, "T_com {t_com}: a robust run at {worst} m");
    }
    assert!(lost > 0, "these runs must hold some the published filter loses");
}

/// The mean of the run-by-run differences a - b and the upper end of its 95 % t interval
/// (30 runs: 29 degrees of freedom, t = 2.045).
fn paired_upper(a: &[f64], b: &[f64]) -> (f64, f64) {
    assert_eq!(a.len(), 30);
    let d: Vec<f64> = a.iter().zip(b).map(|(a, b)| a - b).collect();
    let n = d.len() as f64;
    let mean = d.iter().sum::<f64>() / n;
    let sd = (d.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / (n - 1.0)).sqrt();
    (mean, mean + 2.045 * sd / n.sqrt())
}

/// garin2024-sea in still water at CI scale (T_com 3 s, 30 runs): the filter with a clock
/// state and Student-t ranges against the paper's, paired run by run: the mean of the
/// differences and its 95 % t interval lie below zero.
#[test]
fn garin2024_sea_the_clock_state_and_student_t_ranges_beat_the_paper_filter() {
    let Scenario::FixedBeacon(mut s) = parse(builtin("garin2024-sea").unwrap().toml, "garin2024-sea").unwrap() else {
        unreachable!()
    };
    assert!(s.sea.link.false_prob > 0.0 && s.sea.clocks.drift_sigma_ppm > 0.0);
    s.sea.current = Default::default();
    s.sweep.t_com_s = Some(vec![3.0]);
    let r = monte_carlo(&Scenario::FixedBeacon(s), 30, 1, None, &|| {}).unwrap();
    let (sea, paper) = (cell(&r, 0, "range+doppler-sea"), cell(&r, 0, "range+doppler"));
    let (mean, upper) = paired_upper(&sea.run_mean_errors_m, &paper.run_mean_errors_m);
    eprintln!(
        "sea {:.2} m, paper {:.2} m; paired difference {mean:.2} m, upper 95 % {upper:.2}",
        sea.mean_error_m, paper.mean_error_m
    );
    assert!(upper < 0.0, "paired difference {mean} m, upper bound {upper}");
}

/// garin2024-sea with its current (0.1 m/s) at CI scale (T_com 3 s, 30 runs): the filter
/// with the current as a state against the same filter without it, paired run by run: the
/// mean of the differences and its 95 % t interval lie below zero; over the runs that are
/// not outliers its mean NEES lies in the 95 % band of their count, where the filter
/// without the state is far above it. (Over every run it is not: this seed's runs hold
/// one of the runs the filter loses, 2 of 300 in docs/reproductions/garin2024.md.)
#[test]
fn garin2024_sea_a_current_state_carries_the_filter_through_a_current() {
    let Scenario::FixedBeacon(mut s) = parse(builtin("garin2024-sea").unwrap().toml, "garin2024-sea").unwrap() else {
        unreachable!()
    };
    assert!(s.sea.current.speed_m_s >= 0.1);
    s.sweep.t_com_s = Some(vec![3.0]);
    let r = monte_carlo(&Scenario::FixedBeacon(s), 30, 1, None, &|| {}).unwrap();
    let (current, still) = (cell(&r, 0, "range+doppler-current"), cell(&r, 0, "range+doppler-sea"));
    let (mean, upper) = paired_upper(&current.run_mean_errors_m, &still.run_mean_errors_m);
    let band = current.nees_band;
    eprintln!(
        "with the state {:.2} m (NEES {:.2}, all runs {:.2}), without {:.2} m (NEES {:.2}); band {band:?}; paired difference {mean:.2} m, upper 95 % {upper:.2}",
        current.mean_error_m, current.nees_mean, current.nees_mean_all_runs, still.mean_error_m, still.nees_mean
    );
    assert!(upper < 0.0, "paired difference {mean} m, upper bound {upper}");
    assert!(band[0] < current.nees_mean && current.nees_mean < band[1], "NEES {} out of {band:?}", current.nees_mean);
    assert!(still.nees_mean > still.nees_band[1], "without the state: NEES {}", still.nees_mean);
}

/// A simulated run says what its innovations say, without the truth: the paper's filter
/// told ranges and Doppler speeds ten times as precise as the world draws them (sigmas
/// sqrt(12) / 10 m and sqrt(0.2) / 10 m/s): its innovations keep the world's noise while
/// it expects a hundredth of its variance, less the state's share of S (so the ratio is
/// short of 100: 11.5 in this run). The run's findings name it, and its mean NIS is over
/// 5 times the paper's filter's.
#[test]
fn a_run_names_a_filter_told_too_little_noise() {
    let Scenario::FixedBeacon(mut s) = parse(builtin("garin2024").unwrap().toml, "garin2024").unwrap() else {
        unreachable!()
    };
    let mut told = s.estimators[0].clone();
    told.name = Some("told-too-little".into());
    told.noise.range_sigma_m = Some(12f64.sqrt() / 10.0);
    told.noise.doppler_sigma_m_s = Some(0.2f64.sqrt() / 10.0);
    s.estimators.push(told);
    let s = Scenario::FixedBeacon(s);
    let out = onebeacon_sim::run::simulate(&s, &s.base_cell(), s.seed(), 0, false);
    let labels = s.track_labels();
    let findings = out.findings(&labels);
    let line = findings.iter().find(|l| l.starts_with("overconfident")).expect("an overconfidence line");
    assert!(line.contains("told-too-little"), "{findings:?}");
    let nis = |label: &str| out.stats[labels.iter().position(|l| l == label).unwrap()].nis_mean();
    assert!(
        nis("told-too-little") > 5.0 * nis("range+doppler"),
        "{} against {}",
        nis("told-too-little"),
        nis("range+doppler")
    );
}
