//! Where each vehicle's estimators start in a run, and the tracks no stream
//! configuration describes. Each vehicle's estimators start at its truth plus one draw
//! from the run's seeded initial stream (the same draw for all of them), so comparisons
//! are paired. A world gives its vehicles' initial truth; the vehicles' computers
//! ([`crate::computers`]) start from these draws. The fixed-beacon world's AUV runs
//! garin2024's filters, built here; a fleet with the channel model gives its iUSBL
//! navigators their receiver.

use crate::engine::Track;
use crate::scenario::fleet::{Fleet, SignalModel};
use crate::scenario::{EstimatorKind, EstimatorSpec, FixedBeacon, Host, MovingBeacon, MovingBeaconCell, PassiveUsbl};
use crate::seed::{Stream, gauss, rng, vehicle_rng};
use nalgebra::{SVector, Vector2};
use onebeacon::config::builder::{TrackerStart, VehicleModel};
use onebeacon::dsp::beamform::pyramid_8cm;
use onebeacon::dsp::receiver::{ModeReceiver, ReceiverConfig};
use onebeacon::dsp::waveform::rypkema_modes;
use onebeacon::geo::wrap_angle;
use onebeacon::guidance::{PolarGrid, best_standoff};
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

/// The seeds of each estimator of every AUV of a fleet scenario's run, in track order.
pub(crate) fn fleet_seeds(s: &Fleet, seed: u64, run: u64) -> Vec<Vec<u64>> {
    (0..s.auvs.len())
        .map(|v| {
            let mut init_rng = vehicle_rng(seed, run, v, Stream::Initial);
            s.estimators.iter().map(|_| init_rng.random()).collect()
        })
        .collect()
}

/// How a fleet AUV's computer builds each estimator ([`crate::computers::OnBoard::tracks`]):
/// by its spec; with the channel model the iUSBL navigators take the captures through
/// their receiver, which no stream configuration describes.
pub(crate) fn fleet_builder(s: &Fleet) -> impl Fn(&EstimatorSpec, TrackerStart, VehicleModel) -> Builder {
    let (waveforms, elements) = (rypkema_modes(), pyramid_8cm());
    let channel = s.signal.model == SignalModel::Channel;
    let sound = s.signal.sound_speed_m_s;
    move |e, start, model| {
        if !(channel && e.kind.iusbl()) {
            return e.builder(start, model);
        }
        let config = e.iusbl.clone().unwrap_or_default().config(e.kind == EstimatorKind::Iusbl);
        let (elements, filter_seed) = (elements.clone(), e.seed.unwrap_or(0));
        Box::new(move |_, _, _, _| {
            let rc = ReceiverConfig { sound_speed_m_s: sound, ..Default::default() };
            let receiver = ModeReceiver::new(&waveforms, &elements, rc);
            Box::new(IusblNavigator::new(config, Some(receiver), filter_seed as u64))
        })
    }
}

/// The ASV's start in a moving-beacon world: the best standoff for the vehicle's start
/// depth and the ASV's reach (sousa Fig. 4.7), in the direction `asv.start_bearing_deg`
/// from the vehicle.
pub(crate) fn initial_asv_position(s: &MovingBeacon, cell: &MovingBeaconCell) -> Vector2<f64> {
    let reach = s.asv.max_speed_m_s * s.acoustics.ping_period_s;
    let grid = PolarGrid { radial: 20, angular: 36, refinements: 10 };
    let d = best_standoff((cell.depth_m - s.asv.transducer_depth_m).max(0.0), reach, grid).distance_m;
    let b = s.asv.start_bearing_deg.to_radians();
    Vector2::new(s.vehicle.start_north_m, s.vehicle.start_east_m) + Vector2::new(b.cos(), b.sin()) * d
}
