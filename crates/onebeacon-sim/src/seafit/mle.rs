//! A maximum-likelihood fit: the negative log-likelihood minimised by Nelder-Mead
//! (argmin), restarted from its best point until a restart gains nothing, and the
//! covariance of the estimate from the inverse of its curvature there (the observed
//! Fisher information, by central differences of central differences: finitediff).

use argmin::core::{CostFunction, Error, Executor, State};
use argmin::solver::neldermead::NelderMead;
use nalgebra::DMatrix;

/// A fitted parameter vector, its negative log-likelihood and covariance (None where
/// the curvature is not positive definite: a parameter at the edge of what it may be,
/// or one the data do not inform).
#[derive(Debug, Clone)]
pub(crate) struct Fit {
    pub x: Vec<f64>,
    pub nll: f64,
    pub covariance: Option<DMatrix<f64>>,
}

impl Fit {
    /// The standard deviation of parameter `i`.
    pub fn sd(&self, i: usize) -> Option<f64> {
        self.covariance.as_ref().map(|c| c[(i, i)].sqrt()).filter(|s| s.is_finite())
    }

    /// The 95 % interval of g(x) by the delta method, `g` of the parameters (its
    /// gradient by central differences): None without a covariance.
    pub fn interval_of(&self, g: impl Fn(&[f64]) -> f64) -> Option<[f64; 2]> {
        let c = self.covariance.as_ref()?;
        let v = g(&self.x);
        let grad: Vec<f64> = (0..self.x.len())
            .map(|i| {
                let h = 1e-6 * (1.0 + self.x[i].abs());
                let (mut a, mut b) = (self.x.clone(), self.x.clone());
                a[i] += h;
                b[i] -= h;
                (g(&a) - g(&b)) / (2.0 * h)
            })
            .collect();
        let grad = nalgebra::DVector::from_vec(grad);
        let sd = (grad.transpose() * c * &grad)[(0, 0)].sqrt();
        sd.is_finite().then_some([v - 1.96 * sd, v + 1.96 * sd])
    }
}

struct Cost<'a>(&'a (dyn Fn(&[f64]) -> f64 + Sync));

impl CostFunction for Cost<'_> {
    type Param = Vec<f64>;
    type Output = f64;
    fn cost(&self, p: &Vec<f64>) -> Result<f64, Error> {
        let v = (self.0)(p);
        // a point where the likelihood is not defined is as bad as can be
        Ok(if v.is_finite() { v } else { f64::MAX })
    }
}

/// Minimises `nll` from `start`, the first simplex `step` away along each axis
/// (parameters scaled so that a step of about 1 is a large move). At most 6 restarts of
/// 4000 iterations each.
pub(crate) fn minimise(nll: &(dyn Fn(&[f64]) -> f64 + Sync), start: &[f64], step: f64) -> Result<Fit, Error> {
    let (best, best_cost) = minimise_only(nll, start, step)?;
    let covariance = curvature(nll, &best);
    Ok(Fit { x: best, nll: best_cost, covariance })
}

/// [`minimise`] without the curvature: the point and its cost.
fn minimise_only(nll: &(dyn Fn(&[f64]) -> f64 + Sync), start: &[f64], step: f64) -> Result<(Vec<f64>, f64), Error> {
    let mut best = start.to_vec();
    let mut best_cost = nll(&best);
    let mut step = step;
    for _ in 0..6 {
        let mut simplex = vec![best.clone()];
        for i in 0..best.len() {
            let mut p = best.clone();
            p[i] += step;
            simplex.push(p);
        }
        let solver = NelderMead::new(simplex).with_sd_tolerance(1e-10)?;
        let result = Executor::new(Cost(nll), solver).configure(|s| s.max_iters(4000)).run()?;
        let state = result.state();
        let (cost, x) = (state.get_best_cost(), state.get_best_param().cloned().unwrap_or_else(|| best.clone()));
        let gained = best_cost - cost;
        if cost <= best_cost {
            (best, best_cost) = (x, cost);
        }
        if gained < 1e-7 {
            break;
        }
        step = (step * 0.5).max(0.05);
    }
    Ok((best, best_cost))
}

