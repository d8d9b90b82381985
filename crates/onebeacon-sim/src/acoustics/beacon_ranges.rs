//! Each beacon's ranges as one receiver heard them (`[[sea.ranges]]`): a scale, an
//! offset, a drift and Gaussian noise about the slant distance, with the link's
//! multipath and false detections. `onebeacon sea-fit` fits them on a log and a log's
//! twin draws them; the scenario worlds refuse them (their beacon is one, its noise
//! `signal.range_sigma_m`).

use super::link::{Link, LinkErrors};
use crate::seed::gauss;
use rand_pcg::Pcg64Mcg;
use serde::{Deserialize, Serialize};

/// `[[sea.ranges]]`: beacon `beacon`'s ranges (without `beacon`: every beacon without
/// an entry of its own), r = (1 + scale) d + offset_m + drift_m_s t + e (t from the
/// log's first range), e Gaussian of `sigma_m` on the direct path, with the link's
/// multipath and false detections of this beacon (seafit/ranges.rs is the same model
/// fitted). An entry without `beacon` draws each beacon's drift from `[sea.clocks]`.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct BeaconRanges {
    pub beacon: Option<u32>,
    pub sigma_m: f64,
    pub offset_m: f64,
    pub scale: f64,
    pub drift_m_s: f64,
    pub multipath_prob: f64,
    pub multipath_excess_m: f64,
    pub false_prob: f64,
    pub false_max_range_m: f64,
}

impl BeaconRanges {
    /// The link this beacon's outliers are drawn by (no losses: a twin keeps the log's).
    pub(crate) fn link_errors(&self) -> LinkErrors {
        LinkErrors {
            multipath_prob: self.multipath_prob,
            multipath_excess_m: self.multipath_excess_m,
            false_prob: self.false_prob,
            false_max_range_m: self.false_max_range_m,
            ..LinkErrors::default()
        }
    }

    /// The range heard at `t_s` (s since the first range) of a true distance `d_m`.
    pub(crate) fn hear(&self, t_s: f64, d_m: f64, link: &mut Link, rng: &mut Pcg64Mcg) -> f64 {
        let clean = (1.0 + self.scale) * d_m + self.offset_m + self.drift_m_s * t_s + gauss(rng, self.sigma_m);
        // a lost message is the log's to lose: a twin hears every range the log holds
        link.hear(clean).unwrap_or(clean)
    }

    pub(crate) fn check(&self) -> Result<(), String> {
        let which = self.beacon.map_or("every other beacon".to_string(), |b| format!("beacon {b}"));
        let at = |key: &str| format!("sea.ranges ({which}).{key}");
        for (key, v, lo, hi, what) in [
            ("sigma_m", self.sigma_m, 0.0, 1e3, "m"),
            ("offset_m", self.offset_m, -1e4, 1e4, "m"),
            ("scale", self.scale, -0.5, 0.5, "a share of the distance"),
            ("drift_m_s", self.drift_m_s, -1.0, 1.0, "m/s"),
            ("multipath_prob", self.multipath_prob, 0.0, 1.0, "a probability"),
            ("multipath_excess_m", self.multipath_excess_m, 0.0, 1000.0, "m"),
            ("false_prob", self.false_prob, 0.0, 1.0, "a probability"),
            ("false_max_range_m", self.false_max_range_m, 0.0, 1e5, "m"),
        ] {
            if !(lo..=hi).contains(&v) {
                return Err(format!("{} = {v:?}: allowed from {lo} to {hi} ({what})", at(key)));
            }
        }
        if self.multipath_prob + self.false_prob > 1.0 {
            return Err(format!("{}: with multipath_prob, at most 1 in all", at("false_prob")));
        }
        if self.false_prob > 0.0 && self.false_max_range_m <= 0.0 {
            return Err(format!("{}: must be > 0 with false_prob", at("false_max_range_m")));
        }
        Ok(())
    }
}
