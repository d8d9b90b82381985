//! Posterior Cramer-Rao bounds (Tichavsky et al. 1998): J_{k+1} = (Q_k + F_k J_k^-1
//! F_k')^-1 + E[H' R^-1 H], for the moving-beacon, range-only case and for bearings
//! from a moving USBL (passive_usbl).
//! The vehicle's truth does not depend on the draws, so F_k and Q_k are evaluated on
//! it; the range information depends on where the guided ASV was, so it is averaged
//! over the Monte Carlo runs first, then one recursion is run (never an average of
//! per-run inverses). Q and R are read from the navigator's own models
//! ([`onebeacon::nav::SensorNoise`]), so the bound and the filter share every noise.

use crate::scenario::moving_beacon::Vehicle;
use crate::scenario::{MovingBeacon, PassiveUsbl};
use crate::vehicles::rov::body_velocity;
use crate::world::{PassiveUsblWorld, TruthPath};
use nalgebra::{DMatrix, SMatrix, SVector};
use onebeacon::filter::ProcessModel;
use onebeacon::measure::{ScalarModel, StateComponent};
use onebeacon::models::hoff::{DIM, idx};
use onebeacon::models::kinematic6dof::Cov;
use std::collections::BTreeMap;

/// One step of the recursion from the bound `c` = J^-1: the bound after a transition
/// with Jacobian `f` and process noise `q`, and measurements of information `info`.
fn step<const N: usize>(
    c: &SMatrix<f64, N, N>,
    f: &SMatrix<f64, N, N>,
    q: &SMatrix<f64, N, N>,
    info: &SMatrix<f64, N, N>,
) -> SMatrix<f64, N, N> {
    let predicted = f * c * f.transpose() + q;
    let j = predicted.try_inverse().unwrap_or_else(SMatrix::zeros) + info;
    j.try_inverse().unwrap_or(predicted)
}

/// The mean over `runs` runs of summed information `sum` (the world's state size N).
fn mean_information<const N: usize>(sum: &DMatrix<f64>, runs: usize) -> SMatrix<f64, N, N> {
    SMatrix::<f64, N, N>::from_column_slice(sum.as_slice()) / runs as f64
}

/// Root of the bound on the mean squared horizontal position error of vehicle `v`
/// (path and depth set: [`MovingBeacon::vehicles`]) over the mission, given the sum
/// over `runs` runs of the range information it received, by step (steps without a
/// range are absent, so that the sum holds one entry per ping, not per step).
pub fn horizontal_rmse_bound(
    s: &MovingBeacon,
    v: &Vehicle,
    information_sum: &BTreeMap<usize, DMatrix<f64>>,
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
        let model = noise.process_model(body_velocity(&v.body_path(), (k - 1) as f64 * dt + dt / 2.0));
        let f = model.jacobian(truth.state(), dt);
        let q = model.noise_covariance(truth.state(), dt);
        truth.step();
        let info = information_sum.get(&k).map_or(sensor_info, |i| sensor_info + mean_information::<6>(i, runs));
        c = step(&c, &f, &q, &info);
        sum += c[(0, 0)] + c[(1, 1)];
    }
    (sum / (steps + 1) as f64).sqrt()
}

/// Root of the bound on the mean squared horizontal position error of AUV `v` of a
/// passive-USBL scenario over the mission, given the sum over `runs` runs of the
/// information of the bearings it was heard at (by step): the reports' information every
/// step, the process of eq. 4 (its Gaussian form, that of the first estimator) on the
/// AUV's circle (a `remus100` follows it by ILOS within decimetres; the bound is taken on
/// the path, the bearings' information at the truth), the start of the trackers' initial
/// uncertainty.
pub fn bearing_rmse_bound(
    s: &PassiveUsbl,
    v: usize,
    information_sum: &BTreeMap<usize, DMatrix<f64>>,
    runs: usize,
) -> f64 {
    type Cov8 = SMatrix<f64, DIM, DIM>;
    let noise = s.tracker_noise();
    let process = s.estimators[0].tracker_config(noise).process;
    let reports = [
        StateComponent::angle(idx::PSI, noise.heading_sigma_rad.powi(2)),
        StateComponent::value(idx::U, noise.speed_sigma_m_s.powi(2)),
        StateComponent::value(idx::Z, noise.depth_sigma_m.powi(2)),
    ];
    let truth = PassiveUsblWorld::truth_state(s, v);
    let x0 = truth(0.0);
    let report_info = reports.iter().fold(Cov8::zeros(), |acc, m| {
        let h = ScalarModel::<DIM>::jacobian(m, &x0);
        acc + h.transpose() * h / m.variance(&x0)
    });
    let mut c = Cov8::from_diagonal(&crate::factory::tracker_sigma(s).map(|x| x * x));
    let mut sum = c[(0, 0)] + c[(1, 1)];
    let (steps, dt) = (s.steps(), s.mission.message_period_s);
    for k in 1..=steps {
        let x = truth((k - 1) as f64 * dt);
        let f = ProcessModel::jacobian(&process, &x, dt);
        let q = ProcessModel::noise_covariance(&process, &x, dt);
        let info = information_sum.get(&k).map_or(report_info, |i| report_info + mean_information::<DIM>(i, runs));
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
    use nalgebra::Matrix6;

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
        let d = |m: Matrix6<f64>| DMatrix::from_column_slice(6, 6, m.as_slice());
        let info = BTreeMap::from([(2, d(h([30.0, 0.0, 0.0]) * 4.0 * 2.0)), (5, d(h([0.0, 40.0, 0.0]) * 4.0 * 3.0))]);
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
                j += sensor
                    + info.get(&k).map_or_else(Matrix6::zeros, |m| Matrix6::from_column_slice(m.as_slice())) / 4.0;
            }
            let c = j.try_inverse().unwrap();
            sum += c[(0, 0)] + c[(1, 1)];
        }
        assert_relative_eq!(bound, (sum / (steps + 1) as f64).sqrt(), max_relative = 1e-9);
    }
}
