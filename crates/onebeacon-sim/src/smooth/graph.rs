//! From a log's time-ordered items to the smoother's graph: a node (pose) at the start
//! and at every motion increment (odometry rows; speed or body-velocity samples, the
//! held velocity integrated since the node before), a motion factor between each two
//! nodes, heading fixes at their nearest node, acoustic measurements between the two
//! nodes around them, calibration variables after the poses with their priors.
//!
//! A craft tracked with a constant-velocity model (`track_accel_sigma_m_s2`: no motion
//! rows, or rows the model does not read, as the tracker does not) has a node (position
//! and velocity) at the start and at every acoustic measurement's time, joined by
//! constant-velocity factors.

use super::factor::{At, CalVars, Factor, Node};
use super::{Calibrate, Offsets, SmoothConfig, SmoothError};
use nalgebra::Vector3;
use onebeacon::filter::FilterKind;
use onebeacon::geo::wrap_angle;
use onebeacon::log::Log;
use onebeacon::nav::Kind;
use onebeacon::nav::session::Input;
use onebeacon::nav::tracking::INITIAL_VELOCITY_SIGMA_M_S;
use onebeacon::nav::{Measurement, PlanarConfig, planar};
use std::collections::{BTreeMap, BTreeSet};

/// Standard deviation of the heading change between two nodes when nothing measures
/// it (speed and compass logs: the compass holds the heading), rad.
const UNMEASURED_TURN_SIGMA_RAD: f64 = 1.0;
/// Floors of a motion factor's standard deviations (a zero-length increment), m and rad.
const MIN_STEP_SIGMA_M: f64 = 1e-3;
const MIN_TURN_SIGMA_RAD: f64 = 1e-4;
/// Measurements of a track closer in time than this share a node, s (a craft at 2 m/s
/// moves 2 mm in it).
const SAME_NODE_S: f64 = 1e-3;

#[derive(Debug)]
pub(crate) struct Graph {
    pub t_s: Vec<f64>,
    pub node: Node,
    /// The start's heading, rad (a track's course while at rest).
    pub start_heading_rad: f64,
    pub factors: Vec<Factor>,
    /// Dead reckoning from the start (the initial values of the poses; a track's: the
    /// tracker run forward), then the calibration variables' nominal values.
    pub x0: Vec<f64>,
    /// Calibration variables: name and index.
    pub calibration: Vec<(String, usize)>,
    /// Ground-truth (t, north, east, its own sigma) rows.
    pub truth: Vec<(f64, f64, f64, f64)>,
    /// Measurements used per kind, and items the smoother has no factor for, per kind.
    pub used: BTreeMap<&'static str, usize>,
    pub ignored: BTreeMap<&'static str, usize>,
}

/// An acoustic measurement waiting for its nodes.
struct Heard {
    t_s: f64,
    kind: Kind,
    beacon: Vector3<f64>,
    depth_m: f64,
}

