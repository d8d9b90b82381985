//! Fitting an estimator's noise keys to a log: the values that maximise the likelihood
//! of its innovations (every range, Doppler speed and heading fix it weighs, with the
//! covariance S the filter predicts, as the estimator weighs them: Gaussian, or its
//! heavy-tailed kernel, a gated-out one costing the gate), found by a pattern search on
//! their logarithms within a factor of [`BOUND_FACTOR`] of where each starts. No ground truth is used, so a log without one can be tuned; the fit is
//! in-sample on that log, to be applied to another (`replay --estimators`).

use super::{Log, LogError, replay};
use crate::scenario::EstimatorSpec;
use onebeacon::nav::evaluation::ErrorStats;
use rayon::prelude::*;
use std::collections::BTreeSet;

/// The keys `tune` can fit, with the value a search starts from when the key is 0 (a
/// process noise that is off).
pub const TUNABLE: [(&str, f64); 10] = [
    ("range_sigma_m", 1.0),
    ("doppler_sigma_m_s", 0.1),
    ("heading_sigma_deg", 2.0),
    ("distance_sigma_frac", 0.02),
    ("heading_change_sigma_frac", 0.02),
    ("heading_walk_deg_per_sqrt_m", 0.1),
    ("speed_sigma_m_s", 0.05),
    ("bias_walk_m_per_sqrt_s", 0.005),
    ("position_walk_m_per_sqrt_s", 0.1),
    ("track_accel_sigma_m_s2", 0.1),
];

/// The keys tuned when none are named: the range noise and the odometry's.
pub const DEFAULT_KEYS: [&str; 4] =
    ["range_sigma_m", "distance_sigma_frac", "heading_change_sigma_frac", "heading_walk_deg_per_sqrt_m"];

/// The value of a tunable key in `spec`: given, or the default the estimator runs with;
/// None for a key `tune` does not know.
fn key_value(spec: &EstimatorSpec, key: &str) -> Option<f64> {
    let c = spec.planar_config();
    let n = c.noise;
    Some(match key {
        "range_sigma_m" => n.range_sigma_m,
        "doppler_sigma_m_s" => n.doppler_sigma_m_s,
        "heading_sigma_deg" => n.heading_sigma_rad.to_degrees(),
        "distance_sigma_frac" => n.distance_sigma_frac,
        "heading_change_sigma_frac" => n.heading_change_sigma_frac,
        "heading_walk_deg_per_sqrt_m" => n.heading_walk_rad_per_sqrt_m.to_degrees(),
        "speed_sigma_m_s" => n.speed_sigma_m_s,
        "bias_walk_m_per_sqrt_s" => n.bias_walk_m_per_sqrt_s,
        "position_walk_m_per_sqrt_s" => n.position_walk_m_per_sqrt_s,
        "track_accel_sigma_m_s2" => c.track_accel_sigma_m_s2.unwrap_or(0.0),
        _ => return None,
    })
}

/// An estimator tuned on a log.
#[derive(Debug, Clone)]
pub struct Tuned {
    /// The estimator with its tuned keys set.
    pub spec: EstimatorSpec,
    /// Each key: its value before and after.
    pub keys: Vec<(String, f64, f64)>,
    /// Each key's 95 % interval from the likelihood's curvature at the fit (Wald's, on
    /// the key's logarithm, the other keys free): None where the curvature does not
    /// determine one (a key at its bound, a flat or saddle-shaped likelihood). It takes
    /// the innovations as independent; on a real log they are not, and the interval is
    /// a lower bound on how uncertain the value is.
    pub intervals: Vec<Option<[f64; 2]>>,
    /// Default keys left out: the estimator does not use them on this log.
    pub dropped: Vec<String>,
    /// The innovations' negative log-likelihood before and after (as the estimator
    /// weighs them).
    pub nll_before: f64,
    pub nll_after: f64,
    /// The estimator's statistics on the log before and after (errors and NEES need
    /// the log's ground truth; in-sample).
    pub before: ErrorStats,
    pub after: ErrorStats,
    /// Replays of the log the search took.
    pub evaluations: usize,
}

/// The fewest innovations a tuned key needs: fewer and the likelihood's optimum is
/// whatever fits those few corrections.
pub const MIN_INNOVATIONS_PER_KEY: usize = 10;

