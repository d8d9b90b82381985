//! The fixed-beacon world (garin2024): an AUV following a boustrophedon under the
//! feedback-linearising controller, a fixed beacon, communication frames every T_com.

use crate::acoustics::clock::Clock;
use crate::acoustics::link::Link;
use crate::engine::{VehicleTruth, World};
use crate::scenario::sea::FIXED_BEACON_SOUND_SPEED_M_S;
use crate::scenario::{FixedBeacon, FixedBeaconCell};
use crate::seed::{Stream, rng};
use crate::sensor_errors::{DriftingSensors, SensorErrors};
use crate::sensors::SensorSuite;
use crate::vehicles::{Path, TruthState, feedback_linearising_control};
use crate::water::Water;
use nalgebra::{Vector2, Vector3, Vector6};
use onebeacon::geo::wrap_angle;
use onebeacon::models::unicycle::State;
use onebeacon::nav::{Kind, Measurement};
use onebeacon::vehicle::Command;

pub(crate) struct FixedBeaconWorld {
    dt: f64,
    speed: f64,
    steps: usize,
    t_com_s: f64,
    path: Path,
    beacon: Vector2<f64>,
    truth: TruthState,
    /// The command computed at the last step, applied over the next (eq. 2).
    omega: f64,
    accel: f64,
    sensors: SensorSuite,
    /// The AUV's clock and the beacon's: their difference is a range error.
    clocks: [Clock; 2],
    /// The AUV's acoustic link: losses and outliers.
    link: Link,
    /// The AHRS heading's wandering bias (`[sea.sensors]`; None: off, so that the
    /// heading is not wrapped twice).
    drift: Option<DriftingSensors>,
    /// The water's current (`[sea.current]`), when it flows: it carries the AUV over
    /// ground, where its accelerometer and gyro see only its motion through the water.
    water: Option<Water>,
    /// Frames sent so far.
    frame_index: u64,
    distance_m: f64,
}

impl FixedBeaconWorld {
    pub(crate) fn new(s: &FixedBeacon, cell: &FixedBeaconCell, seed: u64, run: u64) -> Self {
        let speed = s.mission.speed_m_s;
        let path = s.path();
        let r0 = path.at_time(0.0, speed);
        let truth = TruthState { pos: r0.pos, psi: r0.vel.y.atan2(r0.vel.x), v: speed };
        let (omega, accel) = feedback_linearising_control(&truth, &r0);
        Self {
            dt: s.mission.dt_s,
            speed,
            steps: s.steps(),
            t_com_s: cell.t_com_s,
            path,
            beacon: s.beacon_ned_m(),
            truth,
            omega,
            accel,
            sensors: SensorSuite::new(&s.sensors, s.comms.frame_loss_prob, seed, run),
            clocks: [Stream::Clock, Stream::BeaconClock].map(|c| Clock::new(&s.sea.clocks, rng(seed, run, c))),
            link: Link::new(&s.sea.link, rng(seed, run, Stream::Link)),
            drift: (s.sea.sensors != SensorErrors::default())
                .then(|| DriftingSensors::new(&s.sea.sensors, rng(seed, run, Stream::Sensors))),
            water: s.sea.current.flows().then(|| Water::new(s.sea.current.clone(), rng(seed, run, Stream::Current))),
            frame_index: 0,
            distance_m: 0.0,
        }
    }

    /// The AUV's truth now in the unicycle state layout [x, y, psi, v, Omega, a].
    pub(crate) fn unicycle_state(&self) -> State {
        let t = &self.truth;
        State::from([t.pos.x, t.pos.y, t.psi, t.v, self.omega, self.accel])
    }
}

impl World for FixedBeaconWorld {
    fn vehicles(&self) -> usize {
        1
    }

    fn steps(&self) -> usize {
        self.steps
    }

    fn t_s(&self, k: usize) -> f64 {
        k as f64 * self.dt
    }

