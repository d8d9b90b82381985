//! Calibration states a range navigator may append to its pose, so that a range reads
//! (1 + k) r + b: a range offset b (m), its drift b' (m/s) and a range scale k; and the
//! water's current (c_N, c_E), m/s, which carries the pose over ground.
//!
//! What they stand for at sea: a clock offset dt between the beacon's clock and the
//! vehicle's turns a one-way travel time into a range offset c dt (1 ms: 1.5 m at 1500
//! m/s); a relative drift of f ppm makes the offset grow by c f 1e-6 m/s (1 ppm: 1.5
//! mm/s, 5.4 m an hour), the drift state; a sound speed c_eff where the vehicle converts
//! with c reads every range c_eff / c too long, the scale k = c_eff / c - 1. A vehicle
//! that measures its motion through the water (an accelerometer, a propeller's RPM, a
//! DVL on water track) is carried over ground by the current, which its ranges see and
//! its motion sensors do not: garin2024 names the current its main limitation
//! (conclusions: "transverse speed due to current is not estimated").

use crate::filter::ProcessModel;
use crate::measure::{RadialSpeed2d, ScalarModel};
use nalgebra::{SMatrix, SVector, Vector2};

/// Which calibration states a navigator estimates, each with its prior.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct RangeCalibration {
    /// The range offset b (a clock offset, a latency).
    pub offset: Option<OffsetPrior>,
    /// The range scale k, its prior standard deviation (dimensionless).
    pub scale_sigma: Option<f64>,
    /// The water's current, two states (north, east), m/s.
    pub current: Option<CurrentPrior>,
}

/// The current's prior and motion: zero mean, `sigma_m_s` on each axis, a random walk
/// of `walk_m_s_per_sqrt_s` on each.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CurrentPrior {
    pub sigma_m_s: f64,
    pub walk_m_s_per_sqrt_s: f64,
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
    /// The current's north component; its east component follows.
    pub current: Option<usize>,
}

impl RangeCalibration {
    /// How many states it appends: 0 to 5.
    pub const fn states(&self) -> usize {
        self.range_states() + if self.current.is_some() { 2 } else { 0 }
    }

    /// The range's own states: the offset, its drift, the scale (0 to 3).
    const fn range_states(&self) -> usize {
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
            current_walk_m_s_per_sqrt_s: self.current.map_or(0.0, |c| c.walk_m_s_per_sqrt_s),
        }
    }

    pub(crate) fn layout(&self, base: usize) -> Layout {
        let offset = self.offset.map(|_| base);
        let drift = self.offset.and_then(|o| o.drift_sigma_m_s).map(|_| base + 1);
        let scale = self.scale_sigma.map(|_| base + self.range_states() - 1);
        let current = self.current.map(|_| base + self.range_states());
        Layout { offset, drift, scale, current }
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
        if let Some(c) = self.current {
            prior.extend([(0.0, c.sigma_m_s); 2]);
        }
        prior
    }
}

/// A process model of the pose's `B` components (`inner`, north and east its first two)
/// with the calibration states behind them: the offset integrates its drift (b'
/// constant) and walks; the scale is constant; the current walks and carries the pose.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Calibrated<P, const B: usize> {
    pub inner: P,
    pub layout: Layout,
    pub offset_walk_m_per_sqrt_s: f64,
    pub current_walk_m_s_per_sqrt_s: f64,
}

impl<P: ProcessModel<B>, const B: usize, const N: usize> ProcessModel<N> for Calibrated<P, B> {
    fn propagate(&self, x: &SVector<f64, N>, dt: f64) -> SVector<f64, N> {
        let mut n = *x;
        n.fixed_rows_mut::<B>(0).copy_from(&self.inner.propagate(&x.fixed_rows::<B>(0).into_owned(), dt));
        self.carry(x, &mut n, dt);
        n
    }

    fn jacobian(&self, x: &SVector<f64, N>, dt: f64) -> SMatrix<f64, N, N> {
        self.embed(&self.inner.jacobian(&x.fixed_rows::<B>(0).into_owned(), dt), dt)
    }

