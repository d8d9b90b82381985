//! Unscented Kalman filter with Merwe's scaled sigma points (van der Merwe 2004; Julier
//! and Uhlmann 1997), over the same [`ProcessModel`] and [`MeasurementModel`] as the
//! EKF, so that every navigator runs it unchanged.
//!
//! 2N + 1 sigma points x, x +- sqrt(N + lambda) L_i with L L' = P, lambda = alpha^2 (N +
//! kappa) - N; mean weights W0 = lambda / (N + lambda), Wi = 1 / (2 (N + lambda)); the
//! covariance weight of the centre adds 1 - alpha^2 + beta. Angles are averaged as
//! wrapped residuals about the centre point (state components the process model marks,
//! measurement components the measurement model marks), so a heading near +-pi averages
//! correctly. The covariance update is Joseph's form with the statistically linearised
//! H = Pxz' P^-1: symmetric, and first-order insensitive to errors in the gain. The square root of P
//! tolerates states with exactly zero variance (a calibration state switched off).

use super::{FilterError, Gated, GaussianFilter, MeasurementModel, ProcessModel};
use crate::geo::wrap_angle;
use nalgebra::{SMatrix, SVector};

/// Merwe's sigma-point parameters.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct UkfParams {
    /// Spread of the sigma points around the mean (0 < alpha <= 1).
    pub alpha: f64,
    /// Prior knowledge of the distribution (2 is optimal for a Gaussian).
    pub beta: f64,
    /// Secondary scaling (N + kappa > 0).
    pub kappa: f64,
}

impl Default for UkfParams {
    /// alpha = 1, beta = 2, kappa = 0: points at sqrt(N) standard deviations, centre mean
    /// weight 0, no negative weights (robust for the 6-7 states of the navigators).
    fn default() -> Self {
        Self { alpha: 1.0, beta: 2.0, kappa: 0.0 }
    }
}

impl UkfParams {
    /// (N + lambda, mean weight of the centre, covariance weight of the centre, weight
    /// of every other point).
    fn weights(&self, n: usize) -> (f64, f64, f64, f64) {
        let n = n as f64;
        let c = self.alpha * self.alpha * (n + self.kappa); // N + lambda
        let lambda = c - n;
        let wm0 = lambda / c;
        (c, wm0, wm0 + 1.0 - self.alpha * self.alpha + self.beta, 0.5 / c)
    }
}

/// The unscented Kalman filter: state estimate, covariance and sigma-point parameters.
#[derive(Debug, Clone, PartialEq)]
pub struct Ukf<const N: usize> {
    pub x: SVector<f64, N>,
    pub p: SMatrix<f64, N, N>,
    pub params: UkfParams,
}

/// Lower-triangular L with L L' = A for a symmetric positive semi-definite A. A column
/// whose pivot is zero (to rounding) is left zero, so states with exactly zero variance
/// need no jitter; a clearly negative pivot is an error.
pub(crate) fn psd_cholesky<const N: usize>(a: &SMatrix<f64, N, N>) -> Option<SMatrix<f64, N, N>> {
    let scale = (0..N).map(|i| a[(i, i)].abs()).fold(0.0, f64::max);
    let tol = scale * 1e-12;
    let mut l = SMatrix::<f64, N, N>::zeros();
    for j in 0..N {
        let d = a[(j, j)] - (0..j).map(|k| l[(j, k)] * l[(j, k)]).sum::<f64>();
        if !d.is_finite() || d < -tol.max(1e-300) * 1e3 {
            return None;
        }
        if d <= tol {
            continue; // a (numerically) deterministic direction
        }
        let ljj = d.sqrt();
        l[(j, j)] = ljj;
        for i in j + 1..N {
            let s = a[(i, j)] - (0..j).map(|k| l[(i, k)] * l[(j, k)]).sum::<f64>();
            l[(i, j)] = s / ljj;
        }
    }
    Some(l)
}

impl<const N: usize> Ukf<N> {
    pub fn new(x: SVector<f64, N>, p: SMatrix<f64, N, N>, params: UkfParams) -> Self {
        Self { x, p, params }
    }

    /// The 2N + 1 sigma points of (x, P), as columns offsets from x: point 0 is x, point
    /// 1 + i is x + d_i and point 1 + N + i is x - d_i.
    fn spread(&self, c: f64) -> Result<SMatrix<f64, N, N>, FilterError> {
        // nalgebra's factorisation when P is positive definite (the common case, and
        // the faster one), the semi-definite one when a state has zero variance
        let l = match self.p.cholesky() {
            Some(ch) => ch.unpack(),
            None => psd_cholesky(&self.p).ok_or(FilterError::InnovationNotPositiveDefinite)?,
        };
        Ok(l * c.sqrt())
    }
}

