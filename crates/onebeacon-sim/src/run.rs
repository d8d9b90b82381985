//! One simulated run: the scenario's world driven by the [engine](crate::engine), every
//! estimator on every vehicle on the same truth and the same measurement draws (a
//! paired comparison), scored and recorded by observers. A pure function of (scenario,
//! cell, seed, run index).

use crate::computers::{self, OnBoard};
use crate::engine::{self, Aboard, Observer, Step, VehicleTruth, World};
use crate::factory;
use crate::information::{Information, bearing_information, range_information};
use crate::messages::{Computer, Messages};
use crate::metrics::RunMetrics;
use crate::scenario::fleet::SignalModel;
use crate::scenario::{Cell, EstimatorSpec, Scenario};
use crate::world::{FixedBeaconWorld, FleetWorld, MovingBeaconWorld, PassiveUsblWorld};
use nalgebra::{DMatrix, Vector2, Vector3};
use onebeacon::config::builder::{TrackerStart, VehicleModel};
use onebeacon::nav::diagnosis::PerBeacon;
use onebeacon::nav::evaluation::{ErrorStats, horizontal_error};
use onebeacon::nav::restart::Builder;
use onebeacon::nav::{Measurement, Outcome};

/// One estimator's estimate at one step.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Estimate {
    /// The vehicle it estimates (index into the scenario's vehicles).
    pub vehicle: usize,
    /// NED position, m.
    pub pos: Vector3<f64>,
    /// Heading, rad in (-pi, pi].
    pub psi: f64,
    /// Forward speed, m/s, when the estimator has it as a state.
    pub speed: Option<f64>,
    /// Standard deviations of north and east, m.
    pub sigma_pos: Vector2<f64>,
    /// Horizontal position error, m.
    pub error_m: f64,
    /// NEES of the horizontal position.
    pub nees: f64,
}

impl Estimate {
    /// The record of navigator estimate `e` of vehicle `vehicle` with its horizontal
    /// error and NEES.
    pub fn new(vehicle: usize, e: &onebeacon::nav::Estimate, error_m: f64, nees: Option<f64>) -> Self {
        Self {
            vehicle,
            pos: e.position_ned_m,
            psi: e.heading_rad(),
            speed: e.speed_m_s,
            sigma_pos: Vector2::new(e.sigma_north_m(), e.sigma_east_m()),
            error_m,
            nees: nees.unwrap_or(f64::NAN),
        }
    }
}

/// One vehicle's truth at one step (NaN where unknown: a log without ground truth).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TruthRecord {
    /// NED position, m; heading, rad in (-pi, pi]; speed over ground, m/s.
    pub pos: Vector3<f64>,
    pub heading: f64,
    pub speed: f64,
    /// The reference's own error on each horizontal axis, m (a log's ground truth with
    /// `sigma_m`; 0 for the simulator's truth).
    pub sigma_m: f64,
}

impl TruthRecord {
    fn of(t: &VehicleTruth) -> Self {
        Self {
            pos: t.eta.fixed_rows::<3>(0).into_owned(),
            heading: onebeacon::geo::wrap_angle(t.eta[5]),
            speed: t.speed_m_s,
            sigma_m: 0.0,
        }
    }
}

pub use crate::engine::PilotRecord;

/// Truth and all estimates at one step.
#[derive(Debug, Clone, PartialEq)]
pub struct StepRecord {
    pub t_s: f64,
    /// Every vehicle's truth, in the scenario's order.
    pub truth: Vec<TruthRecord>,
    /// The beacon's true position (fixed, or on the surface vehicle).
    pub beacon: Vector3<f64>,
    /// Whether an acoustic measurement was heard in this step.
    pub frame: bool,
    /// Every (vehicle, estimator) track, in the order of [`Scenario::tracks`].
    pub estimates: Vec<Estimate>,
    /// The dynamic vehicles' autopilots (empty in a world without them).
    pub pilots: Vec<PilotRecord>,
}

// the guidance decisions are the onboard controllers' records
pub use onebeacon::vehicle::{BearingSnapshot, FimSnapshot, GuidanceSnapshot};

