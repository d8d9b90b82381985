//! Range checks on a parsed scenario. The first violation is reported with its key.
//! The rules a number or a name obeys are shared with the log descriptions'
//! ([`crate::replay::validate`]).

use super::Scenario;
use super::estimator::{EstimatorKind, EstimatorSpec, Host, Sign};
use onebeacon::nav::Aiding;

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

/// A scenario's checks: each world's are beside its type.
pub(super) fn validate(s: &Scenario) -> Result<(), Violation> {
    match s {
        Scenario::FixedBeacon(s) => super::fixed_beacon::validate_fixed(s),
        Scenario::MovingBeacon(s) => super::moving_beacon::validate_moving(s),
        Scenario::PassiveUsbl(s) => super::passive_usbl::validate_passive(s),
        Scenario::Fleet(s) => super::fleet::validate_fleet(s),
    }
}

pub(super) fn violation(key: impl Into<String>, value: impl std::fmt::Debug, allowed: impl Into<String>) -> Violation {
    Violation { key: key.into(), value: format!("{value:?}"), allowed: allowed.into() }
}

/// A run of `duration_s` (which the key `duration_key` sets) in steps of `dt_s`: at
/// least one step, at most 1e8.
pub(super) fn check_steps(duration_s: f64, dt_s: f64, duration_key: &str) -> Result<(), Violation> {
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

pub(super) const NAME_RULE: &str = "must be non-empty ASCII letters, digits and + - _ .";

pub(super) fn valid_name(name: &str) -> bool {
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
pub(super) fn check_names(section: &str, names: &[String]) -> Result<(), Violation> {
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
        let tracker = e.kind.tracks_bearings();
        if e.kind.iusbl() && host != Host::Log {
            return Err(Violation {
                key: key("kind"),
                value: format!("{:?}", e.kind.label()),
                allowed: format!("navigates on a beacon's array fixes: a fleet world or a log, not a {}", host.label()),
            });
        }
        // a log may carry USBL bearings (a surface vehicle's stream)
        if tracker && !matches!(host, Host::PassiveUsbl | Host::Log)
            || host == Host::PassiveUsbl && matches!(e.kind, EstimatorKind::RangeDoppler | EstimatorKind::Rosb)
        {
            let allowed = if tracker {
                format!("tracks a vehicle by USBL bearings: a passive_usbl world or a log, not a {}", host.label())
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
        let has = if host == Host::Log && tracker { Aiding::BEARING } else { host.acoustic() };
        let asked = e.aiding(host);
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

pub(super) fn check_list_nonempty<T>(key: &str, v: &Option<Vec<T>>) -> Result<(), Violation> {
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
pub(super) fn check_table(prefix: &str, fields: &[(&str, f64, Rule)], name: Option<&String>) -> Result<(), Violation> {
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
pub(super) fn check_vehicle_names(names: &[String], others: &str, rule: &str) -> Result<(), Violation> {
    match (1..names.len()).find(|&k| names[..k].contains(&names[k])) {
        Some(k) => Err(Violation {
            key: format!("{others}[{}].name", k - 1),
            value: format!("{:?}", names[k]),
            allowed: rule.into(),
        }),
        None => Ok(()),
    }
}
