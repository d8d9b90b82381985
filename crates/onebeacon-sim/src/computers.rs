//! Each vehicle's computer in a world, described once: the stream configuration a
//! vehicle reads (`onebeacon stream CONFIG`: estimators, controller, where each vehicle
//! it estimates starts), with the run's exact starts. The engine runs the
//! [`Unit`](onebeacon::vehicle::unit::Unit) it builds ([`OnBoard::aboard`]), the very
//! computer `stream` runs, and `run --messages` writes it ([`crate::messages`]): a
//! fixed-beacon world's AUV (garin2024's filters, no controller), a passive-USBL world's
//! surface vehicle (tracking every AUV, its bearing planner), a moving-beacon world's
//! beacon vehicle (the estimators of the vehicle it serves, its FIM guidance) and the
//! vehicles it does not serve, each fleet AUV (its iUSBL navigators and dead reckoning,
//! its behaviours).

use crate::engine::Aboard;
use crate::scenario::estimator::IusblKeys;
use crate::scenario::fleet::{Fleet, Navigation};
use crate::scenario::moving_beacon::GuidanceKind as FimKind;
use crate::scenario::passive_usbl::GuidanceKind as BearingKind;
use crate::scenario::{
    EstimatorKind, EstimatorSpec, FixedBeacon, MovingBeacon, MovingBeaconCell, PassiveUsbl, PassiveUsblCell,
};
use crate::vehicles::sandshark::SandSharkParams;
use nalgebra::Vector2;
use onebeacon::config::builder::{TrackerStart, VehicleModel};
use onebeacon::config::controller::{
    BearingModeName, BearingSpec, BehavioursSpec, ControllerSpec, FimMetricName, FimModeName, FimSpec, MetricName,
};
use onebeacon::config::stream::{FrameKey, Initial, InitialFrom, StreamConfig, VehicleStart};
use onebeacon::models::hoff::idx;
use onebeacon::models::kinematic6dof::State as Eta;
use onebeacon::models::unicycle::State as UnicycleState;
use onebeacon::nav::restart::Builder;
use onebeacon::nav::usbl_track::TrackState;

/// Where one vehicle's estimators start, exactly as the simulator drew it: what the
/// configuration's `[initial]` (or `[[tracked]]` table) says in degrees, to the last
/// bit where a degree value can say it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Start {
    /// The engine's index of the vehicle.
    pub vehicle: usize,
    /// North, east (m), heading (rad), and their standard deviations (m, rad).
    pub pose: (f64, f64, f64),
    pub sigmas: (f64, f64),
    /// The rest of a tracker's or the 6-DOF filter's start.
    pub tracker: TrackerStart,
}

/// One vehicle's computer in a run.
pub(crate) struct OnBoard {
    /// Its stream configuration (named for the vehicle: `auv`, `asv`, or the AUV's name): `[initial]` (or `[[tracked]]`, one per start) from
    /// `starts`.
    pub config: StreamConfig,
    /// One per vehicle it estimates, in the order of its sessions.
    pub starts: Vec<Start>,
}

impl OnBoard {
    /// The computer the engine runs: the [`Unit`](onebeacon::vehicle::unit::Unit) its
    /// configuration builds ([`StreamConfig::unit_of`]), one session per vehicle it
    /// estimates started at time 0 at its exact start, each estimator built by `build`
    /// (the spec's own [`EstimatorSpec::builder`] but where a world's signal needs
    /// another).
    pub(crate) fn aboard(&self, build: &dyn Fn(&EstimatorSpec, TrackerStart, VehicleModel) -> Builder) -> Aboard {
        let starts: Vec<VehicleStart> = self
            .starts
            .iter()
            .map(|s| VehicleStart {
                start: onebeacon::nav::session::Start::At { t0_s: Some(0.0), pose: s.pose },
                tracker: s.tracker,
                sigmas: s.sigmas,
            })
            .collect();
        Aboard { unit: self.config.unit_of(&starts, build), vehicles: self.starts.iter().map(|s| s.vehicle).collect() }
    }
}

/// The computers of a run, in order, each estimator built by `build` (its spec's
/// [`EstimatorSpec::builder`], or a fleet's with the channel model:
/// [`crate::factory::fleet_builder`]).
pub(crate) fn aboard(
    computers: &[OnBoard],
    build: &dyn Fn(&EstimatorSpec, TrackerStart, VehicleModel) -> Builder,
) -> Vec<Aboard> {
    computers.iter().map(|c| c.aboard(build)).collect()
}

