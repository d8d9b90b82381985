//! The layers of the workspace, read from the sources' paths (`use` trees expanded, and
//! paths written inline), test code left out:
//!
//! - the onboard crate (`onebeacon`) names nothing of the simulator;
//! - truth (`vehicles`, `acoustics`, `sensors`) names no configuration, world, engine,
//!   record or evaluation: only truth and the seeded random streams;
//! - the worlds name no vehicle's mind: not `onebeacon::guidance`, nor the controllers
//!   and behaviours of `onebeacon::vehicle`, nor the simulator's `computers` that
//!   describe them; and build no navigator (the simulator's `computers` and `factory` do);
//! - the engine names no world, record, configuration or controller factory;
//! - within each crate the top-level modules import each other without a cycle.
//!
//! `a_planted_violation_is_found` shows the checker failing on each kind of violation.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

/// One source file: its module path in its crate (`["world", "fleet"]`) and its code
/// (see [`code`]).
struct Source {
    module: Vec<String>,
    code: String,
    /// The modules it declares (`mod log;`), which its `use` paths may start with.
    children: BTreeSet<String>,
}

impl Source {
    fn new(module: Vec<String>, text: &str) -> Self {
        let code = code(text);
        let children = code
            .split(';')
            .filter_map(|s| {
                let w: Vec<&str> = s.split_whitespace().collect();
                let i = w.iter().rposition(|x| *x == "mod")?;
                (i + 2 == w.len()).then(|| w[i + 1].to_string())
            })
            .collect();
        Self { module, code, children }
    }
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
                out.push(Source::new(module, &std::fs::read_to_string(&p).expect("source reads")));
            }
        }
    }
    test_modules_left_out(out)
}

/// `files` without the test-only ones: a file whose parent declares it only under
/// `#[cfg(test)]` (`#[cfg(test)] mod burst_tests;`), and the files under it.
fn test_modules_left_out(mut files: Vec<Source>) -> Vec<Source> {
    files.sort_by_key(|f| f.module.len());
    let mut kept: Vec<Source> = Vec::new();
    for f in files {
        let declared = match f.module.split_last() {
            None => true,
            Some((name, parent)) => kept.iter().any(|p| p.module == parent && p.children.contains(name)),
        };
        if declared {
            kept.push(f);
        }
    }
    kept
}

/// The text without comments, string and character literals' contents (their quotes
/// kept) and test-only items: each `#[cfg(test)]` item to its closing brace or its `;`.
fn code(text: &str) -> String {
    let bare = blank_literals(text);
    let mut out = String::with_capacity(bare.len());
    let mut rest = bare.as_str();
    while let Some(i) = rest.find("#[cfg(test)]") {
        out.push_str(&rest[..i]);
        let item = &rest[i..];
        // the item ends at its first `;` outside braces, or at the brace closing its body
        let (mut depth, mut end) = (0usize, item.len());
        for (j, ch) in item.char_indices() {
            match ch {
                '{' => depth += 1,
                '}' if depth > 0 => {
                    depth -= 1;
                    if depth == 0 {
                        end = j + 1;
                        break;
                    }
                }
                ';' if depth == 0 => {
                    end = j + 1;
                    break;
                }
                _ => {}
            }
        }
        // keep the line count: what is left out becomes its newlines
        out.extend(item[..end].chars().filter(|&c| c == '\n'));
        rest = &item[end..];
    }
    out.push_str(rest);
    out
}

