//! The fleet world (rypkema): SandShark-like AUVs, a beacon towed by a boat along a
//! scripted track (and one fixed at the dock), the operator's schedule of command
//! modes. Each AUV's onboard controller ([`onebeacon::vehicle::behaviours`]) reads the
//! confirmed mode and where the vehicle is relative to the beacon from its first
//! estimator (the iUSBL navigator); its setpoint moves the vehicle. Every `ping_period_s` the transmitting beacon sends its
//! mode's chirp: through the channel simulation to each AUV's array (the captures go to
//! the navigators' receiver chains), or drawn as range, direction and mode (abstract).

use crate::acoustics::channel::{Boundaries, Channel, simulate_ping};
use crate::acoustics::clock::Clock;
use crate::acoustics::link::{Arrival, Link};
use crate::acoustics::profile::Profile;
use crate::engine::{PilotRecord, VehicleTruth, World};
use crate::scenario::fleet::{Fleet, SignalModel, Transmitter};
use crate::seed::{Stream, gauss, vehicle_rng};
use crate::sensor_errors::{DriftingSensors, SensorErrors as DriftErrors};
use crate::vehicles::autopilot::Command;
use crate::vehicles::sandshark::{SandShark, SensorErrors};
use crate::water::Water;
use nalgebra::{Matrix3, Rotation3, Vector3};
use onebeacon::dsp::beamform::{azimuth_inclination, pyramid_8cm};
use onebeacon::dsp::waveform::{Lfm, rypkema_modes};
use onebeacon::nav::{BeaconFix, Capture, Kind, Measurement};
use onebeacon::vehicle::{Command as VehicleCommand, Phase, Setpoint, Situation};
use rand::RngExt;
use rand_pcg::Pcg64Mcg;
use std::sync::Arc;

/// The capture window after the transmit epoch, s (8000 samples at 37.5 kS/s).
const WINDOW_S: f64 = 8000.0 / 37_500.0;
/// Shallower than this an AUV hears nothing (its array is out of the water), m.
const SURFACE_M: f64 = 0.3;

/// One AUV: truth, its last command, sensor errors and random streams.
struct Auv {
    truth: SandShark,
    errors: SensorErrors,
    launch_s: f64,
    distance_m: f64,
    setpoint: Setpoint,
    phase: Phase,
    mode: Option<usize>,
    imu_rng: Pcg64Mcg,
    acoustic_rng: Pcg64Mcg,
    /// Its clock and its link (`[sea]`).
    clock: Clock,
    link: Link,
    /// Its AHRS's and speed's drifting errors on top of the `[sandshark]` ones
    /// (`[sea.sensors]`; None: off, so that the heading is not wrapped twice).
    drift: Option<DriftingSensors>,
}

/// A ping sent, waiting for the end of the capture window.
#[derive(Debug, Clone, Copy)]
struct Sent {
    t_tx: f64,
    source: Vector3<f64>,
    mode: usize,
    from: Transmitter,
}

pub(crate) struct FleetWorld {
    s: Fleet,
    auvs: Vec<Auv>,
    waveforms: [Lfm; 4],
    elements: Vec<Vector3<f64>>,
    sent: Vec<Sent>,
    gps_rng: Pcg64Mcg,
    /// The boat's and the dock's beacon clocks, and the sea's sound-speed profile
    /// (`[sea]`).
    beacon_clocks: [Clock; 2],
    profile: Option<Profile>,
    /// The arrays' mounting misalignment in the AUVs' bodies (`sea.usbl.misalignment_deg`),
    /// when there is one.
    mounting: Option<Matrix3<f64>>,
    /// The water's current (`[sea.current]`), when it flows: it carries every AUV over
    /// ground, while their speed comes from the propeller's RPM (through the water).
    water: Option<Water>,
    /// The next transmit epoch.
    next_ping_s: f64,
    k: usize,
}

