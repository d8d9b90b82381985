//! The simulation engine: one loop for every world.
//!
//! Each step: the controller of every vehicle's computer ([`Aboard`]: the onboard
//! crate's [`Unit`], the one `onebeacon stream` runs on a vehicle) decides on what its
//! vehicle knows of itself and on its navigators' beliefs; the [`World`] moves the
//! truth of its vehicles and beacons one step under those commands and says which
//! measurements each underwater vehicle received during it; the engine pushes them, in
//! order, into the session of every computer that estimates that vehicle, as `stream`
//! takes a line, and predicts every session to the step's time. Then it shows the step
//! to the [`Observer`]s: error statistics, recording, guidance snapshots, information
//! for the bound. A world holds no estimator, controller or scoring code, an observer
//! no world code, so a new estimator runs in every world and a new world scores every
//! estimator.

use nalgebra::{Vector3, Vector6};
use onebeacon::nav::session::{Input, Item};
use onebeacon::nav::{Estimate, Measurement, Navigator, Outcome};
use onebeacon::vehicle::unit::Unit;
use onebeacon::vehicle::{Command, Decided, Situation};

/// The truth of one underwater vehicle at one step.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct VehicleTruth {
    /// NED position and roll, pitch, yaw (rad, yaw not wrapped).
    pub eta: Vector6<f64>,
    /// Speed over ground, m/s.
    pub speed_m_s: f64,
    /// Distance travelled since the start, m.
    pub distance_m: f64,
}

/// What a dynamic vehicle's autopilots were commanded at the end of one step, and
/// what the vehicle did: heading (rad), surge speed (m/s), depth (m).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PilotRecord {
    /// The underwater vehicle's index, or None for the beacon's surface vehicle.
    pub vehicle: Option<usize>,
    pub command: crate::vehicles::autopilot::Command,
    pub heading_rad: f64,
    pub speed_m_s: f64,
    pub depth_m: f64,
    /// A fleet AUV's confirmed command mode (index into the bank) and what its autonomy
    /// does (None elsewhere).
    pub mode: Option<usize>,
    pub phase: Option<onebeacon::vehicle::Phase>,
}

impl PilotRecord {
    pub(crate) fn of(
        vehicle: Option<usize>,
        command: crate::vehicles::autopilot::Command,
        body: &crate::vehicles::rigid_body::BodyState,
    ) -> Self {
        Self {
            vehicle,
            command,
            heading_rad: body.euler().2,
            speed_m_s: body.nu[0],
            depth_m: body.position_ned_m.z,
            mode: None,
            phase: None,
        }
    }
}

/// A world: its truth, its beacons, and the acoustic channel that decides who hears
/// what, when.
pub(crate) trait World {
    /// Number of underwater vehicles (each with every estimator of the scenario).
    fn vehicles(&self) -> usize;
    /// Steps after the start.
    fn steps(&self) -> usize;
    /// Time of step `k`, s.
    fn t_s(&self, k: usize) -> f64;
    /// The truth of vehicle `v` now.
    fn truth(&self, v: usize) -> VehicleTruth;
    /// Where the beacon is now.
    fn beacon_ned_m(&self) -> Vector3<f64>;
    /// Appends what the dynamic vehicles' autopilots were last commanded, and what the
    /// vehicles do now (none in a world of kinematic vehicles).
    fn pilots(&self, _out: &mut Vec<PilotRecord>) {}
    /// What the vehicle of helm `h` knows of itself at the start of the move from step
    /// `k - 1` to `k` when its controller decides now (its clock, a surface vehicle's
    /// GPS and compass); None: it keeps its last command. Helm `h` is the `h`-th
    /// computer with a controller; a world of no helm has none.
    fn situation(&mut self, _k: usize, _h: usize) -> Option<Situation> {
        None
    }
    /// Moves from step `k - 1` to `k` under each helm's last command (None before its
    /// first) and appends to `heard[v]` what was measured of vehicle `v` during the step,
    /// in the order its estimators must process it.
    fn advance(&mut self, k: usize, commands: &[Option<Command>], heard: &mut [Vec<Measurement>]);
}

