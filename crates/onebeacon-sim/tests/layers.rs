//! The layers of the workspace, read from the sources' paths (`use` trees expanded, and
//! paths written inline), test code left out:
//!
//! - the onboard crate (`onebeacon`) names nothing of the simulator;
//! - truth (`vehicles`, `acoustics`, `sensors`) names no configuration, world, engine,
//!   record or evaluation: only truth and the seeded random streams;
//! - the worlds name no vehicle's mind: not `onebeacon::guidance`, nor the controllers
//!   and behaviours of `onebeacon::vehicle`, nor the simulator's `helms` that build them;
//!   and build no navigator (the simulator's `factory` does);
//! - the engine names no world, record, configuration or controller factory;
//! - within each crate the top-level modules import each other without a cycle.
//!
//! `a_planted_violation_is_found` shows the checker failing on each kind of violation.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

/// One source file: its module path in its crate (`["world", "fleet"]`) and its text.
struct Source {
    module: Vec<String>,
    text: String,
}

/// Every `.rs` file under `dir`, with module paths relative to it.
fn sources(dir: &Path) -> Vec<Source> {
    let mut out = Vec::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        for entry in std::fs::read_dir(&d).expect("source directory reads") {
            let p = entry.expect("entry reads").path();
            if p.is_dir() {
                stack.push(p);
            } else if p.extension().is_some_and(|e| e == "rs") {
                let rel = p.strip_prefix(dir).expect("under its root");
                let mut module: Vec<String> = rel.iter().map(|c| c.to_string_lossy().into_owned()).collect();
                let last = module.pop().expect("a file name").trim_end_matches(".rs").to_string();
                if last != "mod" && last != "lib" && last != "main" {
                    module.push(last);
                }
                out.push(Source { module, text: std::fs::read_to_string(&p).expect("source reads") });
            }
        }
    }
    out
}

/// The text without its test module and comments.
fn code(text: &str) -> String {
    let text = text.split("#[cfg(test)]").next().unwrap_or("");
    text.lines().map(|l| l.split("//").next().unwrap_or("")).collect::<Vec<_>>().join("\n")
}

/// The paths of a `use` tree body (`a::b::{c, d::{e, f}}` -> a::b::c, a::b::d::e, a::b::d::f).
fn expand(tree: &str, prefix: &str, out: &mut Vec<String>) {
    let tree = tree.trim();
    if let Some(open) = tree.find('{') {
        let head = tree[..open].trim().trim_end_matches("::");
        // (a `use ` inside a string literal has no closing brace after its opening one)
        let inner = &tree[open + 1..tree.rfind('}').filter(|&c| c > open).unwrap_or(tree.len())];
        let prefix = if head.is_empty() { prefix.to_string() } else { format!("{prefix}{head}::") };
        let mut depth = 0;
        let mut start = 0;
        for (i, ch) in inner.char_indices() {
            match ch {
                '{' => depth += 1,
                '}' => depth -= 1,
                ',' if depth == 0 => {
                    expand(&inner[start..i], &prefix, out);
                    start = i + 1;
                }
                _ => {}
            }
        }
        expand(&inner[start..], &prefix, out);
    } else if !tree.is_empty() {
        let path = tree.split(" as ").next().unwrap_or(tree).trim();
        out.push(format!("{prefix}{path}"));
    }
}

