//! `onebeacon`: single-beacon underwater navigation, from scenario to table and plot.

/// `print!` and `println!` that return an error (one line, exit status 1) where stdout
/// cannot be written (a full disk, `> /dev/full`) instead of panicking.
macro_rules! out {
    ($($arg:tt)*) => {{
        use std::io::Write as _;
        write!(std::io::stdout().lock(), $($arg)*).map_err(crate::stdout_error)?
    }};
}
macro_rules! outln {
    ($($arg:tt)*) => {{
        use std::io::Write as _;
        writeln!(std::io::stdout().lock(), $($arg)*).map_err(crate::stdout_error)?
    }};
}

mod campaign;
mod commands;
mod dsp;
mod fleet;
mod output;
mod plot;
mod progress;
mod replay;
mod report;
#[cfg(feature = "ros2")]
mod ros2;
mod sea_fit;
mod smooth;
mod tune;
mod twin;

use clap::{Parser, Subcommand};

/// The error of a failed write to stdout.
fn stdout_error(e: std::io::Error) -> anyhow::Error {
    anyhow::anyhow!("cannot write to stdout: {e}")
}
use std::path::PathBuf;
use std::process::ExitCode;

/// Navigation of underwater vehicles from one acoustic beacon: simulate, estimate,
/// compare.
#[derive(Debug, Parser)]
#[command(name = "onebeacon", version)]
struct Cli {
    #[command(subcommand)]
    command: Command,
    /// The memory budget, GiB: a configuration whose estimated working set is larger is
    /// refused before any work (default: $ONEBEACON_MEMORY_GIB, else half this
    /// machine's memory).
    #[arg(long, global = true, value_name = "GiB", value_parser = positive_f64)]
    memory_gib: Option<f64>,
}

/// The memory budget of this invocation ([`onebeacon_sim::budget`]).
static BUDGET: std::sync::OnceLock<onebeacon_sim::budget::Budget> = std::sync::OnceLock::new();

/// Refuses (as bad input) `s` with `concurrent` runs at once, `recorded` of them keeping
/// every step, where it would not fit in the memory budget.
pub(crate) fn check_memory(
    name: &str,
    s: &onebeacon_sim::Scenario,
    concurrent: usize,
    recorded: usize,
) -> anyhow::Result<()> {
    budget().check_scenario(s, concurrent, recorded).map_err(|e| BadInput(format!("{name}: {e}")).into())
}

/// The memory budget of this invocation.
pub(crate) fn budget() -> onebeacon_sim::budget::Budget {
    *BUDGET.get().expect("set in main")
}