/// A stream configuration of `estimators` and `controller`, NED, planar, its vehicles
/// yet to be given.
fn config(description: String, estimators: Vec<EstimatorSpec>, controller: Option<ControllerSpec>) -> StreamConfig {
    StreamConfig {
        name: "asv".into(),
        description,
        frame: FrameKey::Ned,
        model: VehicleModel::Planar,
        beacons: Vec::new(),
        initial: Initial::default(),
        tracked: Vec::new(),
        estimators,
        noise: Default::default(),
        limits: Default::default(),
        controller,
    }
}

/// A vehicle given at time 0 at `pose` (north, east, heading rad), with its position's
/// and heading's standard deviations `sigmas` (m, rad).
fn given((x_m, y_m, heading_rad): (f64, f64, f64), (position_sigma_m, heading_sigma_rad): (f64, f64)) -> Initial {
    Initial {
        from: InitialFrom::Given,
        t0_s: Some(0.0),
        x_m: Some(x_m),
        y_m: Some(y_m),
        heading_deg: Some(heading_rad.to_degrees()),
        position_sigma_m,
        heading_sigma_deg: heading_sigma_rad.to_degrees(),
        ..Initial::default()
    }
}

/// The AUV's computer of a fixed-beacon run: garin2024's filters (`model =
/// "unicycle"`), no controller, started at `z0` (the truth plus one draw,
/// [`crate::factory::fixed_beacon_start`]) with the scenario's standard deviations.
pub(crate) fn fixed_beacon(s: &FixedBeacon, z0: &UnicycleState) -> OnBoard {
    let i = &s.initial;
    let start = Start {
        vehicle: 0,
        pose: (z0[0], z0[1], z0[2]),
        sigmas: (i.position_sigma_m, i.heading_sigma_deg.to_radians()),
        tracker: TrackerStart {
            state: [0.0, 0.0, z0[3], 0.0, 0.0],
            sigma: [0.0, 0.0, i.speed_sigma_m_s, 0.0],
            yaw_rate_accel: [z0[4], z0[5]],
            yaw_rate_accel_sigma: [i.yaw_rate_sigma_rad_s, i.accel_sigma_m_s2],
            ..TrackerStart::default()
        },
    };
    let initial = Initial {
        speed_m_s: z0[3],
        yaw_rate_deg_s: z0[4].to_degrees(),
        accel_m_s2: z0[5],
        heading_sigma_deg: i.heading_sigma_deg,
        speed_sigma_m_s: i.speed_sigma_m_s,
        yaw_rate_sigma_deg_s: i.yaw_rate_sigma_rad_s.to_degrees(),
        accel_sigma_m_s2: i.accel_sigma_m_s2,
        ..given(start.pose, start.sigmas)
    };
    let description = format!("The AUV's computer of a simulated {} run", s.name);
    let config = StreamConfig {
        name: "auv".into(),
        initial,
        model: VehicleModel::Unicycle,
        ..config(description, s.estimators.clone(), None)
    };
    OnBoard { config, starts: vec![start] }
}

/// Each estimator of a passive-USBL scenario as the surface vehicle's stream
/// configuration describes it: the scenario's, with the world's noise (which the
/// trackers assume unless told otherwise) written out.
fn passive_usbl_estimators(s: &PassiveUsbl) -> Vec<EstimatorSpec> {
    s.estimators
        .iter()
        .map(|e| {
            let mut e = e.clone();
            e.usbl.usbl_sigma_deg_per_m = e.usbl.usbl_sigma_deg_per_m.or(Some(s.usbl.noise_deg_per_m));
            e.usbl.compass_sigma_deg = e.usbl.compass_sigma_deg.or(Some(s.asv.compass_noise_deg));
            e.noise.heading_sigma_deg = e.noise.heading_sigma_deg.or(Some(s.reports.heading_noise_deg));
            e.noise.speed_sigma_m_s = e.noise.speed_sigma_m_s.or(Some(s.reports.speed_noise_m_s));
            e.noise.depth_sigma_m = e.noise.depth_sigma_m.or(Some(s.reports.depth_noise_m));
            e.name = Some(e.name());
            e
        })
        .collect()
}

