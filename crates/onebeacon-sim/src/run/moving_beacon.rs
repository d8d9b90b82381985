//! The moving-beacon world (sousa): the underwater vehicle follows its path by body
//! velocities; the ASV carries the beacon, pings every period and moves, between pings,
//! to the waypoint its guidance chose at the last ping; each ping reaches the vehicle
//! when the wavefront meets it. Every estimator runs on the same truth and draws; the
//! first estimator's estimate is what the vehicle reports to the ASV's guidance.

use super::{Estimate, GuidanceSnapshot, RunOutput, StepRecord};
use crate::acoustics::Ping;
use crate::metrics::ErrorAccumulator;
use crate::scenario::moving_beacon::{EstimatorKind, GuidanceKind};
use crate::scenario::{MovingBeacon, MovingBeaconCell};
use crate::seed::{Stream, gauss, rng};
use crate::vehicles::asv::{AsvLimits, AsvState};
use crate::vehicles::rov::{body_velocity, rk4_step};
use nalgebra::{SVector, Vector2, Vector3};
use onebeacon::filter::consistency::nees;
use onebeacon::guidance::{FimPlanner, Metric, PolarGrid, ReachingSet, best_standoff};
use onebeacon::measure::ScalarModel;
use onebeacon::models::kinematic6dof::{BodyVelocity, Cov, State, idx, rotation};
use onebeacon::nav::{BeaconFix, Kind, Measurement, Navigator, Range6DofNavigator};

/// The vehicle's true state at every step (it does not depend on the draws).
pub fn truth_trajectory(s: &MovingBeacon, cell: &MovingBeaconCell) -> Vec<State> {
    let v = &s.vehicle;
    let dt = s.mission.dt_s;
    let mut eta = State::from([v.start_north_m, v.start_east_m, cell.depth_m, 0.0, 0.0, v.heading_deg.to_radians()]);
    let mut out = Vec::with_capacity(s.steps() + 1);
    out.push(eta);
    for k in 0..s.steps() {
        eta = rk4_step(&eta, k as f64 * dt, dt, |t| body_velocity(v, cell.path, t));
        out.push(eta);
    }
    out
}

/// The ASV's start: the best standoff for the vehicle's start depth and the ASV's reach
/// (sousa Fig. 4.7), in the direction `asv.start_bearing_deg` from the vehicle.
pub fn initial_asv_position(s: &MovingBeacon, cell: &MovingBeaconCell) -> Vector2<f64> {
    let reach = s.asv.max_speed_m_s * s.acoustics.ping_period_s;
    let grid = PolarGrid { radial: 20, angular: 36, refinements: 10 };
    let d = best_standoff((cell.depth_m - s.asv.transducer_depth_m).max(0.0), reach, grid).distance_m;
    let b = s.asv.start_bearing_deg.to_radians();
    Vector2::new(s.vehicle.start_north_m, s.vehicle.start_east_m) + Vector2::new(b.cos(), b.sin()) * d
}

/// The ping on its way with what the vehicle will be told of its origin.
struct InFlight {
    ping: Ping,
    gps: Vector3<f64>,
}

