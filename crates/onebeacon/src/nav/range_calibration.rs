//! Calibration states a range navigator may append to its pose, so that a range reads
//! (1 + k) r + b: a range offset b (m), its drift b' (m/s) and a range scale k.
//!
//! What they stand for at sea: a clock offset dt between the beacon's clock and the
//! vehicle's turns a one-way travel time into a range offset c dt (1 ms: 1.5 m at 1500
//! m/s); a relative drift of f ppm makes the offset grow by c f 1e-6 m/s (1 ppm: 1.5
//! mm/s, 5.4 m an hour), the drift state; a sound speed c_eff where the vehicle converts
//! with c reads every range c_eff / c too long, the scale k = c_eff / c - 1.

use crate::filter::ProcessModel;
use crate::measure::ScalarModel;
use nalgebra::{SMatrix, SVector};

/// Which calibration states a navigator estimates, each with its prior.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct RangeCalibration {
    /// The range offset b (a clock offset, a latency).
    pub offset: Option<OffsetPrior>,
    /// The range scale k, its prior standard deviation (dimensionless).
    pub scale_sigma: Option<f64>,
}

/// The range offset's prior and motion.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct OffsetPrior {
    /// Initial offset and its standard deviation, m.
    pub initial_m: f64,
    pub sigma_m: f64,
    /// A random walk of the offset, m / sqrt(s) (a clock's phase noise).
    pub walk_m_per_sqrt_s: f64,
    /// The standard deviation of a constant drift of the offset, m/s, when the drift
    /// is a state (a clock's frequency error); no drift state when None.
    pub drift_sigma_m_s: Option<f64>,
}

/// Where the calibration states sit after a pose of `base` components.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct Layout {
    pub offset: Option<usize>,
    pub drift: Option<usize>,
    pub scale: Option<usize>,
}

impl RangeCalibration {
    /// How many states it appends: 0 to 3.
    pub const fn states(&self) -> usize {
        let offset = match self.offset {
            Some(OffsetPrior { drift_sigma_m_s: Some(_), .. }) => 2,
            Some(_) => 1,
            None => 0,
        };
        offset + if self.scale_sigma.is_some() { 1 } else { 0 }
    }

    /// The calibration states' motion behind a pose of `B` components, over no pose
    /// model yet ([`Calibrated::over`] puts one under it).
    pub(crate) fn motion<const B: usize>(&self) -> Calibrated<(), B> {
        Calibrated {
            inner: (),
            layout: self.layout(B),
            offset_walk_m_per_sqrt_s: self.offset.map_or(0.0, |o| o.walk_m_per_sqrt_s),
        }
    }

    pub(crate) fn layout(&self, base: usize) -> Layout {
        let offset = self.offset.map(|_| base);
        let drift = self.offset.and_then(|o| o.drift_sigma_m_s).map(|_| base + 1);
        let scale = self.scale_sigma.map(|_| base + self.states() - 1);
        Layout { offset, drift, scale }
    }

    /// The full state's mean and covariance: the pose's (`x0`, `p0`), then each
    /// calibration state at its prior, uncorrelated.
    ///
    /// # Panics
    /// When `N` is not `B` + [`Self::states`].
    pub(crate) fn initial<const B: usize, const N: usize>(
        &self,
        x0: &SVector<f64, B>,
        p0: &SMatrix<f64, B, B>,
    ) -> (SVector<f64, N>, SMatrix<f64, N, N>) {
        assert_eq!(N, B + self.states(), "state dimension against the calibration states");
        let (mut x, mut p) = (SVector::<f64, N>::zeros(), SMatrix::<f64, N, N>::zeros());
        x.fixed_rows_mut::<B>(0).copy_from(x0);
        p.fixed_view_mut::<B, B>(0, 0).copy_from(p0);
        for (i, (value, sigma)) in self.prior().into_iter().enumerate() {
            (x[B + i], p[(B + i, B + i)]) = (value, sigma * sigma);
        }
        (x, p)
    }

    /// The appended states' initial values and standard deviations, in layout order.
    fn prior(&self) -> Vec<(f64, f64)> {
        let mut prior = Vec::new();
        if let Some(o) = self.offset {
            prior.push((o.initial_m, o.sigma_m));
            prior.extend(o.drift_sigma_m_s.map(|s| (0.0, s)));
        }
        prior.extend(self.scale_sigma.map(|s| (0.0, s)));
        prior
    }
}

/// A process model of the pose's `B` components (`inner`) with the calibration states
/// behind them: the offset integrates its drift (b' constant) and walks; the scale is
/// constant.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Calibrated<P, const B: usize> {
    pub inner: P,
    pub layout: Layout,
    pub offset_walk_m_per_sqrt_s: f64,
}