#[derive(Debug, Subcommand)]
enum Command {
    /// List the built-in scenarios, or print one (`--show NAME`) to copy and edit.
    Scenarios {
        /// Print this built-in scenario's TOML.
        #[arg(long, value_name = "NAME")]
        show: Option<String>,
    },
    /// One run of a scenario: trajectory.csv, summary.json and plots in DIR.
    Run {
        /// Built-in scenario name or path of a TOML file.
        scenario: String,
        /// Base seed (default: the scenario's `seed`).
        #[arg(long)]
        seed: Option<u64>,
        /// Which run of the seed to simulate (run i of `mc`).
        #[arg(long, default_value_t = 0)]
        run: u64,
        /// Moving-beacon scenarios: the ping whose guidance metric is mapped in
        /// guidance.png (0 is the first); passive-USBL scenarios: the planner decision.
        #[arg(long, default_value_t = 1)]
        ping: usize,
        /// Passive-USBL scenarios: the message (1 is the first, one period after the
        /// start) whose particle cloud belief.png draws with its bearing [default: 9, at
        /// 36 s as hoff2024 Fig. 4-5].
        #[arg(long, default_value_t = 9)]
        message: usize,
        /// Output directory (default: out/<scenario>-run).
        #[arg(long, value_name = "DIR")]
        out: Option<PathBuf>,
        /// Also write each vehicle computer's side of the run (fixed_beacon: the AUV;
        /// passive_usbl: the surface vehicle; moving_beacon: the beacon vehicle and the
        /// vehicles it does not serve; fleet with the abstract signal model: each AUV):
        /// NAME.stream.toml (its `stream` configuration), NAME.input.jsonl (what it
        /// heard) and NAME.decisions.jsonl (the simulator's commands; none without a
        /// controller), for `onebeacon stream NAME.stream.toml < NAME.input.jsonl`.
        #[arg(long)]
        messages: bool,
    },
    /// Monte Carlo over the scenario's sweep: a table per estimator, or JSON. With
    /// --shard I/N, one share of it (for many machines; `mc merge` combines the shares);
    /// with --slurm N, a Slurm array job of N shards and the merge after them.
    #[command(args_conflicts_with_subcommands = true, subcommand_negates_reqs = true)]
    Mc {
        #[command(subcommand)]
        merge: Option<McCommand>,
        /// Built-in scenario name or path of a TOML file.
        #[arg(required = true)]
        scenario: Option<String>,
        /// Runs per sweep cell (default: the scenario's `runs`).
        #[arg(long, value_parser = clap::value_parser!(u32).range(1..=1_000_000))]
        runs: Option<u32>,
        /// Base seed (default: the scenario's `seed`).
        #[arg(long)]
        seed: Option<u64>,
        /// Worker threads (default: one per core). Results do not depend on it. (With
        /// --slurm, each shard's threads are its --cpus-per-task.)
        #[arg(long, value_parser = clap::value_parser!(u16).range(1..=1024), conflicts_with = "slurm")]
        threads: Option<u16>,
        /// Also write mc.json and plots to this directory; with --shard, where the
        /// partial (partial-I-of-N.json) goes; with --slurm, where campaign.sh goes.
        #[arg(long, value_name = "DIR")]
        out: Option<PathBuf>,
        /// Print one JSON object on stdout instead of the table.
        #[arg(long, conflicts_with_all = ["shard", "slurm"])]
        json: bool,
        /// Compute share I of N of the (cell, run) pairs (pair j = cell x runs + run
        /// goes to share j mod N) and write it as DIR/partial-I-of-N.json (needs --out).
        #[arg(long, value_name = "I/N", requires = "out", conflicts_with = "slurm")]
        shard: Option<onebeacon_sim::montecarlo::Shard>,
        /// Write (with --out DIR) or print a Slurm submission script: an array job of N
        /// shards (sbatch --array=0-(N-1)) and a merge job after them.
        #[arg(long, value_name = "N", value_parser = clap::value_parser!(u32).range(1..=100_000))]
        slurm: Option<u32>,
        /// --slurm: the partition (sbatch --partition).
        #[arg(long, requires = "slurm")]
        partition: Option<String>,
        /// --slurm: each job's time limit (sbatch --time, e.g. 02:00:00).
        #[arg(long, requires = "slurm")]
        time: Option<String>,
        /// --slurm: the account to charge (sbatch --account).
        #[arg(long, requires = "slurm")]
        account: Option<String>,
        /// --slurm: cores per shard (sbatch --cpus-per-task; the shard's --threads).
        #[arg(long, requires = "slurm", default_value_t = 1, value_parser = clap::value_parser!(u16).range(1..=1024))]
        cpus_per_task: u16,
    },
    /// Recorded runs of a fleet scenario (rypkema-m1, rypkema-m6) with its mission
    /// statistics: the 2-norm error's 68 % and 95 % per AUV and estimator and for the
    /// fleet, when every AUV confirmed every command, the formation's spacing and the
    /// survey's coverage; tracks.png, modes.png, error.png, particles.png,
    /// trajectory.csv (run 0) and fleet.json in DIR.
    Fleet {
        /// Built-in scenario name or path of a TOML file of kind "fleet".
        scenario: String,
        /// Runs (default: the scenario's `runs`).
        #[arg(long, value_parser = clap::value_parser!(u32).range(1..=10_000))]
        runs: Option<u32>,
        /// Base seed (default: the scenario's `seed`).
        #[arg(long)]
        seed: Option<u64>,
        /// Worker threads (default: one per core). Results do not depend on it.
        #[arg(long, value_parser = clap::value_parser!(u16).range(1..=1024))]
        threads: Option<u16>,
        /// The time of run 0 whose particles particles.png draws, s.
        #[arg(long, default_value_t = 600.0, value_name = "T")]
        snapshot_s: f64,
        /// Output directory (default: out/<scenario>-fleet).
        #[arg(long, value_name = "DIR")]
        out: Option<PathBuf>,
        /// Print one JSON object on stdout instead of the table.
        #[arg(long)]
        json: bool,
    },
    /// Acoustic signal chain: simulate one ping as a WAV, or process a WAV.
    Dsp {
        #[command(subcommand)]
        command: DspCommand,
    },
    /// Replay a real log (CSV files described by a TOML file) through every estimator it
    /// configures, scored against its ground truth: trajectory.csv, summary.json,
    /// rejected.csv, top_view.png and error.png in DIR, and a table (or --json).
    Replay {
        /// The log description (TOML; see docs/logs.md).
        log: PathBuf,
        /// Output directory (default: out/<log>-replay[-beacons-...]).
        #[arg(long, value_name = "DIR")]
        out: Option<PathBuf>,
        /// Use only these beacons (ids, comma-separated), e.g. one at a time.
        #[arg(long, value_delimiter = ',', value_name = "IDS")]
        beacons: Option<Vec<u32>>,
        /// Print one JSON object, summary.json, instead of the table (docs/outputs.md
        /// lists every key: the start, warnings, noise, reference, holdout, and per
        /// estimator its errors, NEES, NIS, calibration and per-beacon innovations).
        #[arg(long)]
        json: bool,
        /// Print the merged, time-ordered stream as JSON Lines (the input of `stream`)
        /// and stop; with --beacons, the measurements of those beacons only.
        #[arg(long, conflicts_with_all = ["json", "out", "holdout"])]
        print_stream: bool,
        /// Run the `[[estimators]]` of this TOML file instead of the log's (what `tune`
        /// writes).
        #[arg(long, value_name = "FILE")]
        estimators: Option<PathBuf>,
        /// Leave each of these beacons out in turn (ids, comma-separated, or `all`): every
        /// estimator runs without it and predicts its ranges; the residual RMS, mean and
        /// mean NIS of those predictions (a score without ground truth) go to the table,
        /// holdout.csv and summary.json's `holdout`.
        #[arg(long, value_delimiter = ',', value_name = "IDS|all")]
        holdout: Option<Vec<String>>,
    },
    /// Smooth a log after the dive: every pose at once (sparse nonlinear least squares
    /// over the motion, heading, range, Doppler and USBL measurements, with calibration
    /// variables and a heavy-tailed kernel; docs/smooth.md), beside the log's filters:
    /// trajectory.csv (a `smoother` column), summary.json, top_view.png and error.png in
    /// DIR, and the replay's table with a `smoother` line (or --json).
    Smooth {
        /// The log description (TOML; see docs/logs.md).
        log: PathBuf,
        /// Output directory (default: out/<log>-smooth[-beacons-...]).
        #[arg(long, value_name = "DIR")]
        out: Option<PathBuf>,
        /// Use only these beacons (ids, comma-separated).
        #[arg(long, value_delimiter = ',', value_name = "IDS")]
        beacons: Option<Vec<u32>>,
        /// Weigh the measurements as this estimator of the log does (its noise, kernel,
        /// gate and calibration); default: the log's [noise] (the filters' defaults for
        /// keys it does not give), a Huber kernel and the calibration variables
        /// range_scale and turn_scale.
        #[arg(long, value_name = "ESTIMATOR")]
        like: Option<String>,
        /// Read the `[[estimators]]` of this TOML file instead of the log's (for the
        /// filters beside the smoother and for --like).
        #[arg(long, value_name = "FILE")]
        estimators: Option<PathBuf>,
        /// The calibration variables (comma-separated): none, all, range_scale,
        /// turn_scale, distance_scale, offsets (one per beacon), shared_offset,
        /// clock_drift.
        #[arg(long, value_delimiter = ',', value_name = "VARS")]
        calibrate: Option<Vec<String>>,
        /// The kernel of ranges, Doppler speeds, bearings and heading fixes: none,
        /// huber (k 1.345), cauchy (k 2.3849), student_t (4 dof).
        #[arg(long, value_name = "KERNEL")]
        kernel: Option<String>,
        /// Smooth a craft that sends no motion data with a constant-velocity model:
        /// the white acceleration's sqrt spectral density, m/s^1.5 (the key
        /// track_accel_sigma_m_s2; docs/smooth.md). Motion rows and heading fixes are
        /// then not read.
        #[arg(long, value_name = "SIGMA")]
        track_accel: Option<f64>,
        /// Print one JSON object (the summary) instead of the table.
        #[arg(long)]
        json: bool,
    },
    /// Fit estimators' noise keys to a log: the values that maximise the likelihood of
    /// their innovations (no ground truth needed). Writes estimators.toml (the log's
    /// estimators, tuned, for `replay --estimators` on another log) and tune.json.
    Tune {
        /// The log description (TOML).
        log: PathBuf,
        /// The estimators to tune (names, comma-separated; default: every one that uses
        /// ranges or Doppler).
        #[arg(long, value_delimiter = ',', value_name = "NAMES")]
        estimators: Option<Vec<String>>,
        /// The keys to fit (default: range_sigma_m, distance_sigma_frac,
        /// heading_change_sigma_frac, heading_walk_deg_per_sqrt_m).
        #[arg(long, value_delimiter = ',', value_name = "KEYS")]
        keys: Option<Vec<String>>,
        /// Use only these beacons (ids, comma-separated).
        #[arg(long, value_delimiter = ',', value_name = "IDS")]
        beacons: Option<Vec<u32>>,
        /// Fit to the log with its beacons together and with each beacon alone (the
        /// likelihoods multiplied): noise that also serves single-beacon navigation.
        #[arg(long)]
        each_beacon: bool,
        /// Output directory (default: out/<log>-tune).
        #[arg(long, value_name = "DIR")]
        out: Option<PathBuf>,
        /// Print one JSON object instead of the table.
        #[arg(long)]
        json: bool,
    },
    /// Fit the sea of a log: per beacon its range noise, bias, scale, drift, multipath
    /// and false detections, the lost messages, the heading bias, the speed scale and
    /// the current, against its ground truth (or the smoother's trajectory), each with
    /// a 95 % interval. Writes sea.toml (a `[sea]` table for a scenario, each value's
    /// source beside it) and sea-fit.json; prints the table (docs/logs.md, "The sea of
    /// a log").
    SeaFit {
        /// The log description (TOML).
        log: PathBuf,
        /// Use only these beacons (ids, comma-separated).
        #[arg(long, value_delimiter = ',', value_name = "IDS")]
        beacons: Option<Vec<u32>>,
        /// The windows over which the speed scale, the current and the odometry's scales
        /// are fitted, s.
        #[arg(long, value_name = "S", default_value_t = 60.0)]
        window_s: f64,
        /// Output directory (default: out/<log>-sea).
        #[arg(long, value_name = "DIR")]
        out: Option<PathBuf>,
        /// Print one JSON object instead of the table.
        #[arg(long)]
        json: bool,
    },
    /// Simulate a log's mission again with a fitted sea (the log's truth, beacons and
    /// measurement times; each value drawn anew), run its estimators on every run, and
    /// compare their RMSE, final error and NEES with the log's own replay, per beacon
    /// set; writes twin.csv, twin.json, twin.png (docs/logs.md, "The twin of a log").
    Twin {
        /// The log description (TOML).
        log: PathBuf,
        #[command(flatten)]
        args: twin::TwinArgs,
    },
    /// Run the estimators of CONFIG on JSON Lines measurements from stdin, writing one
    /// JSON line of estimates per input line to stdout, flushed after each.
    Stream {
        /// Log description or stream configuration (TOML): frame, beacons, initial
        /// state, estimators; its [[source]] tables are ignored.
        config: PathBuf,
    },
    /// Run the vehicle's computer of CONFIG as a ROS 2 node: its live topics in, per
    /// estimator nav_msgs/Odometry, the waypoint and diagnostics out (docs/ros2.md).
    #[cfg(feature = "ros2")]
    Ros2(ros2::Ros2Args),
    /// Beacon-vehicle guidance tools.
    Guidance {
        #[command(subcommand)]
        command: GuidanceCommand,
    },
}

