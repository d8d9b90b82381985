//! The fixed-beacon world (garin2024): an AUV following a boustrophedon under the
//! feedback-linearising controller, a fixed beacon, communication frames every T_com.

use super::{Estimate, RunOutput, StepRecord};
use crate::metrics::ErrorAccumulator;
use crate::scenario::{FixedBeacon, FixedBeaconCell};
use crate::seed::{Stream, gauss, rng};
use crate::sensors::SensorSuite;
use crate::vehicles::{TruthState, feedback_linearising_control};
use nalgebra::{SVector, Vector2, Vector3};
use onebeacon::filter::consistency::nees;
use onebeacon::models::unicycle::{Cov, State};
use onebeacon::nav::{Measurement, Navigator, SingleBeaconNavigator};

/// Simulates run `run` of `cell` under base seed `seed`; records every step if `record`.
pub(super) fn simulate(s: &FixedBeacon, cell: &FixedBeaconCell, seed: u64, run: u64, record: bool) -> RunOutput {
    let dt = s.mission.dt_s;
    let speed = s.mission.speed_m_s;
    let path = s.path();
    let beacon = s.beacon_ned_m();
    let steps = s.steps();

    let r0 = path.at_time(0.0, speed);
    let mut truth = TruthState { pos: r0.pos, psi: r0.vel.y.atan2(r0.vel.x), v: speed };
    let (mut omega, mut accel) = feedback_linearising_control(&truth, &r0);
    let mut sensors = SensorSuite::new(&s.sensors, s.comms.frame_loss_prob, seed, run);

    // initial estimate: truth plus one draw, shared by all estimators
    let i = &s.initial;
    let sigma0 = SVector::<f64, 6>::from([
        i.position_sigma_m,
        i.position_sigma_m,
        i.heading_sigma_deg.to_radians(),
        i.speed_sigma_m_s,
        i.yaw_rate_sigma_rad_s,
        i.accel_sigma_m_s2,
    ]);
    let mut init_rng = rng(seed, run, Stream::Initial);
    let z_true = State::from([truth.pos.x, truth.pos.y, truth.psi, truth.v, omega, accel]);
    let z0 = z_true + sigma0.map(|sd| gauss(&mut init_rng, sd));
    let p0 = Cov::from_diagonal(&sigma0.component_mul(&sigma0));
    let mut filters: Vec<SingleBeaconNavigator> = s
        .estimators
        .iter()
        .map(|e| SingleBeaconNavigator::new(e.kind.aiding(), e.tuning(), e.filter_kind(), 0.0, z0, p0))
        .collect();

    let mut acc = vec![ErrorAccumulator::new(steps + 1); filters.len()];
    let mut trajectory = Vec::with_capacity(if record { steps + 1 } else { 0 });
    let mut distance = 0.0;
    let mut frames_decoded = 0;
    // scores every filter against the truth; builds the estimates only when recording
    let observe =
        |filters: &[SingleBeaconNavigator], acc: &mut [ErrorAccumulator], truth: &TruthState, record: bool| {
            let mut estimates = Vec::with_capacity(if record { filters.len() } else { 0 });
            for (f, a) in filters.iter().zip(acc.iter_mut()) {
                let est = f.estimate();
                let e = est.position_ned_m.xy() - truth.pos;
                let n = nees(&e, &est.horizontal_cov_m2);
                a.push(e.norm(), n);
                if record {
                    estimates.push(Estimate::new(&est, e.norm(), n));
                }
            }
            estimates
        };
    let estimates = observe(&filters, &mut acc, &truth, record);
    if record {
        trajectory.push(step_record(0.0, &truth, beacon, false, estimates));
    }

    let mut frame_index = 0u64;
    for k in 1..=steps {
        let t = k as f64 * dt;
        // truth moves under the command of the previous step (eq. 3-4), then a new
        // command is computed from the reference (eq. 2)
        truth = truth.step(omega, accel, dt);
        distance += truth.v.abs() * dt;
        (omega, accel) = feedback_linearising_control(&truth, &path.at_time(t, speed));

        let sample = sensors.proprioceptive(t, &truth, omega, accel);
        // a frame every T_com seconds, at the first step at or after each multiple
        let due = ((t + 1e-9) / cell.t_com_s).floor() as u64;
        let frame = if due > frame_index {
            frame_index = due;
            sensors.comm_frame(&truth, beacon)
        } else {
            None
        };
        frames_decoded += u64::from(frame.is_some());
        for (f, a) in filters.iter_mut().zip(acc.iter_mut()) {
            // a frame decoded during the step is fused with the step's inertial sample
            let outcomes = frame.iter().chain([&sample]).map(|kind| f.process(&Measurement::new(t, *kind)));
            a.count_failures(outcomes);
        }
        let estimates = observe(&filters, &mut acc, &truth, record);
        if record {
            trajectory.push(step_record(t, &truth, beacon, frame.is_some(), estimates));
        }
    }

    RunOutput {
        metrics: acc.iter().map(|a| a.finish(distance)).collect(),
        trajectory,
        distance_m: distance,
        frames_decoded,
        range_information: Vec::new(),
        guidance: Vec::new(),
    }
}

