//! What a twin draws: each item of the log read against the truth once (the true
//! distance of a range, the true path and turn of an odometry row, the true heading),
//! then, run after run, a value drawn about it from the sea. What the sea has no model
//! for is kept as logged and counted.

use crate::acoustics::beacon_ranges::BeaconRanges;
use crate::acoustics::link::Link;
use crate::scenario::sea::{FIXED_BEACON_SOUND_SPEED_M_S, Sea};
use crate::seafit::truth::Track;
use crate::seed::{Stream, gauss, rng, vehicle_rng};
use crate::sensor_errors::DriftingSensors;
use onebeacon::geo::{Frame, wrap_angle};
use onebeacon::log::Log;
use onebeacon::nav::Kind;
use onebeacon::nav::item::Item;
use onebeacon::nav::session::Input;
use std::collections::BTreeMap;

/// Items kept as logged, by kind and why.
pub type Kept = BTreeMap<String, usize>;

/// What one item becomes in a run.
#[derive(Debug, Clone, Copy)]
enum Plan {
    Keep,
    /// A range to the `beacon`-th model, at `t_s` since the first range, of a true
    /// distance.
    Range {
        model: usize,
        t_s: f64,
        distance_m: f64,
    },
    /// An odometry row: true path and turn over `dt_s`; with `body`, the true forward and
    /// lateral share of the path (cos, sin of the course off the heading).
    Odometry {
        distance_m: f64,
        turn_rad: f64,
        dt_s: f64,
        body: Option<[f64; 2]>,
    },
    Heading {
        heading_rad: f64,
    },
}

/// The log read against the truth, ready to draw runs.
pub(crate) struct Drawer<'a> {
    sea: &'a Sea,
    frame: Frame,
    items: &'a [Item],
    plans: Vec<Plan>,
    /// One range model per beacon heard, in order of first range.
    models: Vec<BeaconRanges>,
    /// Whether a model's drift is drawn per run from `[sea.clocks]` (no entry of its own).
    drawn_drift: Vec<bool>,
    kept: Kept,
}

/// The notes a sea's tables give a twin: what it does not draw.
pub(crate) fn notes(sea: &Sea) -> Vec<String> {
    let mut notes = Vec::new();
    if sea.link.loss_prob > 0.0 {
        notes.push("sea.link.loss_prob: not drawn: a twin keeps the log's own losses (its measurement times)".into());
    }
    if sea.sensors.speed_scale_sigma > 0.0 || sea.current.speed_m_s > 0.0 {
        notes.push("sea.sensors.speed_scale_sigma and sea.current: not drawn: a twin keeps the log's speeds".into());
    }
    if sea.clocks.offset_sigma_s > 0.0 || sea.clocks.walk_s_per_sqrt_s > 0.0 {
        notes.push(
            "sea.clocks' offset and walk: not drawn: a twin's ranges take offset_m and drift_m_s of [[sea.ranges]]"
                .into(),
        );
    }
    if sea.sensors.heading_bias_sigma_deg > 0.0 {
        notes.push(
            "headings: the Gauss-Markov bias drawn about the truth's heading, without white noise (no key holds it)"
                .into(),
        );
    }
    notes
}

impl<'a> Drawer<'a> {
    pub(crate) fn new(log: &Log, sea: &'a Sea, track: &Track, items: &'a [Item]) -> Self {
        let mut kept = Kept::new();
        let mut keep = |why: String| {
            *kept.entry(why).or_default() += 1;
            Plan::Keep
        };
        let t0 = items
            .iter()
            .find(|i| matches!(&i.input, Input::Measurement(Kind::Range { .. } | Kind::RangeDoppler { .. })))
            .map_or(0.0, |i| i.t_s);
        let mut models: Vec<BeaconRanges> = Vec::new();
        let mut drawn_drift = Vec::new();
        let mut depth = 0.0;
        let mut last_odometry: Option<(f64, [f64; 2], Option<f64>)> = None;
        let mut plans = Vec::with_capacity(items.len());
        for item in items {
            let t = item.t_s;
            let Input::Measurement(k) = item.input.clone().to_ned(log.frame) else {
                plans.push(Plan::Keep);
                continue;
            };
            let here = track.at(t);
            let plan = match (&k, here) {
                (Kind::Depth { depth_m }, _) => {
                    depth = *depth_m;
                    keep("depth (the truth's own)".into())
                }
                (Kind::Range { beacon, .. } | Kind::RangeDoppler { beacon, .. }, Some((p, _))) => {
                    let b = beacon.position_ned_m;
                    match sea
                        .ranges
                        .iter()
                        .find(|r| r.beacon == Some(beacon.id))
                        .or_else(|| sea.ranges.iter().find(|r| r.beacon.is_none()))
                    {
                        _ if !b.iter().all(|c| c.is_finite()) => keep(format!("{} (a tracked beacon)", k.name())),
                        None => keep(format!("{} (beacon {}: no [[sea.ranges]] entry)", k.name(), beacon.id)),
                        Some(m) => {
                            let model = match models.iter().position(|x| x.beacon == Some(beacon.id)) {
                                Some(i) => i,
                                None => {
                                    drawn_drift.push(m.beacon.is_none());
                                    models.push(BeaconRanges { beacon: Some(beacon.id), ..*m });
                                    models.len() - 1
                                }
                            };
                            let d = ((p[0] - b.x).powi(2) + (p[1] - b.y).powi(2) + (depth - b.z).powi(2)).sqrt();
                            if matches!(k, Kind::RangeDoppler { .. }) {
                                keep("range_doppler's Doppler".into());
                            }
                            Plan::Range { model, t_s: t - t0, distance_m: d }
                        }
                    }
                }
                (Kind::Odometry { .. } | Kind::BodyOdometry { .. }, Some((p, h))) => {
                    let plan = match last_odometry {
                        Some((t_last, q, g)) if sea.odometry != Default::default() => match (h, g) {
                            (Some(h), Some(g)) => {
                                let (dn, de) = (p[0] - q[0], p[1] - q[1]);
                                let mid = g + 0.5 * wrap_angle(h - g);
                                let course = de.atan2(dn) - mid;
                                let body = matches!(k, Kind::BodyOdometry { .. }).then(|| [course.cos(), course.sin()]);
                                Plan::Odometry {
                                    distance_m: dn.hypot(de),
                                    turn_rad: wrap_angle(h - g),
                                    dt_s: t - t_last,
                                    body,
                                }
                            }
                            _ => keep(format!("{} (the truth has no heading)", k.name())),
                        },
                        Some(_) => keep(format!("{} (no [sea.odometry])", k.name())),
                        None => keep(format!("{} (the first row: no span)", k.name())),
                    };
                    last_odometry = Some((t, p, h));
                    plan
                }
                (Kind::Heading { .. }, Some((_, Some(h)))) => Plan::Heading { heading_rad: h },
                (Kind::Heading { .. }, Some((_, None))) => keep("heading (the truth has no heading)".into()),
                (_, None) => {
                    last_odometry = None;
                    keep(format!("{} (outside the truth)", k.name()))
                }
                _ => keep(format!("{} (no model)", k.name())),
            };
            plans.push(plan);
        }
        Self { sea, frame: log.frame, items, plans, models, drawn_drift, kept }
    }

