//! Error statistics of one run and their aggregation over Monte Carlo runs
//! (garin2024 section 4.1: mean error, its variance, outliers, %etd).

use onebeacon::nav::evaluation::{ErrorStats, chi_square_band, quantile};
use serde::Serialize;

/// Statistics of one estimator over one run.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct RunMetrics {
    /// Mean horizontal position error over the run, m (infinite if the filter diverged
    /// to non-finite numbers).
    pub mean_error_m: f64,
    /// Variance of the error over the run, m^2.
    pub error_variance_m2: f64,
    /// Mean squared error, m^2.
    pub mse_m2: f64,
    pub max_error_m: f64,
    pub final_error_m: f64,
    /// Error in percent of the distance travelled in the whole run ("%etd"): max, mean.
    pub etd_max_pct: f64,
    pub etd_mean_pct: f64,
    /// Mean NEES of the horizontal position (2 degrees of freedom).
    pub nees_mean: f64,
    /// Filter updates refused (innovation covariance not positive definite).
    pub failed_updates: u64,
    /// Mean error over the first and the second half of the steps, m: whether the error
    /// stays bounded.
    pub mean_error_first_half_m: f64,
    pub mean_error_second_half_m: f64,
}

impl RunMetrics {
    /// Words in [`RunMetrics::to_words`].
    pub const WORDS: usize = 11;

    /// The fields as 64-bit words, floats as their bit patterns: exact, and able to
    /// carry infinities (a shard's partial, [`crate::partial`]).
    pub fn to_words(&self) -> [u64; Self::WORDS] {
        // no `..`: a new field must be added here
        let RunMetrics {
            mean_error_m,
            error_variance_m2,
            mse_m2,
            max_error_m,
            final_error_m,
            etd_max_pct,
            etd_mean_pct,
            nees_mean,
            failed_updates,
            mean_error_first_half_m,
            mean_error_second_half_m,
        } = *self;
        let f = f64::to_bits;
        [
            f(mean_error_m),
            f(error_variance_m2),
            f(mse_m2),
            f(max_error_m),
            f(final_error_m),
            f(etd_max_pct),
            f(etd_mean_pct),
            f(nees_mean),
            failed_updates,
            f(mean_error_first_half_m),
            f(mean_error_second_half_m),
        ]
    }

    /// The inverse of [`RunMetrics::to_words`]; `w` has [`RunMetrics::WORDS`] words.
    pub fn from_words(w: &[u64]) -> RunMetrics {
        let f = |i: usize| f64::from_bits(w[i]);
        RunMetrics {
            mean_error_m: f(0),
            error_variance_m2: f(1),
            mse_m2: f(2),
            max_error_m: f(3),
            final_error_m: f(4),
            etd_max_pct: f(5),
            etd_mean_pct: f(6),
            nees_mean: f(7),
            failed_updates: w[8],
            mean_error_first_half_m: f(9),
            mean_error_second_half_m: f(10),
        }
    }
}

impl RunMetrics {
    /// The run's statistics from its errors, scored every step with half
    /// ([`ErrorStats::with_half`]) the steps; `distance_m` is the distance travelled in
    /// the run.
    pub fn of(st: &ErrorStats, distance_m: f64) -> RunMetrics {
        let n = st.count.max(1) as f64;
        let mean = st.sum_m / n;
        let mse = st.sum_sq_m2 / n;
        // %etd is undefined for a vehicle that does not move
        let pct = if distance_m > 1e-6 { 100.0 / distance_m } else { f64::NAN };
        let bad = st.diverged || st.count == 0;
        let first = st.half.min(st.count);
        let second = st.count - first;
        RunMetrics {
            mean_error_m: if bad { f64::INFINITY } else { mean },
            error_variance_m2: if bad { f64::INFINITY } else { (mse - mean * mean).max(0.0) },
            mse_m2: if bad { f64::INFINITY } else { mse },
            max_error_m: if bad { f64::INFINITY } else { st.max_m },
            final_error_m: if bad { f64::INFINITY } else { st.final_m },
            etd_max_pct: if bad { f64::INFINITY } else { st.max_m * pct },
            etd_mean_pct: if bad { f64::INFINITY } else { mean * pct },
            nees_mean: if st.nees_count == 0 { f64::NAN } else { st.nees_mean() },
            failed_updates: st.failed as u64,
            mean_error_first_half_m: if bad || first == 0 { f64::INFINITY } else { st.first_half_sum_m / first as f64 },
            mean_error_second_half_m: if bad || second == 0 {
                f64::INFINITY
            } else {
                (st.sum_m - st.first_half_sum_m) / second as f64
            },
        }
    }
}

