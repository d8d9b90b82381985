//! What a configuration key may be, and the one-line error that says so: the rules the
//! onboard configuration (estimators, controllers, stream) and the simulator's scenarios
//! and logs share. The first violation is reported with its key.

/// A key that is not what it may be: `key = value: allowed`.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("key `{key}` = {value}: {allowed}")]
pub struct Violation {
    pub key: String,
    pub value: String,
    pub allowed: String,
}

/// Rules for one number.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Rule {
    Positive,
    NonNegative,
    Probability,
    Finite,
    /// A threshold: > 0, infinity (`inf` in TOML) meaning none.
    Threshold,
}

pub fn check(key: &str, value: f64, rule: Rule) -> Result<(), Violation> {
    let (ok, allowed) = match rule {
        Rule::Positive => (value > 0.0, "must be a finite number > 0"),
        Rule::NonNegative => (value >= 0.0, "must be a finite number >= 0"),
        Rule::Probability => ((0.0..=1.0).contains(&value), "must be a probability in [0, 1]"),
        Rule::Finite => (true, "must be a finite number"),
        Rule::Threshold => (value > 0.0, "must be a number > 0, or inf for none"),
    };
    if ok && (value.is_finite() || rule == Rule::Threshold) {
        Ok(())
    } else {
        Err(Violation { key: key.to_string(), value: format!("{value:?}"), allowed: allowed.to_string() })
    }
}

pub fn check_count(key: &str, value: usize, min: usize, max: usize) -> Result<(), Violation> {
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

pub const NAME_RULE: &str = "must be non-empty ASCII letters, digits and + - _ .";

pub fn valid_name(name: &str) -> bool {
    !name.is_empty() && name.chars().all(|c| c.is_ascii_alphanumeric() || "+-_.".contains(c))
}

/// A name that output directories are made of: a name, not a path (no separator, not
/// `.` or `..`), at most 100 characters.
pub fn check_file_name(key: &str, name: &str) -> Result<(), Violation> {
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
pub fn check_names(section: &str, names: &[String]) -> Result<(), Violation> {
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

/// The UKF's sigma-point keys of estimator `k` (`prefix` names its table), for a state
/// of `states` components: 0 < alpha <= 1, beta >= 0, states + kappa > 0.
pub fn check_ukf(
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
