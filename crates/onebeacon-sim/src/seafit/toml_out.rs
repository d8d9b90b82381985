//! A fitted sea written out: the `[sea]` table of the scenario format, every value with
//! its source beside it (the log, the fit, its 95 % interval), each beacon's ranges
//! and the odometry in the tables a log's twin reads; and the same as JSON.

use super::{NOMINAL_SOUND_SPEED_M_S, SeaFit, Value};
use serde_json::{Value as Json, json};
use std::fmt::Write;

/// Several beacons' values of one quantity as one: the inverse-variance mean and its
/// interval; the plain mean, without an interval, when any lacks one.
fn pool(values: &[Value]) -> Option<Value> {
    if values.is_empty() {
        return None;
    }
    let sds: Option<Vec<f64>> = values.iter().map(|v| v.interval.map(|[lo, hi]| (hi - lo) / (2.0 * 1.96))).collect();
    match sds.filter(|s| s.iter().all(|s| *s > 0.0)) {
        Some(sds) => {
            let w: Vec<f64> = sds.iter().map(|s| 1.0 / (s * s)).collect();
            let total: f64 = w.iter().sum();
            let mean = values.iter().zip(&w).map(|(v, w)| v.value * w).sum::<f64>() / total;
            let sd = 1.0 / total.sqrt();
            Some(Value { value: mean, interval: Some([mean - 1.96 * sd, mean + 1.96 * sd]) })
        }
        None => {
            Some(Value { value: values.iter().map(|v| v.value).sum::<f64>() / values.len() as f64, interval: None })
        }
    }
}

/// 5 significant digits.
fn num(v: f64) -> String {
    if v == 0.0 || !v.is_finite() {
        return format!("{v:?}");
    }
    let digits = (4 - v.abs().log10().floor() as i32).clamp(0, 12) as usize;
    let s = format!("{v:.digits$}");
    if s.contains('.') { s } else { format!("{s}.0") }
}

fn interval(v: &Value) -> String {
    v.interval.map_or("no interval: the likelihood's curvature gave none".into(), |[lo, hi]| {
        format!("95 % [{}, {}]", num(lo), num(hi))
    })
}

fn key(out: &mut String, name: &str, v: f64, source: &str) {
    let line = format!("{name} = {}", num(v));
    let _ = writeln!(out, "{line:<35} # {source}");
}

impl SeaFit {
    /// The multipath excess of the beacons that show multipath, pooled.
    fn multipath_excess(&self) -> Option<Value> {
        pool(
            &self
                .ranges
                .iter()
                .filter(|r| r.multipath_prob.value > 0.0)
                .map(|r| r.multipath_excess_m)
                .collect::<Vec<_>>(),
        )
    }