#[derive(Debug, Subcommand)]
enum McCommand {
    /// Combine the partials of every shard of `mc --shard I/N` into what the unsharded
    /// `mc` gives, bit for bit; refuses partials of different scenarios, seeds, runs or
    /// versions, and missing or duplicate shares.
    Merge {
        /// Directories holding partial-*-of-*.json files, or partial files.
        #[arg(required = true, value_name = "DIR|FILE")]
        partials: Vec<PathBuf>,
        /// Also write mc.json and plots to this directory.
        #[arg(long, value_name = "DIR")]
        out: Option<PathBuf>,
        /// Print one JSON object on stdout instead of the table.
        #[arg(long)]
        json: bool,
    },
}

#[derive(Debug, Subcommand)]
enum DspCommand {
    /// Simulate one ping on every element of the array: a multichannel float WAV and a
    /// JSON sidecar with the truth (range_m, azimuth_deg, inclination_deg, mode, ...).
    Simulate {
        /// Ping configuration (TOML; every key optional; see docs/scenarios.md).
        #[arg(long, value_name = "FILE")]
        config: Option<String>,
        /// The WAV to write; the sidecar gets the same name with .json.
        #[arg(long, value_name = "FILE.wav")]
        out: PathBuf,
    },
    /// Run the receiver on a multichannel WAV (simulated or recorded): mode, range,
    /// azimuth and inclination.
    Process {
        /// The WAV: one channel per array element, starting at the transmit epoch.
        wav: PathBuf,
        /// Ping configuration: array, sample rate, sound speed (defaults as simulate).
        #[arg(long, value_name = "FILE")]
        config: Option<String>,
        /// Also write range.csv, range.png, beam.png and estimate.json here.
        #[arg(long, value_name = "DIR")]
        out: Option<PathBuf>,
        /// Print one JSON object with the estimates.
        #[arg(long)]
        json: bool,
    },
}

