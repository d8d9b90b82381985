//! Range checks on a parsed scenario. The first violation is reported with its key.
//! The rules a number or a name obeys are shared with the log descriptions'
//! ([`crate::replay::validate`]).

use super::estimator::{EstimatorKind, EstimatorSpec, Host, Sign};
use super::fleet::{Fleet, FleetEstimator, MODES};
use super::moving_beacon::Vehicle;
use super::passive_usbl::{AsvVehicle, Auv, AuvVehicle};
use super::{FixedBeacon, MovingBeacon, PassiveUsbl, Scenario};

pub(crate) struct Violation {
    pub key: String,
    pub value: String,
    pub allowed: String,
}

/// Rules for one number.
#[derive(Clone, Copy)]
pub(crate) enum Rule {
    Positive,
    NonNegative,
    Probability,
    Finite,
}

pub(crate) fn check(key: &str, value: f64, rule: Rule) -> Result<(), Violation> {
    let (ok, allowed) = match rule {
        Rule::Positive => (value > 0.0, "must be a finite number > 0"),
        Rule::NonNegative => (value >= 0.0, "must be a finite number >= 0"),
        Rule::Probability => ((0.0..=1.0).contains(&value), "must be a probability in [0, 1]"),
        Rule::Finite => (true, "must be a finite number"),
    };
    if ok && value.is_finite() {
        Ok(())
    } else {
        Err(Violation { key: key.to_string(), value: format!("{value:?}"), allowed: allowed.to_string() })
    }
}

/// Checks fields of one section; the key is built from the section and the field
/// name, so it cannot drift from the schema.
macro_rules! check_fields_impl {
    ($section:literal, $obj:expr, { $($field:ident: $rule:ident),* $(,)? }) => {
        $( $crate::scenario::validate::check(concat!($section, ".", stringify!($field)), $obj.$field, $crate::scenario::validate::Rule::$rule)?; )*
    };
}
pub(crate) use check_fields_impl as check_fields;

pub(crate) fn check_count(key: &str, value: usize, min: usize, max: usize) -> Result<(), Violation> {
    if (min..=max).contains(&value) {
        Ok(())
    } else {
        Err(Violation {
            key: key.to_string(),
            value: value.to_string(),
            allowed: format!("must be a whole number from {min} to {max}"),
        })
    }
}

pub(super) fn validate(s: &Scenario) -> Result<(), Violation> {
    match s {
        Scenario::FixedBeacon(s) => validate_fixed(s),
        Scenario::MovingBeacon(s) => validate_moving(s),
        Scenario::PassiveUsbl(s) => validate_passive(s),
        Scenario::Fleet(s) => validate_fleet(s),
    }
}

fn violation(key: impl Into<String>, value: impl std::fmt::Debug, allowed: impl Into<String>) -> Violation {
    Violation { key: key.into(), value: format!("{value:?}"), allowed: allowed.into() }
}

