//! Monte Carlo: `runs` runs of every sweep cell, in parallel with rayon. Run i of every
//! cell is seeded from (seed, i), results are collected in run order and aggregated
//! sequentially, so the output is bit-identical for any number of threads. Cells are
//! done one after the other (their runs in parallel) so that only one cell's per-run
//! data is held at a time.

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

/// Failure to set up the worker threads.
#[derive(Debug, thiserror::Error)]
#[error("cannot start {threads} worker threads: {message}")]
pub struct ThreadPoolError {
    pub threads: usize,
    pub message: String,
}

/// Runs the sweep of `scenario` with `runs` runs per cell from base seed `seed`, on
/// `threads` threads (None: rayon's default). `progress` is called once per finished
/// run, from any thread.
pub fn monte_carlo(
    scenario: &Scenario,
    runs: usize,
    seed: u64,
    threads: Option<usize>,
    progress: &(dyn Fn() + Sync),
) -> Result<McResult, ThreadPoolError> {
    let work = || scenario.cells().iter().map(|cell| run_cell(scenario, cell, runs, seed, progress)).collect();
    let cells = match threads {
        Some(n) => rayon::ThreadPoolBuilder::new()
            .num_threads(n)
            .build()
            .map_err(|e| ThreadPoolError { threads: n, message: e.to_string() })?
            .install(work),
        None => work(),
    };
    Ok(McResult { runs, seed, cells })
}

/// What the aggregation keeps of one run: its metrics and its acoustic information.
type RunSummary = (Vec<RunMetrics>, Vec<(usize, usize, DMatrix<f64>)>);

fn run_cell(scenario: &Scenario, cell: &Cell, runs: usize, seed: u64, progress: &(dyn Fn() + Sync)) -> CellResult {
    let per_run: Vec<RunSummary> = (0..runs as u64)
        .into_par_iter()
        .map(|r| {
            let out = simulate(scenario, cell, seed, r, false);
            progress();
            (out.metrics, out.information)
        })
        .collect();
    let estimators = scenario
        .tracks()
        .into_iter()
        .enumerate()
        .map(|(e, track)| {
            let metrics: Vec<_> = per_run.iter().map(|(m, _)| m[e]).collect();
            (track, summarise(&metrics))
        })
        .collect();
    // the information summed over the runs, per vehicle and step: one entry per step
    // with an acoustic measurement, not per step (memory follows the pings)
    let sum_information = |vehicles: usize| {
        let mut sum: Vec<BTreeMap<usize, DMatrix<f64>>> = vec![BTreeMap::new(); vehicles];
        for (_, info) in &per_run {
            for (v, k, m) in info {
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
