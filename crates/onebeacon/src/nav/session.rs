//! The session a vehicle's computer runs (and log replay, item by item): every
//! configured estimator fed the same time-ordered items one at a time, scored against
//! the ground truth when it comes. Items are what a log or a live stream carries:
//! measurements, beacon positions, ground truth, in the source's frame.

use crate::geo::Frame;
use crate::nav::diagnosis::{BeaconStats, PerBeacon};
use crate::nav::evaluation::{ErrorStats, horizontal_error};
pub use crate::nav::item::{Input, Item, TruthPose, resolve_beacon};
use crate::nav::limits::Limits;
use crate::nav::restart::Restart;
use crate::nav::{Estimate, Kind, Measurement, Navigator, Outcome};
use nalgebra::Vector3;
use std::collections::{BTreeMap, BTreeSet};

/// When and where the estimators start.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Start {
    /// At `t0_s` (the first item's time when `None`) from a NED pose (N, E, psi).
    At { t0_s: Option<f64>, pose: (f64, f64, f64) },
    /// At the first ground-truth item that carries a heading.
    FirstTruth,
    /// A ground truth without heading, in a stream (which cannot look ahead): at the
    /// first ground-truth item `track_m` from the first one (`from`, once seen), there,
    /// heading along the chord between the two.
    Track { track_m: f64, from: Option<(f64, f64)> },
}

/// A measurement an estimator's gate rejected, or an item screened out for every
/// estimator (`estimator` None, `nis` NaN) with its reason.
#[derive(Debug, Clone, PartialEq)]
pub struct Rejection {
    pub estimator: Option<usize>,
    pub t_s: f64,
    pub kind: &'static str,
    pub beacon_id: u32,
    pub value: f64,
    pub nis: f64,
    pub reason: String,
}

/// Items in a row past the time gap that are taken as a new time base.
const JUMP_ITEMS: usize = 3;

/// Whether two items are the same message: equal, NaN fields (a tracked beacon's
/// position before it is resolved) equal to NaN. A capture (thousands of samples) is
/// compared by value alone, not through its printed form.
fn same_input(a: &Input, b: &Input) -> bool {
    let capture = matches!(a, Input::Measurement(Kind::Capture(_)));
    a == b || (!capture && a.name() == b.name() && format!("{a:?}") == format!("{b:?}"))
}

/// How many items of one time are kept to screen repeats among them (a logger or a
/// bridge that sends a message twice); past it, repeats at that time are not looked for.
const REPEATS_KEPT: usize = 64;

/// An item that no estimator saw: out of time order, out of the [`Limits`], or naming a
/// beacon whose position is not known.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{reason}")]
pub struct Screened {
    pub reason: String,
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
    /// The estimators started again from their last sound estimate during this item.
    pub reinitialised: Vec<usize>,
}

/// What taking one item did ([`Session::take`]): each estimator's outcome (none for
/// beacon positions and truth; held by the session until its next item, so that taking
/// an item allocates nothing), and the ground-truth pose when it is one.
#[derive(Debug, Clone, PartialEq)]
pub struct Taken<'a> {
    pub t_s: f64,
    pub outcomes: &'a [Option<Outcome>],
    pub truth: Option<TruthPose>,
    /// The measurement the estimators were given (its beacon's position resolved).
    pub measurement: Option<Kind>,
}

/// The value of a measurement that rejection logs show (range, else radial speed).
fn measured_value(m: &Kind) -> f64 {
    match *m {
        Kind::Range { range_m, .. } | Kind::RangeDoppler { range_m, .. } => range_m,
        Kind::Doppler { radial_speed_m_s, .. } => radial_speed_m_s,
        _ => f64::NAN,
    }
}

pub use super::restart::Builder;

