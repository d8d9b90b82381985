//! Posterior Cramer-Rao bound of the moving-beacon, range-only case (Tichavsky et al.
//! 1998; ../shared/acoustics.md): J_{k+1} = (Q_k + F_k J_k^-1 F_k')^-1 + E[H' R^-1 H].
//! The vehicle's truth does not depend on the draws, so F_k and Q_k are evaluated on
//! it; the range information depends on where the guided ASV was, so it is averaged
//! over the Monte Carlo runs first, then one recursion is run (never an average of
//! per-run inverses).

use crate::run::truth_trajectory;
use crate::scenario::{MovingBeacon, MovingBeaconCell};
use crate::vehicles::rov::body_velocity;
use nalgebra::{Matrix6, SVector};
use onebeacon::filter::ProcessModel;
use onebeacon::models::kinematic6dof::{Cov, Kinematic6Dof, idx};

/// Root of the bound on the mean squared horizontal position error over the mission,
/// given the sum over `runs` runs of the range information received at each step.
pub fn horizontal_rmse_bound(
    s: &MovingBeacon,
    cell: &MovingBeaconCell,
    information_sum: &[Matrix6<f64>],
    runs: usize,
) -> f64 {
    let truth = truth_trajectory(s, cell);
    let dt = s.mission.dt_s;
    let n = &s.sensors;
    let (v2, w2) = (n.velocity_noise_m_s.powi(2), n.rate_noise_rad_s.powi(2));
    let q_nu = Cov::from_diagonal(&SVector::from([v2, v2, v2, w2, w2, w2]));
    let att = n.attitude_noise_deg.to_radians().powi(2);
    let mut sensor_info = Cov::zeros(); // depth and attitude every step
    sensor_info[(idx::D, idx::D)] = 1.0 / n.depth_noise_m.powi(2);
    for a in [idx::ROLL, idx::PITCH, idx::YAW] {
        sensor_info[(a, a)] = 1.0 / att;
    }
    let i = &s.initial;
    let a0 = i.attitude_sigma_deg.to_radians().powi(2);
    let p0 = Cov::from_diagonal(&SVector::from([
        i.position_sigma_m.powi(2),
        i.position_sigma_m.powi(2),
        i.depth_sigma_m.powi(2),
        a0,
        a0,
        a0,
    ]));
    let mut c = p0; // the bound itself, J^-1
    let mut sum = c[(0, 0)] + c[(1, 1)];
    for k in 1..truth.len() {
        let model = Kinematic6Dof::new(body_velocity(&s.vehicle, cell.path, (k - 1) as f64 * dt + dt / 2.0));
        let f = model.jacobian(&truth[k - 1], dt);
        let g = model.input_jacobian(&truth[k - 1], dt);
        let predicted = f * c * f.transpose() + g * q_nu * g.transpose();
        let mut j = predicted.try_inverse().unwrap_or_else(Cov::zeros) + sensor_info;
        if let Some(info) = information_sum.get(k) {
            j += info / runs as f64;
        }
        c = j.try_inverse().unwrap_or(predicted);
        sum += c[(0, 0)] + c[(1, 1)];
    }
    (sum / truth.len() as f64).sqrt()
}
