//! Loading a scenario from a built-in name or a file, with one-line errors that name
//! the source, the key and what is allowed.

use super::{FixedBeacon, Fleet, MovingBeacon, PassiveUsbl, Scenario, builtin, validate};
use onebeacon::config::toml_file::{self, ConfigError};
use std::path::Path;

/// Why a scenario could not be loaded. Each message is one line naming the source (file
/// or built-in), the key and what is allowed.
#[derive(Debug, thiserror::Error)]
pub enum ScenarioError {
    #[error("unknown scenario `{name}`: built-in scenarios are {available}; or give the path of a .toml file")]
    UnknownBuiltin { name: String, available: String },
    #[error(transparent)]
    File(#[from] ConfigError),
}

/// Loads `name_or_path`: a built-in scenario name, or the path of a TOML file.
pub fn load(name_or_path: &str) -> Result<Scenario, ScenarioError> {
    if builtin(name_or_path).is_some() {
        return load_builtin(name_or_path);
    }
    let looks_like_path = name_or_path.ends_with(".toml") || name_or_path.contains(['/', '\\']);
    if !looks_like_path && !Path::new(name_or_path).exists() {
        return load_builtin(name_or_path);
    }
    load_file(Path::new(name_or_path))
}

/// Loads the built-in scenario `name`.
pub fn load_builtin(name: &str) -> Result<Scenario, ScenarioError> {
    match builtin(name) {
        Some(b) => parse(b.toml, &format!("built-in scenario `{}`", b.name)),
        None => Err(ScenarioError::UnknownBuiltin {
            name: name.to_string(),
            available: super::BUILTINS.iter().map(|b| format!("`{}`", b.name)).collect::<Vec<_>>().join(", "),
        }),
    }
}

/// Loads the scenario of the TOML file at `path`.
pub fn load_file(path: &Path) -> Result<Scenario, ScenarioError> {
    parse(&toml_file::read(path)?, &path.display().to_string())
}

/// Deserializes TOML into `T` with errors naming the source, line and key.
pub(crate) fn deserialize<T: serde::de::DeserializeOwned>(text: &str, source_name: &str) -> Result<T, ScenarioError> {
    Ok(toml_file::deserialize(text, source_name)?)
}

/// Turns a validation failure into the error naming the source.
pub(crate) fn invalid(source_name: &str, v: validate::Violation) -> ScenarioError {
    toml_file::invalid(source_name, v).into()
}

/// Parses and validates scenario TOML; `source_name` names it in errors.
pub fn parse(text: &str, source_name: &str) -> Result<Scenario, ScenarioError> {
    // the world's kind decides the schema; a bad `kind` is reported by the default one,
    // and text that is no TOML (an integer beyond 64 bits too) as what it is
    let table: toml::Table = deserialize(text, source_name)?;
    let kind = table.get("kind").and_then(|k| k.as_str().map(String::from));
    let scenario = if kind.as_deref() == Some("moving_beacon") {
        Scenario::MovingBeacon(deserialize::<MovingBeacon>(text, source_name)?)
    } else if kind.as_deref() == Some("passive_usbl") {
        Scenario::PassiveUsbl(deserialize::<PassiveUsbl>(text, source_name)?)
    } else if kind.as_deref() == Some("fleet") {
        Scenario::Fleet(deserialize::<Fleet>(text, source_name)?)
    } else {
        Scenario::FixedBeacon(deserialize::<FixedBeacon>(text, source_name)?)
    };
    let canonical: toml::Table = toml::from_str(&scenario.to_toml()).expect("canonical TOML parses");
    tables_where_tables_belong(&table, &canonical, "").map_err(|v| invalid(source_name, v))?;
    scenario.validate().map_err(|v| invalid(source_name, v))?;
    Ok(scenario)
}

/// Refuses an array where the schema has a table (`canonical`: what was read, written
/// back with every key): serde builds a struct from an array by position, so
/// `mission = [1, 2]` would silently set the mission's first two keys.
pub(crate) fn tables_where_tables_belong(
    input: &toml::Table,
    canonical: &toml::Table,
    at: &str,
) -> Result<(), validate::Violation> {
    use toml::Value::{Array, Table};
    for (k, v) in input {
        let key = if at.is_empty() { k.clone() } else { format!("{at}.{k}") };
        match (v, canonical.get(k)) {
            (Array(_), Some(Table(_))) => {
                return Err(validate::Violation {
                    key,
                    value: "an array".into(),
                    allowed: "must be a table (a [section] or { key = value, ... }), not an array".into(),
                });
            }
            (Table(t), Some(Table(c))) => tables_where_tables_belong(t, c, &key)?,
            (Array(a), Some(Array(c))) => {
                for (i, (x, y)) in a.iter().zip(c).enumerate() {
                    if let (Table(x), Table(y)) = (x, y) {
                        tables_where_tables_belong(x, y, &format!("{key}[{i}]"))?;
                    }
                }
            }
            _ => {}
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn err(text: &str) -> String {
        parse(text, "test.toml").unwrap_err().to_string()
    }

    #[test]
    fn minimal_scenario_takes_defaults() {
        let Scenario::FixedBeacon(s) = parse("name = \"x\"\n", "test.toml").unwrap() else { panic!() };
        assert_eq!(s.runs, 300);
        assert_eq!(s.comms.t_com_s, 3.0);
        assert_eq!(s.estimators.len(), 2);
    }

    #[test]
    fn errors_name_the_key_and_what_is_allowed() {
        let e = err("name = \"x\"\n[comms]\nt_comm_s = 3.0\n");
        assert!(e.contains("test.toml") && e.contains("t_comm_s") && e.contains("t_com_s"), "{e}");
        assert!(e.contains("line 3"), "{e}");

        let e = err("name = \"x\"\n[comms]\nt_com_s = \"fast\"\n");
        assert!(e.contains("comms.t_com_s") && e.contains("line 3"), "{e}");

        let e = err("name = \"x\"\n[comms]\nt_com_s = -1.0\n");
        assert!(e.contains("comms.t_com_s") && e.contains("-1") && e.contains("> 0"), "{e}");

        let e = err("name = \"x\"\n[sensors]\nrange_noise_m = nan\n");
        assert!(e.contains("sensors.range_noise_m") && e.contains("NaN"), "{e}");

        let e = err("name = \"x\"\n[sensors]\ndoppler_noise_m_s = -0.1\n");
        assert!(e.contains("sensors.doppler_noise_m_s") && e.contains(">= 0"), "{e}");

        let e = err("name = \"x\"\nruns = 0\n");
        assert!(e.contains("`runs`") && e.contains("from 1 to"), "{e}");

        // a number TOML cannot hold is named as such, not as another kind's unknown key
        let e = err(
            "kind = \"passive_usbl\"\nname = \"x\"\n[[estimators]]\nkind = \"pf\"\nparticles = 18446744073709551615\n[asv]\n",
        );
        assert!(e.contains("line 5") && !e.contains("unknown field"), "{e}");

        // an array where a table belongs is not read by position
        for text in ["name = \"x\"\nmission = [1.0, 2.0]\n", "name = \"x\"\ncomms = []\n"] {
            let e = err(text);
            assert!(e.contains("must be a table"), "{text}: {e}");
        }

        let e = err("name = \"x\"\n[sweep]\nt_com_s = [3.0, 0.0]\n");
        assert!(e.contains("sweep.t_com_s[1]"), "{e}");

        let e = err("name = \"x\"\n[[estimators]]\nkind = \"kalman\"\n");
        assert!(e.contains("estimators[0].kind") && e.contains("range+doppler"), "{e}");

        let e = err("name = \"x\"\n[comms\n");
        assert!(e.contains("test.toml: line 2"), "{e}");

        let e = err("name = \"x\"\nkind = \"floating\"\n");
        assert!(e.contains("kind") && e.contains("moving_beacon"), "{e}");

        let e = err("name = \"x\"\nkind = \"moving_beacon\"\n[sweep]\npath = [\"zigzag\"]\n");
        assert!(e.contains("sweep.path[0]") && e.contains("circular"), "{e}");

        let e = err("name = \"x\"\nkind = \"moving_beacon\"\n[acoustics]\nsound_speed_m_s = 0\n");
        assert!(e.contains("acoustics.sound_speed_m_s") && e.contains("> 0"), "{e}");

        let e = err("description = \"no name\"\n");
        assert!(e.contains("name"), "{e}");

        let p = "name = \"x\"\nkind = \"passive_usbl\"\n";
        let e = err(&format!("{p}[guidance]\nr1_m = 30.0\n"));
        assert!(e.contains("guidance.r2_m") && e.contains("at least guidance.r1_m"), "{e}");
        let e = err(&format!("{p}[[estimators]]\nkind = \"bearing\"\nparticles = 100\n"));
        assert!(e.contains("estimators[0].particles") && e.contains("kind = \"pf\""), "{e}");
        let e = err(&format!("{p}[[estimators]]\nkind = \"rosb\"\n"));
        assert!(e.contains("estimators[0].kind") && e.contains("passive_usbl world gives USBL bearings"), "{e}");
        let e = err("name = \"x\"\n[[estimators]]\nkind = \"pf\"\n");
        assert!(e.contains("estimators[0].kind") && e.contains("a passive_usbl world or a log"), "{e}");
        let e = err(&format!("{p}[[estimators]]\nkind = \"pf\"\ness_fraction = 1.5\n"));
        assert!(e.contains("estimators[0].ess_fraction") && e.contains("probability"), "{e}");
        let e = err(&format!("{p}[[estimators]]\nkind = \"pf\"\nrange_sigma_m = 1.0\n"));
        assert!(e.contains("estimators[0].range_sigma_m") && e.contains("passive_usbl"), "{e}");
        let e = err(&format!("{p}[sweep]\nguidance = [\"det\", \"zigzag\"]\n"));
        assert!(e.contains("sweep.guidance[1]") && e.contains("max-eig"), "{e}");
        let e = err(&format!("{p}[usbl]\nnoise_deg_per_m = 0.0\n"));
        assert!(e.contains("usbl.noise_deg_per_m") && e.contains("> 0"), "{e}");
        let e = err(&format!("{p}[current]\nspeed_m_s = 0.2\n"));
        assert!(e.contains("current.speed_m_s") && e.contains("otter"), "{e}");
        let e = err(&format!("{p}[auv]\nvehicle = \"remus100\"\nspeed_m_s = 3.0\n"));
        assert!(e.contains("auv.speed_m_s") && e.contains("2.4"), "{e}");
        let e = err(&format!("{p}[auv]\nvehicle = \"remus\"\n"));
        assert!(e.contains("auv.vehicle") && e.contains("remus100"), "{e}");

        for e in [err("name = 1\n"), err("name=\"x\"\n[mission]\ndt_s = inf\n")] {
            assert!(!e.contains('\n'), "{e}");
        }
    }
}
