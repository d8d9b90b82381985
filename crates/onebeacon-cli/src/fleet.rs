//! `onebeacon fleet`: recorded runs of a fleet scenario (rypkema) with its mission
//! statistics, and the pictures of the first run.

use crate::output::Staging;
use crate::{BadInput, plot, report};
use anyhow::{Context, Result};
use onebeacon_sim::fleet::{FleetStatistics, commands, statistics};
use onebeacon_sim::run::{RunOutput, simulate, simulate_with_belief};
use onebeacon_sim::scenario::{self, Cell, Scenario};
use rayon::prelude::*;
use std::fmt::Write as _;
use std::path::PathBuf;
use std::time::Instant;

/// Particles kept for particles.png (the whole set of 500).
const SNAPSHOT_PARTICLES: usize = 500;

/// The paper's Table 3 (all six missions, real data), for the table.
const PAPER_P68_M: f64 = 7.89;
const PAPER_P95_M: f64 = 22.74;

/// `onebeacon fleet SCENARIO [--runs N] [--seed N] [--threads N] [--snapshot-s T] [--out DIR] [--json]`
pub fn fleet(
    name: &str,
    runs: Option<usize>,
    seed: Option<u64>,
    threads: Option<usize>,
    snapshot_s: f64,
    out: Option<PathBuf>,
    json: bool,
) -> Result<()> {
    let s = scenario::load(name)?;
    let Scenario::Fleet(f) = &s else {
        return Err(BadInput(format!(
            "{name}: `fleet` takes a scenario of kind \"fleet\" (rypkema-m1, rypkema-m6); use `run` or `mc` for this one"
        ))
        .into());
    };
    if !(0.0..=f.mission.duration_s).contains(&snapshot_s) {
        return Err(BadInput(format!(
            "--snapshot-s {snapshot_s}: must be within the mission, 0 to {} s",
            f.mission.duration_s
        ))
        .into());
    }
    let runs = runs.unwrap_or(s.runs());
    let seed = seed.unwrap_or(s.seed());
    crate::check_memory(name, &s, onebeacon_sim::budget::concurrent_runs(threads, runs), runs)?;
    let dir = out.unwrap_or_else(|| PathBuf::from("out").join(format!("{}-fleet", s.name())));
    let staging = Staging::new(&dir, &crate::commands::scenario_inputs(name))?;
    let bar = crate::progress::Progress::new(runs as u64, "runs", format!("fleet {}", s.name()));
    let step = (snapshot_s / f.mission.dt_s).round() as usize;
    let start = Instant::now();
    let work = || -> Vec<RunOutput> {
        (0..runs as u64)
            .into_par_iter()
            .map(|r| {
                let out = if r == 0 {
                    simulate_with_belief(&s, &Cell::Fleet, seed, r, step, SNAPSHOT_PARTICLES)
                } else {
                    simulate(&s, &Cell::Fleet, seed, r, true)
                };
                bar.inc(1);
                out
            })
            .collect()
    };
    let outputs = match threads {
        Some(n) => rayon::ThreadPoolBuilder::new()
            .num_threads(n)
            .build()
            .map_err(|e| BadInput(format!("--threads {n}: {e}")))?
            .install(work),
        None => work(),
    };
    let wall_s = start.elapsed().as_secs_f64();
    bar.finish();
    let stats = statistics(f, seed, &outputs);

    let first = &outputs[0];
    let (vehicles, names) = (s.vehicle_names(), s.track_labels());
    let title = format!("{} seed {seed} run 0", s.name());
    staging.write("trajectory.csv", &report::trajectory_csv(&vehicles, &names, &first.trajectory)?)?;
    let json_text = serde_json::json!({"scenario": s.name(), "seed": seed, "wall_s": wall_s, "statistics": stats});
    staging.write("fleet.json", json_text.to_string().as_bytes())?;
    plot::fleet_tracks(&staging.file("tracks.png"), &vehicles, &title, &first.trajectory)
        .context("cannot draw tracks.png")?;
    plot::fleet_modes(&staging.file("modes.png"), &vehicles, &title, &first.trajectory, &commands(f))
        .context("cannot draw modes.png")?;
    plot::error_vs_time(&staging.file("error.png"), &names, &title, &first.trajectory)
        .context("cannot draw error.png")?;
    if let Some(b) = &first.belief {
        plot::factored_snapshot(&staging.file("particles.png"), b).context("cannot draw particles.png")?;
    }
    let files = staging.commit()?;
    if json {
        outln!("{json_text}");
    } else {
        out!("{}", table(s.name(), seed, wall_s, &stats));
        outln!("wrote:");
        for f in files {
            outln!("  {}", f.display());
        }
    }
    Ok(())
}

fn table(name: &str, seed: u64, wall_s: f64, st: &FleetStatistics) -> String {
    let mut t = String::new();
    let _ = writeln!(t, "{name}: {} runs from seed {seed} in {wall_s:.0} s", st.runs);
    let _ = writeln!(
        t,
        "2-norm error while submerged (m)   {:>8} {:>8} {:>8} {:>9} {:>8} {:>13}",
        "68 %", "95 %", "mean", "steps", "nees", "nees_band95"
    );
    for e in st.tracks.iter().chain(&st.fleet) {
        let (nees, band) = if e.nees_mean.is_nan() {
            ("-".to_string(), "-".to_string())
        } else {
            (format!("{:.2}", e.nees_mean), format!("{:.2}-{:.2}", e.nees_band[0], e.nees_band[1]))
        };
        let _ = writeln!(
            t,
            "  {:<32} {:>8.2} {:>8.2} {:>8.2} {:>9} {nees:>8} {band:>13}",
            e.label, e.p68_m, e.p95_m, e.mean_m, e.samples
        );
    }
    let _ =
        writeln!(t, "  {:<32} {PAPER_P68_M:>8.2} {PAPER_P95_M:>8.2}   (rypkema Table 3, real data)", "paper, all AUVs");
    let _ = writeln!(
        t,
        "modes: every AUV confirmed every command in every run: {}; largest delay {:.1} s",
        if st.all_confirmed { "yes" } else { "NO" },
        st.max_delay_s
    );
    for c in &st.confirmations {
        let delay = c.delay_s.map_or("never".to_string(), |d| format!("+{d:.1} s"));
        let _ =
            writeln!(t, "  run 0: {:<10} mode {} commanded at {:>6.0} s: {delay}", c.vehicle, c.mode, c.commanded_s);
    }
    if let Some(sp) = &st.spacing {
        let _ = writeln!(
            t,
            "formation (offset follow, from 300 s after the command): spacing error over {} pairs, {} samples: \
             mean |e| {:.1} m, rms {:.1} m, 95 % |e| {:.1} m",
            sp.pairs, sp.samples, sp.mean_abs_error_m, sp.rms_error_m, sp.p95_abs_error_m
        );
    }
    if let Some(c) = &st.coverage {
        let _ = writeln!(
            t,
            "trackline survey (run 0): {:.0} m2 of {:.0} m cells visited, extent {:.0} m across x {:.0} m along the lines",
            c.area_m2, c.cell_m, c.across_m, c.along_m
        );
    }
    t
}
