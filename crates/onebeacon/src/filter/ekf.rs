//! Extended Kalman filter over fixed-size nalgebra states (garin2024 Algorithm 1).
//!
//! The filter knows nothing of vehicles or beacons: a [`ProcessModel`] gives the
//! transition and its Jacobian F, a [`MeasurementModel`] gives h(x), its Jacobian H and
//! which components are angles. The covariance update is in Joseph form, which stays
//! symmetric positive semi-definite for any gain.

use super::GaussianFilter;
use crate::geo::wrap_angle;
use nalgebra::{SMatrix, SVector};

/// Errors of a filter step. The state is left unchanged when one is returned.
#[derive(Debug, Clone, Copy, PartialEq, thiserror::Error)]
pub enum FilterError {
    #[error("innovation covariance is not positive definite (measurement noise too small or state covariance broken)")]
    InnovationNotPositiveDefinite,
    #[error("measurement or prediction is not finite")]
    NonFinite,
}

/// A discrete-time process model x_{k+1} = f(x_k, dt) + w, w ~ N(0, Q), that owns its Q.
pub trait ProcessModel<const N: usize> {
    /// The predicted state after `dt` seconds.
    fn propagate(&self, x: &SVector<f64, N>, dt: f64) -> SVector<f64, N>;
    /// The Jacobian df/dx at `x`.
    fn jacobian(&self, x: &SVector<f64, N>, dt: f64) -> SMatrix<f64, N, N>;
    /// Both at once; override when they share work (the same sines, say).
    fn transition(&self, x: &SVector<f64, N>, dt: f64) -> (SVector<f64, N>, SMatrix<f64, N, N>) {
        (self.propagate(x, dt), self.jacobian(x, dt))
    }
    /// The process noise covariance Q the model adds over `dt` from `x` (zero for a
    /// deterministic model).
    fn noise_covariance(&self, _x: &SVector<f64, N>, _dt: f64) -> SMatrix<f64, N, N> {
        SMatrix::zeros()
    }
    /// Whether state component `i` is an angle (averaged and differenced wrapped to
    /// (-pi, pi] by the unscented filter).
    fn is_angle(&self, _i: usize) -> bool {
        false
    }
    /// The predicted covariance F P F' + Q; override to exploit the sparsity of F.
    fn propagate_covariance(
        &self,
        f: &SMatrix<f64, N, N>,
        p: &SMatrix<f64, N, N>,
        q: &SMatrix<f64, N, N>,
    ) -> SMatrix<f64, N, N> {
        f * p * f.transpose() + q
    }
}

/// A measurement model z = h(x) + v with M components.
pub trait MeasurementModel<const N: usize, const M: usize> {
    /// The predicted measurement h(x).
    fn predict(&self, x: &SVector<f64, N>) -> SVector<f64, M>;
    /// The Jacobian dh/dx at `x`.
    fn jacobian(&self, x: &SVector<f64, N>) -> SMatrix<f64, M, N>;
    /// Whether component `i` is an angle, whose innovation is wrapped to (-pi, pi].
    fn is_angle(&self, _i: usize) -> bool {
        false
    }
    /// The state component that component `i` measures directly, when row `i` of the
    /// Jacobian is the unit row e_k at every x ([`crate::measure::ScalarModel::unit_row`]).
    fn unit_row(&self, _i: usize) -> Option<usize> {
        None
    }
    /// The noise covariance R of a measurement taken at `x` (it may depend on the state:
    /// a beacon's position error projected on the line of sight).
    fn covariance(&self, x: &SVector<f64, N>) -> SMatrix<f64, M, M>;
    /// A noisy measurement at `x`: h(x) plus a draw from N(0, R(x)). What the simulator
    /// measures, so the filter's R and the world's noise are one number.
    fn sample<R: rand::Rng + ?Sized>(&self, x: &SVector<f64, N>, rng: &mut R) -> SVector<f64, M> {
        let l = self.covariance(x).cholesky().map_or_else(SMatrix::zeros, |c| c.l());
        let n = SVector::<f64, M>::from_fn(|_, _| super::gauss(rng, 1.0));
        self.predict(x) + l * n
    }
}

