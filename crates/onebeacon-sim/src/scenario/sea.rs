//! The `[sea]` table: error sources of the real sea a world can switch on, all off by
//! default (the reproductions run without them). So far the clocks of the one-way
//! travel-time worlds (fixed_beacon, moving_beacon) and the sound-speed profile of the
//! moving_beacon world.

use super::validate::{Rule, Violation, check};
use crate::acoustics::clock::ClockErrors;
use crate::acoustics::link::LinkErrors;
use crate::acoustics::profile::Profile;
use onebeacon::dsp::sound_speed::mackenzie;
use serde::{Deserialize, Serialize};

/// The sound speed a fixed_beacon world, which times no ping, turns a clock error into
/// a range error with, m/s.
pub const FIXED_BEACON_SOUND_SPEED_M_S: f64 = 1500.0;

/// `[sea]`.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct Sea {
    /// `[sea.clocks]`: every vehicle's and the beacon's clock draw these errors.
    pub clocks: ClockErrors,
    /// `[sea.sound_speed]`: the water's sound speed by depth, which the pings travel
    /// through while the vehicles convert with the scenario's one speed.
    pub sound_speed: Option<SoundSpeed>,
    /// `[sea.link]`: lost messages, multipath and false ranges.
    pub link: LinkErrors,
}

/// `[sea.sound_speed]`: a cast, as speeds or as temperatures (Mackenzie 1981) at
/// increasing depths, linear in between and constant beyond.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct SoundSpeed {
    pub depth_m: Vec<f64>,
    pub speed_m_s: Vec<f64>,
    pub temperature_c: Vec<f64>,
    /// With `temperature_c`: salinity, ppt (default 35).
    pub salinity_ppt: Option<f64>,
}

/// Salinity of a cast given by temperatures without `salinity_ppt`, ppt.
const DEFAULT_SALINITY_PPT: f64 = 35.0;

impl SoundSpeed {
    /// The profile: the speeds, or Mackenzie's speed at each temperature and depth.
    pub fn profile(&self) -> Profile {
        let speeds = if self.speed_m_s.is_empty() {
            let s = self.salinity_ppt.unwrap_or(DEFAULT_SALINITY_PPT);
            self.depth_m.iter().zip(&self.temperature_c).map(|(&d, &t)| mackenzie(t, s, d)).collect()
        } else {
            self.speed_m_s.clone()
        };
        Profile::new(self.depth_m.clone(), speeds)
    }

    fn check(&self) -> Result<(), Violation> {
        let key = |k: &str| format!("sea.sound_speed.{k}");
        let list = |v: &[f64]| format!("{v:?}");
        let d = &self.depth_m;
        if d.is_empty() || d.iter().any(|z| !(0.0..=8000.0).contains(z)) || d.windows(2).any(|w| w[1] <= w[0]) {
            return Err(Violation {
                key: key("depth_m"),
                value: list(d),
                allowed: "one depth at least, increasing, each in 0-8000 m".into(),
            });
        }
        let (speeds, temps) = (!self.speed_m_s.is_empty(), !self.temperature_c.is_empty());
        if speeds == temps {
            return Err(Violation {
                key: key("speed_m_s"),
                value: list(&self.speed_m_s),
                allowed: "give speed_m_s or temperature_c (one of the two), one per depth".into(),
            });
        }
        let (name, values, range, what) = if speeds {
            ("speed_m_s", &self.speed_m_s, 1400.0..=1650.0, "m/s, sea water's 1400-1650")
        } else {
            ("temperature_c", &self.temperature_c, 2.0..=30.0, "deg C, Mackenzie's 2-30")
        };
        if values.len() != d.len() || values.iter().any(|v| !range.contains(v)) {
            return Err(Violation {
                key: key(name),
                value: list(values),
                allowed: format!("one per depth ({}), each in {what}", d.len()),
            });
        }
        if let Some(s) = self.salinity_ppt
            && (!(25.0..=40.0).contains(&s) || speeds)
        {
            return Err(Violation {
                key: key("salinity_ppt"),
                value: format!("{s:?}"),
                allowed: "with temperature_c only, in Mackenzie's 25-40 ppt".into(),
            });
        }
        Ok(())
    }
}

fn check_link(l: &LinkErrors) -> Result<(), Violation> {
    for (key, v) in [
        ("sea.link.loss_prob", l.loss_prob),
        ("sea.link.multipath_prob", l.multipath_prob),
        ("sea.link.false_prob", l.false_prob),
    ] {
        check(key, v, Rule::Probability)?;
    }
    check("sea.link.multipath_excess_m", l.multipath_excess_m, Rule::NonNegative)?;
    check("sea.link.false_max_range_m", l.false_max_range_m, Rule::NonNegative)?;
    let bad = |key: &str, v: f64, allowed: String| Err(Violation { key: key.into(), value: format!("{v:?}"), allowed });
    if l.loss_prob >= 1.0 {
        return bad("sea.link.loss_prob", l.loss_prob, "must be below 1 (every message lost)".into());
    }
    if l.multipath_prob + l.false_prob > 1.0 {
        return bad("sea.link.false_prob", l.false_prob, "with multipath_prob, at most 1 in all".into());
    }
    if let Some(b) = l.loss_burst_mean {
        let least = 1.0 / (1.0 - l.loss_prob);
        if !(b.is_finite() && b >= least) {
            return bad(
                "sea.link.loss_burst_mean",
                b,
                format!("a mean run of lost messages >= 1 / (1 - loss_prob) = {least} (independent losses)"),
            );
        }
    }
    if l.false_prob > 0.0 && l.false_max_range_m <= 0.0 {
        return bad("sea.link.false_max_range_m", l.false_max_range_m, "must be > 0 with false_prob".into());
    }
    Ok(())
}

impl Sea {
    pub(super) fn check(&self) -> Result<(), Violation> {
        check_link(&self.link)?;
        if let Some(s) = &self.sound_speed {
            s.check()?;
        }
        let c = &self.clocks;
        for (key, v) in [
            ("sea.clocks.offset_sigma_s", c.offset_sigma_s),
            ("sea.clocks.drift_sigma_ppm", c.drift_sigma_ppm),
            ("sea.clocks.walk_s_per_sqrt_s", c.walk_s_per_sqrt_s),
        ] {
            check(key, v, Rule::NonNegative)?;
        }
        Ok(())
    }
}
