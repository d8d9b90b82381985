//! `onebeacon replay` (a log through every estimator, scored against its ground truth)
//! and `onebeacon stream` (JSON Lines in, one estimate line out per line, flushed).

use crate::BadInput;
use crate::output::Staging;
use crate::{plot, report};
use anyhow::{Context, Result};
use onebeacon::io::jsonl;
use onebeacon::log::{Log, stream_setup};
use onebeacon::nav::session::Session;
use onebeacon_sim::replay::{Replay, replay as run_replay};
use onebeacon_sim::run::StepRecord;
use std::collections::BTreeSet;
use std::io::Write;
use std::path::{Path, PathBuf};

/// `--beacons` checked against the log's beacons.
pub(crate) fn beacon_filter(ids: Option<Vec<u32>>, known: &BTreeSet<u32>) -> Result<Option<BTreeSet<u32>>> {
    onebeacon_sim::replay::beacon_filter(ids, known).map_err(|e| BadInput(format!("--beacons {e}")).into())
}

/// A log made ready for `replay` or `smooth`: its beacons, its output directory
/// (`out/<log>-<command>[-beacons-...]` by default), the memory budget checked.
pub(crate) struct Prepared {
    pub log: Log,
    pub filter: Option<BTreeSet<u32>>,
    pub used: Vec<u32>,
    pub staging: Staging,
}

impl Prepared {
    /// The log `log` (its estimators read from `estimators` when given) prepared for
    /// `command`, writing to `out` (default: out/<log>-<command>[-beacons-...]).
    pub(crate) fn new(
        log: Log,
        estimators: Option<&Path>,
        out: Option<PathBuf>,
        beacons: Option<Vec<u32>>,
        command: &str,
    ) -> Result<Self> {
        let known = log.beacon_ids();
        let filter = beacon_filter(beacons, &known)?;
        let used: Vec<u32> =
            filter.clone().map_or_else(|| known.iter().copied().collect(), |f| f.into_iter().collect());
        let suffix =
            filter.as_ref().map(|f| format!("-beacons-{}", f.iter().map(u32::to_string).collect::<Vec<_>>().join("-")));
        let name = &log.description.name;
        let dir =
            out.unwrap_or_else(|| PathBuf::from("out").join(format!("{name}-{command}{}", suffix.unwrap_or_default())));
        crate::budget().check_replay(&log, false).map_err(|e| BadInput(e.to_string()))?;
        let mut inputs = log.files();
        inputs.extend(estimators.map(Path::to_path_buf));
        let staging = Staging::new(&dir, &inputs)?;
        Ok(Self { log, filter, used, staging })
    }

    /// Replays the log's estimators, each record given to `extra` first (to add the
    /// estimates named `extra_names`), writing trajectory.csv as it goes (the plots get
    /// at most 20 000 evenly spaced rows), then summary.json (the replay's summary, to
    /// which `extend` adds), rejected.csv, top_view.png and error.png titled
    /// "<log><label>, beacons ...". Returns the replay, the summary, the title and the
    /// replay's wall time, s.
    pub(crate) fn replay(
        &self,
        label: &str,
        extra_names: &[String],
        mut extra: impl FnMut(&mut StepRecord),
        extend: impl FnOnce(&mut serde_json::Value) -> Result<()>,
    ) -> Result<(Replay, serde_json::Value, String, f64)> {
        let started = std::time::Instant::now();
        let (log, staging) = (&self.log, &self.staging);
        let vehicles = ["auv".to_string()];
        let mut names: Vec<String> = log.description.estimators.iter().map(|e| e.name()).collect();
        names.extend_from_slice(extra_names);
        let file = std::fs::File::create(staging.file("trajectory.csv")).context("cannot write trajectory.csv")?;
        let mut trajectory = report::TrajectoryWriter::new(std::io::BufWriter::new(file), &vehicles, &names)?;
        let mut plotted = plot::Thinned::new(10_000);
        let r = run_replay(log, self.filter.clone(), |mut record| -> Result<()> {
            extra(&mut record);
            trajectory.write(&record)?;
            plotted.push(record);
            Ok(())
        })?;
        trajectory.finish()?.flush().context("cannot write trajectory.csv")?;
        let wall_s = started.elapsed().as_secs_f64();
        let mut s = onebeacon_sim::json::replay_summary(log, &self.used, &r, wall_s);
        extend(&mut s)?;
        staging.write("summary.json", serde_json::to_string_pretty(&s)?.as_bytes())?;
        staging.write("rejected.csv", &rejected_csv(&r.session)?)?;
        let used = &self.used;
        let fixed: Vec<_> =
            used.iter().filter_map(|b| log.beacons.get(b).map(|p| (*b, log.frame.to_ned(p.x, p.y, p.z)))).collect();
        let beacons = used.iter().map(u32::to_string).collect::<Vec<_>>().join(", ");
        let title = format!("{}{label}, beacons {beacons}", log.description.name);
        plot::top_view(&staging.file("top_view.png"), &vehicles, &names, &title, plotted.records(), Some(&fixed))
            .context("cannot draw top_view.png")?;
        plot::error_vs_time(&staging.file("error.png"), &names, &title, plotted.records())
            .context("cannot draw error.png")?;
        Ok((r, s, title, wall_s))
    }