pub(crate) fn build(log: &Log, beacons: Option<&BTreeSet<u32>>, cfg: &SmoothConfig) -> Result<Graph, SmoothError> {
    let start = log.initial_start(beacons)?;
    let noise = &cfg.noise;
    let track = cfg.track_accel_sigma_m_s2.is_some();
    let mut g = Graph {
        t_s: vec![start.t0_s],
        node: if track { Node::Track } else { Node::Pose },
        start_heading_rad: start.pose.2,
        factors: Vec::new(),
        x0: Vec::new(),
        calibration: Vec::new(),
        truth: Vec::new(),
        used: BTreeMap::new(),
        ignored: BTreeMap::new(),
    };
    // motion between nodes: (forward, lateral, turn, sigmas), applied once the
    // calibration variables have their indices
    let mut motion: Vec<Step> = Vec::new();
    let mut headings: Vec<(f64, f64)> = Vec::new();
    let mut heard: Vec<Heard> = Vec::new();
    let mut tracked: BTreeMap<u32, Vector3<f64>> = BTreeMap::new();
    let mut depth_m = 0.0;
    let mut held: Option<(f64, f64, Option<f64>)> = None; // forward, lateral speed, yaw rate
    let mut odometry = false;
    let step_sigma = |d: f64, turn: f64| {
        let s = (noise.distance_sigma_frac * d).max(MIN_STEP_SIGMA_M);
        let turn_var = (noise.heading_change_sigma_frac * turn).powi(2) + noise.heading_walk_rad_per_sqrt_m.powi(2) * d;
        [s, s, turn_var.sqrt().max(MIN_TURN_SIGMA_RAD)]
    };
    // the physical limits every item must respect before an estimator sees it (the
    // session's screen, `[limits]`)
    let limits = log.description.limits;
    let mut last_t: Option<f64> = None;
    for item in log.items()? {
        let item = item?;
        let t = item.t_s;
        if limits.check(&item.input, last_t.map(|l| t - l)).is_err() {
            count(&mut g.ignored, "screened by [limits]");
            continue;
        }
        last_t = Some(t);
        match item.input.to_ned(log.frame) {
            Input::Truth(p) => g.truth.push((t, p.north_m, p.east_m, p.sigma_m)),
            Input::BeaconPosition { beacon_id, position } => {
                tracked.insert(beacon_id, position);
            }
            _ if t < start.t0_s => {}
            // a track reads the acoustic measurements and the depth only
            Input::Measurement(m) if track && m.beacon().is_none() => match m {
                Kind::Depth { depth_m: d } => depth_m = d,
                _ => count(&mut g.ignored, m.name()),
            },
            Input::Measurement(m) => match m {
                Kind::Odometry { distance_m: d, heading_change_rad: turn } => {
                    odometry = true;
                    g.t_s.push(t);
                    motion.push((d, 0.0, Some(turn), step_sigma(d.abs(), turn)));
                    count(&mut g.used, "odometry");
                }
                Kind::BodyOdometry { forward_m: f, lateral_m: l, heading_change_rad: turn } => {
                    odometry = true;
                    g.t_s.push(t);
                    motion.push((f, l, Some(turn), step_sigma(f.hypot(l), turn)));
                    count(&mut g.used, "body_odometry");
                }
                Kind::Speed { .. } | Kind::BodyVelocity { .. } if odometry => count(&mut g.ignored, m.name()),
                Kind::Speed { speed_m_s } | Kind::BodyVelocity { nu: [speed_m_s, ..] } => {
                    let last = *g.t_s.last().unwrap_or(&start.t0_s);
                    if let Some((u, v, r)) = held
                        && t > last
                    {
                        let dt = t - last;
                        let (f, l) = (u * dt, v * dt);
                        let mut sigma = step_sigma(f.hypot(l), r.map_or(0.0, |r| r * dt));
                        let speed_sigma = noise.speed_sigma_m_s * dt;
                        sigma[0] = sigma[0].hypot(speed_sigma);
                        sigma[1] = sigma[1].hypot(speed_sigma);
                        if r.is_none() {
                            sigma[2] = UNMEASURED_TURN_SIGMA_RAD;
                        }
                        g.t_s.push(t);
                        motion.push((f, l, r.map(|r| r * dt), sigma));
                    }
                    held = Some(match m {
                        Kind::BodyVelocity { nu } => (nu[0], nu[1], Some(nu[5])),
                        _ => (speed_m_s, 0.0, None),
                    });
                    count(&mut g.used, m.name());
                }
                Kind::Heading { heading_rad } | Kind::Attitude { heading_rad, .. } => {
                    headings.push((t, heading_rad));
                    count(&mut g.used, m.name());
                }
                Kind::Depth { depth_m: d } => depth_m = d,
                Kind::Range { beacon, .. }
                | Kind::Doppler { beacon, .. }
                | Kind::RangeDoppler { beacon, .. }
                | Kind::Bearing { station: beacon, .. } => {
                    if beacons.is_some_and(|b| !b.contains(&beacon.id)) {
                        continue;
                    }
                    let position = if beacon.position_ned_m.iter().all(|v| v.is_finite()) {
                        beacon.position_ned_m
                    } else if let Some(p) = tracked.get(&beacon.id) {
                        *p
                    } else {
                        count(&mut g.ignored, "range before its beacon's position");
                        continue;
                    };
                    heard.push(Heard { t_s: t, kind: m, beacon: position, depth_m });
                }
                other => count(&mut g.ignored, other.name()),
            },
        }
    }
    if track {
        for h in &heard {
            if h.t_s - g.t_s[g.t_s.len() - 1] > SAME_NODE_S {
                g.t_s.push(h.t_s);
            }
        }
    } else if motion.is_empty() {
        return Err(SmoothError::NoMotion);
    }
    let n = g.t_s.len();
    // calibration variables after the nodes
    let mut next = g.node.size() * n;
    let mut var = |g: &mut Graph, on: bool, name: String, mean: f64, sigma: f64| {
        on.then(|| {
            let i = next;
            next += 1;
            g.calibration.push((name, i));
            g.factors.push(Factor::Prior { var: i, mean, sigma });
            i
        })
    };
    let Calibrate { range_scale, turn_scale, distance_scale, offsets, clock_drift } = cfg.calibrate;
    // a track has no motion to scale
    let (turn_scale, distance_scale) = (turn_scale && !track, distance_scale && !track);
    let p = &cfg.priors;
    let turn_var = var(&mut g, turn_scale, "turn_scale".into(), 1.0, p.turn_scale_sigma);
    let dist_var = var(&mut g, distance_scale, "distance_scale".into(), 1.0, p.distance_scale_sigma);
    let ranged = heard.iter().any(|h| matches!(h.kind, Kind::Range { .. } | Kind::RangeDoppler { .. }));
    let scale_var = var(&mut g, range_scale && ranged, "range_scale".into(), 1.0, p.range_scale_sigma);
    let drift_var = var(&mut g, clock_drift && ranged, "range_drift_m_per_s".into(), 0.0, p.drift_sigma_m_per_s);
    let ids: BTreeSet<u32> = heard
        .iter()
        .filter(|h| matches!(h.kind, Kind::Range { .. } | Kind::RangeDoppler { .. }))
        .filter_map(|h| h.kind.beacon().map(|b| b.id))
        .collect();
    let offset_vars: BTreeMap<u32, usize> = match offsets {
        Offsets::None => BTreeMap::new(),
        Offsets::Shared => var(&mut g, ranged, "range_offset_m".into(), p.offset_m, p.offset_sigma_m)
            .map(|i| ids.iter().map(|&id| (id, i)).collect())
            .unwrap_or_default(),
        Offsets::PerBeacon => ids
            .iter()
            .filter_map(|&id| {
                var(&mut g, true, format!("range_offset_m[{id}]"), p.offset_m, p.offset_sigma_m).map(|i| (id, i))
            })
            .collect(),
    };
    let (n0, e0, psi0) = start.pose;
    let heading_sigma = log.description.initial.heading_sigma_deg.to_radians();
    let ps = start.position_sigma_m;
    if let Some(accel) = cfg.track_accel_sigma_m_s2 {
        let (q, v) = (accel * accel, INITIAL_VELOCITY_SIGMA_M_S);
        for (var, mean, sigma) in [(0, n0, ps), (1, e0, ps), (2, 0.0, v), (3, 0.0, v)] {
            g.factors.push(Factor::Prior { var, mean, sigma });
        }
        for k in 0..n - 1 {
            let dt_s = g.t_s[k + 1] - g.t_s[k];
            g.factors.extend((0..2).map(|axis| Factor::ConstantVelocity { k, axis, dt_s, q }));
        }
        g.x0 = track_initial(&g.t_s, &heard, [n0, e0], ps, accel, cfg);
    } else {
        g.factors.push(Factor::PosePrior { k: 0, mean: [n0, e0, psi0], sigma: [ps, ps, heading_sigma] });
    }
    for (k, &(f, l, turn, sigma)) in motion.iter().enumerate() {
        g.factors.push(Factor::Motion {
            k,
            forward_m: f,
            lateral_m: l,
            turn_rad: turn,
            sigma,
            turn_scale: turn.and(turn_var),
            distance_scale: dist_var,
        });
    }
    // heading fixes at their nearest node
    let mut fixed_heading: BTreeMap<usize, f64> = BTreeMap::new();
    for &(t, h) in &headings {
        let k = nearest(&g.t_s, t);
        fixed_heading.insert(k, h);
        g.factors.push(Factor::Heading { k, heading_rad: h, sigma: noise.heading_sigma_rad });
    }
    let t0 = start.t0_s;
    for h in heard {
        let at = match g.node {
            Node::Pose => between(&g.t_s, h.t_s),
            Node::Track => At { k: nearest(&g.t_s, h.t_s), alpha: 0.0, next: false, dt_s: 0.0, node: Node::Track },
        };
        let (b, dz) = ([h.beacon.x, h.beacon.y], h.depth_m - h.beacon.z);
        let id = h.kind.beacon().map_or(0, |b| b.id);
        let cal = CalVars { scale: scale_var, offset: offset_vars.get(&id).copied(), drift: drift_var };
        let range = |g: &mut Graph, range_m: f64| {
            g.factors.push(Factor::Range {
                at,
                beacon: b,
                dz_m: dz,
                range_m,
                sigma: noise.range_sigma_m,
                cal,
                t_rel_s: h.t_s - t0,
            });
            count(&mut g.used, "range");
        };
        let doppler = |g: &mut Graph, speed_m_s: f64| {
            if at.node == Node::Track || (at.next && at.dt_s > 0.0) {
                g.factors.push(Factor::Doppler { at, beacon: b, dz_m: dz, speed_m_s, sigma: noise.doppler_sigma_m_s });
                count(&mut g.used, "doppler");
            }
        };
        match h.kind {
            Kind::Range { range_m, .. } => range(&mut g, range_m),
            Kind::Doppler { radial_speed_m_s, .. } => doppler(&mut g, radial_speed_m_s),
            Kind::RangeDoppler { range_m, radial_speed_m_s, .. } => {
                range(&mut g, range_m);
                doppler(&mut g, radial_speed_m_s);
            }
            Kind::Bearing { station_heading_rad, azimuth_rad, elevation_rad, .. } => {
                g.factors.push(Factor::Bearing {
                    at,
                    station: [h.beacon.x, h.beacon.y, h.beacon.z],
                    station_heading_rad,
                    depth_m: h.depth_m,
                    az_el: [azimuth_rad, elevation_rad],
                    sigma: cfg.usbl_sigma_rad,
                });
                count(&mut g.used, "bearing");
            }
            _ => {}
        }
    }
    // initial values: dead reckoning from the start with the turn scale that best
    // explains the ranges, nominal calibration
    let kappa = match turn_var {
        Some(_) => best_turn_scale(&g.factors, &motion, [n0, e0, psi0], &fixed_heading, p.turn_scale_sigma, next),
        None => 1.0,
    };
    if g.node == Node::Pose {
        g.x0 = dead_reckoning(&motion, [n0, e0, psi0], &fixed_heading, kappa);
    }
    g.x0.resize(next, 0.0);
    for (name, i) in &g.calibration {
        g.x0[*i] = match name.as_str() {
            "turn_scale" => kappa,
            n if n.ends_with("scale") => 1.0,
            n if n.starts_with("range_offset") => p.offset_m,
            _ => 0.0,
        };
    }
    Ok(g)
}