impl FleetWorld {
    pub(crate) fn new(s: &Fleet, seed: u64, run: u64) -> Self {
        let auvs = s
            .auvs
            .iter()
            .enumerate()
            .map(|(v, a)| {
                let mut imu_rng = vehicle_rng(seed, run, v, Stream::Imu);
                let heading = a.start_heading_deg.to_radians();
                Auv {
                    truth: SandShark::new(Vector3::new(a.start_north_m, a.start_east_m, 0.0), heading),
                    errors: SensorErrors::draw(&s.sandshark, &mut imu_rng),
                    launch_s: a.launch_s,
                    distance_m: 0.0,
                    setpoint: Setpoint { heading_rad: heading, speed_m_s: 0.0, depth_m: 0.0 },
                    phase: Phase::Waiting,
                    mode: None,
                    imu_rng,
                    acoustic_rng: vehicle_rng(seed, run, v, Stream::Acoustic),
                    clock: Clock::new(&s.sea.clocks, vehicle_rng(seed, run, v, Stream::Clock)),
                    link: Link::new(&s.sea.link, vehicle_rng(seed, run, v, Stream::Link)),
                    drift: (s.sea.sensors != DriftErrors::default())
                        .then(|| DriftingSensors::new(&s.sea.sensors, vehicle_rng(seed, run, v, Stream::Sensors))),
                }
            })
            .collect();
        Self {
            s: s.clone(),
            auvs,
            waveforms: rypkema_modes(),
            elements: pyramid_8cm(),
            sent: Vec::new(),
            gps_rng: crate::seed::rng(seed, run, Stream::BeaconGps),
            beacon_clocks: [0, 1].map(|b| Clock::new(&s.sea.clocks, vehicle_rng(seed, run, b, Stream::BeaconClock))),
            profile: s.sea.sound_speed.as_ref().map(|p| p.profile()),
            mounting: s.sea.usbl.misalignment_deg.iter().any(|a| *a != 0.0).then(|| {
                let [r, p, y] = s.sea.usbl.misalignment_deg.map(f64::to_radians);
                Rotation3::from_euler_angles(r, p, y).into_inner()
            }),
            water: s
                .sea
                .current
                .flows()
                .then(|| Water::new(s.sea.current.clone(), crate::seed::rng(seed, run, Stream::Current))),
            next_ping_s: 0.0,
            k: 0,
        }
    }

    fn dt(&self) -> f64 {
        self.s.mission.dt_s
    }

    /// Where beacon `from` is at `t`.
    fn beacon_at(&self, from: Transmitter, t: f64) -> Vector3<f64> {
        match from {
            Transmitter::Boat => self.s.boat_at(t),
            Transmitter::Dock => Vector3::new(self.s.dock.north_m, self.s.dock.east_m, self.s.dock.beacon_depth_m),
        }
    }

