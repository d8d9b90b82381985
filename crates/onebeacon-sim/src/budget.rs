//! The memory budget: one check, made before any allocation that scales with the input,
//! by every command and by the Python package alike (`run`, `mc`, `fleet`, `replay`,
//! `smooth`, `tune`, `stream`, `mc merge`; Python's `Navigator` too). What a vehicle's
//! filters hold is the onboard crate's figure (`onebeacon::config::working_set`).
//!
//! A configuration is refused up front, with the keys to change, where the estimate of
//! the bytes it would hold exceeds the budget: by default half of this machine's
//! physical memory (8 GiB where it cannot be read); `--memory-gib` or the environment
//! variable `ONEBEACON_MEMORY_GIB` sets it. The estimates are upper bounds: a particle
//! filter of `n` particles of `d` states holds what
//! [`particle_filter_bytes`] counts (its states twice in single precision, its weights).
//! Measured with the states in double precision (before issue 57): a 40 s `run` of
//! hoff2024 with 5e7 particles peaked at 7.83 GB resident (`/usr/bin/time -v`),
//! estimated 8.47 GB; in single precision, a `stream` with 2e6, 0.165 GiB against 0.179.

use crate::run::{Estimate, StepRecord, TruthRecord, recorded_bytes};
use crate::scenario::{EstimatorSpec, Host, Scenario};
use onebeacon::config::stream::StreamConfig;
use onebeacon::config::working_set::particle_filter_bytes;
use onebeacon::log::Log;
use onebeacon::nav::planar::{EXTENDED_STATES, STATES, STATES_WITH_OFFSETS};

/// The environment variable that sets the budget, GiB.
pub const ENV: &str = "ONEBEACON_MEMORY_GIB";

const GIB: f64 = 1024.0 * 1024.0 * 1024.0;
/// What a run holds besides its filters (scenario, worlds, buffers), bytes.
const BASE_BYTES: f64 = 64e6;

/// Why a configuration is refused: one line, naming the keys to change.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum BudgetError {
    #[error(
        "{what} would hold about {need:.1} GB ({detail}); the memory budget is {budget:.1} GB ({origin}): \
         lower {keys}, or raise the budget with --memory-gib or {ENV}"
    )]
    Over { what: String, need: f64, detail: String, budget: f64, origin: &'static str, keys: String },
    #[error("{from} = `{value}`: the memory budget must be a number of GiB > 0")]
    Invalid { from: &'static str, value: String },
}

/// A number of bytes that a command may hold.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Budget {
    bytes: f64,
    source: &'static str,
}

impl Budget {
    /// The budget `gib` (a flag's value), else `ONEBEACON_MEMORY_GIB`, else half this
    /// machine's physical memory.
    pub fn resolve(gib: Option<f64>) -> Result<Budget, BudgetError> {
        let valid = |v: f64| v.is_finite() && v > 0.0;
        if let Some(g) = gib {
            return if valid(g) {
                Ok(Budget { bytes: g * GIB, source: "--memory-gib" })
            } else {
                Err(BudgetError::Invalid { from: "--memory-gib", value: g.to_string() })
            };
        }
        if let Ok(text) = std::env::var(ENV) {
            return match text.trim().parse::<f64>() {
                Ok(g) if valid(g) => Ok(Budget { bytes: g * GIB, source: ENV }),
                _ => Err(BudgetError::Invalid { from: ENV, value: text }),
            };
        }
        Ok(match physical_memory_bytes() {
            Some(b) => Budget { bytes: b / 2.0, source: "half this machine's memory" },
            None => Budget { bytes: 8.0 * GIB, source: "8 GiB: this machine's memory is unknown" },
        })
    }

    /// Refuses `need` bytes above the budget: `what` needs them (`detail` says how they
    /// add up), `keys` are what to lower.
    pub fn check(&self, what: &str, need: f64, detail: &str, keys: &str) -> Result<(), BudgetError> {
        if need <= self.bytes {
            return Ok(());
        }
        Err(BudgetError::Over {
            what: what.to_string(),
            need: need / 1e9,
            detail: detail.to_string(),
            budget: self.bytes / 1e9,
            origin: self.source,
            keys: keys.to_string(),
        })
    }