/// A track's initial values: the constant-velocity tracker of the same noise run
/// forward over the measurements, its position and velocity at each node (started at
/// rest, nodes no measurement reaches keep the start). Started at rest instead, the
/// solver falls into other minima (a mirror of the track about two beacons' baseline:
/// 20-190 m off in half of the test's runs).
fn track_initial(
    t_s: &[f64],
    heard: &[Heard],
    start: [f64; 2],
    sigma_m: f64,
    accel: f64,
    cfg: &SmoothConfig,
) -> Vec<f64> {
    let config = PlanarConfig {
        noise: cfg.noise,
        nis_gate: cfg.nis_gate,
        robust: cfg.kernel,
        track_accel_sigma_m_s2: Some(accel),
        ..PlanarConfig::default()
    };
    // the navigators' own factory: this config makes it the constant-velocity tracker
    let mut filter = planar::builder(config, FilterKind::Ekf)(t_s[0], (start[0], start[1], 0.0), sigma_m, 0.0);
    let mut x = [start[0], start[1], 0.0, 0.0].repeat(t_s.len());
    for h in heard {
        let mut kind = h.kind.clone();
        if let Some(b) = kind.beacon_mut() {
            b.position_ned_m = h.beacon;
        }
        filter.process(&Measurement { t_s: h.t_s, kind: Kind::Depth { depth_m: h.depth_m } });
        filter.process(&Measurement { t_s: h.t_s, kind });
        let e = filter.estimate();
        let (speed, course) = (e.speed_m_s.unwrap_or(0.0), e.heading_rad());
        let k = nearest(t_s, h.t_s);
        x[4 * k..4 * k + 4].copy_from_slice(&[e.north_m(), e.east_m(), speed * course.cos(), speed * course.sin()]);
    }
    x
}

