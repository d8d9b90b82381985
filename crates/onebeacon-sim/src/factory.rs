//! From an estimator spec to its navigator, in every world: the one place the simulator
//! builds navigators. Each vehicle's estimators start at its truth plus one draw from the
//! run's seeded initial stream (the same draw for all of them), so comparisons are
//! paired. A world gives its vehicles' initial truth; what estimates it is built here.

use crate::engine::Track;
use crate::scenario::estimator::IusblKeys;
use crate::scenario::fleet::{Fleet, Navigation, SignalModel};
use crate::scenario::{EstimatorKind, EstimatorSpec, FixedBeacon, Host, MovingBeacon, PassiveUsbl};
use crate::seed::{Stream, gauss, rng, vehicle_rng};
use crate::vehicles::sandshark::SandSharkParams;
use nalgebra::SVector;
use onebeacon::config::builder::{TrackerStart, VehicleModel};
use onebeacon::dsp::beamform::pyramid_8cm;
use onebeacon::dsp::receiver::{ModeReceiver, ReceiverConfig};
use onebeacon::dsp::waveform::rypkema_modes;
use onebeacon::geo::wrap_angle;
use onebeacon::models::hoff::{DIM, idx};
use onebeacon::models::kinematic6dof::State as Eta;
use onebeacon::models::unicycle::{Cov, State};
use onebeacon::nav::restart::Builder;
use onebeacon::nav::usbl_track::TrackState;
use onebeacon::nav::{IusblNavigator, single_beacon};
use rand::RngExt;

/// Every estimator of a fixed-beacon scenario on its AUV, started at the truth `z_true`
/// plus one draw (the same for all).
pub(crate) fn fixed_beacon(s: &FixedBeacon, z_true: State, seed: u64, run: u64) -> Vec<Track> {
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
    let z0 = z_true + sigma0.map(|sd| gauss(&mut init_rng, sd));
    let p0 = Cov::from_diagonal(&sigma0.component_mul(&sigma0));
    let pose = (z0[0], z0[1], z0[2]);
    s.estimators
        .iter()
        .map(|e| {
            let (aiding, tuning, filter) = (e.aiding(Host::FixedBeacon), e.ekf_tuning(), e.filter_kind());
            let (gate, robust) = e.gate();
            let guards = single_beacon::Guards {
                min_speed_m_s: e.min_speed_m_s,
                mirror: e.mirror_recovery.unwrap_or(true),
                gate,
                robust,
            };
            let calibration = e.range_calibration();
            let builder: Builder = Box::new(move |t0, (north, east, heading), _, _| {
                let mut z = z0;
                (z[0], z[1], z[2]) = (north, east, heading);
                single_beacon::boxed(aiding, tuning, filter, t0, (z, p0), calibration, guards)
            });
            Track::new(0, builder, pose, (i.position_sigma_m, sigma0[2]))
        })
        .collect()
}

/// Where a moving-beacon scenario's estimators of each vehicle start: its truth
/// `truth0[v]` plus one draw (the same for all its estimators).
pub(crate) fn moving_beacon_starts(s: &MovingBeacon, truth0: &[Eta], seed: u64, run: u64) -> Vec<Eta> {
    let i = &s.initial;
    let a0 = i.attitude_sigma_deg.to_radians();
    let sigma0 = SVector::<f64, 6>::from([i.position_sigma_m, i.position_sigma_m, i.depth_sigma_m, a0, a0, a0]);
    truth0
        .iter()
        .enumerate()
        .map(|(v, eta)| {
            let mut init_rng = vehicle_rng(seed, run, v, Stream::Initial);
            eta + sigma0.map(|sd| gauss(&mut init_rng, sd))
        })
        .collect()
}

/// Each estimator of a moving-beacon scenario as a stream configuration describes it:
/// the scenario's, with the world's sensor noise written out where it gives none.
pub(crate) fn moving_beacon_estimators(s: &MovingBeacon) -> Vec<EstimatorSpec> {
    let (n, a) = (&s.sensors, &s.acoustics);
    s.estimators
        .iter()
        .map(|e| {
            let mut e = e.clone();
            e.range_sigma_m = e.range_sigma_m.or(Some(a.range_noise_m));
            e.depth_sigma_m = e.depth_sigma_m.or(Some(n.depth_noise_m));
            e.velocity_sigma_m_s = e.velocity_sigma_m_s.or(Some(n.velocity_noise_m_s));
            e.rate_sigma_rad_s = e.rate_sigma_rad_s.or(Some(n.rate_noise_rad_s));
            e.attitude_sigma_deg = e.attitude_sigma_deg.or(Some(n.attitude_noise_deg));
            e.name = Some(e.name());
            e
        })
        .collect()
}