    /// What AUV `v` hears of ping `p`, if anything: lost on the link, or heard with the
    /// two clocks' difference (the AUV's at reception, the beacon's at transmission) on
    /// its travel time.
    fn hear(&mut self, v: usize, p: &Sent, gps: Vector3<f64>, tx_clock_s: f64) -> Option<Measurement> {
        let sig = &self.s.signal;
        let auv = &mut self.auvs[v];
        let at = auv.truth.position_ned_m;
        if at.z < SURFACE_M || auv.launch_s > p.t_tx {
            return None;
        }
        let d = p.source - at;
        let r = d.norm();
        if r > sig.max_range_m {
            return None;
        }
        let arrival = auv.link.arrive();
        if arrival == Arrival::Lost {
            return None;
        }
        let clock_s = auv.clock.error_s(p.t_tx + r / sig.sound_speed_m_s) - tx_clock_s;
        let beacon = BeaconFix {
            id: p.from as u32,
            position_ned_m: gps,
            sigma_m: self.s.dock.gps_sigma_m,
            t_tx_s: Some(p.t_tx),
        };
        let t = p.t_tx + WINDOW_S;
        // the array's axes: the body's, turned by its mounting (the navigator levels
        // with the body's attitude, taking the array as aligned)
        let att = self.mounting.map_or(auv.truth.attitude(), |m| auv.truth.attitude() * m);
        let rng = &mut auv.acoustic_rng;
        let kind = match sig.model {
            SignalModel::Channel => {
                let (s, c) = auv.truth.heading_rad.sin_cos();
                let velocity = Vector3::new(c, s, 0.0) * auv.truth.speed_over_ground();
                let ch = Channel {
                    fs_hz: 37_500.0,
                    capture_len: 8000,
                    sound_speed_m_s: sig.sound_speed_m_s,
                    snr_db: Some(sig.snr_db_at_100m - 20.0 * (r.max(1.0) / 100.0).log10()),
                    boundaries: Some(Boundaries {
                        water_depth_m: sig.water_depth_m,
                        surface_coef: sig.surface_coef,
                        bottom_coef: sig.bottom_coef,
                        wall_east_m: None,
                        wall_coef: 0.0,
                    }),
                    clock_offset_s: clock_s,
                    clock_drift_ppm: 0.0,
                    radial_speed_m_s: velocity.dot(&(d / r.max(1e-9))),
                };
                let samples = simulate_ping(&self.waveforms[p.mode], &p.source, &at, &att, &self.elements, &ch, rng);
                Kind::Capture(Arc::new(Capture { beacon, samples }))
            }
            SignalModel::Abstract => {
                let mut mode = p.mode;
                if rng.random_bool(sig.mode_error_probability) {
                    mode = (mode + rng.random_range(1..4usize)) % 4;
                }
                // the direct path (its travel time along the profile's eigenray when the
                // sea has one) or the surface-reflected one, from the source's image
                let (d, excess_m) = match arrival {
                    Arrival::Multipath { excess_m } => {
                        (Vector3::new(p.source.x, p.source.y, -p.source.z) - at, excess_m)
                    }
                    _ => (d, 0.0),
                };
                let path_m = d.norm();
                let travelled = match (&self.profile, arrival) {
                    (Some(c), Arrival::Direct) => sig.sound_speed_m_s * c.travel_time(d.xy().norm(), p.source.z, at.z),
                    _ => path_m,
                };
                let late_m = sig.sound_speed_m_s * clock_s + excess_m;
                let truth = att.transpose() * d / path_m;
                let (az, incl) = azimuth_inclination(&truth);
                let sa = sig.angle_sigma_deg.to_radians();
                let (range_m, azimuth_rad, inclination_rad) = if let Arrival::False { u } = arrival {
                    let z: f64 = rng.random_range(-1.0..=1.0);
                    (u * self.s.sea.link.false_max_range_m, rng.random_range(0.0..std::f64::consts::TAU), z.acos())
                } else if rng.random_bool(sig.outlier_probability) {
                    let z: f64 = rng.random_range(-1.0..=1.0);
                    (
                        r + rng.random_range(0.0..=sig.outlier_max_m),
                        rng.random_range(0.0..std::f64::consts::TAU),
                        z.acos(),
                    )
                } else {
                    (
                        travelled + late_m + gauss(rng, sig.range_sigma_m),
                        az + gauss(rng, sa),
                        (incl + gauss(rng, sa)).clamp(0.0, std::f64::consts::PI),
                    )
                };
                Kind::ArrayFix { beacon, range_m, azimuth_rad, inclination_rad, mode }
            }
        };
        Some(Measurement::new(t, kind))
    }
}

impl World for FleetWorld {
    fn vehicles(&self) -> usize {
        self.auvs.len()
    }

    fn steps(&self) -> usize {
        self.s.steps()
    }

    fn t_s(&self, k: usize) -> f64 {
        k as f64 * self.dt()
    }

    fn truth(&self, v: usize) -> VehicleTruth {
        let a = &self.auvs[v];
        let p = a.truth.position_ned_m;
        VehicleTruth {
            eta: nalgebra::Vector6::new(p.x, p.y, p.z, 0.0, a.truth.pitch_rad, a.truth.heading_rad),
            speed_m_s: a.truth.speed_over_ground(),
            distance_m: a.distance_m,
        }
    }

    fn beacon_ned_m(&self) -> Vector3<f64> {
        let t = self.t_s(self.k);
        let from = self.s.scheduled(t).map_or(Transmitter::Boat, |e| e.from);
        self.beacon_at(from, t)
    }

