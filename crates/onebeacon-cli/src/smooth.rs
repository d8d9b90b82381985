//! `onebeacon smooth`: a log smoothed over every pose after the dive, beside its filters
//! and its ground truth.

use crate::BadInput;
use crate::output::Staging;
use crate::replay::{beacon_filter, print_table};
use crate::{plot, report};
use anyhow::{Context, Result};
use nalgebra::{Vector2, Vector3};
use onebeacon_sim::replay::{Log, replay as run_replay};
use onebeacon_sim::run::Estimate;
use onebeacon_sim::smooth::{Smoothed, smooth as run_smooth};
use std::io::Write;
use std::path::PathBuf;

/// `smooth`'s options besides the log.
pub struct SmoothArgs {
    pub out: Option<PathBuf>,
    pub beacons: Option<Vec<u32>>,
    pub json: bool,
    pub like: Option<String>,
    pub estimators: Option<PathBuf>,
    pub calibrate: Option<Vec<String>>,
    pub kernel: Option<String>,
}

/// `onebeacon smooth LOG.toml [--out DIR] [--beacons 0,5] [--like NAME] [--calibrate ...]
/// [--kernel ...] [--json]`
pub fn smooth(path: &std::path::Path, a: SmoothArgs) -> Result<()> {
    let mut log = Log::load(path)?;
    if let Some(file) = &a.estimators {
        log.description.estimators = onebeacon_sim::replay::log::load_estimators(file)?;
    }
    let known = log.beacon_ids();
    let filter = beacon_filter(a.beacons.clone(), &known)?;
    let cfg = onebeacon_sim::smooth::config(&log, a.like.as_deref(), a.calibrate.as_deref(), a.kernel.as_deref())
        .map_err(|e| BadInput(format!("--{e}")))?;
    let used: Vec<u32> = filter.clone().map_or_else(|| known.iter().copied().collect(), |f| f.into_iter().collect());
    let suffix =
        filter.as_ref().map(|f| format!("-beacons-{}", f.iter().map(u32::to_string).collect::<Vec<_>>().join("-")));
    let name = &log.description.name;
    let dir = a
        .out
        .clone()
        .unwrap_or_else(|| PathBuf::from("out").join(format!("{name}-smooth{}", suffix.unwrap_or_default())));
    crate::budget().check_replay(&log, false).map_err(|e| BadInput(e.to_string()))?;
    let staging = Staging::new(&dir)?;

    eprintln!("smoothing {name} ...");
    let smoothed = run_smooth(&log, filter.as_ref(), &cfg)?;
    eprintln!(
        "smoothed {} poses in {:.3} s ({} iterations); replaying the filters ...",
        smoothed.poses.len(),
        smoothed.build_s + smoothed.solve_s,
        smoothed.iterations
    );
    let started = std::time::Instant::now();
    let vehicles = ["auv".to_string()];
    let mut names: Vec<String> = log.description.estimators.iter().map(|e| e.name()).collect();
    names.push("smoother".into());
    let file = std::fs::File::create(staging.file("trajectory.csv")).context("cannot write trajectory.csv")?;
    let mut trajectory = report::TrajectoryWriter::new(std::io::BufWriter::new(file), &vehicles, &names)?;
    let mut plotted = plot::Thinned::new(10_000);
    let r = run_replay(&log, filter, |mut record| -> Result<()> {
        record.estimates.push(estimate(&smoothed, record.t_s, record.truth[0].pos));
        trajectory.write(&record)?;
        plotted.push(record);
        Ok(())
    })?;
    trajectory.finish()?.flush().context("cannot write trajectory.csv")?;
    let wall_s = started.elapsed().as_secs_f64();
    let mut summary = onebeacon_sim::json::replay_summary(&log, &used, &r, wall_s);
    summary["estimators"]
        .as_array_mut()
        .context("the summary lists its estimators")?
        .push(onebeacon_sim::json::smoother_summary("smoother", &smoothed));
    staging.write("summary.json", serde_json::to_string_pretty(&summary)?.as_bytes())?;
    let fixed: Vec<_> =
        used.iter().filter_map(|b| log.beacons.get(b).map(|p| (*b, log.frame.to_ned(p.x, p.y, p.z)))).collect();
    let title = format!("{name} smoothed, beacons {}", used.iter().map(u32::to_string).collect::<Vec<_>>().join(", "));
    plot::top_view(&staging.file("top_view.png"), &vehicles, &names, &title, plotted.records(), Some(&fixed))
        .context("cannot draw top_view.png")?;
    plot::error_vs_time(&staging.file("error.png"), &names, &title, plotted.records())
        .context("cannot draw error.png")?;
    let files = staging.commit()?;
    for w in r.warnings(log.has_truth()) {
        eprintln!("warning: {w}");
    }
    if a.json {
        outln!("{summary}");
        return Ok(());
    }
    let s = &smoothed;
    outln!(
        "{title}: {} poses, {} measurements, read in {:.3} s, smoothed in {:.3} s ({} iterations, cost {:.1} -> {:.1}, {} gated)",
        s.poses.len(),
        s.used.values().sum::<usize>(),
        s.build_s,
        s.solve_s,
        s.iterations,
        s.cost0,
        s.cost,
        s.gated
    );
    if !s.ignored.is_empty() {
        let list: Vec<String> = s.ignored.iter().map(|(k, n)| format!("{n} {k}")).collect();
        outln!("no factor for: {}", list.join(", "));
    }
    print_table(&summary, &r.dropped)?;
    let cal: Vec<String> = s.calibration.iter().map(|(k, v, sigma)| format!("{k} {v:.4} (sigma {sigma:.4})")).collect();
    if !cal.is_empty() {
        outln!("smoother calibration: {}", cal.join(", "));
    }
    outln!("wrote:");
    for f in files {
        outln!("  {}", f.display());
    }
    Ok(())
}

/// The smoother's row at time `t`, scored against the truth `truth` (NaN: none).
fn estimate(s: &Smoothed, t: f64, truth: Vector3<f64>) -> Estimate {
    let (p, cov) = s.at(t);
    let e = Vector2::new(p[0] - truth.x, p[1] - truth.y);
    Estimate {
        vehicle: 0,
        pos: Vector3::new(p[0], p[1], 0.0),
        psi: onebeacon::geo::wrap_angle(p[2]),
        speed: None,
        sigma_pos: Vector2::new(cov[(0, 0)].sqrt(), cov[(1, 1)].sqrt()),
        error_m: e.norm(),
        nees: onebeacon::filter::consistency::nees(&e, &cov).unwrap_or(f64::NAN),
    }
}