/// The extended Kalman filter: state estimate and its covariance.
#[derive(Debug, Clone, PartialEq)]
pub struct Ekf<const N: usize> {
    pub x: SVector<f64, N>,
    pub p: SMatrix<f64, N, N>,
}

impl<const N: usize> Ekf<N> {
    pub fn new(x: SVector<f64, N>, p: SMatrix<f64, N, N>) -> Self {
        Self { x, p }
    }

    /// Update with measurement `z` of noise covariance `r` (Algorithm 1, lines 2, 5-8,
    /// with the Joseph-form covariance). Returns the normalised innovation squared
    /// (NIS), distributed chi-square with M degrees of freedom when the filter is
    /// consistent.
    pub fn update<const M: usize, H: MeasurementModel<N, M>>(
        &mut self,
        model: &H,
        z: &SVector<f64, M>,
        r: &SMatrix<f64, M, M>,
    ) -> Result<f64, FilterError> {
        GaussianFilter::update_gated(self, model, z, r, f64::INFINITY).map(|g| g.nis())
    }
}

impl<const N: usize> GaussianFilter<N> for Ekf<N> {
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
    /// Prediction (Algorithm 1, lines 1, 3, 4): x = f(x), P = F P F' + Q.
    fn predict<P: ProcessModel<N>>(&mut self, model: &P, dt: f64, q: &SMatrix<f64, N, N>) {
        let (x, f) = model.transition(&self.x, dt);
        self.x = x;
        self.p = model.propagate_covariance(&f, &self.p, q);
    }

    /// The cross covariance of the linearised step: P F'.
    fn predict_cross<P: ProcessModel<N>>(&mut self, model: &P, dt: f64, q: &SMatrix<f64, N, N>) -> SMatrix<f64, N, N> {
        let (x, f) = model.transition(&self.x, dt);
        let cross = self.p * f.transpose();
        self.x = x;
        self.p = model.propagate_covariance(&f, &self.p, q);
        cross
    }

    /// [`Ekf::update`] with innovation gating: a measurement whose NIS exceeds `max_nis`
    /// (a chi-square quantile with M degrees of freedom) is rejected and leaves the
    /// state untouched.
    fn update_gated<const M: usize, H: MeasurementModel<N, M>>(
        &mut self,
        model: &H,
        z: &SVector<f64, M>,
        r: &SMatrix<f64, M, M>,
        max_nis: f64,
    ) -> Result<Gated, FilterError> {
        let h = model.jacobian(&self.x);
        let mut nu = z - model.predict(&self.x);
        for i in 0..M {
            if model.is_angle(i) {
                nu[i] = wrap_angle(nu[i]);
            }
        }
        if !nu.iter().all(|v| v.is_finite()) {
            return Err(FilterError::NonFinite);
        }
        let pht = times_ht(model, &h, &self.p);
        // S = H (P H') + R, with H (P H') = ((P H')' H')'
        let s = times_ht(model, &h, &pht.transpose()).transpose() + r;
        // Cholesky proves S positive definite; the closed-form inverse of small
        // matrices is several times faster than inverting through the factor.
        let det_s = det_from_cholesky(&s.cholesky().ok_or(FilterError::InnovationNotPositiveDefinite)?);
        let s_inv = s.try_inverse().ok_or(FilterError::InnovationNotPositiveDefinite)?;
        let nis = nu.dot(&(s_inv * nu));
        let innovation = Innovation::of(&nu, &s, det_s, nis);
        if nis > max_nis {
            return Ok(Gated::Rejected(innovation));
        }
        let k = pht * s_inv;
        self.x += k * nu;
        // Joseph form (I - K H) P (I - K H)' + K R K', with (I - K H) P = P - K (P H')'
        // and ((I - K H) P) (I - K H)' = A - (A H') K' for A = (I - K H) P: in all,
        // A - (A H' - K R) K'.
        let a = self.p - k * pht.transpose();
        let p = a - (times_ht(model, &h, &a) - k * r) * k.transpose();
        self.p = (p + p.transpose()) * 0.5;
        Ok(Gated::Accepted(innovation))
    }
}