/// A vehicle's computer in a world: the [`Unit`] it runs (what `onebeacon stream` runs
/// on the vehicle: its sessions of estimators, its controller) and, for each of its
/// sessions, the world's vehicle it estimates.
pub(crate) struct Aboard {
    pub unit: Unit,
    pub vehicles: Vec<usize>,
}

impl Aboard {
    /// The first navigator that estimates vehicle `v` on this computer.
    pub(crate) fn navigator_of(&self, v: usize) -> Option<&dyn Navigator> {
        let i = self.vehicles.iter().position(|&w| w == v)?;
        self.unit.session(i).navigator(0)
    }
}

/// The vehicle each track estimates: a track is one estimator of one session of one
/// computer, in that order.
pub(crate) fn vehicle_of(computers: &[Aboard]) -> Vec<usize> {
    let sessions = computers.iter().flat_map(|c| c.vehicles.iter().enumerate().map(move |(i, &v)| (c, i, v)));
    sessions.flat_map(|(c, i, v)| std::iter::repeat_n(v, c.unit.session(i).names.len())).collect()
}

/// What observers see of one step.
pub(crate) struct Step<'a> {
    pub k: usize,
    pub t_s: f64,
    /// Per vehicle.
    pub truth: &'a [VehicleTruth],
    pub heard: &'a [Vec<Measurement>],
    pub beacon_ned_m: Vector3<f64>,
    pub pilots: &'a [PilotRecord],
    /// Per track: which vehicle it is on, and its estimate now.
    pub vehicle_of: &'a [usize],
    pub estimates: &'a [Estimate],
}