fn validate_fleet(s: &Fleet) -> Result<(), Violation> {
    check_file_name("name", &s.name)?;
    check_count("runs", s.runs, 1, 1_000_000)?;
    check_fields!("mission", s.mission, { duration_s: Positive, dt_s: Positive, ping_period_s: Positive });
    if s.mission.dt_s > s.mission.ping_period_s {
        return Err(violation("mission.dt_s", s.mission.dt_s, "must be at most mission.ping_period_s"));
    }
    check_steps(s.mission.duration_s, s.mission.dt_s, "mission.duration_s")?;
    check_fields!("signal", s.signal, {
        sound_speed_m_s: Positive,
        water_depth_m: Positive,
        snr_db_at_100m: Finite,
        range_sigma_m: NonNegative,
        angle_sigma_deg: NonNegative,
        outlier_probability: Probability,
        outlier_max_m: NonNegative,
        mode_error_probability: Probability,
        max_range_m: Positive,
    });
    for (key, v) in [("signal.surface_coef", s.signal.surface_coef), ("signal.bottom_coef", s.signal.bottom_coef)] {
        if !(-1.0..=1.0).contains(&v) {
            return Err(violation(key, v, "must be a reflection coefficient in [-1, 1]"));
        }
    }
    check_fields!("sandshark", s.sandshark, {
        max_turn_rate_deg_s: Positive,
        heading_gain_per_s: Positive,
        speed_time_constant_s: Positive,
        coast_time_constant_s: Positive,
        max_depth_rate_m_s: Positive,
        depth_gain_per_s: Positive,
        rise_rate_m_s: NonNegative,
        heading_error_deg: NonNegative,
        heading_error_time_s: Positive,
        heading_white_deg: NonNegative,
        attitude_white_deg: NonNegative,
        speed_scale_sigma: NonNegative,
        speed_white_m_s: NonNegative,
        depth_white_m: NonNegative,
    });
    let n = &s.navigation;
    check_count("navigation.particles", n.particles, 10, 100_000)?;
    check_count("navigation.reinitialised", n.reinitialised, 0, n.particles - 1)?;
    check_count("navigation.confirmations", n.confirmations, 1, 100)?;
    check_fields!("navigation", s.navigation, {
        max_range_m: Positive,
        sigma_speed_m_s: NonNegative,
        sigma_heading_deg: NonNegative,
        beacon_speed_m_s: NonNegative,
        floor: Probability,
        beam_exponent: Positive,
    });
    check_fields!("dock", s.dock, { north_m: Finite, east_m: Finite, beacon_depth_m: NonNegative, gps_sigma_m: NonNegative });
    check_count("boat (waypoints)", s.boat.len(), 1, 100_000)?;
    for (i, w) in s.boat.iter().enumerate() {
        for (k, v) in [("t_s", w.t_s), ("north_m", w.north_m), ("east_m", w.east_m)] {
            check(&format!("boat[{i}].{k}"), v, Rule::Finite)?;
        }
        if i > 0 && w.t_s <= s.boat[i - 1].t_s {
            return Err(violation(format!("boat[{i}].t_s"), w.t_s, "must be later than the waypoint before"));
        }
    }
    check_count("schedule (entries)", s.schedule.len(), 1, 100_000)?;
    for (i, e) in s.schedule.iter().enumerate() {
        check(&format!("schedule[{i}].t_s"), e.t_s, Rule::NonNegative)?;
        if i > 0 && e.t_s < s.schedule[i - 1].t_s {
            return Err(violation(format!("schedule[{i}].t_s"), e.t_s, "must not be earlier than the entry before"));
        }
        if e.mode > MODES {
            return Err(violation(format!("schedule[{i}].mode"), e.mode, format!("must be 0 (silent) to {MODES}")));
        }
    }
    check_count("auvs (count)", s.auvs.len(), 1, 16)?;
    let names: Vec<String> = s.auvs.iter().map(|a| a.name.clone()).collect();
    check_names("auvs", &names)?;
    for (i, a) in s.auvs.iter().enumerate() {
        let at = |k: &str| format!("auvs[{i}].{k}");
        for (k, v, rule) in [
            ("start_north_m", a.start_north_m, Rule::Finite),
            ("start_east_m", a.start_east_m, Rule::Finite),
            ("start_heading_deg", a.start_heading_deg, Rule::Finite),
            ("launch_s", a.launch_s, Rule::NonNegative),
            ("speed_m_s", a.speed_m_s, Rule::Positive),
            ("depth_m", a.depth_m, Rule::Positive),
        ] {
            check(&at(k), v, rule)?;
        }
        let water = s.signal.water_depth_m;
        if a.depth_m >= water {
            return Err(violation(
                at("depth_m"),
                a.depth_m,
                format!("must be above the bed: less than signal.water_depth_m = {water} m"),
            ));
        }
        for (j, m) in a.modes.iter().enumerate() {
            let at = |k: &str| format!("auvs[{i}].modes[{j}].{k}");
            if !(1..=MODES).contains(&m.mode) {
                return Err(violation(at("mode"), m.mode, format!("must be 1 to {MODES}")));
            }
            if a.modes[..j].iter().any(|o| o.mode == m.mode) {
                return Err(violation(at("mode"), m.mode, "must differ from this AUV's other modes"));
            }
            check(&at("offset_north_m"), m.offset_north_m, Rule::Finite)?;
            check(&at("offset_east_m"), m.offset_east_m, Rule::Finite)?;
            for key in m.required() {
                let Some(v) = m.value(key) else {
                    return Err(violation(at(key), "missing", format!("is needed by a {:?} behaviour", m.behaviour)));
                };
                check(&at(key), v, if *key == "heading_deg" { Rule::Finite } else { Rule::Positive })?;
            }
            if let Some(c) = m.ceiling_m.filter(|c| *c >= water) {
                return Err(violation(
                    at("ceiling_m"),
                    c,
                    format!("must be above the bed: less than signal.water_depth_m = {water} m"),
                ));
            }
        }
    }
    match s.estimators.first() {
        Some(FleetEstimator::Iusbl | FleetEstimator::IusblJoint) => {}
        other => {
            return Err(violation(
                "estimators",
                other.map(|e| e.label()),
                "the first estimator flies the behaviours: it must be `iusbl` or `iusbl-joint`",
            ));
        }
    }
    if s.estimators.iter().enumerate().any(|(i, e)| s.estimators[..i].contains(e)) {
        return Err(violation(
            "estimators",
            s.estimators.iter().map(|e| e.label()).collect::<Vec<_>>(),
            "must all differ",
        ));
    }
    Ok(())
}