/// The outcome of one run.
#[derive(Debug, Clone, PartialEq)]
pub struct RunOutput {
    /// One entry per track, in the order of [`Scenario::tracks`].
    pub metrics: Vec<RunMetrics>,
    /// Every step, when recording was asked for; empty otherwise.
    pub trajectory: Vec<StepRecord>,
    /// Distance travelled by each vehicle, m.
    pub distance_m: Vec<f64>,
    /// Acoustic measurements heard (frames decoded, ranges), all vehicles together.
    pub frames_decoded: u64,
    /// Each track's error and NIS statistics and its corrections beacon by beacon: what
    /// [`RunOutput::findings`] reads.
    pub stats: Vec<ErrorStats>,
    pub per_beacon: Vec<PerBeacon>,
    /// Measurements the vehicles' computers screened out (out of their limits or of time
    /// order), and the first one's reason: none in a sound world.
    pub screened: (usize, Option<String>),
    /// For bounds: the Fisher information H' R^-1 H of each acoustic measurement at
    /// the truth (the world's state size), with the vehicle and the step it was received
    /// in (moving-beacon and passive-USBL runs; empty otherwise).
    pub information: Vec<(usize, usize, DMatrix<f64>)>,
    /// The guidance decisions of a recorded moving-beacon run, one per ping.
    pub guidance: Vec<GuidanceSnapshot>,
    /// The first vehicle's first estimator's belief at the step asked for
    /// ([`simulate_with_belief`]).
    pub belief: Option<BeliefSnapshot>,
}

/// What the first estimator of the first vehicle believed at one step, with what it
/// had just measured: for a picture of the particle cloud (hoff2024 Fig. 4-6).
#[derive(Debug, Clone, PartialEq)]
pub struct BeliefSnapshot {
    pub t_s: f64,
    /// Equally weighted samples of its position belief (a particle filter's particles,
    /// drawn by weight), NED.
    pub positions: Vec<Vector3<f64>>,
    pub estimate: Vector3<f64>,
    pub truth: Vector3<f64>,
    /// The bearing measured at this step: the station's reported position and heading,
    /// azimuth, elevation (rad).
    pub bearing: Option<(Vector3<f64>, f64, f64, f64)>,
    /// A factored particle filter's last range and angle sets (rypkema Fig. 6).
    pub sets: Option<onebeacon::filter::factored::FactoredSets>,
    /// The beacon's true position (for beacon-relative pictures).
    pub beacon: Vector3<f64>,
}

/// Bytes a recorded run of `s` holds (its trajectory), about.
pub fn recorded_bytes(s: &Scenario) -> f64 {
    let per_step = size_of::<StepRecord>()
        + s.vehicle_names().len() * size_of::<TruthRecord>()
        + s.tracks().len() * size_of::<Estimate>();
    (s.steps() + 1) as f64 * per_step as f64
}

impl RunOutput {
    /// What the tracks' innovations say without the truth, one line each, the tracks
    /// named `labels` ([`onebeacon::nav::diagnosis::findings`]: overconfident filters,
    /// beacons gated out or reading apart).
    pub fn findings(&self, labels: &[String]) -> Vec<String> {
        let mut findings = onebeacon::nav::diagnosis::findings(labels, &self.stats, &self.per_beacon);
        if let (n @ 1.., Some(first)) = &self.screened {
            findings.push(format!("{n} measurement(s) screened out by the vehicles' computers, the first: {first}"));
        }
        findings
    }
}

/// Simulates run `run` of `cell` under base seed `seed`; records every step if `record`.
/// A cell of another world than the scenario's is a programming error.
pub fn simulate(s: &Scenario, cell: &Cell, seed: u64, run: u64, record: bool) -> RunOutput {
    simulate_recording(s, cell, seed, run, Recorder::new(record, None), false).0
}

/// [`simulate`] recording every step, and the belief of the first vehicle's first
/// estimator at step `step` (up to `samples` samples of it; None if it has none or the
/// run is shorter).
pub fn simulate_with_belief(s: &Scenario, cell: &Cell, seed: u64, run: u64, step: usize, samples: usize) -> RunOutput {
    simulate_recording(s, cell, seed, run, Recorder::new(true, Some((step, samples))), false).0
}

