//! Tables, CSV and JSON of runs and Monte Carlo results.

use anyhow::Result;
use onebeacon_sim::Scenario;
use onebeacon_sim::montecarlo::McResult;
use onebeacon_sim::run::RunOutput;
use onebeacon_sim::scenario::Cell;
use serde_json::{Value, json};
use std::fmt::Write;

/// JSON number, or null when not finite (JSON has no NaN or infinity).
fn num(v: f64) -> Value {
    if v.is_finite() { json!(v) } else { Value::Null }
}

fn sweep_json(cell: &Cell) -> Value {
    Value::Object(cell.values().into_iter().map(|(k, v)| (k.to_string(), num(v))).collect())
}

/// trajectory.csv: one row per step with the truth and every estimator's estimate,
/// standard deviations, error and NEES.
pub fn trajectory_csv(s: &Scenario, out: &RunOutput) -> Result<Vec<u8>> {
    let mut w = csv::Writer::from_writer(Vec::new());
    let mut header: Vec<String> =
        ["t_s", "truth_north_m", "truth_east_m", "truth_heading_deg", "truth_speed_m_s", "frame"]
            .map(String::from)
            .to_vec();
    for e in &s.estimators {
        for col in ["north_m", "east_m", "heading_deg", "speed_m_s", "sigma_north_m", "sigma_east_m", "error_m", "nees"]
        {
            header.push(format!("{}_{col}", e.name()));
        }
    }
    w.write_record(&header)?;
    for r in &out.trajectory {
        let mut row = vec![
            format!("{:.2}", r.t_s),
            format!("{:.4}", r.truth.pos.x),
            format!("{:.4}", r.truth.pos.y),
            format!("{:.3}", onebeacon::geo::wrap_angle(r.truth.psi).to_degrees()),
            format!("{:.4}", r.truth.v),
            u8::from(r.frame).to_string(),
        ];
        for e in &r.estimates {
            row.extend([
                format!("{:.4}", e.pos.x),
                format!("{:.4}", e.pos.y),
                format!("{:.3}", e.psi.to_degrees()),
                format!("{:.4}", e.v),
                format!("{:.4}", e.sigma_pos.x),
                format!("{:.4}", e.sigma_pos.y),
                format!("{:.4}", e.error_m),
                format!("{:.4}", e.nees),
            ]);
        }
        w.write_record(&row)?;
    }
    Ok(w.into_inner()?)
}

/// summary.json of one run.
pub fn run_summary_json(s: &Scenario, seed: u64, run: u64, cell: &Cell, out: &RunOutput) -> String {
    let estimators: Vec<Value> = s
        .estimators
        .iter()
        .zip(&out.metrics)
        .map(|(e, m)| {
            json!({
                "estimator": e.name(),
                "mean_error_m": num(m.mean_error_m),
                "error_variance_m2": num(m.error_variance_m2),
                "rmse_m": num(m.mse_m2.sqrt()),
                "max_error_m": num(m.max_error_m),
                "final_error_m": num(m.final_error_m),
                "etd_max_pct": num(m.etd_max_pct),
                "etd_mean_pct": num(m.etd_mean_pct),
                "nees_mean": num(m.nees_mean),
                "failed_updates": m.failed_updates,
            })
        })
        .collect();
    let v = json!({
        "scenario": s.name,
        "seed": seed,
        "run": run,
        "sweep": sweep_json(cell),
        "duration_s": num(s.duration_s()),
        "distance_m": num(out.distance_m),
        "frames_decoded": out.frames_decoded,
        "estimators": estimators,
    });
    serde_json::to_string_pretty(&v).expect("serialisable") + "\n"
}

/// The table printed by `run`.
pub fn run_table(s: &Scenario, seed: u64, run: u64, cell: &Cell, out: &RunOutput) -> String {
    let mut t = String::new();
    let _ = writeln!(
        t,
        "{}: seed {seed}, run {run}, T_com {} s, {:.0} m in {:.0} s, {} frames decoded",
        s.name,
        cell.t_com_s,
        out.distance_m,
        s.duration_s(),
        out.frames_decoded
    );
    let _ = writeln!(
        t,
        "{:<16} {:>10} {:>9} {:>9} {:>10} {:>9}",
        "estimator", "mean_err_m", "rmse_m", "max_m", "final_m", "nees"
    );
    for (e, m) in s.estimators.iter().zip(&out.metrics) {
        let _ = writeln!(
            t,
            "{:<16} {:>10.3} {:>9.3} {:>9.3} {:>10.3} {:>9.2}",
            e.name(),
            m.mean_error_m,
            m.mse_m2.sqrt(),
            m.max_error_m,
            m.final_error_m,
            m.nees_mean
        );
    }
    t
}

