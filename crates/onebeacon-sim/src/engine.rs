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

/// One estimator on one vehicle.
pub(crate) struct Track {
    pub vehicle: usize,
    pub navigator: Box<dyn Navigator>,
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
    /// The outcome of track `track`'s processing of one measurement.
    fn outcome(&mut self, _track: usize, _outcome: &Outcome) {}
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
                observers.iter_mut().for_each(|o| o.outcome(i, &outcome));
            }
            estimates[i] = t.navigator.estimate();
        }
        for (v, tr) in truth.iter_mut().enumerate() {
            *tr = world.truth(v);
        }
    }
}