    /// Refuses simulating `s` with `concurrent` runs at once, `recorded` of them
    /// keeping every step (`run`: 1, `fleet`: all), where it would not fit.
    pub fn check_scenario(&self, s: &Scenario, concurrent: usize, recorded: usize) -> Result<(), BudgetError> {
        let per_run = run_bytes(s);
        let record = recorded_bytes(s) * recorded as f64;
        let need = per_run * concurrent.max(1) as f64 + record;
        let mut detail = format!("{:.2} GB a run x {} at once", per_run / 1e9, concurrent.max(1));
        if recorded > 0 {
            detail.push_str(&format!(
                " + {:.2} GB of recorded steps ({recorded} run(s) x {} steps x {} estimators)",
                record / 1e9,
                s.steps(),
                s.tracks().len()
            ));
        }
        let mut keys: Vec<&str> = match s {
            Scenario::PassiveUsbl(_) => vec!["the estimators' `particles`", "guidance.planner_particles"],
            Scenario::Fleet(_) => vec!["navigation.particles"],
            _ => vec![],
        };
        if concurrent > 1 {
            keys.push("--threads");
        }
        if recorded > 0 {
            keys.push("mission.duration_s (or raise mission.dt_s)");
        }
        if recorded > 1 {
            keys.push("--runs");
        }
        let keys = keys.join(", ");
        let what = format!("{} ({})", s.name(), if recorded > 0 { "recorded runs" } else { "the runs" });
        self.check(&what, need, &detail, &keys)
    }
}

impl Budget {
    /// Refuses replaying `log` where it would not fit: its estimators, the rows the plots
    /// keep (20 000 at most) and, with `keep_records` (the Python package returns every
    /// row), one trajectory row per data row of its CSV files (counted).
    pub fn check_replay(&self, log: &Log, keep_records: bool) -> Result<(), BudgetError> {
        let estimators = log.description.estimators.len();
        let row = record_bytes(estimators);
        let rows = if keep_records { source_rows(log, |_| true) } else { PLOTTED_ROWS };
        let need = BASE_BYTES + filters_bytes(&log.description.estimators) + rows * row;
        let detail = format!("{estimators} estimators, {rows:.0} rows of {row:.0} bytes kept");
        let keys = if keep_records { "the log's length (cut it), [[estimators]]" } else { "[[estimators]]" };
        self.check(&format!("replaying {}", log.description.name), need, &detail, keys)
    }
}

impl Budget {
    /// Refuses a twin of `log` (`onebeacon twin`) with `concurrent` runs under way where
    /// it would not fit: the replay's share ([`Budget::check_replay`]), every row of the
    /// log held once with its plan (counted as two items) and once more per run under
    /// way (its drawn stream), each run's estimators.
    pub fn check_twin(&self, log: &Log, concurrent: usize) -> Result<(), BudgetError> {
        self.check_replay(log, false)?;
        let rows = source_rows(log, |_| true);
        let item = std::mem::size_of::<onebeacon::nav::item::Item>() as f64;
        let n = concurrent as f64;
        let need = BASE_BYTES + n * filters_bytes(&log.description.estimators) + rows * item * (2.0 + n);
        let detail = format!("{rows:.0} rows of {item:.0} bytes held {:.0} times", 2.0 + n);
        self.check(
            &format!("a twin of {}", log.description.name),
            need,
            &detail,
            "--threads, the log's length (cut it)",
        )
    }