/// Statistics of one estimator over the runs of one sweep cell, as in garin2024 Tables
/// 3 and 4. Outliers are runs whose mean error lies beyond q1 - 1.5 IQR or q3 + 1.5 IQR
/// of all runs' mean errors (section 4.1.1); they are counted and left out of the
/// error statistics, NEES included; `nees_mean_all_runs` keeps them, since a diverged
/// run is exactly what a consistency check must also see.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct CellSummary {
    pub runs: usize,
    pub outliers: usize,
    /// Mean over inlier runs of the run's mean error, m.
    pub mean_error_m: f64,
    /// Mean over inlier runs of the run's error variance, m^2.
    pub error_variance_m2: f64,
    /// Root of the mean squared error over inlier runs and steps, m.
    pub rmse_m: f64,
    pub etd_max_pct: f64,
    pub etd_mean_pct: f64,
    /// Mean position NEES over the inlier runs and their steps.
    pub nees_mean: f64,
    /// 95 % band of the run-averaged NEES of a consistent filter over the inlier runs:
    /// chi2(2N)/N quantiles.
    pub nees_band: [f64; 2],
    /// Mean position NEES over all runs, outliers included (infinite if a filter's
    /// covariance broke down).
    pub nees_mean_all_runs: f64,
    pub failed_updates: u64,
    /// Mean over inlier runs of the mean error in the first and second half, m.
    pub mean_error_first_half_m: f64,
    pub mean_error_second_half_m: f64,
    /// Every run's mean error in run order, outliers included, m: what paired
    /// comparisons between estimators or cells of the same runs are made of.
    pub run_mean_errors_m: Vec<f64>,
    /// Every run's mean position NEES in run order, outliers included (NaN without a
    /// covariance): the spread behind `nees_mean`, and what pairs two builds' NEES.
    pub run_nees: Vec<f64>,
}

/// Aggregates runs (in run order) into a cell summary.
pub fn summarise(runs: &[RunMetrics]) -> CellSummary {
    assert!(!runs.is_empty(), "a cell has at least one run");
    let mut means: Vec<f64> = runs.iter().map(|r| r.mean_error_m).collect();
    means.sort_by(f64::total_cmp);
    let (q1, q3) = (quantile(&means, 0.25), quantile(&means, 0.75));
    let iqr = q3 - q1;
    let (lo, hi) = (q1 - 1.5 * iqr, q3 + 1.5 * iqr);
    let inliers: Vec<&RunMetrics> =
        runs.iter().filter(|r| r.mean_error_m.is_finite() && r.mean_error_m >= lo && r.mean_error_m <= hi).collect();
    let avg = |f: &dyn Fn(&RunMetrics) -> f64| {
        if inliers.is_empty() { f64::NAN } else { inliers.iter().map(|r| f(r)).sum::<f64>() / inliers.len() as f64 }
    };
    let nees_all = if runs.iter().all(|r| r.nees_mean.is_finite()) {
        runs.iter().map(|r| r.nees_mean).sum::<f64>() / runs.len() as f64
    } else {
        f64::INFINITY
    };
    CellSummary {
        runs: runs.len(),
        outliers: runs.len() - inliers.len(),
        mean_error_m: avg(&|r| r.mean_error_m),
        error_variance_m2: avg(&|r| r.error_variance_m2),
        rmse_m: avg(&|r| r.mse_m2).sqrt(),
        etd_max_pct: avg(&|r| r.etd_max_pct),
        etd_mean_pct: avg(&|r| r.etd_mean_pct),
        nees_mean: avg(&|r| r.nees_mean),
        nees_band: chi_square_band(inliers.len(), 2),
        nees_mean_all_runs: nees_all,
        failed_updates: runs.iter().map(|r| r.failed_updates).sum(),
        mean_error_first_half_m: avg(&|r| r.mean_error_first_half_m),
        mean_error_second_half_m: avg(&|r| r.mean_error_second_half_m),
        run_mean_errors_m: runs.iter().map(|r| r.mean_error_m).collect(),
        run_nees: runs.iter().map(|r| r.nees_mean).collect(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    fn run(mean: f64) -> RunMetrics {
        let mut a = ErrorStats::with_half(1);
        a.push(mean - 1.0, Some(1.0));
        a.push(mean + 1.0, Some(3.0));
        RunMetrics::of(&a, 1000.0)
    }

    #[test]
    fn accumulator_statistics() {
        let m = run(5.0);
        assert_relative_eq!(m.mean_error_m, 5.0);
        assert_relative_eq!(m.error_variance_m2, 1.0, max_relative = 1e-12);
        assert_relative_eq!(m.mse_m2, 26.0);
        assert_relative_eq!(m.etd_max_pct, 0.6);
        assert_relative_eq!(m.etd_mean_pct, 0.5);
        assert_relative_eq!(m.nees_mean, 2.0);
        assert_eq!(m.final_error_m, 6.0);
        assert_relative_eq!(m.mean_error_first_half_m, 4.0);
        assert_relative_eq!(m.mean_error_second_half_m, 6.0);
        let mut still = ErrorStats::with_half(1);
        still.push(1.0, None);
        assert!(RunMetrics::of(&still, 0.0).etd_mean_pct.is_nan());
    }

    #[test]
    fn tukey_outliers_are_counted_and_excluded() {
        // 1..=9 and one far run: q1 = 3.25, q3 = 7.75 over the ten, fence 14.5
        let mut runs: Vec<RunMetrics> = (1..=9).map(|i| run(i as f64 + 1.0)).collect();
        runs.push(run(40.0));
        let s = summarise(&runs);
        assert_eq!(s.outliers, 1);
        assert_relative_eq!(s.mean_error_m, 6.0); // mean of 2..=10
        assert_relative_eq!(s.nees_mean, 2.0);
        assert_eq!(s.nees_band, chi_square_band(9, 2));
        assert_eq!(s.run_nees, vec![2.0; 10]); // every run's, the outlier's too
        // a diverged run is an outlier; NEES over all runs sees it
        let mut acc = ErrorStats::with_half(1);
        acc.push(f64::NAN, None);
        runs.push(RunMetrics::of(&acc, 1000.0));
        let s = summarise(&runs);
        assert_eq!(s.outliers, 2);
        assert!(s.nees_mean.is_finite() && s.nees_mean_all_runs.is_infinite());
    }
}
