//! One share of a twin's runs (`onebeacon twin --shard I/N`) as a JSON file, and the
//! merge of every share's file into the twin the unsharded command gives, bit for bit.
//! The shares are checked by the campaign's own rules ([`crate::partial::check_shares`]);
//! a share holds the sea it drew from and the log's replay scores, so a share of another
//! log, beacon set or sea is refused by name.

use super::{Score, Twin};
use crate::montecarlo::Shard;
use crate::partial::{MergeError, Share, VERSION, check_shares, parse_partial, read_parsed};
use crate::scenario::sea::Sea;
use serde::{Deserialize, Serialize};

/// The `format` field of a twin's partial.
pub const FORMAT: &str = "onebeacon-twin-partial/1";

/// A score's three floats as bit patterns (a lost track's infinity survives).
type Bits = [u64; 3];

fn bits(s: &Score) -> Bits {
    [s.rmse_m.to_bits(), s.final_m.to_bits(), s.nees.to_bits()]
}

fn score(b: &Bits) -> Score {
    Score { rmse_m: f64::from_bits(b[0]), final_m: f64::from_bits(b[1]), nees: f64::from_bits(b[2]) }
}

/// One share's runs: what `onebeacon twin --shard I/N` writes.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct TwinPartial {
    pub format: String,
    pub version: String,
    /// The log's name, for messages.
    pub log: String,
    /// The sea the runs drew from, as TOML.
    pub sea_toml: String,
    pub runs: usize,
    pub seed: u64,
    pub shard: usize,
    pub shards: usize,
    /// Seconds the share took, on its machine.
    pub wall_s: f64,
    /// Each cell: its beacons, its estimator and the log's own replay score.
    pub cells: Vec<(Vec<u32>, String, Bits)>,
    /// Each run of the share: its index and its score in every cell.
    pub results: Vec<(u64, Vec<Bits>)>,
}

/// The sea as the TOML a partial holds (a sea's `[sea]` table, canonical).
fn sea_toml(sea: &Sea) -> String {
    toml::to_string(sea).expect("a sea serialises")
}

impl TwinPartial {
    /// The partial of the share `shard` of `runs` runs: `twin` is that share's twin.
    pub fn new(log: &str, sea: &Sea, twin: &Twin, runs: usize, seed: u64, shard: Shard, wall_s: f64) -> Self {
        let cells = twin.cells.iter().map(|c| (c.beacons.clone(), c.estimator.clone(), bits(&c.real))).collect();
        let results = twin
            .run_indices
            .iter()
            .enumerate()
            .map(|(k, run)| (*run, twin.cells.iter().map(|c| bits(&c.runs[k])).collect()))
            .collect();
        TwinPartial {
            format: FORMAT.into(),
            version: VERSION.into(),
            log: log.into(),
            sea_toml: sea_toml(sea),
            runs,
            seed,
            shard: shard.index,
            shards: shard.count,
            wall_s,
            cells,
            results,
        }
    }

    pub fn to_json(&self) -> String {
        serde_json::to_string(self).expect("serialisable")
    }

    /// Reads a partial from `text` (`path` names it in errors), its shape checked.
    pub fn from_json(text: &str, path: &str) -> Result<Self, MergeError> {
        let p: TwinPartial = parse_partial(text, path, "twin", FORMAT, TwinPartial::shard_of)?;
        let not = |message: String| MergeError::NotPartial { path: path.into(), by: "twin", message };
        let shard = p.shard_of();
        let expected = shard.pairs(1, p.runs).map(|(_, run)| run);
        if p.results.iter().map(|r| r.0).ne(expected.take(p.results.len())) {
            return Err(not(format!("its runs are not those of shard {shard} of {} runs", p.runs)));
        }
        if let Some((run, _)) = p.results.iter().find(|r| r.1.len() != p.cells.len()) {
            return Err(not(format!("run {run} has not one score per cell ({})", p.cells.len())));
        }
        Ok(p)
    }

    fn shard_of(&self) -> Shard {
        Shard { index: self.shard, count: self.shards }
    }

    fn share<'a>(&'a self, path: &'a str) -> Share<'a> {
        Share {
            path,
            version: &self.version,
            seed: self.seed,
            runs: self.runs,
            shard: self.shard_of(),
            results: self.results.len(),
        }
    }
}

/// Reads the twin partials of `paths` (files, or directories of `partial-*-of-*.json`).
pub fn read_twin_partials(
    paths: &[std::path::PathBuf],
    budget: &crate::budget::Budget,
) -> Result<Vec<(String, TwinPartial)>, MergeError> {
    read_parsed(paths, budget, "twin", TwinPartial::from_json)
}

/// What the shares of a twin merge into.
#[derive(Debug, Clone)]
pub struct MergedTwin {
    pub twin: Twin,
    pub runs: usize,
    pub seed: u64,
    /// The shares' compute times added up, s.
    pub wall_s: f64,
}

/// The twin of every share: `real` is the twin of no run of the log named `log` under
/// `sea` with the same beacon sets (its cells' replay scores, what it kept, its notes),
/// the partials every share's. Returns it with every run's scores in run order.
pub fn merge_twin(
    log: &str,
    mut real: Twin,
    sea: &Sea,
    partials: Vec<(String, TwinPartial)>,
) -> Result<MergedTwin, MergeError> {
    let Some((first_path, first)) = partials.first() else { return Err(MergeError::Empty) };
    let ours = sea_toml(sea);
    let heads: Vec<(Vec<u32>, String, Bits)> =
        real.cells.iter().map(|c| (c.beacons.clone(), c.estimator.clone(), bits(&c.real))).collect();
    for (path, p) in &partials {
        let mismatch = |what, a: String, b: String| MergeError::Mismatch {
            first: "this command".into(),
            second: path.clone(),
            what,
            a,
            b,
        };
        if p.sea_toml != ours {
            return Err(mismatch("the sea (--sea)", "--sea's [sea]".into(), "the one its runs drew from".into()));
        }
        if p.cells != heads {
            let what = "the log or its beacon sets (their replay's cells and scores)";
            return Err(mismatch(what, format!("log `{log}`"), format!("log `{}`", p.log)));
        }
    }
    let (runs, seed) = (first.runs, first.seed);
    if runs == 0 || first.shards > runs {
        return Err(MergeError::Count {
            path: first_path.clone(),
            what: if runs == 0 { "runs" } else { "shards" },
            value: if runs == 0 { runs } else { first.shards },
            cells: 1,
            runs,
            pairs: runs.to_string(),
        });
    }
    let shares: Vec<Share> = partials.iter().map(|(path, p)| p.share(path)).collect();
    check_shares(&shares, runs)?;
    let mut by_run: Vec<Option<Vec<Bits>>> = vec![None; runs];
    let mut wall_s = 0.0;
    for (_, p) in partials {
        wall_s += p.wall_s;
        for (run, scores) in p.results {
            by_run[run as usize] = Some(scores);
        }
    }
    for (run, scores) in by_run.into_iter().enumerate() {
        let scores = scores.expect("every run held by its share, checked");
        for (cell, s) in real.cells.iter_mut().zip(&scores) {
            cell.runs.push(score(s));
        }
        real.run_indices.push(run as u64);
    }
    Ok(MergedTwin { twin: real, runs, seed, wall_s })
}
