//! The session a vehicle's computer runs (and log replay, item by item): every
//! configured estimator fed the same time-ordered items one at a time, scored against
//! the ground truth when it comes. Items are what a log or a live stream carries:
//! measurements, beacon positions, ground truth, in the source's frame.

use crate::filter::FilterKind;
use crate::filter::consistency::nees;
use crate::geo::Frame;
use crate::nav::{BeaconFix, Estimate, Kind, Measurement, Navigator, Outcome, PlanarConfig, PlanarNavigator};
use nalgebra::{Vector2, Vector3};
use std::collections::{BTreeMap, BTreeSet};

/// A ground-truth pose (heading when the log has one). Items hold SI values in the
/// log's frame (x, y in `north_m`, `east_m` for NED logs) until [`Input::to_ned`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TruthPose {
    pub north_m: f64,
    pub east_m: f64,
    pub heading_rad: Option<f64>,
}

/// One item of the time-ordered stream.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Input {
    Measurement(Kind),
    /// A beacon's position now (a moving beacon's track; fixes later measurements).
    BeaconPosition {
        beacon_id: u32,
        position: Vector3<f64>,
    },
    Truth(TruthPose),
}

#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Item {
    pub t_s: f64,
    pub input: Input,
}

impl Input {
    /// This input, given in `frame`, in NED: the one place where logs and streams
    /// change frame.
    pub fn to_ned(self, frame: Frame) -> Input {
        let point = |p: Vector3<f64>| frame.to_ned(p.x, p.y, p.z);
        match self {
            Input::Measurement(mut m) => {
                if let Some(b) = m.beacon_mut() {
                    b.position_ned_m = point(b.position_ned_m);
                }
                Input::Measurement(match m {
                    Kind::Odometry { distance_m, heading_change_rad } => {
                        Kind::Odometry { distance_m, heading_change_rad: frame.turn_to_ned(heading_change_rad) }
                    }
                    Kind::Heading { heading_rad } => Kind::Heading { heading_rad: frame.heading_to_ned(heading_rad) },
                    Kind::Attitude { roll_rad, pitch_rad, heading_rad } => {
                        Kind::Attitude { roll_rad, pitch_rad, heading_rad: frame.heading_to_ned(heading_rad) }
                    }
                    other => other,
                })
            }
            Input::BeaconPosition { beacon_id, position } => {
                Input::BeaconPosition { beacon_id, position: point(position) }
            }
            Input::Truth(p) => {
                let n = frame.to_ned(p.north_m, p.east_m, 0.0);
                Input::Truth(TruthPose {
                    north_m: n.x,
                    east_m: n.y,
                    heading_rad: p.heading_rad.map(|h| frame.heading_to_ned(h)),
                })
            }
        }
    }
}

/// The position of beacon `id` for a measurement (log or stream): a fixed beacon's, or
/// NaN for a tracked one (the session supplies its latest position); otherwise the
/// message naming the known beacons.
pub fn resolve_beacon(
    id: u32,
    fixed: &BTreeMap<u32, Vector3<f64>>,
    tracked: &BTreeSet<u32>,
) -> Result<BeaconFix, String> {
    match fixed.get(&id) {
        Some(p) => Ok(BeaconFix::fixed(id, *p)),
        None if tracked.contains(&id) => Ok(BeaconFix::fixed(id, Vector3::repeat(f64::NAN))),
        None => {
            let known: Vec<String> = fixed.keys().chain(tracked).map(u32::to_string).collect();
            Err(format!("beacon {id} is not among the beacons ({})", known.join(", ")))
        }
    }
}

/// When and where the estimators start.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Start {
    /// At `t0_s` (the first item's time when `None`) from a NED pose (N, E, psi).
    At { t0_s: Option<f64>, pose: (f64, f64, f64) },
    /// At the first ground-truth item that carries a heading.
    FirstTruth,
}

/// A measurement an estimator's gate rejected.
#[derive(Debug, Clone, PartialEq)]
pub struct Rejection {
    pub estimator: usize,
    pub t_s: f64,
    pub kind: &'static str,
    pub beacon_id: u32,
    pub value: f64,
    pub nis: f64,
}

/// Error statistics of one estimator against the ground truth.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct ErrorStats {
    pub count: usize,
    pub sum_m: f64,
    pub sum_sq_m2: f64,
    pub max_m: f64,
    pub final_m: f64,
    pub rejected: usize,
    pub failed: usize,
    /// Position NEES (2 dof): sum and count of the finite ones, and how many were within
    /// the 95 % chi-square quantile.
    pub nees_sum: f64,
    pub nees_count: usize,
    pub nees_within_95: usize,
}