/// Every estimator on one stream. Estimates and errors are in NED.
pub struct Session {
    pub names: Vec<String>,
    /// The frame of the items pushed.
    frame: Frame,
    /// Until the start, the estimators' builders; then each one's restart policy.
    builders: Vec<Builder>,
    navs: Vec<Box<dyn Navigator>>,
    restarts: Vec<Restart>,
    start: Start,
    sigma_position_m: f64,
    sigma_heading_rad: f64,
    /// Only these beacons are used (all when `None`).
    beacons: Option<BTreeSet<u32>>,
    tracked: BTreeMap<u32, Vector3<f64>>,
    pub stats: Vec<ErrorStats>,
    /// The ground-truth rows scored and the sum of their own variances (sigma_m^2 per
    /// axis): a reference with an error of its own puts a floor under every RMSE.
    pub reference_rows: usize,
    pub reference_var_sum_m2: f64,
    /// Each estimator's corrections beacon by beacon (at most `limits.max_beacons`).
    pub beacon_stats: Vec<PerBeacon>,
    /// The beacon held out ([`Session::with_held_out`]) and each estimator's prediction
    /// of its ranges.
    held_out: Option<u32>,
    pub held_out_stats: Vec<BeaconStats>,
    /// Gate rejections and screened items, the first `limits.max_rejections` of them.
    pub rejected: Vec<Rejection>,
    /// Items before the start, beacon measurements left out by the beacon filter, and
    /// items screened out (time order, limits, unknown beacon position).
    pub before_start: usize,
    pub left_out: usize,
    pub screened: usize,
    /// A ground-truth row without heading was screened while the session waits for one
    /// (said once: the rows after it wait silently).
    told_no_heading: bool,
    /// The position of the last beacon heard.
    pub last_beacon: Option<Vector3<f64>>,
    limits: Limits,
    /// The time of the last item accepted.
    last_t: Option<f64>,
    /// Items in a row that jumped past the gap: the latest's time and their count.
    jump: Option<(f64, usize)>,
    /// The items taken at the time of the last one (at most [`REPEATS_KEPT`]), against
    /// which a repeated message is screened.
    at_last_t: Vec<Input>,
    /// What the estimators made of the last item taken ([`Taken::outcomes`]).
    outcomes: Vec<Option<Outcome>>,
    /// Whether the estimators keep their history ([`Session::with_history`]).
    keep_history: bool,
}

impl std::fmt::Debug for Session {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Session").field("names", &self.names).field("started", &self.started()).finish_non_exhaustive()
    }
}

impl Session {
    pub fn new(
        frame: Frame,
        estimators: Vec<(String, Builder)>,
        start: Start,
        (sigma_position_m, sigma_heading_rad): (f64, f64),
        beacons: Option<BTreeSet<u32>>,
    ) -> Self {
        let n = estimators.len();
        let (names, builders) = estimators.into_iter().unzip();
        Self {
            names,
            frame,
            builders,
            navs: Vec::new(),
            start,
            sigma_position_m,
            sigma_heading_rad,
            beacons,
            tracked: BTreeMap::new(),
            stats: vec![ErrorStats::default(); n],
            reference_rows: 0,
            reference_var_sum_m2: 0.0,
            beacon_stats: vec![PerBeacon::default(); n],
            held_out: None,
            held_out_stats: vec![BeaconStats::default(); n],
            rejected: Vec::new(),
            before_start: 0,
            left_out: 0,
            screened: 0,
            told_no_heading: false,
            last_beacon: None,
            limits: Limits::default(),
            last_t: None,
            jump: None,
            at_last_t: Vec::new(),
            outcomes: Vec::new(),
            restarts: Vec::new(),
            keep_history: false,
        }
    }

    /// The session with its estimators' initial position sigma set to `sigma_m`.
    pub fn with_position_sigma(mut self, sigma_m: f64) -> Self {
        self.sigma_position_m = sigma_m;
        self
    }

    /// The session with every estimator that can keeping its history for a
    /// Rauch-Tung-Striebel pass ([`super::capability::Smoothing::keep_history`]; from a
    /// restart on, for one restarted).
    pub fn with_history(mut self) -> Self {
        self.keep_history = true;
        self
    }

    /// The session with beacon `id` held out: no estimator takes its measurements; each
    /// one predicts its ranges ([`Navigator::weigh`]) into `held_out_stats`. A score that
    /// needs no ground truth: how well the others predict a beacon never heard.
    pub fn with_held_out(mut self, id: u32) -> Self {
        self.held_out = Some(id);
        self
    }

    /// The session with `limits` instead of [`Limits::default`].
    pub fn with_limits(mut self, limits: Limits) -> Self {
        self.limits = limits;
        self
    }

    pub fn limits(&self) -> &Limits {
        &self.limits
    }

    /// The ground truth's own error over the rows scored, the RMS of their sigma_m (per
    /// axis), m; 0 for an exact truth.
    pub fn reference_sigma_m(&self) -> f64 {
        if self.reference_rows == 0 { 0.0 } else { (self.reference_var_sum_m2 / self.reference_rows as f64).sqrt() }
    }

    /// The floor a ground truth with its own error puts under every RMSE, m: a perfect
    /// estimator scored against it errs sqrt(2 mean sigma^2) (sigma on each axis).
    pub fn rmse_floor_m(&self) -> f64 {
        std::f64::consts::SQRT_2 * self.reference_sigma_m()
    }

