//! The sea of a log: its ranges, lost messages, heading, speed and odometry against a
//! reference trajectory (the log's ground truth, or without one the smoother's
//! trajectory), fitted to the error models the simulator draws from, each value with a
//! 95 % interval; written as a `[sea]` table in the scenario format (`onebeacon
//! sea-fit`; docs/logs.md, "The sea of a log").

mod link;
mod mle;
mod motion;
mod ranges;
mod toml_out;
pub(crate) mod truth;

#[cfg(test)]
mod tests;

pub use link::{LossFit, Transitions};
pub use motion::{HeadingFit, OdometryFit, SpeedFit};
pub use ranges::{RangeFit, Value};

use crate::smooth::{SmoothConfig, SmoothError, smooth};
use motion::{OdometryWindow, VelocityWindow};
use onebeacon::geo::wrap_angle as wrap;
use onebeacon::log::{Log, LogError};
use onebeacon::nav::Kind;
use onebeacon::nav::session::Input;
use ranges::Pair;
use std::collections::{BTreeMap, BTreeSet};
use truth::Track;

/// The sound speed a range drift is read as a clock drift with, m/s: the fixed-beacon
/// world's (a log does not say its own).
pub use crate::scenario::sea::FIXED_BEACON_SOUND_SPEED_M_S as NOMINAL_SOUND_SPEED_M_S;

/// What `sea-fit` is asked.
#[derive(Debug, Clone)]
pub struct SeaFitOptions {
    /// The beacons to fit (all when None).
    pub beacons: Option<BTreeSet<u32>>,
    /// The windows of the speed and odometry fits, s.
    pub window_s: f64,
}

impl Default for SeaFitOptions {
    fn default() -> Self {
        Self { beacons: None, window_s: 60.0 }
    }
}

