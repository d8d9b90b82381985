//! Scoring an estimator against a truth: the horizontal error and its NEES at one time,
//! their statistics over a run or a log (with the NIS of the corrections weighed), the
//! 95 % chi-square bands and quantiles. One module for the simulator's runs, the replay
//! of a log, the stream and the fleet's percentiles.

use super::{Estimate, Outcome, Robust};
use crate::filter::consistency::nees;
use nalgebra::Vector2;
use statrs::distribution::{ChiSquared, ContinuousCDF};

/// The 95 % quantile of chi-square with 2 degrees of freedom, -2 ln 0.05.
pub const NEES_95_2DOF: f64 = 5.991464547107982;

/// The 95 % quantile of chi-square with 1 degree of freedom, 1.96^2.
pub const NIS_95_1DOF: f64 = 3.841458820694124;

/// The horizontal error of estimate `e` against a reference (north, east), m, and its
/// NEES (None when the covariance is not positive definite), the reference's own error
/// (`reference_sigma_m` on each axis, 0 for the truth) added to the estimate's
/// covariance: the difference of two independent errors has the sum of their
/// covariances.
pub fn horizontal_error(e: &Estimate, north_m: f64, east_m: f64, reference_sigma_m: f64) -> (f64, Option<f64>) {
    let d = Vector2::new(e.position_ned_m.x - north_m, e.position_ned_m.y - east_m);
    let cov = e.horizontal_cov_m2 + nalgebra::Matrix2::identity() * reference_sigma_m.powi(2);
    (d.norm(), nees(&d, &cov))
}

/// Error statistics of one estimator against the truth, time after time.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct ErrorStats {
    /// Errors counted (finite ones), their sum, sum of squares, largest and last.
    pub count: usize,
    pub sum_m: f64,
    pub sum_sq_m2: f64,
    pub max_m: f64,
    pub final_m: f64,
    /// An error was not finite: the filter diverged to non-finite numbers.
    pub diverged: bool,
    /// The first `half` errors also summed apart (whether the error stays bounded).
    pub half: usize,
    pub first_half_sum_m: f64,
    /// Corrections rejected by the gate, and updates that could not be computed.
    pub rejected: usize,
    pub failed: usize,
    /// Times the estimator's state or covariance stopped being finite and positive
    /// definite and it was started again from its last sound estimate.
    pub reinitialised: usize,
    /// Position NEES (2 dof): sum and count of the finite ones, and how many were within
    /// the 95 % chi-square quantile.
    pub nees_sum: f64,
    pub nees_count: usize,
    pub nees_within_95: usize,
    /// NIS (1 dof) of every scalar correction the estimator weighed, accepted or gated
    /// out: sum, count, and how many were within the 95 % chi-square quantile.
    pub nis_sum: f64,
    pub nis_count: usize,
    pub nis_within_95: usize,
    /// Sum of ln det S of the same corrections: with the NIS, their Gaussian likelihood.
    pub ln_det_s_sum: f64,
    /// How the estimator weighs a correction ([`ErrorStats::weighed_as`]): its gate and
    /// heavy-tailed kernel, and the sum of each correction's cost under them.
    pub gate: Option<f64>,
    pub kernel: Option<Robust>,
    pub cost_sum: f64,
}

impl ErrorStats {
    /// Statistics that score each correction as an estimator with this gate (NIS beyond
    /// it: an outlier, its cost the gate's) and kernel weighs it.
    pub fn weighed_as(self, gate: Option<f64>, kernel: Option<Robust>) -> Self {
        Self { gate: gate.filter(|g| g.is_finite()), kernel, ..self }
    }

    /// Statistics whose first `half` errors are also summed apart (a run of 2 half steps).
    pub fn with_half(half: usize) -> Self {
        Self { half, ..Self::default() }
    }

    /// Adds one error and its position NEES (None or not finite: not counted). A
    /// non-finite error marks the statistics diverged and is not counted.
    pub fn push(&mut self, error_m: f64, nees: Option<f64>) {
        if !error_m.is_finite() {
            self.diverged = true;
            return;
        }
        if self.count < self.half {
            self.first_half_sum_m += error_m;
        }
        self.count += 1;
        self.sum_m += error_m;
        self.sum_sq_m2 += error_m * error_m;
        self.max_m = self.max_m.max(error_m);
        self.final_m = error_m;
        if let Some(v) = nees.filter(|v| v.is_finite()) {
            self.nees_sum += v;
            self.nees_count += 1;
            self.nees_within_95 += usize::from(v <= NEES_95_2DOF);
        }
    }