/// `text` with comments removed and the insides of string and character literals
/// (raw strings too) blanked, newlines kept.
fn blank_literals(text: &str) -> String {
    let b: Vec<char> = text.chars().collect();
    let mut out = String::with_capacity(text.len());
    let mut i = 0;
    let at = |i: usize| b.get(i).copied().unwrap_or('\0');
    while i < b.len() {
        let c = b[i];
        let word_before = i > 0 && (b[i - 1].is_alphanumeric() || b[i - 1] == '_');
        if c == '/' && at(i + 1) == '/' {
            while i < b.len() && b[i] != '\n' {
                i += 1;
            }
        } else if c == '/' && at(i + 1) == '*' {
            let mut depth = 0;
            while i < b.len() {
                if b[i] == '/' && at(i + 1) == '*' {
                    depth += 1;
                    i += 2;
                } else if b[i] == '*' && at(i + 1) == '/' {
                    depth -= 1;
                    i += 2;
                    if depth == 0 {
                        break;
                    }
                } else {
                    if b[i] == '\n' {
                        out.push('\n');
                    }
                    i += 1;
                }
            }
        } else if c == 'r' && !word_before && (at(i + 1) == '"' || (at(i + 1) == '#' && matches!(at(i + 2), '#' | '"')))
        {
            // a raw string: r"…", r#"…"#, …
            let mut j = i + 1;
            let mut hashes = 0;
            while at(j) == '#' {
                hashes += 1;
                j += 1;
            }
            j += 1;
            while j < b.len() && !(b[j] == '"' && (1..=hashes).all(|h| at(j + h) == '#')) {
                if b[j] == '\n' {
                    out.push('\n');
                }
                j += 1;
            }
            out.push_str("\"\"");
            i = j + 1 + hashes;
        } else if c == '"' {
            let mut j = i + 1;
            while j < b.len() && b[j] != '"' {
                if b[j] == '\\' {
                    j += 1;
                }
                if at(j) == '\n' {
                    out.push('\n');
                }
                j += 1;
            }
            out.push_str("\"\"");
            i = j + 1;
        } else if c == '\'' && (at(i + 1) == '\\' || at(i + 2) == '\'') {
            // a character literal (a lifetime has no closing quote after one character)
            let mut j = i + 1;
            if at(j) == '\\' {
                j += 1;
            }
            j += 1;
            while j < b.len() && b[j] != '\'' {
                j += 1;
            }
            out.push_str("' '");
            i = j + 1;
        } else {
            out.push(c);
            i += 1;
        }
    }
    out
}

/// The paths of a `use` tree body with the name each brings into scope
/// (`a::b::{c, d::{e as f}}` -> (a::b::c, c), (a::b::d::e, f)).
fn expand(tree: &str, prefix: &str, out: &mut Vec<(String, String)>) {
    let tree = tree.trim();
    if let Some(open) = tree.find('{') {
        let head = tree[..open].trim().trim_end_matches("::");
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
        let mut parts = tree.split(" as ");
        let path = format!("{prefix}{}", parts.next().unwrap_or(tree).trim());
        let name = parts.next().map(str::trim).unwrap_or_else(|| path.rsplit("::").next().unwrap_or(""));
        out.push((path.clone(), name.to_string()));
    }
}

/// The `use` declarations of `code`: (path, the name it brings into scope).
fn uses(code: &str) -> Vec<(String, String)> {
    let mut out = Vec::new();
    let mut rest = code;
    while let Some(i) = rest.find("use ") {
        let before = rest[..i].chars().last();
        let after = &rest[i + 4..];
        let end = after.find(';').unwrap_or(after.len());
        if before.is_none_or(|c| c.is_whitespace() || c == '{' || c == ';' || c == ')') {
            expand(&after[..end], "", &mut out);
        }
        rest = &after[end.min(after.len())..];
    }
    out
}

/// `p` made absolute against `module`: `crate::`, `super::` and `self::` resolved;
/// other crates' paths (`onebeacon…`) as written; None for anything else.
fn absolute(p: &str, src: &Source) -> Option<String> {
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
        Some(c) if c.starts_with("onebeacon") => return Some(parts.join("::")),
        Some(c) if src.children.contains(c) => {}
        _ => return None,
    }
    base.extend(parts.iter().map(|s| s.to_string()));
    Some(format!("crate::{}", base.join("::")))
}