/// The smallest step of the search, as a factor on a value: it stops at 2 %.
const FINEST_STEP: f64 = 1.02;

/// How far a value may go from where it started, as a factor either way: a fit that
/// wants more (a range sigma of 1.5 m driven to 15 m by a few gross outliers) says the
/// model misses something, and the value stops at the bound, reported.
pub const BOUND_FACTOR: f64 = 10.0;

/// Whether a key tuned from `from` to `to` stopped at its bound.
pub fn at_bound(from: f64, to: f64) -> bool {
    (to / from).ln().abs() >= BOUND_FACTOR.ln() * 0.999
}

/// The step, on a key's logarithm, of the finite differences of the likelihood's
/// curvature: a factor of 1.1.
const CURVATURE_STEP: f64 = 0.095_310_179_804_324_87; // ln 1.1

/// Each key's 95 % interval, or None.
type Intervals = Vec<Option<[f64; 2]>>;

/// The 95 % intervals of keys at `x` (logarithms), from the Hessian of `f` there by
/// central differences over the keys not at their bound (`bounded`; held where they
/// are): 2 k^2 evaluations for k free keys. None for a key at its bound, and for every
/// key where the Hessian is not positive definite.
fn intervals(
    x: &[f64],
    f0: f64,
    bounded: &[bool],
    f: impl Fn(&[f64]) -> Result<f64, LogError> + Sync,
) -> Result<(Intervals, usize), LogError> {
    let free: Vec<usize> = (0..x.len()).filter(|i| !bounded[*i]).collect();
    let k = free.len();
    let h = CURVATURE_STEP;
    let at = |moves: &[(usize, f64)]| {
        let mut y = x.to_vec();
        for (i, d) in moves {
            y[free[*i]] += d;
        }
        y
    };
    // the points: each free key +-h, each pair (+-h, +-h)
    let mut points: Vec<Vec<(usize, f64)>> = Vec::new();
    for i in 0..k {
        points.push(vec![(i, h)]);
        points.push(vec![(i, -h)]);
        for j in 0..i {
            for (a, b) in [(h, h), (h, -h), (-h, h), (-h, -h)] {
                points.push(vec![(i, a), (j, b)]);
            }
        }
    }
    let values = points.par_iter().map(|m| f(&at(m))).collect::<Result<Vec<_>, _>>()?;
    let mut hessian = nalgebra::DMatrix::<f64>::zeros(k, k);
    let mut v = values.iter();
    for i in 0..k {
        let (plus, minus) = (*v.next().expect("counted"), *v.next().expect("counted"));
        hessian[(i, i)] = (plus - 2.0 * f0 + minus) / (h * h);
        for j in 0..i {
            let c: Vec<f64> = (0..4).map(|_| *v.next().expect("counted")).collect();
            let hij = (c[0] - c[1] - c[2] + c[3]) / (4.0 * h * h);
            (hessian[(i, j)], hessian[(j, i)]) = (hij, hij);
        }
    }
    let covariance = hessian.cholesky().map(|c| c.inverse());
    let mut out = vec![None; x.len()];
    for (i, &key) in free.iter().enumerate() {
        let sd = covariance.as_ref().map_or(f64::NAN, |c| c[(i, i)].sqrt());
        if sd.is_finite() {
            out[key] = Some([round4((x[key] - 1.96 * sd).exp()), round4((x[key] + 1.96 * sd).exp())]);
        }
    }
    Ok((out, values.len()))
}

/// A value rounded to 4 significant digits (what the tuned file holds).
fn round4(v: f64) -> f64 {
    if v == 0.0 || !v.is_finite() {
        return v;
    }
    let scale = 10f64.powi(3 - v.abs().log10().floor() as i32);
    (v * scale).round() / scale
}