    fn transition(&self, x: &SVector<f64, N>, dt: f64) -> (SVector<f64, N>, SMatrix<f64, N, N>) {
        let (pose, f) = self.inner.transition(&x.fixed_rows::<B>(0).into_owned(), dt);
        let mut n = *x;
        n.fixed_rows_mut::<B>(0).copy_from(&pose);
        self.carry(x, &mut n, dt);
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
        self.walk(&mut q, dt);
        q
    }

    fn is_angle(&self, i: usize) -> bool {
        i < B && self.inner.is_angle(i)
    }
}

impl<const B: usize> Calibrated<(), B> {
    /// The same calibration states behind the pose model `inner`.
    pub(crate) fn over<P>(self, inner: P) -> Calibrated<P, B> {
        let Self { layout, offset_walk_m_per_sqrt_s, current_walk_m_s_per_sqrt_s, .. } = self;
        Calibrated { inner, layout, offset_walk_m_per_sqrt_s, current_walk_m_s_per_sqrt_s }
    }
}

impl<P, const B: usize> Calibrated<P, B> {
    /// What the calibration states add to the propagated state `n` of `x` over `dt`.
    fn carry<const N: usize>(&self, x: &SVector<f64, N>, n: &mut SVector<f64, N>, dt: f64) {
        if let (Some(o), Some(d)) = (self.layout.offset, self.layout.drift) {
            n[o] += x[d] * dt; // b(t + dt) = b(t) + b' dt
        }
        if let Some(c) = self.layout.current {
            n[0] += x[c] * dt; // p(t + dt) = p(t) + (pose's motion through the water) + c dt
            n[1] += x[c + 1] * dt;
        }
    }

    /// Writes the random walks of the offset and the current over `dt` into `q`.
    pub(crate) fn walk<const N: usize>(&self, q: &mut SMatrix<f64, N, N>, dt: f64) {
        if let Some(o) = self.layout.offset {
            q[(o, o)] = self.offset_walk_m_per_sqrt_s.powi(2) * dt;
        }
        if let Some(c) = self.layout.current {
            let var = self.current_walk_m_s_per_sqrt_s.powi(2) * dt;
            (q[(c, c)], q[(c + 1, c + 1)]) = (var, var);
        }
    }