    /// Counts what processing one measurement did: a failed update, a correction's NIS
    /// (and a gate's rejection when `rejections`).
    pub fn push_outcome(&mut self, outcome: &Outcome, rejections: bool) {
        match *outcome {
            Outcome::Failed(_) => self.failed += 1,
            Outcome::Accepted(i) => self.push_nis(i.nis, i.det_s, false),
            Outcome::Rejected(i) => {
                self.push_nis(i.nis, i.det_s, true);
                self.rejected += usize::from(rejections);
            }
            Outcome::Applied | Outcome::Skipped => {}
        }
    }

    /// A correction's NIS, costing the gate's value when `rejected` (a correction a lost
    /// navigator's open gate let through costs its own).
    fn push_nis(&mut self, nis: f64, det_s: f64, rejected: bool) {
        if nis.is_finite() && det_s > 0.0 && det_s.is_finite() {
            self.nis_sum += nis;
            self.nis_count += 1;
            self.nis_within_95 += usize::from(nis <= NIS_95_1DOF);
            self.ln_det_s_sum += det_s.ln();
            let d2 = match (rejected, self.gate) {
                (true, Some(g)) => nis.min(g),
                _ => nis,
            };
            self.cost_sum += self.kernel.map_or(0.5 * d2, |k| -k.log_density(d2));
        }
    }

    pub fn rmse_m(&self) -> f64 {
        (self.sum_sq_m2 / self.count as f64).sqrt()
    }
    pub fn mean_m(&self) -> f64 {
        self.sum_m / self.count as f64
    }
    /// Mean position NEES: 2 for a consistent filter, more for an overconfident one.
    pub fn nees_mean(&self) -> f64 {
        self.nees_sum / self.nees_count as f64
    }
    /// Fraction of the NEES values within the 95 % quantile (0.95 when consistent).
    pub fn nees_within_95_fraction(&self) -> f64 {
        self.nees_within_95 as f64 / self.nees_count as f64
    }
    /// Mean NIS: 1 for a consistent filter (its innovations as large as it expects).
    pub fn nis_mean(&self) -> f64 {
        self.nis_sum / self.nis_count as f64
    }
    /// Fraction of the NIS values within the 95 % quantile (0.95 when consistent).
    pub fn nis_within_95_fraction(&self) -> f64 {
        self.nis_within_95 as f64 / self.nis_count as f64
    }

    /// The negative log-likelihood of the corrections weighed, as the estimator weighs
    /// them (what `tune` minimises): sum of ln det(2 pi S) / 2 + rho(NIS), rho its
    /// kernel's cost (Huber's, Student's t, Cauchy's; NIS / 2 without one, the
    /// innovations' Gaussian density), a gated-out correction costing the gate's value
    /// (an outlier's flat tail).
    pub fn neg_log_likelihood(&self) -> f64 {
        0.5 * (self.ln_det_s_sum + self.nis_count as f64 * std::f64::consts::TAU.ln()) + self.cost_sum
    }
}

/// The q-quantile of values sorted ascending, by linear interpolation between order
/// statistics (type 7); NaN for none; where the upper neighbour is not finite (a
/// diverged run), the lower order statistic.
pub fn quantile(sorted: &[f64], q: f64) -> f64 {
    if sorted.is_empty() {
        return f64::NAN;
    }
    let h = (sorted.len() - 1) as f64 * q;
    let (lo, hi) = (h.floor() as usize, h.ceil() as usize);
    if lo == hi || !sorted[hi].is_finite() {
        sorted[lo]
    } else {
        sorted[lo] + (h - lo as f64) * (sorted[hi] - sorted[lo])
    }
}