impl<P: ProcessModel<B>, const B: usize, const N: usize> ProcessModel<N> for Calibrated<P, B> {
    fn propagate(&self, x: &SVector<f64, N>, dt: f64) -> SVector<f64, N> {
        let mut n = *x;
        n.fixed_rows_mut::<B>(0).copy_from(&self.inner.propagate(&x.fixed_rows::<B>(0).into_owned(), dt));
        if let (Some(o), Some(d)) = (self.layout.offset, self.layout.drift) {
            n[o] += x[d] * dt; // b(t + dt) = b(t) + b' dt
        }
        n
    }

    fn jacobian(&self, x: &SVector<f64, N>, dt: f64) -> SMatrix<f64, N, N> {
        self.embed(&self.inner.jacobian(&x.fixed_rows::<B>(0).into_owned(), dt), dt)
    }

    fn transition(&self, x: &SVector<f64, N>, dt: f64) -> (SVector<f64, N>, SMatrix<f64, N, N>) {
        let (pose, f) = self.inner.transition(&x.fixed_rows::<B>(0).into_owned(), dt);
        let mut n = *x;
        n.fixed_rows_mut::<B>(0).copy_from(&pose);
        if let (Some(o), Some(d)) = (self.layout.offset, self.layout.drift) {
            n[o] += x[d] * dt; // b(t + dt) = b(t) + b' dt
        }
        (n, self.embed(&f, dt))
    }

    /// The pose's own (sparse) F P F' + Q when there is no calibration state, so that
    /// a navigator without one computes exactly what its pose model does.
    fn propagate_covariance(
        &self,
        f: &SMatrix<f64, N, N>,
        p: &SMatrix<f64, N, N>,
        q: &SMatrix<f64, N, N>,
    ) -> SMatrix<f64, N, N> {
        if N != B {
            return f * p * f.transpose() + q;
        }
        let block = |m: &SMatrix<f64, N, N>| m.fixed_view::<B, B>(0, 0).into_owned();
        let mut out = SMatrix::<f64, N, N>::zeros();
        out.fixed_view_mut::<B, B>(0, 0).copy_from(&self.inner.propagate_covariance(&block(f), &block(p), &block(q)));
        out
    }

    fn noise_covariance(&self, x: &SVector<f64, N>, dt: f64) -> SMatrix<f64, N, N> {
        let mut q = SMatrix::<f64, N, N>::zeros();
        q.fixed_view_mut::<B, B>(0, 0).copy_from(&self.inner.noise_covariance(&x.fixed_rows::<B>(0).into_owned(), dt));
        if let Some(o) = self.layout.offset {
            q[(o, o)] = self.offset_walk_m_per_sqrt_s.powi(2) * dt;
        }
        q
    }

    fn is_angle(&self, i: usize) -> bool {
        i < B && self.inner.is_angle(i)
    }
}

impl<const B: usize> Calibrated<(), B> {
    /// The same calibration states behind the pose model `inner`.
    pub(crate) fn over<P>(self, inner: P) -> Calibrated<P, B> {
        Calibrated { inner, layout: self.layout, offset_walk_m_per_sqrt_s: self.offset_walk_m_per_sqrt_s }
    }
}

impl<P, const B: usize> Calibrated<P, B> {
    /// The pose's Jacobian `f` in the full state's, with the offset's dependence on its
    /// drift.
    fn embed<const N: usize>(&self, f: &SMatrix<f64, B, B>, dt: f64) -> SMatrix<f64, N, N> {
        let mut full = SMatrix::<f64, N, N>::identity();
        full.fixed_view_mut::<B, B>(0, 0).copy_from(f);
        if let (Some(o), Some(d)) = (self.layout.offset, self.layout.drift) {
            full[(o, d)] = dt;
        }
        full
    }
}

/// A range as the calibrated sensor reads it, (1 + k) r + b (r of the geometric model
/// `R`: [`crate::measure::Range3d`], sousa eq. 3.7, or `Range2d`, garin2024 eq. 19),
/// with the offset and scale read from the state where the layout puts them (zero where
/// it has none).
#[derive(Debug, Clone, Copy)]
pub(crate) struct CalibratedRange<R> {
    pub range: R,
    pub layout: Layout,
}

impl<R: ScalarModel<N>, const N: usize> ScalarModel<N> for CalibratedRange<R> {
    fn predict(&self, x: &SVector<f64, N>) -> f64 {
        let r = ScalarModel::<N>::predict(&self.range, x);
        let k = self.layout.scale.map_or(0.0, |i| x[i]);
        let b = self.layout.offset.map_or(0.0, |i| x[i]);
        (1.0 + k) * r + b
    }

