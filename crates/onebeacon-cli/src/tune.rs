//! `onebeacon tune`: an estimator's noise keys fitted to a log by the likelihood of its
//! innovations, written as `[[estimators]]` tables that `replay --estimators` runs on
//! another log.

use crate::BadInput;
use crate::output::Staging;
use anyhow::Result;
use onebeacon::log::Log;
use onebeacon::nav::evaluation::ErrorStats;
use onebeacon_sim::replay::tune::{BOUND_FACTOR, DEFAULT_KEYS, TUNABLE, Tuned, at_bound, tune as fit};
use serde_json::{Value, json};
use std::path::{Path, PathBuf};

/// What `tune` is asked to do.
pub struct TuneArgs {
    pub estimators: Option<Vec<String>>,
    pub keys: Option<Vec<String>>,
    pub beacons: Option<Vec<u32>>,
    /// Also each beacon alone: the likelihoods of every replay multiplied.
    pub each_beacon: bool,
    pub out: Option<PathBuf>,
    pub json: bool,
}

/// `onebeacon tune LOG.toml [--estimators A,B] [--keys K,L] [--beacons 0,5] [--each-beacon] [--out DIR] [--json]`
pub fn tune(path: &Path, args: TuneArgs) -> Result<()> {
    let TuneArgs { estimators, keys, beacons, each_beacon, out, json: as_json } = args;
    let log = Log::load(path)?;
    crate::budget().check_replay(&log, false).map_err(|e| BadInput(e.to_string()))?;
    let filter = crate::replay::beacon_filter(beacons, &log.beacon_ids())?;
    let mut sets = vec![filter.clone()];
    if each_beacon {
        let ids = filter.clone().unwrap_or_else(|| log.beacon_ids());
        sets.extend(ids.into_iter().map(|b| Some(std::collections::BTreeSet::from([b]))));
    }
    let named = keys.is_some();
    let keys = keys.unwrap_or_else(|| DEFAULT_KEYS.iter().map(|k| k.to_string()).collect());
    for k in &keys {
        if !TUNABLE.iter().any(|(t, _)| t == k) {
            let known: Vec<&str> = TUNABLE.iter().map(|t| t.0).collect();
            return Err(BadInput(format!("--keys {k}: not a key tune can fit (keys: {})", known.join(", "))).into());
        }
    }
    let specs = &log.description.estimators;
    let names: Vec<String> = specs.iter().map(|e| e.name()).collect();
    // default: every estimator that weighs a beacon measurement
    let chosen: Vec<usize> = match &estimators {
        Some(list) => list
            .iter()
            .map(|n| {
                names.iter().position(|m| m == n).ok_or_else(|| {
                    BadInput(format!(
                        "--estimators {n}: not an estimator of the log (estimators: {})",
                        names.join(", ")
                    ))
                })
            })
            .collect::<Result<_, _>>()?,
        None => (0..specs.len()).filter(|&i| specs[i].planar_config().aiding.any()).collect(),
    };
    if chosen.is_empty() {
        return Err(
            BadInput(format!("{}: no estimator uses ranges or Doppler; nothing to tune", path.display())).into()
        );
    }
    let name = &log.description.name;
    let dir = out.unwrap_or_else(|| PathBuf::from("out").join(format!("{name}-tune")));
    let staging = Staging::new(&dir, &log.files())?;
    let started = std::time::Instant::now();
    let bar = crate::progress::Progress::new(chosen.len() as u64, "estimators", format!("tuning {name}"));
    let mut tuned: Vec<(usize, Tuned)> = Vec::new();
    for &i in &chosen {
        bar.set_message(format!("tuning {}", names[i]));
        let rounds = std::cell::Cell::new(0);
        let t = fit(&log, &specs[i], &keys, named, &sets, || {
            rounds.set(rounds.get() + 1);
            bar.set_message(format!("tuning {}, round {}", names[i], rounds.get()));
        })?;
        tuned.push((i, t));
        bar.inc(1);
    }
    bar.finish();
    let wall_s = started.elapsed().as_secs_f64();

    // every estimator of the log, the tuned ones replaced
    let mut all = specs.clone();
    for (i, t) in &tuned {
        all[*i] = t.spec.clone();
    }
    #[derive(serde::Serialize)]
    struct File<'a> {
        estimators: &'a [onebeacon_sim::scenario::EstimatorSpec],
    }
    let header = format!(
        "# The estimators of {} with {} fitted by `onebeacon tune` on that log{} (in-sample):\n\
         # onebeacon replay OTHER_LOG.toml --estimators THIS_FILE\n",
        path.display(),
        keys.join(", "),
        if each_beacon { " with its beacons together and each alone" } else { "" }
    );
    let text = header + &toml::to_string(&File { estimators: &all })?;
    staging.write("estimators.toml", text.as_bytes())?;
    let summary = json!({
        "log": name,
        "keys": keys,
        "each_beacon": each_beacon,
        "wall_s": wall_s,
        "estimators": tuned.iter().map(|(i, t)| tuned_json(&names[*i], t)).collect::<Vec<_>>(),
    });
    staging.write("tune.json", serde_json::to_string_pretty(&summary)?.as_bytes())?;
    let files = staging.commit()?;
    if as_json {
        outln!("{summary}");
        return Ok(());
    }
    let (n, plural) = (tuned.len(), if tuned.len() == 1 { "" } else { "s" });
    outln!("{name}: {n} estimator{plural} tuned in {wall_s:.1} s (in-sample: these figures are on the log tuned on)");
    for (i, t) in &tuned {
        let (b, a) = (&t.before, &t.after);
        outln!(
            "{}: -ln L {:.1} -> {:.1} ({} corrections with the beacons together), {} replays",
            names[*i],
            t.nll_before,
            t.nll_after,
            a.nis_count,
            t.evaluations
        );
        for ((k, from, to), interval) in t.keys.iter().zip(&t.intervals) {
            let note = match interval {
                _ if at_bound(*from, *to) => format!(
                    " (at its bound, a factor of {BOUND_FACTOR} from the start: the fit wants it further, the \
                     model misses something; docs/logs.md, \"Tuning a log's noise\")"
                ),
                Some([lo, hi]) => format!(" (95 % {lo:.4}-{hi:.4})"),
                None => " (no interval: the likelihood is flat or saddle-shaped there)".to_string(),
            };
            outln!("  {k:<30} {from:>10.4} -> {to:.4}{note}");
        }
        if !t.dropped.is_empty() {
            outln!("  not tuned (unused by this estimator on this log): {}", t.dropped.join(", "));
        }
        if a.rejected > 0 {
            outln!("  {} of {} corrections gated out after the fit", a.rejected, a.nis_count);
        }
        outln!(
            "  rmse {:.3} -> {:.3} m, nees {:.1} -> {:.1} (2 when consistent), nis {:.2} -> {:.2} (1)",
            b.rmse_m(),
            a.rmse_m(),
            b.nees_mean(),
            a.nees_mean(),
            b.nis_mean(),
            a.nis_mean()
        );
    }
    outln!("wrote:");
    for f in files {
        outln!("  {}", f.display());
    }
    Ok(())
}

fn stats_json(s: &ErrorStats) -> Value {
    let num = |v: f64| if v.is_finite() { json!(v) } else { Value::Null };
    json!({"rmse_m": num(s.rmse_m()), "nees_mean": num(s.nees_mean()), "nis_mean": num(s.nis_mean())})
}

fn tuned_json(name: &str, t: &Tuned) -> Value {
    let keys: serde_json::Map<String, Value> = t
        .keys
        .iter()
        .zip(&t.intervals)
        .map(|((k, a, b), i)| {
            (k.clone(), json!({"before": a, "after": b, "at_bound": at_bound(*a, *b), "interval_95": i}))
        })
        .collect();
    json!({
        "name": name,
        "keys": keys,
        "not_tuned": t.dropped,
        "neg_log_likelihood": {"before": t.nll_before, "after": t.nll_after},
        "corrections": t.after.nis_count,
        "gated": t.after.rejected,
        "replays": t.evaluations,
        "before": stats_json(&t.before),
        "after": stats_json(&t.after),
    })
}
