//! Range-aided navigation of a 6-DOF underwater vehicle (sousa section 3.2): dead
//! reckoning on measured body velocities (eq. 3.1-3.2), attitude and depth updates
//! (eq. 3.3-3.6), and OWTT range updates to a beacon whose position travels with the
//! measurement (eq. 3.7-3.10).

use crate::filter::{Ekf, FilterError};
use crate::measure::{Range3d, ScalarModel, StateComponent};
use crate::models::kinematic6dof::{BodyVelocity, Cov, DIM, Kinematic6Dof, State, idx};
use nalgebra::{Matrix2, SMatrix, SVector, Vector1, Vector3, Vector4};

/// Noise of the vehicle's sensors as the filter models them (standard deviations).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SensorNoise {
    /// Body linear velocity (u, v, w), m/s.
    pub velocity_m_s: f64,
    /// Body angular rate (p, q, r), rad/s.
    pub rate_rad_s: f64,
    pub depth_m: f64,
    /// Roll, pitch, heading, rad.
    pub attitude_rad: f64,
}

/// A one-way travel-time range: the beacon's position when it transmitted (as the
/// beacon vehicle knew it, with the standard deviation of that knowledge per horizontal
/// axis), and the range c (t_rx - t_tx).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct OwttRange {
    pub t_tx_s: f64,
    pub t_rx_s: f64,
    pub beacon_ned_m: Vector3<f64>,
    pub beacon_sigma_m: f64,
    pub range_m: f64,
    /// Range noise standard deviation, m.
    pub sigma_m: f64,
}

/// The EKF of sousa section 3.2 over eta = [N, E, D, phi, theta, psi].
#[derive(Debug, Clone)]
pub struct Range6DofEkf {
    noise: SensorNoise,
    q_nu: Cov,
    ekf: Ekf<DIM>,
}

const DEPTH: StateComponent = StateComponent::value(idx::D);
const ROLL: StateComponent = StateComponent::angle(idx::ROLL);
const PITCH: StateComponent = StateComponent::angle(idx::PITCH);
const YAW: StateComponent = StateComponent::angle(idx::YAW);

impl Range6DofEkf {
    pub fn new(noise: SensorNoise, eta0: State, p0: Cov) -> Self {
        let (v2, w2) = (noise.velocity_m_s.powi(2), noise.rate_rad_s.powi(2));
        let q_nu = Cov::from_diagonal(&SVector::from([v2, v2, v2, w2, w2, w2]));
        Self { noise, q_nu, ekf: Ekf::new(eta0, p0) }
    }

    /// Dead reckoning over `dt` with the measured body velocities `nu`: P = F P F' +
    /// G Q G' with G = dt J (eq. 3.2).
    pub fn predict(&mut self, dt: f64, nu: &BodyVelocity) {
        let model = Kinematic6Dof::new(*nu);
        let g = model.input_jacobian(&self.ekf.x, dt);
        let q = g * self.q_nu * g.transpose();
        self.ekf.predict(&model, dt, &q);
    }

    /// Depth and attitude update (eq. 3.3-3.6); `z` = [D, phi, theta, psi].
    pub fn update_attitude_depth(&mut self, z: &Vector4<f64>) -> Result<f64, FilterError> {
        let models: [&dyn ScalarModel<DIM>; 4] = [&DEPTH, &ROLL, &PITCH, &YAW];
        let (d2, a2) = (self.noise.depth_m.powi(2), self.noise.attitude_rad.powi(2));
        let r = SMatrix::<f64, 4, 4>::from_diagonal(&Vector4::new(d2, a2, a2, a2));
        self.ekf.update(&models, z, &r)
    }