    /// The `[sea]` table: `command` is what made it (cited in every source).
    pub fn to_toml(&self, command: &str) -> String {
        let mut out = String::new();
        let against = match self.reference {
            "ground truth" => "the log's ground truth",
            _ => "the smoother's trajectory (the log has no ground truth)",
        };
        let _ = writeln!(out, "# The sea of a log, fitted by `{command}`, read against {against}:");
        let _ = writeln!(out, "# each value with its 95 % interval (maximum likelihood: the curvature at the optimum,");
        let _ = writeln!(
            out,
            "# or the profile for the heading bias; pooled over beacons). `onebeacon twin` reads it whole;
# a scenario takes its [sea.clocks], [sea.link], [sea.sensors] and [sea.current] (the
# [[sea.ranges]] and [sea.odometry] are a log's: a world refuses them)."
        );
        for n in &self.notes {
            let _ = writeln!(out, "# note: {n}");
        }
        let src = |what: &str, v: &Value| format!("fit ({what}), {}", interval(v));
        if let Some(d) = &self.drift_sigma_ppm {
            let _ = writeln!(out, "\n[sea.clocks]");
            let what = format!("the {} beacons' range drifts at {NOMINAL_SOUND_SPEED_M_S} m/s", self.ranges.len());
            key(&mut out, "drift_sigma_ppm", d.value, &src(&what, d));
        }
        let n: usize = self.ranges.iter().map(|r| r.ranges).sum();
        let has_link = self.loss_pooled.is_some() || !self.ranges.is_empty();
        if has_link {
            let _ = writeln!(out, "\n[sea.link]");
        }
        if let Some(l) = &self.loss_pooled {
            let what = format!(
                "{} messages heard, {} lost, on the beacons' schedules",
                l.counts.hh + l.counts.hl,
                l.counts.ll + l.counts.lh
            );
            key(&mut out, "loss_prob", l.loss_prob.value, &src(&what, &l.loss_prob));
            key(
                &mut out,
                "loss_burst_mean",
                l.loss_burst_mean.value,
                &src("the lost runs' lengths", &l.loss_burst_mean),
            );
        }
        // an outlier kind's probability: one shared by the beacons, so their values
        // weighted by their ranges (a beacon that shows none adds zero, without error)
        let mut kind = |name: &str, of: fn(&super::RangeFit) -> Value, then: &mut dyn FnMut(&mut String)| {
            let (mut p, mut var, mut known) = (0.0, 0.0, true);
            for r in &self.ranges {
                let (v, w) = (of(r), r.ranges as f64 / n as f64);
                p += w * v.value;
                match v.interval {
                    Some([lo, hi]) => var += (w * (hi - lo) / (2.0 * 1.96)).powi(2),
                    None => known &= v.value == 0.0,
                }
            }
            let shown = self.ranges.iter().filter(|r| of(r).value > 0.0).count();
            if shown == 0 {
                key(&mut out, name, 0.0, &format!("fit: none in {n} ranges (below 3 expected at every beacon)"));
                return;
            }
            let v = Value { value: p, interval: known.then(|| [p - 1.96 * var.sqrt(), p + 1.96 * var.sqrt()]) };
            let what = format!("{n} ranges' mixture, {shown} of {} beacons showing it", self.ranges.len());
            key(&mut out, name, v.value, &src(&what, &v));
            then(&mut out);
        };
        if !self.ranges.is_empty() {
            let excess = self.multipath_excess();
            kind("multipath_prob", |r| r.multipath_prob, &mut |out: &mut String| {
                if let Some(e) = excess {
                    key(out, "multipath_excess_m", e.value, &src("the multipath arrivals' excess", &e));
                }
            });
            let r_max = self.ranges.iter().map(|r| r.false_max_range_m).fold(0.0, f64::max);
            kind("false_prob", |r| r.false_prob, &mut |out: &mut String| {
                key(out, "false_max_range_m", r_max, "the log: the largest range heard");
            });
        }
        if self.heading.is_some() || self.speed.is_some() {
            let _ = writeln!(out, "\n[sea.sensors]");
        }
        if let Some(h) = &self.heading {
            let what = format!("{} headings", h.samples);
            key(&mut out, "heading_bias_sigma_deg", h.bias_sigma_deg.value, &src(&what, &h.bias_sigma_deg));
            key(&mut out, "heading_bias_time_constant_s", h.time_constant_s.value, &src(&what, &h.time_constant_s));
        }
        if let Some(s) = &self.speed {
            let what = format!("one draw: |k| of this log's scale {}, {} windows", num(s.scale.value), s.windows);
            key(&mut out, "speed_scale_sigma", s.scale.value.abs(), &src(&what, &s.scale));
            let (n, e) = (s.current_north_m_s.value, s.current_east_m_s.value);
            let _ = writeln!(out, "\n[sea.current]");
            let what = format!("north {}, east {} m/s", num(n), num(e));
            key(
                &mut out,
                "speed_m_s",
                n.hypot(e),
                &format!(
                    "fit ({what}): north {}, east {}",
                    interval(&s.current_north_m_s),
                    interval(&s.current_east_m_s)
                ),
            );
            key(&mut out, "toward_deg", e.atan2(n).to_degrees().rem_euclid(360.0), "fit: the current's direction");
        }
        // each beacon's ranges, then one entry for a beacon the log did not hear (a
        // twin of another log): the beacons' values pooled, the outliers' shares weighted
        // by their ranges, the excess of the beacons that show multipath
        let n_all = self.ranges.iter().map(|r| r.ranges).sum::<usize>().max(1) as f64;
        let share = |of: fn(&super::RangeFit) -> Value| Value {
            value: self.ranges.iter().map(|r| of(r).value * r.ranges as f64).sum::<f64>() / n_all,
            interval: None,
        };
        let pooled = |name: &str| match name {
            "multipath_prob" => Some(share(|r| r.multipath_prob)),
            "false_prob" => Some(share(|r| r.false_prob)),
            "multipath_excess_m" => self.multipath_excess().or(Some(Value { value: 0.0, interval: None })),
            _ => None,
        };
        let entries = self
            .ranges
            .iter()
            .map(|r| (Some(r), format!("{} ranges", r.ranges)))
            .chain((!self.ranges.is_empty()).then(|| (None, format!("the {} beacons pooled", self.ranges.len()))));
        for (r, what) in entries {
            let _ = writeln!(out, "\n[[sea.ranges]]");
            match r {
                Some(r) => {
                    let line = format!("beacon = {}", r.beacon);
                    let _ = writeln!(out, "{line:<35} # the log");
                }
                None => {
                    let _ = writeln!(out, "# every other beacon (no `beacon` key); its drift drawn from [sea.clocks]");
                }
            }
            let mut field = |name: &str, of: fn(&super::RangeFit) -> Value| {
                let v = match r {
                    Some(r) => Some(of(r)),
                    None => pooled(name).or_else(|| pool(&self.ranges.iter().map(of).collect::<Vec<_>>())),
                };
                match v {
                    Some(v) if v.value == 0.0 && v.interval.is_none() => {
                        key(&mut out, name, 0.0, &format!("fit ({what}): none shown (fewer than 3 expected)"))
                    }
                    Some(v) if r.is_none() && v.interval.is_none() => {
                        key(&mut out, name, v.value, &format!("fit ({what}): the beacons' shares by their ranges"))
                    }
                    Some(v) => key(&mut out, name, v.value, &src(&what, &v)),
                    None => {}
                }
            };
            field("sigma_m", |r| r.sigma_m);
            field("offset_m", |r| r.bias_m);
            field("scale", |r| r.scale);
            if r.is_some() {
                field("drift_m_s", |r| r.drift_m_per_s);
            }
            field("multipath_prob", |r| r.multipath_prob);
            field("multipath_excess_m", |r| r.multipath_excess_m);
            field("false_prob", |r| r.false_prob);
            let r_max = r.map_or_else(
                || self.ranges.iter().map(|r| r.false_max_range_m).fold(0.0, f64::max),
                |r| r.false_max_range_m,
            );
            key(&mut out, "false_max_range_m", r_max, "the log: the largest range heard");
        }
        if let Some(o) = &self.odometry {
            // the fit's k reads true = (1 + k) x measured; the simulator's scale, measured =
            // (1 + scale) x true: 1 / (1 + k) - 1, its interval's ends swapped
            let flip = |v: &Value| Value {
                value: 1.0 / (1.0 + v.value) - 1.0,
                interval: v.interval.map(|[lo, hi]| [1.0 / (1.0 + hi) - 1.0, 1.0 / (1.0 + lo) - 1.0]),
            };
            let _ = writeln!(out, "\n[sea.odometry]");
            let what = format!("{} windows", o.windows);
            let d = flip(&o.distance_scale);
            key(&mut out, "distance_scale", d.value, &src(&what, &d));
            match &o.turn_scale {
                Some(t) => key(&mut out, "turn_scale", flip(t).value, &src(&what, &flip(t))),
                None => {
                    key(&mut out, "turn_scale", 0.0, "none: fewer than 4 windows turned over 5 deg against a heading")
                }
            }
            let ds = &o.distance_sigma;
            key(&mut out, "distance_sigma_m_per_sqrt_m", ds.value, &src(&what, ds));
            match &o.turn_sigma {
                Some(t) => {
                    let deg =
                        Value { value: t.value.to_degrees(), interval: t.interval.map(|i| i.map(f64::to_degrees)) };
                    key(&mut out, "turn_sigma_deg_per_sqrt_s", deg.value, &src(&what, &deg));
                }
                None => key(&mut out, "turn_sigma_deg_per_sqrt_s", 0.0, "none: the reference has no heading"),
            }
        }
        if let Some(h) = &self.heading {
            let _ = writeln!(
                out,
                "\n# heading: the errors' mean {} deg, their sd {} deg; white noise {} deg ({})",
                num(h.mean_deg),
                num(h.sd_deg),
                num(h.white_deg.value),
                interval(&h.white_deg)
            );
        }
        out
    }

