//! Range checks on a parsed log description: each source's column keys, its time keys,
//! the beacons, the noise keys, the estimators, the start and the limits. The first
//! violation is reported with its key.

use super::log::{COLUMN_KEYS, InitialFrom, LogDescription, Source, SourceKind, TimeOrder, TimeUnit};
use crate::scenario::estimator::{Host, NOISE_KEYS};
use crate::scenario::validate::{Rule, Violation, check, check_count, check_estimators, check_fields, check_file_name};

/// A position given as exactly one pair: `x`/`y` or `lat`/`lon` (the keys named by
/// `keys`, at `at`).
fn check_position(at: &str, xy: (bool, bool), latlon: (bool, bool), keys: [&str; 4]) -> Result<(), Violation> {
    let [x, y, lat, lon] = keys;
    let (xy_some, latlon_some) = (xy.0 || xy.1, latlon.0 || latlon.1);
    let ok = match (xy_some, latlon_some) {
        (true, false) => xy.0 && xy.1,
        (false, true) => latlon.0 && latlon.1,
        _ => false,
    };
    if ok {
        return Ok(());
    }
    let given = [(x, xy.0), (y, xy.1), (lat, latlon.0), (lon, latlon.1)]
        .iter()
        .filter(|(_, g)| *g)
        .map(|(k, _)| *k)
        .collect::<Vec<_>>();
    Err(Violation {
        key: format!("{at}.{}", if xy_some { x } else { lat }),
        value: if given.is_empty() { "missing".into() } else { format!("given: {}", given.join(", ")) },
        allowed: format!("a position needs `{x}` and `{y}`, or `{lat}` and `{lon}` (one pair, not both)"),
    })
}

/// The time keys of a source: a valid strftime pattern, a date only with a pattern.
fn check_time(i: usize, s: &Source) -> Result<(), Violation> {
    let at = |k: &str| format!("source[{i}].{k}");
    if let Some(f) = &s.time_format {
        let bad = chrono::format::StrftimeItems::new(f).any(|item| matches!(item, chrono::format::Item::Error));
        if bad || f.trim().is_empty() {
            return Err(Violation {
                key: at("time_format"),
                value: format!("{f:?}"),
                allowed: "a strftime pattern such as \"%H:%M:%S%.f\" (with `date`) or \"%Y-%m-%dT%H:%M:%S%.fZ\"".into(),
            });
        }
        if s.time_unit != TimeUnit::S {
            return Err(Violation {
                key: at("time_unit"),
                value: format!("{:?}", s.time_unit).to_lowercase(),
                allowed: "applies to numeric times, not with time_format".into(),
            });
        }
    }
    if let Some(date) = &s.date
        && (s.time_format.is_none() || chrono::NaiveDate::parse_from_str(date, "%Y-%m-%d").is_err())
    {
        return Err(Violation {
            key: at("date"),
            value: format!("{date:?}"),
            allowed: "a day YYYY-MM-DD, for a time_format that writes the time of day only".into(),
        });
    }
    if s.sort && s.time_order.is_some_and(|o| o != TimeOrder::Sort) {
        return Err(Violation {
            key: at("sort"),
            value: "true".into(),
            allowed: "is the older time_order = \"sort\"; give one of the two".into(),
        });
    }
    check(&at("time_offset_s"), s.time_offset_s, Rule::Finite)
}