/// Each estimator of a passive-USBL scenario as the surface vehicle's stream
/// configuration describes it: the scenario's, with the world's noise (which the
/// trackers assume unless told otherwise) written out.
pub(crate) fn passive_usbl_estimators(s: &PassiveUsbl) -> Vec<EstimatorSpec> {
    s.estimators
        .iter()
        .map(|e| {
            let mut e = e.clone();
            e.usbl_sigma_deg_per_m = e.usbl_sigma_deg_per_m.or(Some(s.usbl.noise_deg_per_m));
            e.compass_sigma_deg = e.compass_sigma_deg.or(Some(s.asv.compass_noise_deg));
            e.heading_sigma_deg = e.heading_sigma_deg.or(Some(s.reports.heading_noise_deg));
            e.speed_sigma_m_s = e.speed_sigma_m_s.or(Some(s.reports.speed_noise_m_s));
            e.depth_sigma_m = e.depth_sigma_m.or(Some(s.reports.depth_noise_m));
            e.name = Some(e.name());
            e
        })
        .collect()
}

/// Every estimator of a moving-beacon scenario on every vehicle
/// ([`moving_beacon_estimators`], built as a stream builds them), each vehicle's started
/// at `starts[v]` ([`moving_beacon_starts`]).
pub(crate) fn moving_beacon(s: &MovingBeacon, starts: &[Eta]) -> Vec<Track> {
    let i = &s.initial;
    let a0 = i.attitude_sigma_deg.to_radians();
    let estimators = moving_beacon_estimators(s);
    let mut tracks = Vec::new();
    for (v, eta0) in starts.iter().enumerate() {
        let start = TrackerStart {
            state: [eta0[2], eta0[4], 0.0, 0.0, 0.0],
            sigma: [i.depth_sigma_m, a0, 0.0, 0.0],
            roll_rad: eta0[3],
            seed: None,
        };
        tracks.extend(estimators.iter().map(|e| {
            let builder = e.builder(start, VehicleModel::Kinematic6Dof);
            Track::new(v, builder, (eta0[0], eta0[1], eta0[5]), (i.position_sigma_m, a0))
        }));
    }
    tracks
}

/// A passive-USBL scenario's trackers' initial standard deviations, state order.
pub(crate) fn tracker_sigma(s: &PassiveUsbl) -> SVector<f64, DIM> {
    let i = &s.initial;
    let bias = i.rate_bias_sigma_deg_s.to_radians();
    SVector::<f64, DIM>::from([
        i.position_sigma_m,
        i.position_sigma_m,
        i.depth_sigma_m,
        i.pitch_sigma_deg.to_radians(),
        i.heading_sigma_deg.to_radians(),
        i.speed_sigma_m_s,
        bias,
        bias,
    ])
}

/// Where a passive-USBL scenario's trackers of each AUV start: its truth `truth0[v]`
/// plus one draw, and the seed its particle filters share.
pub(crate) fn tracker_starts(s: &PassiveUsbl, truth0: &[TrackState], seed: u64, run: u64) -> Vec<(TrackState, u64)> {
    let sigma0 = tracker_sigma(s);
    truth0
        .iter()
        .enumerate()
        .map(|(v, x)| {
            let mut init_rng = vehicle_rng(seed, run, v, Stream::Initial);
            let mut x0 = x + sigma0.map(|sd| gauss(&mut init_rng, sd));
            x0[idx::PSI] = wrap_angle(x0[idx::PSI]);
            (x0, init_rng.random())
        })
        .collect()
}

/// Every estimator of a passive-USBL scenario on every AUV
/// ([`passive_usbl_estimators`]), each AUV's started as [`tracker_starts`] says (the same
/// for all its estimators).
pub(crate) fn passive_usbl(s: &PassiveUsbl, starts: &[(TrackState, u64)]) -> Vec<Track> {
    let sigma0 = tracker_sigma(s);
    let estimators = passive_usbl_estimators(s);
    let mut tracks = Vec::new();
    for (v, &(x0, pf_seed)) in starts.iter().enumerate() {
        let start = TrackerStart {
            state: [x0[idx::Z], x0[idx::THETA], x0[idx::U], x0[idx::B_THETA], x0[idx::B_PSI]],
            sigma: [sigma0[idx::Z], sigma0[idx::THETA], sigma0[idx::U], sigma0[idx::B_THETA]],
            roll_rad: 0.0,
            // the seed's 64 bits as TOML's signed integer
            seed: Some(pf_seed as i64),
        };
        for e in &estimators {
            let builder = e.builder(start, VehicleModel::Planar);
            tracks.push(Track::new(v, builder, (x0[idx::X], x0[idx::Y], x0[idx::PSI]), (sigma0[0], sigma0[idx::PSI])));
        }
    }
    tracks
}