    /// Moves the files into place and prints the replay's warnings; the files written.
    pub(crate) fn finish(self, r: &Replay) -> Result<Vec<PathBuf>> {
        let files = self.staging.commit()?;
        for w in r.warnings(self.log.has_truth()) {
            eprintln!("warning: {w}");
        }
        Ok(files)
    }
}

/// What `onebeacon replay` was asked.
pub struct ReplayArgs<'a> {
    pub out: Option<PathBuf>,
    pub beacons: Option<Vec<u32>>,
    pub as_json: bool,
    pub print_stream: bool,
    pub estimators: Option<&'a Path>,
    pub holdout: Option<Vec<String>>,
}

/// `onebeacon replay LOG.toml [--out DIR] [--beacons 0,5] [--json] [--print-stream]
/// [--estimators FILE] [--holdout IDS|all]`
pub fn replay(path: &Path, args: ReplayArgs) -> Result<()> {
    let mut log = Log::load(path)?;
    if let Some(file) = args.estimators {
        log.description.use_estimators(file)?;
    }
    if args.print_stream {
        let only = beacon_filter(args.beacons, &log.beacon_ids())?;
        let mut stdout = std::io::BufWriter::new(std::io::stdout().lock());
        let mut items = log.items()?;
        for item in &mut items {
            let item = item?;
            let beacon = match &item.input {
                onebeacon::nav::session::Input::Measurement(m) => m.beacon().map(|b| b.id),
                onebeacon::nav::session::Input::BeaconPosition { beacon_id, .. } => Some(*beacon_id),
                onebeacon::nav::session::Input::Truth(_) => None,
            };
            if beacon.is_some_and(|b| only.as_ref().is_some_and(|o| !o.contains(&b))) {
                continue;
            }
            writeln!(stdout, "{}", jsonl::item_json(&item))?;
        }
        stdout.flush()?;
        for d in items.damage() {
            eprintln!("warning: {d}; what came before it was read");
        }
        return Ok(());
    }
    let p = Prepared::new(log, args.estimators, args.out, args.beacons, "replay")?;
    let held = holdout_beacons(args.holdout, &p.used)?;
    let names: Vec<String> = p.log.description.estimators.iter().map(|e| e.name()).collect();
    let mut table = Vec::new();
    if !held.is_empty() {
        let progress = crate::progress::Progress::new(held.len() as u64, "beacons", "holding out".into());
        for id in &held {
            progress.set_message(format!("holding out beacon {id}"));
            table.push((*id, onebeacon_sim::replay::holdout(&p.log, p.filter.as_ref(), *id)?));
            progress.inc(1);
        }
        progress.finish();
    }
    let (r, summary, title, wall_s) = p.replay(
        "",
        &[],
        |_| {},
        |s| {
            if !table.is_empty() {
                s["holdout"] = holdout_json(&names, &table);
                p.staging.write("holdout.csv", &holdout_csv(&names, &table)?)?;
            }
            Ok(())
        },
    )?;
    let files = p.finish(&r)?;
    if args.as_json {
        outln!("{summary}");
        return Ok(());
    }
    outln!("{title}: {} measurements, replayed in {:.1} ms", r.items, wall_s * 1e3);
    print_table(&summary, &r.dropped)?;
    print_holdout(&names, &table)?;
    outln!("wrote:");
    for f in files {
        outln!("  {}", f.display());
    }
    Ok(())
}

