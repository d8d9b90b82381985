//! What several test files share: a t interval from the runs of a campaign.

use statrs::distribution::{ContinuousCDF, StudentsT};

/// The two-sided 99 % Student t interval of the mean of independent values `v` (at
/// least two): the tolerance of a figure measured over `v.len()` runs.
pub fn t_interval_99(v: &[f64]) -> (f64, f64) {
    let n = v.len() as f64;
    let mean = v.iter().sum::<f64>() / n;
    let sd = (v.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / (n - 1.0)).sqrt();
    let half = StudentsT::new(0.0, 1.0, n - 1.0).unwrap().inverse_cdf(0.995) * sd / n.sqrt();
    (mean - half, mean + half)
}
