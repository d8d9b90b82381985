//! One beacon's ranges against the true distance: r = (1 + k) d + b + c t + e, where e
//! is the receiver's Gaussian noise (sigma) on the direct path; with probability p_m a
//! multipath arrival, the noise plus an exponential excess of mean mu (an exponentially
//! modified Gaussian); with probability p_f a false detection, r uniform on [0, R] (R:
//! the largest range heard from the beacon). k is a sound-speed scale, b an offset (the
//! clocks' offsets, a turnaround), c a drift (the clocks' rates apart, times the sound
//! speed). The sea layer's model (`acoustics::link`, `acoustics::clock`), fitted by
//! maximum likelihood. A kind of outlier the ranges do not show (p N below 3: fewer than
//! three expected) is left out and the fit made again, so that its vanishing
//! probability does not leave every interval undefined.

use super::mle::{Fit, minimise};
use statrs::function::erf::erfc;

/// One range: time since the log's first range, s, the range heard and the true
/// distance, m.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Pair {
    pub t_s: f64,
    pub range_m: f64,
    pub distance_m: f64,
}

/// A fitted value and its 95 % interval (None: the curvature did not give one).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Value {
    pub value: f64,
    pub interval: Option<[f64; 2]>,
}

/// One beacon's fitted range errors.
#[derive(Debug, Clone, PartialEq)]
pub struct RangeFit {
    pub beacon: u32,
    pub ranges: usize,
    pub bias_m: Value,
    /// k: ranges read (1 + k) times the distance.
    pub scale: Value,
    pub drift_m_per_s: Value,
    pub sigma_m: Value,
    pub multipath_prob: Value,
    pub multipath_excess_m: Value,
    pub false_prob: Value,
    pub false_max_range_m: f64,
}

/// Which kinds of outlier the model holds.
#[derive(Debug, Clone, Copy)]
struct Kinds {
    multipath: bool,
    false_: bool,
}

/// Parameters, scaled so that 1 is a large move: b (m), 100 k, c (m per hour), ln sigma,
/// then a_m and ln mu with multipath, a_f with false detections (the weights are the
/// softmax of (0, a_m, a_f)).
struct Layout {
    kinds: Kinds,
}

const HOUR: f64 = 3600.0;

impl Layout {
    fn false_index(&self) -> usize {
        4 + 2 * self.kinds.multipath as usize
    }
    /// (p_direct, p_m, p_f)
    fn weights(&self, x: &[f64]) -> (f64, f64, f64) {
        let am = if self.kinds.multipath { x[4] } else { f64::NEG_INFINITY };
        let af = if self.kinds.false_ { x[self.false_index()] } else { f64::NEG_INFINITY };
        let top = 0f64.max(am).max(af);
        let (e0, em, ef) = ((-top).exp(), (am - top).exp(), (af - top).exp());
        let s = e0 + em + ef;
        (e0 / s, em / s, ef / s)
    }
    fn mu(&self, x: &[f64]) -> f64 {
        if self.kinds.multipath { x[5].exp() } else { 0.0 }
    }
}

/// ln N(e; 0, s)
fn ln_normal(e: f64, s: f64) -> f64 {
    -0.5 * (e / s).powi(2) - s.ln() - 0.918_938_533_204_672_7
}

/// ln of the density of N(0, s) + Exp(mean mu) at e: ln(1/mu) + s^2 / (2 mu^2) - e / mu
/// + ln Phi(e / s - s / mu), Phi through erfc for its far left tail.
fn ln_emg(e: f64, s: f64, mu: f64) -> f64 {
    let z = e / s - s / mu;
    let phi = 0.5 * erfc(-z / std::f64::consts::SQRT_2);
    -mu.ln() + s * s / (2.0 * mu * mu) - e / mu + phi.ln()
}

fn ln_sum_exp(a: f64, b: f64) -> f64 {
    let m = a.max(b);
    if m == f64::NEG_INFINITY { m } else { m + ((a - m).exp() + (b - m).exp()).ln() }
}

fn nll(layout: &Layout, pairs: &[Pair], r_max: f64, x: &[f64]) -> f64 {
    let (b, k, c, s) = (x[0], x[1] / 100.0, x[2] / HOUR, x[3].exp());
    let (p0, pm, pf) = layout.weights(x);
    let mu = layout.mu(x);
    let (l0, lm, lf) = (p0.ln(), pm.ln(), (pf / r_max).ln());
    let mut total = 0.0;
    for p in pairs {
        let e = p.range_m - ((1.0 + k) * p.distance_m + b + c * p.t_s);
        let mut l = l0 + ln_normal(e, s);
        if layout.kinds.multipath {
            l = ln_sum_exp(l, lm + ln_emg(e, s, mu));
        }
        if layout.kinds.false_ && p.range_m >= 0.0 && p.range_m <= r_max {
            l = ln_sum_exp(l, lf);
        }
        total -= l;
    }
    total
}