/// Every path a file names, absolute: its `use` trees expanded, and the paths written
/// inline, whether they start at a crate (`crate::`, `super::`, `onebeacon::…`) or at a
/// name a `use` brought in (`single_beacon::boxed` after `use onebeacon::nav::single_beacon`).
fn paths(src: &Source) -> BTreeSet<String> {
    let imported = uses(&src.code);
    let mut out: BTreeSet<String> = imported.iter().filter_map(|(p, _)| absolute(p, src)).collect();
    let names: BTreeMap<&str, String> = imported
        .iter()
        .filter_map(|(p, n)| Some((n.as_str(), absolute(p, src)?)))
        .filter(|(n, _)| *n != "*" && *n != "self")
        .collect();
    let code = &src.code;
    let word = |c: char| c.is_alphanumeric() || c == '_' || c == ':';
    for (i, _) in code.match_indices("::") {
        let start = code[..i].rfind(|c: char| !word(c)).map_or(0, |s| s + 1);
        let end = code[i..].find(|c: char| !word(c)).map_or(code.len(), |e| i + e);
        let p = &code[start..end];
        let first = p.split("::").next().unwrap_or("");
        if let Some(a) = absolute(p, src) {
            out.insert(a);
        } else if let Some(full) = names.get(first) {
            out.insert(format!("{full}{}", &p[first.len()..]));
        }
    }
    out
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
            "crate::computers",
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
            "crate::computers",
            "onebeacon::nav::GaussianTracker",
            "onebeacon::nav::IusblNavigator",
            "onebeacon::nav::ParticleTracker",
            "onebeacon::nav::PlanarNavigator",
            "onebeacon::nav::Range6DofNavigator",
            "onebeacon::nav::SingleBeaconNavigator",
            "onebeacon::nav::TrackingNavigator",
            "onebeacon::nav::single_beacon::boxed",
            "onebeacon::nav::range_6dof::boxed",
            "onebeacon::nav::planar::builder",
            "onebeacon::config::builder",
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
            "crate::computers",
        ],
    },
    Rule {
        name: "the engine imports a world, records, configuration or controllers",
        within: &["engine"],
        forbidden: &["crate::world", "crate::run", "crate::scenario", "crate::computers", "onebeacon::guidance"],
    },
];

const ONBOARD_RULES: &[Rule] =
    &[Rule { name: "the onboard crate imports the simulator", within: &[""], forbidden: &["onebeacon_sim"] }];

/// What a rule's forbidden entry matches in a path: the entry and everything under it;
/// for a type (`onebeacon::nav::IusblNavigator`), the type under any path of its crate
/// (`onebeacon::nav::iusbl::IusblNavigator`); for a module of the onboard crate, the
/// types defined there and nowhere else under any path (its re-exports), and a glob
/// import of it or of a module above it.
fn forbids(entry: &str, path: &str, only_in: &BTreeMap<String, BTreeSet<String>>) -> bool {
    let segments: Vec<&str> = path.split("::").collect();
    let root = entry.split("::").next().unwrap_or("");
    let last = entry.rsplit("::").next().unwrap_or("");
    let under_root = segments.first() == Some(&root);
    path == entry
        || path.starts_with(&format!("{entry}::"))
        || path.strip_suffix("::*").is_some_and(|g| entry == g || entry.starts_with(&format!("{g}::")))
        || (under_root && last.starts_with(char::is_uppercase) && segments.contains(&last))
        || (under_root && only_in.get(entry).is_some_and(|types| segments.iter().any(|s| types.contains(*s))))
}