    /// Range update (eq. 3.7-3.10). The beacon's position error adds its projection on
    /// the horizontal line of sight to the range variance.
    pub fn update_range(&mut self, m: &OwttRange) -> Result<f64, FilterError> {
        let model = Range3d { beacon: m.beacon_ned_m };
        let h = ScalarModel::<DIM>::jacobian(&model, &self.ekf.x);
        let horizontal = h[0] * h[0] + h[1] * h[1];
        let r = m.sigma_m.powi(2) + m.beacon_sigma_m.powi(2) * horizontal;
        let models: [&dyn ScalarModel<DIM>; 1] = [&model];
        self.ekf.update(&models, &Vector1::new(m.range_m), &nalgebra::Matrix1::new(r))
    }

    pub fn state(&self) -> &State {
        &self.ekf.x
    }
    pub fn covariance(&self) -> &Cov {
        &self.ekf.p
    }
    /// NED position, m.
    pub fn position(&self) -> Vector3<f64> {
        self.ekf.x.fixed_rows::<3>(0).into_owned()
    }
    /// Covariance of the horizontal position.
    pub fn horizontal_covariance(&self) -> Matrix2<f64> {
        self.ekf.p.fixed_view::<2, 2>(0, 0).into_owned()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::filter::ProcessModel;

    fn noise() -> SensorNoise {
        SensorNoise { velocity_m_s: 0.05, rate_rad_s: 0.002, depth_m: 0.05, attitude_rad: 0.02 }
    }

    /// A stationary vehicle 20 m deep, ranges from a beacon circling it at 30 m with no
    /// noise: the horizontal position converges from a 5 m error to centimetres, while
    /// dead reckoning alone keeps the error.
    #[test]
    fn ranges_from_a_circling_beacon_fix_the_position() {
        let truth = State::from([0.0, 0.0, 20.0, 0.0, 0.0, 0.3]);
        let mut start = truth;
        start[idx::N] += 3.0;
        start[idx::E] -= 4.0;
        let p0 = Cov::from_diagonal(&SVector::from([25.0, 25.0, 0.01, 1e-3, 1e-3, 1e-3]));
        let mut f = Range6DofEkf::new(noise(), start, p0);
        let mut dr = f.clone();
        let still = BodyVelocity::zeros();
        for k in 0..600 {
            f.predict(0.1, &still);
            dr.predict(0.1, &still);
            let z = Vector4::new(20.0, 0.0, 0.0, 0.3);
            f.update_attitude_depth(&z).unwrap();
            dr.update_attitude_depth(&z).unwrap();
            if k % 50 == 0 {
                let a = k as f64 * 0.02;
                let beacon = Vector3::new(30.0 * a.cos(), 30.0 * a.sin(), 0.0);
                let range = (truth.fixed_rows::<3>(0) - beacon).norm();
                let m = OwttRange {
                    t_tx_s: 0.0,
                    t_rx_s: 0.0,
                    beacon_ned_m: beacon,
                    beacon_sigma_m: 0.0,
                    range_m: range,
                    sigma_m: 0.1,
                };
                f.update_range(&m).unwrap();
            }
        }
        let err = |e: &Range6DofEkf| (e.position() - truth.fixed_rows::<3>(0)).xy().norm();
        assert!(err(&f) < 0.05, "range-aided error {}", err(&f));
        assert!(err(&dr) > 4.9, "dead-reckoning error {}", err(&dr));
        // the covariance shrank accordingly
        assert!(f.horizontal_covariance().trace() < 0.05);
    }

    /// Prediction agrees with the model and inflates P by the mapped input noise.
    #[test]
    fn prediction_maps_input_noise() {
        let eta = State::from([1.0, 2.0, 3.0, 0.1, -0.1, 1.0]);
        let mut f = Range6DofEkf::new(noise(), eta, Cov::zeros());
        let nu = BodyVelocity::from([1.0, 0.0, 0.1, 0.0, 0.0, 0.05]);
        f.predict(0.5, &nu);
        let m = Kinematic6Dof::new(nu);
        assert!((f.state() - m.propagate(&eta, 0.5)).norm() < 1e-12);
        let g = m.input_jacobian(&eta, 0.5);
        let expected = g * f.q_nu * g.transpose();
        assert!((f.covariance() - expected).norm() < 1e-15);
    }
}