    pub(crate) fn kept(&self) -> Kept {
        self.kept.clone()
    }

    /// Run `run`'s stream under base seed `seed`: the log's items, each drawn anew where
    /// it has a plan.
    pub(crate) fn run(&self, seed: u64, run: u64) -> Vec<Item> {
        let mut ranges = rng(seed, run, Stream::Acoustic);
        let mut odometry = rng(seed, run, Stream::Imu);
        let mut clocks = rng(seed, run, Stream::Clock);
        let mut sensors = DriftingSensors::new(&self.sea.sensors, rng(seed, run, Stream::Sensors));
        let drift_sigma_m_s = self.sea.clocks.drift_sigma_ppm * 1e-6 * FIXED_BEACON_SOUND_SPEED_M_S;
        let models: Vec<BeaconRanges> = self
            .models
            .iter()
            .zip(&self.drawn_drift)
            .map(|(m, drawn)| {
                // two clocks apart: the difference of two drifts of sigma each
                let drift = if *drawn { gauss(&mut clocks, drift_sigma_m_s * 2f64.sqrt()) } else { m.drift_m_s };
                BeaconRanges { drift_m_s: drift, ..*m }
            })
            .collect();
        let mut links: Vec<Link> = models
            .iter()
            .enumerate()
            .map(|(i, m)| Link::new(&m.link_errors(), vehicle_rng(seed, run, i, Stream::Link)))
            .collect();
        let o = &self.sea.odometry;
        self.items
            .iter()
            .zip(&self.plans)
            .map(|(item, plan)| {
                let Input::Measurement(k) = &item.input else { return item.clone() };
                let k = k.clone();
                let drawn = match (*plan, k) {
                    (Plan::Keep, k) => return Item { t_s: item.t_s, input: Input::Measurement(k) },
                    (Plan::Range { model, t_s, distance_m }, Kind::Range { beacon, .. }) => Kind::Range {
                        beacon,
                        range_m: models[model].hear(t_s, distance_m, &mut links[model], &mut ranges),
                    },
                    (Plan::Range { model, t_s, distance_m }, Kind::RangeDoppler { beacon, radial_speed_m_s, .. }) => {
                        let range_m = models[model].hear(t_s, distance_m, &mut links[model], &mut ranges);
                        Kind::RangeDoppler { beacon, range_m, radial_speed_m_s }
                    }
                    (Plan::Odometry { distance_m, turn_rad, dt_s, body }, _) => {
                        let (d, turn) = o.read(distance_m, turn_rad, dt_s, &mut odometry);
                        // the turn in NED, back to the log's frame (the map is its own inverse)
                        let turn = self.frame.turn_to_ned(turn);
                        match body {
                            None => Kind::Odometry { distance_m: d, heading_change_rad: turn },
                            Some([c, s]) => Kind::BodyOdometry {
                                forward_m: d * c,
                                lateral_m: self.frame.turn_to_ned(d * s),
                                heading_change_rad: turn,
                            },
                        }
                    }
                    (Plan::Heading { heading_rad }, _) => {
                        Kind::Heading { heading_rad: self.frame.heading_to_ned(sensors.heading(item.t_s, heading_rad)) }
                    }
                    (_, k) => k,
                };
                Item { t_s: item.t_s, input: Input::Measurement(drawn) }
            })
            .collect()
    }
}