/// The controller of a passive-USBL world's ASV, starting at `home`: the planner knows
/// the USBL as the first estimator assumes it.
fn bearing_controller(s: &PassiveUsbl, cell: &PassiveUsblCell, home: Vector2<f64>) -> ControllerSpec {
    let g = &s.guidance;
    // the baselines keep the determinant for their (unused) planner
    let (mode, metric) = match cell.guidance {
        BearingKind::Determinant => (BearingModeName::Planner, MetricName::Determinant),
        BearingKind::MaxEigenvalue => (BearingModeName::Planner, MetricName::MaxEigenvalue),
        BearingKind::Static => (BearingModeName::Static, MetricName::Determinant),
        BearingKind::Circle => (BearingModeName::Circle, MetricName::Determinant),
        BearingKind::Offset => (BearingModeName::Offset, MetricName::Determinant),
    };
    ControllerSpec::Bearing(BearingSpec {
        mode,
        metric,
        r1_m: g.r1_m,
        r2_m: g.r2_m,
        radii: g.radii,
        angles: g.angles,
        usbl_sigma_deg_per_m: s.estimators[0].usbl.usbl_sigma_deg_per_m.unwrap_or(s.usbl.noise_deg_per_m),
        nominal_speed_m_s: s.asv.nominal_speed_m_s,
        period_s: s.mission.message_period_s,
        planner_particles: g.planner_particles,
        lead_periods: g.lead_periods,
        circle_radius_m: g.circle_radius_m,
        offset_m: g.offset_m,
        home_x_m: home.x,
        home_y_m: home.y,
        decide_on: "own_fix".into(),
    })
}

/// The surface vehicle's computer of a passive-USBL run: its trackers of every AUV,
/// started where the simulator drew them (`starts`: the state and its particle filters'
/// seed, [`crate::factory::tracker_starts`]), and its planner, starting at `home`.
pub(crate) fn passive_usbl(
    s: &PassiveUsbl,
    cell: &PassiveUsblCell,
    home: Vector2<f64>,
    starts: &[(TrackState, u64)],
) -> OnBoard {
    let (i, sigma0) = (&s.initial, crate::factory::tracker_sigma(s));
    let starts: Vec<Start> = starts
        .iter()
        .enumerate()
        .map(|(v, &(x0, seed))| Start {
            vehicle: v,
            pose: (x0[idx::X], x0[idx::Y], x0[idx::PSI]),
            sigmas: (sigma0[idx::X], sigma0[idx::PSI]),
            tracker: TrackerStart {
                state: [x0[idx::Z], x0[idx::THETA], x0[idx::U], x0[idx::B_THETA], x0[idx::B_PSI]],
                sigma: [sigma0[idx::Z], sigma0[idx::THETA], sigma0[idx::U], sigma0[idx::B_THETA]],
                // the seed's 64 bits as TOML's signed integer
                seed: Some(seed as i64),
                ..TrackerStart::default()
            },
        })
        .collect();
    let tracked = starts
        .iter()
        .map(|st| {
            let [depth, pitch, speed, pitch_bias, heading_bias] = st.tracker.state;
            Initial {
                seed: st.tracker.seed,
                depth_m: depth,
                pitch_deg: pitch.to_degrees(),
                speed_m_s: speed,
                pitch_rate_bias_deg_s: pitch_bias.to_degrees(),
                heading_rate_bias_deg_s: heading_bias.to_degrees(),
                // the scenario's own values, which the sigmas above are in radians
                position_sigma_m: i.position_sigma_m,
                heading_sigma_deg: i.heading_sigma_deg,
                depth_sigma_m: i.depth_sigma_m,
                pitch_sigma_deg: i.pitch_sigma_deg,
                speed_sigma_m_s: i.speed_sigma_m_s,
                rate_bias_sigma_deg_s: i.rate_bias_sigma_deg_s,
                ..given(st.pose, st.sigmas)
            }
        })
        .collect();
    let description =
        format!("The surface vehicle's computer of a simulated {} run (onebeacon run --messages)", s.name);
    let controller = bearing_controller(s, cell, home);
    let config = StreamConfig { tracked, ..config(description, passive_usbl_estimators(s), Some(controller)) };
    OnBoard { config, starts }
}

/// Each estimator of a moving-beacon scenario as a stream configuration describes it:
/// the scenario's, with the world's sensor noise written out where it gives none.
fn moving_beacon_estimators(s: &MovingBeacon) -> Vec<EstimatorSpec> {
    let (n, a) = (&s.sensors, &s.acoustics);
    s.estimators
        .iter()
        .map(|e| {
            let mut e = e.clone();
            e.noise.range_sigma_m = e.noise.range_sigma_m.or(Some(a.range_noise_m));
            e.noise.depth_sigma_m = e.noise.depth_sigma_m.or(Some(n.depth_noise_m));
            e.six_dof.velocity_sigma_m_s = e.six_dof.velocity_sigma_m_s.or(Some(n.velocity_noise_m_s));
            e.six_dof.rate_sigma_rad_s = e.six_dof.rate_sigma_rad_s.or(Some(n.rate_noise_rad_s));
            e.six_dof.attitude_sigma_deg = e.six_dof.attitude_sigma_deg.or(Some(n.attitude_noise_deg));
            e.name = Some(e.name());
            e
        })
        .collect()
}