/// The 95 % profile-likelihood interval of parameter `i` of `fit`: the values where the
/// likelihood, maximised over the other parameters, falls 1.92 (chi-square, 1 dof, 95 %
/// over 2) below its maximum; each end found by bisection (12 steps, to 1/2000 of the
/// curvature's half-width) after stepping out
/// from the curvature's interval. Where the likelihood is skewed (a variance or a
/// correlation time from a short record), this covers as the curvature's cannot. None
/// without a covariance to start from.
pub(crate) fn profile_interval(nll: &(dyn Fn(&[f64]) -> f64 + Sync), fit: &Fit, i: usize) -> Option<[f64; 2]> {
    let sd = fit.sd(i)?;
    let others: Vec<f64> = fit.x.iter().enumerate().filter(|(j, _)| *j != i).map(|(_, v)| *v).collect();
    let with = |v: f64, rest: &[f64]| {
        let mut x = rest.to_vec();
        x.insert(i, v);
        x
    };
    // the profile at v: the others re-fitted from the optimum
    let profile = |v: f64| -> f64 {
        if others.is_empty() {
            return nll(&[v]) - fit.nll;
        }
        let cost = |rest: &[f64]| nll(&with(v, rest));
        minimise_only(&cost, &others, 0.1).map_or(f64::INFINITY, |(_, c)| c - fit.nll)
    };
    let end = |direction: f64| -> f64 {
        let (mut inside, mut out) = (fit.x[i], fit.x[i] + direction * 1.96 * sd);
        let mut steps = 0;
        while profile(out) < 1.92 && steps < 20 {
            (inside, out) = (out, out + direction * 1.96 * sd);
            steps += 1;
        }
        for _ in 0..12 {
            let mid = 0.5 * (inside + out);
            if profile(mid) < 1.92 { inside = mid } else { out = mid }
        }
        0.5 * (inside + out)
    };
    Some([end(-1.0), end(1.0)])
}

/// The inverse of the Hessian of `nll` at `x`, if positive definite.
fn curvature(nll: &(dyn Fn(&[f64]) -> f64 + Sync), x: &[f64]) -> Option<DMatrix<f64>> {
    let f = |p: &Vec<f64>| -> Result<f64, Error> { Ok(nll(p)) };
    let grad = finitediff::vec::central_diff(&f);
    let hessian = finitediff::vec::central_hessian(&grad)(&x.to_vec()).ok()?;
    let n = x.len();
    let h = DMatrix::from_fn(n, n, |i, j| hessian[i][j]);
    h.cholesky().map(|c| c.inverse())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A Gaussian sample's mean and log sigma: the fit lands on the closed form (the
    /// sample mean and the maximum-likelihood sigma), and the covariance is the inverse
    /// Fisher information, sigma^2 / n for the mean and 1 / (2 n) for log sigma.
    #[test]
    fn a_gaussian_sample_is_fitted_to_its_closed_form() {
        let xs: Vec<f64> = (0..400).map(|i| 3.0 + ((i * 7919 % 400) as f64 / 400.0 - 0.5) * 2.0).collect();
        let n = xs.len() as f64;
        let mean = xs.iter().sum::<f64>() / n;
        let sigma = (xs.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / n).sqrt();
        let nll = |p: &[f64]| {
            let s = p[1].exp();
            xs.iter().map(|x| 0.5 * ((x - p[0]) / s).powi(2) + p[1]).sum::<f64>()
        };
        let fit = minimise(&nll, &[0.0, 0.0], 1.0).unwrap();
        assert!((fit.x[0] - mean).abs() < 1e-5, "{:?} against {mean}", fit.x);
        assert!((fit.x[1].exp() - sigma).abs() < 1e-5, "{:?} against {sigma}", fit.x);
        let (sd_mean, sd_log) = (fit.sd(0).unwrap(), fit.sd(1).unwrap());
        assert!((sd_mean / (sigma / n.sqrt()) - 1.0).abs() < 1e-3, "{sd_mean}");
        assert!((sd_log / (1.0 / (2.0 * n)).sqrt() - 1.0).abs() < 1e-3, "{sd_log}");
        let [lo, hi] = fit.interval_of(|p| p[1].exp()).unwrap();
        // the delta method: sigma +- 1.96 sigma / sqrt(2 n)
        let half = 1.96 * sigma / (2.0 * n).sqrt();
        assert!((lo - (sigma - half)).abs() < 1e-4 && (hi - (sigma + half)).abs() < 1e-4, "{lo} {hi}");
    }
}