/// Weighted mean of `points` about `points[0]`, wrapping the components `is_angle` marks.
fn mean<const D: usize>(
    points: &[SVector<f64, D>],
    wm0: f64,
    wi: f64,
    is_angle: impl Fn(usize) -> bool,
) -> SVector<f64, D> {
    let centre = points[0];
    let mut m = centre * wm0;
    for p in &points[1..] {
        m += p * wi;
    }
    for k in (0..D).filter(|&k| is_angle(k)) {
        // mean of the wrapped residuals about the centre point
        let r: f64 = points[1..].iter().map(|p| wrap_angle(p[k] - centre[k])).sum::<f64>() * wi;
        m[k] = wrap_angle(centre[k] + r);
    }
    m
}

fn residual<const D: usize>(
    a: &SVector<f64, D>,
    b: &SVector<f64, D>,
    is_angle: &impl Fn(usize) -> bool,
) -> SVector<f64, D> {
    let mut d = a - b;
    for k in (0..D).filter(|&k| is_angle(k)) {
        d[k] = wrap_angle(d[k]);
    }
    d
}

/// The unscented transform through `f` of the 2N + 1 sigma points about `x` spread by
/// `d` (x, x + d_i, x - d_i) with weights (wm0, wc0, wi): the points' weighted mean
/// (angle-aware), their covariance plus `noise`, and the cross covariance of the state
/// with them, sum Wc dX dY'.
fn transform<const N: usize, const D: usize>(
    x: &SVector<f64, N>,
    d: &SMatrix<f64, N, N>,
    (wm0, wc0, wi): (f64, f64, f64),
    f: impl Fn(&SVector<f64, N>) -> SVector<f64, D>,
    is_angle: impl Fn(usize) -> bool,
    noise: &SMatrix<f64, D, D>,
) -> (SVector<f64, D>, SMatrix<f64, D, D>, SMatrix<f64, N, D>) {
    let mut ys = Vec::with_capacity(2 * N + 1);
    ys.push(f(x));
    for sign in [1.0, -1.0] {
        for i in 0..N {
            ys.push(f(&(x + d.column(i) * sign)));
        }
    }
    let m = mean(&ys, wm0, wi, &is_angle);
    let (mut cov, mut cross) = (*noise, SMatrix::<f64, N, D>::zeros());
    for (j, yj) in ys.iter().enumerate() {
        let dy = residual(yj, &m, &is_angle);
        let w = if j == 0 { wc0 } else { wi };
        cov += dy * dy.transpose() * w;
        if j > 0 {
            // the state offset of point j: +d_i or -d_i
            let dx = if j <= N { d.column(j - 1).into_owned() } else { -d.column(j - 1 - N) };
            cross += dx * dy.transpose() * w;
        }
    }
    (m, cov, cross)
}

impl<const N: usize> GaussianFilter<N> for Ukf<N> {
    fn mean(&self) -> &SVector<f64, N> {
        &self.x
    }
    fn covariance(&self) -> &SMatrix<f64, N, N> {
        &self.p
    }
    fn mean_mut(&mut self) -> &mut SVector<f64, N> {
        &mut self.x
    }
    fn covariance_mut(&mut self) -> &mut SMatrix<f64, N, N> {
        &mut self.p
    }

    /// Unscented prediction: every sigma point through the model, the (angle-aware)
    /// weighted mean, and P = sum Wc dY dY' + Q. A covariance that is not positive
    /// semi-definite leaves the filter as it was.
    #[inline(never)] // keeps the EKF path of AnyFilter small where the UKF is not used
    fn predict<P: ProcessModel<N>>(&mut self, model: &P, dt: f64, q: &SMatrix<f64, N, N>) {
        self.predict_cross(model, dt, q);
    }

    /// The cross covariance of the sigma points before and after: sum Wc dX dY' (the
    /// covariance itself where the prediction cannot be made).
    fn predict_cross<P: ProcessModel<N>>(&mut self, model: &P, dt: f64, q: &SMatrix<f64, N, N>) -> SMatrix<f64, N, N> {
        let (c, wm0, wc0, wi) = self.params.weights(N);
        let Ok(d) = self.spread(c) else { return self.p };
        let (m, p, cross) =
            transform(&self.x, &d, (wm0, wc0, wi), |x| model.propagate(x, dt), |k| model.is_angle(k), q);
        self.x = m;
        self.p = (p + p.transpose()) * 0.5;
        cross
    }