/// `--holdout` checked against the beacons run: the ids to hold out in turn.
fn holdout_beacons(asked: Option<Vec<String>>, used: &[u32]) -> Result<Vec<u32>> {
    let Some(asked) = asked else { return Ok(Vec::new()) };
    let list = || used.iter().map(u32::to_string).collect::<Vec<_>>().join(", ");
    if asked.iter().any(|a| a == "all") {
        if used.len() < 2 {
            return Err(BadInput(format!("--holdout all: one beacon ({}) leaves none to run on", list())).into());
        }
        return Ok(used.to_vec());
    }
    let mut ids = Vec::new();
    for a in &asked {
        let id = a.trim().parse::<u32>().ok().filter(|id| used.contains(id)).ok_or_else(|| {
            BadInput(format!("--holdout {a}: not a beacon of this run (beacons: {}; or `all`)", list()))
        })?;
        if used.len() < 2 {
            return Err(BadInput(format!("--holdout {id}: the only beacon of this run leaves none to run on")).into());
        }
        if !ids.contains(&id) {
            ids.push(id);
        }
    }
    Ok(ids)
}

type HoldoutTable = [(u32, Vec<onebeacon::nav::diagnosis::BeaconStats>)];

/// summary.json's `holdout`: per beacon held out, per estimator, its ranges predicted.
fn holdout_json(names: &[String], table: &HoldoutTable) -> serde_json::Value {
    let num = |v: f64| if v.is_finite() { serde_json::json!(v) } else { serde_json::Value::Null };
    let per = |stats: &[onebeacon::nav::diagnosis::BeaconStats]| {
        let entries = names.iter().zip(stats).map(|(n, b)| {
            let v = serde_json::json!({
                "ranges": b.residual_count,
                "residual_rms_m": num(b.residual_rms_m()),
                "residual_mean_m": num(b.residual_mean_m()),
                "nis_mean": num(b.nis_mean()),
            });
            (n.clone(), v)
        });
        serde_json::Value::Object(entries.collect())
    };
    serde_json::Value::Object(table.iter().map(|(id, stats)| (id.to_string(), per(stats))).collect())
}

fn holdout_csv(names: &[String], table: &HoldoutTable) -> Result<Vec<u8>> {
    let mut w = csv::Writer::from_writer(Vec::new());
    w.write_record(["beacon", "estimator", "ranges", "residual_rms_m", "residual_mean_m", "nis_mean"])?;
    for (id, stats) in table {
        for (n, b) in names.iter().zip(stats) {
            let f = |v: f64| format!("{v:.4}");
            w.write_record([
                id.to_string(),
                n.clone(),
                b.residual_count.to_string(),
                f(b.residual_rms_m()),
                f(b.residual_mean_m()),
                f(b.nis_mean()),
            ])?;
        }
    }
    Ok(w.into_inner()?)
}

/// The holdout table: one line per estimator, per beacon held out its predicted ranges'
/// residual RMS (m), mean (m) and mean NIS.
fn print_holdout(names: &[String], table: &HoldoutTable) -> Result<()> {
    if table.is_empty() {
        return Ok(());
    }
    outln!("held out (each beacon's ranges predicted by a run without it): residual RMS m / mean m / mean NIS");
    let header: String = table.iter().map(|(id, _)| format!(" {:>22}", format!("beacon {id}"))).collect();
    outln!("{:<20}{header}", "estimator");
    for (k, name) in names.iter().enumerate() {
        let cells: String = table
            .iter()
            .map(|(_, stats)| {
                let b = &stats[k];
                let cell = match b.residual_count {
                    0 => "-".to_string(),
                    _ => format!("{:.2} / {:+.2} / {:.1}", b.residual_rms_m(), b.residual_mean_m(), b.nis_mean()),
                };
                format!(" {cell:>22}")
            })
            .collect();
        outln!("{name:<20}{cells}");
    }
    Ok(())
}

