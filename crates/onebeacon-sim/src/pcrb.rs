//! Posterior Cramer-Rao bound of the moving-beacon, range-only case (Tichavsky et al.
//! 1998): J_{k+1} = (Q_k + F_k J_k^-1 F_k')^-1 + E[H' R^-1 H].
//! The vehicle's truth does not depend on the draws, so F_k and Q_k are evaluated on
//! it; the range information depends on where the guided ASV was, so it is averaged
//! over the Monte Carlo runs first, then one recursion is run (never an average of
//! per-run inverses). Q and R are read from the navigator's own models
//! ([`onebeacon::nav::SensorNoise`]), so the bound and the filter share every noise.

use crate::scenario::MovingBeacon;
use crate::scenario::moving_beacon::Vehicle;
use crate::vehicles::rov::body_velocity;
use crate::world::TruthPath;
use nalgebra::{Matrix6, SVector};
use onebeacon::filter::ProcessModel;
use onebeacon::measure::ScalarModel;
use onebeacon::models::kinematic6dof::Cov;
use std::collections::BTreeMap;

/// One step of the recursion from the bound `c` = J^-1: the bound after a transition
/// with Jacobian `f` and process noise `q`, and measurements of information `info`.
fn step(c: &Cov, f: &Cov, q: &Cov, info: &Cov) -> Cov {
    let predicted = f * c * f.transpose() + q;
    let j = predicted.try_inverse().unwrap_or_else(Cov::zeros) + info;
    j.try_inverse().unwrap_or(predicted)
}

/// Root of the bound on the mean squared horizontal position error of vehicle `v`
/// (path and depth set: [`MovingBeacon::vehicles`]) over the mission, given the sum
/// over `runs` runs of the range information it received, by step (steps without a
/// range are absent, so that the sum holds one entry per ping, not per step).
pub fn horizontal_rmse_bound(
    s: &MovingBeacon,
    v: &Vehicle,
    information_sum: &BTreeMap<usize, Matrix6<f64>>,
    runs: usize,
) -> f64 {
    let mut truth = TruthPath::new(s, v);
    let dt = s.mission.dt_s;
    let noise = s.sensor_noise();
    // depth and attitude every step: H' R^-1 H of the navigator's models
    let x0 = *truth.state();
    let sensor_info = noise.depth_attitude_models().iter().fold(Cov::zeros(), |acc, m| {
        let h = ScalarModel::<6>::jacobian(m, &x0);
        acc + h.transpose() * h / m.variance(&x0)
    });
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
    let steps = s.steps();
    for k in 1..=steps {
        let model = noise.process_model(body_velocity(v, v.path, (k - 1) as f64 * dt + dt / 2.0));
        let f = model.jacobian(truth.state(), dt);
        let q = model.noise_covariance(truth.state(), dt);
        truth.step();
        let info = information_sum.get(&k).map_or(sensor_info, |i| sensor_info + i / runs as f64);
        c = step(&c, &f, &q, &info);
        sum += c[(0, 0)] + c[(1, 1)];
    }
    (sum / (steps + 1) as f64).sqrt()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scenario::moving_beacon::PathKind;
    use crate::scenario::{MovingBeaconCell, Scenario, builtin, parse};
    use approx::assert_relative_eq;

    /// A stationary vehicle without process noise: the bound is the inverse of the
    /// summed information, J_k = J0 + k S + sum of the range information up to k, with S
    /// the depth and attitude information 1/sigma^2 on their diagonal (closed form,
    /// written out here from the scenario's sigmas).
    #[test]
    fn static_vehicle_without_process_noise_sums_the_information() {
        let Scenario::MovingBeacon(mut s) = parse(builtin("sousa").unwrap().toml, "sousa").unwrap() else {
            unreachable!()
        };
        s.mission.duration_s = 3.0;
        s.mission.dt_s = 0.5;
        s.sensors.velocity_noise_m_s = 0.0;
        s.sensors.rate_noise_rad_s = 0.0;
        let cell = MovingBeaconCell { path: PathKind::Stationary, ..s.base_cell() };
        let steps = s.steps();
        assert_eq!(steps, 6);
        // range information at steps 2 and 5 from two beacons, summed over 4 runs
        let h = |b: [f64; 3]| {
            let v = SVector::<f64, 6>::from([-b[0], -b[1], 5.0 - b[2], 0.0, 0.0, 0.0]).normalize();
            v * v.transpose()
        };
        let info = BTreeMap::from([(2, h([30.0, 0.0, 0.0]) * 4.0 * 2.0), (5, h([0.0, 40.0, 0.0]) * 4.0 * 3.0)]);
        let bound = horizontal_rmse_bound(&s, &s.vehicles(&cell)[0], &info, 4);

        let i = &s.initial;
        let att = i.attitude_sigma_deg.to_radians().powi(-2);
        let mut j = Cov::from_diagonal(&SVector::from([
            i.position_sigma_m.powi(-2),
            i.position_sigma_m.powi(-2),
            i.depth_sigma_m.powi(-2),
            att,
            att,
            att,
        ]));
        let n = &s.sensors;
        let satt = n.attitude_noise_deg.to_radians().powi(-2);
        let sensor = Cov::from_diagonal(&SVector::from([0.0, 0.0, n.depth_noise_m.powi(-2), satt, satt, satt]));
        let mut sum = 0.0;
        for k in 0..=steps {
            if k > 0 {
                j += sensor + info.get(&k).copied().unwrap_or_else(Matrix6::zeros) / 4.0;
            }
            let c = j.try_inverse().unwrap();
            sum += c[(0, 0)] + c[(1, 1)];
        }
        assert_relative_eq!(bound, (sum / (steps + 1) as f64).sqrt(), max_relative = 1e-9);
    }
}
