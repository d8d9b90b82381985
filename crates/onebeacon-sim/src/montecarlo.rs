//! Monte Carlo: `runs` runs of every sweep cell, in parallel with rayon. Run i of every
//! cell is seeded from (seed, i), results are collected in run order and aggregated
//! sequentially, so the output is bit-identical for any number of threads. Cells are
//! done one after the other (their runs in parallel) so that only one cell's per-run
//! data is held at a time.
//!
//! A sweep can also be cut into shares ([`Shard`]) run on different machines: each
//! share's [`RunSummary`]s ([`monte_carlo_shard`]), gathered and [`aggregate`]d, give
//! the same [`McResult`] bit for bit ([`crate::partial`] is their file).

use crate::metrics::{CellSummary, RunMetrics, summarise};
use crate::pcrb::{bearing_rmse_bound, horizontal_rmse_bound};
use crate::run::simulate;
use crate::scenario::{Cell, Scenario, Track};
use nalgebra::DMatrix;
use rayon::prelude::*;
use std::collections::BTreeMap;

/// The results of one sweep cell: one summary per estimator, in scenario order.
#[derive(Debug, Clone, PartialEq)]
pub struct CellResult {
    pub cell: Cell,
    /// One summary per (vehicle, estimator) track, in the order of [`Scenario::tracks`].
    pub estimators: Vec<(Track, CellSummary)>,
    /// Posterior Cramer-Rao bound on each vehicle's horizontal RMSE (moving-beacon and
    /// passive-USBL cells; empty otherwise).
    pub pcrb_rmse_m: Vec<f64>,
}

impl CellResult {
    /// The bound of vehicle `v`, where there is one.
    pub fn pcrb(&self, v: usize) -> Option<f64> {
        self.pcrb_rmse_m.get(v).copied()
    }
}

/// The results of a Monte Carlo sweep.
#[derive(Debug, Clone, PartialEq)]
pub struct McResult {
    pub runs: usize,
    pub seed: u64,
    pub cells: Vec<CellResult>,
}

/// Why a sweep gave no result.
#[derive(Debug, thiserror::Error)]
pub enum SweepError {
    #[error("cannot start {threads} worker threads: {message}")]
    ThreadPool { threads: usize, message: String },
    /// [`Progress::stopped`] said so: the runs under way finished, no other started.
    #[error("stopped before the sweep was done")]
    Stopped,
}

/// What a sweep tells as it goes, and whether it must stop. Any `Fn() + Sync` closure
/// is one that ticks and never stops.
pub trait Progress: Sync {
    /// A run finished (called from any worker thread).
    fn tick(&self);
    /// Whether to start no more runs (asked before each).
    fn stopped(&self) -> bool {
        false
    }
}

impl<F: Fn() + Sync> Progress for F {
    fn tick(&self) {
        self()
    }
}

/// Runs the sweep of `scenario` with `runs` runs per cell from base seed `seed`, on
/// `threads` threads (None: rayon's default). `progress` is called once per finished
/// run, from any thread.
pub fn monte_carlo(
    scenario: &Scenario,
    runs: usize,
    seed: u64,
    threads: Option<usize>,
    progress: &dyn Progress,
) -> Result<McResult, SweepError> {
    let cells = in_pool(threads, || {
        scenario
            .cells()
            .iter()
            .enumerate()
            .map(|(c, cell)| {
                let per_run: Option<Vec<RunSummary>> =
                    (0..runs as u64).into_par_iter().map(|r| run_one(scenario, cell, c, seed, r, progress)).collect();
                Ok(summarise_cell(scenario, cell, &per_run.ok_or(SweepError::Stopped)?))
            })
            .collect::<Result<Vec<_>, SweepError>>()
    })??;
    Ok(McResult { runs, seed, cells })
}

/// What the aggregation keeps of one run of one cell: its metrics (one per track) and
/// its acoustic information (vehicle, step, matrix). A shard's partial result is a list
/// of these.
#[derive(Debug, Clone, PartialEq)]
pub struct RunSummary {
    /// The cell's index in [`Scenario::cells`].
    pub cell: usize,
    pub run: u64,
    pub metrics: Vec<RunMetrics>,
    pub information: Vec<(usize, usize, DMatrix<f64>)>,
}

/// Share `index` of `count` of a sweep's (cell, run) pairs: pair j = cell x runs + run
/// belongs to the share j mod `count`, so that every share holds runs of every cell
/// and the shares' costs stay alike when cells differ in cost.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Shard {
    pub index: usize,
    pub count: usize,
}

impl Shard {
    /// The whole sweep in one share.
    pub const WHOLE: Shard = Shard { index: 0, count: 1 };

    /// The (cell, run) pairs of this share, in (cell, run) order.
    pub fn pairs(self, cells: usize, runs: usize) -> impl Iterator<Item = (usize, u64)> {
        (0..cells * runs).skip(self.index).step_by(self.count.max(1)).map(move |j| (j / runs, (j % runs) as u64))
    }