/// Tunes `keys` of `spec` on `log` replayed with each of `beacon_sets` (all beacons for
/// `None`; the likelihoods of the sets multiplied, so that one choice serves a filter
/// with many beacons and with one): a compass search on
/// the logarithms of the values, steps from a factor of 2 down to 2 % (doubled after a
/// round that helped, halved after one that did not), each round trying every key up
/// and down (in parallel; the result does not depend on the thread count).
/// `progress` is called after each round.
/// A key the estimator does not use on the log (see below) is refused when `named` (the
/// user asked for it) and left out otherwise (the default keys), said in
/// [`Tuned::dropped`].
pub fn tune(
    log: &Log,
    spec: &EstimatorSpec,
    keys: &[String],
    named: bool,
    beacon_sets: &[Option<BTreeSet<u32>>],
    progress: impl Fn(),
) -> Result<Tuned, LogError> {
    assert!(!beacon_sets.is_empty(), "at least one beacon set");
    let start: Vec<f64> = keys
        .iter()
        .map(|k| {
            let nominal = TUNABLE.iter().find(|(t, _)| t == k).map(|t| t.1).expect("checked against TUNABLE");
            key_value(spec, k).filter(|v| *v > 0.0).unwrap_or(nominal).ln()
        })
        .collect();
    let with = |x: &[f64]| {
        let mut s = spec.clone();
        for (k, v) in keys.iter().zip(x) {
            *s.key_mut(k).expect("checked against TUNABLE") = Some(round4(v.exp()));
        }
        s
    };
    // one replay: the negative log-likelihood and the statistics of the first set
    let replay_one = |x: &[f64], set: &Option<BTreeSet<u32>>| -> Result<(f64, ErrorStats), LogError> {
        let mut one = log.clone();
        one.description.estimators = vec![with(x)];
        let r = replay(&one, set.clone(), |_| Ok::<(), LogError>(()))?;
        let st = r.session.stats[0];
        // a filter that weighs nothing, or diverges to non-finite, is the worst there is
        let nll = st.neg_log_likelihood();
        Ok((if st.nis_count > 0 && nll.is_finite() { nll } else { f64::INFINITY }, st))
    };
    let evaluate = |x: &[f64]| -> Result<(f64, ErrorStats), LogError> {
        let each = beacon_sets.par_iter().map(|set| replay_one(x, set)).collect::<Result<Vec<_>, _>>()?;
        Ok((each.iter().map(|e| e.0).sum(), each[0].1))
    };
    // a key the estimator's model does not have would change the model, not fit it
    if let Some(k) = keys.iter().find(|k| *k == "track_accel_sigma_m_s2")
        && spec.planar.track_accel_sigma_m_s2.is_none()
    {
        return Err(LogError::File {
            file: log.description.name.clone(),
            message: format!(
                "estimator `{}` does not use {k}: setting it would make it a constant-velocity tracker, another \
                 model (tune it on an estimator that sets it)",
                spec.name()
            ),
        });
    }
    let (nll_before, before) = evaluate(&start)?;
    // a key that changes none of the innovations is one the estimator does not use on
    // this log (a Doppler noise without Doppler speeds, a bias walk without a bias)
    let doubled = (0..keys.len())
        .into_par_iter()
        .map(|i| {
            let mut y = start.clone();
            y[i] += 2f64.ln();
            evaluate(&y).map(|(nll, _)| nll)
        })
        .collect::<Result<Vec<_>, _>>()?;
    let unused: Vec<usize> = (0..keys.len()).filter(|i| doubled[*i] == nll_before && nll_before.is_finite()).collect();
    if !named && !unused.is_empty() && unused.len() < keys.len() {
        let kept: Vec<String> =
            keys.iter().enumerate().filter(|(i, _)| !unused.contains(i)).map(|(_, k)| k.clone()).collect();
        let mut t = tune(log, spec, &kept, true, beacon_sets, progress)?;
        t.dropped = unused.iter().map(|i| keys[*i].clone()).collect();
        return Ok(t);
    }
    if let Some(&i) = unused.first() {
        return Err(LogError::File {
            file: log.description.name.clone(),
            message: format!(
                "estimator `{}` does not use {} on this log (doubling it changes none of its innovations): \
                 leave it out of --keys",
                spec.name(),
                keys[i]
            ),
        });
    }
    // a likelihood of fewer innovations than a handful per key fits noise, not the log
    let needed = MIN_INNOVATIONS_PER_KEY * keys.len();
    if before.nis_count < needed {
        return Err(LogError::File {
            file: log.description.name.clone(),
            message: format!(
                "estimator `{}` weighs {} innovation(s) on this log{}; tuning {} key(s) needs at least {needed} \
                 ({MIN_INNOVATIONS_PER_KEY} per key): tune fewer keys, on a longer log, or an estimator that uses \
                 ranges or Doppler",
                spec.name(),
                before.nis_count,
                if before.nis_count == 0 { " (it uses no measurement: nothing to fit)" } else { "" },
                keys.len()
            ),
        });
    }
    let (mut x, mut best, mut evaluations) = (start.clone(), nll_before, beacon_sets.len() * (1 + keys.len()));
    let mut step = 2f64.ln();
    while step >= FINEST_STEP.ln() {
        let candidates: Vec<Vec<f64>> = (0..2 * keys.len())
            .map(|c| {
                let mut y = x.clone();
                let (i, bound) = (c / 2, BOUND_FACTOR.ln());
                y[i] = (y[i] + if c % 2 == 0 { step } else { -step }).clamp(start[i] - bound, start[i] + bound);
                y
            })
            .filter(|y| *y != x)
            .collect();
        let scores = candidates.par_iter().map(|y| evaluate(y).map(|(nll, _)| nll)).collect::<Result<Vec<_>, _>>()?;
        evaluations += candidates.len() * beacon_sets.len();
        // the best candidate, the first of equals
        let (i, nll) =
            scores.iter().enumerate().fold((usize::MAX, best), |a, (i, &s)| if s < a.1 { (i, s) } else { a });
        // a move that helped doubles the step (to a factor of 2), one that did not halves it
        if i == usize::MAX {
            step /= 2.0;
        } else {
            x = candidates[i].clone();
            best = nll;
            step = (step * 2.0).min(2f64.ln());
        }
        progress();
    }
    let keys: Vec<(String, f64, f64)> = keys
        .iter()
        .zip(start.iter().zip(&x))
        .map(|(k, (a, b))| (k.clone(), round4(a.exp()), round4(b.exp())))
        .collect();
    let (nll_after, after) = evaluate(&x)?;
    evaluations += beacon_sets.len();
    let bounded: Vec<bool> = keys.iter().map(|(_, a, b)| at_bound(*a, *b)).collect();
    let (intervals, n) = intervals(&x, nll_after, &bounded, |y| evaluate(y).map(|(nll, _)| nll))?;
    evaluations += n * beacon_sets.len();
    // a fit that gates out most corrections has made the gate, not the noise, explain
    // the log: refused
    if 2 * after.rejected > after.nis_count {
        return Err(LogError::File {
            file: log.description.name.clone(),
            message: format!(
                "estimator `{}` tuned gates out {} of its {} corrections: the fit explains the log by rejecting it \
                 (check the log's ranges and the estimator's nis_gate; tune fewer keys)",
                spec.name(),
                after.rejected,
                after.nis_count
            ),
        });
    }
    Ok(Tuned {
        spec: with(&x),
        keys,
        intervals,
        dropped: Vec::new(),
        nll_before,
        nll_after,
        before,
        after,
        evaluations,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use onebeacon::nav::Robust;
    use rand::SeedableRng;
    use rand_distr::{Distribution, Normal};

    /// A vehicle on a 40 m circle with exact odometry, ranged from three beacons with
    /// Gaussian noise of 0.8 m, every `outlier_every`-th range 40 m long (none for 0),
    /// with the estimator `estimator` (TOML keys after name and kind): the log, the
    /// standard deviation of the Gaussian noise drawn and every range's error.
    fn circle_log(
        name: &str,
        outlier_every: usize,
        estimator: &str,
    ) -> (onebeacon::log::testing::TestLog, f64, Vec<f64>) {
        let beacons = [(0, 60.0, 0.0), (1, -30.0, 50.0), (2, -30.0, -50.0)];
        let noise = Normal::new(0.0, 0.8).unwrap();
        let mut rng = rand_pcg::Pcg64::seed_from_u64(7);
        let (r, step) = (40.0f64, 0.5f64);
        let dpsi = step / r;
        let (mut odo, mut ranges, mut truth) =
            (String::from("t,d,dh\n"), String::from("t,id,r\n"), String::from("t,x,y,h\n"));
        let (mut drawn_sq, mut drawn_n, mut errors) = (0.0, 0, Vec::new());
        let (mut n, mut e, mut psi) = (0.0f64, 0.0f64, 0.0f64);
        truth += "0,0,0,0\n";
        for k in 1..=2000 {
            let t = k as f64 * 0.5;
            n += 2.0 * r * (dpsi / 2.0).sin() * (psi + dpsi / 2.0).cos();
            e += 2.0 * r * (dpsi / 2.0).sin() * (psi + dpsi / 2.0).sin();
            psi += dpsi;
            odo += &format!("{t},{},{dpsi}\n", 2.0 * r * (dpsi / 2.0).sin());
            truth += &format!("{t},{n},{e},{psi}\n");
            if k % 2 == 0 {
                let (id, bn, be) = beacons[(k / 2) % 3];
                let w: f64 = noise.sample(&mut rng);
                drawn_sq += w * w;
                drawn_n += 1;
                let outlier = if outlier_every > 0 && (k / 2) % outlier_every == 0 { 40.0 } else { 0.0 };
                errors.push(w + outlier);
                ranges += &format!("{t},{id},{}\n", (n - bn).hypot(e - be) + w + outlier);
            }
        }
        let beacon_rows: String = beacons.iter().map(|(id, n, e)| format!("{id},{n},{e}\n")).collect();
        let beacon_rows = format!("id,x,y\n{beacon_rows}");
        let toml = format!(
            "name = \"circle\"\n\
            [[source]]\nkind = \"odometry\"\nfile = \"odo.csv\"\ntime = \"t\"\ndistance = \"d\"\nheading_change = \"dh\"\n\
            [[source]]\nkind = \"range\"\nfile = \"ranges.csv\"\ntime = \"t\"\nbeacon = \"id\"\nrange = \"r\"\n\
            [[source]]\nkind = \"ground_truth\"\nfile = \"truth.csv\"\ntime = \"t\"\nx = \"x\"\ny = \"y\"\nheading = \"h\"\n\
            [beacons]\nfile = \"b.csv\"\nid = \"id\"\nx = \"x\"\ny = \"y\"\n\
            [[estimators]]\nname = \"ekf\"\nkind = \"range-ekf\"\nrange_sigma_m = 2.0\ndistance_sigma_frac = 0.001\n\
            heading_change_sigma_frac = 0.001\nheading_walk_deg_per_sqrt_m = 0.001\n{estimator}"
        );
        let files = [("odo.csv", &odo), ("ranges.csv", &ranges), ("truth.csv", &truth), ("b.csv", &beacon_rows)];
        let log =
            onebeacon::log::testing::write_log("tune", name, &toml, &files.map(|(f, t)| (f, t.as_str()))).unwrap();
        (log, (drawn_sq / drawn_n as f64).sqrt(), errors)
    }

    fn range_sigma(log: &Log) -> Result<Tuned, LogError> {
        tune(log, &log.description.estimators[0], &["range_sigma_m".to_string()], true, &[None], || {})
    }

    /// Gaussian noise only: tuning `range_sigma_m` from 2 m recovers the noise drawn
    /// (its sample standard deviation) to 10 %, and lowers the likelihood's cost.
    #[test]
    fn tune_recovers_the_range_noise_of_a_synthetic_log() {
        let (log, drawn, _) = circle_log("clean", 0, "");
        let t = range_sigma(&log).unwrap();
        let fitted = t.keys[0].2;
        assert!((fitted / drawn - 1.0).abs() < 0.1, "fitted {fitted} m, drawn {drawn} m");
        assert!(t.nll_after < t.nll_before);
        assert_eq!(t.spec.noise.range_sigma_m, Some(fitted));
    }

    /// The fitted range sigma's interval against the closed form: n Gaussian residuals
    /// give ln sigma a standard error of 1 / sqrt(2 n) (the Fisher information of a
    /// normal's log scale, 2 per residual); over the 1000 ranges, a 95 % interval of
    /// +-1.96 / sqrt(2000) on the logarithm, which holds the noise drawn. The filter adds
    /// its state's uncertainty to each S, so the width is matched to 20 %.
    #[test]
    fn a_tuned_key_has_the_interval_of_its_likelihood() {
        let (log, drawn, errors) = circle_log("interval", 0, "");
        let t = range_sigma(&log).unwrap();
        let ([lo, hi], fitted) = (t.intervals[0].expect("an interval"), t.keys[0].2);
        assert!(lo < drawn && drawn < hi, "[{lo}, {hi}] against {drawn} drawn");
        let half = (hi / lo).ln() / 2.0;
        let closed = 1.96 / (2.0 * errors.len() as f64).sqrt();
        assert!((half / closed - 1.0).abs() < 0.2, "half-width {half} on ln sigma, closed form {closed}");
        assert!(lo < fitted && fitted < hi);
    }

    /// A key the estimator does not use is refused when asked for by name, and left out
    /// of the default keys: the circle log has no Doppler speed (doubling its noise
    /// changes nothing), and a constant-velocity tracker's acceleration noise would make
    /// the odometry filter another model. Before issue 53 both were "tuned".
    #[test]
    fn a_key_the_estimator_does_not_use_is_refused() {
        let (log, _, _) = circle_log("unused", 0, "");
        let spec = &log.description.estimators[0];
        for (key, says) in [
            ("doppler_sigma_m_s", "does not use doppler_sigma_m_s on this log"),
            ("track_accel_sigma_m_s2", "constant-velocity tracker"),
        ] {
            let keys = ["range_sigma_m".to_string(), key.to_string()];
            let e = tune(&log, spec, &keys, true, &[None], || {}).unwrap_err().to_string();
            assert!(e.contains(says), "{e}");
        }
        let keys = ["range_sigma_m".to_string(), "doppler_sigma_m_s".to_string()];
        let t = tune(&log, spec, &keys, false, &[None], || {}).unwrap();
        assert_eq!((t.keys.len(), t.dropped.clone()), (1, vec!["doppler_sigma_m_s".to_string()]));
    }

    /// The sigma that maximises a likelihood of the ranges' errors alone, cost rho(d^2)
    /// plus ln sigma per range, by brute force over 1 mm steps (the filter adds its
    /// state's uncertainty to each S: small here, exact odometry and three beacons).
    fn brute_force_sigma(errors: &[f64], rho: impl Fn(f64) -> f64) -> f64 {
        let cost = |s: f64| errors.iter().map(|e| rho((e / s).powi(2)) + s.ln()).sum::<f64>();
        (100..20_000)
            .map(|i| i as f64 * 1e-3)
            .fold((0.0, f64::INFINITY), |b, s| if cost(s) < b.1 { (s, cost(s)) } else { b })
            .0
    }

    /// One range in ten 40 m long: a Gaussian estimator's (ungated) likelihood widens the noise to
    /// cover them (more than 5 times the noise drawn); a Student-t (4 dof) and a gated
    /// estimator, tuned by their own likelihood, land within 10 % of that likelihood's
    /// optimum over the ranges' errors, by brute force (the Student-t's is 1.26 times the
    /// noise drawn: its tail still feels the outliers; the gated one's the noise drawn).
    #[test]
    fn robust_and_gated_estimators_are_tuned_by_their_own_likelihood() {
        let (gauss, drawn, _) = circle_log("outliers-gauss", 10, "nis_gate = inf\n");
        let wide = range_sigma(&gauss).unwrap().keys[0].2;
        assert!(wide > 5.0 * drawn, "a Gaussian fit covers the outliers: {wide} m");
        let student = Robust::StudentT { dof: 4.0 };
        type Rho<'a> = &'a dyn Fn(f64) -> f64;
        let cases: [(&str, &str, Rho); 2] = [
            ("student", "robust = \"student_t\"\nnis_gate = inf\n", &|d2| -student.log_density(d2)),
            ("gated", "nis_gate = 10.83\n", &|d2: f64| 0.5 * d2.min(10.83)),
        ];
        for (name, keys, rho) in cases {
            let (log, _, errors) = circle_log(&format!("outliers-{name}"), 10, keys);
            let fitted = range_sigma(&log).unwrap().keys[0].2;
            let best = brute_force_sigma(&errors, rho);
            assert!((fitted / best - 1.0).abs() < 0.1, "{name}: fitted {fitted} m, likelihood's optimum {best} m");
        }
    }

    /// Every other range 40 m long and a tight gate: whatever the fit, most corrections
    /// are gated out, and tune refuses it by name.
    #[test]
    fn a_fit_that_gates_out_most_corrections_is_refused() {
        let (log, _, _) = circle_log("mostly-outliers", 2, "nis_gate = 3.84\n");
        let e = range_sigma(&log).unwrap_err().to_string();
        assert!(e.contains("gates out") && e.contains("explains the log by rejecting it"), "{e}");
    }
}
