//! The commands: scenarios, run, mc.

use crate::output::Staging;
use crate::{BadInput, plot, report};
use anyhow::{Context, Result};
use onebeacon::guidance::{PolarGrid, best_standoff};
use onebeacon_sim::montecarlo::monte_carlo;
use onebeacon_sim::run::{GuidanceSnapshot, simulate, simulate_messages, simulate_with_belief};

/// Particles drawn (by weight) for belief.png.
const BELIEF_SAMPLES: usize = 50_000;
use onebeacon_sim::scenario::{self, BUILTINS};
use std::io::Write;
use std::path::{Path, PathBuf};
use std::time::Instant;

/// `onebeacon scenarios [--show NAME]`
pub fn scenarios(show: Option<&str>) -> Result<()> {
    let mut out = std::io::stdout().lock();
    match show {
        Some(name) => {
            let b = scenario::builtin(name).ok_or_else(|| {
                let names: Vec<_> = BUILTINS.iter().map(|b| format!("`{}`", b.name)).collect();
                BadInput(format!("--show {name}: no such built-in scenario; built-ins are {}", names.join(", ")))
            })?;
            out.write_all(b.toml.as_bytes())?;
        }
        None => {
            let width = BUILTINS.iter().map(|b| b.name.len()).max().unwrap_or(0);
            for b in BUILTINS {
                let s = scenario::parse(b.toml, b.name)?;
                writeln!(out, "{:<width$} {}", b.name, s.description())?;
            }
        }
    }
    Ok(())
}

/// `onebeacon run SCENARIO [--seed N] [--run I] [--ping K] [--message M] [--out DIR]`
pub fn run(
    name: &str,
    seed: Option<u64>,
    run: u64,
    ping: usize,
    message: usize,
    out: Option<PathBuf>,
    messages: bool,
) -> Result<()> {
    use onebeacon_sim::Scenario;
    let s = scenario::load(name)?;
    crate::check_memory(name, &s, 1, 1)?;
    let seed = seed.unwrap_or(s.seed());
    let streamable = match &s {
        Scenario::Fleet(f) => f.signal.model == onebeacon_sim::scenario::fleet::SignalModel::Abstract,
        _ => true,
    };
    if messages && !streamable {
        return Err(BadInput(format!(
            "--messages: {}: a fleet's AUVs are streamed with signal.model = \"abstract\" (the channel model's captures are not JSON lines)",
            s.name()
        ))
        .into());
    }
    let dir = out.unwrap_or_else(|| PathBuf::from("out").join(format!("{}-run", s.name())));
    let staging = Staging::new(&dir, &scenario_inputs(name))?;
    let cell = s.base_cell();
    let passive = matches!(s, Scenario::PassiveUsbl(_));
    if passive && !(1..=s.steps()).contains(&message) {
        return Err(BadInput(format!("--message {message}: the run has messages 1 to {}", s.steps())).into());
    }
    let belief = passive.then_some((message, BELIEF_SAMPLES));
    let (result, computers) = if messages {
        simulate_messages(&s, &cell, seed, run, belief)
    } else if passive {
        (simulate_with_belief(&s, &cell, seed, run, message, BELIEF_SAMPLES), None)
    } else {
        (simulate(&s, &cell, seed, run, true), None)
    };
    for c in computers.iter().flatten() {
        let input: String = c.input.iter().map(|l| format!("{l}\n")).collect();
        let decisions: String = c.decisions.iter().map(|d| format!("{d}\n")).collect();
        staging.write(&format!("{}.stream.toml", c.name), c.config.as_bytes())?;
        staging.write(&format!("{}.input.jsonl", c.name), input.as_bytes())?;
        staging.write(&format!("{}.decisions.jsonl", c.name), decisions.as_bytes())?;
    }

    let (vehicles, names) = (s.vehicle_names(), s.track_labels());
    staging.write("trajectory.csv", &report::trajectory_csv(&vehicles, &names, &result.trajectory)?)?;
    staging.write("summary.json", report::run_summary_json(&s, seed, run, &cell, &result).as_bytes())?;
    let title = format!("{} seed {seed} run {run}, {}", s.name(), cell.label());
    plot::top_view(&staging.file("top_view.png"), &vehicles, &names, &title, &result.trajectory, None)
        .context("cannot draw top_view.png")?;
    plot::error_vs_time(&staging.file("error.png"), &names, &title, &result.trajectory)
        .context("cannot draw error.png")?;
    if let Some(b) = &result.belief {
        plot::belief_density(&staging.file("belief.png"), b).context("cannot draw belief.png")?;
    }
    if result.trajectory.iter().any(|r| !r.pilots.is_empty()) {
        plot::autopilots(&staging.file("autopilots.png"), &vehicles, &title, &result.trajectory)
            .context("cannot draw autopilots.png")?;
    }
    if let onebeacon_sim::Scenario::Fleet(f) = &s {
        plot::fleet_tracks(&staging.file("tracks.png"), &vehicles, &title, &result.trajectory)
            .context("cannot draw tracks.png")?;
        let commands = onebeacon_sim::fleet::commands(f);
        plot::fleet_modes(&staging.file("modes.png"), &vehicles, &title, &result.trajectory, &commands)
            .context("cannot draw modes.png")?;
    }
    if !result.guidance.is_empty() {
        let snapshot = result
            .guidance
            .get(ping)
            .ok_or_else(|| BadInput(format!("--ping {ping}: the run has pings 0 to {}", result.guidance.len() - 1)))?;
        match snapshot {
            GuidanceSnapshot::Fim(g) => plot::guidance_map(&staging.file("guidance.png"), g),
            GuidanceSnapshot::Bearing(b) => plot::bearing_map(&staging.file("guidance.png"), b),
        }
        .context("cannot draw guidance.png")?;
    }
    let files = staging.commit()?;
    // what the innovations say without the truth (also summary.json's warnings)
    for w in result.findings(&names) {
        eprintln!("warning: {w}");
    }

    out!("{}", report::run_table(&s, seed, run, &cell, &result));
    outln!("wrote:");
    for f in files {
        outln!("  {}", f.display());
    }
    Ok(())
}

