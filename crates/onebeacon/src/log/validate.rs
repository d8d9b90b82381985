//! Range checks on a parsed log description's own keys: each source's column keys, its
//! time keys, the beacons and the origin (the keys it shares with a stream configuration
//! are checked by [`crate::config::stream::StreamConfig::check`]). The first
//! violation is reported with its key.

use super::schema::{COLUMN_KEYS, IncrementFrame, LogDescription, Source, SourceKind, TimeOrder, TimeUnit};
use crate::config::check::{Rule, Violation, check};

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

/// Where a source's rows are: a CSV `file` with its `time` column, or a `bag` and its
/// `topic`.
fn check_place(i: usize, s: &Source) -> Result<(), Violation> {
    let at = |k: &str| format!("source[{i}].{k}");
    let fail = |key: &str, value: &str, allowed: &str| {
        Err(Violation { key: at(key), value: value.into(), allowed: allowed.into() })
    };
    let live = s.file.is_none() && s.bag.is_none();
    if !live && (s.r#type.is_some() || s.definition.is_some()) {
        let key = if s.r#type.is_some() { "type" } else { "definition" };
        return fail(key, "given", "names a live topic's type (onebeacon ros2); a file or a bag says its own");
    }
    match (&s.file, &s.bag) {
        (Some(_), Some(_)) => fail("bag", "given with file", "a source reads a CSV `file` or a ROS 2 `bag`, not both"),
        (None, None) if s.topic.is_none() || s.r#type.is_none() => fail(
            if s.topic.is_none() { "file" } else { "type" },
            "missing",
            "a source reads a CSV `file`, a ROS 2 `bag` with its `topic`, or (onebeacon ros2) a live `topic` with its `type`",
        ),
        (None, None) if s.time_format.is_some() || s.date.is_some() => {
            fail("time_format", "given", "a topic's times are stamps or the time received; time_format reads CSV text")
        }
        (Some(_), None) if s.topic.is_some() => fail("topic", "given", "names a bag's topic: give `bag`, not `file`"),
        (Some(_), None) if s.time.is_none() => fail("time", "missing", "a CSV source names its time column"),
        (None, Some(_)) if s.topic.is_none() => {
            fail("topic", "missing", "a bag source names the topic it reads (\"/dvl/twist\")")
        }
        (None, Some(_)) if s.time_format.is_some() || s.date.is_some() => {
            fail("time_format", "given", "a bag's times are stamps or the recorder's clock; time_format reads CSV text")
        }
        _ => Ok(()),
    }
}

/// What only a vehicle's computer on live topics takes: its own fix, and the vehicle of
/// several (`[[tracked]]`, `tracked` of them) a measurement is about.
fn check_computer(i: usize, s: &Source, tracked: usize) -> Result<(), Violation> {
    let live = s.file.is_none() && s.bag.is_none();
    let (key, value) = match (s.kind, &s.vehicle) {
        (SourceKind::OwnFix, _) => ("kind", "\"own_fix\"".to_string()),
        (_, Some(v)) => ("vehicle", format!("{v:?}")),
        _ => return Ok(()),
    };
    let allowed = if !live {
        "a vehicle's own fix and the vehicle a measurement is about are for a vehicle's computer on live topics (onebeacon ros2); replay estimates one vehicle from files and bags"
    } else if key == "vehicle" && tracked == 0 {
        "names which of the [[tracked]] vehicles a measurement is about; this description tracks none"
    } else {
        return Ok(());
    };
    Err(Violation { key: format!("source[{i}].{key}"), value, allowed: allowed.into() })
}

/// A log description's own keys: each source's column keys, the beacons, the origin.
pub(crate) fn validate_log(d: &LogDescription) -> Result<(), Violation> {
    if !d.model.is_planar() && !d.sources.is_empty() {
        return Err(Violation {
            key: "model".into(),
            value: format!("{:?}", d.model.label()),
            allowed: "\"planar\" for a log with [[source]] tables (their rows are planar odometry); \"6dof\" and \"unicycle\" are for `stream` (on body_velocity, attitude and depth lines; on speed, inertial and acoustic lines)".into(),
        });
    }
    if let Some(o) = &d.origin
        && !super::geodesy::on_earth(o.lat_deg, o.lon_deg)
    {
        return Err(Violation {
            key: "origin".into(),
            value: format!("lat_deg {}, lon_deg {}", o.lat_deg, o.lon_deg),
            allowed: "a latitude in [-90, 90] and a longitude in [-180, 360] degrees".into(),
        });
    }
    for (i, s) in d.sources.iter().enumerate() {
        check_place(i, s)?;
        check_computer(i, s, d.tracked.len())?;
        let (required, optional) = s.kind.columns();
        // a topic's standard messages give the keys a source leaves out: checked on opening it
        let bag = s.file.is_none();
        if let Some(key) = required.iter().find(|k| s.column(k).is_none() && !bag) {
            return Err(Violation {
                key: format!("source[{i}].{key}"),
                value: "missing".into(),
                allowed: format!("a {:?} source needs the column keys {}", s.kind, required.join(", ")),
            });
        }
        const POSITION: [&str; 4] = ["x", "y", "lat", "lon"];
        let positioned = s.kind.positioned();
        let has = |k: &str| s.column(k).is_some();
        if positioned && !(bag && POSITION.iter().all(|k| !has(k))) {
            check_position(&format!("source[{i}]"), (has("x"), has("y")), (has("lat"), has("lon")), POSITION)?;
        }
        let known = |k: &&str| {
            required.contains(k)
                || optional.contains(k)
                || positioned && POSITION.contains(k)
                || *k == "vehicle" && s.kind.about_a_vehicle()
                || ["beacon_sigma", "t_tx"].contains(k) && s.kind.heard()
        };
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
        if let Some(sigma) = s.sigma_m {
            if s.kind != SourceKind::GroundTruth || s.sigma.is_some() {
                return Err(Violation {
                    key: format!("source[{i}].sigma_m"),
                    value: sigma.to_string(),
                    allowed: "applies to a ground_truth source without a `sigma` column (the reference's error)".into(),
                });
            }
            check(&format!("source[{i}].sigma_m"), sigma, Rule::NonNegative)?;
        }
        let turns = matches!(
            s.kind,
            SourceKind::Odometry
                | SourceKind::BodyOdometry
                | SourceKind::BodyVelocity
                | SourceKind::Heading
                | SourceKind::SpeedHeading
                | SourceKind::GroundTruth
                | SourceKind::Bearing
                | SourceKind::Report
                | SourceKind::OwnFix
                | SourceKind::Attitude
        );
        if s.increment_frame != IncrementFrame::Mid
            && !matches!(s.kind, SourceKind::Odometry | SourceKind::BodyOdometry)
        {
            return Err(Violation {
                key: format!("source[{i}].increment_frame"),
                value: "\"start\"".into(),
                allowed: format!("applies to odometry and body_odometry sources, not to a {:?} source", s.kind),
            });
        }
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
    Ok(())
}