/// A robust start: b, k and c by least squares on the ranges within 3 scaled MADs of
/// the median residual, sigma their MAD.
fn start(pairs: &[Pair]) -> [f64; 4] {
    let median = |mut v: Vec<f64>| {
        v.sort_by(f64::total_cmp);
        v[v.len() / 2]
    };
    let raw: Vec<f64> = pairs.iter().map(|p| p.range_m - p.distance_m).collect();
    let m = median(raw.clone());
    let mad = 1.4826 * median(raw.iter().map(|r| (r - m).abs()).collect()).max(1e-3);
    let kept: Vec<&Pair> =
        pairs.iter().zip(&raw).filter(|(_, r)| (**r - m).abs() < 3.0 * mad).map(|(p, _)| p).collect();
    let a = nalgebra::DMatrix::from_fn(kept.len(), 3, |i, j| [1.0, kept[i].distance_m, kept[i].t_s][j]);
    let y = nalgebra::DVector::from_fn(kept.len(), |i, _| kept[i].range_m - kept[i].distance_m);
    let beta =
        a.clone().svd(true, true).solve(&y, 1e-12).unwrap_or_else(|_| nalgebra::DVector::from_vec(vec![m, 0.0, 0.0]));
    [beta[0], beta[1] * 100.0, beta[2] * HOUR, mad.ln()]
}

/// Fits beacon `beacon`'s ranges (at least 20).
pub(crate) fn fit_beacon(beacon: u32, pairs: &[Pair]) -> Result<RangeFit, argmin::core::Error> {
    let r_max = pairs.iter().map(|p| p.range_m).fold(0.0, f64::max).max(1e-3);
    let n = pairs.len() as f64;
    let mut kinds = Kinds { multipath: true, false_: true };
    loop {
        let layout = Layout { kinds };
        let s0 = start(pairs);
        let mut x0 = s0.to_vec();
        if kinds.multipath {
            x0.extend([(0.05f64 / 0.9).ln(), (3.0 * s0[3].exp()).ln()]);
        }
        if kinds.false_ {
            x0.push((0.02f64 / 0.9).ln());
        }
        let cost = |x: &[f64]| nll(&layout, pairs, r_max, x);
        let fit = minimise(&cost, &x0, 0.5)?;
        let (_, pm, pf) = layout.weights(&fit.x);
        // fewer than three expected: the kind is not in these ranges
        let drop_m = kinds.multipath && pm * n < 3.0;
        let drop_f = kinds.false_ && pf * n < 3.0;
        if drop_m || drop_f {
            kinds = Kinds { multipath: kinds.multipath && !drop_m, false_: kinds.false_ && !drop_f };
            continue;
        }
        return Ok(summarise(beacon, pairs.len(), &layout, &fit, r_max));
    }
}

fn summarise(beacon: u32, ranges: usize, layout: &Layout, fit: &Fit, r_max: f64) -> RangeFit {
    let direct = |i: usize, scale: f64| Value {
        value: fit.x[i] * scale,
        interval: fit.sd(i).map(|s| [(fit.x[i] - 1.96 * s) * scale, (fit.x[i] + 1.96 * s) * scale]),
    };
    // a probability's interval (the delta method's) kept within [0, 1]
    let of = |g: &dyn Fn(&[f64]) -> f64| Value {
        value: g(&fit.x),
        interval: fit.interval_of(g).map(|[lo, hi]| [lo.max(0.0), hi.min(1.0)]),
    };
    let log_value = |i: usize| Value {
        value: fit.x[i].exp(),
        interval: fit.sd(i).map(|s| [(fit.x[i] - 1.96 * s).exp(), (fit.x[i] + 1.96 * s).exp()]),
    };
    let none = Value { value: 0.0, interval: None };
    RangeFit {
        beacon,
        ranges,
        bias_m: direct(0, 1.0),
        scale: direct(1, 0.01),
        drift_m_per_s: direct(2, 1.0 / HOUR),
        sigma_m: log_value(3),
        multipath_prob: if layout.kinds.multipath { of(&|x| layout.weights(x).1) } else { none },
        multipath_excess_m: if layout.kinds.multipath { log_value(5) } else { none },
        false_prob: if layout.kinds.false_ { of(&|x| layout.weights(x).2) } else { none },
        false_max_range_m: r_max,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The exponentially modified Gaussian integrates to 1 and has mean mu (a brute-force
    /// sum on a fine grid).
    #[test]
    fn the_multipath_density_is_a_density_with_its_mean() {
        let (s, mu) = (0.4, 3.0);
        let (mut mass, mut mean) = (0.0, 0.0);
        let h = 1e-3;
        for i in 0..60_000 {
            let e = -10.0 + i as f64 * h;
            let p = ln_emg(e, s, mu).exp() * h;
            mass += p;
            mean += e * p;
        }
        assert!((mass - 1.0).abs() < 1e-4, "{mass}");
        assert!((mean - mu).abs() < 1e-3, "{mean}");
    }
}
