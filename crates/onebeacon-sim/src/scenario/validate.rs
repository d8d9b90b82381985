//! The range checks each world's schema makes on a parsed scenario (the first violation
//! is reported with its key).
//! The rules a number or a name obeys are shared with the log descriptions'
//! ([`crate::replay::validate`]).

pub(crate) use onebeacon::config::check::{
    NAME_RULE, Rule, Violation, check, check_count, check_file_name, check_names, valid_name,
};
pub(crate) use onebeacon::config::check_estimators;

/// Checks fields of one section; the key is built from the section and the field
/// name, so it cannot drift from the schema.
macro_rules! check_fields_impl {
    ($section:literal, $obj:expr, { $($field:ident: $rule:ident),* $(,)? }) => {
        $( $crate::scenario::validate::check(concat!($section, ".", stringify!($field)), $obj.$field, $crate::scenario::validate::Rule::$rule)?; )*
    };
}
pub(crate) use check_fields_impl as check_fields;

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