/// Every path a file names, absolute: `crate::`, `super::` and `self::` resolved against
/// its module; other crates' paths as written.
fn paths(src: &Source) -> BTreeSet<String> {
    let code = code(&src.text);
    let mut raw = Vec::new();
    let mut rest = code.as_str();
    while let Some(i) = rest.find("use ") {
        let before = rest[..i].chars().last();
        let after = &rest[i + 4..];
        let end = after.find(';').unwrap_or(after.len());
        if before.is_none_or(|c| c.is_whitespace() || c == '{' || c == ';' || c == ')') {
            expand(&after[..end], "", &mut raw);
        }
        rest = &after[end.min(after.len())..];
    }
    // paths written inline
    for (i, _) in code.match_indices("::") {
        let start = code[..i].rfind(|c: char| !(c.is_alphanumeric() || c == '_' || c == ':')).map_or(0, |s| s + 1);
        let end =
            code[i..].find(|c: char| !(c.is_alphanumeric() || c == '_' || c == ':')).map_or(code.len(), |e| i + e);
        let p = &code[start..end];
        if p.starts_with("crate::") || p.starts_with("super::") || p.starts_with("onebeacon") {
            raw.push(p.to_string());
        }
    }
    raw.into_iter()
        .filter_map(|p| {
            let mut parts: Vec<&str> = p.split("::").filter(|s| !s.is_empty()).collect();
            let mut base: Vec<String> = src.module.clone();
            match parts.first().copied() {
                Some("crate") => {
                    base.clear();
                    parts.remove(0);
                }
                Some("super") => {
                    // a file's own module is its last component (mod.rs already dropped)
                    while parts.first() == Some(&"super") {
                        base.pop();
                        parts.remove(0);
                    }
                }
                Some("self") => {
                    parts.remove(0);
                }
                Some(c) if c.starts_with("onebeacon") => return Some(p.clone()),
                _ => return None,
            }
            base.extend(parts.iter().map(|s| s.to_string()));
            Some(format!("crate::{}", base.join("::")))
        })
        .collect()
}

/// A rule: files whose module starts with one of `within` must not name a path that
/// starts with one of `forbidden`.
struct Rule {
    name: &'static str,
    within: &'static [&'static str],
    forbidden: &'static [&'static str],
}

const SIM_RULES: &[Rule] = &[
    Rule {
        name: "truth imports configuration, a world, the engine, records or evaluation",
        within: &["vehicles", "acoustics", "sensors"],
        forbidden: &[
            "crate::scenario",
            "crate::replay",
            "crate::world",
            "crate::engine",
            "crate::run",
            "crate::helms",
            "crate::metrics",
            "crate::montecarlo",
            "crate::chain",
            "onebeacon::config",
        ],
    },
    Rule {
        name: "a world builds an estimator (the factory's job)",
        within: &["world"],
        forbidden: &[
            "crate::factory",
            "onebeacon::nav::GaussianTracker",
            "onebeacon::nav::IusblNavigator",
            "onebeacon::nav::ParticleTracker",
            "onebeacon::nav::PlanarNavigator",
            "onebeacon::nav::Range6DofNavigator",
            "onebeacon::nav::SingleBeaconNavigator",
            "onebeacon::nav::TrackingNavigator",
        ],
    },
    Rule {
        name: "a world imports a vehicle's guidance or autonomy",
        within: &["world"],
        forbidden: &[
            "onebeacon::guidance",
            "onebeacon::vehicle::autonomy",
            "onebeacon::vehicle::behaviours",
            "onebeacon::vehicle::bearing",
            "onebeacon::vehicle::fim",
            "crate::helms",
        ],
    },
    Rule {
        name: "the engine imports a world, records, configuration or controllers",
        within: &["engine"],
        forbidden: &["crate::world", "crate::run", "crate::scenario", "crate::helms", "onebeacon::guidance"],
    },
];

const ONBOARD_RULES: &[Rule] =
    &[Rule { name: "the onboard crate imports the simulator", within: &[""], forbidden: &["onebeacon_sim"] }];

/// The violations of `rules` in `files`: (rule, module, path).
fn violations(files: &[Source], rules: &[Rule]) -> Vec<(String, String, String)> {
    let mut out = Vec::new();
    for f in files {
        let module = f.module.join("::");
        for r in rules.iter().filter(|r| r.within.iter().any(|w| module.starts_with(w))) {
            for p in paths(f) {
                if r.forbidden.iter().any(|x| p == *x || p.starts_with(&format!("{x}::"))) {
                    out.push((r.name.to_string(), module.clone(), p));
                }
            }
        }
    }
    out
}