#[derive(Debug, Subcommand)]
enum GuidanceCommand {
    /// Best initial horizontal distance between a surface beacon and a target at each
    /// depth (sousa Fig. 4.7-4.8): the distance whose best second ping, within the
    /// ASV's reach (speed x period), carries the most Fisher information.
    Standoff {
        /// ASV maximum speed, m/s.
        #[arg(long, value_parser = positive_f64)]
        speed_m_s: f64,
        /// Target depths, m, comma-separated.
        #[arg(long, value_delimiter = ',', required = true, value_parser = non_negative_f64)]
        depths_m: Vec<f64>,
        /// Time between pings, s.
        #[arg(long, default_value_t = 10.0, value_parser = positive_f64)]
        period_s: f64,
        /// Print one JSON object on stdout instead of the table.
        #[arg(long)]
        json: bool,
    },
}

fn parse_finite(s: &str) -> Result<f64, String> {
    s.trim().parse::<f64>().ok().filter(|v| v.is_finite()).ok_or_else(|| format!("`{s}` is not a finite number"))
}

fn positive_f64(s: &str) -> Result<f64, String> {
    parse_finite(s).and_then(|v| if v > 0.0 { Ok(v) } else { Err(format!("{v} must be > 0")) })
}

fn non_negative_f64(s: &str) -> Result<f64, String> {
    parse_finite(s).and_then(|v| if v >= 0.0 { Ok(v) } else { Err(format!("{v} must be >= 0")) })
}