/// The files a command reads for the scenario `name`: its TOML file, or nothing for a
/// built-in one.
pub(crate) fn scenario_inputs(name: &str) -> Vec<PathBuf> {
    let file = Path::new(name);
    if onebeacon_sim::scenario::builtin(name).is_none() && file.exists() { vec![file.to_path_buf()] } else { vec![] }
}

/// `onebeacon mc SCENARIO [--runs N] [--seed N] [--threads N] [--out DIR] [--json]`
pub fn mc(
    name: &str,
    runs: Option<usize>,
    seed: Option<u64>,
    threads: Option<usize>,
    out: Option<PathBuf>,
    json: bool,
) -> Result<()> {
    let s = scenario::load(name)?;
    let runs = runs.unwrap_or(s.runs());
    let seed = seed.unwrap_or(s.seed());
    crate::check_memory(name, &s, onebeacon_sim::budget::concurrent_runs(threads, runs), 0)?;
    // an unwritable --out fails before the runs, not after
    let staging = out.as_deref().map(|d| Staging::new(d, &scenario_inputs(name))).transpose()?;

    let total = (runs * s.cells().len()) as u64;
    let bar = crate::progress::Progress::new(total, "runs", format!("mc {}", s.name()));
    let start = Instant::now();
    let result = monte_carlo(&s, runs, seed, threads, &|| bar.inc(1))?;
    let wall_s = start.elapsed().as_secs_f64();
    bar.finish();

    write_mc(&s, &result, wall_s, staging, json)
}

/// What `mc` and `mc merge` print (the table, or with `json` the JSON object) and write
/// in `staging`'s directory (mc.json, mc_error.png).
pub fn write_mc(
    s: &onebeacon_sim::Scenario,
    result: &onebeacon_sim::montecarlo::McResult,
    wall_s: f64,
    staging: Option<Staging>,
    json: bool,
) -> Result<()> {
    let json_text = report::mc_json(s, result, wall_s);
    if let Some(staging) = staging {
        staging.write("mc.json", json_text.as_bytes())?;
        plot::mc_errors(&staging.file("mc_error.png"), s, result).context("cannot draw mc_error.png")?;
        let files = staging.commit()?;
        if !json {
            for f in files {
                eprintln!("wrote {}", f.display());
            }
        }
    }
    if json {
        outln!("{json_text}");
    } else {
        out!("{}", report::mc_table(s, result, wall_s));
    }
    Ok(())
}

/// `onebeacon guidance standoff --speed-m-s V --depths-m D1,D2,... [--period-s T] [--json]`
pub fn standoff(speed_m_s: f64, depths_m: &[f64], period_s: f64, json: bool) -> Result<()> {
    let reach = speed_m_s * period_s;
    let rows: Vec<_> = depths_m.iter().map(|&d| best_standoff(d, reach, PolarGrid::default())).collect();
    if json {
        let v = serde_json::json!({
            "speed_m_s": speed_m_s,
            "period_s": period_s,
            "reach_m": reach,
            "standoffs": rows.iter().map(|s| serde_json::json!({
                "depth_m": s.depth_m, "distance_m": s.distance_m, "det_fim": s.det_fim,
            })).collect::<Vec<_>>(),
        });
        outln!("{v}");
    } else {
        outln!("ASV at {speed_m_s} m/s, ping every {period_s} s: reach {reach} m (range noise 1 m)");
        outln!("{:>9} {:>12} {:>14}", "depth_m", "standoff_m", "det_fim_1/m4");
        for s in rows {
            outln!("{:>9.2} {:>12.2} {:>14.5}", s.depth_m, s.distance_m, s.det_fim);
        }
    }
    Ok(())
}
