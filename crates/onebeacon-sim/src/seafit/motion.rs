//! The vehicle's own sensors against the truth.
//!
//! - Heading: e = measured - true heading is a mean, a first-order Gauss-Markov bias
//!   (stationary sigma, correlation time: `sensor_errors`) and white noise; its
//!   likelihood by a scalar Kalman filter over the samples' own times, maximised.
//! - Speed through the water: over windows, the true displacement is (1 + k) times the
//!   measured velocity's integral (speed along the measured heading) plus the current
//!   times the window, a linear model fitted by least squares (two rows a window).
//! - Odometry: the true path length of a window against the odometry's distance, and
//!   the true turn against its heading change: two scales through the origin.

use super::mle::{minimise, profile_interval};
use super::ranges::Value;

/// The heading bias fitted.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HeadingFit {
    pub samples: usize,
    /// The errors' mean, deg.
    pub mean_deg: f64,
    pub bias_sigma_deg: Value,
    pub time_constant_s: Value,
    pub white_deg: Value,
    /// The errors' standard deviation about their mean, deg.
    pub sd_deg: f64,
}

/// Speed scale and current.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SpeedFit {
    pub windows: usize,
    pub scale: Value,
    pub current_north_m_s: Value,
    pub current_east_m_s: Value,
}

/// Odometry scales, true = (1 + k) x measured, and the white noise about them: the
/// distance's variance growing with the path (m per sqrt m), the turn's with the time
/// (rad per sqrt s, a heading random walk).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct OdometryFit {
    pub windows: usize,
    pub distance_scale: Value,
    pub turn_scale: Option<Value>,
    pub distance_sigma: Value,
    pub turn_sigma: Option<Value>,
}

/// The heading errors `(t, e)` (rad, in time order), at most 20 000 of them (evenly
/// thinned beyond). The bias is the simulator's: zero-mean, so a constant offset reads
/// as a bias of long correlation time; the errors' mean is given beside.
pub(crate) fn fit_heading(errors: &[(f64, f64)]) -> Result<HeadingFit, argmin::core::Error> {
    let step = errors.len().div_ceil(20_000).max(1);
    let e: Vec<(f64, f64)> = errors.iter().step_by(step).copied().collect();
    let span = e.last().map_or(0.0, |l| l.0) - e[0].0;
    let nll = |x: &[f64]| {
        let (sg, tau, sw) = (x[0].exp(), x[1].exp(), x[2].exp());
        let (mut g, mut p) = (0.0, sg * sg);
        let mut last = e[0].0;
        let mut total = 0.0;
        for &(t, y) in &e {
            let a = (-(t - last) / tau).exp();
            last = t;
            g *= a; // the Gauss-Markov bias's exact discretisation (`sensor_errors`)
            p = a * a * p + (1.0 - a * a) * sg * sg;
            let s = p + sw * sw;
            let v = y - g;
            total += 0.5 * (v * v / s + s.ln());
            let k = p / s;
            g += k * v;
            p *= 1.0 - k;
        }
        total
    };
    let n = e.len() as f64;
    let mean = e.iter().map(|x| x.1).sum::<f64>() / n;
    let rms = (e.iter().map(|x| x.1 * x.1).sum::<f64>() / n).sqrt().max(1e-4);
    let x0 = [(rms * 0.7).ln(), (span / 10.0).max(1.0).ln(), (rms * 0.7).ln()];
    let fit = minimise(&nll, &x0, 0.5)?;
    // the bias's sigma and time by their profiles: a short record's likelihood of them
    // is skewed (the curvature's intervals covered 88 % of 200 seeds, the profiles' 93-94
    // %: tests.rs); the white noise's by the curvature (96 %)
    let log_value = |i: usize, to: fn(f64) -> f64| {
        let interval = if i < 2 {
            profile_interval(&nll, &fit, i)
        } else {
            fit.sd(i).map(|s| [fit.x[i] - 1.96 * s, fit.x[i] + 1.96 * s])
        };
        Value { value: to(fit.x[i].exp()), interval: interval.map(|[lo, hi]| [to(lo.exp()), to(hi.exp())]) }
    };
    let sd_mean = (e.iter().map(|x| (x.1 - mean).powi(2)).sum::<f64>() / n).sqrt();
    Ok(HeadingFit {
        samples: e.len(),
        mean_deg: mean.to_degrees(),
        bias_sigma_deg: log_value(0, f64::to_degrees),
        time_constant_s: log_value(1, |x| x),
        white_deg: log_value(2, f64::to_degrees),
        sd_deg: sd_mean.to_degrees(),
    })
}

