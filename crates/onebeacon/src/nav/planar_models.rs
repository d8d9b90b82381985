//! The planar navigator's models ([`super::planar`]): its odometry step, the drift of
//! its extended states (the current carrying the position, the heading offset decaying)
//! and the heading fix that reads the heading plus its offset.

use super::planar_config::PlanarNoise;
use crate::filter::ProcessModel;
use crate::geo::wrap_angle;
use crate::measure::ScalarModel;
use nalgebra::{SMatrix, SVector, Vector3};

type State<const N: usize> = SVector<f64, N>;
type Cov<const N: usize> = SMatrix<f64, N, N>;

/// Index of each state component.
pub mod idx {
    pub const N: usize = 0;
    pub const E: usize = 1;
    pub const PSI: usize = 2;
    pub const BIAS: usize = 3;
    pub const RANGE_SCALE: usize = 4;
    pub const DISTANCE_SCALE: usize = 5;
    pub const TURN_SCALE: usize = 6;
    pub const HEADING_OFFSET: usize = 7;
    pub const CURRENT_N: usize = 8;
    pub const CURRENT_E: usize = 9;
}

/// Over `dt`: the current carries the position, the heading offset decays toward zero
/// (exp(-dt / time)); linear.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Drift {
    pub dt: f64,
    pub decay: f64,
}

impl<const N: usize> ProcessModel<N> for Drift {
    fn propagate(&self, x: &State<N>, _dt: f64) -> State<N> {
        let mut n = *x;
        n[idx::N] += x[idx::CURRENT_N] * self.dt;
        n[idx::E] += x[idx::CURRENT_E] * self.dt;
        n[idx::HEADING_OFFSET] *= self.decay;
        n
    }

    fn jacobian(&self, _x: &State<N>, _dt: f64) -> Cov<N> {
        let mut f = Cov::<N>::identity();
        f[(idx::N, idx::CURRENT_N)] = self.dt;
        f[(idx::E, idx::CURRENT_E)] = self.dt;
        f[(idx::HEADING_OFFSET, idx::HEADING_OFFSET)] = self.decay;
        f
    }

    fn is_angle(&self, i: usize) -> bool {
        i == idx::PSI || i == idx::HEADING_OFFSET
    }
}

/// A heading fix that reads psi + h (the heading offset state), wrapped.
#[derive(Debug, Clone, Copy)]
pub(crate) struct OffsetHeading {
    pub var: f64,
}

impl<const N: usize> ScalarModel<N> for OffsetHeading {
    fn predict(&self, x: &State<N>) -> f64 {
        wrap_angle(x[idx::PSI] + x[idx::HEADING_OFFSET])
    }
    fn jacobian(&self, _x: &State<N>) -> SMatrix<f64, 1, N> {
        SMatrix::from_fn(|_, j| if j == idx::PSI || j == idx::HEADING_OFFSET { 1.0 } else { 0.0 })
    }
    fn is_angle(&self) -> bool {
        true
    }
    fn variance(&self, _x: &State<N>) -> f64 {
        self.var
    }
}

/// An odometry step with measured body-frame increments, forward `d` and starboard
/// `lat` (0 for distance-only odometry), and heading change `dpsi`, corrected by the
/// scale states: the increment (1 + k_d) (d, lat) rotated by the mid-increment heading,
/// then the heading change (1 + k_t) dpsi (second-order odometry model, composed on
/// SE(2)), with errors `sigma_d` (forward), `sigma_lat` (starboard) and the configured
/// heading noise.
#[derive(Debug, Clone, Copy)]
pub(crate) struct OdometryStep {
    pub d: f64,
    pub lat: f64,
    pub dpsi: f64,
    pub sigma_d: f64,
    pub sigma_lat: f64,
    pub noise: PlanarNoise,
}

