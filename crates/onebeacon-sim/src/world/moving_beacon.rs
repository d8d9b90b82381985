//! The moving-beacon world (sousa): underwater vehicles follow their paths by body
//! velocities; the ASV carries the beacon, pings every period and moves, between pings,
//! to the waypoint its onboard controller ([`onebeacon::vehicle::fim`]) chose at the
//! last ping; each ping reaches each vehicle when the wavefront meets it.

use crate::acoustics::Ping;
use crate::acoustics::clock::Clock;
use crate::acoustics::link::Link;
use crate::acoustics::profile::Profile;
use crate::engine::{PilotRecord, VehicleTruth, World};
use crate::scenario::moving_beacon::Vehicle;
use crate::scenario::passive_usbl::AsvVehicle;
use crate::scenario::{MovingBeacon, MovingBeaconCell};
use crate::seed::{Stream, gauss, rng, vehicle_rng};
use crate::sensor_errors::DriftingSensors;
use crate::vehicles::asv::{AsvLimits, AsvState};
use crate::vehicles::autopilot::{Command, MAX_STEP_S, step_over};
use crate::vehicles::otter::OtterPilot;
use crate::vehicles::rov::{body_velocity, rk4_step};
use nalgebra::{Vector2, Vector3};
use onebeacon::measure::ScalarModel;
use onebeacon::models::kinematic6dof::{BodyVelocity, State, idx};
use onebeacon::nav::{BeaconFix, Kind, Measurement, SensorNoise};
use onebeacon::vehicle::{Command as VehicleCommand, OwnFix, Situation};
use rand_pcg::Pcg64Mcg;

/// The true state of vehicle `v` (path and depth set), step after step: RK4 on its
/// body velocities. It does not depend on the draws; it is computed as it goes, so a
/// run holds one state whatever its length.
#[derive(Debug, Clone)]
pub struct TruthPath {
    vehicle: Vehicle,
    dt: f64,
    k: usize,
    eta: State,
}

impl TruthPath {
    /// The vehicle at its start (step 0).
    pub fn new(s: &MovingBeacon, v: &Vehicle) -> Self {
        let eta = State::from([v.start_north_m, v.start_east_m, v.depth_m, 0.0, 0.0, v.heading_deg.to_radians()]);
        Self { vehicle: v.clone(), dt: s.mission.dt_s, k: 0, eta }
    }

    /// The state at the current step.
    pub fn state(&self) -> &State {
        &self.eta
    }

    /// Moves to the next step.
    pub fn step(&mut self) {
        let path = self.vehicle.body_path();
        self.eta = rk4_step(&self.eta, self.k as f64 * self.dt, self.dt, |t| body_velocity(&path, t));
        self.k += 1;
    }
}

/// The ping on its way with what the vehicles will be told of its origin.
struct InFlight {
    ping: Ping,
    gps: Vector3<f64>,
    /// What the beacon's clock read minus the true time at transmission, s.
    clock_s: f64,
    /// Which vehicles heard it already.
    heard: Vec<bool>,
}

/// One underwater vehicle: its truth, its sensors' random streams, its last measured
/// body velocity.
struct Underwater {
    spec: Vehicle,
    truth: TruthPath,
    velocity_rng: Pcg64Mcg,
    attitude_rng: Pcg64Mcg,
    /// The range noise stream; None: the world's acoustic stream (the first vehicle's,
    /// as in a single-vehicle world).
    range_rng: Option<Pcg64Mcg>,
    /// The vehicle's clock, which times the pings' arrivals.
    clock: Clock,
    /// Its acoustic link: losses and outliers.
    link: Link,
    /// Its DVL's and heading sensor's drifting errors (`[sea.sensors]`).
    sensors: DriftingSensors,
    nu_meas: BodyVelocity,
    distance_m: f64,
}

pub(crate) struct MovingBeaconWorld<'a> {
    s: &'a MovingBeacon,
    noise: SensorNoise,
    vehicles: Vec<Underwater>,
    lim: AsvLimits,
    asv: AsvState,
    /// The ASV's surge speed over the last step.
    asv_speed: f64,
    /// The Otter's dynamics and autopilots when the ASV is one (`asv.vehicle`), and its
    /// last command.
    otter: Option<OtterPilot>,
    asv_command: Option<Command>,
    waypoint: Vector2<f64>,
    arrive_at: f64,
    next_ping: f64,
    in_flight: Vec<InFlight>,
    /// GPS errors of the ASV (and the first vehicle's range errors).
    acoustic_rng: Pcg64Mcg,
    /// The beacon's clock, which times the pings' transmissions.
    beacon_clock: Clock,
    /// The sea's sound-speed profile, when it has one (`[sea.sound_speed]`).
    profile: Option<Profile>,
    /// The current step.
    k: usize,
}

