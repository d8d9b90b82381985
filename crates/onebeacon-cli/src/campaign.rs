//! Campaigns on many machines: `mc --shard I/N` (one share of the sweep as a partial
//! file), `mc merge` (the partials into the unsharded result) and `mc --slurm N` (a
//! Slurm array job of the shards with a merge job after it).

use crate::output::Staging;
use crate::{BadInput, commands};
use anyhow::{Context, Result};
use onebeacon_sim::Scenario;
use onebeacon_sim::montecarlo::{Shard, monte_carlo_shard};
use onebeacon_sim::partial::{MergeError, Partial, merge, read_partials};
use onebeacon_sim::scenario;
use std::path::{Path, PathBuf};
use std::time::Instant;

/// `onebeacon mc SCENARIO --shard I/N --out DIR`: writes DIR/partial-I-of-N.json beside
/// the other shards' files (never half-written: staged, then moved in).
pub fn shard(
    name: &str,
    runs: Option<usize>,
    seed: Option<u64>,
    threads: Option<usize>,
    shard: Shard,
    out: &Path,
) -> Result<()> {
    let s = scenario::load(name)?;
    let runs = runs.unwrap_or(s.runs());
    let seed = seed.unwrap_or(s.seed());
    check_shard_count(&s, runs, &format!("--shard {shard}"), shard.count)?;
    crate::check_memory(name, &s, onebeacon_sim::budget::concurrent_runs(threads, runs), 0)?;
    let file = onebeacon_sim::partial::file_name(shard);
    let staging = Staging::beside(out, &[&file])?;
    let total = shard.len(s.cells().len() * runs) as u64;
    let bar = crate::progress::Progress::new(total, "runs", format!("mc {} shard {shard}", s.name()));
    let start = Instant::now();
    let summaries = monte_carlo_shard(&s, runs, seed, shard, threads, &|| bar.inc(1))?;
    bar.finish();
    let partial = Partial::new(&s, runs, seed, shard, start.elapsed().as_secs_f64(), &summaries);
    staging.write(&file, partial.to_json().as_bytes())?;
    for f in staging.move_files_to()? {
        eprintln!("wrote {} ({total} of {} runs)", f.display(), runs * s.cells().len());
    }
    Ok(())
}

/// `onebeacon mc merge DIR|FILE... [--out DIR] [--json]`: what `mc` prints and writes,
/// from the partials of every shard.
pub fn merge_partials(paths: &[PathBuf], out: Option<PathBuf>, json: bool) -> Result<()> {
    let bad = |e: MergeError| BadInput(e.to_string());
    let merged = merge(read_partials(paths, &crate::budget()).map_err(bad)?).map_err(bad)?;
    let staging = out.as_deref().map(|d| Staging::new(d, paths)).transpose()?;
    commands::write_mc(&merged.scenario, &merged.result, merged.wall_s, staging, json)
}

/// Slurm settings of `mc --slurm N`.
pub struct Slurm {
    pub shards: usize,
    pub partition: Option<String>,
    pub time: Option<String>,
    pub cpus_per_task: u16,
    pub account: Option<String>,
}

/// `onebeacon mc SCENARIO --slurm N [--partition P] [--time T] [--cpus-per-task C]
/// [--account A] [--out DIR]`: with --out, DIR/campaign.sh (submit it with `bash`) and
/// DIR/scenario.toml; without, campaign.sh on stdout for the user to adapt.
pub fn slurm(name: &str, runs: Option<usize>, seed: Option<u64>, slurm: &Slurm, out: Option<PathBuf>) -> Result<()> {
    let s = scenario::load(name)?;
    let (runs, seed) = (runs.unwrap_or(s.runs()), seed.unwrap_or(s.seed()));
    check_shard_count(&s, runs, &format!("--slurm {}", slurm.shards), slurm.shards)?;
    let exe = std::env::current_exe().context("cannot find the onebeacon executable")?;
    match out {
        Some(dir) => {
            let dir = absolute(&dir)?;
            let staging = Staging::beside(&dir, &["campaign.sh", "scenario.toml"])?;
            let scenario_file = dir.join("scenario.toml");
            let toml = format!("# the scenario of the campaign written by `onebeacon mc --slurm`\n{}", s.to_toml());
            staging.write("scenario.toml", toml.as_bytes())?;
            let script = campaign_script(&s, &exe, &scenario_file.display().to_string(), runs, seed, slurm, &dir);
            staging.write("campaign.sh", script.as_bytes())?;
            let files = staging.move_files_to()?;
            for f in &files {
                eprintln!("wrote {}", f.display());
            }
            outln!("submit with: bash {}", dir.join("campaign.sh").display());
        }
        None => {
            // a file is named by its absolute path: the jobs may start elsewhere
            let source = if scenario::builtin(name).is_some() {
                name.to_string()
            } else {
                absolute(Path::new(name))?.display().to_string()
            };
            let dir = absolute(&PathBuf::from("out").join(format!("{}-campaign", s.name())))?;
            out!("{}", campaign_script(&s, &exe, &source, runs, seed, slurm, &dir));
        }
    }
    Ok(())
}

