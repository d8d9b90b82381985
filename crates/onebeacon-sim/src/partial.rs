//! The partial result of one share of a sharded Monte Carlo ([`crate::montecarlo::Shard`]),
//! as a JSON file, and the merge of the partials of every share into the result the
//! unsharded sweep gives, bit for bit.
//!
//! A partial holds what the aggregation needs of each of its runs (metrics and acoustic
//! information) with every float as its IEEE-754 bit pattern, so that nothing is
//! rounded on the way (JSON numbers could not carry a diverged run's infinity either),
//! and the scenario as canonical TOML ([`Scenario::to_toml`]), so that partials of the
//! same scenario agree whether it was named as a built-in or as a file.

use crate::metrics::RunMetrics;
use crate::montecarlo::{AggregateError, McResult, RunSummary, Shard, aggregate};
use crate::scenario::{Scenario, ScenarioError, parse};
use nalgebra::DMatrix;
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;

/// The `format` field of a partial.
pub const FORMAT: &str = "onebeacon-mc-partial/1";
/// The version of onebeacon that writes and merges partials.
pub const VERSION: &str = env!("CARGO_PKG_VERSION");

/// One share's results: what `onebeacon mc --shard I/N` writes.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Partial {
    pub format: String,
    pub version: String,
    /// The scenario's name, for messages.
    pub scenario: String,
    /// The scenario, canonical TOML: what the partial's runs simulated.
    pub scenario_toml: String,
    pub runs: usize,
    pub seed: u64,
    pub shard: usize,
    pub shards: usize,
    /// Seconds the share took to compute, on its machine.
    pub wall_s: f64,
    pub results: Vec<Record>,
}

/// One run of one cell, floats as bit patterns.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Record {
    pub cell: usize,
    pub run: u64,
    /// Per track: [`RunMetrics::to_words`].
    pub metrics: Vec<Vec<u64>>,
    /// (vehicle, step, rows, the matrix's entries column by column).
    pub information: Vec<(usize, usize, usize, Vec<u64>)>,
}