impl<'a> MovingBeaconWorld<'a> {
    /// The world of `cell` with the ASV starting at `asv0`.
    pub(crate) fn new(s: &'a MovingBeacon, cell: &MovingBeaconCell, asv0: Vector2<f64>, seed: u64, run: u64) -> Self {
        let vehicles: Vec<Underwater> = s
            .vehicles(cell)
            .into_iter()
            .enumerate()
            .map(|(v, spec)| Underwater {
                truth: TruthPath::new(s, &spec),
                spec,
                velocity_rng: vehicle_rng(seed, run, v, Stream::Imu),
                attitude_rng: vehicle_rng(seed, run, v, Stream::Heading),
                range_rng: (v > 0).then(|| vehicle_rng(seed, run, v, Stream::Acoustic)),
                clock: Clock::new(&s.sea.clocks, vehicle_rng(seed, run, v, Stream::Clock)),
                link: Link::new(&s.sea.link, vehicle_rng(seed, run, v, Stream::Link)),
                sensors: DriftingSensors::new(&s.sea.sensors, vehicle_rng(seed, run, v, Stream::Sensors)),
                nu_meas: BodyVelocity::zeros(),
                distance_m: 0.0,
            })
            .collect();
        let start = vehicles[0].truth.state();
        let toward_vehicle = Vector2::new(start[idx::N], start[idx::E]) - asv0;
        Self {
            s,
            noise: s.sensor_noise(),
            vehicles,
            lim: AsvLimits {
                max_speed_m_s: s.asv.max_speed_m_s,
                max_turn_rate_rad_s: s.asv.max_turn_rate_deg_s.to_radians(),
            },
            asv: AsvState { pos: asv0, psi: toward_vehicle.y.atan2(toward_vehicle.x) },
            asv_speed: 0.0,
            otter: (s.asv.vehicle == AsvVehicle::Otter)
                .then(|| OtterPilot::on_surface(asv0, toward_vehicle.y.atan2(toward_vehicle.x))),
            asv_command: None,
            waypoint: asv0,
            arrive_at: 0.0,
            next_ping: 0.0,
            in_flight: Vec::new(),
            acoustic_rng: rng(seed, run, Stream::Acoustic),
            beacon_clock: Clock::new(&s.sea.clocks, rng(seed, run, Stream::BeaconClock)),
            profile: s.sea.sound_speed.as_ref().map(|p| p.profile()),
            k: 0,
        }
    }

    /// Every vehicle's true state now.
    pub(crate) fn states(&self) -> Vec<State> {
        self.vehicles.iter().map(|u| *u.truth.state()).collect()
    }
}