    #[inline(never)]
    fn update_gated<const M: usize, H: MeasurementModel<N, M>>(
        &mut self,
        model: &H,
        z: &SVector<f64, M>,
        r: &SMatrix<f64, M, M>,
        max_nis: f64,
    ) -> Result<Gated, FilterError> {
        let (c, wm0, wc0, wi) = self.params.weights(N);
        let d = self.spread(c)?;
        let is_angle = |k| model.is_angle(k);
        let (zm, s, pxz) = transform(&self.x, &d, (wm0, wc0, wi), |x| model.predict(x), is_angle, r);
        let nu = residual(z, &zm, &is_angle);
        if !nu.iter().all(|v| v.is_finite()) || !s.iter().all(|v| v.is_finite()) {
            return Err(FilterError::NonFinite);
        }
        let s_chol = s.cholesky().ok_or(FilterError::InnovationNotPositiveDefinite)?;
        let nis = nu.dot(&s_chol.solve(&nu));
        let det_s = super::ekf::det_from_cholesky(&s_chol);
        let innovation = super::ekf::Innovation::of(&nu, &s, det_s, nis);
        if nis > max_nis {
            return Ok(Gated::Rejected(innovation));
        }
        let k = s_chol.solve(&pxz.transpose()).transpose(); // K = Pxz S^-1
        // Joseph form with the statistically linearised H = Pxz' P^-1 and the effective
        // noise R_eff = S - H P H': (I - K H) P (I - K H)' + K R_eff K' expands to
        // P - K Pxz' - Pxz K' + K S K', which needs no inverse of P (singular when a
        // calibration state is switched off) and, like Joseph's form, is insensitive to
        // first order to errors in K
        let kpxz = k * pxz.transpose();
        let p = self.p - kpxz - kpxz.transpose() + k * s * k.transpose();
        self.x += k * nu;
        self.p = (p + p.transpose()) * 0.5;
        Ok(Gated::Accepted(innovation))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::filter::Ekf;
    use approx::assert_relative_eq;
    use nalgebra::{Matrix1, Matrix2, Vector1, Vector2};
    use rand::{RngExt, SeedableRng};
    use rand_distr::StandardNormal;

    use crate::filter::ekf::tests::{ConstantVelocity, PositionFix};

    /// On a linear-Gaussian problem the unscented transform is exact: the UKF equals the
    /// Kalman filter (here the EKF, itself checked against the closed form in ekf.rs)
    /// for any sigma-point parameters.
    #[test]
    fn equals_the_kalman_filter_on_a_linear_problem() {
        for params in [UkfParams::default(), UkfParams { alpha: 0.1, beta: 2.0, kappa: 1.0 }] {
            let dt: f64 = 0.5;
            let q = Matrix2::new(dt.powi(3) / 3.0, dt.powi(2) / 2.0, dt.powi(2) / 2.0, dt) * 0.04;
            let r = Matrix1::new(0.3);
            let (x0, p0) = (Vector2::new(0.0, 1.0), Matrix2::new(4.0, 0.5, 0.5, 1.0));
            let mut kf = Ekf::new(x0, p0);
            let mut ukf = Ukf::new(x0, p0, params);
            let mut rng = rand_pcg::Pcg64Mcg::seed_from_u64(3);
            let mut truth = Vector2::new(0.3, 0.9);
            for _ in 0..100 {
                truth = ConstantVelocity.propagate(&truth, dt);
                let z = Vector1::new(truth[0] + 0.3f64.sqrt() * rng.sample::<f64, _>(StandardNormal));
                kf.predict(&ConstantVelocity, dt, &q);
                ukf.predict(&ConstantVelocity, dt, &q);
                let a = kf.update_gated(&PositionFix, &z, &r, f64::INFINITY).unwrap();
                let b = ukf.update_gated(&PositionFix, &z, &r, f64::INFINITY).unwrap();
                assert_relative_eq!(a.nis(), b.nis(), max_relative = 1e-7);
                for i in 0..2 {
                    assert_relative_eq!(kf.x[i], ukf.x[i], max_relative = 1e-8, epsilon = 1e-10);
                    for j in 0..2 {
                        assert_relative_eq!(kf.p[(i, j)], ukf.p[(i, j)], max_relative = 1e-7, epsilon = 1e-11);
                    }
                }
            }
        }
    }

    /// On a mildly nonlinear problem (a range from a beacon 1 km away, a 0.1 m position
    /// uncertainty) the UKF and the EKF agree to first order: the linearisation error is
    /// of order sigma^2 / r = 1e-5 m, far below the update itself (0.5 m).
    #[test]
    fn agrees_with_the_ekf_to_first_order_on_a_mildly_nonlinear_problem() {
        use crate::measure::{Range2d, ScalarModel};
        let beacon = Vector2::new(800.0, 600.0);
        let range = Range2d { beacon, var: 0.01 };
        let models: [&dyn ScalarModel<2>; 1] = [&range];
        let x0 = Vector2::new(0.3, -0.2);
        let p0 = Matrix2::new(0.01, 0.002, 0.002, 0.02);
        let z = Vector1::new(999.5); // true range from x0 is about 999.70
        let mut ekf = Ekf::new(x0, p0);
        let mut ukf = Ukf::new(x0, p0, UkfParams::default());
        let r = models.covariance(&x0);
        let a = ekf.update_gated(&models, &z, &r, f64::INFINITY).unwrap().nis();
        let b = ukf.update_gated(&models, &z, &r, f64::INFINITY).unwrap().nis();
        assert!((ekf.x - x0).norm() > 0.05, "the update moves the state");
        assert!((ekf.x - ukf.x).norm() < 1e-4, "EKF {} UKF {}", ekf.x, ukf.x);
        // the covariances part at second order: the measurement's gradient turns by sigma / r
        // over the cloud, so relatively by (sigma / r)^2 = 2e-8 with sigma^2 the largest
        // eigenvalue of P0 (measured: 6.9e-9)
        let sigma2 = p0.symmetric_eigenvalues().max();
        let bound = sigma2 / (x0 - beacon).norm_squared() * p0.norm();
        assert!((ekf.p - ukf.p).norm() < bound, "EKF {} UKF {} (bound {bound})", ekf.p, ukf.p);
        assert_relative_eq!(a, b, max_relative = 1e-3);
        // and a strongly nonlinear one (beacon 0.5 m away) separates them
        let near = Range2d { beacon: Vector2::new(0.6, 0.2), var: 0.01 };
        let models: [&dyn ScalarModel<2>; 1] = [&near];
        let (mut ekf, mut ukf) = (Ekf::new(x0, p0 * 10.0), Ukf::new(x0, p0 * 10.0, UkfParams::default()));
        let z = Vector1::new(0.3);
        ekf.update_gated(&models, &z, &r, f64::INFINITY).unwrap();
        ukf.update_gated(&models, &z, &r, f64::INFINITY).unwrap();
        assert!((ekf.x - ukf.x).norm() > 1e-3);
    }

    /// A zero-variance state stays exactly zero-variance and at its value.
    #[test]
    fn zero_variance_states_are_left_alone() {
        let x0 = Vector2::new(1.0, 2.0);
        let p0 = Matrix2::new(4.0, 0.0, 0.0, 0.0);
        let mut ukf = Ukf::new(x0, p0, UkfParams::default());
        ukf.update_gated(&PositionFix, &Vector1::new(3.0), &Matrix1::new(1.0), f64::INFINITY).unwrap();
        assert_relative_eq!(ukf.x[0], 1.0 + 4.0 / 5.0 * 2.0, max_relative = 1e-12);
        assert_eq!((ukf.x[1], ukf.p[(1, 1)], ukf.p[(0, 1)]), (2.0, 0.0, 0.0));
        assert_relative_eq!(ukf.p[(0, 0)], 4.0 - 16.0 / 5.0, max_relative = 1e-12);
    }

    #[test]
    fn psd_cholesky_factors_and_refuses_indefinite() {
        let a = Matrix2::new(4.0, 2.0, 2.0, 3.0);
        let l = psd_cholesky(&a).unwrap();
        assert_relative_eq!(l * l.transpose(), a, epsilon = 1e-12);
        assert!(psd_cholesky(&Matrix2::new(1.0, 2.0, 2.0, 1.0)).is_none());
    }

    /// Angle averaging across the cut: sigma points of a heading at pi straddle +-pi.
    #[test]
    fn angle_mean_across_the_cut() {
        struct Heading;
        impl ProcessModel<1> for Heading {
            fn propagate(&self, x: &SVector<f64, 1>, _dt: f64) -> SVector<f64, 1> {
                SVector::<f64, 1>::new(wrap_angle(x[0]))
            }
            fn jacobian(&self, _x: &SVector<f64, 1>, _dt: f64) -> SMatrix<f64, 1, 1> {
                SMatrix::<f64, 1, 1>::identity()
            }
            fn is_angle(&self, _i: usize) -> bool {
                true
            }
        }
        let pi = std::f64::consts::PI;
        let mut ukf = Ukf::new(SVector::<f64, 1>::new(pi - 0.01), Matrix1::new(0.04), UkfParams::default());
        ukf.predict(&Heading, 1.0, &Matrix1::new(0.0));
        assert_relative_eq!(ukf.x[0], pi - 0.01, epsilon = 1e-12);
        assert_relative_eq!(ukf.p[(0, 0)], 0.04, max_relative = 1e-12);
    }
}