/// Something that watches a run.
pub(crate) trait Observer {
    fn step(&mut self, step: &Step<'_>);
    /// Helm `helm`'s decision (the controller of the `helm`-th computer that has one) on
    /// what its vehicle knew of itself.
    fn decided(&mut self, _helm: usize, _situation: &Situation, _decided: &Decided) {}
    /// Track `track`'s estimator stopped being sound and started again (the session's
    /// restart policy, [`onebeacon::nav::restart::Restart`]).
    fn restarted(&mut self, _track: usize) {}
    /// A computer estimating vehicle `vehicle` screened measurement `m` out (out of its
    /// limits or of time order, `reason`): none of its estimators saw it.
    fn screened(&mut self, _vehicle: usize, _m: &Measurement, _reason: &str) {}
    /// The outcome of track `track`'s processing of measurement `m`.
    fn outcome(&mut self, _track: usize, _m: &Measurement, _outcome: &Outcome) {}
    /// Every computer as it stands at step `k` (before [`Observer::step`]), for an
    /// observer that records more of a navigator than its estimate (a particle cloud).
    fn inspect(&mut self, _k: usize, _computers: &[Aboard]) {}
}

/// Runs `world` from its start to its last step with its vehicles' `computers`, shown
/// to `observers`. A track is one estimator of one session of one computer, in that
/// order. Every measurement goes to the computers as `stream` takes a line, screened
/// alike ([`Unit::take`]): one out of the computer's limits or of time order reaches no
/// estimator, as on the vehicle. Estimates are asked for, and the restart policy
/// applied, at each step's time ([`Unit::predict_to`]).
pub(crate) fn run(world: &mut dyn World, computers: &mut [Aboard], observers: &mut [&mut dyn Observer]) {
    let vehicles = world.vehicles();
    for c in computers.iter_mut() {
        assert!(c.unit.start_by(0.0), "a world's computers start at time 0");
    }
    let vehicle_of = vehicle_of(computers);
    let helm_of: Vec<usize> = (0..computers.len()).filter(|&c| computers[c].unit.has_controller()).collect();
    let mut heard = vec![Vec::new(); vehicles];
    let mut truth: Vec<VehicleTruth> = (0..vehicles).map(|v| world.truth(v)).collect();
    let mut estimates: Vec<Estimate> =
        computers.iter().flat_map(|c| c.unit.sessions()).flat_map(|s| s.final_estimates()).collect();
    let mut pilots = Vec::new();
    let mut commands = vec![None; helm_of.len()];
    let mut k = 0;
    loop {
        observers.iter_mut().for_each(|o| o.inspect(k, computers));
        pilots.clear();
        world.pilots(&mut pilots);
        let step = Step {
            k,
            t_s: world.t_s(k),
            truth: &truth,
            heard: &heard,
            beacon_ned_m: world.beacon_ned_m(),
            pilots: &pilots,
            vehicle_of: &vehicle_of,
            estimates: &estimates,
        };
        observers.iter_mut().for_each(|o| o.step(&step));
        if k == world.steps() {
            return;
        }
        k += 1;
        heard.iter_mut().for_each(Vec::clear);
        for (h, &c) in helm_of.iter().enumerate() {
            let Some(situation) = world.situation(k, h) else { continue };
            let unit = &mut computers[c].unit;
            if let Some(fix) = situation.fix {
                unit.set_fix(fix);
            }
            let decided = unit
                .decide(situation.t_s)
                .expect("a computer with a controller decides")
                .expect("a world gives its helms what they read");
            commands[h] = Some(decided.command);
            observers.iter_mut().for_each(|o| o.decided(h, &situation, &decided));
        }
        world.advance(k, &commands, &mut heard);
        let t_s = world.t_s(k);
        let mut first = 0;
        for c in computers.iter_mut() {
            // the computer's first track
            let own = first;
            for (i, &v) in c.vehicles.iter().enumerate() {
                for m in &heard[v] {
                    let item = Item { t_s: m.t_s, input: Input::Measurement(m.kind.clone()) };
                    let done = match c.unit.take(i, &item) {
                        Ok(Some(done)) => done,
                        Ok(None) => continue,
                        Err(screened) => {
                            observers.iter_mut().for_each(|o| o.screened(v, m, &screened.reason));
                            continue;
                        }
                    };
                    for (j, out) in done.outcomes.iter().enumerate() {
                        if let Some(out) = out {
                            observers.iter_mut().for_each(|o| o.outcome(first + j, m, out));
                        }
                    }
                }
                first += c.unit.session(i).names.len();
            }
            // scored at the step's time, also when no message reached it
            let again = c.unit.predict_to(t_s, &mut estimates[own..first]).expect("started at time 0");
            for j in again {
                observers.iter_mut().for_each(|o| o.restarted(own + j));
            }
        }
        for (v, tr) in truth.iter_mut().enumerate() {
            *tr = world.truth(v);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use onebeacon::geo::Frame;
    use onebeacon::nav::Kind;
    use onebeacon::nav::restart::Builder;
    use onebeacon::nav::session::{Session, Start};
    use std::sync::Arc;
    use std::sync::atomic::{AtomicUsize, Ordering};

    /// A dead-reckoning navigator whose state turns to NaN when it processes anything.
    struct Fragile {
        inner: Box<dyn Navigator>,
        broken: bool,
    }

    impl Navigator for Fragile {
        fn process(&mut self, _: &Measurement) -> Outcome {
            self.broken = true;
            Outcome::Applied
        }
        fn estimate(&self) -> Estimate {
            let mut e = self.inner.estimate();
            if self.broken {
                e.position_ned_m.x = f64::NAN;
            }
            e
        }
    }

    /// One vehicle that hears one speed (m/s) a step for three steps.
    struct Still(f64);

    impl World for Still {
        fn vehicles(&self) -> usize {
            1
        }
        fn steps(&self) -> usize {
            3
        }
        fn t_s(&self, k: usize) -> f64 {
            k as f64
        }
        fn truth(&self, _: usize) -> VehicleTruth {
            VehicleTruth { eta: Vector6::zeros(), speed_m_s: 0.0, distance_m: 0.0 }
        }
        fn beacon_ned_m(&self) -> Vector3<f64> {
            Vector3::zeros()
        }
        fn advance(&mut self, k: usize, _: &[Option<Command>], heard: &mut [Vec<Measurement>]) {
            heard[0].push(Measurement::new(k as f64, Kind::Speed { speed_m_s: self.0 }));
        }
    }

    /// The restarts and the screened measurements a run shows.
    #[derive(Default)]
    struct Told {
        restarts: Vec<usize>,
        screened: Vec<(usize, String)>,
    }

    impl Observer for Told {
        fn step(&mut self, _: &Step<'_>) {}
        fn restarted(&mut self, track: usize) {
            self.restarts.push(track);
        }
        fn screened(&mut self, vehicle: usize, _: &Measurement, reason: &str) {
            self.screened.push((vehicle, reason.to_string()));
        }
    }

    /// A computer of one session of `builder`, on vehicle 0, started at (5, -3, 0.2).
    fn computer(builder: Builder) -> Aboard {
        let start = Start::At { t0_s: Some(0.0), pose: (5.0, -3.0, 0.2) };
        let session = Session::new(Frame::Ned, vec![("only".into(), builder)], start, (1.0, 0.1), None);
        Aboard { unit: Unit::new(vec![session], Default::default(), Frame::Ned, None), vehicles: vec![0] }
    }

    /// The engine applies the session's policy: an estimator whose state stops being
    /// sound is built again from its last sound pose at the step's time, and observers
    /// are told; every speed breaks it again here, so three steps, three restarts.
    #[test]
    fn an_unsound_estimator_starts_again_as_in_the_session() {
        let builds = Arc::new(AtomicUsize::new(0));
        let counted = builds.clone();
        let planar = onebeacon::nav::planar::builder(Default::default(), onebeacon::filter::FilterKind::Ekf);
        let builder: Builder = Box::new(move |t0, at, sp, sh| {
            counted.fetch_add(1, Ordering::SeqCst);
            Box::new(Fragile { inner: planar(t0, at, sp, sh), broken: false })
        });
        let mut computers = vec![computer(builder)];
        let mut told = Told::default();
        run(&mut Still(1.0), &mut computers, &mut [&mut told]);
        assert_eq!(told.restarts, [0, 0, 0]);
        assert!(told.screened.is_empty());
        assert_eq!(builds.load(Ordering::SeqCst), 4);
        let e = computers[0].unit.session(0).navigator(0).unwrap().estimate();
        assert_eq!((e.north_m(), e.east_m(), e.heading_rad(), e.t_s), (5.0, -3.0, 0.2, 3.0));
    }

    /// A measurement out of the computer's limits (a speed of 25 m/s against
    /// `limits.max_speed_m_s` = 20) reaches no estimator, as on the vehicle, and the
    /// observers are told why: the dead reckoning stays where it started.
    #[test]
    fn a_measurement_out_of_the_limits_reaches_no_estimator() {
        let planar = onebeacon::nav::planar::builder(Default::default(), onebeacon::filter::FilterKind::Ekf);
        let mut computers = vec![computer(planar)];
        let mut told = Told::default();
        run(&mut Still(25.0), &mut computers, &mut [&mut told]);
        assert_eq!(told.screened.len(), 3, "{:?}", told.screened);
        assert!(
            told.screened.iter().all(|(v, r)| *v == 0 && r.contains("limits.max_speed_m_s")),
            "{:?}",
            told.screened
        );
        let e = computers[0].unit.session(0).navigator(0).unwrap().estimate();
        assert_eq!((e.north_m(), e.east_m()), (5.0, -3.0));
    }
}