    /// What the estimators' innovations say of the run so far
    /// ([`super::diagnosis::findings`]): one line each.
    pub fn findings(&self) -> Vec<String> {
        super::diagnosis::findings(&self.names, &self.stats, &self.beacon_stats)
    }

    /// What the session waits for before it starts.
    pub fn waiting_for(&self) -> String {
        match self.start {
            Start::At { t0_s: Some(t0), .. } => format!("the start time {t0} s"),
            Start::At { t0_s: None, .. } => "the first item".into(),
            Start::FirstTruth => "the first ground_truth item with a heading".into(),
            Start::Track { track_m, .. } => format!("a ground-truth track {track_m} m long"),
        }
    }

    /// Every estimator's latest estimate (empty before the start).
    pub fn final_estimates(&self) -> Vec<Estimate> {
        self.navs.iter().map(|n| n.estimate()).collect()
    }

    /// Each estimator's per-beacon range offsets (beacon, offset m, its sigma m); empty
    /// for one without them.
    pub fn beacon_offsets(&self) -> Vec<Vec<(u32, f64, f64)>> {
        self.navs.iter().map(|n| n.beacon_offsets().map(|o| o.offsets()).unwrap_or_default()).collect()
    }

    /// Estimator `i`'s navigator (None before the start).
    pub fn navigator(&self, i: usize) -> Option<&dyn Navigator> {
        self.navs.get(i).map(|n| &**n)
    }

    /// Estimator `i`'s Rauch-Tung-Striebel smoothed run kept since the start
    /// ([`Session::with_history`]); None for one that keeps none, or before the start.
    pub fn smoothed(&mut self, i: usize) -> Option<Vec<Estimate>> {
        Some(self.navs.get_mut(i)?.smoothing()?.smoothed())
    }

    pub fn started(&self) -> bool {
        !self.navs.is_empty()
    }

    /// Starts the estimators by time `t_s` when their start is a given pose due by then
    /// (a controller that decides before the first item reads them); whether they run.
    /// A time further past the start time than `limits.max_time_gap_s` starts nothing:
    /// it is another clock, which the items set ([`Session::push`]).
    pub fn start_by(&mut self, t_s: f64) -> bool {
        let gap = self.limits.max_time_gap_s;
        if let (false, Start::At { t0_s, pose }) = (self.started(), self.start)
            && t0_s.is_none_or(|t0| t_s >= t0 && t_s - t0 <= gap)
        {
            self.begin(t0_s.unwrap_or(t_s), pose);
        }
        self.started()
    }

    fn begin(&mut self, t0: f64, pose: (f64, f64, f64)) {
        let sigmas = (self.sigma_position_m, self.sigma_heading_rad);
        self.restarts = std::mem::take(&mut self.builders).into_iter().map(|b| Restart::new(b, pose, sigmas)).collect();
        self.navs = self.restarts.iter().map(|r| r.build(t0, pose)).collect();
        if self.keep_history {
            self.navs.iter_mut().filter_map(|n| n.smoothing()).for_each(|s| s.keep_history());
        }
    }

    /// Predicts every estimator to `t_s` (a clock tick: the time of a simulator's step),
    /// writes their estimates into `estimates` (one per estimator) and applies the
    /// restart policy as after an item: the estimators started again (empty, allocating
    /// nothing, when none was), or `None` before the start. The items' time order stays
    /// the items' own: an item older than `t_s` is still taken.
    pub fn predict_to(&mut self, t_s: f64, estimates: &mut [Estimate]) -> Option<Vec<usize>> {
        if !self.started() {
            return None;
        }
        debug_assert_eq!(estimates.len(), self.navs.len(), "one estimate per estimator");
        for (nav, e) in self.navs.iter_mut().zip(estimates.iter_mut()) {
            nav.predict_to(t_s);
            *e = nav.estimate();
        }
        Some(self.restart_unsound(estimates, t_s))
    }

    /// A filter whose state stops being sound starts again from its last sound estimate
    /// (`estimates` then hold the new one's) at `t_s`: reported, never silently kept.
    fn restart_unsound(&mut self, estimates: &mut [Estimate], t_s: f64) -> Vec<usize> {
        let mut reinitialised = Vec::new();
        for (i, e) in estimates.iter_mut().enumerate() {
            if self.restarts[i].apply(&mut self.navs[i], e, t_s) {
                if self.keep_history
                    && let Some(s) = self.navs[i].smoothing()
                {
                    s.keep_history();
                }
                self.stats[i].reinitialised += 1;
                reinitialised.push(i);
            }
        }
        reinitialised
    }

    /// Records a rejection while the log has room.
    fn log_rejection(&mut self, r: Rejection) {
        if self.rejected.len() < self.limits.max_rejections {
            self.rejected.push(r);
        }
    }

