//! Every key of a built-in scenario and of a shipped log description is documented:
//! docs/scenarios.md and docs/logs.md name each key path in backticks (arrays of tables
//! as `estimators[].kind`). A key added to a file without its line in the docs fails.

use std::path::{Path, PathBuf};

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

/// Every leaf key path of a TOML table.
fn key_paths(table: &toml::Table, prefix: &str, out: &mut Vec<String>) {
    for (k, v) in table {
        let path = format!("{prefix}{k}");
        match v {
            toml::Value::Table(t) => key_paths(t, &format!("{path}."), out),
            toml::Value::Array(a) if a.iter().all(toml::Value::is_table) && !a.is_empty() => {
                for t in a.iter().filter_map(toml::Value::as_table) {
                    key_paths(t, &format!("{path}[]."), out);
                }
            }
            _ => out.push(path),
        }
    }
}

fn undocumented(toml_text: &str, doc: &str) -> Vec<String> {
    let table: toml::Table = toml_text.parse().expect("shipped TOML parses");
    let mut keys = Vec::new();
    key_paths(&table, "", &mut keys);
    keys.sort();
    keys.dedup();
    keys.into_iter().filter(|k| !doc.contains(&format!("`{k}`"))).collect()
}

#[test]
fn every_key_of_the_built_in_scenarios_is_documented() {
    let doc = std::fs::read_to_string(root().join("docs/scenarios.md")).unwrap();
    for b in onebeacon_sim::scenario::BUILTINS {
        let missing = undocumented(b.toml, &doc);
        assert!(missing.is_empty(), "scenario {}: keys missing from docs/scenarios.md: {missing:?}", b.name);
    }
    // and the check can fail
    assert_eq!(undocumented("[mission]\nwarp_factor = 9\n", &doc), ["mission.warp_factor"]);
}

#[test]
fn every_key_of_the_shipped_log_descriptions_is_documented() {
    let doc = std::fs::read_to_string(root().join("docs/logs.md")).unwrap();
    let dir = root().join("data/plaza");
    let mut seen = 0;
    for entry in std::fs::read_dir(&dir).unwrap() {
        let path = entry.unwrap().path();
        if path.extension().is_some_and(|e| e == "toml") {
            let missing = undocumented(&std::fs::read_to_string(&path).unwrap(), &doc);
            assert!(missing.is_empty(), "{}: keys missing from docs/logs.md: {missing:?}", path.display());
            seen += 1;
        }
    }
    assert!(seen >= 2);
}