/// m H' for `model`'s Jacobian `h`: the column of m a unit row of H selects, the
/// product with the others. The same bits as `m * h.transpose()` (a product with a unit
/// row adds exact zeros to the one term), in a fraction of the work for the state
/// components every inertial update carries.
fn times_ht<const R: usize, const N: usize, const M: usize, H: MeasurementModel<N, M>>(
    model: &H,
    h: &SMatrix<f64, M, N>,
    m: &SMatrix<f64, R, N>,
) -> SMatrix<f64, R, M> {
    let mut out = SMatrix::<f64, R, M>::zeros();
    for j in 0..M {
        match model.unit_row(j) {
            Some(k) => out.set_column(j, &m.column(k)),
            None => out.set_column(j, &(m * h.row(j).transpose())),
        }
    }
    out
}

/// How a measurement compared with its prediction before an update: its NIS, the
/// determinant of its innovation covariance S (with the NIS, the measurement's
/// likelihood), and its first component's innovation z - h(x) with that component's
/// standard deviation sqrt(S_00) (a range's residual in metres: the mean of many tells
/// a biased beacon).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Innovation {
    pub nis: f64,
    pub det_s: f64,
    pub residual: f64,
    pub sigma: f64,
}

impl Innovation {
    /// The innovation `nu` with covariance `s` (its determinant `det_s`) and NIS `nis`.
    pub(crate) fn of<const M: usize>(nu: &SVector<f64, M>, s: &SMatrix<f64, M, M>, det_s: f64, nis: f64) -> Self {
        Self { nis, det_s, residual: nu[0], sigma: s[(0, 0)].max(0.0).sqrt() }
    }

    /// No comparison to report (a navigator that weighs without a Gaussian prediction).
    pub const NONE: Innovation = Innovation { nis: f64::NAN, det_s: f64::NAN, residual: f64::NAN, sigma: f64::NAN };
}

/// What a gated update did, with the measurement's [`Innovation`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Gated {
    Accepted(Innovation),
    Rejected(Innovation),
}

impl Gated {
    pub fn innovation(self) -> Innovation {
        match self {
            Gated::Accepted(i) | Gated::Rejected(i) => i,
        }
    }

    pub fn nis(self) -> f64 {
        self.innovation().nis
    }

    /// det S.
    pub fn det_s(self) -> f64 {
        self.innovation().det_s
    }
}

