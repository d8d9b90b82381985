//! `onebeacon twin`: a log's mission simulated again with a fitted sea, its estimators
//! scored on every run beside the log's own replay.

use crate::BadInput;
use crate::output::Staging;
use anyhow::{Context, Result};
use onebeacon::log::Log;
use onebeacon_sim::montecarlo::Shard;
use onebeacon_sim::scenario::sea::Sea;
use onebeacon_sim::twin::partial::{MergedTwin, TwinPartial, merge_twin, read_twin_partials};
use onebeacon_sim::twin::{NEES_FACTOR, Twin, TwinError, TwinOptions, twin};
use serde_json::json;
use std::collections::BTreeSet;
use std::path::{Path, PathBuf};

/// What `twin` is asked besides the log (its command-line options).
#[derive(Debug, clap::Args)]
pub struct TwinArgs {
    /// The sea: a file with a [sea] table (`onebeacon sea-fit` writes sea.toml).
    #[arg(long, value_name = "SEA.toml")]
    pub sea: PathBuf,
    /// Simulated runs.
    #[arg(long, default_value_t = 50, value_parser = clap::value_parser!(u32).range(1..=100_000), conflicts_with = "merge")]
    pub runs: u32,
    /// Base seed.
    #[arg(long, default_value_t = 1, conflicts_with = "merge")]
    pub seed: u64,
    /// Worker threads (default: one per core). Results do not depend on it.
    #[arg(long, value_parser = clap::value_parser!(u16).range(1..=1024), conflicts_with = "merge")]
    pub threads: Option<u16>,
    /// One beacon set (ids, comma-separated; default: all the beacons, then each alone).
    #[arg(long, value_delimiter = ',', value_name = "IDS")]
    pub beacons: Option<Vec<u32>>,
    /// Output directory (default: out/<log>-twin); with --shard, where the partial
    /// (partial-I-of-N.json) goes.
    #[arg(long, value_name = "DIR")]
    pub out: Option<PathBuf>,
    /// Print one JSON object instead of the table.
    #[arg(long, conflicts_with = "shard")]
    pub json: bool,
    /// Simulate share I of N of the runs (run j goes to share j mod N) and write it as
    /// DIR/partial-I-of-N.json; `--merge` puts the shares together.
    #[arg(long, value_name = "I/N", conflicts_with = "merge")]
    pub shard: Option<Shard>,
    /// Put the shares of `--shard` together (their directories or partial files) into
    /// what the unsharded command prints and writes; the log, --sea and --beacons must
    /// be the shares' (their runs and seed are taken from them).
    #[arg(long, num_args = 1.., value_name = "DIR|FILE")]
    pub merge: Option<Vec<PathBuf>>,
}

/// A `[sea]` table read from `path` (a sea-fit's sea.toml, or any file whose `[sea]`
/// table the scenario format takes, other tables ignored).
fn read_sea(path: &Path) -> Result<Sea> {
    #[derive(serde::Deserialize)]
    struct File {
        sea: Option<Sea>,
    }
    let at = path.display();
    let text = onebeacon::io::file::read_text(path).map_err(|e| BadInput(format!("--sea {at}: {e}")))?;
    let file: File = toml::from_str(&text).map_err(|e| {
        let line = e.span().map_or(String::new(), |s| format!("line {}: ", text[..s.start].matches('\n').count() + 1));
        BadInput(format!("--sea {at}: {line}{}", e.message().replace('\n', " ")))
    })?;
    file.sea.ok_or_else(|| BadInput(format!("--sea {at}: no [sea] table (`onebeacon sea-fit LOG` writes one)")).into())
}

