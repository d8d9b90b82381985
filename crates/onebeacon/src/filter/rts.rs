//! The Rauch-Tung-Striebel pass: a Gaussian filter's predictions kept as it runs, then
//! smoothed backward from its final belief (Rauch, Tung and Striebel 1965; Särkkä,
//! *Bayesian Filtering and Smoothing*, 2013, theorem 8.2 for the EKF, whose cross
//! covariance is P F', and the unscented smoother, whose cross covariance comes from
//! the sigma points, sec. 9.3). Updates between two predictions need not be kept: the
//! belief before a prediction is the filtered one, all of them included.

use nalgebra::{SMatrix, SVector};

/// A mean and its covariance.
pub type Moments<const N: usize> = (SVector<f64, N>, SMatrix<f64, N, N>);

/// One prediction: its time, the belief before and after it, and the cross covariance
/// of the state before and after (E[(x_k - m_k)(x_k+1 - m_k+1)']).
#[derive(Debug, Clone, PartialEq)]
struct Step<const N: usize> {
    t_s: f64,
    before: Moments<N>,
    after: Moments<N>,
    cross: SMatrix<f64, N, N>,
}

/// A filter's predictions from time `t0_s` on.
#[derive(Debug, Clone, PartialEq)]
pub struct History<const N: usize> {
    t0_s: f64,
    steps: Vec<Step<N>>,
}

impl<const N: usize> History<N> {
    pub fn new(t0_s: f64) -> Self {
        Self { t0_s, steps: Vec::new() }
    }

    /// Keeps a prediction at `t_s` from `before` to `after` with its cross covariance.
    pub fn push(&mut self, t_s: f64, before: Moments<N>, after: Moments<N>, cross: SMatrix<f64, N, N>) {
        self.steps.push(Step { t_s, before, after, cross });
    }

    /// The smoothed belief over each interval between predictions, given the filter's
    /// final belief `last`: (the interval's start time, moments), in time order, one more
    /// than the predictions (the first from `t0_s`). Differences of the components
    /// `is_angle` marks are wrapped (`gain` for a singular predicted covariance).
    pub fn smooth(&self, last: Moments<N>, is_angle: impl Fn(usize) -> bool) -> Vec<(f64, Moments<N>)> {
        let mut out = Vec::with_capacity(self.steps.len() + 1);
        let (mut xs, mut ps) = last;
        for s in self.steps.iter().rev() {
            out.push((s.t_s, (xs, ps)));
            let (xb, pb) = &s.before;
            let (xa, pa) = &s.after;
            let g = gain(&s.cross, pa);
            let mut dx = xs - xa;
            for k in (0..N).filter(|&k| is_angle(k)) {
                dx[k] = crate::geo::wrap_angle(dx[k]);
            }
            xs = xb + g * dx;
            ps = pb + g * (ps - pa) * g.transpose();
            ps = (ps + ps.transpose()) * 0.5;
        }
        out.push((self.t0_s, (xs, ps)));
        out.reverse();
        out
    }
}

/// The smoother's gain G = C Pa^-1, from Pa G' = C' (Pa symmetric). A component of
/// zero variance (a calibration state the filter does not estimate) has zero rows and
/// columns in Pa and C, and a gain of zero; a predicted covariance that still cannot be
/// inverted gives a gain of zero (the later belief passed through).
fn gain<const N: usize>(cross: &SMatrix<f64, N, N>, pa: &SMatrix<f64, N, N>) -> SMatrix<f64, N, N> {
    let mut p = *pa;
    for k in 0..N {
        if p[(k, k)] == 0.0 {
            p[(k, k)] = 1.0;
        }
    }
    p.cholesky().map_or_else(SMatrix::zeros, |c| c.solve(&cross.transpose()).transpose())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::filter::{AnyFilter, FilterKind, GaussianFilter, MeasurementModel, ProcessModel};
    use crate::measure::StateComponent;
    use approx::assert_relative_eq;
    use nalgebra::{DMatrix, DVector, Matrix2, Vector1, Vector2};

    /// A constant-velocity model (position, velocity) over `dt`.
    struct Cv;
    impl ProcessModel<2> for Cv {
        fn propagate(&self, x: &SVector<f64, 2>, dt: f64) -> SVector<f64, 2> {
            Vector2::new(x[0] + dt * x[1], x[1])
        }
        fn jacobian(&self, _x: &SVector<f64, 2>, dt: f64) -> SMatrix<f64, 2, 2> {
            Matrix2::new(1.0, dt, 0.0, 1.0)
        }
    }

    /// On a linear Gaussian chain the RTS pass is the exact posterior: every smoothed
    /// mean and variance equals the batch solution of the whole chain's normal equations
    /// (a dense inverse of the stacked information matrix), with the EKF and the UKF.
    #[test]
    fn rts_equals_the_batch_posterior_of_a_linear_chain() {
        let (n, dt, q, r) = (25, 0.5, Matrix2::new(0.01, 0.0, 0.0, 0.04), 0.3);
        let p0 = Matrix2::new(4.0, 0.0, 0.0, 1.0);
        let z: Vec<f64> = (0..n).map(|k| 0.7 * k as f64 * dt + (k as f64 * 1.3).sin()).collect();
        for kind in [FilterKind::Ekf, FilterKind::Ukf(Default::default())] {
            let mut f = AnyFilter::new(kind, SVector::zeros(), p0);
            let mut h = History::new(0.0);
            let model = [StateComponent::value(0, r)];
            for (k, zk) in z.iter().enumerate() {
                if k > 0 {
                    let before = (*f.mean(), *f.covariance());
                    let cross = f.predict_cross(&Cv, dt, &q);
                    h.push(k as f64 * dt, before, (*f.mean(), *f.covariance()), cross);
                }
                f.update_gated(&model, &Vector1::new(*zk), &model.covariance(f.mean()), f64::INFINITY).unwrap();
            }
            let smoothed = h.smooth((*f.mean(), *f.covariance()), |_| false);
            // batch: prior on x0, motion x_k+1 - F x_k ~ N(0, Q), z_k - x_k[0] ~ N(0, r)
            let dim = 2 * n;
            let (mut info, mut b) = (DMatrix::<f64>::zeros(dim, dim), DVector::<f64>::zeros(dim));
            let p0i = p0.try_inverse().unwrap();
            let mut corner = info.view_mut((0, 0), (2, 2));
            corner += p0i;
            let qi = q.try_inverse().unwrap();
            let f_m = Cv.jacobian(&SVector::zeros(), dt);
            for k in 0..n - 1 {
                // [-F I]' Qi [-F I]
                let mut a = DMatrix::<f64>::zeros(2, dim);
                a.view_mut((0, 2 * k), (2, 2)).copy_from(&(-f_m));
                a.view_mut((0, 2 * k + 2), (2, 2)).copy_from(&Matrix2::identity());
                info += a.transpose() * qi * &a;
            }
            for (k, zk) in z.iter().enumerate() {
                info[(2 * k, 2 * k)] += 1.0 / r;
                b[2 * k] += zk / r;
            }
            let cov = info.clone().try_inverse().unwrap();
            let mean = &cov * b;
            assert_eq!(smoothed.len(), n);
            for (k, (t, (x, p))) in smoothed.iter().enumerate() {
                assert_relative_eq!(*t, k as f64 * dt);
                for i in 0..2 {
                    assert_relative_eq!(x[i], mean[2 * k + i], epsilon = 1e-9, max_relative = 1e-9);
                    assert_relative_eq!(p[(i, i)], cov[(2 * k + i, 2 * k + i)], epsilon = 1e-9, max_relative = 1e-9);
                }
            }
        }
    }
}