    /// The pose's Jacobian `f` in the full state's, with the offset's dependence on its
    /// drift and the position's on the current.
    fn embed<const N: usize>(&self, f: &SMatrix<f64, B, B>, dt: f64) -> SMatrix<f64, N, N> {
        let mut full = SMatrix::<f64, N, N>::identity();
        full.fixed_view_mut::<B, B>(0, 0).copy_from(f);
        if let (Some(o), Some(d)) = (self.layout.offset, self.layout.drift) {
            full[(o, d)] = dt;
        }
        if let Some(c) = self.layout.current {
            (full[(0, c)], full[(1, c + 1)]) = (dt, dt);
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

/// A Doppler radial speed over ground (closing positive): the vehicle's through the
/// water (`doppler`, garin2024 eq. 20) plus the current's share toward the beacon, -u.c
/// with u the unit vector from the beacon to the vehicle, the current read from the state
/// where the layout puts it (none: still water).
#[derive(Debug, Clone, Copy)]
pub(crate) struct CarriedDoppler {
    pub doppler: RadialSpeed2d,
    pub current: Option<usize>,
}

impl CarriedDoppler {
    /// The horizontal offset d from the beacon, the unit vector u along it, the distance,
    /// and the current, when there is one and the vehicle is off the beacon.
    fn geometry<const N: usize>(&self, x: &SVector<f64, N>) -> Option<Geometry> {
        let i = self.current?;
        let d = Vector2::new(x[0], x[1]) - self.doppler.beacon;
        let r = d.norm();
        (r > 1e-9).then(|| Geometry { d, u: d / r, r, current: Vector2::new(x[i], x[i + 1]) })
    }
}

/// [`CarriedDoppler::geometry`]'s parts.
struct Geometry {
    d: Vector2<f64>,
    u: Vector2<f64>,
    r: f64,
    current: Vector2<f64>,
}

impl<const N: usize> ScalarModel<N> for CarriedDoppler {
    fn predict(&self, x: &SVector<f64, N>) -> f64 {
        let water = ScalarModel::<N>::predict(&self.doppler, x);
        self.geometry(x).map_or(water, |g| water - self.doppler.slant(g.d.x, g.d.y).0 * g.u.dot(&g.current))
    }

    fn jacobian(&self, x: &SVector<f64, N>) -> SMatrix<f64, 1, N> {
        let mut h = ScalarModel::<N>::jacobian(&self.doppler, x);
        if let (Some(Geometry { d, u, r, current: c }), Some(i)) = (self.geometry(x), self.current) {
            // the current's share -f u.c along the slant line of sight (f = 1 level with
            // the beacon): d(-u.c)/dp = -(c - u (u.c)) / r, d(-u.c)/dc = -u, and the
            // slant factor's gradient df
            let (f, df) = self.doppler.slant(d.x, d.y);
            let dp = -(c - u * u.dot(&c)) / r * f - df * u.dot(&c);
            (h[0], h[1]) = (h[0] + dp.x, h[1] + dp.y);
            (h[i], h[i + 1]) = (-f * u.x, -f * u.y);
        }
        h
    }

    fn variance(&self, x: &SVector<f64, N>) -> f64 {
        ScalarModel::<N>::variance(&self.doppler, x)
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
        RangeCalibration { offset: Some(offset), scale_sigma: Some(0.01), current: None }
    }

    #[test]
    fn layouts_put_each_state_after_the_pose() {
        let l = full().layout(6);
        assert_eq!((l.offset, l.drift, l.scale, l.current), (Some(6), Some(7), Some(8), None));
        let scale_only = RangeCalibration { offset: None, scale_sigma: Some(0.01), current: None };
        assert_eq!(scale_only.layout(6), Layout { offset: None, drift: None, scale: Some(6), current: None });
        let water = CurrentPrior { sigma_m_s: 0.2, walk_m_s_per_sqrt_s: 1e-3 };
        let all = RangeCalibration { current: Some(water), ..full() };
        assert_eq!(all.layout(6), Layout { current: Some(9), ..full().layout(6) });
        assert_eq!(all.states(), 5);
        let current_only = RangeCalibration { current: Some(water), ..Default::default() };
        assert_eq!(current_only.layout(6), Layout { offset: None, drift: None, scale: None, current: Some(6) });
        assert_eq!(current_only.prior(), vec![(0.0, 0.2), (0.0, 0.2)]);
        let no_drift = RangeCalibration {
            offset: Some(OffsetPrior { drift_sigma_m_s: None, ..full().offset.unwrap() }),
            ..full()
        };
        assert_eq!(no_drift.layout(6), Layout { offset: Some(6), drift: None, scale: Some(7), current: None });
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
        let model = Calibrated::<_, 6> {
            inner,
            layout: full().layout(6),
            offset_walk_m_per_sqrt_s: 0.01,
            current_walk_m_s_per_sqrt_s: 0.0,
        };
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

    /// A current carries the position by c dt on top of the pose's own motion, F has dt
    /// where the position meets the current, and the current walks: its Q is walk^2 dt
    /// on each axis.
    #[test]
    fn the_current_carries_the_pose() {
        let nu = SVector::from([1.0, 0.0, 0.1, 0.0, 0.0, 0.05]);
        let inner = Kinematic6Dof { nu, velocity_sigma_m_s: 0.1, rate_sigma_rad_s: 0.01 };
        let water = CurrentPrior { sigma_m_s: 0.2, walk_m_s_per_sqrt_s: 2e-3 };
        let calibration = RangeCalibration { current: Some(water), ..Default::default() };
        let model = calibration.motion::<6>().over(inner);
        let x = SVector::<f64, 8>::from([1.0, 2.0, 3.0, 0.1, -0.1, 1.0, 0.3, -0.2]);
        let n = ProcessModel::<8>::propagate(&model, &x, 10.0);
        let pose = inner.propagate(&x.fixed_rows::<6>(0).into_owned(), 10.0);
        assert_abs_diff_eq!(n[0], pose[0] + 3.0, epsilon = 1e-12);
        assert_abs_diff_eq!(n[1], pose[1] - 2.0, epsilon = 1e-12);
        assert_eq!(n.fixed_rows::<4>(2).into_owned(), pose.fixed_rows::<4>(2).into_owned());
        assert_eq!((n[6], n[7]), (0.3, -0.2));
        let f = ProcessModel::<8>::jacobian(&model, &x, 10.0);
        for j in 0..8 {
            let mut xp = x;
            xp[j] += 1e-6;
            let fd = (ProcessModel::<8>::propagate(&model, &xp, 10.0) - n) / 1e-6;
            for i in 0..8 {
                assert_abs_diff_eq!(f[(i, j)], fd[i], epsilon = 1e-5);
            }
        }
        let q = ProcessModel::<8>::noise_covariance(&model, &x, 10.0);
        assert_abs_diff_eq!(q[(6, 6)], 4e-6 * 10.0, epsilon = 1e-18);
        assert_abs_diff_eq!(q[(7, 7)], 4e-6 * 10.0, epsilon = 1e-18);
    }

    /// The Doppler speed over ground: a vehicle 10 m north of the beacon, still in a
    /// current of 0.5 m/s toward the south, closes at 0.5 m/s; toward the east, abeam,
    /// at 0. The Jacobian matches finite differences, and without a current the model is
    /// the water's.
    #[test]
    fn the_doppler_over_ground_has_the_currents_share() {
        let doppler = RadialSpeed2d { beacon: Vector2::new(0.0, 0.0), known_speed_m_s: None, dz_m: 0.0, var: 0.1 };
        let m = CarriedDoppler { doppler, current: Some(6) };
        let at = |c: [f64; 2]| SVector::<f64, 8>::from([10.0, 0.0, 0.0, 0.0, 0.0, 0.0, c[0], c[1]]);
        assert_abs_diff_eq!(ScalarModel::<8>::predict(&m, &at([-0.5, 0.0])), 0.5, epsilon = 1e-12);
        assert_abs_diff_eq!(ScalarModel::<8>::predict(&m, &at([0.0, 0.5])), 0.0, epsilon = 1e-12);
        let x = SVector::<f64, 8>::from([30.0, -40.0, 0.7, 1.2, 0.0, 0.0, 0.25, -0.15]);
        // the Jacobian against forward differences
        let differences = |m: &CarriedDoppler| {
            let h = ScalarModel::<8>::jacobian(m, &x);
            for j in 0..8 {
                let mut xp = x;
                xp[j] += 1e-6;
                let fd = (ScalarModel::<8>::predict(m, &xp) - ScalarModel::<8>::predict(m, &x)) / 1e-6;
                assert_abs_diff_eq!(h[j], fd, epsilon = 1e-6);
            }
        };
        differences(&m);
        let still = CarriedDoppler { doppler, current: None };
        assert_eq!(ScalarModel::<8>::predict(&still, &x), ScalarModel::<8>::predict(&doppler, &x));
        // 30 m below the beacon, 40 m off: the current's share is 4/5 of the level one
        let below = CarriedDoppler { doppler: RadialSpeed2d { dz_m: 30.0, ..doppler }, current: Some(6) };
        let at = SVector::<f64, 8>::from([40.0, 0.0, 0.0, 0.0, 0.0, 0.0, -0.5, 0.0]);
        assert_abs_diff_eq!(ScalarModel::<8>::predict(&below, &at), 0.4, epsilon = 1e-12);
        differences(&below);
    }
}