    fn truth(&self, _v: usize) -> VehicleTruth {
        let t = &self.truth;
        VehicleTruth {
            eta: Vector6::new(t.pos.x, t.pos.y, 0.0, 0.0, 0.0, t.psi),
            speed_m_s: t.v,
            distance_m: self.distance_m,
        }
    }

    fn beacon_ned_m(&self) -> Vector3<f64> {
        Vector3::new(self.beacon.x, self.beacon.y, 0.0)
    }

    fn advance(&mut self, k: usize, _: &[Option<Command>], heard: &mut [Vec<Measurement>]) {
        let t = self.t_s(k);
        // truth moves under the command of the previous step (eq. 3-4), then a new
        // command is computed from the reference (eq. 2)
        self.truth = self.truth.step(self.omega, self.accel, self.dt);
        let current = self.water.as_mut().map(|w| w.step(self.dt).xy());
        if let Some(c) = current {
            self.truth.pos += c * self.dt;
        }
        self.distance_m += self.truth.v.abs() * self.dt;
        (self.omega, self.accel) = feedback_linearising_control(&self.truth, &self.path.at_time(t, self.speed));

        let mut sample = self.sensors.proprioceptive(t, &self.truth, self.omega, self.accel);
        if let (Some(drift), Kind::Inertial { heading_rad, .. }) = (&mut self.drift, &mut sample) {
            *heading_rad = wrap_angle(drift.heading(t, *heading_rad));
        }
        // a frame every T_com seconds, at the first step at or after each multiple; a
        // frame decoded during the step is fused with the step's inertial sample
        let due = ((t + 1e-9) / self.t_com_s).floor() as u64;
        if due > self.frame_index {
            self.frame_index = due;
            // the travel time read between the beacon's clock at transmission and the
            // AUV's at reception
            let c = FIXED_BEACON_SOUND_SPEED_M_S;
            let t_tx = t - (self.truth.pos - self.beacon).norm() / c;
            let [auv, beacon] = &mut self.clocks;
            let clock_m = c * (auv.error_s(t) - beacon.error_s(t_tx));
            // lost, or heard on another path
            let frame = self.sensors.comm_frame(&self.truth, self.beacon, clock_m).and_then(|mut frame| {
                if let Kind::RangeDoppler { range_m, radial_speed_m_s, .. } = &mut frame {
                    *range_m = self.link.hear(*range_m)?;
                    // the Doppler shift is of the speed over ground: the current's share
                    // toward the beacon (eq. 13 has the speed through the water)
                    if let Some(c) = current {
                        *radial_speed_m_s += c.dot(&(self.beacon - self.truth.pos).normalize());
                    }
                }
                Some(frame)
            });
            if let Some(frame) = frame {
                heard[0].push(Measurement::new(t, frame));
            }
        }
        heard[0].push(Measurement::new(t, sample));
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::run::simulate;
    use crate::scenario::Cell;
    use crate::scenario::fixed_beacon::Sensors;
    use crate::scenario::{Scenario, builtin, parse};
    use crate::water::Current;

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
        let a = simulate(&Scenario::FixedBeacon(s.clone()), &Cell::FixedBeacon(c), 5, 3, true);
        let b = simulate(&Scenario::FixedBeacon(s.clone()), &Cell::FixedBeacon(c), 5, 3, true);
        let other = simulate(&Scenario::FixedBeacon(s.clone()), &Cell::FixedBeacon(c), 5, 4, false);
        assert_eq!(a, b);
        assert_ne!(a.metrics, other.metrics);
        assert_eq!(a.trajectory.len(), 481);
        assert_eq!(a.frames_decoded, 40);
    }