/// A run of `duration_s` (which the key `duration_key` sets) in steps of `dt_s`: at
/// least one step, at most 1e8.
fn check_steps(duration_s: f64, dt_s: f64, duration_key: &str) -> Result<(), Violation> {
    if dt_s > duration_s {
        return Err(Violation {
            key: "mission.dt_s".into(),
            value: format!("{dt_s:?}"),
            allowed: format!("must not exceed the mission's duration, {duration_s:.6} s (set by {duration_key})"),
        });
    }
    let steps = duration_s / dt_s;
    if steps > 1e8 {
        return Err(Violation {
            key: duration_key.into(),
            value: format!("{duration_s:.4e} s of mission"),
            allowed: format!(
                "gives {steps:.4e} steps of mission.dt_s = {dt_s:?} s; at most 1e8 steps per run: shorten the \
                 mission or raise mission.dt_s"
            ),
        });
    }
    Ok(())
}

const NAME_RULE: &str = "must be non-empty ASCII letters, digits and + - _ .";

fn valid_name(name: &str) -> bool {
    !name.is_empty() && name.chars().all(|c| c.is_ascii_alphanumeric() || "+-_.".contains(c))
}

/// A name that output directories are made of: a name, not a path (no separator, not
/// `.` or `..`), at most 100 characters.
pub(crate) fn check_file_name(key: &str, name: &str) -> Result<(), Violation> {
    if valid_name(name) && name.len() <= 100 && name != "." && name != ".." {
        Ok(())
    } else {
        Err(Violation {
            key: key.into(),
            value: format!("{name:?}"),
            allowed: format!("{NAME_RULE}, at most 100 characters, not `.` or `..` (a name, not a path)"),
        })
    }
}

/// At least one of `section` (`estimators`, say); names of ASCII letters, digits and
/// + - _ . , all different.
fn check_names(section: &str, names: &[String]) -> Result<(), Violation> {
    if names.is_empty() {
        return Err(Violation {
            key: section.into(),
            value: "[]".into(),
            allowed: format!("at least one of {section} is needed"),
        });
    }
    for (k, name) in names.iter().enumerate() {
        let violation =
            |allowed: String| Violation { key: format!("{section}[{k}].name"), value: format!("{name:?}"), allowed };
        if !valid_name(name) {
            return Err(violation(NAME_RULE.into()));
        }
        if names[..k].contains(name) {
            return Err(violation(format!("must differ from the other {section}' names (set `name`)")));
        }
    }
    Ok(())
}