/// The 95 % quantile of chi-square with 2 degrees of freedom, -2 ln 0.05.
pub const NEES_95_2DOF: f64 = 5.991464547107982;

impl ErrorStats {
    pub fn rmse_m(&self) -> f64 {
        (self.sum_sq_m2 / self.count as f64).sqrt()
    }
    pub fn mean_m(&self) -> f64 {
        self.sum_m / self.count as f64
    }
    /// Mean position NEES: 2 for a consistent filter, more for an overconfident one.
    pub fn nees_mean(&self) -> f64 {
        self.nees_sum / self.nees_count as f64
    }
    /// Fraction of the NEES values within the 95 % quantile (0.95 when consistent).
    pub fn nees_within_95_fraction(&self) -> f64 {
        self.nees_within_95 as f64 / self.nees_count as f64
    }

    fn push(&mut self, err: f64, nees: f64) {
        self.count += 1;
        self.sum_m += err;
        self.sum_sq_m2 += err * err;
        self.max_m = self.max_m.max(err);
        self.final_m = err;
        if nees.is_finite() {
            self.nees_sum += nees;
            self.nees_count += 1;
            self.nees_within_95 += usize::from(nees <= NEES_95_2DOF);
        }
    }
}

/// What one item did: each estimator's outcome (none for beacon positions and truth)
/// and estimate, and when the item is a ground-truth pose each estimator's horizontal
/// error (m) and its NEES.
#[derive(Debug, Clone, PartialEq)]
pub struct Step {
    pub t_s: f64,
    pub outcomes: Vec<Option<Outcome>>,
    pub estimates: Vec<Estimate>,
    pub truth: Option<TruthPose>,
    pub errors: Option<Vec<(f64, f64)>>,
}

/// Horizontal error and its NEES against `truth` (NaN when the covariance is singular).
fn error_and_nees(e: &Estimate, truth: &TruthPose) -> (f64, f64) {
    let d = Vector2::new(e.north_m() - truth.north_m, e.east_m() - truth.east_m);
    (d.norm(), nees(&d, &e.horizontal_cov_m2).unwrap_or(f64::NAN))
}

/// Every estimator on one stream. Estimates and errors are in NED.
#[derive(Debug, Clone)]
pub struct Session {
    pub names: Vec<String>,
    /// The frame of the items pushed.
    frame: Frame,
    configs: Vec<(PlanarConfig, FilterKind)>,
    navs: Vec<PlanarNavigator>,
    start: Start,
    sigma_position_m: f64,
    sigma_heading_rad: f64,
    /// Only these beacons are used (all when `None`).
    beacons: Option<BTreeSet<u32>>,
    tracked: BTreeMap<u32, Vector3<f64>>,
    pub stats: Vec<ErrorStats>,
    pub rejected: Vec<Rejection>,
    /// Items before the start, and beacon measurements left out by the beacon filter
    /// or naming a beacon whose position is not known yet.
    pub before_start: usize,
    pub left_out: usize,
    /// The position of the last beacon heard.
    pub last_beacon: Option<Vector3<f64>>,
}

impl Session {
    pub fn new(
        frame: Frame,
        estimators: Vec<(String, PlanarConfig, FilterKind)>,
        start: Start,
        (sigma_position_m, sigma_heading_rad): (f64, f64),
        beacons: Option<BTreeSet<u32>>,
    ) -> Self {
        let n = estimators.len();
        let (names, configs) = estimators.into_iter().map(|(n, c, f)| (n, (c, f))).unzip();
        Self {
            names,
            frame,
            configs,
            navs: Vec::new(),
            start,
            sigma_position_m,
            sigma_heading_rad,
            beacons,
            tracked: BTreeMap::new(),
            stats: vec![ErrorStats::default(); n],
            rejected: Vec::new(),
            before_start: 0,
            left_out: 0,
            last_beacon: None,
        }
    }

    /// Every estimator's latest estimate (empty before the start).
    pub fn final_estimates(&self) -> Vec<Estimate> {
        self.navs.iter().map(PlanarNavigator::estimate).collect()
    }

    pub fn started(&self) -> bool {
        !self.navs.is_empty()
    }