    /// A current of 0.3 m/s toward the north (noise-free sensors): every Doppler speed is
    /// the speed over ground toward the beacon, the AUV's own v along its heading plus the
    /// current (1e-9 m/s), and the AUV is carried off the still-water track (by 0.6 m
    /// at most in 300 s, 0.3 m/s for 2 s: its controller sees the truth and steers back,
    /// crabbing into the current; asserted above 0.3 m, none in still water).
    #[test]
    fn a_current_carries_the_auv_and_shows_in_the_doppler() {
        let track = |current: Current| {
            let mut s = garin();
            s.sensors = Sensors::noise_free();
            let flows = current.flows();
            s.sea.current = current;
            let mut world = FixedBeaconWorld::new(&s, &s.base_cell(), 1, 0);
            let mut out = Vec::new();
            for k in 1..=1200 {
                let mut heard = vec![Vec::new()];
                world.advance(k, &[], &mut heard);
                for m in &heard[0] {
                    if let Kind::RangeDoppler { radial_speed_m_s, .. } = m.kind {
                        let t = &world.truth;
                        let ground = Vector2::new(t.psi.cos(), t.psi.sin()) * t.v + Vector2::new(0.3, 0.0);
                        let toward = (world.beacon - t.pos).normalize();
                        if flows {
                            assert!((radial_speed_m_s - ground.dot(&toward)).abs() < 1e-9, "at {} s", m.t_s);
                        }
                    }
                }
                out.push(world.truth.pos);
            }
            out
        };
        let still = track(Current::default());
        let carried = track(Current { speed_m_s: 0.3, ..Current::default() });
        let off = still.iter().zip(&carried).map(|(a, b)| (a - b).norm()).fold(0.0, f64::max);
        assert!(off > 0.3, "{off} m");
    }

    /// `[sea.sensors]`'s heading bias on the AHRS against the same run without: each
    /// heading read differs from the clean one by the bias (a 1e7 s time constant: it
    /// moves by under 0.01 rad over 300 s), which is not zero.
    #[test]
    fn the_heading_bias_reaches_the_ahrs() {
        let headings = |sensors: SensorErrors| {
            let mut s = garin();
            s.sea.sensors = sensors;
            let mut world = FixedBeaconWorld::new(&s, &s.base_cell(), 1, 0);
            let mut out = Vec::new();
            for k in 1..=1200 {
                let mut heard = vec![Vec::new()];
                world.advance(k, &[], &mut heard);
                out.extend(heard[0].iter().filter_map(|m| match m.kind {
                    Kind::Inertial { heading_rad, .. } => Some(heading_rad),
                    _ => None,
                }));
            }
            out
        };
        let base = headings(SensorErrors::default());
        let biased = headings(SensorErrors {
            heading_bias_sigma_deg: 2.0,
            heading_bias_time_constant_s: 1e7,
            ..SensorErrors::default()
        });
        assert_eq!(base.len(), 1200);
        let bias = wrap_angle(biased[0] - base[0]);
        assert!(bias.abs() > 1e-4, "bias {bias}");
        for (b, h) in base.iter().zip(&biased) {
            assert!((wrap_angle(h - b) - bias).abs() < 0.01, "{h} against {b}");
        }
    }

    /// Clocks that drift apart: with noise-free sensors a range's error is c times what
    /// the AUV's clock read at reception minus what the beacon's read at transmission, a
    /// straight line in time through zero when the clocks only drift (plus the beacon's
    /// drift over the travel time, under a centimetre here); 1 ppm apart is 5.4 m after
    /// an hour.
    #[test]
    fn drifting_clocks_make_a_range_error_that_grows_with_time() {
        let mut s = garin();
        s.sensors = Sensors::noise_free();
        s.mission.duration_s = Some(3600.0);
        s.sea.clocks.drift_sigma_ppm = 1.0;
        let mut world = FixedBeaconWorld::new(&s, &s.base_cell(), 1, 0);
        let mut errors = Vec::new();
        for k in 1..=world.steps() {
            let mut heard = vec![Vec::new()];
            world.advance(k, &[], &mut heard);
            for m in &heard[0] {
                if let onebeacon::nav::Kind::RangeDoppler { range_m, .. } = m.kind {
                    errors.push((m.t_s, range_m - (world.truth.pos - world.beacon).norm()));
                }
            }
        }
        let (t_end, e_end) = *errors.last().unwrap();
        let slope = e_end / t_end;
        assert!(e_end.abs() > 0.5, "the clocks drifted apart by {e_end} m in an hour");
        for (t, e) in &errors {
            assert!((e - slope * t).abs() < 0.01, "at {t} s: {e} m off the line {slope} m/s");
        }
    }