    /// How many pairs this share of `pairs` holds: the indices below `pairs` that are
    /// `index` mod `count`, counted without visiting them.
    pub fn len(self, pairs: usize) -> usize {
        if self.index >= pairs { 0 } else { (pairs - self.index - 1) / self.count.max(1) + 1 }
    }
}

impl std::fmt::Display for Shard {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}/{}", self.index, self.count)
    }
}

impl std::str::FromStr for Shard {
    type Err = String;
    /// `I/N` with 0 <= I < N.
    fn from_str(s: &str) -> Result<Self, String> {
        let bad = || format!("`{s}`: expected I/N with 0 <= I < N (e.g. 0/4), N at most 100000");
        let (i, n) = s.split_once('/').ok_or_else(bad)?;
        let (index, count): (usize, usize) =
            (i.trim().parse().map_err(|_| bad())?, n.trim().parse().map_err(|_| bad())?);
        if count == 0 || index >= count || count > 100_000 {
            return Err(bad());
        }
        Ok(Shard { index, count })
    }
}

pub(crate) fn in_pool<T: Send>(threads: Option<usize>, work: impl FnOnce() -> T + Send) -> Result<T, SweepError> {
    match threads {
        Some(n) => Ok(rayon::ThreadPoolBuilder::new()
            .num_threads(n)
            .build()
            .map_err(|e| SweepError::ThreadPool { threads: n, message: e.to_string() })?
            .install(work)),
        None => Ok(work()),
    }
}

/// Runs one share of the sweep ([`Shard`]) and returns its runs' summaries in (cell,
/// run) order; [`aggregate`] turns the summaries of all shares into the [`McResult`]
/// that [`monte_carlo`] gives, bit for bit. `progress` is called once per finished run.
pub fn monte_carlo_shard(
    scenario: &Scenario,
    runs: usize,
    seed: u64,
    shard: Shard,
    threads: Option<usize>,
    progress: &dyn Progress,
) -> Result<Vec<RunSummary>, SweepError> {
    let cells = scenario.cells();
    let pairs: Vec<(usize, u64)> = shard.pairs(cells.len(), runs).collect();
    in_pool(threads, || {
        pairs.into_par_iter().map(|(c, r)| run_one(scenario, &cells[c], c, seed, r, progress)).collect::<Option<_>>()
    })?
    .ok_or(SweepError::Stopped)
}

fn run_one(
    scenario: &Scenario,
    cell: &Cell,
    index: usize,
    seed: u64,
    run: u64,
    progress: &dyn Progress,
) -> Option<RunSummary> {
    if progress.stopped() {
        return None;
    }
    let out = simulate(scenario, cell, seed, run, false);
    progress.tick();
    Some(RunSummary { cell: index, run, metrics: out.metrics, information: out.information })
}

/// Why summaries do not make a whole sweep.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum AggregateError {
    #[error("run {run} of cell {cell} is missing")]
    Missing { cell: usize, run: u64 },
    #[error("run {run} of cell {cell} is given twice")]
    Duplicate { cell: usize, run: u64 },
    #[error("run {run} of cell {cell} is outside the sweep ({cells} cells x {runs} runs)")]
    Outside { cell: usize, run: u64, cells: usize, runs: usize },
    #[error("run {run} of cell {cell} has {got} tracks' metrics; the scenario has {tracks} tracks")]
    Tracks { cell: usize, run: u64, got: usize, tracks: usize },
    #[error(
        "run {run} of cell {cell} has an information matrix of vehicle {vehicle}, {rows} x {rows}; the cell has \
         {vehicles} vehicle(s) with {dim} x {dim} matrices"
    )]
    Information { cell: usize, run: u64, vehicle: usize, rows: usize, vehicles: usize, dim: usize },
}

/// How many vehicles a run of `cell` reports acoustic information for, and the size of
/// its matrices (none where the scenario has no bound to compute).
fn information_shape(scenario: &Scenario, cell: &Cell) -> (usize, usize) {
    match (scenario, cell) {
        (Scenario::MovingBeacon(s), Cell::MovingBeacon(c)) => (s.vehicles(c).len(), 6),
        (Scenario::PassiveUsbl(s), Cell::PassiveUsbl(_)) => (s.auvs().len(), onebeacon::models::hoff::DIM),
        _ => (0, 0),
    }
}