/// `onebeacon twin LOG.toml --sea SEA.toml [--runs 50] [--seed 1] [--threads N]
/// [--beacons IDS] [--out DIR] [--json]`: writes twin.csv, twin.json and twin.png in DIR
/// (default out/<log>-twin), prints the table (or the JSON). With `--shard I/N`, the
/// share's runs alone, as DIR/partial-I-of-N.json; with `--merge PATHS`, the shares'
/// runs instead of new ones.
pub fn run(path: &Path, a: TwinArgs) -> Result<()> {
    let (runs_asked, threads) = (a.runs as usize, a.threads.map(usize::from));
    let log = Log::load(path)?;
    let sea = read_sea(&a.sea)?;
    sea.check_twin().map_err(|e| BadInput(format!("--sea {}: {e}", a.sea.display())))?;
    let concurrent = onebeacon_sim::budget::concurrent_runs(threads, runs_asked);
    crate::budget().check_twin(&log, concurrent).map_err(|e| BadInput(e.to_string()))?;
    let known = log.beacon_ids();
    let sets: Vec<Option<BTreeSet<u32>>> = match crate::replay::beacon_filter(a.beacons, &known)? {
        Some(set) => vec![Some(set)],
        // all the beacons, then each alone
        None if known.len() > 1 => {
            std::iter::once(None).chain(known.iter().map(|b| Some(BTreeSet::from([*b])))).collect()
        }
        None => vec![None],
    };
    let name = log.description.name.clone();
    let dir = a.out.unwrap_or_else(|| PathBuf::from("out").join(format!("{name}-twin")));
    let mut inputs = log.files();
    inputs.push(a.sea.clone());
    inputs.extend(a.merge.iter().flatten().cloned());
    let shard = a.shard.unwrap_or(Shard::WHOLE);
    if shard.count > runs_asked {
        return Err(BadInput(format!("--shard {shard}: {runs_asked} runs cut into at most {runs_asked} shares")).into());
    }
    // the output is staged before the runs: a directory that cannot take it fails first
    let partial_file = onebeacon_sim::partial::file_name(shard);
    let staging = match a.shard {
        Some(_) => Staging::beside(&dir, &[&partial_file])?,
        None => Staging::new(&dir, &inputs)?,
    };
    let started = std::time::Instant::now();
    let runs = if a.merge.is_some() { 0 } else { runs_asked };
    let opts = TwinOptions { runs, seed: a.seed, threads, sets, shard };
    // a merge simulates nothing: the replay alone, without a progress line
    let bar =
        (runs > 0).then(|| crate::progress::Progress::new(shard.len(runs) as u64, "runs", format!("twin of {name}")));
    let t = twin(&log, &sea, &opts, &|| bar.iter().for_each(|b| b.inc(1))).map_err(|e| match e {
        TwinError::Sea(m) => anyhow::Error::from(BadInput(format!("--sea {}: {m}", a.sea.display()))),
        e => e.into(),
    })?;
    bar.iter().for_each(|b| b.finish());
    let (t, runs, seed, wall_s) = match &a.merge {
        Some(paths) => {
            let bad = |e: onebeacon_sim::partial::MergeError| BadInput(e.to_string());
            let partials = read_twin_partials(paths, &crate::budget()).map_err(bad)?;
            let MergedTwin { twin, runs, seed, wall_s } = merge_twin(&name, t, &sea, partials).map_err(bad)?;
            (twin, runs, seed, wall_s)
        }
        None => (t, runs_asked, a.seed, started.elapsed().as_secs_f64()),
    };
    if a.shard.is_some() {
        let partial = TwinPartial::new(&name, &sea, &t, runs, seed, shard, wall_s);
        staging.write(&partial_file, partial.to_json().as_bytes())?;
        for f in staging.move_files_to()? {
            eprintln!("wrote {} ({} of {runs} runs)", f.display(), t.run_indices.len());
        }
        return Ok(());
    }
    let summary = to_json(&t, &name, &a.sea, runs, seed, wall_s);
    staging.write("twin.json", serde_json::to_string_pretty(&summary)?.as_bytes())?;
    staging.write("twin.csv", to_csv(&t)?.as_bytes())?;
    let title = format!("{name}: twin with {} ({runs} runs)", a.sea.display());
    crate::plot::twin_bands(&staging.file("twin.png"), &title, &t).context("cannot draw twin.png")?;
    let files = staging.commit()?;
    if a.json {
        outln!("{summary}");
        return Ok(());
    }
    print_table(&t, &title, wall_s)?;
    outln!("wrote:");
    for f in files {
        outln!("  {}", f.display());
    }
    Ok(())
}

fn set_label(beacons: &[u32]) -> String {
    beacons.iter().map(u32::to_string).collect::<Vec<_>>().join("+")
}

