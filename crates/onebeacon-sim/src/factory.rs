//! Where each vehicle's estimators start in a run, and the one navigator no stream
//! configuration describes. Each vehicle's estimators start at its truth plus one draw
//! from the run's seeded initial stream (the same draw for all of them), so comparisons
//! are paired. A world gives its vehicles' initial truth; the vehicles' computers
//! ([`crate::computers`]) start from these draws. A fleet with the channel model gives
//! its iUSBL navigators their receiver, which no stream configuration describes.

use crate::scenario::fleet::{Fleet, SignalModel};
use crate::scenario::{EstimatorKind, EstimatorSpec, FixedBeacon, MovingBeacon, MovingBeaconCell, PassiveUsbl};
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
use onebeacon::models::unicycle::State;
use onebeacon::nav::IusblNavigator;
use onebeacon::nav::restart::Builder;
use onebeacon::nav::usbl_track::TrackState;
use rand::RngExt;

/// Where a fixed-beacon scenario's estimators start: the AUV's truth `z_true` plus one
/// draw of the scenario's initial standard deviations (the same for all estimators).
pub(crate) fn fixed_beacon_start(s: &FixedBeacon, z_true: State, seed: u64, run: u64) -> State {
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
    z_true + sigma0.map(|sd| gauss(&mut init_rng, sd))
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

/// How a fleet AUV's computer builds each estimator ([`crate::computers::OnBoard::aboard`]):
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