/// Aggregates the summaries of every (cell, run) pair of the sweep, in any order, into
/// the result [`monte_carlo`] gives for (scenario, runs, seed).
pub fn aggregate(
    scenario: &Scenario,
    runs: usize,
    seed: u64,
    summaries: Vec<RunSummary>,
) -> Result<McResult, AggregateError> {
    let cells = scenario.cells();
    let tracks = scenario.tracks().len();
    let shapes: Vec<_> = cells.iter().map(|c| information_shape(scenario, c)).collect();
    let mut slots: Vec<Option<RunSummary>> = vec![None; cells.len() * runs];
    for s in summaries {
        let (cell, run) = (s.cell, s.run);
        if cell >= cells.len() || run >= runs as u64 {
            return Err(AggregateError::Outside { cell, run, cells: cells.len(), runs });
        }
        if s.metrics.len() != tracks {
            return Err(AggregateError::Tracks { cell, run, got: s.metrics.len(), tracks });
        }
        let (vehicles, dim) = shapes[cell];
        if let Some((vehicle, _, m)) = s.information.iter().find(|(v, _, m)| *v >= vehicles || m.shape() != (dim, dim))
        {
            return Err(AggregateError::Information { cell, run, vehicle: *vehicle, rows: m.nrows(), vehicles, dim });
        }
        let slot = &mut slots[cell * runs + run as usize];
        if slot.is_some() {
            return Err(AggregateError::Duplicate { cell, run });
        }
        *slot = Some(s);
    }
    let mut slots = slots.into_iter();
    let mut results = Vec::with_capacity(cells.len());
    for (c, cell) in cells.iter().enumerate() {
        let per_run: Vec<RunSummary> = (0..runs as u64)
            .map(|run| slots.next().flatten().ok_or(AggregateError::Missing { cell: c, run }))
            .collect::<Result<_, _>>()?;
        results.push(summarise_cell(scenario, cell, &per_run));
    }
    Ok(McResult { runs, seed, cells: results })
}

/// The cell's result from its runs' summaries, in run order.
fn summarise_cell(scenario: &Scenario, cell: &Cell, per_run: &[RunSummary]) -> CellResult {
    let runs = per_run.len();
    let estimators = scenario
        .tracks()
        .into_iter()
        .enumerate()
        .map(|(e, track)| {
            let metrics: Vec<_> = per_run.iter().map(|s| s.metrics[e]).collect();
            (track, summarise(&metrics))
        })
        .collect();
    // the information summed over the runs, per vehicle and step: one entry per step
    // with an acoustic measurement, not per step (memory follows the pings)
    let sum_information = |vehicles: usize| {
        let mut sum: Vec<BTreeMap<usize, DMatrix<f64>>> = vec![BTreeMap::new(); vehicles];
        for s in per_run {
            for (v, k, m) in &s.information {
                sum[*v].entry(*k).and_modify(|s| *s += m).or_insert_with(|| m.clone());
            }
        }
        sum
    };
    let pcrb_rmse_m = match (scenario, cell) {
        (Scenario::MovingBeacon(s), Cell::MovingBeacon(c)) => {
            let vehicles = s.vehicles(c);
            let sum = sum_information(vehicles.len());
            vehicles.iter().zip(&sum).map(|(v, sum)| horizontal_rmse_bound(s, v, sum, runs)).collect()
        }
        (Scenario::PassiveUsbl(s), Cell::PassiveUsbl(_)) => {
            let sum = sum_information(s.auvs().len());
            sum.iter().enumerate().map(|(v, sum)| bearing_rmse_bound(s, v, sum, runs)).collect()
        }
        _ => Vec::new(),
    };
    CellResult { cell: *cell, estimators, pcrb_rmse_m }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scenario::{builtin, parse};

    fn short_garin() -> Scenario {
        let Scenario::FixedBeacon(mut s) = parse(builtin("garin2024").unwrap().toml, "garin2024").unwrap() else {
            unreachable!()
        };
        s.mission.duration_s = Some(400.0);
        s.sweep.t_com_s = Some(vec![3.0, 15.0]);
        Scenario::FixedBeacon(s)
    }

    #[test]
    fn results_do_not_depend_on_thread_count() {
        let s = short_garin();
        let one = monte_carlo(&s, 6, 11, Some(1), &|| {}).unwrap();
        let two = monte_carlo(&s, 6, 11, Some(2), &|| {}).unwrap();
        let three = monte_carlo(&s, 6, 11, Some(3), &|| {}).unwrap();
        assert_eq!(one, two);
        assert_eq!(one, three);
        assert_eq!(one.cells.len(), 2);
    }

    /// The closed form against counting the pairs one by one.
    #[test]
    fn a_shares_length_is_its_pairs_counted() {
        for (cells, runs) in [(1, 1), (3, 5), (4, 7), (2, 1)] {
            for count in 1..=cells * runs + 2 {
                for index in 0..count {
                    let shard = Shard { index, count };
                    assert_eq!(shard.len(cells * runs), shard.pairs(cells, runs).count(), "{shard} of {cells}x{runs}");
                }
            }
        }
    }

    #[test]
    fn progress_is_reported_once_per_run() {
        let s = short_garin();
        let count = std::sync::atomic::AtomicUsize::new(0);
        monte_carlo(&s, 4, 1, Some(2), &|| {
            count.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
        })
        .unwrap();
        assert_eq!(count.into_inner(), 8);
    }
}