    fn jacobian(&self, x: &SVector<f64, N>) -> SMatrix<f64, 1, N> {
        let k = self.layout.scale.map_or(0.0, |i| x[i]);
        let mut h = ScalarModel::<N>::jacobian(&self.range, x) * (1.0 + k);
        if let Some(i) = self.layout.offset {
            h[i] = 1.0;
        }
        if let Some(i) = self.layout.scale {
            h[i] = ScalarModel::<N>::predict(&self.range, x);
        }
        h
    }

    fn variance(&self, x: &SVector<f64, N>) -> f64 {
        ScalarModel::<N>::variance(&self.range, x)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::measure::Range3d;
    use crate::models::kinematic6dof::Kinematic6Dof;
    use approx::assert_abs_diff_eq;
    use nalgebra::Vector3;

    fn full() -> RangeCalibration {
        let offset =
            OffsetPrior { initial_m: 0.5, sigma_m: 2.0, walk_m_per_sqrt_s: 0.01, drift_sigma_m_s: Some(0.003) };
        RangeCalibration { offset: Some(offset), scale_sigma: Some(0.01) }
    }

    #[test]
    fn layouts_put_each_state_after_the_pose() {
        let l = full().layout(6);
        assert_eq!((l.offset, l.drift, l.scale), (Some(6), Some(7), Some(8)));
        let scale_only = RangeCalibration { offset: None, scale_sigma: Some(0.01) };
        assert_eq!(scale_only.layout(6), Layout { offset: None, drift: None, scale: Some(6) });
        let no_drift = RangeCalibration {
            offset: Some(OffsetPrior { drift_sigma_m_s: None, ..full().offset.unwrap() }),
            ..full()
        };
        assert_eq!(no_drift.layout(6), Layout { offset: Some(6), drift: None, scale: Some(7) });
        assert_eq!(full().prior(), vec![(0.5, 2.0), (0.0, 0.003), (0.0, 0.01)]);
        assert_eq!(RangeCalibration::default().states(), 0);
    }

    /// (1 + k) r + b on a 3-4-12 triangle, and the Jacobian against finite differences.
    #[test]
    fn the_calibrated_range_and_its_jacobian() {
        let range = Range3d { beacon: Vector3::new(50.0, 100.0, 0.5), sigma_m: 1.0, beacon_sigma_m: 0.0 };
        let m = CalibratedRange { range, layout: full().layout(6) };
        let x = SVector::<f64, 9>::from([53.0, 104.0, 12.5, 0.1, -0.1, 2.0, 2.8, 0.001, 0.07]);
        assert_abs_diff_eq!(ScalarModel::<9>::predict(&m, &x), 1.07 * 13.0 + 2.8, epsilon = 1e-12);
        let h = ScalarModel::<9>::jacobian(&m, &x);
        for j in 0..9 {
            let mut xp = x;
            xp[j] += 1e-6;
            let fd = (ScalarModel::<9>::predict(&m, &xp) - ScalarModel::<9>::predict(&m, &x)) / 1e-6;
            assert_abs_diff_eq!(h[j], fd, epsilon = 1e-6);
        }
        assert_eq!(h[7], 0.0, "the drift enters through the process, not the range");
    }

    /// The offset integrates its drift; the pose moves as the inner model alone; the
    /// walk is the offset's only process noise.
    #[test]
    fn the_offset_integrates_its_drift() {
        let nu = SVector::from([1.0, 0.0, 0.1, 0.0, 0.0, 0.05]);
        let inner = Kinematic6Dof { nu, velocity_sigma_m_s: 0.1, rate_sigma_rad_s: 0.01 };
        let model = Calibrated::<_, 6> { inner, layout: full().layout(6), offset_walk_m_per_sqrt_s: 0.01 };
        let x = SVector::<f64, 9>::from([1.0, 2.0, 3.0, 0.1, -0.1, 1.0, 2.0, 0.0015, 0.01]);
        let n = ProcessModel::<9>::propagate(&model, &x, 10.0);
        let pose = inner.propagate(&x.fixed_rows::<6>(0).into_owned(), 10.0);
        assert_eq!(n.fixed_rows::<6>(0).into_owned(), pose);
        assert_abs_diff_eq!(n[6], 2.0 + 0.015, epsilon = 1e-15);
        assert_eq!((n[7], n[8]), (0.0015, 0.01));
        let f = ProcessModel::<9>::jacobian(&model, &x, 10.0);
        assert_eq!(f[(6, 7)], 10.0);
        let q = ProcessModel::<9>::noise_covariance(&model, &x, 10.0);
        assert_abs_diff_eq!(q[(6, 6)], 1e-4 * 10.0, epsilon = 1e-18);
        assert_eq!((q[(7, 7)], q[(8, 8)]), (0.0, 0.0));
    }
}