pub(super) fn simulate(s: &MovingBeacon, cell: &MovingBeaconCell, seed: u64, run: u64, record: bool) -> RunOutput {
    let dt = s.mission.dt_s;
    let steps = s.steps();
    let truth = truth_trajectory(s, cell);
    let (c, period) = (s.acoustics.sound_speed_m_s, s.acoustics.ping_period_s);
    let reach = s.asv.max_speed_m_s * period;
    let z_tx = s.asv.transducer_depth_m;
    let lim =
        AsvLimits { max_speed_m_s: s.asv.max_speed_m_s, max_turn_rate_rad_s: s.asv.max_turn_rate_deg_s.to_radians() };
    let noise = s.sensor_noise();
    let mut vel_rng = rng(seed, run, Stream::Imu);
    let mut att_rng = rng(seed, run, Stream::Heading);
    let mut ac_rng = rng(seed, run, Stream::Acoustic);

    // filters start at the truth plus one draw (shared)
    let i = &s.initial;
    let a0 = i.attitude_sigma_deg.to_radians();
    let sigma0 = SVector::<f64, 6>::from([i.position_sigma_m, i.position_sigma_m, i.depth_sigma_m, a0, a0, a0]);
    let mut init_rng = rng(seed, run, Stream::Initial);
    let eta0 = truth[0] + sigma0.map(|sd| gauss(&mut init_rng, sd));
    let p0 = Cov::from_diagonal(&sigma0.component_mul(&sigma0));
    let mut filters: Vec<Range6DofNavigator> = s
        .estimators
        .iter()
        .map(|e| Range6DofNavigator::new(noise, e.kind == EstimatorKind::RangeEkf, e.filter_kind(), 0.0, eta0, p0))
        .collect();

    let planner = |metric| FimPlanner {
        metric,
        grid: PolarGrid { radial: s.guidance.grid_radial, angular: s.guidance.grid_angular, refinements: 12 },
        range_var_m2: s.acoustics.range_noise_m.powi(2),
        beacon_depth_m: z_tx,
    };
    let asv0 = initial_asv_position(s, cell);
    let toward_vehicle = Vector2::new(truth[0][idx::N], truth[0][idx::E]) - asv0;
    let mut asv = AsvState { pos: asv0, psi: toward_vehicle.y.atan2(toward_vehicle.x) };
    let mut waypoint = asv0;
    let mut arrive_at = 0.0;
    let mut next_ping = 0.0;
    let mut in_flight: Vec<InFlight> = Vec::new();
    let mut nu_meas = BodyVelocity::zeros();

    let mut acc = vec![ErrorAccumulator::new(steps + 1); filters.len()];
    let mut trajectory = Vec::with_capacity(if record { steps + 1 } else { 0 });
    let mut range_information = Vec::new();
    let mut guidance = Vec::new();
    let (mut distance, mut heard) = (0.0, 0u64);

    let observe = |filters: &[Range6DofNavigator], acc: &mut [ErrorAccumulator], eta: &State| {
        let mut out = Vec::with_capacity(if record { filters.len() } else { 0 });
        for (f, a) in filters.iter().zip(acc.iter_mut()) {
            let est = f.estimate();
            let e = (est.position_ned_m - eta.fixed_rows::<3>(0)).xy();
            let n = nees(&e, &est.horizontal_cov_m2);
            a.push(e.norm(), n);
            if record {
                out.push(Estimate::new(&est, e.norm(), n));
            }
        }
        out
    };
    let speed_of = |t: f64| body_velocity(&s.vehicle, cell.path, t).fixed_rows::<3>(0).norm();
    let beacon_at = |a: &AsvState| Vector3::new(a.pos.x, a.pos.y, z_tx);
    let estimates = observe(&filters, &mut acc, &truth[0]);
    if record {
        trajectory.push(record_step(0.0, &truth[0], speed_of(0.0), beacon_at(&asv), false, estimates));
    }

    for k in 1..=steps {
        let (t0, t1) = ((k - 1) as f64 * dt, k as f64 * dt);
        // the ASV pings, then picks where to be at the next ping (sousa 3.3)
        if t0 + 1e-9 >= next_ping {
            let gps = Vector3::new(
                asv.pos.x + gauss(&mut ac_rng, s.asv.gps_noise_m),
                asv.pos.y + gauss(&mut ac_rng, s.asv.gps_noise_m),
                z_tx,
            ); // eq. 4.3
            in_flight.push(InFlight { ping: Ping { t_tx: t0, origin: beacon_at(&asv) }, gps });
            let est = &filters[0];
            let target = est.estimate().position_ned_m;
            let lin = nu_meas.fixed_rows::<3>(0).into_owned();
            let st = est.state();
            let target_next = target + rotation(st[idx::ROLL], st[idx::PITCH], st[idx::YAW]) * lin * period;
            let here = gps.xy();
            // the baselines' snapshots map approach A's metric
            let metric = if cell.guidance == GuidanceKind::ApproachB { Metric::ApproachB } else { Metric::ApproachA };
            waypoint = match cell.guidance {
                GuidanceKind::ApproachA | GuidanceKind::ApproachB => {
                    planner(metric)
                        .next_waypoint(&ReachingSet { center: here, radius: reach }, here, &target, &target_next)
                        .waypoint
                }
                GuidanceKind::Static => asv0,
                GuidanceKind::Circle => {
                    let r = s.guidance.circle_radius_m;
                    let rel = here - target.xy();
                    let angle = rel.y.atan2(rel.x) + (reach / r).min(std::f64::consts::FRAC_PI_2);
                    target.xy() + Vector2::new(angle.cos(), angle.sin()) * r
                }
            };
            if record {
                guidance.push(GuidanceSnapshot {
                    t_s: t0,
                    planner: planner(metric),
                    previous: here,
                    reach_m: reach,
                    target,
                    target_next,
                    waypoint,
                });
            }
            arrive_at = t0 + period;
            next_ping += period;
        }
        let (u, r) = asv.command(waypoint, arrive_at - t0, &lim);
        asv = asv.step(u, r, dt);

        // the vehicle's body velocities over the step, as measured
        // drawn from the process model the navigators use
        nu_meas = noise.process_model(body_velocity(&s.vehicle, cell.path, t0 + dt / 2.0)).sample_input(&mut vel_rng);
        let (p0v, p1v) = (truth[k - 1].fixed_rows::<3>(0).into_owned(), truth[k].fixed_rows::<3>(0).into_owned());
        distance += (p1v - p0v).norm();

        // pings heard during the step, in order of arrival
        let mut arrivals: Vec<Measurement> = Vec::new();
        in_flight.retain(|f| match f.ping.arrival(c, t0, &p0v, t1, &p1v) {
            Some(t_rx) => {
                // the range noise of the navigators' range model (the GPS error is drawn
                // apart, on the position the ASV reports)
                let at_origin = BeaconFix::fixed(0, f.ping.origin);
                let range_noise = noise.range_model(&at_origin).noise(&truth[k], &mut ac_rng);
                let range_m = c * (t_rx - f.ping.t_tx) + range_noise;
                let beacon =
                    BeaconFix { id: 0, position_ned_m: f.gps, sigma_m: s.asv.gps_noise_m, t_tx_s: Some(f.ping.t_tx) };
                arrivals.push(Measurement::new(t_rx, Kind::Range { beacon, range_m }));
                false
            }
            None => true,
        });
        arrivals.sort_by(|a, b| a.t_s.total_cmp(&b.t_s));
        for m in &arrivals {
            // information of this range about the true state, for the bound: the
            // navigator's own range model, at the truth
            if let Kind::Range { beacon, .. } = m.kind {
                let model = noise.range_model(&beacon);
                let h = ScalarModel::<6>::jacobian(&model, &truth[k]);
                range_information.push((k, h.transpose() * h / model.variance(&truth[k])));
            }
        }
        heard += arrivals.len() as u64;

        let [d_m, roll_m, pitch_m, yaw_m] = noise.depth_attitude_models();
        let x = &truth[k];
        let depth = Kind::Depth { depth_m: x[idx::D] + d_m.noise(x, &mut att_rng) };
        let attitude = Kind::Attitude {
            roll_rad: x[idx::ROLL] + roll_m.noise(x, &mut att_rng),
            pitch_rad: x[idx::PITCH] + pitch_m.noise(x, &mut att_rng),
            heading_rad: onebeacon::geo::wrap_angle(x[idx::YAW] + yaw_m.noise(x, &mut att_rng)),
        };
        // the step's body velocities from its start, the ranges as they arrive, then
        // depth and attitude at its end
        let start = Measurement::new(t0, Kind::BodyVelocity { nu: nu_meas.into() });
        let end = [Measurement::new(t1, depth), Measurement::new(t1, attitude)];
        for (f, a) in filters.iter_mut().zip(acc.iter_mut()) {
            let events = std::iter::once(&start).chain(&arrivals).chain(&end);
            a.count_failures(events.map(|m| f.process(m)));
        }
        let estimates = observe(&filters, &mut acc, &truth[k]);
        if record {
            trajectory.push(record_step(t1, &truth[k], speed_of(t1), beacon_at(&asv), !arrivals.is_empty(), estimates));
        }
    }

    RunOutput {
        metrics: acc.iter().map(|a| a.finish(distance.max(1e-9))).collect(),
        trajectory,
        distance_m: distance,
        frames_decoded: heard,
        range_information,
        guidance,
    }
}

fn record_step(
    t_s: f64,
    eta: &State,
    speed: f64,
    beacon: Vector3<f64>,
    frame: bool,
    estimates: Vec<Estimate>,
) -> StepRecord {
    StepRecord {
        t_s,
        truth_pos: eta.fixed_rows::<3>(0).into_owned(),
        truth_heading: onebeacon::geo::wrap_angle(eta[idx::YAW]),
        truth_speed: speed,
        beacon,
        frame,
        estimates,
    }
}