/// Input the user can fix (flags, scenario, output path): exit status 2.
#[derive(Debug, thiserror::Error)]
#[error("{0}")]
pub struct BadInput(pub String);

fn main() -> ExitCode {
    // Rust ignores SIGPIPE, so printing into a closed pipe (`| head`, a reader that
    // quit) would panic; the default action ends the process quietly instead.
    #[cfg(unix)]
    // SAFETY: called first thing, before any other thread exists
    unsafe {
        libc::signal(libc::SIGPIPE, libc::SIG_DFL);
    }
    output::remove_staging_on_signals();
    let cli = match Cli::try_parse() {
        Ok(cli) => cli,
        Err(e) => {
            use clap::error::ErrorKind::*;
            if matches!(e.kind(), DisplayHelp | DisplayVersion | DisplayHelpOnMissingArgumentOrSubcommand) {
                let _ = e.print();
                return if e.kind() == DisplayHelpOnMissingArgumentOrSubcommand {
                    ExitCode::from(2)
                } else {
                    ExitCode::SUCCESS
                };
            }
            // one line: clap's message up to its usage block, which names the flag and
            // what is allowed
            let text = e.to_string();
            let message: Vec<&str> =
                text.lines().map(str::trim).take_while(|l| !l.is_empty() && !l.starts_with("Usage:")).collect();
            let message = message.join(" ");
            eprintln!("error: {} (see `onebeacon --help`)", message.trim_start_matches("error: "));
            return ExitCode::from(2);
        }
    };
    match onebeacon_sim::budget::Budget::resolve(cli.memory_gib) {
        Ok(b) => {
            let _ = BUDGET.set(b);
        }
        Err(e) => {
            eprintln!("error: {e}");
            return ExitCode::from(2);
        }
    }
    // the lanes' instruction set, capped by ONEBEACON_SIMD: a name it does not know is
    // refused here (the library ignores it)
    if let Ok(v) = std::env::var(onebeacon::filter::lanes::Level::VARIABLE)
        && let Err(e) = onebeacon::filter::lanes::Level::parse(&v)
    {
        eprintln!("error: {e}");
        return ExitCode::from(2);
    }
    let result = match cli.command {
        Command::Scenarios { show } => commands::scenarios(show.as_deref()),
        Command::Run { scenario, seed, run, ping, message, out, messages } => {
            commands::run(&scenario, seed, run, ping, message, out, messages)
        }
        Command::Mc { merge: Some(McCommand::Merge { partials, out, json }), .. } => {
            campaign::merge_partials(&partials, out, json)
        }
        Command::Mc {
            merge: None,
            scenario,
            runs,
            seed,
            threads,
            out,
            json,
            shard,
            slurm,
            partition,
            time,
            account,
            cpus_per_task,
        } => {
            let scenario = scenario.expect("clap requires it without a subcommand");
            let (runs, threads) = (runs.map(|r| r as usize), threads.map(usize::from));
            match (shard, slurm) {
                (Some(shard), _) => {
                    campaign::shard(&scenario, runs, seed, threads, shard, &out.expect("clap requires it"))
                }
                (None, Some(n)) => {
                    let slurm = campaign::Slurm { shards: n as usize, partition, time, cpus_per_task, account };
                    campaign::slurm(&scenario, runs, seed, &slurm, out)
                }
                (None, None) => commands::mc(&scenario, runs, seed, threads, out, json),
            }
        }
        Command::Fleet { scenario, runs, seed, threads, snapshot_s, out, json } => {
            fleet::fleet(&scenario, runs.map(|r| r as usize), seed, threads.map(usize::from), snapshot_s, out, json)
        }
        Command::Dsp { command: DspCommand::Simulate { config, out } } => dsp::simulate(config.as_deref(), &out),
        Command::Dsp { command: DspCommand::Process { wav, config, out, json } } => {
            dsp::process(&wav, config.as_deref(), out, json)
        }
        Command::Replay { log, out, beacons, json, print_stream, estimators, holdout } => replay::replay(
            &log,
            replay::ReplayArgs {
                out,
                beacons,
                as_json: json,
                print_stream,
                estimators: estimators.as_deref(),
                holdout,
            },
        ),
        Command::Smooth { log, out, beacons, like, estimators, calibrate, kernel, track_accel, json } => {
            smooth::smooth(
                &log,
                smooth::SmoothArgs { out, beacons, json, like, estimators, calibrate, kernel, track_accel },
            )
        }
        Command::Tune { log, estimators, keys, beacons, each_beacon, out, json } => {
            tune::tune(&log, tune::TuneArgs { estimators, keys, beacons, each_beacon, out, json })
        }
        Command::SeaFit { log, beacons, window_s, out, json } => {
            sea_fit::sea_fit(&log, sea_fit::SeaFitArgs { beacons, window_s, out, json })
        }
        Command::Twin { log, args } => twin::run(&log, args),
        Command::Stream { config } => replay::stream(&config),
        #[cfg(feature = "ros2")]
        Command::Ros2(args) => ros2::run(args),
        Command::Guidance { command: GuidanceCommand::Standoff { speed_m_s, depths_m, period_s, json } } => {
            commands::standoff(speed_m_s, &depths_m, period_s, json)
        }
    };
    // what is still buffered must reach stdout too
    let result = result.and_then(|()| std::io::Write::flush(&mut std::io::stdout()).map_err(stdout_error));
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            let msg = format!("{e:#}").replace('\n', " ");
            eprintln!("error: {msg}");
            let input = e.downcast_ref::<onebeacon_sim::ScenarioError>().is_some()
                || e.downcast_ref::<onebeacon::log::LogError>().is_some()
                || e.downcast_ref::<BadInput>().is_some();
            ExitCode::from(if input { 2 } else { 1 })
        }
    }
}