/// det S from its Cholesky factor: the squared product of the factor's diagonal.
pub(crate) fn det_from_cholesky<const M: usize>(l: &nalgebra::Cholesky<f64, nalgebra::Const<M>>) -> f64 {
    let p: f64 = l.l_dirty().diagonal().iter().product();
    p * p
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use approx::assert_relative_eq;
    use nalgebra::{Matrix1x2, Matrix2, Vector1, Vector2};
    use rand::{RngExt, SeedableRng};
    use rand_distr::StandardNormal;

    /// Constant-velocity model in one dimension: x = [position, velocity].
    pub(crate) struct ConstantVelocity;
    impl ProcessModel<2> for ConstantVelocity {
        fn propagate(&self, x: &Vector2<f64>, dt: f64) -> Vector2<f64> {
            self.jacobian(x, dt) * x
        }
        fn jacobian(&self, _x: &Vector2<f64>, dt: f64) -> Matrix2<f64> {
            Matrix2::new(1.0, dt, 0.0, 1.0)
        }
    }
    /// Position measurement.
    pub(crate) struct PositionFix;
    impl MeasurementModel<2, 1> for PositionFix {
        fn predict(&self, x: &Vector2<f64>) -> Vector1<f64> {
            Vector1::new(x[0])
        }
        fn jacobian(&self, _x: &Vector2<f64>) -> Matrix1x2<f64> {
            Matrix1x2::new(1.0, 0.0)
        }
        fn covariance(&self, _x: &Vector2<f64>) -> nalgebra::Matrix1<f64> {
            nalgebra::Matrix1::new(0.3)
        }
    }

    /// On a linear-Gaussian problem the EKF must equal the textbook Kalman filter,
    /// written here in closed form for the scalar-measurement case with the short
    /// covariance update P = (I - K H) P.
    #[test]
    fn equals_closed_form_kalman_filter_on_linear_problem() {
        let dt: f64 = 0.5;
        let q = Matrix2::new(dt.powi(3) / 3.0, dt.powi(2) / 2.0, dt.powi(2) / 2.0, dt) * 0.04;
        let r = 0.3_f64;
        let mut ekf = Ekf::new(Vector2::new(0.0, 1.0), Matrix2::new(4.0, 0.0, 0.0, 1.0));

        // closed form, element by element
        let (mut x0, mut x1) = (0.0_f64, 1.0_f64);
        let (mut p00, mut p01, mut p11) = (4.0_f64, 0.0_f64, 1.0_f64);

        let mut rng = rand_pcg::Pcg64Mcg::seed_from_u64(7);
        let mut truth = Vector2::new(0.3, 0.9);
        for _ in 0..200 {
            truth = ConstantVelocity.propagate(&truth, dt);
            let z = truth[0] + r.sqrt() * rng.sample::<f64, _>(StandardNormal);

            ekf.predict(&ConstantVelocity, dt, &q);
            let nis = ekf.update(&PositionFix, &Vector1::new(z), &nalgebra::Matrix1::new(r)).unwrap();

            // predict
            x0 += dt * x1;
            let n00 = p00 + 2.0 * dt * p01 + dt * dt * p11 + q[(0, 0)];
            let n01 = p01 + dt * p11 + q[(0, 1)];
            let n11 = p11 + q[(1, 1)];
            // update
            let s = n00 + r;
            let (k0, k1) = (n00 / s, n01 / s);
            let innov = z - x0;
            x0 += k0 * innov;
            x1 += k1 * innov;
            p00 = (1.0 - k0) * n00;
            p01 = (1.0 - k0) * n01;
            p11 = n11 - k1 * n01;

            assert_relative_eq!(nis, innov * innov / s, max_relative = 1e-9);
            assert_relative_eq!(ekf.x[0], x0, max_relative = 1e-9, epsilon = 1e-12);
            assert_relative_eq!(ekf.x[1], x1, max_relative = 1e-9, epsilon = 1e-12);
            assert_relative_eq!(ekf.p[(0, 0)], p00, max_relative = 1e-9);
            assert_relative_eq!(ekf.p[(0, 1)], p01, max_relative = 1e-9, epsilon = 1e-12);
            assert_relative_eq!(ekf.p[(1, 1)], p11, max_relative = 1e-9);
        }
        // and the filter tracks the truth within a few standard deviations
        assert!((ekf.x[0] - truth[0]).abs() < 4.0 * ekf.p[(0, 0)].sqrt());
    }

    /// A scalar model with its unit row hidden: the filter multiplies by the whole row.
    struct Dense<T>(T);
    impl<const N: usize, T: crate::measure::ScalarModel<N>> crate::measure::ScalarModel<N> for Dense<T> {
        fn predict(&self, x: &SVector<f64, N>) -> f64 {
            self.0.predict(x)
        }
        fn jacobian(&self, x: &SVector<f64, N>) -> SMatrix<f64, 1, N> {
            self.0.jacobian(x)
        }
        fn is_angle(&self) -> bool {
            self.0.is_angle()
        }
        fn variance(&self, x: &SVector<f64, N>) -> f64 {
            self.0.variance(x)
        }
    }

    /// Picking the state components a unit row selects gives the bits of the whole
    /// products (a range row beside them stays a product), over a hundred random states
    /// and covariances.
    #[test]
    fn unit_rows_give_the_bits_of_the_dense_products() {
        use crate::measure::{Range2d, ScalarModel, StateComponent};
        let mut rng = rand_pcg::Pcg64Mcg::seed_from_u64(3);
        let range = Range2d { beacon: Vector2::new(50.0, 100.0), var: 12.0 };
        let parts = [StateComponent::angle(2, 0.01), StateComponent::value(4, 0.005), StateComponent::value(5, 0.005)];
        for _ in 0..100 {
            let x = SVector::<f64, 6>::from_fn(|_, _| 10.0 * rng.sample::<f64, _>(StandardNormal));
            let l =
                SMatrix::<f64, 6, 6>::from_fn(|i, j| if j <= i { rng.sample::<f64, _>(StandardNormal) } else { 0.0 });
            let p = l * l.transpose() + SMatrix::<f64, 6, 6>::identity() * 0.1;
            let z = SVector::<f64, 4>::from_fn(|i, _| {
                let m: &dyn ScalarModel<6> = if i == 0 { &range } else { &parts[i - 1] };
                m.predict(&x) + rng.sample::<f64, _>(StandardNormal)
            });
            let picked: [&dyn ScalarModel<6>; 4] = [&range, &parts[0], &parts[1], &parts[2]];
            let dense = [Dense(parts[0]), Dense(parts[1]), Dense(parts[2])];
            let multiplied: [&dyn ScalarModel<6>; 4] = [&range, &dense[0], &dense[1], &dense[2]];
            let r = picked.covariance(&x);
            let (mut a, mut b) = (Ekf::new(x, p), Ekf::new(x, p));
            let na = a.update(&picked, &z, &r).unwrap();
            let nb = b.update(&multiplied, &z, &r).unwrap();
            assert_eq!(na.to_bits(), nb.to_bits());
            assert!(a.x.iter().zip(b.x.iter()).all(|(u, v)| u.to_bits() == v.to_bits()));
            assert!(a.p.iter().zip(b.p.iter()).all(|(u, v)| u.to_bits() == v.to_bits()));
        }
    }

    /// Heading-like measurement near +-pi: the innovation must be wrapped.
    struct AngleFix;
    impl MeasurementModel<2, 1> for AngleFix {
        fn predict(&self, x: &Vector2<f64>) -> Vector1<f64> {
            Vector1::new(x[0])
        }
        fn jacobian(&self, _x: &Vector2<f64>) -> Matrix1x2<f64> {
            Matrix1x2::new(1.0, 0.0)
        }
        fn covariance(&self, _x: &Vector2<f64>) -> nalgebra::Matrix1<f64> {
            nalgebra::Matrix1::new(0.1)
        }
        fn is_angle(&self, _i: usize) -> bool {
            true
        }
    }

    #[test]
    fn angle_innovations_are_wrapped() {
        let pi = std::f64::consts::PI;
        let mut ekf = Ekf::new(Vector2::new(pi - 0.01, 0.0), Matrix2::identity() * 0.1);
        let z = Vector1::new(-pi + 0.01); // 0.02 rad further on, across the cut
        let nis = ekf.update(&AngleFix, &z, &nalgebra::Matrix1::new(0.1)).unwrap();
        assert_relative_eq!(nis, 0.02 * 0.02 / 0.2, max_relative = 1e-6);
        assert_relative_eq!(ekf.x[0], pi, epsilon = 1e-9);
    }

    #[test]
    fn singular_innovation_is_an_error_and_leaves_state() {
        let mut ekf = Ekf::new(Vector2::new(1.0, 2.0), Matrix2::zeros());
        let before = ekf.clone();
        let err = ekf.update(&PositionFix, &Vector1::new(1.0), &nalgebra::Matrix1::new(0.0));
        assert_eq!(err, Err(FilterError::InnovationNotPositiveDefinite));
        assert_eq!(ekf, before);
        let err = ekf.update(&PositionFix, &Vector1::new(f64::NAN), &nalgebra::Matrix1::new(1.0));
        assert_eq!(err, Err(FilterError::NonFinite));
        assert_eq!(ekf, before);
    }

    #[test]
    fn gated_update_rejects_above_the_threshold_and_leaves_state() {
        let mut ekf = Ekf::new(Vector2::new(0.0, 0.0), Matrix2::identity());
        let r = nalgebra::Matrix1::new(1.0);
        let before = ekf.clone();
        // innovation 3, S = 1 + 1: NIS 4.5
        let rejected = ekf.update_gated(&PositionFix, &Vector1::new(3.0), &r, 4.4).unwrap();
        assert!(matches!(rejected, Gated::Rejected(..)));
        assert_relative_eq!(rejected.nis(), 4.5, epsilon = 1e-12);
        assert_relative_eq!(rejected.det_s(), 2.0, epsilon = 1e-12);
        assert_eq!(ekf, before);
        let accepted = ekf.update_gated(&PositionFix, &Vector1::new(3.0), &r, 4.6).unwrap();
        assert!(matches!(accepted, Gated::Accepted(..)));
        assert_relative_eq!(accepted.nis(), 4.5, epsilon = 1e-12);
        assert_relative_eq!(ekf.x[0], 1.5, epsilon = 1e-12);
    }
}