/// [`simulate`] recording every step (and the belief at `belief`: step, samples), with
/// what each vehicle's computer heard and decided ([`crate::messages`]); None for a
/// fleet with the channel model, whose captures are not JSON lines.
pub fn simulate_messages(
    s: &Scenario,
    cell: &Cell,
    seed: u64,
    run: u64,
    belief: Option<(usize, usize)>,
) -> (RunOutput, Option<Vec<Computer>>) {
    simulate_recording(s, cell, seed, run, Recorder::new(true, belief), true)
}

fn simulate_recording(
    s: &Scenario,
    cell: &Cell,
    seed: u64,
    run: u64,
    recorder: Recorder,
    messages: bool,
) -> (RunOutput, Option<Vec<Computer>>) {
    match (s, cell) {
        (Scenario::FixedBeacon(s), Cell::FixedBeacon(c)) => {
            let mut world = FixedBeaconWorld::new(s, c, seed, run);
            let z0 = factory::fixed_beacon_start(s, world.unicycle_state(), seed, run);
            let on_board = vec![computers::fixed_beacon(s, &z0)];
            drive(&mut world, &on_board, &EstimatorSpec::builder, Vec::new(), recorder, messages)
        }
        (Scenario::MovingBeacon(s), Cell::MovingBeacon(c)) => {
            let asv0 = factory::initial_asv_position(s, c);
            let mut world = MovingBeaconWorld::new(s, c, asv0, seed, run);
            let starts = factory::moving_beacon_starts(s, &world.states(), seed, run);
            let on_board = computers::moving_beacon(s, c, asv0, &starts);
            let mut info = Information::new(range_information(s.sensor_noise()));
            let extra: Vec<&mut dyn Observer> = vec![&mut info];
            let (mut out, m) = drive(&mut world, &on_board, &EstimatorSpec::builder, extra, recorder, messages);
            out.information = info.into_inner();
            (out, m)
        }
        (Scenario::PassiveUsbl(s), Cell::PassiveUsbl(c)) => {
            let mut world = PassiveUsblWorld::new(s, seed, run);
            let starts = factory::tracker_starts(s, &world.initial_states(), seed, run);
            let on_board = vec![computers::passive_usbl(s, c, world.asv_start(), &starts)];
            let mut info = Information::new(bearing_information(s.tracker_noise()));
            let extra: Vec<&mut dyn Observer> = vec![&mut info];
            let (mut out, m) = drive(&mut world, &on_board, &EstimatorSpec::builder, extra, recorder, messages);
            out.information = info.into_inner();
            (out, m)
        }
        (Scenario::Fleet(s), Cell::Fleet) => {
            let mut world = FleetWorld::new(s, seed, run);
            let on_board = computers::fleet(s, &factory::fleet_seeds(s, seed, run));
            // the channel model's captures are not JSON lines
            let messages = messages && s.signal.model != SignalModel::Channel;
            drive(&mut world, &on_board, &factory::fleet_builder(s), Vec::new(), recorder, messages)
        }
        _ => panic!("sweep cell {cell:?} does not belong to scenario {}", s.name()),
    }
}

/// Runs the engine on the vehicles' `computers` (each estimator built by `build`), with
/// the scoring and recording observers (and `extra`); with what each computer with a
/// controller heard and decided when `messages`.
fn drive(
    world: &mut dyn World,
    computers: &[OnBoard],
    build: &dyn Fn(&EstimatorSpec, TrackerStart, VehicleModel) -> Builder,
    extra: Vec<&mut dyn Observer>,
    mut recorder: Recorder,
    messages: bool,
) -> (RunOutput, Option<Vec<Computer>>) {
    let mut aboard = computers::aboard(computers, build);
    let mut scoring = Scoring::new(engine::vehicle_of(&aboard), world.steps());
    let mut m = messages.then(|| Messages::new(computers));
    {
        let mut observers: Vec<&mut dyn Observer> = vec![&mut scoring, &mut recorder];
        // each pushed reborrowed, for as long as the run
        for o in extra {
            observers.push(o);
        }
        if let Some(m) = m.as_mut() {
            observers.push(m);
        }
        engine::run(world, &mut aboard, &mut observers);
    }
    let out = RunOutput {
        metrics: scoring
            .acc
            .iter()
            .zip(&scoring.vehicle_of)
            .map(|(a, &v)| RunMetrics::of(a, scoring.distance_m[v]))
            .collect(),
        trajectory: recorder.trajectory,
        distance_m: scoring.distance_m,
        frames_decoded: scoring.heard,
        stats: scoring.acc,
        per_beacon: scoring.per_beacon,
        screened: scoring.screened,
        information: Vec::new(),
        guidance: recorder.guidance,
        belief: recorder.belief,
    };
    (out, m.map(Messages::into_inner))
}