#[derive(Debug, thiserror::Error)]
pub enum SeaFitError {
    #[error(transparent)]
    Log(#[from] LogError),
    #[error("no ground truth in the log, and the smoother could not give a trajectory: {0}")]
    Smooth(#[from] SmoothError),
    #[error("the fit of {what} failed: {message}")]
    Fit { what: String, message: String },
    #[error("nothing to fit: {0}")]
    Nothing(String),
}

/// The fitted sea of a log.
#[derive(Debug, Clone)]
pub struct SeaFit {
    /// What the measurements were read against: "ground truth" or "smoother".
    pub reference: &'static str,
    pub ranges: Vec<RangeFit>,
    /// Per beacon, and pooled (summed counts).
    pub loss: Vec<(u32, LossFit)>,
    pub loss_pooled: Option<LossFit>,
    /// The clocks' drift standard deviation, ppm, from the ranges' drifts.
    pub drift_sigma_ppm: Option<Value>,
    pub heading: Option<HeadingFit>,
    pub speed: Option<SpeedFit>,
    pub odometry: Option<OdometryFit>,
    /// What could not be fitted, and why.
    pub notes: Vec<String>,
}

/// Fits the sea of `log`; `progress` is told each step's name.
pub fn fit(log: &Log, opts: &SeaFitOptions, progress: impl Fn(&str)) -> Result<SeaFit, SeaFitError> {
    let mut notes = Vec::new();
    progress("reading the log");
    let mut reads = Reads::default();
    for item in log.items()? {
        let item = item?;
        let t = item.t_s;
        match item.input.to_ned(log.frame) {
            Input::Truth(p) => reads.truth.push((t, [p.north_m, p.east_m], p.heading_rad)),
            Input::Measurement(k) => reads.measurement(t, k, opts.beacons.as_ref()),
            Input::BeaconPosition { .. } => {}
        }
    }
    let (track, reference) = if reads.truth.len() >= 2 {
        (Track::new(std::mem::take(&mut reads.truth)), "ground truth")
    } else {
        progress("smoothing (the log has no ground truth)");
        notes.push("no ground truth: every value is read against the smoother's trajectory, which the same ranges made: their errors are understated".into());
        let s = smooth(log, opts.beacons.as_ref(), &SmoothConfig::default())?;
        let rows = s.t_s.iter().zip(&s.poses).map(|(t, p)| (*t, [p[0], p[1]], Some(p[2]))).collect();
        (Track::new(rows), "smoother")
    };
    let depth = Track::new(reads.depth.iter().map(|(t, d)| (*t, [*d, 0.0], None)).collect());
    let t0 = reads.ranges.values().flatten().map(|r| r.0).fold(f64::INFINITY, f64::min);
    let fail = |what: String| move |e: argmin::core::Error| SeaFitError::Fit { what, message: e.to_string() };
    let mut out = SeaFit {
        reference,
        ranges: Vec::new(),
        loss: Vec::new(),
        loss_pooled: None,
        drift_sigma_ppm: None,
        heading: None,
        speed: None,
        odometry: None,
        notes,
    };
    let mut pooled = Transitions::default();
    let mut scheduled = false;
    for (beacon, rows) in &reads.ranges {
        progress(&format!("beacon {beacon}: {} ranges", rows.len()));
        let pairs: Vec<Pair> = rows
            .iter()
            .filter_map(|&(t, r, b)| {
                let (p, _) = track.at(t)?;
                let z = depth.at(t).map_or(0.0, |d| d.0[0]);
                let d = ((p[0] - b[0]).powi(2) + (p[1] - b[1]).powi(2) + (z - b[2]).powi(2)).sqrt();
                Some(Pair { t_s: t - t0, range_m: r, distance_m: d })
            })
            .collect();
        if pairs.len() < 20 {
            out.notes.push(format!(
                "beacon {beacon}: {} ranges within the reference, fewer than 20: not fitted",
                pairs.len()
            ));
            continue;
        }
        out.ranges.push(ranges::fit_beacon(*beacon, &pairs).map_err(fail(format!("beacon {beacon}'s ranges")))?);
        let times: Vec<f64> = rows.iter().map(|r| r.0).collect();
        match link::period(&times) {
            Some(p) => {
                scheduled = true;
                let c = link::transitions(&times, p);
                pooled += c;
                if let Some(f) = link::fit(c, Some(p)) {
                    out.loss.push((*beacon, f));
                }
            }
            None => out.notes.push(format!("beacon {beacon}: its ranges keep no schedule: its losses are not fitted")),
        }
    }
    if scheduled {
        out.loss_pooled = link::fit(pooled, None);
    }
    out.drift_sigma_ppm = drift_sigma(&out.ranges);
    if reads.headings.len() >= 20 {
        let errors: Vec<(f64, f64)> = reads
            .headings
            .iter()
            .filter_map(|&(t, h)| track.at(t).and_then(|(_, th)| th).map(|th| (t, wrap(h - th))))
            .collect();
        if errors.len() >= 20 {
            progress("heading");
            out.heading = Some(motion::fit_heading(&errors).map_err(fail("the heading".into()))?);
        } else {
            out.notes.push("the reference has no heading: the heading bias is not fitted".into());
        }
    }
    out.speed = motion::fit_speed(&reads.velocity_windows(&track, opts.window_s));
    out.odometry = motion::fit_odometry(&reads.odometry_windows(&track, opts.window_s));
    // a heading no gyro or wheel could match: the reference's heading is the odometry's
    if let Some(t) = out.odometry.and_then(|o| o.turn_sigma).filter(|t| t.value < 1e-6) {
        out.notes.push(format!(
            "the {reference}'s heading follows the odometry's turns to {:.1e} rad per sqrt s: it is the odometry's own heading, so the odometry's turn errors are not seen (turn_scale and turn_sigma read 0)",
            t.value
        ));
    }
    if out.ranges.is_empty() && out.heading.is_none() && out.speed.is_none() && out.odometry.is_none() {
        return Err(SeaFitError::Nothing(format!(
            "no beacon with 20 ranges, heading, speed or odometry within the {reference}"
        )));
    }
    Ok(out)
}

/// The clocks' drift sigma from the beacons' range drifts c_i (m/s, each fitted with a
/// standard deviation s_i): each is the rate of two clocks apart times the sound speed,
/// of variance 2 sigma^2, and its fit adds s_i^2, so sigma^2 = sum (c_i^2 - s_i^2) /
/// (2 B) in ppm^2 (0 where the drifts are no larger than their fit errors); its interval
/// from chi-square with B degrees of freedom on sum c_i^2 less the fit errors (the
/// beacons' sharing of the vehicle's clock neglected).
fn drift_sigma(fits: &[RangeFit]) -> Option<Value> {
    use statrs::distribution::{ChiSquared, ContinuousCDF};
    let b = fits.len();
    let chi = ChiSquared::new(b as f64).ok()?;
    let ppm = |v: f64| v / NOMINAL_SOUND_SPEED_M_S * 1e6;
    let ss: f64 = fits.iter().map(|f| ppm(f.drift_m_per_s.value).powi(2)).sum::<f64>() / 2.0;
    let fit_error: f64 = fits
        .iter()
        .map(|f| f.drift_m_per_s.interval.map_or(0.0, |[lo, hi]| ppm((hi - lo) / (2.0 * 1.96)).powi(2)))
        .sum::<f64>()
        / 2.0;
    let sigma = |ss: f64| ((ss - fit_error) / b as f64).max(0.0).sqrt();
    let n = b as f64;
    Some(Value {
        value: sigma(ss),
        interval: Some([sigma(ss * n / chi.inverse_cdf(0.975)), sigma(ss * n / chi.inverse_cdf(0.025))]),
    })
}

/// What the log holds, in NED.
#[derive(Default)]
struct Reads {
    truth: Vec<(f64, [f64; 2], Option<f64>)>,
    depth: Vec<(f64, f64)>,
    /// Per beacon: time, range, the beacon's position.
    ranges: BTreeMap<u32, Vec<(f64, f64, [f64; 3])>>,
    headings: Vec<(f64, f64)>,
    /// Time, speed through the water (forward, lateral), and heading when known.
    speeds: Vec<(f64, [f64; 2])>,
    odometry: Vec<(f64, f64, f64)>,
}

impl Reads {
    fn measurement(&mut self, t: f64, k: Kind, beacons: Option<&BTreeSet<u32>>) {
        let mut range = |b: &onebeacon::nav::BeaconFix, r: f64| {
            if beacons.is_none_or(|s| s.contains(&b.id)) {
                let p = b.position_ned_m;
                self.ranges.entry(b.id).or_default().push((t, r, [p.x, p.y, p.z]));
            }
        };
        match k {
            Kind::Range { beacon, range_m } | Kind::RangeDoppler { beacon, range_m, .. } => range(&beacon, range_m),
            Kind::ArrayFix { beacon, range_m, .. } => range(&beacon, range_m),
            Kind::Depth { depth_m } => self.depth.push((t, depth_m)),
            Kind::Heading { heading_rad } | Kind::Attitude { heading_rad, .. } | Kind::Inertial { heading_rad, .. } => {
                self.headings.push((t, heading_rad))
            }
            Kind::Report { heading_rad, speed_m_s, depth_m } => {
                self.headings.push((t, heading_rad));
                self.speeds.push((t, [speed_m_s, 0.0]));
                self.depth.push((t, depth_m));
            }
            Kind::Speed { speed_m_s } => self.speeds.push((t, [speed_m_s, 0.0])),
            Kind::BodyVelocity { nu } => self.speeds.push((t, [nu[0], nu[1]])),
            Kind::Odometry { distance_m, heading_change_rad } => {
                self.odometry.push((t, distance_m, heading_change_rad))
            }
            Kind::BodyOdometry { forward_m, lateral_m, heading_change_rad } => {
                self.odometry.push((t, forward_m.hypot(lateral_m), heading_change_rad))
            }
            _ => {}
        }
    }

    /// The measured velocity (the latest speed, held, along the reference's heading halfway, or
    /// without one the latest measured heading: a heading error is fitted on its own)
    /// summed over windows of `window_s` within the reference, beside the reference's
    /// displacement.
    fn velocity_windows(&self, track: &Track, window_s: f64) -> Vec<VelocityWindow> {
        if self.speeds.is_empty() || self.headings.is_empty() {
            return Vec::new();
        }
        let mut events: Vec<(f64, Option<[f64; 2]>, Option<f64>)> =
            self.speeds.iter().map(|&(t, s)| (t, Some(s), None)).collect();
        events.extend(self.headings.iter().map(|&(t, h)| (t, None, Some(h))));
        events.sort_by(|a, b| a.0.total_cmp(&b.0));
        let (mut speed, mut heading) = (None::<[f64; 2]>, None::<f64>);
        let mut out = Vec::new();
        let mut open: Option<(f64, [f64; 2])> = None; // start time, integral
        let mut last_t = events[0].0;
        for &(t, s, h) in &events {
            let psi = track.at(0.5 * (last_t + t)).and_then(|x| x.1).or(heading);
            if let (Some(v), Some(psi), Some((_, sum))) = (speed, psi, open.as_mut()) {
                let dt = t - last_t;
                let (c, si) = (psi.cos(), psi.sin());
                sum[0] += (v[0] * c - v[1] * si) * dt;
                sum[1] += (v[0] * si + v[1] * c) * dt;
            }
            last_t = t;
            speed = s.or(speed);
            heading = h.or(heading);
            let here = track.at(t).map(|x| x.0);
            match (open, here) {
                (Some((t_start, sum)), Some(p)) if t - t_start >= window_s => {
                    if let Some((p0, _)) = track.at(t_start) {
                        out.push(VelocityWindow {
                            measured: sum,
                            truth: [p[0] - p0[0], p[1] - p0[1]],
                            span_s: t - t_start,
                        });
                    }
                    open = Some((t, [0.0; 2]));
                }
                (None, Some(_)) if speed.is_some() && heading.is_some() => open = Some((t, [0.0; 2])),
                (_, None) => open = None,
                _ => {}
            }
        }
        out
    }

    /// The odometry's distance and turn over windows of `window_s` within the reference,
    /// beside the reference's path length and turn at the same times.
    fn odometry_windows(&self, track: &Track, window_s: f64) -> Vec<OdometryWindow> {
        let mut out = Vec::new();
        let mut open: Option<(f64, OdometryWindow)> = None;
        let mut last: Option<([f64; 2], Option<f64>)> = None;
        for &(t, d, turn) in &self.odometry {
            let Some((p, h)) = track.at(t) else {
                (open, last) = (None, None);
                continue;
            };
            if let (Some((_, w)), Some((q, g))) = (open.as_mut(), last) {
                w.distance_m += d;
                w.turn_rad += turn;
                w.true_distance_m += (p[0] - q[0]).hypot(p[1] - q[1]);
                w.true_turn_rad = match (w.true_turn_rad, h, g) {
                    (Some(a), Some(h), Some(g)) => Some(a + wrap(h - g)),
                    _ => None,
                };
            }
            last = Some((p, h));
            match open {
                Some((t_start, w)) if t - t_start >= window_s => {
                    out.push(OdometryWindow { span_s: t - t_start, ..w });
                    open = None;
                }
                _ => {}
            }
            if open.is_none() {
                let w = OdometryWindow {
                    distance_m: 0.0,
                    turn_rad: 0.0,
                    true_distance_m: 0.0,
                    true_turn_rad: h.map(|_| 0.0),
                    span_s: 0.0,
                };
                open = Some((t, w));
            }
        }
        out
    }
}