    /// Refuses smoothing `log` (`onebeacon smooth`) where it would not fit: the replay's
    /// share ([`Budget::check_replay`]), the smoother's graph ([`SMOOTHER_NODE_BYTES`] a
    /// motion row, [`SMOOTHER_FACTOR_BYTES`] any other row) and the history each
    /// Gaussian filter with beacon aiding keeps for its Rauch-Tung-Striebel pass (two
    /// means and covariances and a cross covariance a prediction, [`rts_step_bytes`]) at
    /// every row (an upper bound: a filter predicts at its motion rows and, with a random
    /// walk, at its other rows). Rows are counted in the files. Measured against it:
    /// plaza1 252 MB (0.4 GB estimated), 600 000 odometry and truth rows 1016 MB (1.6 GB);
    /// cfb7f93's estimate was 6-12 times the need.
    pub fn check_smooth(&self, log: &Log) -> Result<(), BudgetError> {
        use onebeacon::log::schema::SourceKind::*;
        let estimators = &log.description.estimators;
        let kept: Vec<usize> = estimators
            .iter()
            .filter(|e| e.kind.aiding(Host::Log).any() && !e.kind.tracks_bearings() && !e.kind.iusbl())
            .filter(|e| e.planar.track_accel_sigma_m_s2.is_none())
            .map(|e| match (e.calibration.estimate_beacon_offsets == Some(true), e.planar_config().extended()) {
                (true, _) => STATES_WITH_OFFSETS,
                (false, true) => EXTENDED_STATES,
                (false, false) => STATES,
            })
            .collect();
        // the rows counted: motion rows make the graph's nodes, the others its factors
        let motion = |k| matches!(k, Odometry | BodyOdometry | BodyVelocity | Speed | SpeedHeading);
        let nodes = source_rows(log, motion);
        let others = source_rows(log, |k| !motion(k));
        let history = kept.iter().map(|&n| rts_step_bytes(n)).sum::<f64>();
        let replay = BASE_BYTES + filters_bytes(estimators) + PLOTTED_ROWS * record_bytes(estimators.len());
        let need = replay + nodes * SMOOTHER_NODE_BYTES + others * SMOOTHER_FACTOR_BYTES + (nodes + others) * history;
        let detail = format!(
            "{nodes:.0} motion rows (nodes of the graph) and {others:.0} other rows, each a step of {} filters' \
             histories",
            kept.len()
        );
        self.check(
            &format!("smoothing {}", log.description.name),
            need,
            &detail,
            "the log's length (cut it), [[estimators]]",
        )
    }
}

impl Budget {
    /// Refuses the vehicle's computer of `config` (`onebeacon stream`, the Python
    /// `Navigator`) where it would not fit ([`StreamConfig::working_set_bytes`]), before
    /// its filters are built.
    pub fn check_stream(&self, config: &StreamConfig) -> Result<(), BudgetError> {
        let need = BASE_BYTES + config.working_set_bytes();
        let vehicles = config.tracked.len().max(1);
        let detail = format!("{} estimator(s) for {vehicles} vehicle(s)", config.estimators.len());
        let keys = if vehicles > 1 {
            "the estimators' `particles`, [[tracked]], controller.planner_particles"
        } else {
            "the estimators' `particles`, controller.planner_particles"
        };
        self.check(&format!("the vehicle's computer of {}", config.name), need, &detail, keys)
    }
}

/// What the filters of `estimators` hold for one vehicle, bytes.
fn filters_bytes(estimators: &[EstimatorSpec]) -> f64 {
    estimators.iter().map(EstimatorSpec::working_set_bytes).sum()
}

/// The bytes of one node of the smoother's graph (a motion row) with its motion factor,
/// solver and marginals: measured as the peak resident set of `smooth` on a log of
/// 600 000 odometry rows and as many ground-truth rows (1016 MB, /usr/bin/time -v: about
/// 1.6 kB a row), rounded up; plaza1 (9658 nodes, 13 186 ranges) takes about 0.9 kB a
/// node.
const SMOOTHER_NODE_BYTES: f64 = 2048.0;
/// The bytes of one other row (a measurement's factor, a ground-truth row), at most:
/// a factor holds a few dozen numbers. No measurement of its own: the node's quarter.
const SMOOTHER_FACTOR_BYTES: f64 = 512.0;

/// The data rows of `log`'s sources whose kind `which` picks, counted (the lines of
/// each file but its header); a file that cannot be read counts nothing (the replay
/// names it).
fn source_rows(log: &Log, which: impl Fn(onebeacon::log::schema::SourceKind) -> bool) -> f64 {
    use std::io::Read;
    let mut rows = 0u64;
    for s in log.description.sources.iter().filter(|s| which(s.kind)) {
        if let Some(bag) = &s.bag {
            rows += bag_messages(&log.base().join(bag));
            continue;
        }
        let Some(file) = &s.file else { continue };
        let Ok(mut f) = onebeacon::io::file::open_bounded(&log.base().join(file)) else { continue };
        let mut buf = vec![0u8; 1 << 16];
        let mut lines = 0u64;
        while let Ok(n) = f.read(&mut buf) {
            if n == 0 {
                break;
            }
            lines += buf[..n].iter().filter(|&&b| b == b'\n').count() as u64;
        }
        rows += lines.saturating_sub(1);
    }
    rows as f64
}

/// The messages a ROS 2 bag (a file or a directory of splits) can hold, at most: every
/// message of every topic takes 48 bytes at least (MCAP's message record is 31 bytes
/// before its data, a CDR message with a header 16 and more).
fn bag_messages(path: &std::path::Path) -> u64 {
    let size = |p: &std::path::Path| std::fs::metadata(p).map(|m| m.len()).unwrap_or(0);
    let bytes = match std::fs::read_dir(path) {
        Ok(dir) => dir.filter_map(|e| e.ok()).map(|e| size(&e.path())).sum(),
        Err(_) => size(path),
    };
    bytes / 48
}