/// For each module of the onboard crate (`onebeacon::vehicle::fim`), the public types
/// defined in it (or below it) and in no other module.
fn types_only_in(onboard: &[Source]) -> BTreeMap<String, BTreeSet<String>> {
    let mut defined: BTreeMap<String, BTreeSet<String>> = BTreeMap::new();
    for f in onboard {
        let w: Vec<&str> = f.code.split_whitespace().collect();
        for pair in w.windows(3) {
            if pair[0] == "pub" && matches!(pair[1], "struct" | "enum" | "trait" | "type") {
                let name: String = pair[2].chars().take_while(|c| c.is_alphanumeric() || *c == '_').collect();
                defined.entry(name).or_default().insert(f.module.join("::"));
            }
        }
    }
    let mut out: BTreeMap<String, BTreeSet<String>> = BTreeMap::new();
    for (name, modules) in defined {
        let (Some(first), Some(last)) = (modules.first(), modules.last()) else { continue };
        if first != last {
            continue;
        }
        // every module it is in, and each module above
        let parts: Vec<&str> = first.split("::").collect();
        for n in 1..=parts.len() {
            out.entry(format!("onebeacon::{}", parts[..n].join("::"))).or_default().insert(name.clone());
        }
    }
    out
}

/// The violations of `rules` in `files`: (rule, module, path); `onboard` tells which
/// types each onboard module defines.
fn violations(files: &[Source], rules: &[Rule], onboard: &[Source]) -> Vec<(String, String, String)> {
    let only_in = types_only_in(onboard);
    let mut out = Vec::new();
    for f in files {
        let module = f.module.join("::");
        for r in rules.iter().filter(|r| r.within.iter().any(|w| module.starts_with(w))) {
            for p in paths(f) {
                if r.forbidden.iter().any(|x| forbids(x, &p, &only_in)) {
                    out.push((r.name.to_string(), module.clone(), p));
                }
            }
        }
    }
    out
}

/// The import loops of a crate: in each folder (the crate's root included), a cycle
/// among the modules it holds, each with the files below it, if any (as `folder: a -> b
/// -> a`). A path to a name the folder's own file re-exports counts as a path to the
/// module that defines it.
fn loops(files: &[Source]) -> Vec<String> {
    let folders: BTreeSet<Vec<String>> =
        files.iter().flat_map(|f| (0..f.module.len()).map(|n| f.module[..n].to_vec())).collect();
    let mut out = Vec::new();
    for folder in folders {
        let depth = folder.len();
        let prefix = |m: &[String]| m.len() > depth && m[..depth] == folder[..];
        let nodes: BTreeSet<&str> =
            files.iter().filter(|f| prefix(&f.module)).map(|f| f.module[depth].as_str()).collect();
        let own = |s: &str| format!("crate::{}", folder.iter().map(|x| format!("{x}::")).collect::<String>() + s);
        // the names the folder's own file brings in from its modules
        let mut reexports: BTreeMap<String, &str> = BTreeMap::new();
        for f in files.iter().filter(|f| f.module == folder) {
            for (path, name) in uses(&f.code) {
                let Some(a) = absolute(&path, f) else { continue };
                if let Some(&m) = nodes.iter().find(|m| a.starts_with(&own(&format!("{m}::")))) {
                    reexports.insert(own(&name), m);
                }
            }
        }
        let mut graph: BTreeMap<&str, BTreeSet<&str>> = BTreeMap::new();
        for f in files.iter().filter(|f| prefix(&f.module)) {
            let from = f.module[depth].as_str();
            let edges = graph.entry(from).or_default();
            for p in paths(f) {
                let to = nodes.iter().find(|m| p == own(m) || p.starts_with(&own(&format!("{m}::")))).copied().or_else(
                    || reexports.iter().find(|(n, _)| p == **n || p.starts_with(&format!("{n}::"))).map(|(_, m)| *m),
                );
                if let Some(to) = to.filter(|t| *t != from) {
                    edges.insert(to);
                }
            }
        }
        if let Some(c) = cycle(&graph) {
            out.push(format!(
                "{}: {}",
                if folder.is_empty() { "crate".into() } else { folder.join("::") },
                c.join(" -> ")
            ));
        }
    }
    out
}