    /// The link loses frames besides the modem's own loss and puts its multipath excess
    /// on the ranges it keeps: with noise-free sensors, an hour of frames every 3 s
    /// (1200), half lost in bursts of 4 and every range long by an exponential excess of
    /// mean 10 m. The heard count is within 5 standard errors of 600 (a Markov chain's:
    /// variance 1200 p (1 - p) (1 + rho) / (1 - rho), rho = 0.5) and the mean excess
    /// within 5 of 10 m.
    #[test]
    fn the_link_loses_frames_and_lengthens_ranges() {
        let mut s = garin();
        s.sensors = Sensors::noise_free();
        s.mission.duration_s = Some(3600.0);
        s.comms.frame_loss_prob = 0.0;
        s.sea.link.loss_prob = 0.5;
        s.sea.link.loss_burst_mean = Some(4.0);
        s.sea.link.multipath_prob = 1.0;
        s.sea.link.multipath_excess_m = 10.0;
        let mut world = FixedBeaconWorld::new(&s, &s.base_cell(), 1, 0);
        let mut excess = Vec::new();
        for k in 1..=world.steps() {
            let mut heard = vec![Vec::new()];
            world.advance(k, &[], &mut heard);
            for m in &heard[0] {
                if let Kind::RangeDoppler { range_m, .. } = m.kind {
                    excess.push(range_m - (world.truth.pos - world.beacon).norm());
                }
            }
        }
        let n = excess.len() as f64;
        let se = (1200.0 * 0.25 * 3.0f64).sqrt();
        assert!((n - 600.0).abs() < 5.0 * se, "{n} frames heard of 1200");
        let mean = excess.iter().sum::<f64>() / n;
        assert!((mean - 10.0).abs() < 5.0 * 10.0 / n.sqrt(), "mean excess {mean} m");
        assert!(excess.iter().all(|e| *e >= 0.0));
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
            e.noise.range_sigma_m = Some(1e-3);
            e.noise.doppler_sigma_m_s = Some(1e-4);
            e.noise.heading_sigma_deg = Some(1e-4f64.to_degrees());
            e.unicycle.yaw_rate_sigma_rad_s = Some(1e-5);
            e.unicycle.accel_sigma_m_s2 = Some(1e-5);
        }
        // the UKF too
        let mut ukf = s.estimators[0].clone();
        ukf.filter = crate::scenario::FilterName::Ukf;
        s.estimators.push(ukf);
        let out = simulate(&Scenario::FixedBeacon(s.clone()), &Cell::FixedBeacon(s.base_cell()), 1, 0, false);
        // the whole path: its legs and the half circles between them (garin2024 4.1.1: 1567 m),
        // travelled for the steps that cover it (a whole number: half a step either way) at
        // the path speed, which the path follower holds to 0.1 % (measured: 0.024 %)
        let p = &s.path;
        let path_m =
            p.legs as f64 * p.leg_length_m + (p.legs - 1) as f64 * std::f64::consts::PI * p.leg_spacing_m / 2.0;
        let tolerance_m = 0.5 * s.mission.speed_m_s * s.mission.dt_s + 1e-3 * path_m;
        assert!((out.distance_m[0] - path_m).abs() <= tolerance_m, "distance {} against {path_m} m", out.distance_m[0]);
        for (e, m) in s.estimators.iter().zip(&out.metrics) {
            assert!(m.final_error_m < 0.01, "{}: final error {} m", e.name(), m.final_error_m);
            assert!(m.max_error_m < 0.01, "{}: max error {} m", e.name(), m.max_error_m);
        }
    }
}
