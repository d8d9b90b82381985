//! The `[sea]` table: error sources of the real sea a world can switch on, all off by
//! default (the reproductions run without them): clocks (worlds that time one-way
//! travel), a sound-speed profile (worlds whose signals travel between depths), the
//! acoustic link's losses and outliers (every world that hears messages), and a USBL
//! head's misalignment, waves, floor and occluded sectors (worlds with a USBL), the
//! vehicles' drifting sensors and the water's current.

use super::validate::{Rule, Violation, check};
use crate::acoustics::beacon_ranges::BeaconRanges;
use crate::acoustics::clock::ClockErrors;
use crate::acoustics::link::LinkErrors;
use crate::acoustics::profile::Profile;
use crate::acoustics::usbl_head::UsblErrors;
use crate::scenario::World;
use crate::sensor_errors::{OdometryErrors, SensorErrors};
use crate::water::Current;
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
    /// `[sea.usbl]`: the USBL head's mounting, waves, attitude sensor, floor and
    /// occluded sectors.
    pub usbl: UsblErrors,
    /// `[sea.sensors]`: the vehicles' heading bias, speed scale and speed dropouts.
    pub sensors: SensorErrors,
    /// `[sea.current]`: the water's current, which carries the vehicles over ground.
    pub current: Current,
    /// `[[sea.ranges]]`: each beacon's ranges as a log heard them (a log's twin only).
    pub ranges: Vec<BeaconRanges>,
    /// `[sea.odometry]`: a log's odometry (a log's twin only).
    pub odometry: OdometryErrors,
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