/// A cycle in `graph`, if any (as a path a -> b -> ... -> a).
fn cycle(graph: &BTreeMap<&str, BTreeSet<&str>>) -> Option<Vec<String>> {
    // depth-first search: an edge to a module on the stack closes a cycle
    fn visit<'a>(
        m: &'a str,
        graph: &BTreeMap<&'a str, BTreeSet<&'a str>>,
        stack: &mut Vec<&'a str>,
        done: &mut BTreeSet<&'a str>,
    ) -> Option<Vec<String>> {
        if let Some(i) = stack.iter().position(|s| *s == m) {
            let mut c: Vec<String> = stack[i..].iter().map(|s| s.to_string()).collect();
            c.push(m.to_string());
            return Some(c);
        }
        if !done.insert(m) {
            return None;
        }
        stack.push(m);
        for d in graph.get(m).into_iter().flatten() {
            if let Some(c) = visit(d, graph, stack, done) {
                return Some(c);
            }
        }
        stack.pop();
        None
    }
    let mut done = BTreeSet::new();
    graph.keys().find_map(|m| visit(m, graph, &mut Vec::new(), &mut done))
}

fn crate_sources(name: &str) -> Vec<Source> {
    sources(&root().join("crates").join(name).join("src"))
}

#[test]
fn the_layers_hold() {
    let sim = crate_sources("onebeacon-sim");
    let onboard = crate_sources("onebeacon");
    assert!(sim.len() > 30 && onboard.len() > 30, "the sources were found");
    let mut found = violations(&sim, SIM_RULES, &onboard);
    found.extend(violations(&onboard, ONBOARD_RULES, &onboard));
    assert!(found.is_empty(), "layer violations:\n{}", lines(&found));
    let l: Vec<String> = ["onebeacon", "onebeacon-sim", "onebeacon-cli", "onebeacon-py"]
        .iter()
        .flat_map(|name| loops(&crate_sources(name)).into_iter().map(move |l| format!("{name}: {l}")))
        .collect();
    assert!(l.is_empty(), "import loops:\n  {}", l.join("\n  "));
}

fn lines(found: &[(String, String, String)]) -> String {
    found.iter().map(|(r, m, p)| format!("  {r}: {m} names {p}")).collect::<Vec<_>>().join("\n")
}

fn plant(module: &[&str], text: &str) -> Source {
    Source::new(module.iter().map(|s| s.to_string()).collect(), text)
}

/// What the planted files among the sources name against the simulator's rules.
fn planted(files: Vec<Source>) -> BTreeSet<String> {
    let (mut sim, onboard) = (crate_sources("onebeacon-sim"), crate_sources("onebeacon"));
    sim.extend(files);
    violations(&sim, SIM_RULES, &onboard).into_iter().map(|(_, _, p)| p).collect()
}

/// Each kind of violation, planted in a copy of the sources, is found; and the reading
/// of paths resolves grouped, renamed, `super::` and inline paths.
#[test]
fn a_planted_violation_is_found() {
    let found = planted(vec![
        plant(&["world", "planted"], "use onebeacon::{nav::Kind, vehicle::{Situation, fim::FimGuidance as G}};"),
        plant(&["world", "planted2"], "fn t() { let _ = onebeacon::nav::ParticleTracker::new; }"),
        plant(&["vehicles", "planted"], "fn f() { let _ = super::super::scenario::Host::Log; }"),
        plant(&["engine"], "fn g() -> crate::run::Estimate { todo!() }"),
        plant(&["sensors", "planted"], "use onebeacon::config::stream::Initial;"),
    ]);
    let expected = [
        "onebeacon::vehicle::fim::FimGuidance",
        "onebeacon::nav::ParticleTracker::new",
        "crate::scenario::Host::Log",
        "crate::run::Estimate",
        "onebeacon::config::stream::Initial",
    ];
    assert_eq!(found, expected.iter().map(|s| s.to_string()).collect());
    // a cycle: truth naming the engine, which names truth's autopilot commands
    let mut sim = crate_sources("onebeacon-sim");
    assert!(loops(&sim).is_empty());
    sim.push(plant(&["vehicles", "planted"], "use crate::engine::VehicleTruth;"));
    let l = loops(&sim);
    assert!(
        l.len() == 1 && l[0].starts_with("crate: ") && l[0].contains("vehicles") && l[0].contains("engine"),
        "{l:?}"
    );
    // and what a test module names does not count
    let onboard = vec![plant(&["nav"], "use crate::geo;\n#[cfg(test)]\nmod tests { use onebeacon_sim::run; }")];
    assert!(violations(&onboard, ONBOARD_RULES, &onboard).is_empty());
}