/// 95 % band for the average of `n` independent chi-square(`dof`) variables (NaN for
/// none): the range a consistent filter's mean NEES (or NIS) falls in.
pub fn chi_square_band(n: usize, dof: usize) -> [f64; 2] {
    match ChiSquared::new((n * dof) as f64) {
        Ok(chi) => [chi.inverse_cdf(0.025) / n as f64, chi.inverse_cdf(0.975) / n as f64],
        Err(_) => [f64::NAN, f64::NAN],
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::nav::Innovation;
    use approx::assert_relative_eq;

    /// Two errors, 4 and 6 m with NEES 1 and 3: mean 5, rmse sqrt(26), halves 4 and 6;
    /// a NaN marks the statistics diverged and is not counted.
    #[test]
    fn statistics_of_errors() {
        let mut s = ErrorStats::with_half(1);
        s.push(4.0, Some(1.0));
        s.push(6.0, Some(3.0));
        assert_relative_eq!(s.mean_m(), 5.0);
        assert_relative_eq!(s.rmse_m(), 26f64.sqrt());
        assert_relative_eq!(s.nees_mean(), 2.0);
        assert_eq!((s.first_half_sum_m, s.max_m, s.final_m, s.nees_within_95), (4.0, 6.0, 6.0, 2));
        s.push(f64::NAN, None);
        assert!(s.diverged && s.count == 2);
    }

    /// A correction's cost as the estimator weighs it, by hand: NIS 1 and 25 with det S
    /// 1; Gaussian 13, gated at 10.83 (1 + 10.83) / 2, Huber k = 1 (1 / 2 and 5 - 1 / 2),
    /// Cauchy k = 1 (ln 2 / 2 and ln 26 / 2); ungated and Gaussian, (ln 2 pi + NIS) / 2.
    #[test]
    fn own_likelihood_of_gated_and_robust_corrections() {
        let accepted = |nis: f64| Outcome::Accepted(Innovation { nis, det_s: 1.0, residual: nis.sqrt(), sigma: 1.0 });
        let cost = |gate, kernel| {
            let mut s = ErrorStats::default().weighed_as(gate, kernel);
            s.push_outcome(&accepted(1.0), true);
            s.push_outcome(&Outcome::Rejected(Innovation { nis: 25.0, ..accepted(1.0).innovation().unwrap() }), true);
            s.neg_log_likelihood() - std::f64::consts::TAU.ln()
        };
        assert_relative_eq!(cost(None, None), 13.0);
        assert_relative_eq!(cost(Some(f64::INFINITY), None), 13.0);
        assert_relative_eq!(cost(Some(10.83), None), 0.5 * (1.0 + 10.83));
        assert_relative_eq!(cost(None, Some(Robust::Huber { k: 1.0 })), 0.5 + 4.5);
        assert_relative_eq!(cost(None, Some(Robust::Cauchy { k: 1.0 })), 0.5 * (2f64.ln() + 26f64.ln()));
        let mut g = ErrorStats::default();
        g.push_outcome(&accepted(1.0), true);
        assert_relative_eq!(g.neg_log_likelihood(), 0.5 * (std::f64::consts::TAU.ln() + 1.0));
    }

    #[test]
    fn nees_quantile_and_statistics() {
        // chi-square(2) is exponential with mean 2: its 95 % quantile is -2 ln 0.05;
        // chi-square(1)'s is 1.96^2 (to the printed digits of the normal table)
        assert_relative_eq!(NEES_95_2DOF, -2.0 * 0.05f64.ln(), max_relative = 1e-12);
        assert_relative_eq!(NIS_95_1DOF, 1.959964f64.powi(2), max_relative = 1e-6);
        let mut s = ErrorStats::default();
        for (err, nees) in [(1.0, Some(1.0)), (3.0, Some(9.0)), (2.0, Some(f64::NAN)), (2.0, Some(2.0))] {
            s.push(err, nees);
        }
        assert_eq!((s.count, s.nees_count, s.nees_within_95), (4, 3, 2));
        assert_relative_eq!(s.nees_mean(), 4.0);
        assert_relative_eq!(s.nees_within_95_fraction(), 2.0 / 3.0);
        assert_relative_eq!(s.rmse_m(), (18.0f64 / 4.0).sqrt());
        assert_eq!((s.max_m, s.final_m), (3.0, 2.0));
    }

    /// Type 7 quantiles of 1..=4 (R's quantile(1:4, c(0.25, 0.68, 0.95))): 1.75, 3.04,
    /// 3.85; none: NaN; a non-finite upper neighbour gives the lower order statistic.
    #[test]
    fn quantiles_interpolate_order_statistics() {
        let v = [1.0, 2.0, 3.0, 4.0];
        assert_relative_eq!(quantile(&v, 0.25), 1.75);
        assert_relative_eq!(quantile(&v, 0.68), 3.04, max_relative = 1e-12);
        assert_relative_eq!(quantile(&v, 0.95), 3.85, max_relative = 1e-12);
        assert!(quantile(&[], 0.5).is_nan());
        assert_eq!(quantile(&[1.0, f64::INFINITY], 0.5), 1.0);
    }

    #[test]
    fn chi_square_band_matches_published_quantiles() {
        // N x ANEES ~ chi2(N n) (Bar-Shalom et al. 2001, 5.4): N = 50, n = 2: [1.48, 2.59];
        // N = 100, n = 2: [1.63, 2.41]
        let b = chi_square_band(50, 2);
        assert!((b[0] - 1.48).abs() < 0.01 && (b[1] - 2.59).abs() < 0.01, "{b:?}");
        let b = chi_square_band(100, 2);
        assert!((b[0] - 1.63).abs() < 0.01 && (b[1] - 2.41).abs() < 0.01, "{b:?}");
        assert!(chi_square_band(0, 2)[0].is_nan());
    }
}