/// The iUSBL navigator's settings of a fleet scenario (its navigation, dock and signal).
pub(crate) fn iusbl_keys(s: &Fleet) -> IusblKeys {
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
        (e.estimate_distance_scale, e.distance_scale_sigma) = (Some(true), Some(p.speed_scale_sigma));
    }
    e.speed_coast_time_s = Some(p.coast_time_constant_s);
    if n.current_sigma_m_s > 0.0 {
        e.estimate_current = Some(true);
        (e.current_sigma_m_s, e.current_walk_m_s_per_sqrt_s) =
            (Some(n.current_sigma_m_s), Some(n.current_walk_m_s_per_sqrt_s));
    }
    if p.heading_error_deg > 0.0 {
        e.estimate_heading_offset = Some(true);
        (e.heading_offset_sigma_deg, e.heading_offset_time_s) =
            (Some(p.heading_error_deg), Some(p.heading_error_time_s));
    }
    e.speed_sigma_m_s = Some(p.speed_white_m_s);
    e.heading_sigma_deg = Some(p.heading_white_deg.max(1e-4f64.to_degrees()));
    e.heading_walk_deg_per_sqrt_m = Some(p.max_turn_rate_deg_s);
    e.nis_gate = Some(f64::INFINITY);
    e
}

/// Each estimator of a fleet AUV as its computer's stream configuration describes it,
/// with the run's seeds (`seeds`, [`fleet_seeds`]): the iUSBL navigators with the
/// scenario's settings ([`iusbl_keys`]), the dead reckoning ([`fleet_dead_reckoning`]).
pub(crate) fn fleet_estimators(s: &Fleet, seeds: &[u64]) -> Vec<EstimatorSpec> {
    let keys = iusbl_keys(s);
    s.estimators
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
        .collect()
}

/// The seeds of each estimator of every AUV of a fleet scenario's run, in track order.
pub(crate) fn fleet_seeds(s: &Fleet, seed: u64, run: u64) -> Vec<Vec<u64>> {
    (0..s.auvs.len())
        .map(|v| {
            let mut init_rng = vehicle_rng(seed, run, v, Stream::Initial);
            s.estimators.iter().map(|_| init_rng.random()).collect()
        })
        .collect()
}

/// Every AUV's estimators of a fleet scenario, in the scenario's order.
/// built as a stream builds them from [`fleet_estimators`]; with the channel model the
/// iUSBL navigators take the captures through their receiver.
pub(crate) fn fleet(s: &Fleet, seed: u64, run: u64) -> Vec<Track> {
    let (waveforms, elements) = (rypkema_modes(), pyramid_8cm());
    let channel = s.signal.model == SignalModel::Channel;
    // the pose and its sigmas are the builder's arguments; the rest is a tracker's
    let start = TrackerStart { state: [0.0; 5], sigma: [0.0; 4], roll_rad: 0.0, seed: None };
    let mut tracks = Vec::new();
    for ((v, a), seeds) in s.auvs.iter().enumerate().zip(fleet_seeds(s, seed, run)) {
        for e in fleet_estimators(s, &seeds) {
            let pose = (a.start_north_m, a.start_east_m, a.start_heading_deg.to_radians());
            let builder: Builder = if channel && e.kind.iusbl() {
                let config = e.iusbl.clone().unwrap_or_default().config(e.kind == EstimatorKind::Iusbl);
                let (elements, sound, filter_seed) = (elements.clone(), s.signal.sound_speed_m_s, e.seed.unwrap_or(0));
                Box::new(move |_, _, _, _| {
                    let rc = ReceiverConfig { sound_speed_m_s: sound, ..Default::default() };
                    let receiver = ModeReceiver::new(&waveforms, &elements, rc);
                    Box::new(IusblNavigator::new(config, Some(receiver), filter_seed as u64))
                })
            } else {
                e.builder(start, VehicleModel::Planar)
            };
            tracks.push(Track::new(v, builder, pose, (1.0, 0.05)));
        }
    }
    tracks
}