/// Least squares y = A beta over rows in clusters of `cluster` consecutive rows (one
/// window's): beta, and its cluster-robust covariance, the sandwich (A'A)^-1 (sum over
/// clusters of A_g' r_g r_g' A_g) (A'A)^-1 times the small-sample factor
/// G / (G - 1) x (N - 1) / (N - K) (Cameron and Miller 2015, "A Practitioner's Guide to
/// Cluster-Robust Inference"). A window's two rows share one along-track error, which
/// the plain residual variance would understate: the speed scale's intervals covered
/// 90 % of 200 seeds with it, 94 % with this (tests.rs).
fn least_squares(rows: &[(Vec<f64>, f64)], cluster: usize) -> Option<(Vec<f64>, nalgebra::DMatrix<f64>)> {
    let (n, k) = (rows.len(), rows.first()?.0.len());
    let g = n / cluster;
    if g <= k || n % cluster != 0 {
        return None;
    }
    let a = nalgebra::DMatrix::from_fn(n, k, |i, j| rows[i].0[j]);
    let y = nalgebra::DVector::from_fn(n, |i, _| rows[i].1);
    let ata_inv = (a.transpose() * &a).try_inverse()?;
    let beta = &ata_inv * a.transpose() * &y;
    let r = &y - &a * &beta;
    let mut meat = nalgebra::DMatrix::<f64>::zeros(k, k);
    for c in 0..g {
        let rows = c * cluster..(c + 1) * cluster;
        let score = a.rows(rows.start, cluster).transpose() * r.rows(rows.start, cluster);
        meat += &score * score.transpose();
    }
    let factor = g as f64 / (g - 1) as f64 * (n - 1) as f64 / (n - k) as f64;
    Some((beta.iter().copied().collect(), &ata_inv * meat * &ata_inv * factor))
}

fn value(beta: &[f64], cov: &nalgebra::DMatrix<f64>, i: usize, offset: f64) -> Value {
    let sd = cov[(i, i)].sqrt();
    Value {
        value: beta[i] + offset,
        interval: sd.is_finite().then(|| [beta[i] + offset - 1.96 * sd, beta[i] + offset + 1.96 * sd]),
    }
}

/// One window: the measured velocity's integral (north, east), m, the true
/// displacement, m, and the window's length, s.
#[derive(Debug, Clone, Copy)]
pub(crate) struct VelocityWindow {
    pub measured: [f64; 2],
    pub truth: [f64; 2],
    pub span_s: f64,
}

/// Speed scale and current from at least 4 windows.
pub(crate) fn fit_speed(windows: &[VelocityWindow]) -> Option<SpeedFit> {
    let rows: Vec<(Vec<f64>, f64)> = windows
        .iter()
        .flat_map(|w| {
            [(vec![w.measured[0], w.span_s, 0.0], w.truth[0]), (vec![w.measured[1], 0.0, w.span_s], w.truth[1])]
        })
        .collect();
    if windows.len() < 4 {
        return None;
    }
    let (beta, cov) = least_squares(&rows, 2)?;
    Some(SpeedFit {
        windows: windows.len(),
        scale: value(&beta, &cov, 0, -1.0),
        current_north_m_s: value(&beta, &cov, 1, 0.0),
        current_east_m_s: value(&beta, &cov, 2, 0.0),
    })
}

/// One odometry window: measured distance and turn, true path length and turn.
#[derive(Debug, Clone, Copy)]
pub(crate) struct OdometryWindow {
    pub distance_m: f64,
    pub turn_rad: f64,
    pub true_distance_m: f64,
    pub true_turn_rad: Option<f64>,
    pub span_s: f64,
}

/// The white noise of residuals `(e, x)` whose variance is q x (x > 0): its sigma,
/// sqrt(q), q = mean(e^2 / x) by maximum likelihood, with the chi-square interval of n
/// windows.
fn noise_per_sqrt(residuals: &[(f64, f64)]) -> Option<Value> {
    use statrs::distribution::{ChiSquared, ContinuousCDF};
    let r: Vec<f64> = residuals.iter().filter(|(_, x)| *x > 0.0).map(|(e, x)| e * e / x).collect();
    let n = r.len() as f64;
    let chi = ChiSquared::new(n).ok()?;
    let sum: f64 = r.iter().sum();
    Some(Value {
        value: (sum / n).sqrt(),
        interval: Some([(sum / chi.inverse_cdf(0.975)).sqrt(), (sum / chi.inverse_cdf(0.025)).sqrt()]),
    })
}

pub(crate) fn fit_odometry(windows: &[OdometryWindow]) -> Option<OdometryFit> {
    if windows.len() < 4 {
        return None;
    }
    let d: Vec<(Vec<f64>, f64)> = windows.iter().map(|w| (vec![w.distance_m], w.true_distance_m)).collect();
    let (beta, cov) = least_squares(&d, 1)?;
    // the turn from windows that turned (above 5 deg), where the truth has a heading
    let turns: Vec<(Vec<f64>, f64)> = windows
        .iter()
        .filter(|w| w.turn_rad.abs() > 5f64.to_radians())
        .filter_map(|w| w.true_turn_rad.map(|t| (vec![w.turn_rad], t)))
        .collect();
    let turn_fit = (turns.len() >= 4).then(|| least_squares(&turns, 1)).flatten();
    let turn_scale = turn_fit.as_ref().map(|(b, c)| value(b, c, 0, -1.0));
    // the noise about the scales: every window's residual (the turn's where the truth
    // has a heading), read as the measured row's error
    let distance_sigma = noise_per_sqrt(
        &windows.iter().map(|w| (w.true_distance_m / beta[0] - w.distance_m, w.true_distance_m)).collect::<Vec<_>>(),
    )?;
    let k_turn = turn_fit.map_or(1.0, |(b, _)| b[0]);
    let turn_sigma = noise_per_sqrt(
        &windows
            .iter()
            .filter_map(|w| w.true_turn_rad.map(|t| (t / k_turn - w.turn_rad, w.span_s)))
            .collect::<Vec<_>>(),
    );
    Some(OdometryFit {
        windows: windows.len(),
        distance_scale: value(&beta, &cov, 0, -1.0),
        turn_scale,
        distance_sigma,
        turn_sigma,
    })
}