    /// Screens `item` out: counted, logged, reported.
    fn screen(&mut self, item: &Item, reason: String) -> Screened {
        self.screened += 1;
        let (beacon_id, value) = match &item.input {
            Input::Measurement(m) => (m.beacon().map_or(0, |b| b.id), measured_value(m)),
            Input::BeaconPosition { beacon_id, .. } => (*beacon_id, f64::NAN),
            Input::Truth(_) => (0, f64::NAN),
        };
        let kind = item.input.name();
        let r = Rejection { estimator: None, t_s: item.t_s, kind, beacon_id, value, nis: f64::NAN, reason };
        self.log_rejection(r.clone());
        Screened { reason: r.reason }
    }

    /// Processes one item (in the session's frame) and scores it: `Ok(None)` before the
    /// estimators start, `Err` for an item screened out (no estimator saw it; the
    /// session goes on). [`Session::take`], then every estimate, the restart policy and,
    /// for a ground-truth item, each estimator's error.
    pub fn push(&mut self, item: &Item) -> Result<Option<Step>, Screened> {
        let Some(Taken { t_s: t, outcomes, truth, measurement }) = self.take(item)? else { return Ok(None) };
        let outcomes = outcomes.to_vec();
        if let Some(kind) = &measurement {
            self.count_outcomes(t, kind, &outcomes);
        }
        let mut estimates: Vec<Estimate> = self.navs.iter().map(|n| n.estimate()).collect();
        let reinitialised = self.restart_unsound(&mut estimates, t);
        if let Some(p) = truth {
            self.reference_rows += 1;
            self.reference_var_sum_m2 += p.sigma_m * p.sigma_m;
        }
        let errors = truth.map(|p| {
            estimates
                .iter()
                .zip(self.stats.iter_mut())
                .map(|(e, s)| {
                    let (err, nees) = horizontal_error(e, p.north_m, p.east_m, p.sigma_m);
                    s.push(err, nees);
                    (err, nees.unwrap_or(f64::NAN))
                })
                .collect()
        });
        Ok(Some(Step { t_s: t, outcomes, estimates, truth, errors, reinitialised }))
    }