/// The replay's table: its start, rows dropped, one line per estimator of `summary`
/// (and the per-beacon range offsets).
pub(crate) fn print_table(summary: &serde_json::Value, dropped: &[onebeacon::log::Dropped]) -> Result<()> {
    let st = &summary["start"];
    let f = |k: &str| st[k].as_f64().unwrap_or(f64::NAN);
    outln!(
        "start ([initial] from = \"{}\"): t {:.3} s, x {:.2} m, y {:.2} m, heading {:.1} deg, position sigma {:.2} m",
        st["from"].as_str().unwrap_or(""),
        f("t_s"),
        f("x_m"),
        f("y_m"),
        f("heading_rad").to_degrees(),
        f("position_sigma_m")
    );
    if let Some(noise) = summary["noise"].as_object().filter(|n| !n.is_empty()) {
        let keys: Vec<String> = noise.iter().map(|(k, v)| format!("{k} = {v}")).collect();
        outln!("noise ([noise], to every estimator that does not set its own): {}", keys.join(", "));
    }
    let reference = &summary["reference"];
    if let Some(floor) = reference["rmse_floor_m"].as_f64().filter(|f| *f > 0.0) {
        outln!(
            "ground truth with its own error (sigma {:.2} m rms per axis over {} rows): no RMSE below about {floor:.2} m \
             can be told apart; NEES counts the reference's covariance, rmse_less_reference_m in summary.json takes its \
             share out",
            reference["sigma_rms_m"].as_f64().unwrap_or(f64::NAN),
            reference["rows"]
        );
    }
    for d in dropped.iter().filter(|d| d.dropped > 0) {
        outln!("{}: {} rows out of time order dropped (time_order = \"drop\")", d.file, d.dropped);
    }
    // (header, summary key, decimals)
    const COLUMNS: [(&str, &str, usize); 12] = [
        ("rmse_m", "rmse_m", 3),
        ("mean_m", "mean_error_m", 3),
        ("final_m", "final_error_m", 3),
        ("max_m", "max_error_m", 3),
        ("rejected", "rejected", 0),
        ("bias_m", "range_bias_m", 3),
        ("k_range", "range_scale", 3),
        ("k_dist", "distance_scale", 3),
        ("k_turn", "turn_scale", 3),
        ("nees", "nees_mean", 1),
        ("in95_%", "nees_within_95_pct", 0),
        ("nis", "nis_mean", 2),
    ];
    let header: String = COLUMNS.iter().map(|(h, _, _)| format!(" {h:>9}")).collect();
    outln!("{:<20}{header}", "estimator");
    for e in summary["estimators"].as_array().into_iter().flatten() {
        let cells: String = COLUMNS
            .iter()
            .map(|(_, k, d)| e[*k].as_f64().map_or(format!(" {:>9}", "-"), |v| format!(" {v:>9.d$}", d = *d)))
            .collect();
        outln!("{:<20}{cells}", e["name"].as_str().unwrap_or(""));
    }
    // per-beacon range offsets (`estimate_beacon_offsets`), one line per estimator
    for e in summary["estimators"].as_array().into_iter().flatten() {
        let Some(offsets) = e["beacon_offsets"].as_object() else { continue };
        let cells: Vec<String> = offsets
            .iter()
            .map(|(b, o)| {
                let (v, sigma) =
                    (o["offset_m"].as_f64().unwrap_or(f64::NAN), o["sigma_m"].as_f64().unwrap_or(f64::NAN));
                format!("beacon {b} {v:+.3} (sigma {sigma:.3})")
            })
            .collect();
        outln!("{}: range offsets, m: {}", e["name"].as_str().unwrap_or(""), cells.join(", "));
    }
    Ok(())
}

fn rejected_csv(s: &Session) -> Result<Vec<u8>> {
    let mut w = csv::Writer::from_writer(Vec::new());
    w.write_record(["estimator", "t_s", "kind", "beacon", "value", "nis", "reason"])?;
    for r in &s.rejected {
        w.write_record([
            r.estimator.map_or_else(|| "*".to_string(), |i| s.names[i].clone()),
            format!("{:.6}", r.t_s),
            r.kind.to_string(),
            r.beacon_id.to_string(),
            if r.value.abs() < 1e9 { format!("{:.6}", r.value) } else { format!("{:e}", r.value) },
            format!("{:.3}", r.nis),
            r.reason.clone(),
        ])?;
    }
    Ok(w.into_inner()?)
}

/// `onebeacon stream CONFIG.toml`: JSON Lines on stdin, one JSON line per estimate (and
/// with a `[controller]`, the command) on stdout, flushed after each; bad lines are
/// reported on stderr and skipped.
pub fn stream(config: &Path) -> Result<()> {
    let mut unit = stream_setup(config, |s| crate::budget().check_stream(s))?;
    onebeacon::io::stream::run(&mut unit, std::io::stdin().lock(), std::io::stdout().lock(), |line, m| {
        eprintln!("stdin line {line}: {m}")
    })
    .context("cannot read stdin or write stdout")?;
    Ok(())
}
