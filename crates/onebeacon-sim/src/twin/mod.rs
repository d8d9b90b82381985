//! A log's twin (`onebeacon twin`): the log's mission simulated again, run after run,
//! with a fitted sea. The truth is the log's ground truth (without one, the smoother's
//! trajectory); the beacons and every measurement's time are the log's, so its rates and
//! gaps are too; each measurement's value is drawn anew from the sea about the truth.
//! The log's own estimators run on every simulated stream and on the log itself, and
//! each (beacon set, estimator) cell compares the real score with the simulated spread
//! (docs/logs.md, "The twin of a log").

mod draw;
pub mod partial;

#[cfg(test)]
pub(crate) mod tests;

use crate::montecarlo::{Progress, Shard, SweepError, in_pool};
use crate::replay::{replay, session_from};
use crate::scenario::EstimatorKind;
use crate::scenario::sea::Sea;
use crate::seafit::truth::Track;
use crate::smooth::{SmoothConfig, SmoothError, smooth};
use onebeacon::log::{Log, LogError};
use onebeacon::nav::evaluation::{ErrorStats, quantile};
use onebeacon::nav::item::Item;
use onebeacon::nav::item::TruthPose;
use onebeacon::nav::session::Input;
use rayon::prelude::*;
use std::collections::BTreeSet;

pub use draw::Kept;

/// What `twin` is asked.
#[derive(Debug, Clone)]
pub struct TwinOptions {
    pub runs: usize,
    pub seed: u64,
    pub threads: Option<usize>,
    /// The beacon sets, each run by every estimator (None: all the log's beacons).
    pub sets: Vec<Option<BTreeSet<u32>>>,
    /// The share of the runs to simulate (run j goes to share j mod N).
    pub shard: Shard,
}

#[derive(Debug, thiserror::Error)]
pub enum TwinError {
    #[error(transparent)]
    Log(#[from] LogError),
    #[error("the sea: {0}")]
    Sea(String),
    #[error("no ground truth in the log, and the smoother could not give a trajectory: {0}")]
    Smooth(#[from] SmoothError),
    #[error(transparent)]
    Sweep(#[from] SweepError),
}

/// One estimator's score on one run: RMSE, final error, m, and mean NEES (NaN: none).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Score {
    pub rmse_m: f64,
    pub final_m: f64,
    pub nees: f64,
}

impl Score {
    fn of(s: &ErrorStats) -> Self {
        Score { rmse_m: s.rmse_m(), final_m: s.final_m, nees: s.nees_mean() }
    }
}

/// The 5 %, 50 % and 95 % points of a score over the runs.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Band {
    pub p5: f64,
    pub median: f64,
    pub p95: f64,
}

impl Band {
    fn of(mut v: Vec<f64>) -> Self {
        v.sort_by(f64::total_cmp);
        Band { p5: quantile(&v, 0.05), median: quantile(&v, 0.5), p95: quantile(&v, 0.95) }
    }