    fn begin(&mut self, t0: f64, pose: (f64, f64, f64)) {
        self.navs = self
            .configs
            .iter()
            .map(|(c, f)| PlanarNavigator::new(*c, *f, t0, pose, self.sigma_position_m, self.sigma_heading_rad))
            .collect();
    }

    /// Processes one item (in the session's frame); `None` before the estimators start.
    pub fn push(&mut self, item: &Item) -> Option<Step> {
        let t = item.t_s;
        let item = &Item { t_s: t, input: item.input.to_ned(self.frame) };
        if let Input::BeaconPosition { beacon_id, position } = item.input {
            self.tracked.insert(beacon_id, position);
        }
        if !self.started() {
            match (self.start, &item.input) {
                (Start::At { t0_s, pose }, _) if t0_s.is_none_or(|t0| t >= t0) => self.begin(t0_s.unwrap_or(t), pose),
                (Start::FirstTruth, Input::Truth(TruthPose { north_m, east_m, heading_rad: Some(h) })) => {
                    self.begin(t, (*north_m, *east_m, *h))
                }
                _ => {
                    self.before_start += 1;
                    return None;
                }
            }
        }
        let mut outcomes = vec![None; self.navs.len()];
        let mut truth = None;
        match item.input {
            Input::Measurement(m) => {
                if let Some(kind) = self.resolve(m) {
                    let m = Measurement::new(t, kind);
                    for (i, nav) in self.navs.iter_mut().enumerate() {
                        let out = nav.process(&m);
                        self.stats[i].failed += usize::from(matches!(out, Outcome::Failed(_)));
                        if let Outcome::Rejected(nis) = out {
                            self.stats[i].rejected += 1;
                            let (beacon_id, value) = match kind {
                                Kind::Range { beacon, range_m } => (beacon.id, range_m),
                                Kind::Doppler { beacon, radial_speed_m_s }
                                | Kind::RangeDoppler { beacon, radial_speed_m_s, .. } => (beacon.id, radial_speed_m_s),
                                _ => (0, f64::NAN),
                            };
                            let kind = kind.name();
                            self.rejected.push(Rejection { estimator: i, t_s: t, kind, beacon_id, value, nis });
                        }
                        outcomes[i] = Some(out);
                    }
                }
            }
            Input::Truth(p) => truth = Some(p),
            Input::BeaconPosition { .. } => {}
        }
        let estimates: Vec<Estimate> = self.navs.iter().map(PlanarNavigator::estimate).collect();
        let errors = truth.map(|p| {
            estimates
                .iter()
                .zip(self.stats.iter_mut())
                .map(|(e, s)| {
                    let (err, nees) = error_and_nees(e, &p);
                    s.push(err, nees);
                    (err, nees)
                })
                .collect()
        });
        Some(Step { t_s: t, outcomes, estimates, truth, errors })
    }

    /// A beacon measurement with its beacon's position (tracked beacons: the latest),
    /// or `None` when the beacon is filtered out or its position is not known yet.
    fn resolve(&mut self, mut m: Kind) -> Option<Kind> {
        let Some(beacon) = m.beacon_mut() else { return Some(m) };
        let id = beacon.id;
        let position = if beacon.position_ned_m.iter().all(|v| v.is_finite()) {
            Some(beacon.position_ned_m)
        } else {
            self.tracked.get(&id).copied()
        };
        let allowed = self.beacons.as_ref().is_none_or(|b| b.contains(&id));
        let Some(position) = position.filter(|_| allowed) else {
            self.left_out += 1;
            return None;
        };
        beacon.position_ned_m = position;
        self.last_beacon = Some(position);
        Some(m)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn nees_quantile_and_statistics() {
        // chi-square(2) is exponential with mean 2: its 95 % quantile is -2 ln 0.05
        approx::assert_relative_eq!(NEES_95_2DOF, -2.0 * 0.05f64.ln(), max_relative = 1e-12);
        let mut s = ErrorStats::default();
        for (err, nees) in [(1.0, 1.0), (3.0, 9.0), (2.0, f64::NAN), (2.0, 2.0)] {
            s.push(err, nees);
        }
        assert_eq!((s.count, s.nees_count, s.nees_within_95), (4, 3, 2));
        approx::assert_relative_eq!(s.nees_mean(), 4.0);
        approx::assert_relative_eq!(s.nees_within_95_fraction(), 2.0 / 3.0);
        approx::assert_relative_eq!(s.rmse_m(), (18.0f64 / 4.0).sqrt());
        assert_eq!((s.max_m, s.final_m), (3.0, 2.0));
    }
}