/// The beacons whose innovations a run counts apart, per track.
const MAX_BEACONS_COUNTED: usize = 64;

/// Error statistics of every track, failed updates, acoustic measurements heard, and
/// each vehicle's distance travelled so far.
struct Scoring {
    acc: Vec<ErrorStats>,
    /// Each track's corrections beacon by beacon (what the innovations say).
    per_beacon: Vec<PerBeacon>,
    /// The vehicle of each track.
    vehicle_of: Vec<usize>,
    distance_m: Vec<f64>,
    heard: u64,
    /// Measurements screened out, and the first one's reason.
    screened: (usize, Option<String>),
}

impl Scoring {
    fn new(vehicle_of: Vec<usize>, steps: usize) -> Self {
        // steps + 1 errors scored, the first half of them apart
        let acc = vec![ErrorStats::with_half(steps.div_ceil(2)); vehicle_of.len()];
        let per_beacon = vec![PerBeacon::default(); vehicle_of.len()];
        Self { acc, per_beacon, vehicle_of, distance_m: Vec::new(), heard: 0, screened: (0, None) }
    }
}

impl Observer for Scoring {
    fn step(&mut self, s: &Step<'_>) {
        for ((a, e), &v) in self.acc.iter_mut().zip(s.estimates).zip(&self.vehicle_of) {
            let (error_m, nees) = horizontal_error(e, s.truth[v].eta[0], s.truth[v].eta[1], 0.0);
            a.push(error_m, nees);
        }
        self.heard += s.heard.iter().flatten().filter(|m| m.kind.beacon().is_some()).count() as u64;
        self.distance_m.clear();
        self.distance_m.extend(s.truth.iter().map(|t| t.distance_m));
    }

    fn outcome(&mut self, track: usize, m: &Measurement, outcome: &Outcome) {
        self.acc[track].push_outcome(outcome, true);
        self.per_beacon[track].push(&m.kind, outcome, MAX_BEACONS_COUNTED);
    }

    fn restarted(&mut self, track: usize) {
        self.acc[track].reinitialised += 1;
    }

    fn screened(&mut self, vehicle: usize, m: &Measurement, reason: &str) {
        self.screened.0 += 1;
        self.screened
            .1
            .get_or_insert_with(|| format!("vehicle {vehicle}'s {} at {} s: {reason}", m.kind.name(), m.t_s));
    }
}

/// Every step and every guidance decision, when asked for, and the belief at one step.
struct Recorder {
    on: bool,
    trajectory: Vec<StepRecord>,
    guidance: Vec<GuidanceSnapshot>,
    /// The step whose belief to keep, and how many samples of it.
    belief_at: Option<(usize, usize)>,
    belief: Option<BeliefSnapshot>,
}

impl Recorder {
    fn new(on: bool, belief_at: Option<(usize, usize)>) -> Self {
        Self { on, trajectory: Vec::new(), guidance: Vec::new(), belief_at, belief: None }
    }
}

impl Observer for Recorder {
    fn inspect(&mut self, k: usize, computers: &[Aboard]) {
        let Some((_, samples)) = self.belief_at.filter(|(at, _)| *at == k) else { return };
        let Some(first) = computers.iter().find_map(|c| c.navigator_of(0)) else { return };
        if let Some(particles) = first.particles() {
            let e = first.estimate();
            self.belief = Some(BeliefSnapshot {
                t_s: e.t_s,
                positions: particles.position_sample(samples),
                estimate: e.position_ned_m,
                truth: Vector3::from_element(f64::NAN),
                bearing: None,
                sets: first.factored().map(|f| f.factored_sets().clone()),
                beacon: Vector3::from_element(f64::NAN),
            });
        }
    }