    /// Whether `x` lies within the 5-95 % band.
    pub fn holds(&self, x: f64) -> bool {
        (self.p5..=self.p95).contains(&x)
    }
}

/// One (beacon set, estimator) cell: the real replay's score and the simulated runs'.
#[derive(Debug, Clone, PartialEq)]
pub struct TwinCell {
    pub beacons: Vec<u32>,
    pub estimator: String,
    pub real: Score,
    pub runs: Vec<Score>,
}

impl TwinCell {
    pub fn rmse(&self) -> Band {
        Band::of(self.runs.iter().map(|s| s.rmse_m).collect())
    }
    pub fn final_error(&self) -> Band {
        Band::of(self.runs.iter().map(|s| s.final_m).collect())
    }
    pub fn nees(&self) -> Band {
        Band::of(self.runs.iter().map(|s| s.nees).collect())
    }
    /// The real mean NEES over the simulated median (NaN without a NEES).
    pub fn nees_ratio(&self) -> f64 {
        self.real.nees / self.nees().median
    }
}

/// A twin's cells, and what it kept of the log as logged.
#[derive(Debug, Clone)]
pub struct Twin {
    pub reference: &'static str,
    pub cells: Vec<TwinCell>,
    /// The index of each simulated run, in the order of every cell's `runs`.
    pub run_indices: Vec<u64>,
    pub kept: Kept,
    pub notes: Vec<String>,
}

/// How far a real NEES may be from the simulated median, a factor either way (the
/// issue's target for a twin that predicts a log).
pub const NEES_FACTOR: f64 = 1.5;

impl Twin {
    /// Cells whose real RMSE lies within the simulated 5-95 % band (of the cells with a
    /// real RMSE: a log without ground truth has none), and those whose real NEES is
    /// within [`NEES_FACTOR`] of the simulated median (of the cells with one).
    pub fn agreement(&self) -> ((usize, usize), (usize, usize)) {
        let scored: Vec<&TwinCell> = self.cells.iter().filter(|c| c.real.rmse_m.is_finite()).collect();
        let rmse = scored.iter().filter(|c| c.rmse().holds(c.real.rmse_m)).count();
        let with_nees: Vec<f64> = self.cells.iter().map(|c| c.nees_ratio()).filter(|r| r.is_finite()).collect();
        let nees = with_nees.iter().filter(|r| (1.0 / NEES_FACTOR..=NEES_FACTOR).contains(*r)).count();
        ((rmse, scored.len()), (nees, with_nees.len()))
    }
}

/// The twin of `log` under `sea`: `progress` ticks once per simulated run.
pub fn twin(log: &Log, sea: &Sea, opts: &TwinOptions, progress: &dyn Progress) -> Result<Twin, TwinError> {
    sea.check_twin().map_err(TwinError::Sea)?;
    let mut items: Vec<Item> = log.items()?.collect::<Result<_, _>>()?;
    let truth: Vec<(f64, [f64; 2], Option<f64>)> = items
        .iter()
        .filter_map(|i| match i.input.clone().to_ned(log.frame) {
            Input::Truth(p) => Some((i.t_s, [p.north_m, p.east_m], p.heading_rad)),
            _ => None,
        })
        .collect();
    let mut notes = draw::notes(sea);
    let (track, reference) = if truth.len() >= 2 {
        (Track::new(truth), "ground truth")
    } else {
        notes.push("no ground truth: the twin's truth is the smoother's trajectory (the runs are scored against it, the log itself against nothing)".into());
        let s = smooth(log, None, &SmoothConfig::default())?;
        let rows: Vec<_> = s.t_s.iter().zip(&s.poses).map(|(t, p)| (*t, [p[0], p[1]], Some(p[2]))).collect();
        // the smoothed poses scored as a ground truth, after the measurements of their time
        for &(t, p, h) in &rows {
            let (x, y, _) = log.frame.from_ned(&nalgebra::Vector3::new(p[0], p[1], 0.0));
            let heading_rad = h.map(|h| log.frame.heading_from_ned(h));
            items.push(Item {
                t_s: t,
                input: Input::Truth(TruthPose { north_m: x, east_m: y, heading_rad, sigma_m: 0.0 }),
            });
        }
        items.sort_by(|a, b| a.t_s.total_cmp(&b.t_s));
        (Track::new(rows), "smoother")
    };
    let drawer = draw::Drawer::new(log, sea, &track, &items);
    // an estimator that hears no beacon (dead reckoning) scores the same on every set:
    // its cell is the first set's alone
    let hears: Vec<bool> = log.description.estimators.iter().map(|e| e.kind != EstimatorKind::DeadReckoning).collect();
    let scored = |set: usize, i: usize| set == 0 || hears[i];
    let mut cells = Vec::new();
    let mut starts = Vec::new();
    for (k, set) in opts.sets.iter().enumerate() {
        let real = replay(log, set.clone(), |_| Ok::<_, LogError>(()))?;
        starts.push(real.start);
        let beacons: Vec<u32> = set.clone().unwrap_or_else(|| log.beacon_ids()).into_iter().collect();
        for (i, (name, st)) in real.session.names.iter().zip(&real.session.stats).enumerate() {
            if scored(k, i) {
                let real = Score::of(st);
                cells.push(TwinCell { beacons: beacons.clone(), estimator: name.clone(), real, runs: Vec::new() });
            }
        }
    }
    let run_indices: Vec<u64> = opts.shard.pairs(1, opts.runs).map(|(_, run)| run).collect();
    let per_run: Option<Vec<Vec<Score>>> = in_pool(opts.threads, || {
        run_indices
            .par_iter()
            .map(|&run| run)
            .map(|run| {
                if progress.stopped() {
                    return None;
                }
                let stream = drawer.run(opts.seed, run);
                let mut scores = Vec::new();
                for (k, (set, start)) in opts.sets.iter().zip(&starts).enumerate() {
                    let mut session = session_from(log, set.clone(), start);
                    for item in &stream {
                        // a screened item is counted by the session, as in a replay
                        let _ = session.push(item);
                    }
                    let stats = session.stats.iter().enumerate().filter(|(i, _)| scored(k, *i));
                    scores.extend(stats.map(|(_, st)| Score::of(st)));
                }
                progress.tick();
                Some(scores)
            })
            .collect()
    })?;
    for scores in per_run.ok_or(SweepError::Stopped)? {
        for (cell, s) in cells.iter_mut().zip(scores) {
            cell.runs.push(s);
        }
    }
    Ok(Twin { reference, cells, run_indices, kept: drawer.kept(), notes })
}