/// The blind spots of the first checker (issue 54, item 8), each planted: code after a
/// test-only item, a type named by its full path, a name brought in by a `use` and
/// written inline, a re-export, a glob; and a loop between two files of one folder,
/// directly and through the folder's re-export.
#[test]
fn the_former_blind_spots_are_seen() {
    let after_test_item = "#[cfg(test)]\nfn helper() { let s = \"}\"; }\n\nuse onebeacon::guidance::FimPlanner;";
    let found = planted(vec![
        plant(&["world", "p1"], after_test_item),
        plant(&["world", "p2"], "fn f() { onebeacon::nav::single_beacon::SingleBeaconNavigator::new(); }"),
        plant(&["world", "p3"], "use onebeacon::nav::single_beacon;\nfn f() { single_beacon::boxed(); }"),
        plant(&["world", "p4"], "use onebeacon::nav;\nfn f() { nav::planar::builder(); }"),
        plant(&["world", "p5"], "fn f() { let _ = onebeacon::vehicle::FimGuidanceConfig::default(); }"),
        plant(&["world", "p6"], "use onebeacon::vehicle::*;"),
    ]);
    let expected = [
        "onebeacon::guidance::FimPlanner",
        "onebeacon::nav::single_beacon::SingleBeaconNavigator::new",
        "onebeacon::nav::single_beacon::boxed",
        "onebeacon::nav::planar::builder",
        "onebeacon::vehicle::FimGuidanceConfig::default",
        "onebeacon::vehicle::*",
    ];
    assert_eq!(found, expected.iter().map(|s| s.to_string()).collect());
    // a `use` in a string or a comment names nothing
    let quiet = planted(vec![plant(
        &["world", "p7"],
        "const S: &str = \"use onebeacon::guidance;\"; // use onebeacon::guidance;\n",
    )]);
    assert!(quiet.is_empty(), "{quiet:?}");
    // two files of one folder naming each other, directly or through the folder's
    // re-export (`super::Name`)
    let folder = |a: &str, b: &str| {
        let mut sim = crate_sources("onebeacon-sim");
        sim.push(plant(&["chart"], "mod a;\nmod b;\npub use a::Alpha;"));
        sim.push(plant(&["chart", "a"], a));
        sim.push(plant(&["chart", "b"], b));
        loops(&sim)
    };
    assert_eq!(folder("pub struct Alpha; use super::b::Beta;", "pub struct Beta;"), Vec::<String>::new());
    assert_eq!(folder("pub struct Alpha; use super::b::Beta;", "use super::a::Alpha;"), ["chart: a -> b -> a"]);
    assert_eq!(folder("pub struct Alpha; use super::b::Beta;", "fn f(_: super::Alpha) {}"), ["chart: a -> b -> a"]);
    // a file declared under `#[cfg(test)]` is test code, and so is what it declares; a
    // file its parent declares, or no file declares, is not left out
    let kept = test_modules_left_out(vec![
        plant(&[], "mod chart;"),
        plant(&["chart"], "mod a;\n#[cfg(test)]\nmod t;"),
        plant(&["chart", "a"], ""),
        plant(&["chart", "t"], "mod u;"),
        plant(&["chart", "t", "u"], ""),
    ]);
    let modules: Vec<String> = kept.iter().map(|f| f.module.join("::")).collect();
    assert_eq!(modules, ["", "chart", "chart::a"]);
}