    fn step(&mut self, s: &Step<'_>) {
        if let Some(b) = self.belief.as_mut().filter(|_| self.belief_at.is_some_and(|(at, _)| at == s.k)) {
            b.truth = s.truth[0].eta.fixed_rows::<3>(0).into_owned();
            b.beacon = s.beacon_ned_m;
            b.bearing = s.heard[0].iter().find_map(|m| match m.kind {
                onebeacon::nav::Kind::Bearing { station, station_heading_rad, azimuth_rad, elevation_rad } => {
                    Some((station.position_ned_m, station_heading_rad, azimuth_rad, elevation_rad))
                }
                _ => None,
            });
        }
        if !self.on {
            return;
        }
        let estimates = s
            .estimates
            .iter()
            .zip(s.vehicle_of)
            .map(|(e, &v)| {
                let (error_m, nees) = horizontal_error(e, s.truth[v].eta[0], s.truth[v].eta[1], 0.0);
                Estimate::new(v, e, error_m, nees)
            })
            .collect();
        self.trajectory.push(StepRecord {
            t_s: s.t_s,
            truth: s.truth.iter().map(TruthRecord::of).collect(),
            beacon: s.beacon_ned_m,
            frame: s.heard.iter().flatten().any(|m| m.kind.beacon().is_some()),
            estimates,
            pilots: s.pilots.to_vec(),
        });
    }

    fn decided(&mut self, _helm: usize, _situation: &onebeacon::vehicle::Situation, d: &onebeacon::vehicle::Decided) {
        if let Some(g) = d.snapshot.as_ref().filter(|_| self.on) {
            self.guidance.push(g.clone());
        }
    }
}

pub use crate::world::TruthPath;

/// The columns of a recorded trajectory, one row per step: what trajectory.csv holds and
/// the Python package's `run` returns as arrays.
pub mod trajectory {
    use super::StepRecord;

    /// The column names: time, every vehicle's truth (prefixed with its name when there
    /// are several), the beacon, whether an acoustic measurement was heard, and every
    /// track's estimate, standard deviations, error and NEES (prefixed with its label).
    pub fn header(vehicles: &[String], names: &[String]) -> Vec<String> {
        let mut header = vec!["t_s".to_string()];
        for v in vehicles {
            let prefix = if vehicles.len() > 1 { format!("{v}_") } else { String::new() };
            for col in ["truth_north_m", "truth_east_m", "truth_down_m", "truth_heading_deg", "truth_speed_m_s"] {
                header.push(format!("{prefix}{col}"));
            }
        }
        header.extend(["beacon_north_m", "beacon_east_m", "beacon_down_m", "frame"].map(String::from));
        for name in names {
            for col in [
                "north_m",
                "east_m",
                "down_m",
                "heading_deg",
                "speed_m_s",
                "sigma_north_m",
                "sigma_east_m",
                "error_m",
                "nees",
            ] {
                header.push(format!("{name}_{col}"));
            }
        }
        header
    }

    /// One step's values in [`header`]'s order: headings in degrees in (-180, 180], the
    /// frame flag 0 or 1, NaN for a speed the estimator does not have.
    pub fn values(r: &StepRecord) -> Vec<f64> {
        let mut row = vec![r.t_s];
        for t in &r.truth {
            row.extend([t.pos.x, t.pos.y, t.pos.z, onebeacon::geo::wrap_angle(t.heading).to_degrees(), t.speed]);
        }
        row.extend([r.beacon.x, r.beacon.y, r.beacon.z, f64::from(u8::from(r.frame))]);
        for e in &r.estimates {
            row.extend([e.pos.x, e.pos.y, e.pos.z, e.psi.to_degrees(), e.speed.unwrap_or(f64::NAN)]);
            row.extend([e.sigma_pos.x, e.sigma_pos.y, e.error_m, e.nees]);
        }
        row
    }

    /// The whole trajectory by column, in [`header`]'s order.
    pub fn columns(vehicles: &[String], names: &[String], records: &[StepRecord]) -> Vec<(String, Vec<f64>)> {
        let header = header(vehicles, names);
        let mut columns: Vec<Vec<f64>> = header.iter().map(|_| Vec::with_capacity(records.len())).collect();
        for r in records {
            for (c, v) in columns.iter_mut().zip(values(r)) {
                c.push(v);
            }
        }
        header.into_iter().zip(columns).collect()
    }
}
