//! From an estimator spec to its navigator, in every world: the one place the simulator
//! builds navigators. Each vehicle's estimators start at its truth plus one draw from the
//! run's seeded initial stream (the same draw for all of them), so comparisons are
//! paired. A world gives its vehicles' initial truth; what estimates it is built here.

use crate::engine::Track;
use crate::scenario::fleet::{Fleet, FleetEstimator, SignalModel};
use crate::scenario::{EstimatorKind, FixedBeacon, Host, MovingBeacon, PassiveUsbl};
use crate::seed::{Stream, gauss, rng, vehicle_rng};
use nalgebra::SVector;
use onebeacon::dsp::beamform::pyramid_8cm;
use onebeacon::dsp::receiver::{ModeReceiver, ReceiverConfig};
use onebeacon::dsp::waveform::rypkema_modes;
use onebeacon::filter::FilterKind;
use onebeacon::filter::factored::FactoredSettings;
use onebeacon::geo::wrap_angle;
use onebeacon::models::hoff::{DIM, idx};
use onebeacon::models::kinematic6dof::{Cov as Cov6, State as Eta};
use onebeacon::models::unicycle::{Cov, State};
use onebeacon::nav::usbl_track::TrackState;
use onebeacon::nav::{
    Aiding, GaussianTracker, IusblConfig, IusblNavigator, Navigator, ParticleTracker, PlanarConfig, PlanarNavigator,
    Range6DofNavigator, SingleBeaconNavigator,
};
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
    s.estimators
        .iter()
        .map(|e| {
            let nav =
                SingleBeaconNavigator::new(e.aiding(Host::FixedBeacon), e.ekf_tuning(), e.filter_kind(), 0.0, z0, p0);
            // the navigator's own default where the key is absent
            let nav = match e.mirror_recovery {
                Some(on) => nav.with_mirror_recovery(on),
                None => nav,
            }
            .with_min_speed(e.min_speed_m_s);
            Track { vehicle: 0, navigator: Box::new(nav) }
        })
        .collect()
}

/// Every estimator of a moving-beacon scenario on every vehicle, each vehicle's started
/// at its truth `truth0[v]` plus one draw (the same for all its estimators).
pub(crate) fn moving_beacon(s: &MovingBeacon, truth0: &[Eta], seed: u64, run: u64) -> Vec<Track> {
    let i = &s.initial;
    let a0 = i.attitude_sigma_deg.to_radians();
    let sigma0 = SVector::<f64, 6>::from([i.position_sigma_m, i.position_sigma_m, i.depth_sigma_m, a0, a0, a0]);
    let p0 = Cov6::from_diagonal(&sigma0.component_mul(&sigma0));
    let mut tracks = Vec::new();
    for (v, eta) in truth0.iter().enumerate() {
        let mut init_rng = vehicle_rng(seed, run, v, Stream::Initial);
        let eta0 = eta + sigma0.map(|sd| gauss(&mut init_rng, sd));
        tracks.extend(s.estimators.iter().map(|e| Track {
            vehicle: v,
            navigator: Box::new(Range6DofNavigator::new(
                e.sensor_noise(s.sensor_noise()),
                e.aiding(Host::MovingBeacon),
                e.filter_kind(),
                0.0,
                eta0,
                p0,
            )),
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

/// Every estimator of a passive-USBL scenario on every AUV, each AUV's started at its
/// truth `truth0[v]` plus one draw (the same for all its estimators; its particle
/// filters share one seed).
pub(crate) fn passive_usbl(s: &PassiveUsbl, truth0: &[TrackState], seed: u64, run: u64) -> Vec<Track> {
    let sigma0 = tracker_sigma(s);
    let mut tracks = Vec::new();
    for (v, x) in truth0.iter().enumerate() {
        let mut init_rng = vehicle_rng(seed, run, v, Stream::Initial);
        let mut x0 = x + sigma0.map(|sd| gauss(&mut init_rng, sd));
        x0[idx::PSI] = wrap_angle(x0[idx::PSI]);
        let pf_seed: u64 = init_rng.random();
        for e in &s.estimators {
            let config = e.tracker_config(s.tracker_noise());
            let navigator: Box<dyn Navigator> = match e.kind {
                EstimatorKind::Particle => {
                    let (n, settings) = e.particle_settings();
                    Box::new(ParticleTracker::new(config, settings, n, 0.0, &x0, &sigma0, pf_seed))
                }
                _ => Box::new(GaussianTracker::new(config, e.filter_kind(), 0.0, &x0, &sigma0)),
            };
            tracks.push(Track { vehicle: v, navigator });
        }
    }
    tracks
}

/// The iUSBL navigator's settings from the scenario.
pub(crate) fn iusbl_config(s: &Fleet, factored: bool) -> IusblConfig {
    let n = &s.navigation;
    IusblConfig {
        filter: FactoredSettings { particles: n.particles, max_range_m: n.max_range_m, reinitialised: n.reinitialised },
        factored,
        sigma_speed_m_s: n.sigma_speed_m_s,
        sigma_heading_rad: n.sigma_heading_deg.to_radians(),
        beacon_speed_m_s: n.beacon_speed_m_s,
        beacon_depth_m: s.dock.beacon_depth_m,
        confirmations: n.confirmations,
        floor: n.floor,
        beam_exponent: n.beam_exponent,
        fix_sigma_range_m: s.signal.range_sigma_m.max(0.05),
        fix_sigma_angle_rad: s.signal.angle_sigma_deg.to_radians().max(0.5f64.to_radians()),
        sound_speed_m_s: s.signal.sound_speed_m_s,
        ..IusblConfig::default()
    }
}

/// Every AUV's estimators of a fleet scenario, in the scenario's order.
pub(crate) fn fleet(s: &Fleet, seed: u64, run: u64) -> Vec<Track> {
    let (waveforms, elements) = (rypkema_modes(), pyramid_8cm());
    let mut tracks = Vec::new();
    for (v, a) in s.auvs.iter().enumerate() {
        let mut init_rng = vehicle_rng(seed, run, v, Stream::Initial);
        for e in &s.estimators {
            let filter_seed: u64 = init_rng.random();
            let navigator: Box<dyn Navigator> = match e {
                FleetEstimator::Iusbl | FleetEstimator::IusblJoint => {
                    let config = iusbl_config(s, *e == FleetEstimator::Iusbl);
                    let receiver = (s.signal.model == SignalModel::Channel).then(|| {
                        let rc = ReceiverConfig { sound_speed_m_s: s.signal.sound_speed_m_s, ..Default::default() };
                        ModeReceiver::new(&waveforms, &elements, rc)
                    });
                    Box::new(IusblNavigator::new(config, receiver, filter_seed))
                }
                FleetEstimator::DeadReckoning => {
                    let config = PlanarConfig { aiding: Aiding::NONE, ..PlanarConfig::default() };
                    let pose = (a.start_north_m, a.start_east_m, a.start_heading_deg.to_radians());
                    Box::new(PlanarNavigator::new(config, FilterKind::Ekf, 0.0, pose, 1.0, 0.05))
                }
            };
            tracks.push(Track { vehicle: v, navigator });
        }
    }
    tracks
}

/// An estimator of a log description (replay, stream, Python): the planar family its
/// configuration describes, built by the session at its start and again from its last
/// sound pose.
pub(crate) fn log(spec: &crate::scenario::EstimatorSpec) -> onebeacon::nav::session::Builder {
    onebeacon::nav::planar::builder(spec.planar_config(), spec.filter_kind())
}