impl OdometryStep {
    /// The corrected increments (forward, starboard, heading change) and the sine and
    /// cosine of the mid-increment heading at `x`.
    fn corrected<const N: usize>(&self, x: &State<N>) -> (f64, f64, f64, f64, f64) {
        let (gain_d, gain_t) = (1.0 + x[idx::DISTANCE_SCALE], 1.0 + x[idx::TURN_SCALE]);
        let (dc, lc, dpsic) = (gain_d * self.d, gain_d * self.lat, gain_t * self.dpsi);
        let (s, c) = (x[idx::PSI] + dpsic / 2.0).sin_cos();
        (dc, lc, dpsic, s, c)
    }

    /// Input Jacobian G (columns d, lat and dpsi) at `x`.
    fn input_jacobian<const N: usize>(&self, x: &State<N>) -> SMatrix<f64, N, 3> {
        let (gain_d, gain_t) = (1.0 + x[idx::DISTANCE_SCALE], 1.0 + x[idx::TURN_SCALE]);
        let (dc, lc, _, s, c) = self.corrected(x);
        let mut g = SMatrix::<f64, N, 3>::zeros();
        g[(idx::N, 0)] = gain_d * c;
        g[(idx::E, 0)] = gain_d * s;
        g[(idx::N, 1)] = -gain_d * s;
        g[(idx::E, 1)] = gain_d * c;
        g[(idx::N, 2)] = (-dc * s - lc * c) * gain_t / 2.0;
        g[(idx::E, 2)] = (dc * c - lc * s) * gain_t / 2.0;
        g[(idx::PSI, 2)] = gain_t;
        g
    }
}

impl<const N: usize> ProcessModel<N> for OdometryStep {
    fn propagate(&self, x: &State<N>, _dt: f64) -> State<N> {
        let (dc, lc, dpsic, s, c) = self.corrected(x);
        let mut n = *x;
        // forward along the heading, starboard to its right (NED)
        n[idx::N] += dc * c - lc * s;
        n[idx::E] += dc * s + lc * c;
        n[idx::PSI] = wrap_angle(x[idx::PSI] + dpsic);
        n
    }

    fn jacobian(&self, x: &State<N>, _dt: f64) -> Cov<N> {
        let (d, lat, dpsi) = (self.d, self.lat, self.dpsi);
        let (dc, lc, _, s, c) = self.corrected(x);
        let mut f = Cov::<N>::identity();
        f[(idx::N, idx::PSI)] = -dc * s - lc * c;
        f[(idx::E, idx::PSI)] = dc * c - lc * s;
        f[(idx::N, idx::DISTANCE_SCALE)] = d * c - lat * s;
        f[(idx::E, idx::DISTANCE_SCALE)] = d * s + lat * c;
        f[(idx::N, idx::TURN_SCALE)] = (-dc * s - lc * c) * dpsi / 2.0;
        f[(idx::E, idx::TURN_SCALE)] = (dc * c - lc * s) * dpsi / 2.0;
        f[(idx::PSI, idx::TURN_SCALE)] = dpsi;
        f
    }

    /// G Q_u G' with the forward and starboard errors and the heading-change error (its
    /// fraction plus the random walk per metre travelled).
    fn noise_covariance(&self, x: &State<N>, _dt: f64) -> Cov<N> {
        let n = self.noise;
        let g = self.input_jacobian(x);
        let travelled = self.d.hypot(self.lat);
        let var_dpsi =
            (n.heading_change_sigma_frac * self.dpsi).powi(2) + n.heading_walk_rad_per_sqrt_m.powi(2) * travelled;
        let q_u = SMatrix::<f64, 3, 3>::from_diagonal(&Vector3::new(
            self.sigma_d * self.sigma_d,
            self.sigma_lat * self.sigma_lat,
            var_dpsi,
        ));
        g * q_u * g.transpose()
    }

    fn is_angle(&self, i: usize) -> bool {
        i == idx::PSI
    }

    fn propagate_covariance(&self, f: &Cov<N>, p: &Cov<N>, q: &Cov<N>) -> Cov<N> {
        let p = f * p * f.transpose() + q;
        (p + p.transpose()) * 0.5
    }
}