fn step_record(
    t_s: f64,
    truth: &TruthState,
    beacon: Vector2<f64>,
    frame: bool,
    estimates: Vec<Estimate>,
) -> StepRecord {
    StepRecord {
        t_s,
        truth_pos: Vector3::new(truth.pos.x, truth.pos.y, 0.0),
        truth_heading: truth.psi,
        truth_speed: truth.v,
        beacon: Vector3::new(beacon.x, beacon.y, 0.0),
        frame,
        estimates,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scenario::fixed_beacon::Sensors;
    use crate::scenario::{Scenario, builtin, parse};

    fn garin() -> FixedBeacon {
        match parse(builtin("garin2024").unwrap().toml, "garin2024").unwrap() {
            Scenario::FixedBeacon(s) => s,
            _ => unreachable!(),
        }
    }

    #[test]
    fn a_run_is_a_function_of_its_inputs() {
        let mut s = garin();
        s.mission.duration_s = Some(120.0);
        let c = s.base_cell();
        let a = simulate(&s, &c, 5, 3, true);
        let b = simulate(&s, &c, 5, 3, true);
        let other = simulate(&s, &c, 5, 4, false);
        assert_eq!(a, b);
        assert_ne!(a.metrics, other.metrics);
        assert_eq!(a.trajectory.len(), 481);
        assert_eq!(a.frames_decoded, 40);
    }

    #[test]
    fn noise_free_run_ends_with_sub_centimetre_error() {
        let mut s = garin();
        s.sensors = Sensors::noise_free();
        // start on the truth (a millimetre-sized initial draw)
        s.initial.position_sigma_m = 1e-4;
        s.initial.heading_sigma_deg = 1e-5;
        s.initial.speed_sigma_m_s = 1e-5;
        s.initial.yaw_rate_sigma_rad_s = 1e-6;
        s.initial.accel_sigma_m_s2 = 1e-6;
        // and tell the filters their sensors are (nearly) exact
        for e in &mut s.estimators {
            e.r_range_m2 = 1e-6;
            e.r_doppler_m2_s2 = 1e-8;
            e.r_heading_rad2 = 1e-8;
            e.r_yaw_rate_rad2_s2 = 1e-10;
            e.r_accel_m2_s4 = 1e-10;
        }
        // the UKF too
        let mut ukf = s.estimators[0].clone();
        ukf.filter = crate::scenario::FilterName::Ukf;
        s.estimators.push(ukf);
        let out = simulate(&s, &s.base_cell(), 1, 0, false);
        assert!((out.distance_m - 1567.0).abs() < 2.0, "distance {}", out.distance_m);
        for (e, m) in s.estimators.iter().zip(&out.metrics) {
            assert!(m.final_error_m < 0.01, "{}: final error {} m", e.name(), m.final_error_m);
            assert!(m.max_error_m < 0.01, "{}: max error {} m", e.name(), m.max_error_m);
        }
    }
}