    /// Everything fitted, as JSON (values with `[lo, hi]` or null).
    pub fn to_json(&self) -> Json {
        let v = |x: &Value| json!({"value": x.value, "interval": x.interval});
        json!({
            "reference": self.reference,
            "ranges": self.ranges.iter().map(|r| json!({
                "beacon": r.beacon, "ranges": r.ranges, "bias_m": v(&r.bias_m), "scale": v(&r.scale),
                "drift_m_per_s": v(&r.drift_m_per_s), "sigma_m": v(&r.sigma_m),
                "multipath_prob": v(&r.multipath_prob), "multipath_excess_m": v(&r.multipath_excess_m),
                "false_prob": v(&r.false_prob), "false_max_range_m": r.false_max_range_m,
            })).collect::<Vec<_>>(),
            "loss": self.loss.iter().map(|(b, l)| json!({
                "beacon": b, "period_s": l.period_s, "loss_prob": v(&l.loss_prob), "loss_burst_mean": v(&l.loss_burst_mean),
            })).collect::<Vec<_>>(),
            "loss_pooled": self.loss_pooled.map(|l| json!({"loss_prob": v(&l.loss_prob), "loss_burst_mean": v(&l.loss_burst_mean)})),
            "drift_sigma_ppm": self.drift_sigma_ppm.as_ref().map(v),
            "heading": self.heading.map(|h| json!({
                "samples": h.samples, "mean_deg": h.mean_deg, "sd_deg": h.sd_deg, "bias_sigma_deg": v(&h.bias_sigma_deg),
                "time_constant_s": v(&h.time_constant_s), "white_deg": v(&h.white_deg),
            })),
            "speed": self.speed.map(|s| json!({
                "windows": s.windows, "scale": v(&s.scale), "current_north_m_s": v(&s.current_north_m_s),
                "current_east_m_s": v(&s.current_east_m_s),
            })),
            "odometry": self.odometry.map(|o| json!({
                "windows": o.windows, "distance_scale": v(&o.distance_scale), "turn_scale": o.turn_scale.as_ref().map(v),
                "distance_sigma_m_per_sqrt_m": v(&o.distance_sigma), "turn_sigma_rad_per_sqrt_s": o.turn_sigma.as_ref().map(v),
            })),
            "notes": self.notes,
        })
    }
}