/// The `[[estimators]]` tables of `host`: names, the UKF's parameters, every tuning
/// key that is set (it must apply to the host and be in range), and the acoustic
/// measurements (the host must give them).
pub(crate) fn check_estimators(specs: &[EstimatorSpec], host: Host) -> Result<(), Violation> {
    check_names("estimators", &specs.iter().map(|e| e.name()).collect::<Vec<_>>())?;
    // the planar state has 4 to 8 components; 7 bounds kappa for the common case
    let states = match host {
        Host::Log => 7,
        Host::PassiveUsbl => 8,
        Host::FixedBeacon | Host::MovingBeacon => 6,
    };
    for (k, e) in specs.iter().enumerate() {
        let key = |f: &str| format!("estimators[{k}].{f}");
        check_ukf(&format!("estimators[{k}]"), states, (e.ukf_alpha, e.ukf_beta, e.ukf_kappa))?;
        for (name, v, sign, hosts) in e.tuning_keys() {
            if !hosts.contains(&host) {
                let flag = name.starts_with("estimate_") || name == "mirror_recovery";
                let value = if flag { (v != 0.0).to_string() } else { format!("{v:?}") };
                let applies: Vec<&str> = hosts.iter().map(|h| h.label()).collect();
                return Err(Violation {
                    key: key(name),
                    value,
                    allowed: format!("does not apply to a {} (it applies to: {})", host.label(), applies.join(", ")),
                });
            }
            let rule = match sign {
                Sign::Positive => Rule::Positive,
                Sign::NonNegative => Rule::NonNegative,
                Sign::Any => Rule::Finite,
            };
            check(&key(name), v, rule)?;
        }
        if e.estimate_beacon_offsets == Some(true)
            && (e.estimate_bias == Some(true) || e.track_accel_sigma_m_s2.is_some())
        {
            return Err(Violation {
                key: key("estimate_beacon_offsets"),
                value: "true".into(),
                allowed: "replaces the shared offset of estimate_bias (give one of the two), and does not apply to the tracker (track_accel_sigma_m_s2)".into(),
            });
        }
        if e.robust.is_some() && host != Host::Log {
            return Err(Violation {
                key: key("robust"),
                value: format!("{:?}", e.robust),
                allowed: format!("does not apply to a {} (it applies to: log)", host.label()),
            });
        }
        let particle = e.kind == EstimatorKind::Particle;
        let tracker = particle || e.kind == EstimatorKind::Bearing;
        if tracker != (host == Host::PassiveUsbl)
            && (tracker || matches!(e.kind, EstimatorKind::RangeDoppler | EstimatorKind::Rosb))
        {
            let allowed = if tracker {
                format!("tracks a vehicle by USBL bearings: a passive_usbl world only, not a {}", host.label())
            } else {
                "uses ranges; a passive_usbl world gives USBL bearings and the vehicle's reports (kinds pf, bearing, range-ekf, dead-reckoning)".to_string()
            };
            return Err(Violation { key: key("kind"), value: format!("{:?}", e.kind.label()), allowed });
        }
        let pf_only = [
            ("particles", e.particles.is_some()),
            ("resampler", e.resampler.is_some()),
            ("ess_fraction", e.ess_fraction.is_some()),
            ("roughening_k", e.roughening_k.is_some()),
            ("min_effective_particles", e.min_effective_particles.is_some()),
        ];
        if let Some((name, _)) = pf_only.iter().find(|(_, set)| *set).filter(|_| !particle) {
            return Err(Violation {
                key: key(name),
                value: "(set)".into(),
                allowed: format!("applies to a particle filter (kind = \"pf\") only, not to kind {:?}", e.kind.label()),
            });
        }
        if particle {
            check_count(&key("particles"), e.particles.unwrap_or(1), 1, 50_000_000)?;
            if let Some(f) = e.ess_fraction {
                check(&key("ess_fraction"), f, Rule::Probability)?;
            }
        }
        let (asked, has) = (e.aiding(host), host.acoustic());
        if (asked.doppler && !has.doppler) || (asked.range && !has.range) || (asked.bearing && !has.bearing) {
            let (k, value) = match &e.measurements {
                Some(m) => (key("measurements"), format!("{m:?}").to_lowercase()),
                None => (key("kind"), format!("{:?}", e.kind.label())),
            };
            let gives = match host {
                Host::MovingBeacon => "ranges only",
                Host::PassiveUsbl => "USBL bearings only",
                Host::FixedBeacon | Host::Log => "ranges and Doppler speeds only",
            };
            let uses = if asked.doppler && !has.doppler {
                "Doppler speeds"
            } else if asked.range && !has.range {
                "ranges"
            } else {
                "USBL bearings"
            };
            return Err(Violation { key: k, value, allowed: format!("uses {uses}; a {} gives {gives}", host.label()) });
        }
    }
    Ok(())
}

/// The UKF's sigma-point keys of estimator `k` (`prefix` names its table), for a state
/// of `states` components: 0 < alpha <= 1, beta >= 0, states + kappa > 0.
pub(crate) fn check_ukf(
    prefix: &str,
    states: usize,
    (alpha, beta, kappa): (Option<f64>, Option<f64>, Option<f64>),
) -> Result<(), Violation> {
    let bad = |key: &str, v: f64, allowed: String| Violation {
        key: format!("{prefix}.{key}"),
        value: format!("{v:?}"),
        allowed,
    };
    if let Some(a) = alpha.filter(|a| !(a.is_finite() && *a > 0.0 && *a <= 1.0)) {
        return Err(bad("ukf_alpha", a, "must be a number in (0, 1]".into()));
    }
    if let Some(b) = beta {
        check(&format!("{prefix}.ukf_beta"), b, Rule::NonNegative)?;
    }
    if let Some(k) = kappa.filter(|k| !(k.is_finite() && *k + states as f64 > 0.0)) {
        return Err(bad("ukf_kappa", k, format!("must be a finite number > -{states} (the state size)")));
    }
    Ok(())
}