impl World for MovingBeaconWorld<'_> {
    fn vehicles(&self) -> usize {
        self.vehicles.len()
    }

    fn steps(&self) -> usize {
        self.s.steps()
    }

    fn t_s(&self, k: usize) -> f64 {
        k as f64 * self.s.mission.dt_s
    }

    fn truth(&self, v: usize) -> VehicleTruth {
        let u = &self.vehicles[v];
        let t = self.t_s(self.k);
        VehicleTruth {
            eta: *u.truth.state(),
            speed_m_s: body_velocity(&u.spec.body_path(), t).fixed_rows::<3>(0).norm(),
            distance_m: u.distance_m,
        }
    }

    fn beacon_ned_m(&self) -> Vector3<f64> {
        Vector3::new(self.asv.pos.x, self.asv.pos.y, self.s.asv.transducer_depth_m)
    }

    fn pilots(&self, out: &mut Vec<PilotRecord>) {
        if let (Some(otter), Some(c)) = (&self.otter, self.asv_command) {
            out.push(PilotRecord::of(None, c, &otter.state));
        }
    }

    /// At a ping the ASV sends it, and knows where it sent it from by its GPS (eq. 4.3):
    /// its controller decides then. Between pings it keeps its waypoint.
    fn situation(&mut self, k: usize, _h: usize) -> Option<Situation> {
        let t0 = self.t_s(k - 1);
        if t0 + 1e-9 < self.next_ping {
            return None;
        }
        let s = self.s;
        let gps = Vector3::new(
            self.asv.pos.x + gauss(&mut self.acoustic_rng, s.asv.gps_noise_m),
            self.asv.pos.y + gauss(&mut self.acoustic_rng, s.asv.gps_noise_m),
            s.asv.transducer_depth_m,
        ); // eq. 4.3
        self.in_flight.push(InFlight {
            ping: Ping { t_tx: t0, origin: self.beacon_ned_m() },
            gps,
            clock_s: self.beacon_clock.error_s(t0),
            heard: vec![false; self.vehicles.len()],
        });
        self.next_ping += s.acoustics.ping_period_s;
        let fix = OwnFix { position_m: gps.xy(), heading_rad: self.asv.psi, speed_m_s: self.asv_speed };
        Some(Situation { t_s: t0, fix: Some(fix) })
    }

    fn advance(&mut self, k: usize, commands: &[Option<VehicleCommand>], heard: &mut [Vec<Measurement>]) {
        self.k = k;
        let (t0, t1) = (self.t_s(k - 1), self.t_s(k));
        let dt = self.s.mission.dt_s;
        let c = self.s.acoustics.sound_speed_m_s;
        if let Some(Some(VehicleCommand::Waypoint { waypoint, arrive_s })) = commands.first() {
            (self.waypoint, self.arrive_at) = (*waypoint, *arrive_s);
        }
        let (u, r) = self.asv.command(self.waypoint, self.arrive_at - t0, &self.lim);
        if let Some(otter) = &mut self.otter {
            // the same speed, and the course to the waypoint, as the autopilots' commands
            let d = self.waypoint - self.asv.pos;
            let course = if d.norm() < 0.05 { self.asv.psi } else { d.y.atan2(d.x) };
            let command = Command { heading_rad: course, speed_m_s: u, depth_m: None };
            step_over(otter, &command, &Vector3::zeros(), dt, MAX_STEP_S);
            self.asv_command = Some(command);
            self.asv = AsvState { pos: otter.state.position_ned_m.xy(), psi: otter.state.euler().2 };
            self.asv_speed = otter.state.nu[0];
        } else {
            self.asv = self.asv.step(u, r, dt);
            self.asv_speed = u;
        }

        let noise = self.noise;
        for (v, (veh, out)) in self.vehicles.iter_mut().zip(heard.iter_mut()).enumerate() {
            // the vehicle's body velocities over the step, as measured: drawn from the
            // process model the navigators use
            veh.nu_meas = noise
                .process_model(body_velocity(&veh.spec.body_path(), t0 + dt / 2.0))
                .sample_input(&mut veh.velocity_rng);
            // the DVL's scale and outages (`[sea.sensors]`) on its linear part
            let [u, v_, w] = veh.sensors.velocity(t0, [veh.nu_meas[0], veh.nu_meas[1], veh.nu_meas[2]]);
            (veh.nu_meas[0], veh.nu_meas[1], veh.nu_meas[2]) = (u, v_, w);
            let p0 = veh.truth.state().fixed_rows::<3>(0).into_owned();
            veh.truth.step();
            let x = *veh.truth.state();
            let p1 = x.fixed_rows::<3>(0).into_owned();
            veh.distance_m += (p1 - p0).norm();
            out.push(Measurement::new(t0, Kind::BodyVelocity { nu: veh.nu_meas.into() }));

            // pings heard during the step, in order of arrival
            let first = out.len();
            for f in self.in_flight.iter_mut().filter(|f| !f.heard[v]) {
                let Some(t_rx) = f.ping.arrival(c, t0, &p0, t1, &p1) else { continue };
                f.heard[v] = true;
                // the range noise of the navigators' range model (the GPS error is
                // drawn apart, on the position the ASV reports)
                let rng = veh.range_rng.as_mut().unwrap_or(&mut self.acoustic_rng);
                let range_noise = noise.range_model(&BeaconFix::fixed(0, f.ping.origin)).noise(&x, rng);
                // the travel time, along the eigenray of the sea's profile when it has
                // one (the arrival stays the straight ray's: the two differ by
                // milliseconds, over which the vehicle moves millimetres)
                let travel_s = match &self.profile {
                    None => t_rx - f.ping.t_tx,
                    Some(profile) => {
                        let o = f.ping.origin;
                        profile.travel_time((x.fixed_rows::<2>(0) - o.xy()).norm(), o.z, x[idx::D])
                    }
                };
                // as the two clocks read it
                let clock_m = c * (veh.clock.error_s(t_rx) - f.clock_s);
                // lost, or heard on another path
                let Some(range_m) = veh.link.hear(c * travel_s + clock_m + range_noise) else { continue };
                let beacon = BeaconFix {
                    id: 0,
                    position_ned_m: f.gps,
                    sigma_m: self.s.asv.gps_noise_m,
                    t_tx_s: Some(f.ping.t_tx),
                };
                out.push(Measurement::new(t_rx, Kind::Range { beacon, range_m }));
            }
            out[first..].sort_by(|a, b| a.t_s.total_cmp(&b.t_s));

            // depth and attitude at the step's end
            let [d_m, roll_m, pitch_m, yaw_m] = noise.depth_attitude_models();
            let (x, rng) = (&x, &mut veh.attitude_rng);
            out.push(Measurement::new(t1, Kind::Depth { depth_m: x[idx::D] + d_m.noise(x, rng) }));
            out.push(Measurement::new(
                t1,
                Kind::Attitude {
                    roll_rad: x[idx::ROLL] + roll_m.noise(x, rng),
                    pitch_rad: x[idx::PITCH] + pitch_m.noise(x, rng),
                    heading_rad: onebeacon::geo::wrap_angle(veh.sensors.heading(t1, x[idx::YAW]) + yaw_m.noise(x, rng)),
                },
            ));
        }
        self.in_flight.retain(|f| f.heard.iter().any(|h| !h));
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scenario::{Scenario, builtin, parse};
    use crate::sensor_errors::SensorErrors;

    /// The sousa world's DVL and heading with `[sea.sensors]` against the same run
    /// without: every forward speed read is the clean one times one scale (1e-12), not
    /// 1; the heading differs by a bias that barely moves with a 1e7 s time constant
    /// (under 0.01 rad over 200 s); with outages half the time, some steps repeat the
    /// last velocity exactly while the clean one moves on.
    #[test]
    fn drifting_sensors_reach_the_vehicle() {
        let Scenario::MovingBeacon(clean) = parse(builtin("sousa").unwrap().toml, "sousa").unwrap() else {
            unreachable!()
        };
        let read = |sensors: SensorErrors| {
            let mut s = clean.clone();
            s.sea.sensors = sensors;
            let cell = s.base_cell();
            let mut w = MovingBeaconWorld::new(&s, &cell, Vector2::new(30.0, 0.0), 1, 0);
            let mut out = Vec::new();
            for k in 1..=2000 {
                let mut heard = vec![Vec::new(); w.vehicles.len()];
                w.advance(k, &[None], &mut heard);
                let (mut u, mut psi) = (f64::NAN, f64::NAN);
                for m in &heard[0] {
                    match m.kind {
                        Kind::BodyVelocity { nu } => u = nu[0],
                        Kind::Attitude { heading_rad, .. } => psi = heading_rad,
                        _ => {}
                    }
                }
                out.push((u, psi));
            }
            out
        };
        let base = read(SensorErrors::default());
        let scaled = read(SensorErrors {
            speed_scale_sigma: 0.05,
            heading_bias_sigma_deg: 2.0,
            heading_bias_time_constant_s: 1e7,
            ..SensorErrors::default()
        });
        let scale = scaled[0].0 / base[0].0;
        let bias = onebeacon::geo::wrap_angle(scaled[0].1 - base[0].1);
        assert!((scale - 1.0).abs() > 1e-4 && bias.abs() > 1e-4, "scale {scale}, bias {bias}");
        for ((u0, p0), (u, p)) in base.iter().zip(&scaled) {
            assert!((u / u0 - scale).abs() < 1e-12 || u0.abs() < 1e-9, "{u} against {u0}");
            assert!((onebeacon::geo::wrap_angle(p - p0) - bias).abs() < 0.01);
        }
        let out = read(SensorErrors { speed_dropout_prob: 0.5, speed_dropout_mean_s: 5.0, ..SensorErrors::default() });
        let held = out.windows(2).zip(base.windows(2)).filter(|(o, b)| o[1].0 == o[0].0 && b[1].0 != b[0].0).count();
        assert!(held > 100, "{held} steps held");
    }
}