/// A log description: each source's column keys, the estimators, the start.
pub(crate) fn validate_log(d: &LogDescription) -> Result<(), Violation> {
    check_file_name("name", &d.name)?;
    if let Some(o) = &d.origin
        && !crate::replay::geodesy::on_earth(o.lat_deg, o.lon_deg)
    {
        return Err(Violation {
            key: "origin".into(),
            value: format!("lat_deg {}, lon_deg {}", o.lat_deg, o.lon_deg),
            allowed: "a latitude in [-90, 90] and a longitude in [-180, 360] degrees".into(),
        });
    }
    for (i, s) in d.sources.iter().enumerate() {
        let (required, optional) = s.kind.columns();
        if let Some(key) = required.iter().find(|k| s.column(k).is_none()) {
            return Err(Violation {
                key: format!("source[{i}].{key}"),
                value: "missing".into(),
                allowed: format!("a {:?} source needs the column keys {}", s.kind, required.join(", ")),
            });
        }
        const POSITION: [&str; 4] = ["x", "y", "lat", "lon"];
        let positioned = s.kind.positioned();
        if positioned {
            let has = |k: &str| s.column(k).is_some();
            check_position(&format!("source[{i}]"), (has("x"), has("y")), (has("lat"), has("lon")), POSITION)?;
        }
        let known = |k: &&str| required.contains(k) || optional.contains(k) || positioned && POSITION.contains(k);
        if let Some(key) = COLUMN_KEYS.iter().find(|k| s.column(k).is_some() && !known(k)) {
            let allowed: Vec<&str> = required.iter().chain(optional).copied().collect();
            return Err(Violation {
                key: format!("source[{i}].{key}"),
                value: format!("{:?}", s.column(key).cloned().unwrap_or_default()),
                allowed: format!("does not apply to a {:?} source (its column keys: {})", s.kind, allowed.join(", ")),
            });
        }
        check_time(i, s)?;
        check(&format!("source[{i}].heading_offset_deg"), s.heading_offset_deg, Rule::Finite)?;
        let turns = matches!(
            s.kind,
            SourceKind::Odometry
                | SourceKind::BodyOdometry
                | SourceKind::BodyVelocity
                | SourceKind::Heading
                | SourceKind::SpeedHeading
                | SourceKind::GroundTruth
        );
        if !turns && (s.heading_offset_deg != 0.0 || s.heading_clockwise.is_some()) {
            return Err(Violation {
                key: format!("source[{i}].heading_clockwise"),
                value: "given".into(),
                allowed: format!("heading keys do not apply to a {:?} source (it has no heading)", s.kind),
            });
        }
    }
    if let Some(t) = &d.beacons {
        check_position(
            "beacons",
            (t.x.is_some(), t.y.is_some()),
            (t.lat.is_some(), t.lon.is_some()),
            ["x", "y", "lat", "lon"],
        )?;
    }
    for (i, b) in d.beacon_list.iter().enumerate() {
        check_position(
            &format!("beacon[{i}]"),
            (b.x_m.is_some(), b.y_m.is_some()),
            (b.lat_deg.is_some(), b.lon_deg.is_some()),
            ["x_m", "y_m", "lat_deg", "lon_deg"],
        )?;
        for v in [b.x_m, b.y_m, b.lat_deg, b.lon_deg, Some(b.z_m)].into_iter().flatten() {
            check(&format!("beacon[{i}]"), v, Rule::Finite)?;
        }
    }
    for (key, v) in &d.noise {
        let Some((_, positive)) = NOISE_KEYS.iter().find(|(k, _)| k == key) else {
            let keys: Vec<&str> = NOISE_KEYS.iter().map(|k| k.0).collect();
            return Err(Violation {
                key: format!("noise.{key}"),
                value: format!("{v:?}"),
                allowed: format!("is not a noise key (keys: {})", keys.join(", ")),
            });
        };
        check(&format!("noise.{key}"), *v, if *positive { Rule::Positive } else { Rule::NonNegative })?;
    }
    check_estimators(&d.estimators, Host::Log)?;
    for (e, spec) in d.estimators.iter().enumerate() {
        if spec.iusbl.is_some() && !spec.kind.iusbl() {
            return Err(Violation {
                key: format!("estimators[{e}].iusbl"),
                value: "(set)".into(),
                allowed: format!("applies to kinds iusbl and iusbl-joint only, not to {:?}", spec.kind.label()),
            });
        }
        for (key, v, positive) in spec.iusbl.iter().flat_map(|k| k.numbers()) {
            check(
                &format!("estimators[{e}].iusbl.{key}"),
                v,
                if positive { Rule::Positive } else { Rule::NonNegative },
            )?;
        }
    }
    check_initial("initial", &d.initial)?;
    for (v, init) in d.tracked.iter().enumerate() {
        check_initial(&format!("tracked[{v}]"), init)?;
    }
    if let Some(c) = &d.controller {
        c.check(&onebeacon::io::jsonl::kinds()).map_err(|e| Violation {
            key: format!("controller.{}", e.key),
            value: e.value,
            allowed: e.allowed,
        })?;
    }
    let l = &d.limits;
    check_fields!("limits", l, {
        max_range_m: Positive,
        max_speed_m_s: Positive,
        max_rate_rad_s: Positive,
        max_depth_m: Positive,
        max_time_gap_s: Positive,
    });
    check_count("limits.max_beacons", l.max_beacons, 1, 1 << 20)?;
    check_count("limits.max_rejections", l.max_rejections, 0, 100_000_000)?;
    check_count("limits.max_line_bytes", l.max_line_bytes, 64, 1 << 26)?;
    Ok(())
}

/// One `[initial]` table (or one of `[[tracked]]`, `section` naming it).
fn check_initial(section: &str, init: &crate::replay::schema::Initial) -> Result<(), Violation> {
    if init.from == InitialFrom::Given && (init.x_m.is_none() || init.y_m.is_none() || init.heading_deg.is_none()) {
        return Err(Violation {
            key: format!("{section}.from"),
            value: "\"given\"".into(),
            allowed: format!("needs {section}.x_m, {section}.y_m and {section}.heading_deg"),
        });
    }
    for (key, v, rule) in [
        ("position_sigma_m", init.position_sigma_m, Rule::Positive),
        ("heading_sigma_deg", init.heading_sigma_deg, Rule::Positive),
        ("track_m", init.track_m, Rule::Positive),
        ("ranges_window_s", init.ranges_window_s, Rule::Positive),
        ("depth_m", init.depth_m, Rule::Finite),
        ("pitch_deg", init.pitch_deg, Rule::Finite),
        ("speed_m_s", init.speed_m_s, Rule::Finite),
        ("pitch_rate_bias_deg_s", init.pitch_rate_bias_deg_s, Rule::Finite),
        ("heading_rate_bias_deg_s", init.heading_rate_bias_deg_s, Rule::Finite),
        ("depth_sigma_m", init.depth_sigma_m, Rule::Positive),
        ("pitch_sigma_deg", init.pitch_sigma_deg, Rule::Positive),
        ("speed_sigma_m_s", init.speed_sigma_m_s, Rule::Positive),
        ("rate_bias_sigma_deg_s", init.rate_bias_sigma_deg_s, Rule::Positive),
    ] {
        check(&format!("{section}.{key}"), v, rule)?;
    }
    if let Some(t) = init.t0_s {
        check(&format!("{section}.t0_s"), t, Rule::Finite)?;
    }
    Ok(())
}