fn check_list_nonempty<T>(key: &str, v: &Option<Vec<T>>) -> Result<(), Violation> {
    match v {
        Some(v) if v.is_empty() => Err(Violation {
            key: key.into(),
            value: "[]".into(),
            allowed: "must list at least one value, or be left out".into(),
        }),
        _ => Ok(()),
    }
}

/// The numbers of a vehicle's table (`prefix`: its key) and its optional name.
fn check_table(prefix: &str, fields: &[(&str, f64, Rule)], name: Option<&String>) -> Result<(), Violation> {
    for &(field, value, rule) in fields {
        check(&format!("{prefix}.{field}"), value, rule)?;
    }
    if let Some(name) = name.filter(|n| !valid_name(n)) {
        return Err(Violation { key: format!("{prefix}.name"), value: format!("{name:?}"), allowed: NAME_RULE.into() });
    }
    Ok(())
}

/// Names of a world's vehicles, all different: the first repeat is reported at the
/// key `{others}[k].name` (the first vehicle has its own table).
fn check_vehicle_names(names: &[String], others: &str, rule: &str) -> Result<(), Violation> {
    match (1..names.len()).find(|&k| names[..k].contains(&names[k])) {
        Some(k) => Err(Violation {
            key: format!("{others}[{}].name", k - 1),
            value: format!("{:?}", names[k]),
            allowed: rule.into(),
        }),
        None => Ok(()),
    }
}

/// One underwater vehicle's table (`prefix`: its key).
fn check_vehicle(prefix: &str, v: &Vehicle) -> Result<(), Violation> {
    use Rule::*;
    let fields = [
        ("depth_m", v.depth_m, NonNegative),
        ("start_north_m", v.start_north_m, Finite),
        ("start_east_m", v.start_east_m, Finite),
        ("heading_deg", v.heading_deg, Finite),
        ("speed_m_s", v.speed_m_s, NonNegative),
        ("circle_radius_m", v.circle_radius_m, Positive),
        ("spiral_descent_m_s", v.spiral_descent_m_s, NonNegative),
        ("leg_length_m", v.leg_length_m, Positive),
        ("leg_spacing_m", v.leg_spacing_m, Positive),
    ];
    check_table(prefix, &fields, v.name.as_ref())
}

fn validate_moving(s: &MovingBeacon) -> Result<(), Violation> {
    use Rule::*;
    check_file_name("name", &s.name)?;
    check_count("runs", s.runs, 1, 1_000_000)?;
    check_fields!("mission", s.mission, {
        dt_s: Positive,
        duration_s: Positive,
    });
    check_vehicle("vehicle", &s.vehicle)?;
    check_count("other_vehicles (count)", s.other_vehicles.len(), 0, 31)?;
    for (k, v) in s.other_vehicles.iter().enumerate() {
        check_vehicle(&format!("other_vehicles[{k}]"), v)?;
    }
    let vehicles = s.vehicles(&s.base_cell());
    let names: Vec<String> = vehicles.into_iter().filter_map(|v| v.name).collect();
    check_vehicle_names(
        &names,
        "other_vehicles",
        "must differ from the other vehicles' names (`auv` for `vehicle`, `auvN` for the N-th)",
    )?;
    let n = &s.sensors;
    check_fields!("sensors", n, {
        velocity_noise_m_s: Positive,
        rate_noise_rad_s: Positive,
        depth_noise_m: Positive,
        attitude_noise_deg: Positive,
    });
    let a = &s.asv;
    check_fields!("asv", a, {
        max_speed_m_s: Positive,
        max_turn_rate_deg_s: Positive,
        gps_noise_m: NonNegative,
        transducer_depth_m: NonNegative,
        start_bearing_deg: Finite,
    });
    let c = &s.acoustics;
    check_fields!("acoustics", c, {
        ping_period_s: Positive,
        sound_speed_m_s: Positive,
        range_noise_m: Positive,
    });
    check_count("guidance.grid_radial", s.guidance.grid_radial, 1, 10_000)?;
    check_count("guidance.grid_angular", s.guidance.grid_angular, 1, 10_000)?;
    check_fields!("guidance", s.guidance, {
        circle_radius_m: Positive,
    });
    let i = &s.initial;
    check_fields!("initial", i, {
        position_sigma_m: Positive,
        depth_sigma_m: Positive,
        attitude_sigma_deg: Positive,
    });
    check_estimators(&s.estimators, Host::MovingBeacon)?;
    check_list_nonempty("sweep.path", &s.sweep.path)?;
    check_list_nonempty("sweep.guidance", &s.sweep.guidance)?;
    check_list_nonempty("sweep.depth_m", &s.sweep.depth_m)?;
    for (j, &d) in s.sweep.depth_m.iter().flatten().enumerate() {
        check(&format!("sweep.depth_m[{j}]"), d, NonNegative)?;
    }
    check_steps(s.mission.duration_s, s.mission.dt_s, "mission.duration_s")
}