/// The FIM guidance of a moving-beacon world's ASV, starting at `home`.
fn fim_controller(s: &MovingBeacon, cell: &MovingBeaconCell, home: Vector2<f64>) -> ControllerSpec {
    let g = &s.guidance;
    let mode = match cell.guidance {
        FimKind::ApproachA | FimKind::ApproachB => FimModeName::Planner,
        FimKind::Static => FimModeName::Static,
        FimKind::Circle => FimModeName::Circle,
    };
    ControllerSpec::Fim(FimSpec {
        mode,
        metric: if cell.guidance == FimKind::ApproachB { FimMetricName::ApproachB } else { FimMetricName::ApproachA },
        grid_radial: g.grid_radial,
        grid_angular: g.grid_angular,
        range_sigma_m: s.acoustics.range_noise_m,
        beacon_depth_m: s.asv.transducer_depth_m,
        period_s: s.acoustics.ping_period_s,
        max_speed_m_s: s.asv.max_speed_m_s,
        circle_radius_m: g.circle_radius_m,
        home_x_m: home.x,
        home_y_m: home.y,
        ..FimSpec::default()
    })
}

/// The computers of a moving-beacon run: the beacon vehicle's (`asv`), which runs the
/// estimators of the vehicle it serves (the first) and its FIM guidance, starting at
/// `home`; and one without a controller for each other vehicle. Each vehicle's
/// estimators start at `starts[v]` ([`crate::factory::moving_beacon_starts`]).
pub(crate) fn moving_beacon(
    s: &MovingBeacon,
    cell: &MovingBeaconCell,
    home: Vector2<f64>,
    starts: &[Eta],
) -> Vec<OnBoard> {
    let i = &s.initial;
    let a0 = i.attitude_sigma_deg.to_radians();
    let estimators = moving_beacon_estimators(s);
    starts
        .iter()
        .enumerate()
        .map(|(v, eta0)| {
            let start = Start {
                vehicle: v,
                pose: (eta0[0], eta0[1], eta0[5]),
                sigmas: (i.position_sigma_m, a0),
                tracker: TrackerStart {
                    state: [eta0[2], eta0[4], 0.0, 0.0, 0.0],
                    sigma: [i.depth_sigma_m, a0, 0.0, 0.0],
                    roll_rad: eta0[3],
                    ..TrackerStart::default()
                },
            };
            let initial = Initial {
                depth_m: eta0[2],
                roll_deg: eta0[3].to_degrees(),
                pitch_deg: eta0[4].to_degrees(),
                depth_sigma_m: i.depth_sigma_m,
                heading_sigma_deg: i.attitude_sigma_deg,
                pitch_sigma_deg: i.attitude_sigma_deg,
                ..given(start.pose, start.sigmas)
            };
            let (name, description, controller) = if v == 0 {
                let d =
                    format!("The beacon vehicle's computer of a simulated {} run (onebeacon run --messages)", s.name);
                ("asv".to_string(), d, Some(fim_controller(s, cell, home)))
            } else {
                let d = format!("Vehicle {v}'s estimators in a simulated {} run", s.name);
                (format!("vehicle{v}"), d, None)
            };
            let config = StreamConfig {
                name,
                initial,
                model: VehicleModel::Kinematic6Dof,
                ..config(description, estimators.clone(), controller)
            };
            OnBoard { config, starts: vec![start] }
        })
        .collect()
}

/// The iUSBL navigator's settings of a fleet scenario (its navigation, dock and signal).
fn iusbl_keys(s: &Fleet) -> IusblKeys {
    let n = &s.navigation;
    IusblKeys {
        particles: n.particles,
        reinitialised: n.reinitialised,
        max_range_m: n.max_range_m,
        sigma_speed_m_s: n.sigma_speed_m_s,
        sigma_heading_deg: n.sigma_heading_deg,
        // the filter reads the AHRS error the simulation draws from
        heading_bias_sigma_deg: s.sandshark.heading_error_deg,
        beacon_speed_m_s: n.beacon_speed_m_s,
        beacon_depth_m: s.dock.beacon_depth_m,
        confirmations: n.confirmations,
        floor: n.floor,
        beam_exponent: n.beam_exponent,
        fix_range_sigma_m: s.signal.range_sigma_m.max(0.05),
        fix_angle_sigma_deg: s.signal.angle_sigma_deg.max(0.5),
        sound_speed_m_s: s.signal.sound_speed_m_s,
    }
}