/// Motion between nodes: forward, lateral, turn (if measured), standard deviations.
type Step = (f64, f64, Option<f64>, [f64; 3]);

/// The poses (north, east, heading per node, flat) integrated from `start` with the
/// measured turns times `kappa` (a node without one takes its heading fix, or keeps
/// the heading).
fn dead_reckoning(motion: &[Step], start: [f64; 3], fixed: &BTreeMap<usize, f64>, kappa: f64) -> Vec<f64> {
    let mut x = Vec::with_capacity(3 * (motion.len() + 1));
    x.extend_from_slice(&start);
    for (k, &(f, l, turn, _)) in motion.iter().enumerate() {
        let psi = x[3 * k + 2];
        let next_psi = match (turn, fixed.get(&(k + 1))) {
            (Some(turn), _) => psi + kappa * turn,
            (None, Some(&h)) => psi + wrap_angle(h - psi),
            (None, None) => psi,
        };
        let (s, c) = (0.5 * (psi + next_psi)).sin_cos();
        let (n, e) = (x[3 * k] + c * f - s * l, x[3 * k + 1] + s * f + c * l);
        x.extend_from_slice(&[n, e, next_psi]);
    }
    x
}

/// Turn scales searched for the initial values, each side of 1 in prior sigmas.
const TURN_SEARCH_SIGMAS: f64 = 3.0;
const TURN_SEARCH_STEPS: usize = 60;