/// The `mc --json` object (contract: never rename or drop a field).
pub fn mc_json(s: &Scenario, r: &McResult, wall_s: f64) -> String {
    let cells: Vec<Value> = r
        .cells
        .iter()
        .flat_map(|c| {
            c.estimators.iter().map(move |(name, m)| {
                json!({
                    "sweep": sweep_json(&c.cell),
                    "estimator": name,
                    "runs": m.runs,
                    "mean_error_m": num(m.mean_error_m),
                    "error_variance_m2": num(m.error_variance_m2),
                    "rmse_m": num(m.rmse_m),
                    "outliers": m.outliers,
                    "etd_max_pct": num(m.etd_max_pct),
                    "etd_mean_pct": num(m.etd_mean_pct),
                    "nees_mean": num(m.nees_mean),
                    "nees_band": [num(m.nees_band[0]), num(m.nees_band[1])],
                    "nees_mean_all_runs": num(m.nees_mean_all_runs),
                    "failed_updates": m.failed_updates,
                })
            })
        })
        .collect();
    let v = json!({ "scenario": s.name, "runs": r.runs, "seed": r.seed, "cells": cells, "wall_s": wall_s });
    serde_json::to_string(&v).expect("serialisable")
}

fn sweep_label(cell: &Cell) -> String {
    cell.values().iter().map(|(k, v)| format!("{k}={v}")).collect::<Vec<_>>().join(" ")
}

/// The `mc` tables: mean error (outliers) of every estimator side by side, as
/// garin2024 Table 4, then every statistic per estimator, as Table 3.
pub fn mc_table(s: &Scenario, r: &McResult, wall_s: f64) -> String {
    let mut t = String::new();
    let _ = writeln!(t, "{}: {} runs per cell, seed {}, {:.2} s", s.name, r.runs, r.seed, wall_s);
    let _ = writeln!(
        t,
        "(outliers: runs whose mean error is beyond 1.5 IQR of the quartiles; left out of every statistic but nees_all)"
    );
    let _ = writeln!(t);
    let _ = writeln!(t, "Mean positioning error in m (outliers)");
    let _ = write!(t, "{:<14}", "sweep");
    for e in &s.estimators {
        let _ = write!(t, " {:>18}", e.name());
    }
    let _ = writeln!(t);
    for c in &r.cells {
        let _ = write!(t, "{:<14}", sweep_label(&c.cell));
        for (_, m) in &c.estimators {
            let _ = write!(t, " {:>18}", format!("{:.4} ({})", m.mean_error_m, m.outliers));
        }
        let _ = writeln!(t);
    }
    let _ = writeln!(t);
    let _ = writeln!(
        t,
        "{:<14} {:<16} {:>10} {:>5} {:>10} {:>8} {:>9} {:>10} {:>8} {:>15} {:>10}",
        "sweep",
        "estimator",
        "mean_m",
        "out",
        "var_m2",
        "rmse_m",
        "etd_max%",
        "etd_mean%",
        "nees",
        "nees_band95",
        "nees_all"
    );
    for c in &r.cells {
        for (name, m) in &c.estimators {
            let _ = writeln!(
                t,
                "{:<14} {:<16} {:>10.4} {:>5} {:>10.4} {:>8.3} {:>9.4} {:>10.4} {:>8.2} {:>15} {:>10.1}",
                sweep_label(&c.cell),
                name,
                m.mean_error_m,
                m.outliers,
                m.error_variance_m2,
                m.rmse_m,
                m.etd_max_pct,
                m.etd_mean_pct,
                m.nees_mean,
                format!("[{:.2}, {:.2}]", m.nees_band[0], m.nees_band[1]),
                m.nees_mean_all_runs,
            );
        }
    }
    t
}