/// A fleet AUV's dead reckoning as its stream configuration describes it: the planar
/// navigator without aiding whose noise is the one the simulation draws the SandShark's
/// sensors from (`[sandshark]`): the RPM speed's scale error as a distance-scale state
/// and its white noise, the AHRS heading's slow error as a Gauss-Markov heading offset
/// (that no fix can show: its variance carries the drift it causes) and its white noise
/// (at least 1e-4 rad); with the propeller stopped the RPM reads zero while the vehicle
/// coasts on with its coast time constant. The speed input has no turn rate: the heading
/// between fixes walks by as much as the SandShark can turn in a metre at 1 m/s (its
/// largest turn rate, per sqrt(m)), so that each fix moves the heading, not the offset.
/// The current it believes in (`navigation.current_sigma_m_s`), if any, is two states.
/// Nothing is gated.
fn fleet_dead_reckoning(p: &SandSharkParams, n: &Navigation) -> EstimatorSpec {
    let mut e = EstimatorSpec::new(EstimatorKind::DeadReckoning);
    if p.speed_scale_sigma > 0.0 {
        (e.calibration.estimate_distance_scale, e.calibration.distance_scale_sigma) =
            (Some(true), Some(p.speed_scale_sigma));
    }
    e.planar.speed_coast_time_s = Some(p.coast_time_constant_s);
    if n.current_sigma_m_s > 0.0 {
        e.calibration.estimate_current = Some(true);
        (e.calibration.current_sigma_m_s, e.calibration.current_walk_m_s_per_sqrt_s) =
            (Some(n.current_sigma_m_s), Some(n.current_walk_m_s_per_sqrt_s));
    }
    if p.heading_error_deg > 0.0 {
        e.calibration.estimate_heading_offset = Some(true);
        (e.calibration.heading_offset_sigma_deg, e.calibration.heading_offset_time_s) =
            (Some(p.heading_error_deg), Some(p.heading_error_time_s));
    }
    e.noise.speed_sigma_m_s = Some(p.speed_white_m_s);
    e.noise.heading_sigma_deg = Some(p.heading_white_deg.max(1e-4f64.to_degrees()));
    e.planar.heading_walk_deg_per_sqrt_m = Some(p.max_turn_rate_deg_s);
    e.gating.nis_gate = Some(f64::INFINITY);
    e
}

/// Each AUV's computer of a fleet run: the iUSBL navigators with the scenario's
/// settings ([`iusbl_keys`]) and the dead reckoning ([`fleet_dead_reckoning`]), each with
/// its seed of the run (`seeds[v]`, [`crate::factory::fleet_seeds`]), started where the
/// AUV starts; its behaviours by command mode, deciding after each depth reading (the
/// last of a step's sensors).
pub(crate) fn fleet(s: &Fleet, seeds: &[Vec<u64>]) -> Vec<OnBoard> {
    let keys = iusbl_keys(s);
    s.auvs
        .iter()
        .zip(seeds)
        .enumerate()
        .map(|(v, (a, seeds))| {
            let estimators = s
                .estimators
                .iter()
                .zip(seeds)
                .map(|(&kind, &seed)| {
                    let mut e = match kind {
                        EstimatorKind::DeadReckoning => fleet_dead_reckoning(&s.sandshark, &s.navigation),
                        _ => EstimatorSpec { iusbl: Some(keys.clone()), ..EstimatorSpec::new(kind) },
                    };
                    // the seed's 64 bits as TOML's signed integer
                    e.seed = Some(seed as i64);
                    e
                })
                .collect();
            let controller = ControllerSpec::Behaviours(BehavioursSpec {
                speed_m_s: a.speed_m_s,
                depth_m: a.depth_m,
                modes: a.modes.clone(),
                decide_on: "depth".into(),
            });
            // the pose and its sigmas are the builder's arguments; the rest is a tracker's
            let start = Start {
                vehicle: v,
                pose: (a.start_north_m, a.start_east_m, a.start_heading_deg.to_radians()),
                sigmas: (1.0, 0.05),
                tracker: TrackerStart::default(),
            };
            let description = format!("{}'s computer in a simulated {} run (onebeacon run --messages)", a.name, s.name);
            let config = StreamConfig {
                name: a.name.clone(),
                // the dead reckoning's start
                initial: Initial { heading_deg: Some(a.start_heading_deg), ..given(start.pose, start.sigmas) },
                ..config(description, estimators, Some(controller))
            };
            OnBoard { config, starts: vec![start] }
        })
        .collect()
}