/// Bad input where `shards` (given as `flag`) exceed the sweep's (cell, run) pairs: a
/// share would be empty.
fn check_shard_count(s: &Scenario, runs: usize, flag: &str, shards: usize) -> Result<()> {
    let pairs = runs * s.cells().len();
    if shards > pairs {
        return Err(BadInput(format!(
            "{flag}: {} has {pairs} (cell, run) pairs ({} cells x {runs} runs); at most that many shards",
            s.name(),
            s.cells().len()
        ))
        .into());
    }
    Ok(())
}

fn absolute(p: &Path) -> Result<PathBuf> {
    std::path::absolute(p).map_err(|e| BadInput(format!("{}: {e}", p.display())).into())
}

/// Single quotes for the shell.
fn quote(s: &str) -> String {
    format!("'{}'", s.replace('\'', r"'\''"))
}

/// The submission script: the array job of the shards, then the merge job after every
/// shard succeeded (`afterok`).
fn campaign_script(
    s: &Scenario,
    exe: &Path,
    scenario: &str,
    runs: usize,
    seed: u64,
    slurm: &Slurm,
    dir: &Path,
) -> String {
    let n = slurm.shards;
    let mut options = format!(" --cpus-per-task={}", slurm.cpus_per_task);
    for (flag, value) in [("partition", &slurm.partition), ("time", &slurm.time), ("account", &slurm.account)] {
        if let Some(v) = value {
            options.push_str(&format!(" --{flag}={}", quote(v)));
        }
    }
    let name = s.name();
    let cells = s.cells().len();
    format!(
        r#"#!/usr/bin/env bash
# onebeacon mc {name} on Slurm: {cells} cell(s) x {runs} runs (seed {seed}) cut into {n} shards,
# an array job (sbatch --array=0-{last}) whose task I runs `mc --shard I/{n}`, and a merge
# job that starts when every shard succeeded (afterok) and writes the unsharded result.
# Written by `onebeacon mc --slurm`; adapt the sbatch options below to your cluster.
# The executable and OUT must be on a file system that the compute nodes share.
# The job scripts name every path through printf %q: a path is never run as code.
set -euo pipefail
ONEBEACON=${{ONEBEACON:-{exe}}}
SCENARIO={scenario}
OUT=${{OUT:-{dir}}}
SBATCH_OPTIONS=${{SBATCH_OPTIONS:-}}
mkdir -p -- "$OUT/partials" "$OUT/logs"
shard_job=$(printf '#!/usr/bin/env bash\nexec %q mc %q --runs {runs} --seed {seed} --threads "${{SLURM_CPUS_PER_TASK:-1}}" --shard "${{SLURM_ARRAY_TASK_ID}}/{n}" --out %q\n' \
  "$ONEBEACON" "$SCENARIO" "$OUT/partials")
merge_job=$(printf '#!/usr/bin/env bash\nexec %q mc merge %q/partial-*-of-{n}.json --out %q --json\n' \
  "$ONEBEACON" "$OUT/partials" "$OUT/result")
array=$(sbatch --parsable --job-name=onebeacon-{name} --array=0-{last}{options} $SBATCH_OPTIONS \
  --output="$OUT/logs/shard-%a.out" <<<"$shard_job")
array=${{array%%;*}}
merge=$(sbatch --parsable --job-name=onebeacon-{name}-merge --dependency=afterok:"$array"{options} $SBATCH_OPTIONS \
  --output="$OUT/logs/merge.out" <<<"$merge_job")
merge=${{merge%%;*}}
echo "array job $array ({n} shards) and merge job $merge submitted; the result will be $OUT/result/mc.json"
printf '%s %s\n' "$array" "$merge" > "$OUT/jobs"
"#,
        exe = quote(&exe.display().to_string()),
        scenario = quote(scenario),
        dir = quote(&dir.display().to_string()),
        last = n - 1,
    )
}

#[cfg(test)]
mod tests {
    use super::quote;

    #[test]
    fn quoting_survives_single_quotes() {
        assert_eq!(quote("a'b c"), r"'a'\''b c'");
    }
}
