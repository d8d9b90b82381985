//! The simulation engine: one loop for every world.
//!
//! Each step: every [`Helm`] (a vehicle's controller from the onboard crate) decides on
//! what its vehicle knows of itself and on the beliefs of the vehicles it serves; the
//! [`World`] moves the truth of its vehicles and beacons one step under those commands
//! and says which measurements each underwater vehicle received during it; the engine
//! feeds them, in order, to every estimator ([`Track`]) of that vehicle through the
//! [`Navigator`] interface alone. Then it shows the step to the [`Observer`]s: error
//! statistics, recording, guidance snapshots, information for the bound. A world holds
//! no estimator, controller or scoring code, an observer no world code, so a new
//! estimator runs in every world and a new world scores every estimator.

use nalgebra::{Vector3, Vector6};
use onebeacon::nav::restart::{Builder, Restart};
use onebeacon::nav::{Estimate, Measurement, Navigator, Outcome};
use onebeacon::vehicle::{Command, Controller, Decided, Situation};

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
    /// GPS and compass); None: it keeps its last command. A world of no helm has none.
    fn situation(&mut self, _k: usize, _h: usize) -> Option<Situation> {
        None
    }
    /// Moves from step `k - 1` to `k` under each helm's last command (None before its
    /// first) and appends to `heard[v]` what was measured of vehicle `v` during the step,
    /// in the order its estimators must process it.
    fn advance(&mut self, k: usize, commands: &[Option<Command>], heard: &mut [Vec<Measurement>]);
}

/// A vehicle's controller, and the vehicles whose first estimator it reads (its own,
/// or those a surface vehicle serves).
pub(crate) struct Helm {
    pub controller: Box<dyn Controller>,
    pub serves: Vec<usize>,
}

/// One estimator on one vehicle, with the restart policy of an unsound estimator (the
/// session's: [`Restart`]).
pub(crate) struct Track {
    pub vehicle: usize,
    pub navigator: Box<dyn Navigator>,
    restart: Restart,
}

impl Track {
    /// The estimator `builder` gives at time 0 from `pose` (north, east, heading) with
    /// initial sigmas `sigmas` (position m, heading rad), on vehicle `vehicle`.
    pub(crate) fn new(vehicle: usize, builder: Builder, pose: (f64, f64, f64), sigmas: (f64, f64)) -> Self {
        let restart = Restart::new(builder, pose, sigmas);
        Self { vehicle, navigator: restart.build(0.0, pose), restart }
    }
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
    /// Helm `helm`'s decision on what its vehicle knew of itself.
    fn decided(&mut self, _helm: usize, _situation: &Situation, _decided: &Decided) {}
    /// Track `track`'s estimator stopped being sound and started again ([`Restart`]).
    fn restarted(&mut self, _track: usize) {}
    /// The outcome of track `track`'s processing of measurement `m`.
    fn outcome(&mut self, _track: usize, _m: &Measurement, _outcome: &Outcome) {}
    /// Every track's navigator as it stands at step `k` (before [`Observer::step`]),
    /// for an observer that records more than estimates (a particle cloud).
    fn inspect(&mut self, _k: usize, _tracks: &[Track]) {}
}

/// Runs `world` from its start to its last step with `tracks` and `helms`, shown to
/// `observers`.
pub(crate) fn run(
    world: &mut dyn World,
    tracks: &mut [Track],
    helms: &mut [Helm],
    observers: &mut [&mut dyn Observer],
) {
    let vehicles = world.vehicles();
    let vehicle_of: Vec<usize> = tracks.iter().map(|t| t.vehicle).collect();
    // the track each vehicle reports from: its first
    let reporter: Vec<usize> = (0..vehicles)
        .map(|v| vehicle_of.iter().position(|&w| w == v).expect("every vehicle has an estimator"))
        .collect();
    let mut heard = vec![Vec::new(); vehicles];
    let mut truth: Vec<VehicleTruth> = (0..vehicles).map(|v| world.truth(v)).collect();
    let mut estimates: Vec<Estimate> = tracks.iter().map(|t| t.navigator.estimate()).collect();
    let mut pilots = Vec::new();
    let mut commands = vec![None; helms.len()];
    let mut k = 0;
    loop {
        observers.iter_mut().for_each(|o| o.inspect(k, tracks));
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
        for (h, helm) in helms.iter_mut().enumerate() {
            let Some(situation) = world.situation(k, h) else { continue };
            let beliefs: Vec<&dyn Navigator> = helm.serves.iter().map(|&v| &*tracks[reporter[v]].navigator).collect();
            let decided = helm.controller.decide(&situation, &beliefs).expect("a world gives its helms what they read");
            commands[h] = Some(decided.command);
            observers.iter_mut().for_each(|o| o.decided(h, &situation, &decided));
        }
        world.advance(k, &commands, &mut heard);
        for (i, t) in tracks.iter_mut().enumerate() {
            for m in &heard[t.vehicle] {
                let outcome = t.navigator.process(m);
                observers.iter_mut().for_each(|o| o.outcome(i, m, &outcome));
            }
            // scored at the step's time, also when no message reached it
            t.navigator.predict_to(world.t_s(k));
            estimates[i] = t.navigator.estimate();
            if t.restart.apply(&mut t.navigator, &mut estimates[i], world.t_s(k)) {
                observers.iter_mut().for_each(|o| o.restarted(i));
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
    use onebeacon::nav::Kind;
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

    /// One vehicle that hears one speed a step for three steps.
    struct Still;

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
            heard[0].push(Measurement::new(k as f64, Kind::Speed { speed_m_s: 1.0 }));
        }
    }

    struct Restarts(Vec<usize>);

    impl Observer for Restarts {
        fn step(&mut self, _: &Step<'_>) {}
        fn restarted(&mut self, track: usize) {
            self.0.push(track);
        }
    }

    /// The engine applies the session's policy: an estimator whose state stops being
    /// sound is built again from its last sound pose at the step's time, and observers
    /// are told; every step breaks it again here, so three steps, three restarts.
    #[test]
    fn an_unsound_estimator_starts_again_as_in_the_session() {
        let builds = Arc::new(AtomicUsize::new(0));
        let counted = builds.clone();
        let planar = onebeacon::nav::planar::builder(Default::default(), onebeacon::filter::FilterKind::Ekf);
        let builder: Builder = Box::new(move |t0, at, sp, sh| {
            counted.fetch_add(1, Ordering::SeqCst);
            Box::new(Fragile { inner: planar(t0, at, sp, sh), broken: false })
        });
        let mut tracks = vec![Track::new(0, builder, (5.0, -3.0, 0.2), (1.0, 0.1))];
        let mut restarts = Restarts(Vec::new());
        run(&mut Still, &mut tracks, &mut [], &mut [&mut restarts]);
        assert_eq!(restarts.0, [0, 0, 0]);
        assert_eq!(builds.load(Ordering::SeqCst), 4);
        let e = tracks[0].navigator.estimate();
        assert_eq!((e.north_m(), e.east_m(), e.heading_rad(), e.t_s), (5.0, -3.0, 0.2, 3.0));
    }
}