/// One AUV's table of a passive_usbl scenario (`prefix`: its key).
fn check_auv(prefix: &str, a: &Auv) -> Result<(), Violation> {
    use Rule::*;
    let fields = [
        ("centre_north_m", a.centre_north_m, Finite),
        ("centre_east_m", a.centre_east_m, Finite),
        ("circle_radius_m", a.circle_radius_m, Positive),
        ("depth_m", a.depth_m, NonNegative),
        ("speed_m_s", a.speed_m_s, NonNegative),
        ("start_angle_deg", a.start_angle_deg, Finite),
        ("ilos_lookahead_m", a.ilos_lookahead_m, Positive),
        ("ilos_integral_gain", a.ilos_integral_gain, NonNegative),
        ("path_gain", a.path_gain, NonNegative),
    ];
    check_table(prefix, &fields, a.name.as_ref())?;
    // REMUS 100 tops out at 2.48 m/s (1525 rpm) and needs way on for its fins
    if a.vehicle == AuvVehicle::Remus100 && !(0.5..=2.4).contains(&a.speed_m_s) {
        return Err(Violation {
            key: format!("{prefix}.speed_m_s"),
            value: format!("{:?}", a.speed_m_s),
            allowed: "must be from 0.5 to 2.4 m/s for a remus100 (its top speed is 2.48 m/s)".into(),
        });
    }
    Ok(())
}

fn validate_passive(s: &PassiveUsbl) -> Result<(), Violation> {
    check_file_name("name", &s.name)?;
    check_count("runs", s.runs, 1, 1_000_000)?;
    check_fields!("mission", s.mission, {
        duration_s: Positive,
        message_period_s: Positive,
        dt_s: Positive,
    });
    if s.mission.dt_s > s.mission.message_period_s {
        return Err(Violation {
            key: "mission.dt_s".into(),
            value: format!("{:?}", s.mission.dt_s),
            allowed: format!("must be at most mission.message_period_s ({})", s.mission.message_period_s),
        });
    }
    check_steps(s.mission.duration_s, s.mission.dt_s, "mission.duration_s")?;
    check_auv("auv", &s.auv)?;
    check_count("other_auvs (count)", s.other_auvs.len(), 0, 31)?;
    for (k, a) in s.other_auvs.iter().enumerate() {
        check_auv(&format!("other_auvs[{k}]"), a)?;
    }
    let names: Vec<String> = s.auvs().into_iter().filter_map(|a| a.name).collect();
    check_vehicle_names(
        &names,
        "other_auvs",
        "must differ from the other AUVs' names (`auv` for `auv`, `auvN` for the N-th)",
    )?;
    // the trackers assume these unless told otherwise: a zero would be a likelihood
    // of zero width
    check_fields!("reports", s.reports, {
        heading_noise_deg: Positive,
        speed_noise_m_s: Positive,
        depth_noise_m: Positive,
    });
    check_fields!("usbl", s.usbl, {
        noise_deg_per_m: Positive,
        transducer_depth_m: NonNegative,
    });
    check_fields!("asv", s.asv, {
        max_speed_m_s: Positive,
        max_turn_rate_deg_s: Positive,
        nominal_speed_m_s: Positive,
        along_track_gain: NonNegative,
        lookahead_m: Positive,
        ilos_integral_gain: NonNegative,
        gps_noise_m: NonNegative,
        compass_noise_deg: NonNegative,
        start_distance_m: NonNegative,
        start_bearing_deg: Finite,
    });
    check_fields!("current", s.current, {
        speed_m_s: NonNegative,
        toward_deg: Finite,
        speed_sigma_m_s: NonNegative,
        direction_sigma_deg: NonNegative,
        time_constant_s: Positive,
    });
    let dynamic = s.asv.vehicle == AsvVehicle::Otter || s.auvs().iter().any(|a| a.vehicle == AuvVehicle::Remus100);
    if s.current.flows() && !dynamic {
        return Err(Violation {
            key: "current.speed_m_s".into(),
            value: format!("{:?}", s.current.speed_m_s),
            allowed: "must be 0 unless a vehicle feels it (asv.vehicle = \"otter\" or an AUV's vehicle = \"remus100\"; kinematic vehicles move as commanded)".into(),
        });
    }
    let g = &s.guidance;
    check_fields!("guidance", g, {
        r1_m: Positive,
        r2_m: Positive,
        lead_periods: NonNegative,
        circle_radius_m: Positive,
        offset_m: NonNegative,
    });
    if g.r2_m < g.r1_m {
        return Err(Violation {
            key: "guidance.r2_m".into(),
            value: format!("{:?}", g.r2_m),
            allowed: format!("must be at least guidance.r1_m ({})", g.r1_m),
        });
    }
    check_count("guidance.radii", g.radii, 1, 1000)?;
    check_count("guidance.angles", g.angles, 1, 10_000)?;
    check_count("guidance.planner_particles", g.planner_particles, 1, 10_000_000)?;
    check_fields!("initial", s.initial, {
        position_sigma_m: Positive,
        depth_sigma_m: Positive,
        pitch_sigma_deg: Positive,
        heading_sigma_deg: Positive,
        speed_sigma_m_s: Positive,
        rate_bias_sigma_deg_s: Positive,
    });
    check_estimators(&s.estimators, Host::PassiveUsbl)?;
    check_list_nonempty("sweep.guidance", &s.sweep.guidance)
}