/// `key` = `v` within `lo..=hi` (`what` says what the range is).
fn within(key: &str, v: f64, lo: f64, hi: f64, what: &str) -> Result<(), Violation> {
    if (lo..=hi).contains(&v) {
        Ok(())
    } else {
        Err(Violation { key: key.into(), value: format!("{v:?}"), allowed: format!("from {lo} to {hi} ({what})") })
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
    // the upper bounds are guards (no source): far past any sea, short of a units slip
    let path = "m; a reflection's extra path";
    within("sea.link.multipath_excess_m", l.multipath_excess_m, 0.0, 1000.0, path)?;
    let range = "m; an acoustic modem's reach is tens of km";
    within("sea.link.false_max_range_m", l.false_max_range_m, 0.0, 1e5, range)?;
    let bad = |key: &str, v: f64, allowed: String| Err(Violation { key: key.into(), value: format!("{v:?}"), allowed });
    if l.loss_prob >= 1.0 {
        return bad("sea.link.loss_prob", l.loss_prob, "must be below 1 (every message lost)".into());
    }
    if l.multipath_prob + l.false_prob > 1.0 {
        return bad("sea.link.false_prob", l.false_prob, "with multipath_prob, at most 1 in all".into());
    }
    if let Some(b) = l.loss_burst_mean {
        let least = 1.0 / (1.0 - l.loss_prob);
        if !(b.is_finite() && (least..=1e4).contains(&b)) {
            return bad(
                "sea.link.loss_burst_mean",
                b,
                format!("a mean run of lost messages from 1 / (1 - loss_prob) = {least} (independent losses) to 1e4"),
            );
        }
    }
    if l.false_prob > 0.0 && l.false_max_range_m <= 0.0 {
        return bad("sea.link.false_max_range_m", l.false_max_range_m, "must be > 0 with false_prob".into());
    }
    Ok(())
}

fn check_usbl(u: &UsblErrors) -> Result<(), Violation> {
    let bad = |key: &str, value: String, allowed: &str| {
        Err(Violation { key: format!("sea.usbl.{key}"), value, allowed: allowed.into() })
    };
    if u.misalignment_deg.iter().any(|a| !(a.is_finite() && a.abs() <= 30.0)) {
        return bad(
            "misalignment_deg",
            format!("{:?}", u.misalignment_deg),
            "[roll, pitch, yaw], each a residual misalignment within +-30 deg",
        );
    }
    for (key, v, most) in [
        ("wave_roll_deg", u.wave_roll_deg, 30.0),
        ("wave_pitch_deg", u.wave_pitch_deg, 30.0),
        ("attitude_noise_deg", u.attitude_noise_deg, 10.0),
        ("attitude_latency_s", u.attitude_latency_s, 10.0),
        ("angle_floor_deg", u.angle_floor_deg, 30.0),
    ] {
        if !(0.0..=most).contains(&v) {
            return bad(key, format!("{v:?}"), &format!("from 0 to {most}"));
        }
    }
    if !(u.wave_period_s.is_finite() && (1.0..=30.0).contains(&u.wave_period_s)) {
        return bad("wave_period_s", format!("{:?}", u.wave_period_s), "a wave period from 1 to 30 s");
    }
    let width = |[from, to]: [f64; 2]| (to - from).rem_euclid(360.0);
    if let Some(s) =
        u.occluded_deg.iter().find(|s| !s.iter().all(|a| a.is_finite() && a.abs() <= 360.0) || width(**s) == 0.0)
    {
        return bad(
            "occluded_deg",
            format!("{s:?}"),
            "[from, to] pairs in deg from the bow (within +-360), from != to",
        );
    }
    if u.occluded_deg.iter().map(|s| width(*s)).sum::<f64>() >= 360.0 {
        return bad("occluded_deg", format!("{:?}", u.occluded_deg), "sectors that leave the head some of its circle");
    }
    Ok(())
}

/// A current's keys under `table` (`current`, `sea.current`).
/// The bounds of the speed keys are guards (no source): the strongest tidal races run
/// at about 5 m/s.
pub(super) fn check_current(table: &str, c: &Current) -> Result<(), Violation> {
    check(&format!("{table}.toward_deg"), c.toward_deg, Rule::Finite)?;
    for (key, v, lo, hi, what) in [
        ("speed_m_s", c.speed_m_s, 0.0, 10.0, "m/s"),
        ("speed_sigma_m_s", c.speed_sigma_m_s, 0.0, 10.0, "m/s"),
        ("direction_sigma_deg", c.direction_sigma_deg, 0.0, 180.0, "deg"),
        ("time_constant_s", c.time_constant_s, 1e-3, 1e7, "s, > 0"),
    ] {
        within(&format!("{table}.{key}"), v, lo, hi, what)?;
    }
    Ok(())
}

fn check_sensors(e: &SensorErrors) -> Result<(), Violation> {
    for (key, v, range, allowed) in [
        ("heading_bias_sigma_deg", e.heading_bias_sigma_deg, 0.0..=30.0, "from 0 to 30"),
        ("heading_deviation_deg", e.heading_deviation_deg, 0.0..=30.0, "an amplitude from 0 to 30"),
        ("speed_scale_sigma", e.speed_scale_sigma, 0.0..=0.5, "from 0 to 0.5"),
        ("speed_dropout_prob", e.speed_dropout_prob, 0.0..=0.99, "a share of time from 0 to 0.99"),
        (
            "heading_bias_time_constant_s",
            e.heading_bias_time_constant_s,
            1e-3..=1e7,
            "a time constant > 0 s (up to 1e7)",
        ),
        ("speed_dropout_mean_s", e.speed_dropout_mean_s, 1e-3..=1e7, "a mean outage > 0 s (up to 1e7)"),
    ] {
        if !range.contains(&v) {
            return Err(Violation {
                key: format!("sea.sensors.{key}"),
                value: format!("{v:?}"),
                allowed: allowed.into(),
            });
        }
    }
    Ok(())
}

impl Sea {
    /// The checks of every table, and that each set table applies to a world of `kind`.
    pub(super) fn check(&self, kind: World) -> Result<(), Violation> {
        use World::*;
        let set = [
            (
                "sea.clocks",
                self.clocks != ClockErrors::default(),
                &[FixedBeacon, MovingBeacon, Fleet][..],
                "worlds that time one-way travel (fixed_beacon, moving_beacon, fleet)",
            ),
            (
                "sea.sound_speed",
                self.sound_speed.is_some(),
                &[MovingBeacon, PassiveUsbl, Fleet][..],
                "worlds whose signals travel between depths (moving_beacon, passive_usbl, fleet)",
            ),
            (
                "sea.link",
                self.link != LinkErrors::default(),
                &[FixedBeacon, MovingBeacon, PassiveUsbl, Fleet][..],
                "worlds that hear messages (fixed_beacon, moving_beacon, passive_usbl, fleet)",
            ),
            (
                "sea.usbl",
                self.usbl != UsblErrors::default(),
                &[PassiveUsbl, Fleet][..],
                "worlds with a USBL (passive_usbl; fleet: misalignment_deg only)",
            ),
            (
                "sea.sensors",
                self.sensors != SensorErrors::default(),
                &[FixedBeacon, MovingBeacon, PassiveUsbl, Fleet][..],
                "every world: fixed_beacon (the AHRS heading), moving_beacon (the vehicles' DVL and heading), passive_usbl (the AUVs' reports), fleet (the AUVs' AHRS heading and propeller speed)",
            ),
            (
                "sea.current",
                self.current != Current::default(),
                &[FixedBeacon, Fleet][..],
                "worlds whose vehicles measure their speed through the water (fixed_beacon, fleet); a passive_usbl world's current is its own [current] table, and a moving_beacon world's DVL locks on the bottom",
            ),
            (
                "sea.ranges",
                !self.ranges.is_empty(),
                &[][..],
                "a log's twin (`onebeacon twin`; a world's receiver noise is its own signal.range_sigma_m)",
            ),
            ("sea.odometry", self.odometry != OdometryErrors::default(), &[][..], "a log's twin (`onebeacon twin`)"),
        ];
        if let Some((key, _, _, hosts)) = set.iter().find(|(_, on, kinds, _)| *on && !kinds.contains(&kind)) {
            return Err(Violation {
                key: (*key).into(),
                value: "(set)".into(),
                allowed: format!("applies to {hosts}, not to a {} world", kind.label()),
            });
        }
        check_link(&self.link)?;
        check_usbl(&self.usbl)?;
        // an AUV's inverted USBL is under water, levelled by its own AHRS, heard all round
        if kind == Fleet
            && self.usbl != (UsblErrors { misalignment_deg: self.usbl.misalignment_deg, ..UsblErrors::default() })
        {
            return Err(Violation {
                key: "sea.usbl".into(),
                value: "(set)".into(),
                allowed: "a fleet's inverted USBL takes misalignment_deg only (waves, attitude sensor, floor and occluded sectors are a surface vehicle's head's: passive_usbl)".into(),
            });
        }
        check_sensors(&self.sensors)?;
        check_current("sea.current", &self.current)?;
        // garin2024's AUV measures no speed: it integrates its accelerometer
        if kind == FixedBeacon
            && self.sensors
                != (SensorErrors {
                    heading_bias_sigma_deg: self.sensors.heading_bias_sigma_deg,
                    heading_bias_time_constant_s: self.sensors.heading_bias_time_constant_s,
                    heading_deviation_deg: self.sensors.heading_deviation_deg,
                    ..SensorErrors::default()
                })
        {
            return Err(Violation {
                key: "sea.sensors".into(),
                value: "(set)".into(),
                allowed: "a fixed_beacon world's AUV has no speed sensor: heading_bias_sigma_deg, heading_bias_time_constant_s and heading_deviation_deg only".into(),
            });
        }
        if let Some(s) = &self.sound_speed {
            s.check()?;
        }
        // guards (no source): a modem's crystal drifts by tens of ppm, a clock set by
        // hand is a second off
        let c = &self.clocks;
        within("sea.clocks.offset_sigma_s", c.offset_sigma_s, 0.0, 10.0, "s")?;
        within("sea.clocks.drift_sigma_ppm", c.drift_sigma_ppm, 0.0, 1000.0, "ppm")?;
        within("sea.clocks.walk_s_per_sqrt_s", c.walk_s_per_sqrt_s, 0.0, 0.01, "s/sqrt(s)")?;
        Ok(())
    }
}

impl Sea {
    /// The checks of a log's twin: the tables it draws from checked as a world's are,
    /// the ranges' entries one per beacon at most; a USBL's or a sound-speed profile's
    /// tables refused (a twin keeps the log's angles, its ranges are straight).
    pub fn check_twin(&self) -> Result<(), String> {
        let said = |v: Violation| format!("{} = {}: {}", v.key, v.value, v.allowed);
        for (key, set) in
            [("sea.usbl", self.usbl != UsblErrors::default()), ("sea.sound_speed", self.sound_speed.is_some())]
        {
            if set {
                return Err(format!(
                    "{key}: not drawn by a twin (it keeps the log's angles; its ranges travel straight): leave it out"
                ));
            }
        }
        check_link(&self.link).map_err(said)?;
        check_sensors(&self.sensors).map_err(said)?;
        check_current("sea.current", &self.current).map_err(said)?;
        let c = &self.clocks;
        within("sea.clocks.drift_sigma_ppm", c.drift_sigma_ppm, 0.0, 1000.0, "ppm").map_err(said)?;
        let mut seen = std::collections::BTreeSet::new();
        for r in &self.ranges {
            r.check()?;
            if !seen.insert(r.beacon) {
                let which = r.beacon.map_or("without `beacon`".to_string(), |b| format!("for beacon {b}"));
                return Err(format!("sea.ranges: two entries {which}: one each"));
            }
        }
        self.odometry.check()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn refused(sea: &Sea, kind: World) -> Option<String> {
        sea.check(kind).err().map(|v| format!("{}: {}", v.key, v.allowed))
    }

    /// The keys cfb7f93 left without an upper bound (rc 0 with null cells or errors of
    /// 1e6-1e9 m): each refused by its name at 1e9, taken at a sea's value.
    #[test]
    fn the_seas_keys_have_upper_bounds() {
        let clocks = |c: ClockErrors| Sea { clocks: c, ..Sea::default() };
        let link = |l: LinkErrors| Sea { link: l, ..Sea::default() };
        let current = |c: Current| Sea { current: c, ..Sea::default() };
        let big = 1e9;
        let cases = [
            (clocks(ClockErrors { drift_sigma_ppm: big, ..ClockErrors::default() }), "sea.clocks.drift_sigma_ppm"),
            (clocks(ClockErrors { offset_sigma_s: big, ..ClockErrors::default() }), "sea.clocks.offset_sigma_s"),
            (clocks(ClockErrors { walk_s_per_sqrt_s: big, ..ClockErrors::default() }), "sea.clocks.walk_s_per_sqrt_s"),
            (current(Current { speed_m_s: big, ..Current::default() }), "sea.current.speed_m_s"),
            (current(Current { speed_sigma_m_s: big, ..Current::default() }), "sea.current.speed_sigma_m_s"),
            (current(Current { direction_sigma_deg: big, ..Current::default() }), "sea.current.direction_sigma_deg"),
            (current(Current { time_constant_s: big, ..Current::default() }), "sea.current.time_constant_s"),
            (link(LinkErrors { multipath_excess_m: big, ..LinkErrors::default() }), "sea.link.multipath_excess_m"),
            (link(LinkErrors { false_max_range_m: big, ..LinkErrors::default() }), "sea.link.false_max_range_m"),
            (link(LinkErrors { loss_burst_mean: Some(big), ..LinkErrors::default() }), "sea.link.loss_burst_mean"),
            (
                Sea {
                    sensors: SensorErrors { heading_deviation_deg: 31.0, ..SensorErrors::default() },
                    ..Sea::default()
                },
                "sea.sensors.heading_deviation_deg",
            ),
        ];
        for (sea, key) in cases {
            let why = refused(&sea, World::FixedBeacon).unwrap_or_default();
            assert!(why.starts_with(&format!("{key}: ")) && why.contains("from "), "{key}: {why}");
        }
        let sea = Sea {
            clocks: ClockErrors { drift_sigma_ppm: 20.0, offset_sigma_s: 1e-3, ..ClockErrors::default() },
            current: Current { speed_m_s: 0.5, ..Current::default() },
            link: LinkErrors { multipath_excess_m: 30.0, ..LinkErrors::default() },
            ..Sea::default()
        };
        assert_eq!(refused(&sea, World::FixedBeacon), None);
    }

    /// Each table is checked against the worlds it applies to: refused by its name
    /// elsewhere, accepted where it applies; a fleet's inverted USBL takes the
    /// misalignment alone.
    #[test]
    fn each_table_applies_to_its_worlds() {
        use World::*;
        let clocks = Sea { clocks: ClockErrors { drift_sigma_ppm: 1.0, ..ClockErrors::default() }, ..Sea::default() };
        let usbl =
            Sea { usbl: UsblErrors { misalignment_deg: [0.0, 0.0, 1.0], ..UsblErrors::default() }, ..Sea::default() };
        let sensors =
            Sea { sensors: SensorErrors { speed_scale_sigma: 0.01, ..SensorErrors::default() }, ..Sea::default() };
        let heading =
            Sea { sensors: SensorErrors { heading_bias_sigma_deg: 1.0, ..SensorErrors::default() }, ..Sea::default() };
        let current = Sea { current: Current { speed_m_s: 0.1, ..Current::default() }, ..Sea::default() };
        let profile = Sea {
            sound_speed: Some(SoundSpeed { depth_m: vec![0.0], speed_m_s: vec![1500.0], ..SoundSpeed::default() }),
            ..Sea::default()
        };
        for (sea, key, allowed) in [
            (&clocks, "sea.clocks", [true, true, false, true]),
            (&usbl, "sea.usbl", [false, false, true, true]),
            (&sensors, "sea.sensors", [false, true, true, true]),
            (&heading, "sea.sensors", [true, true, true, true]),
            (&current, "sea.current", [true, false, false, true]),
            (&profile, "sea.sound_speed", [false, true, true, true]),
        ] {
            for (kind, ok) in [FixedBeacon, MovingBeacon, PassiveUsbl, Fleet].into_iter().zip(allowed) {
                let got = refused(sea, kind);
                assert_eq!(got.is_none(), ok, "{key} in {kind:?}: {got:?}");
                if let Some(e) = got {
                    assert!(e.starts_with(key) && e.contains(kind.label()), "{e}");
                }
            }
        }
        let waves = Sea { usbl: UsblErrors { wave_roll_deg: 3.0, ..UsblErrors::default() }, ..Sea::default() };
        assert!(refused(&waves, Fleet).unwrap().contains("misalignment_deg only"));
        assert!(refused(&waves, PassiveUsbl).is_none());
    }
}
