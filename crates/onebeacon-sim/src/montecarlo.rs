//! Monte Carlo: `runs` runs of every sweep cell, in parallel with rayon. Run i of every
//! cell is seeded from (seed, i), results are collected in run order and aggregated
//! sequentially, so the output is bit-identical for any number of threads.

use crate::metrics::{CellSummary, summarise};
use crate::run::simulate;
use crate::scenario::{Cell, Scenario};
use rayon::prelude::*;

/// The results of one sweep cell: one summary per estimator, in scenario order.
#[derive(Debug, Clone, PartialEq)]
pub struct CellResult {
    pub cell: Cell,
    pub estimators: Vec<(String, CellSummary)>,
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
    let cells = scenario.cells();
    let work = || {
        let jobs: Vec<(usize, u64)> = (0..cells.len()).flat_map(|c| (0..runs as u64).map(move |r| (c, r))).collect();
        jobs.par_iter()
            .map(|&(c, r)| {
                let out = simulate(scenario, &cells[c], seed, r, false);
                progress();
                out.metrics
            })
            .collect::<Vec<_>>()
    };
    let per_run = match threads {
        Some(n) => rayon::ThreadPoolBuilder::new()
            .num_threads(n)
            .build()
            .map_err(|e| ThreadPoolError { threads: n, message: e.to_string() })?
            .install(work),
        None => work(),
    };
    let cells = cells
        .iter()
        .enumerate()
        .map(|(c, cell)| {
            let cell_runs = &per_run[c * runs..(c + 1) * runs];
            let estimators = scenario
                .estimators
                .iter()
                .enumerate()
                .map(|(e, spec)| {
                    let metrics: Vec<_> = cell_runs.iter().map(|m| m[e]).collect();
                    (spec.name().to_string(), summarise(&metrics))
                })
                .collect();
            CellResult { cell: *cell, estimators }
        })
        .collect();
    Ok(McResult { runs, seed, cells })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scenario::{builtin, parse};

    fn short_garin() -> Scenario {
        let mut s = parse(builtin("garin2024").unwrap().toml, "garin2024").unwrap();
        s.mission.duration_s = Some(400.0);
        s.sweep.t_com_s = Some(vec![3.0, 15.0]);
        s
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