/// Why partials cannot be read or merged. Each message is one line naming the files.
#[derive(Debug, thiserror::Error)]
pub enum MergeError {
    #[error("no partials given: name directories written by `mc --shard I/N --out DIR`, or partial files")]
    Empty,
    #[error("{path}: cannot read: {message}")]
    Io { path: String, message: String },
    #[error("{path}: no partial-*-of-*.json in this directory (written by `{by} --shard I/N --out DIR`)")]
    NoneInDir { path: String, by: &'static str },
    #[error("{path}: not an onebeacon {by} partial: {message}")]
    NotPartial { path: String, by: &'static str, message: String },
    #[error("{path}: the partial's scenario does not parse: {source}")]
    Scenario { path: String, source: ScenarioError },
    #[error(
        "{path}: shard {shard} should hold {expected} (cell, run) pairs, it holds {got}: the file is incomplete or edited"
    )]
    Incomplete { path: String, shard: Shard, expected: usize, got: usize },
    #[error("{first} and {second} differ in {what}: {a} against {b}; merge only the shares of one `--shard` campaign")]
    Mismatch { first: String, second: String, what: &'static str, a: String, b: String },
    #[error("{path} was written by onebeacon {theirs}; this is {ours}: merge with the version that ran the shards")]
    Version { path: String, theirs: String, ours: String },
    #[error("shard {shard} is given twice: {first} and {second}")]
    Duplicate { shard: Shard, first: String, second: String },
    #[error("missing shard(s) {missing} of {count} (have {have})")]
    Missing { missing: String, count: usize, have: String },
    #[error(
        "{path}: {what} {value} does not fit the campaign ({cells} cell(s) x {runs} runs = {pairs} (cell, run) pairs): \
         the file is corrupt or edited"
    )]
    Count { path: String, what: &'static str, value: usize, cells: usize, runs: usize, pairs: String },
    #[error("{0}")]
    Aggregate(#[from] AggregateError),
    #[error("{0}")]
    Budget(#[from] crate::budget::BudgetError),
}

/// Bytes that reading and merging a partial holds per byte of its file, at most (the
/// parsed JSON and the typed records side by side).
const BYTES_PER_FILE_BYTE: f64 = 8.0;

impl Partial {
    /// The partial of `shard` from its summaries.
    pub fn new(
        scenario: &Scenario,
        runs: usize,
        seed: u64,
        shard: Shard,
        wall_s: f64,
        summaries: &[RunSummary],
    ) -> Partial {
        let results = summaries
            .iter()
            .map(|s| Record {
                cell: s.cell,
                run: s.run,
                metrics: s.metrics.iter().map(|m| m.to_words().to_vec()).collect(),
                information: s
                    .information
                    .iter()
                    .map(|(v, k, m)| (*v, *k, m.nrows(), m.iter().map(|x| x.to_bits()).collect()))
                    .collect(),
            })
            .collect();
        Partial {
            format: FORMAT.to_string(),
            version: VERSION.to_string(),
            scenario: scenario.name().to_string(),
            scenario_toml: scenario.to_toml(),
            runs,
            seed,
            shard: shard.index,
            shards: shard.count,
            wall_s,
            results,
        }
    }

    /// The partial as JSON.
    pub fn to_json(&self) -> String {
        serde_json::to_string(self).expect("serialisable")
    }

    /// Reads a partial from `text` (`path` names it in errors), with its shape checked.
    pub fn from_json(text: &str, path: &str) -> Result<Partial, MergeError> {
        let p: Partial = parse_partial(text, path, "mc", FORMAT, |p: &Partial| p.shard_of())?;
        let not = |message: String| MergeError::NotPartial { path: path.to_string(), by: "mc", message };
        for r in &p.results {
            if r.metrics.iter().any(|m| m.len() != RunMetrics::WORDS)
                || r.information.iter().any(|(_, _, n, e)| n.checked_mul(*n) != Some(e.len()))
            {
                return Err(not(format!("run {} of cell {} has malformed numbers", r.run, r.cell)));
            }
        }
        Ok(p)
    }

    fn shard_of(&self) -> Shard {
        Shard { index: self.shard, count: self.shards }
    }

    fn summaries(self) -> Vec<RunSummary> {
        self.results
            .into_iter()
            .map(|r| RunSummary {
                cell: r.cell,
                run: r.run,
                metrics: r.metrics.iter().map(|w| RunMetrics::from_words(w)).collect(),
                information: r
                    .information
                    .into_iter()
                    .map(|(v, k, n, e)| (v, k, DMatrix::from_iterator(n, n, e.into_iter().map(f64::from_bits))))
                    .collect(),
            })
            .collect()
    }
}

/// The merged sweep: the scenario the partials ran and its result.
#[derive(Debug, Clone)]
pub struct Merged {
    pub scenario: Scenario,
    pub result: McResult,
    /// The shares' compute times added up, s.
    pub wall_s: f64,
}

/// Merges partials (each with the path that names it in errors) into the result of the
/// unsharded sweep. Refuses partials of different scenarios, seeds, runs, shard counts or
/// versions, counts that do not fit the campaign, and missing or duplicate shares, with
/// one line each; every count is checked before anything is allocated by it.
pub fn merge(partials: Vec<(String, Partial)>) -> Result<Merged, MergeError> {
    let Some((first_path, first)) = partials.first() else { return Err(MergeError::Empty) };
    let scenario = parse(&first.scenario_toml, &first.scenario)
        .map_err(|source| MergeError::Scenario { path: first_path.clone(), source })?;
    let (runs, seed, shards) = (first.runs, first.seed, first.shards);
    let cells = scenario.cells().len();
    let product = cells.checked_mul(runs);
    let count = |what, value| MergeError::Count {
        path: first_path.clone(),
        what,
        value,
        cells,
        runs,
        pairs: product.map_or("too many".into(), |p| p.to_string()),
    };
    // nothing is allocated by `pairs` before every share is found to hold its pairs
    let pairs = match product {
        Some(p) if runs > 0 => p,
        _ => return Err(count("runs", runs)),
    };
    if shards > pairs {
        return Err(count("shards", shards));
    }
    for (path, p) in &partials {
        if p.scenario_toml != first.scenario_toml {
            let (a, b) = (format!("`{}`", first.scenario), format!("`{}`", p.scenario));
            let what = if a == b { "the scenario's keys (same name, edited in between)" } else { "scenario" };
            let (first, second) = (first_path.clone(), path.clone());
            return Err(MergeError::Mismatch { first, second, what, a, b });
        }
    }
    let shares: Vec<Share> = partials
        .iter()
        .map(|(path, p)| Share {
            path,
            version: &p.version,
            seed: p.seed,
            runs: p.runs,
            shard: p.shard_of(),
            results: p.results.len(),
        })
        .collect();
    check_shares(&shares, pairs)?;
    let mut summaries = Vec::with_capacity(pairs);
    let mut wall_s = 0.0;
    for (_, p) in partials {
        wall_s += p.wall_s;
        summaries.extend(p.summaries());
    }
    let result = aggregate(&scenario, runs, seed, summaries)?;
    Ok(Merged { scenario, result, wall_s })
}

/// The file name of a share's partial: `partial-I-of-N.json`.
pub fn file_name(shard: Shard) -> String {
    format!("partial-{}-of-{}.json", shard.index, shard.count)
}

/// A partial's JSON `text` (`path` names it in errors) read as a `T` whose `format` field
/// is `format` and whose shard (`shard_of`) is I/N with I < N; `by` names the command that
/// writes it.
pub(crate) fn parse_partial<T: serde::de::DeserializeOwned>(
    text: &str,
    path: &str,
    by: &'static str,
    format: &str,
    shard_of: impl Fn(&T) -> Shard,
) -> Result<T, MergeError> {
    let not = |message: String| MergeError::NotPartial { path: path.to_string(), by, message };
    let head: serde_json::Value = serde_json::from_str(text).map_err(|e| not(e.to_string()))?;
    match head.get("format").and_then(|f| f.as_str()) {
        Some(f) if f == format => {}
        Some(other) => return Err(not(format!("format `{other}`; this version reads `{format}`"))),
        None => return Err(not("no `format` field".into())),
    }
    let p: T = serde_json::from_value(head).map_err(|e| not(e.to_string()))?;
    let shard = shard_of(&p);
    if shard.count == 0 || shard.index >= shard.count {
        return Err(not(format!("shard {}/{} is not I/N with I < N", shard.index, shard.count)));
    }
    Ok(p)
}

/// What a share of a campaign says of the campaign (`mc --shard` or `twin --shard`).
pub(crate) struct Share<'a> {
    pub path: &'a str,
    pub version: &'a str,
    pub seed: u64,
    pub runs: usize,
    pub shard: Shard,
    /// How many results the share holds.
    pub results: usize,
}

/// Checks that `shares` are every share of one campaign of `pairs` results, once each:
/// the version of onebeacon, the seed, the runs and the shard count of the first, each
/// with the count of results its shard holds.
pub(crate) fn check_shares(shares: &[Share], pairs: usize) -> Result<(), MergeError> {
    let Some(first) = shares.first() else { return Err(MergeError::Empty) };
    let (runs, seed, shards) = (first.runs, first.seed, first.shard.count);
    let mut by_shard: BTreeMap<usize, String> = BTreeMap::new();
    for s in shares {
        if s.version != VERSION {
            return Err(MergeError::Version { path: s.path.into(), theirs: s.version.into(), ours: VERSION.into() });
        }
        let mismatch = |what, a: String, b: String| MergeError::Mismatch {
            first: first.path.into(),
            second: s.path.into(),
            what,
            a,
            b,
        };
        if s.seed != seed {
            return Err(mismatch("seed", seed.to_string(), s.seed.to_string()));
        }
        if s.runs != runs {
            return Err(mismatch("runs per cell", runs.to_string(), s.runs.to_string()));
        }
        if s.shard.count != shards {
            return Err(mismatch("shard count", shards.to_string(), s.shard.count.to_string()));
        }
        let expected = s.shard.len(pairs);
        if s.results != expected {
            return Err(MergeError::Incomplete { path: s.path.into(), shard: s.shard, expected, got: s.results });
        }
        if let Some(earlier) = by_shard.insert(s.shard.index, s.path.into()) {
            return Err(MergeError::Duplicate { shard: s.shard, first: earlier, second: s.path.into() });
        }
    }
    if by_shard.len() < shards {
        const SHOWN: usize = 10;
        let mut missing: Vec<String> =
            (0..shards).filter(|i| !by_shard.contains_key(i)).take(SHOWN).map(|i| i.to_string()).collect();
        if shards - by_shard.len() > SHOWN {
            missing.push(format!("and {} more", shards - by_shard.len() - SHOWN));
        }
        let have: Vec<String> = by_shard.keys().take(SHOWN).map(|i| i.to_string()).collect();
        return Err(MergeError::Missing { missing: missing.join(", "), count: shards, have: have.join(", ") });
    }
    Ok(())
}

/// Reads the partials of `paths`: each a partial file, or a directory whose
/// `partial-*-of-*.json` files are all read (in name order). Only regular files are
/// read, and only while their sizes fit in `budget`.
pub fn read_partials(
    paths: &[std::path::PathBuf],
    budget: &crate::budget::Budget,
) -> Result<Vec<(String, Partial)>, MergeError> {
    read_parsed(paths, budget, "mc", Partial::from_json)
}

/// The partial files of `paths` (each a file, or a directory whose `partial-*-of-*.json`
/// files are all read, in name order), each parsed by `parse(text, name)`, with their
/// names: only regular files, and only while their sizes fit in `budget`. `by` names the
/// command that writes them.
pub(crate) fn read_parsed<T>(
    paths: &[std::path::PathBuf],
    budget: &crate::budget::Budget,
    by: &'static str,
    parse: fn(&str, &str) -> Result<T, MergeError>,
) -> Result<Vec<(String, T)>, MergeError> {
    let io = |p: &std::path::Path, e: std::io::Error| MergeError::Io {
        path: p.display().to_string(),
        message: e.to_string(),
    };
    let mut files = Vec::new();
    for path in paths {
        if path.is_dir() {
            let mut found: Vec<_> = std::fs::read_dir(path)
                .map_err(|e| io(path, e))?
                .filter_map(|e| e.ok().map(|e| e.path()))
                .filter(|p| {
                    let name = p.file_name().and_then(|n| n.to_str()).unwrap_or("");
                    name.starts_with("partial-") && name.contains("-of-") && name.ends_with(".json")
                })
                .collect();
            if found.is_empty() {
                return Err(MergeError::NoneInDir { path: path.display().to_string(), by });
            }
            found.sort();
            files.extend(found);
        } else {
            files.push(path.clone());
        }
    }
    // each file's length, read once: the budget is checked on them, and no file is read
    // past its length (one that grows meanwhile, a device)
    let lengths = files
        .iter()
        .map(|f| {
            let meta = std::fs::metadata(f).map_err(|e| io(f, e))?;
            if !meta.is_file() {
                return Err(MergeError::NotPartial {
                    path: f.display().to_string(),
                    by,
                    message: format!("not a regular file (a partial is a file written by `{by} --shard`)"),
                });
            }
            Ok(meta.len())
        })
        .collect::<Result<Vec<u64>, _>>()?;
    let total: u64 = lengths.iter().sum();
    let need = total as f64 * BYTES_PER_FILE_BYTE;
    let detail = format!("{} partial file(s) of {:.2} GB x {BYTES_PER_FILE_BYTE}", files.len(), total as f64 / 1e9);
    budget.check("merging the partials", need, &detail, "the partials given")?;
    files
        .into_iter()
        .zip(lengths)
        .map(|(f, len)| {
            use std::io::Read;
            let mut text = String::new();
            std::fs::File::open(&f).and_then(|file| file.take(len).read_to_string(&mut text)).map_err(|e| io(&f, e))?;
            let name = f.display().to_string();
            parse(&text, &name).map(|p| (name, p))
        })
        .collect()
}
