//! `onebeacon smooth`: a log smoothed over every pose after the dive, beside its filters
//! and its ground truth.

use crate::BadInput;
use crate::replay::{Prepared, print_table};
use anyhow::{Context, Result};
use nalgebra::{Vector2, Vector3};
use onebeacon::log::Log;
use onebeacon_sim::replay::row_estimate;
use onebeacon_sim::replay::rts::rts;
use onebeacon_sim::run::{Estimate, StepRecord};
use onebeacon_sim::smooth::{SmoothError, Smoothed, smooth as run_smooth};
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
    pub track_accel: Option<f64>,
}

/// `onebeacon smooth LOG.toml [--out DIR] [--beacons 0,5] [--like NAME] [--calibrate ...]
/// [--kernel ...] [--track-accel SIGMA] [--json]`
pub fn smooth(path: &std::path::Path, a: SmoothArgs) -> Result<()> {
    let mut log = Log::load(path)?;
    if let Some(file) = &a.estimators {
        log.description.use_estimators(file)?;
    }
    let cfg = onebeacon_sim::smooth::config(
        &log,
        a.like.as_deref(),
        a.calibrate.as_deref(),
        a.kernel.as_deref(),
        a.track_accel,
    )
    .map_err(|e| BadInput(format!("--{e}")))?;
    crate::budget().check_smooth(&log).map_err(|e| BadInput(e.to_string()))?;
    let p = Prepared::new(log, a.estimators.as_deref(), a.out.clone(), a.beacons.clone(), "smooth")?;
    // a log that cannot be read or has nothing to smooth is bad input (exit 2)
    let smoothed = run_smooth(&p.log, p.filter.as_ref(), &cfg).map_err(|e| match e {
        SmoothError::Log(e) => anyhow::Error::from(e),
        other => BadInput(other.to_string()).into(),
    })?;
    eprintln!(
        "smoothed {} poses in {:.3} s ({} iterations); the filters' RTS passes ...",
        smoothed.poses.len(),
        smoothed.build_s + smoothed.solve_s,
        smoothed.iterations
    );
    let runs = rts(&p.log, p.filter.clone())?;
    eprintln!("replaying the filters ...");
    let mut names = vec!["smoother".to_string()];
    names.extend(runs.iter().map(|r| format!("{}+rts", r.name)));
    let extra = |record: &mut StepRecord| {
        let (truth, sigma) = (record.truth[0].pos, record.truth[0].sigma_m);
        record.estimates.push(estimate(&smoothed, record.t_s, truth, sigma));
        for run in &runs {
            // no truth: NaN error and NEES
            let (error_m, nees) = run.error(record.t_s, truth.x, truth.y, sigma);
            record.estimates.push(row_estimate(run.at(record.t_s), (error_m, nees.unwrap_or(f64::NAN))));
        }
    };
    let noise_from = match (&a.like, p.log.description.noise_keys()) {
        (Some(name), _) => format!("--like {name}"),
        (None, Some(_)) => "the log's [noise], the defaults for the rest".to_string(),
        (None, None) => "the defaults".to_string(),
    };
    // the noise the smoother weighed with, and a track's constant-velocity model
    let mut noise_keys = onebeacon_sim::json::noise_keys(&cfg.noise);
    if let Some(a) = cfg.track_accel_sigma_m_s2 {
        noise_keys["track_accel_sigma_m_s2"] = serde_json::json!(a);
    }
    let mut warnings = smoothed.warnings.clone();
    let (r, summary, title, _) = p.replay(" smoothed", &names, extra, |summary| {
        let entries = summary["estimators"].as_array_mut().context("the summary lists its estimators")?;
        entries.push(onebeacon_sim::json::smoother_summary("smoother", &smoothed));
        entries.extend(runs.iter().map(onebeacon_sim::json::rts_summary));
        warnings.extend(worse_than_the_filters(entries));
        summary["smoother_noise"] = serde_json::json!({"from": noise_from, "keys": noise_keys});
        if let Some(list) = summary["warnings"].as_array_mut() {
            list.extend(warnings.iter().map(|w| serde_json::json!(w)));
        }
        Ok(())
    })?;
    let files = p.finish(&r)?;
    for w in &warnings {
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
    let value = |v: &serde_json::Value| {
        let v = format!("{:.4}", v.as_f64().unwrap_or(f64::NAN));
        v.trim_end_matches('0').trim_end_matches('.').to_string()
    };
    let keys: Vec<String> =
        noise_keys.as_object().into_iter().flatten().map(|(k, v)| format!("{k} {}", value(v))).collect();
    outln!("smoother noise ({noise_from}): {}", keys.join(", "));
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

/// How much larger than the best filter's RMSE the smoother's may be before it is said
/// to have failed: it weighs the same measurements with hindsight, so on a log with
/// ground truth it should not be far above the filters (no source: a guard, with a
/// metre's slack for logs where every error is small).
const WORSE_FACTOR: f64 = 2.0;

/// A warning where the smoother's RMSE (`entries`' "smoother") is more than
/// [`WORSE_FACTOR`] times, and a metre above, the best filter's (with or without its RTS
/// pass; dead reckoning left out). None without ground truth (no RMSE).
fn worse_than_the_filters(entries: &[serde_json::Value]) -> Option<String> {
    let rmse = |e: &serde_json::Value| e["rmse_m"].as_f64().filter(|v| v.is_finite());
    let smoother = entries.iter().find(|e| e["name"] == "smoother").and_then(rmse)?;
    let (best, name) = entries
        .iter()
        .filter(|e| e["name"] != "smoother" && !e["name"].as_str().is_some_and(|n| n.starts_with("dead-reckoning")))
        .filter_map(|e| Some((rmse(e)?, e["name"].as_str()?.to_string())))
        .min_by(|a, b| a.0.total_cmp(&b.0))?;
    (smoother > WORSE_FACTOR * best && smoother > best + 1.0).then(|| {
        format!(
            "the smoother's RMSE {smoother:.3} m is over {WORSE_FACTOR} times the best filter's ({name}, {best:.3} m) on \
             the same rows: the solve found a wrong optimum (a misplaced beacon, a units slip, a calibration the \
             data cannot fix); do not use its track"
        )
    })
}

/// The smoother's row at time `t`, scored against the truth `truth` with its own error
/// `sigma_m` (NaN: none).
fn estimate(s: &Smoothed, t: f64, truth: Vector3<f64>, sigma_m: f64) -> Estimate {
    let (p, cov) = s.at(t);
    let (error_m, nees) = s.error(t, truth.x, truth.y, sigma_m);
    Estimate {
        vehicle: 0,
        pos: Vector3::new(p[0], p[1], 0.0),
        psi: onebeacon::geo::wrap_angle(p[2]),
        speed: None,
        sigma_pos: Vector2::new(cov[(0, 0)].sqrt(), cov[(1, 1)].sqrt()),
        error_m,
        nees: nees.unwrap_or(f64::NAN),
    }
}