fn validate_fixed(s: &FixedBeacon) -> Result<(), Violation> {
    use Rule::*;
    check_file_name("name", &s.name)?;
    check_count("runs", s.runs, 1, 1_000_000)?;

    let m = &s.mission;
    check_fields!("mission", m, {
        dt_s: Positive,
        speed_m_s: Positive,
    });
    if let Some(d) = m.duration_s {
        check("mission.duration_s", d, Positive)?;
    }

    let p = &s.path;
    check_fields!("path", p, {
        start_north_m: Finite,
        start_east_m: Finite,
        leg_heading_deg: Finite,
        leg_length_m: Positive,
        leg_spacing_m: Positive,
    });
    check_count("path.legs", p.legs, 1, 10_000)?;

    check_fields!("beacon", s.beacon, {
        north_m: Finite,
        east_m: Finite,
    });

    check_fields!("comms", s.comms, {
        t_com_s: Positive,
        frame_loss_prob: Probability,
    });

    let n = &s.sensors;
    check_fields!("sensors", n, {
        range_noise_m: NonNegative,
        doppler_noise_m_s: NonNegative,
        heading_noise_deg: NonNegative,
        heading_bias_deg: NonNegative,
        heading_bias_drift_deg_per_h: NonNegative,
        gyro_noise_rad_s: NonNegative,
        accel_noise_m_s2: NonNegative,
    });

    let i = &s.initial;
    check_fields!("initial", i, {
        position_sigma_m: Positive,
        heading_sigma_deg: Positive,
        speed_sigma_m_s: Positive,
        yaw_rate_sigma_rad_s: Positive,
        accel_sigma_m_s2: Positive,
    });

    check_estimators(&s.estimators, Host::FixedBeacon)?;

    if let Some(v) = &s.sweep.t_com_s {
        if v.is_empty() {
            return Err(Violation {
                key: "sweep.t_com_s".into(),
                value: "[]".into(),
                allowed: "must list at least one value, or be left out".into(),
            });
        }
        for (j, &t) in v.iter().enumerate() {
            check(&format!("sweep.t_com_s[{j}]"), t, Positive)?;
        }
    }

    // the run must be of a workable size
    let duration_key =
        if m.duration_s.is_some() { "mission.duration_s" } else { "mission.speed_m_s (the path's length / speed_m_s)" };
    check_steps(s.duration_s(), m.dt_s, duration_key)
}