/// A cycle among the top-level modules of a crate, if any (as a path a -> b -> ... -> a).
fn cycle(files: &[Source]) -> Option<Vec<String>> {
    let mut graph: BTreeMap<String, BTreeSet<String>> = BTreeMap::new();
    for f in files {
        let Some(top) = f.module.first() else { continue };
        let edges = graph.entry(top.clone()).or_default();
        for p in paths(f) {
            if let Some(dep) = p.strip_prefix("crate::").and_then(|d| d.split("::").next())
                && dep != top
            {
                edges.insert(dep.to_string());
            }
        }
    }
    let modules: BTreeSet<String> = graph.keys().cloned().collect();
    // depth-first search with colours: an edge to a module on the stack closes a cycle
    fn visit(
        m: &str,
        graph: &BTreeMap<String, BTreeSet<String>>,
        modules: &BTreeSet<String>,
        stack: &mut Vec<String>,
        done: &mut BTreeSet<String>,
    ) -> Option<Vec<String>> {
        if let Some(i) = stack.iter().position(|s| s == m) {
            let mut c = stack[i..].to_vec();
            c.push(m.to_string());
            return Some(c);
        }
        if !done.insert(m.to_string()) {
            return None;
        }
        stack.push(m.to_string());
        for d in graph.get(m).into_iter().flatten().filter(|d| modules.contains(*d)) {
            if let Some(c) = visit(d, graph, modules, stack, done) {
                return Some(c);
            }
        }
        stack.pop();
        None
    }
    let mut done = BTreeSet::new();
    modules.iter().find_map(|m| visit(m, &graph, &modules, &mut Vec::new(), &mut done))
}

fn crate_sources(name: &str) -> Vec<Source> {
    sources(&root().join("crates").join(name).join("src"))
}

#[test]
fn the_layers_hold() {
    let sim = crate_sources("onebeacon-sim");
    let onboard = crate_sources("onebeacon");
    assert!(sim.len() > 30 && onboard.len() > 30, "the sources were found");
    let mut found = violations(&sim, SIM_RULES);
    found.extend(violations(&onboard, ONBOARD_RULES));
    assert!(found.is_empty(), "layer violations:\n{}", lines(&found));
    for name in ["onebeacon", "onebeacon-sim", "onebeacon-cli"] {
        let c = cycle(&crate_sources(name));
        assert!(c.is_none(), "{name}: import cycle {}", c.unwrap_or_default().join(" -> "));
    }
}

fn lines(found: &[(String, String, String)]) -> String {
    found.iter().map(|(r, m, p)| format!("  {r}: {m} names {p}")).collect::<Vec<_>>().join("\n")
}

/// Each kind of violation, planted in a copy of the sources, is found; and the reading
/// of paths resolves grouped, renamed, `super::` and inline paths.
#[test]
fn a_planted_violation_is_found() {
    let plant = |module: &[&str], text: &str| Source {
        module: module.iter().map(|s| s.to_string()).collect(),
        text: text.to_string(),
    };
    let mut sim = crate_sources("onebeacon-sim");
    sim.push(plant(&["world", "planted"], "use onebeacon::{nav::Kind, vehicle::{Situation, fim::FimGuidance as G}};"));
    sim.push(plant(&["world", "planted2"], "fn t() { let _ = onebeacon::nav::ParticleTracker::new; }"));
    sim.push(plant(&["vehicles", "planted"], "fn f() { let _ = super::super::scenario::Host::Log; }"));
    sim.push(plant(&["engine"], "fn g() -> crate::run::Estimate { todo!() }"));
    sim.push(plant(&["sensors", "planted"], "use onebeacon::config::stream::Initial;"));
    let found = violations(&sim, SIM_RULES);
    let named: BTreeSet<&str> = found.iter().map(|(_, _, p)| p.as_str()).collect();
    assert_eq!(
        named,
        BTreeSet::from([
            "onebeacon::vehicle::fim::FimGuidance",
            "onebeacon::nav::ParticleTracker::new",
            "crate::scenario::Host::Log",
            "crate::run::Estimate",
            "onebeacon::config::stream::Initial"
        ]),
        "{}",
        lines(&found)
    );
    // a cycle: truth naming the engine, which names truth's autopilot commands
    let mut sim = crate_sources("onebeacon-sim");
    assert!(cycle(&sim).is_none());
    sim.push(plant(&["vehicles", "planted"], "use crate::engine::VehicleTruth;"));
    let c = cycle(&sim).expect("the planted cycle is found");
    assert!(c.contains(&"vehicles".to_string()) && c.contains(&"engine".to_string()), "{c:?}");
    // and what a test module names does not count
    let onboard = vec![plant(&["nav"], "use crate::geo;\n#[cfg(test)]\nmod tests { use onebeacon_sim::run; }")];
    assert!(violations(&onboard, ONBOARD_RULES).is_empty());
}