fn print_table(t: &Twin, title: &str, wall_s: f64) -> Result<()> {
    outln!("{title}: truth from the {}, {:.1} s", t.reference, wall_s);
    for n in &t.notes {
        outln!("note: {n}");
    }
    for (what, count) in &t.kept {
        outln!("kept as logged: {count} x {what}");
    }
    outln!(
        "{:<10} {:<16} {:>8} {:>24} {:>3} {:>8} {:>24} {:>6}",
        "beacons",
        "estimator",
        "rmse_m",
        "twin rmse_m 50 [5, 95]",
        "in",
        "nees",
        "twin nees 50 [5, 95]",
        "ratio"
    );
    let band = |b: onebeacon_sim::twin::Band| format!("{:.3} [{:.3}, {:.3}]", b.median, b.p5, b.p95);
    for c in &t.cells {
        let r = c.rmse();
        outln!(
            "{:<10} {:<16} {:>8.3} {:>24} {:>3} {:>8.2} {:>24} {:>6.2}",
            set_label(&c.beacons),
            c.estimator,
            c.real.rmse_m,
            band(r),
            match (c.real.rmse_m.is_finite(), r.holds(c.real.rmse_m)) {
                (false, _) => "-",
                (true, true) => "yes",
                (true, false) => "no",
            },
            c.real.nees,
            band(c.nees()),
            c.nees_ratio()
        );
    }
    let ((rmse, cells), (nees, with)) = t.agreement();
    outln!(
        "real RMSE within the twin's 5-95 % band: {rmse} of {cells} cells; real NEES within {NEES_FACTOR}x of the twin's median: {nees} of {with}"
    );
    Ok(())
}

fn to_csv(t: &Twin) -> Result<String> {
    let mut w = csv::Writer::from_writer(Vec::new());
    w.write_record([
        "beacons",
        "estimator",
        "real_rmse_m",
        "twin_rmse_p5_m",
        "twin_rmse_median_m",
        "twin_rmse_p95_m",
        "real_final_m",
        "twin_final_p5_m",
        "twin_final_median_m",
        "twin_final_p95_m",
        "real_nees",
        "twin_nees_p5",
        "twin_nees_median",
        "twin_nees_p95",
    ])?;
    for c in &t.cells {
        let (r, f, n) = (c.rmse(), c.final_error(), c.nees());
        let mut row = vec![set_label(&c.beacons), c.estimator.clone()];
        for v in [
            c.real.rmse_m,
            r.p5,
            r.median,
            r.p95,
            c.real.final_m,
            f.p5,
            f.median,
            f.p95,
            c.real.nees,
            n.p5,
            n.median,
            n.p95,
        ] {
            row.push(format!("{v}"));
        }
        w.write_record(&row)?;
    }
    Ok(String::from_utf8(w.into_inner()?)?)
}

fn to_json(t: &Twin, log: &str, sea: &Path, runs: usize, seed: u64, wall_s: f64) -> serde_json::Value {
    let band = |b: onebeacon_sim::twin::Band| json!({"p5": b.p5, "median": b.median, "p95": b.p95});
    let ((rmse, cells), (nees, with)) = t.agreement();
    json!({
        "log": log,
        "sea": sea.display().to_string(),
        "runs": runs,
        "seed": seed,
        "reference": t.reference,
        "notes": t.notes,
        "kept_as_logged": t.kept,
        "cells": t.cells.iter().map(|c| json!({
            "beacons": c.beacons,
            "estimator": c.estimator,
            "real": {"rmse_m": c.real.rmse_m, "final_m": c.real.final_m, "nees": c.real.nees},
            "twin": {"rmse_m": band(c.rmse()), "final_m": band(c.final_error()), "nees": band(c.nees())},
            "rmse_within_band": c.rmse().holds(c.real.rmse_m),
            "nees_ratio": c.nees_ratio(),
        })).collect::<Vec<_>>(),
        "agreement": {"rmse_within_band": rmse, "cells": cells, "nees_within_factor": nees, "cells_with_nees": with, "nees_factor": NEES_FACTOR},
        "wall_s": wall_s,
    })
}