    fn pilots(&self, out: &mut Vec<PilotRecord>) {
        for (v, a) in self.auvs.iter().enumerate() {
            out.push(PilotRecord {
                vehicle: Some(v),
                command: Command {
                    heading_rad: a.setpoint.heading_rad,
                    speed_m_s: a.setpoint.speed_m_s,
                    depth_m: Some(a.setpoint.depth_m),
                },
                heading_rad: a.truth.heading_rad,
                speed_m_s: a.truth.speed_m_s,
                depth_m: a.truth.position_ned_m.z,
                mode: a.mode,
                phase: Some(a.phase),
            });
        }
    }

    /// An AUV in the water decides every step, on its navigators alone.
    fn situation(&mut self, k: usize, h: usize) -> Option<Situation> {
        let t1 = self.t_s(k);
        (t1 >= self.auvs[h].launch_s).then_some(Situation { t_s: t1, fix: None })
    }

    fn advance(&mut self, k: usize, commands: &[Option<VehicleCommand>], heard: &mut [Vec<Measurement>]) {
        self.k = k;
        let dt = self.dt();
        let t1 = self.t_s(k);
        // the beacon transmits at its epochs
        while self.next_ping_s <= t1 {
            let t_tx = self.next_ping_s;
            self.next_ping_s += self.s.mission.ping_period_s;
            if let Some(e) = self.s.scheduled(t_tx).filter(|e| e.mode > 0) {
                let (mode, from) = (e.mode - 1, e.from);
                self.sent.push(Sent { t_tx, source: self.beacon_at(from, t_tx), mode, from });
            }
        }
        // pings whose capture window has closed are heard
        let due: Vec<Sent> = self.sent.iter().copied().filter(|p| p.t_tx + WINDOW_S <= t1).collect();
        self.sent.retain(|p| p.t_tx + WINDOW_S > t1);
        for p in &due {
            let tx_clock_s = self.beacon_clocks[p.from as usize].error_s(p.t_tx);
            let gps = match p.from {
                Transmitter::Boat => {
                    let s = self.s.dock.gps_sigma_m;
                    p.source + Vector3::new(gauss(&mut self.gps_rng, s), gauss(&mut self.gps_rng, s), 0.0)
                }
                Transmitter::Dock => p.source,
            };
            for (v, h) in heard.iter_mut().enumerate() {
                if let Some(m) = self.hear(v, p, gps, tx_clock_s) {
                    h.push(m);
                }
            }
        }
        let params = self.s.sandshark.clone();
        let current = self.water.as_mut().map(|w| w.step(dt));
        for (v, a) in self.auvs.iter_mut().enumerate() {
            if t1 < a.launch_s {
                continue; // not in the water yet
            }
            if let Some(Some(VehicleCommand::Setpoint { setpoint, mode, phase })) = commands.get(v) {
                (a.setpoint, a.mode, a.phase) = (*setpoint, *mode, *phase);
            }
            a.truth.step(&params, &a.setpoint, dt);
            if let Some(c) = current {
                a.truth.position_ned_m += c * dt;
            }
            a.distance_m += a.truth.speed_over_ground() * dt;
            a.errors.advance(&params, dt, &mut a.imu_rng);
            let rng = &mut a.imu_rng;
            let white = params.attitude_white_deg.to_radians();
            let sog = a.truth.speed_m_s * (1.0 + a.errors.speed_scale) * a.truth.pitch_rad.cos(); // eq. 1
            let mut speed = if a.truth.thrusting { (sog + gauss(rng, params.speed_white_m_s)).max(0.0) } else { 0.0 };
            let mut heading =
                a.truth.heading_rad + a.errors.heading_rad + gauss(rng, params.heading_white_deg.to_radians());
            if let Some(d) = &mut a.drift {
                (speed, heading) = (d.speed(t1, speed), d.heading(t1, heading));
            }
            let h = &mut heard[v];
            h.push(Measurement::new(t1, Kind::Speed { speed_m_s: speed }));
            h.push(Measurement::new(
                t1,
                Kind::Attitude {
                    roll_rad: gauss(rng, white),
                    pitch_rad: a.truth.pitch_rad + gauss(rng, white),
                    heading_rad: onebeacon::geo::wrap_angle(heading),
                },
            ));
            let depth = a.truth.position_ned_m.z + gauss(rng, params.depth_white_m);
            h.push(Measurement::new(t1, Kind::Depth { depth_m: depth }));
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::acoustics::clock::ClockErrors;
    use crate::acoustics::link::LinkErrors;
    use crate::scenario::{Scenario, builtin, parse};
    use crate::water::Current;

    /// rypkema-m1 as built in.
    fn m1() -> Fleet {
        let Scenario::Fleet(s) = parse(builtin("rypkema-m1").unwrap().toml, "m1").unwrap() else { unreachable!() };
        s
    }

    /// Every one of `auvs` AUVs told to dive to 2.5 m and hold `heading_rad` at 1 m/s.
    fn dive(heading_rad: f64, auvs: usize) -> Vec<Option<VehicleCommand>> {
        let setpoint = Setpoint { heading_rad, speed_m_s: 1.0, depth_m: 2.5 };
        vec![Some(VehicleCommand::Setpoint { setpoint, mode: None, phase: Phase::Waiting }); auvs]
    }

    /// Run 0 of `s` for 300 s, every AUV diving on heading 0.5 rad, `each` shown the world
    /// and what every AUV heard after each step; the world at the end.
    fn dive_300_s(s: &Fleet, mut each: impl FnMut(&FleetWorld, usize, &[Vec<Measurement>])) -> FleetWorld {
        let mut w = FleetWorld::new(s, 1, 0);
        let commands = dive(0.5, w.auvs.len());
        for k in 1..=(300.0 / w.dt()).round() as usize {
            let mut heard = vec![Vec::new(); w.auvs.len()];
            w.advance(k, &commands, &mut heard);
            each(&w, k, &heard);
        }
        w
    }

    /// Abstract pings without noise in a sea of offset clocks and a lossy link: every
    /// range heard reads the true one plus c times the AUV's clock less the beacon's
    /// (1e-9 m), and 30 % of the pings a clean link hears on the same tracks are lost
    /// (5 binomial standard errors). An array mounted 2 deg off in yaw reads every
    /// azimuth 2 deg less, its inclination unchanged (1e-9 rad).
    #[test]
    fn clocks_the_link_and_a_misaligned_array_reach_the_abstract_pings() {
        let text = builtin("rypkema-m1").unwrap().toml.replace("model = \"channel\"", "model = \"abstract\"");
        let Scenario::Fleet(mut s) = parse(&text, "m1").unwrap() else { unreachable!() };
        (s.signal.range_sigma_m, s.signal.outlier_probability, s.dock.gps_sigma_m) = (0.0, 0.0, 0.0);
        s.sea.clocks = ClockErrors { offset_sigma_s: 1e-3, ..ClockErrors::default() };
        let heard = |link: LinkErrors, yaw_deg: f64| {
            let mut s = s.clone();
            s.sea.link = link;
            s.sea.usbl.misalignment_deg = [0.0, 0.0, yaw_deg];
            let mut w = FleetWorld::new(&s, 1, 0);
            let c = s.signal.sound_speed_m_s;
            let beacon_s = w.beacon_clocks[0].error_s(0.0);
            let commands = dive(0.0, w.auvs.len());
            let mut heard = Vec::new();
            for k in 1..=6000 {
                let before: Vec<Vector3<f64>> = w.auvs.iter().map(|a| a.truth.position_ned_m).collect();
                let mut out = vec![Vec::new(); w.auvs.len()];
                w.advance(k, &commands, &mut out);
                for (v, ms) in out.iter().enumerate() {
                    for m in ms {
                        let Kind::ArrayFix { beacon, range_m, azimuth_rad, inclination_rad, .. } = m.kind else {
                            continue;
                        };
                        heard.push((azimuth_rad, inclination_rad));
                        let auv_s = w.auvs[v].clock.error_s(m.t_s);
                        let r = (beacon.position_ned_m - before[v]).norm();
                        assert!((range_m - r - c * (auv_s - beacon_s)).abs() < 1e-9, "{v} at {}", m.t_s);
                    }
                }
            }
            heard
        };
        let all = heard(LinkErrors::default(), 0.0);
        let kept = heard(LinkErrors { loss_prob: 0.3, ..LinkErrors::default() }, 0.0).len();
        for ((a0, i0), (a, i)) in all.iter().zip(&heard(LinkErrors::default(), 2.0)) {
            assert!((onebeacon::geo::wrap_angle(a - a0) + 2f64.to_radians()).abs() < 1e-9 && (i - i0).abs() < 1e-9);
        }
        let all = all.len();
        let p = kept as f64 / all as f64;
        assert!(all > 500 && (p - 0.7).abs() < 5.0 * (0.21 / all as f64).sqrt(), "{kept} of {all}");
    }

    /// A current of 0.1 m/s toward the east carries every AUV over ground: after 300 s
    /// under the same commands, each is 0.1 m/s times its time in the water further east
    /// than in still water, and no further north (1e-9 m); AUVs not yet launched stay.
    #[test]
    fn a_current_carries_the_auvs() {
        let s = m1();
        let end = |current: Current| {
            let mut s = s.clone();
            s.sea.current = current;
            // an AUV moves on every step from its launch on
            let mut in_water = vec![0.0; s.auvs.len()];
            let w = dive_300_s(&s, |w, k, _| {
                for (t, a) in in_water.iter_mut().zip(&w.auvs) {
                    *t += if w.t_s(k) >= a.launch_s { w.dt() } else { 0.0 };
                }
            });
            w.auvs.iter().zip(in_water).map(|(a, t)| (a.truth.position_ned_m, t)).collect::<Vec<_>>()
        };
        let still = end(Current::default());
        let carried = end(Current { speed_m_s: 0.1, toward_deg: 90.0, ..Current::default() });
        for ((p0, in_water), (p, _)) in still.iter().zip(&carried) {
            let d = p - p0;
            assert!(
                d.x.abs() < 1e-9 && (d.y - 0.1 * in_water).abs() < 1e-9 && d.z.abs() < 1e-9,
                "{d:?} after {in_water} s"
            );
        }
        assert!(carried.iter().any(|(_, t)| *t > 100.0));
    }

    /// `[sea.sensors]` on the AUVs against the same run without: every speed read is the
    /// clean one times one scale per AUV (1e-12), not 1; every heading differs from the
    /// clean one by a bias that barely moves with a 1e7 s time constant (under 0.01 rad
    /// over 300 s).
    #[test]
    fn drifting_sensors_reach_the_auvs() {
        let s = m1();
        let read = |sensors: DriftErrors| {
            let mut s = s.clone();
            s.sea.sensors = sensors;
            let mut out = Vec::new();
            dive_300_s(&s, |_, _, heard| {
                for (v, ms) in heard.iter().enumerate() {
                    let (mut u, mut psi) = (None, None);
                    for m in ms {
                        match m.kind {
                            Kind::Speed { speed_m_s } => u = Some(speed_m_s),
                            Kind::Attitude { heading_rad, .. } => psi = Some(heading_rad),
                            _ => {}
                        }
                    }
                    if let (Some(u), Some(psi)) = (u, psi) {
                        out.push((v, u, psi));
                    }
                }
            });
            out
        };
        let base = read(DriftErrors::default());
        let drifted = read(DriftErrors {
            speed_scale_sigma: 0.05,
            heading_bias_sigma_deg: 2.0,
            heading_bias_time_constant_s: 1e7,
            ..DriftErrors::default()
        });
        assert_eq!(base.len(), drifted.len());
        let mut first: Vec<Option<(f64, f64)>> = vec![None; s.auvs.len()];
        for ((v, u0, p0), (_, u, p)) in base.iter().zip(&drifted) {
            if *u0 <= 1e-6 {
                continue;
            }
            let (scale, bias) = *first[*v].get_or_insert((u / u0, onebeacon::geo::wrap_angle(p - p0)));
            assert!((scale - 1.0).abs() > 1e-4 && bias.abs() > 1e-4, "{v}: scale {scale}, bias {bias}");
            assert!((u / u0 - scale).abs() < 1e-12, "{v}: {u} against {u0}");
            assert!((onebeacon::geo::wrap_angle(p - p0) - bias).abs() < 0.01, "{v}");
        }
        assert!(first.iter().all(Option::is_some));
    }
}