    /// Takes one item (in the session's frame) into every estimator, as
    /// [`Session::push`] does, without asking for their estimates: no restart check, no
    /// counting of outcomes, no scoring (the simulator's engine, which counts and scores
    /// for itself, at its steps: [`Session::predict_to`]). `Ok(None)` before the start.
    pub fn take(&mut self, item: &Item) -> Result<Option<Taken<'_>>, Screened> {
        let t = item.t_s;
        let dt = self.last_t.map(|last| t - last);
        if !t.is_finite() {
            return Err(self.screen(item, format!("time {t} is not a finite number")));
        }
        if let Some(dt) = dt.filter(|dt| *dt < 0.0) {
            return Err(self.screen(item, format!("time {t} s is {:.6} s before the previous item's", -dt)));
        }
        // before the first item the start time given is the previous time: a stream on
        // another clock (UNIX seconds against t0_s = 0) is a jump like any other
        let given_t0 = match self.start {
            Start::At { t0_s: Some(t0), .. } if self.last_t.is_none() && !self.started() => Some(t0),
            _ => None,
        };
        let gap = dt.or(given_t0.map(|t0| t - t0));
        if let Some(dt) = gap.filter(|dt| *dt > self.limits.max_time_gap_s) {
            // a lone jump is a corrupt time; a few items in a row on the new clock are a
            // real gap (a vehicle back from the surface), taken as the new time base
            let most = self.limits.max_time_gap_s;
            let previous = if given_t0.is_some() { "the start time (initial.t0_s)" } else { "the previous item" };
            let seen = match self.jump {
                Some((t_jump, n)) if (t - t_jump).abs() <= most => n + 1,
                _ => 1,
            };
            self.jump = Some((t, seen));
            if seen < JUMP_ITEMS {
                return Err(self.screen(
                    item,
                    format!(
                        "time {t:?} s jumps {dt:?} s past {previous} (limits.max_time_gap_s = {most}; \
                         {JUMP_ITEMS} items in a row on the new clock restart it)"
                    ),
                ));
            }
            // the new clock is the time base: estimators not yet started start on it
            if let Start::At { pose, .. } = self.start
                && given_t0.is_some()
            {
                self.start = Start::At { t0_s: None, pose };
            }
        }
        if let Err(reason) = self.limits.check(&item.input, dt) {
            return Err(self.screen(item, reason));
        }
        // a message repeated at its own time (a logger or a bridge sending it twice) is
        // weighed once: twice would count its evidence twice, and a particle filter
        // with no time to spread between them collapses
        if self.last_t == Some(t) && self.at_last_t.iter().any(|a| same_input(a, &item.input)) {
            let reason = "a repeat of an item already taken at this time (a message sent twice)";
            return Err(self.screen(item, reason.into()));
        }
        if self.last_t != Some(t) {
            self.at_last_t.clear();
        }
        if self.at_last_t.len() < REPEATS_KEPT {
            self.at_last_t.push(item.input.clone());
        }
        let in_ned;
        let item = if self.frame == Frame::Ned {
            item
        } else {
            in_ned = Item { t_s: t, input: item.input.clone().to_ned(self.frame) };
            &in_ned
        };
        if let Input::BeaconPosition { beacon_id, position } = item.input {
            if !self.tracked.contains_key(&beacon_id) && self.tracked.len() >= self.limits.max_beacons {
                let most = self.limits.max_beacons;
                return Err(
                    self.screen(item, format!("beacon {beacon_id} is one too many (limits.max_beacons = {most})"))
                );
            }
            self.tracked.insert(beacon_id, position);
        }
        self.last_t = Some(t);
        self.jump = None;
        if !self.started() {
            match (self.start, &item.input) {
                (Start::At { t0_s, pose }, _) if t0_s.is_none_or(|t0| t >= t0) => self.begin(t0_s.unwrap_or(t), pose),
                (Start::FirstTruth, Input::Truth(TruthPose { north_m, east_m, heading_rad: Some(h), .. })) => {
                    self.begin(t, (*north_m, *east_m, *h))
                }
                (Start::Track { track_m, from }, Input::Truth(TruthPose { north_m, east_m, .. })) => {
                    let (n0, e0) = from.unwrap_or((*north_m, *east_m));
                    if (north_m - n0).hypot(east_m - e0) < track_m {
                        self.start = Start::Track { track_m, from: Some((n0, e0)) };
                        self.before_start += 1;
                        return Ok(None);
                    }
                    self.begin(t, (*north_m, *east_m, (east_m - e0).atan2(north_m - n0)))
                }
                (Start::FirstTruth, Input::Truth(TruthPose { heading_rad: None, .. })) if !self.told_no_heading => {
                    self.told_no_heading = true;
                    self.before_start += 1;
                    let reason = "a ground-truth row without heading: the estimators start at the first one with a \
                                  heading ([initial] heading_from = \"column\"); for a truth without heading set \
                                  heading_from = \"track\" (said once)";
                    return Err(self.screen(item, reason.into()));
                }
                _ => {
                    self.before_start += 1;
                    return Ok(None);
                }
            }
        }
        self.outcomes.clear();
        self.outcomes.resize(self.navs.len(), None);
        let (mut truth, mut measurement) = (None, None);
        match &item.input {
            Input::Measurement(m) => {
                if let Some(kind) = self.resolve(m.clone()).map_err(|reason| self.screen(item, reason))? {
                    let m = Measurement::new(t, kind);
                    let held = self.held_out.is_some() && m.kind.beacon().map(|b| b.id) == self.held_out;
                    for (i, nav) in self.navs.iter_mut().enumerate().filter(|_| held) {
                        if let Some(innovation) = nav.weighing().and_then(|w| w.weigh(&m)) {
                            self.held_out_stats[i].push_innovation(&m.kind, innovation, false);
                        }
                    }
                    for (nav, out) in self.navs.iter_mut().zip(&mut self.outcomes).filter(|_| !held) {
                        *out = Some(nav.process(&m));
                    }
                    measurement = Some(m.kind);
                }
            }
            Input::Truth(p) => truth = Some(*p),
            Input::BeaconPosition { .. } => {}
        }
        Ok(Some(Taken { t_s: t, outcomes: &self.outcomes, truth, measurement }))
    }

    /// Counts what each estimator made of measurement `kind` (`outcomes`, at `t_s`): its
    /// error statistics, its corrections beacon by beacon, the gate's rejections.
    fn count_outcomes(&mut self, t_s: f64, kind: &Kind, outcomes: &[Option<Outcome>]) {
        for (i, out) in outcomes.iter().enumerate() {
            let Some(out) = out else { continue };
            self.stats[i].push_outcome(out, true);
            self.beacon_stats[i].push(kind, out, self.limits.max_beacons);
            if let Outcome::Rejected(super::Innovation { nis, .. }) = *out {
                self.log_rejection(Rejection {
                    estimator: Some(i),
                    t_s,
                    kind: kind.name(),
                    beacon_id: kind.beacon().map_or(0, |b| b.id),
                    value: measured_value(kind),
                    nis,
                    reason: "NIS gate".into(),
                });
            }
        }
    }

    /// A beacon measurement with its beacon's position (tracked beacons: the latest).
    /// A beacon left out by the beacon filter is counted in `left_out` and goes to no
    /// estimator (`None`); a beacon whose position is not known is an error.
    fn resolve(&mut self, mut m: Kind) -> Result<Option<Kind>, String> {
        let Some(beacon) = m.beacon() else { return Ok(Some(m)) };
        let id = beacon.id;
        let given = beacon.position_ned_m.iter().all(|v| v.is_finite());
        let position = if given { Some(beacon.position_ned_m) } else { self.tracked.get(&id).copied() };
        let Some(position) = position else {
            return Err(format!("beacon {id}'s position is not known yet (no beacon_position item for it)"));
        };
        if self.held_out != Some(id) && !self.beacons.as_ref().is_none_or(|b| b.contains(&id)) {
            self.left_out += 1;
            return Ok(None);
        }
        // written only when filled in: a capture shared with its item is copied then only
        if !given && let Some(beacon) = m.beacon_mut() {
            beacon.position_ned_m = position;
        }
        self.last_beacon = Some(position);
        Ok(Some(m))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::filter::FilterKind;
    use crate::nav::{BeaconFix, PlanarConfig};

    /// Builders of the planar family for named configurations.
    fn planar(est: Vec<(String, PlanarConfig, FilterKind)>) -> Vec<(String, Builder)> {
        est.into_iter().map(|(n, c, f)| (n, crate::nav::planar::builder(c, f))).collect()
    }

    /// A lone jump in time is screened out; three items in a row on a new clock (a
    /// vehicle back from a long gap) restart it, so a session never goes deaf.
    #[test]
    fn a_real_gap_restarts_the_clock() {
        let start = Start::At { t0_s: None, pose: (0.0, 0.0, 0.0) };
        let mut s = Session::new(Frame::Ned, Vec::new(), start, (1.0, 0.1), None);
        let item = |t: f64| Item { t_s: t, input: Input::Measurement(Kind::Speed { speed_m_s: 1.0 }) };
        for t in [0.0, 1.0, 2.0] {
            assert!(s.push(&item(t)).is_ok());
        }
        assert!(s.push(&item(1e15)).is_err());
        assert!(s.push(&item(3.0)).is_ok(), "a lone jump leaves the clock alone");
        let after: Vec<bool> = [10_000.0, 10_001.0, 10_002.0, 10_003.0].map(|t| s.push(&item(t)).is_ok()).to_vec();
        assert_eq!(after, [false, false, true, true]);
        assert_eq!(s.screened, 3);
    }

    /// A stream on another clock than the configuration's `t0_s` (a vehicle counting
    /// UNIX seconds against `run --messages`' t0_s = 0): the first items are a jump like
    /// any other, screened until three in a row set the new time base, and the
    /// estimators start there instead of predicting across 1.7e9 s (cfb7f93: 3.3e9 m off,
    /// every item accepted).
    #[test]
    fn the_gap_from_the_start_time_to_the_first_item_is_screened() {
        let est = vec![("dr".to_string(), PlanarConfig::default(), FilterKind::Ekf)];
        let start = Start::At { t0_s: Some(0.0), pose: (0.0, 0.0, 0.0) };
        let mut s = Session::new(Frame::Ned, planar(est), start, (1.0, 0.1), None);
        let t0 = 1.7e9;
        // a controller deciding on that clock does not start the estimators at 0 either
        assert!(!s.start_by(t0));
        let speed = |t: f64| Item { t_s: t, input: Input::Measurement(Kind::Speed { speed_m_s: 1.0 }) };
        let first = s.push(&speed(t0)).unwrap_err();
        assert!(first.reason.contains("past the start time (initial.t0_s)"), "{first}");
        assert!(s.push(&speed(t0 + 1.0)).is_err());
        assert!(s.push(&speed(t0 + 2.0)).unwrap().is_some(), "the third on the new clock starts the estimators");
        for k in 3..=12 {
            assert!(s.push(&speed(t0 + k as f64)).is_ok());
        }
        // 10 s at 1 m/s heading north from the new start
        let e = &s.final_estimates()[0];
        assert!((e.north_m() - 10.0).abs() < 1e-6 && e.east_m().abs() < 1e-6, "{} {}", e.north_m(), e.east_m());
        assert_eq!(s.screened, 2);
        // a start time close to the stream's is kept as given
        let start = Start::At { t0_s: Some(t0 - 5.0), pose: (0.0, 0.0, 0.0) };
        let est = vec![("dr".to_string(), PlanarConfig::default(), FilterKind::Ekf)];
        let mut s = Session::new(Frame::Ned, planar(est), start, (1.0, 0.1), None);
        assert!(s.push(&speed(t0)).unwrap().is_some());
        assert_eq!(s.final_estimates()[0].t_s, t0);
    }

    /// A message repeated at its own time (a logger or a bridge sending it twice) is
    /// screened, NaN fields and all (a tracked beacon's unresolved position); another
    /// message at that time, or the same at a later time, is taken. At cfb7f93 every
    /// line of a rypkema stream twice put the iUSBL navigator 53 m off; ten times, 267
    /// restarts.
    #[test]
    fn a_repeated_message_is_weighed_once() {
        let start = Start::At { t0_s: None, pose: (0.0, 0.0, 0.0) };
        let mut s = Session::new(Frame::Ned, Vec::new(), start, (1.0, 0.1), None);
        let speed = |t: f64, v: f64| Item { t_s: t, input: Input::Measurement(Kind::Speed { speed_m_s: v }) };
        let unresolved = BeaconFix::fixed(3, Vector3::repeat(f64::NAN));
        let range = Item { t_s: 1.0, input: Input::Measurement(Kind::Range { beacon: unresolved, range_m: 50.0 }) };
        assert!(s.push(&speed(1.0, 1.0)).is_ok());
        let again = s.push(&speed(1.0, 1.0)).unwrap_err();
        assert!(again.reason.contains("a repeat"), "{again}");
        assert!(s.push(&speed(1.0, 1.5)).is_ok(), "another value at the same time");
        let first = s.push(&range).map(|_| ()).map_err(|e| e.reason);
        assert!(!first.as_ref().is_err_and(|r| r.contains("a repeat")), "{first:?}");
        assert!(s.push(&range).unwrap_err().reason.contains("a repeat"));
        assert!(s.push(&speed(2.0, 1.0)).is_ok(), "the same value later");
        assert_eq!(s.screened, 2 + usize::from(first.is_err()));
    }

    /// A stream whose ground truth has no heading (`heading_from = "track"`) starts at
    /// the first truth item 2 m from the first one, heading along the chord: a truth
    /// walking north-east 0.5 m a row starts at its fifth row (2.0 m), at that point,
    /// at 45 deg; the four rows before are counted before the start.
    #[test]
    fn a_track_start_begins_where_the_track_is_long_enough() {
        let est = vec![("dr".to_string(), PlanarConfig::default(), FilterKind::Ekf)];
        let start = Start::Track { track_m: 2.0, from: None };
        let mut s = Session::new(Frame::Ned, planar(est), start, (1.0, 0.1), None);
        let step = 0.5 / 2f64.sqrt();
        for k in 0..6 {
            let (n, e) = (10.0 + step * k as f64, -5.0 + step * k as f64);
            let item = Item { t_s: k as f64, input: Input::Truth(TruthPose::exact(n, e, None)) };
            assert_eq!(s.push(&item).unwrap().is_some(), k >= 4, "row {k}");
            if k == 4 {
                let e0 = &s.final_estimates()[0];
                assert!((e0.north_m() - n).abs() < 1e-12 && (e0.east_m() - e).abs() < 1e-12);
                assert!((e0.heading_rad() - std::f64::consts::FRAC_PI_4).abs() < 1e-12);
            }
        }
        assert_eq!(s.before_start, 4);
    }

    /// A stream that starts at the first ground-truth heading says, once, that a truth
    /// row has none (instead of waiting in silence), and starts at the first that has.
    #[test]
    fn a_truth_without_heading_is_named_once() {
        let est = vec![("dr".to_string(), PlanarConfig::default(), FilterKind::Ekf)];
        let mut s = Session::new(Frame::Ned, planar(est), Start::FirstTruth, (1.0, 0.1), None);
        let truth = |t: f64, heading_rad| Item { t_s: t, input: Input::Truth(TruthPose::exact(t, 0.0, heading_rad)) };
        let first = s.push(&truth(0.0, None)).unwrap_err();
        assert!(first.reason.contains("heading_from = \"track\""), "{first}");
        assert_eq!(s.push(&truth(1.0, None)), Ok(None));
        assert!(s.push(&truth(2.0, Some(0.5))).unwrap().is_some());
        assert_eq!((s.screened, s.before_start), (1, 2));
    }

    /// Every plausible item passes the default limits; the implausible ones are refused
    /// by name.
    /// A filter whose noise matches the measurements' has a mean NIS of 1: a vehicle at
    /// rest ranged 4000 times from three beacons with Gaussian noise of the sigma the
    /// filter assumes gives a mean NIS within the chi-square(4000)/4000 band
    /// [0.957, 1.044] and about 95 % of the values under the 95 % quantile; with the
    /// noise twice the assumed, about 4.
    #[test]
    fn nis_is_one_for_a_matched_filter() {
        use rand::SeedableRng;
        use rand_distr::{Distribution, Normal};
        let beacons = [Vector3::new(30.0, 0.0, 0.0), Vector3::new(0.0, 40.0, 0.0), Vector3::new(-25.0, -25.0, 0.0)];
        let means: Vec<(f64, f64)> = [1.0, 2.0]
            .into_iter()
            .map(|scale| {
                let mut rng = rand_pcg::Pcg64::seed_from_u64(5);
                let noise = Normal::new(0.0, 1.5 * scale).unwrap();
                let start = Start::At { t0_s: None, pose: (0.0, 0.0, 0.0) };
                let mut config = PlanarConfig::default(); // range sigma 1.5 m
                config.noise.position_walk_m_per_sqrt_s = 0.0;
                let est = vec![("ekf".to_string(), config, FilterKind::Ekf)];
                // from the truth with a tiny initial sigma, so the state error stays small
                let mut s = Session::new(Frame::Ned, planar(est), start, (1e-3, 0.1), None);
                for k in 0..4000 {
                    let b = beacons[k % 3];
                    let range = b.norm() + noise.sample(&mut rng);
                    let m = Kind::Range { beacon: BeaconFix::fixed(k as u32 % 3, b), range_m: range };
                    s.push(&Item { t_s: k as f64, input: Input::Measurement(m) }).unwrap();
                }
                (s.stats[0].nis_mean(), s.stats[0].nis_within_95_fraction())
            })
            .collect();
        assert!((0.957..1.044).contains(&means[0].0), "{means:?}");
        assert!((means[0].1 - 0.95).abs() < 0.015, "{means:?}");
        assert!((means[1].0 - 4.0).abs() < 0.4, "{means:?}");
    }

    /// An estimator with `track_accel_sigma_m_s2` is the constant-velocity tracker: it
    /// ignores odometry (a planar navigator moves with it) and reports a speed.
    #[test]
    fn a_track_config_runs_the_constant_velocity_tracker() {
        let start = Start::At { t0_s: None, pose: (0.0, 0.0, 0.0) };
        let track = PlanarConfig { track_accel_sigma_m_s2: Some(0.1), ..PlanarConfig::default() };
        let est = vec![
            ("cv".to_string(), track, FilterKind::Ekf),
            ("dr".to_string(), PlanarConfig::default(), FilterKind::Ekf),
        ];
        let mut s = Session::new(Frame::Ned, planar(est), start, (1.0, 0.1), None);
        for t in [0.0, 1.0, 2.0] {
            let odo = Kind::Odometry { distance_m: 1.0, heading_change_rad: 0.0 };
            s.push(&Item { t_s: t, input: Input::Measurement(odo) }).unwrap();
        }
        let [cv, dr] = [s.final_estimates()[0], s.final_estimates()[1]];
        assert_eq!((cv.north_m(), cv.speed_m_s), (0.0, Some(0.0)));
        assert_eq!((dr.north_m(), dr.speed_m_s), (3.0, None));
    }

    /// An unwrapped heading (an INS that counts turns: 500 turns here) is the heading it
    /// wraps to: same estimates as the wrapped one.
    #[test]
    fn unwrapped_headings_are_taken() {
        let start = Start::At { t0_s: None, pose: (0.0, 0.0, 0.0) };
        let est = vec![("ekf".to_string(), PlanarConfig::default(), FilterKind::Ekf)];
        let turns = 500.0 * std::f64::consts::TAU;
        let finals: Vec<Estimate> = [0.0, turns]
            .into_iter()
            .map(|offset| {
                let mut s = Session::new(Frame::Ned, planar(est.clone()), start, (1.0, 0.1), None);
                for k in 0..50 {
                    let t = k as f64;
                    let odo = Kind::Odometry { distance_m: 1.0, heading_change_rad: 0.02 };
                    s.push(&Item { t_s: t, input: Input::Measurement(odo) }).unwrap();
                    let heading = Kind::Heading { heading_rad: offset + 0.3 + 0.02 * t };
                    s.push(&Item { t_s: t + 0.5, input: Input::Measurement(heading) }).unwrap();
                }
                s.final_estimates()[0]
            })
            .collect();
        assert!(turns > 1e3, "beyond the old 1000 rad bound");
        approx::assert_abs_diff_eq!(finals[0].position_ned_m, finals[1].position_ned_m, epsilon = 1e-9);
    }
}