/// The turn scale whose dead reckoning best explains the ranges (Huber's cost of their
/// residuals, the range scale fitted by least squares), searched over 1 +- 3 prior
/// sigmas: a turn scale error bends dead reckoning so far (plaza2's 4.6 % puts it 32 m
/// off) that the solver, started at 1, ends in another minimum.
fn best_turn_scale(
    factors: &[Factor],
    motion: &[Step],
    start: [f64; 3],
    fixed: &BTreeMap<usize, f64>,
    sigma: f64,
    dim: usize,
) -> f64 {
    if !factors.iter().any(|f| matches!(f, Factor::Range { .. })) {
        return 1.0;
    }
    let huber = onebeacon::nav::Robust::Huber { k: 1.345 };
    let cost = |kappa: f64| {
        let mut x = dead_reckoning(motion, start, fixed, kappa);
        x.resize(dim, 0.0); // the calibration variables, which a slant does not read
        // (slant, range, sigma) per range
        let ranges: Vec<(f64, f64, f64)> = factors.iter().filter_map(|f| f.range_slant(&x)).collect();
        let scale = ranges.iter().map(|(d, z, _)| z * d).sum::<f64>() / ranges.iter().map(|(d, ..)| d * d).sum::<f64>();
        ranges.iter().map(|(d, z, sigma)| -huber.log_density(((scale * d - z) / sigma).powi(2))).sum::<f64>()
    };
    let span = TURN_SEARCH_SIGMAS * sigma;
    (0..=TURN_SEARCH_STEPS)
        .map(|i| 1.0 - span + 2.0 * span * i as f64 / TURN_SEARCH_STEPS as f64)
        .map(|kappa| (kappa, cost(kappa)))
        .fold((1.0, f64::INFINITY), |best, (k, c)| if c < best.1 { (k, c) } else { best })
        .0
}

fn count(map: &mut BTreeMap<&'static str, usize>, kind: &'static str) {
    *map.entry(kind).or_default() += 1;
}

/// The node nearest in time to `t`.
fn nearest(t_s: &[f64], t: f64) -> usize {
    let k = t_s.partition_point(|&x| x < t);
    if k == 0 {
        0
    } else if k == t_s.len() || t - t_s[k - 1] <= t_s[k] - t {
        k - 1
    } else {
        k
    }
}

/// Where time `t` falls between pose nodes (clamped to the first and last).
pub(crate) fn between(t_s: &[f64], t: f64) -> At {
    let k = t_s.partition_point(|&x| x <= t).saturating_sub(1);
    let node = Node::Pose;
    if k + 1 >= t_s.len() {
        return At { k: t_s.len() - 1, alpha: 0.0, next: false, dt_s: 0.0, node };
    }
    let dt_s = t_s[k + 1] - t_s[k];
    let alpha = if dt_s > 0.0 { ((t - t_s[k]) / dt_s).clamp(0.0, 1.0) } else { 0.0 };
    At { k, alpha, next: true, dt_s, node }
}