/// The bytes a Gaussian filter of `n` states keeps per prediction for its
/// Rauch-Tung-Striebel pass, and the smoothed estimate it gives back.
fn rts_step_bytes(n: usize) -> f64 {
    ((2 * (n + n * n) + n * n + 1) * size_of::<f64>() + size_of::<onebeacon::nav::Estimate>()) as f64
}

/// The bytes of one trajectory row kept, with `estimators` estimates.
fn record_bytes(estimators: usize) -> f64 {
    (size_of::<StepRecord>() + size_of::<TruthRecord>() + estimators * size_of::<Estimate>()) as f64
}

/// The rows a replay keeps for its plots, at most.
const PLOTTED_ROWS: f64 = 20_000.0;

/// How many runs a sweep holds at once on `threads` worker threads (default: rayon's,
/// one per core): the runs of one cell go in parallel, the cells one after the other.
pub fn concurrent_runs(threads: Option<usize>, runs: usize) -> usize {
    threads.unwrap_or_else(rayon::current_num_threads).min(runs).max(1)
}

/// Physical memory, bytes (Linux: MemTotal of /proc/meminfo).
fn physical_memory_bytes() -> Option<f64> {
    let text = std::fs::read_to_string("/proc/meminfo").ok()?;
    let line = text.lines().find(|l| l.starts_with("MemTotal:"))?;
    let kib: f64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kib * 1024.0)
}

/// The working set of one run of `s`, bytes: its filters (one per estimator and
/// vehicle) and the planner's subsamples, without the recorded steps.
fn run_bytes(s: &Scenario) -> f64 {
    let specs = |e: &[EstimatorSpec], vehicles: usize| -> f64 {
        e.iter().map(EstimatorSpec::working_set_bytes).sum::<f64>() * vehicles as f64
    };
    BASE_BYTES
        + match s {
            Scenario::FixedBeacon(f) => specs(&f.estimators, 1),
            Scenario::MovingBeacon(m) => specs(&m.estimators, s.vehicle_names().len()),
            // the planner scores a subsample of 3-d positions per AUV and candidate
            Scenario::PassiveUsbl(p) => {
                specs(&p.estimators, p.auvs().len()) + 4.0 * 24.0 * p.guidance.planner_particles as f64
            }
            // the factored filter: 4 f64 per particle and factor (8 single-precision states'
            // bytes)
            Scenario::Fleet(f) => {
                f.auvs.len() as f64 * f.estimators.len() as f64 * particle_filter_bytes(f.navigation.particles, 8)
            }
        }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scenario::{builtin, parse};

    fn hoff(particles: usize) -> Scenario {
        let text = builtin("hoff2024").unwrap().toml.replace("particles = 500000", &format!("particles = {particles}"));
        parse(&text, "hoff2024").unwrap()
    }

    /// The particle filter dominates: 5e7 particles of 8 states are 5e7 x (2 x 8 x 4 + 32)
    /// bytes.
    #[test]
    fn a_particle_filter_of_5e7_is_4_8_gb() {
        assert_eq!(particle_filter_bytes(50_000_000, 8), 4.8e9);
        let one = run_bytes(&hoff(50_000_000));
        assert!((4.8e9..5.0e9).contains(&one), "{one}");
    }

    #[test]
    fn over_the_budget_is_refused_with_the_keys_to_lower() {
        let b = Budget { bytes: 8.0 * GIB, source: "test" };
        let e = b.check_scenario(&hoff(50_000_000), 2, 0).unwrap_err().to_string();
        assert!(e.contains("hoff2024") && e.contains("particles") && e.contains("--memory-gib"), "{e}");
        assert!(b.check_scenario(&hoff(500_000), 2, 0).is_ok());
        assert!(b.check_scenario(&hoff(50_000_000), 1, 0).is_ok());
    }

    #[test]
    fn a_flag_overrides_and_must_be_positive() {
        assert_eq!(Budget::resolve(Some(2.0)).unwrap().bytes, 2.0 * GIB);
        assert!(Budget::resolve(Some(0.0)).is_err());
        assert!(Budget::resolve(Some(f64::NAN)).is_err());
    }
}
