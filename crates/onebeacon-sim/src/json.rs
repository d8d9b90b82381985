//! The JSON forms of results that the CLI prints and writes and the Python package
//! returns, built in one place so that both give the same fields and numbers:
//! `mc --json` ([`mc`]), `run`'s summary.json ([`run_summary`]) and `replay`'s summary
//! ([`replay_summary`]).

use crate::Scenario;
use crate::montecarlo::McResult;
use crate::replay::Replay;
use crate::run::RunOutput;
use crate::scenario::{Cell, SweepValue};
use onebeacon::config::stream::InitialFrom;
use onebeacon::log::Log;
use onebeacon::nav::evaluation::ErrorStats;
use serde_json::{Value, json};

/// JSON number, or null when not finite (JSON has no NaN or infinity).
pub fn num(v: f64) -> Value {
    if v.is_finite() { json!(v) } else { Value::Null }
}

/// The swept keys of a cell and their values.
pub fn sweep(cell: &Cell) -> Value {
    let value = |v: SweepValue| match v {
        SweepValue::Number(x) => num(x),
        SweepValue::Text(t) => json!(t),
    };
    Value::Object(cell.values().into_iter().map(|(k, v)| (k.to_string(), value(v))).collect())
}

/// The `mc --json` object (contract: never rename or drop a field).
pub fn mc(s: &Scenario, r: &McResult, wall_s: f64) -> Value {
    let cells: Vec<Value> = r
        .cells
        .iter()
        .flat_map(|c| {
            c.estimators.iter().map(move |(track, m)| {
                json!({
                    "sweep": sweep(&c.cell),
                    "vehicle": track.vehicle,
                    "estimator": track.estimator,
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
                    "pcrb_rmse_m": c.pcrb(track.vehicle_index).map(num).unwrap_or(Value::Null),
                    "mean_error_first_half_m": num(m.mean_error_first_half_m),
                    "mean_error_second_half_m": num(m.mean_error_second_half_m),
                    "failed_updates": m.failed_updates,
                    "run_mean_errors_m": m.run_mean_errors_m.iter().map(|&e| num(e)).collect::<Vec<_>>(),
                    "run_nees": m.run_nees.iter().map(|&e| num(e)).collect::<Vec<_>>(),
                })
            })
        })
        .collect();
    let v = json!({ "scenario": s.name(), "runs": r.runs, "seed": r.seed, "cells": cells, "wall_s": wall_s });
    v
}

/// summary.json of one run.
pub fn run_summary(s: &Scenario, seed: u64, run: u64, cell: &Cell, out: &RunOutput) -> Value {
    let estimators: Vec<Value> = s
        .tracks()
        .iter()
        .zip(&out.metrics)
        .map(|(track, m)| {
            json!({
                "vehicle": track.vehicle,
                "estimator": track.estimator,
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
        "scenario": s.name(),
        "seed": seed,
        "run": run,
        "sweep": sweep(cell),
        "duration_s": num(s.duration_s()),
        "distance_m": num(out.distance_m[0]),
        "vehicles": s.vehicle_names().iter().zip(&out.distance_m).map(|(name, d)| json!({"name": name, "distance_m": num(*d)})).collect::<Vec<_>>(),
        "frames_decoded": out.frames_decoded,
        "warnings": out.findings(&s.track_labels()),
        "estimators": estimators,
    });
    v
}

/// The smoother's line of a replay summary (the keys of the estimators' lines: errors,
/// NEES, calibration as errors from nominal, per-beacon offsets) and its solve.
pub fn smoother_summary(name: &str, s: &crate::smooth::Smoothed) -> Value {
    let (st, dr) = s.score();
    let mut v = error_fields(name, &st);
    for (k, x) in [
        ("rejected", json!(s.gated)),
        ("dead_reckoning_rmse_m", num(dr.rmse_m())),
        ("iterations", json!(s.iterations)),
        ("converged", json!(s.converged)),
        ("warnings", json!(s.warnings)),
        ("cost", json!({"initial": num(s.cost0), "final": num(s.cost)})),
        ("build_s", json!(s.build_s)),
        ("solve_s", json!(s.solve_s)),
        ("measurements", json!(s.used)),
        ("ignored", json!(s.ignored)),
    ] {
        v[k] = x;
    }
    let mut offsets = serde_json::Map::new();
    for (k, x, sigma) in &s.calibration {
        let cal = json!({"value": num(*x), "sigma": num(*sigma)});
        match k.strip_prefix("range_offset_m[").and_then(|b| b.strip_suffix(']')) {
            Some(b) => {
                offsets.insert(b.to_string(), json!({"offset_m": num(*x), "sigma_m": num(*sigma)}));
            }
            None if k.ends_with("scale") => v[k.as_str()] = num(x - 1.0),
            None if k == "range_offset_m" => v["range_bias_m"] = num(*x),
            None => v[k.as_str()] = num(*x),
        }
        v["calibration"][k.as_str()] = cal;
    }
    if !offsets.is_empty() {
        v["beacon_offsets"] = Value::Object(offsets);
    }
    v
}

/// The fields of an entry of a summary's `estimators` that score its errors against
/// the ground truth (null where no row was scored).
fn error_fields(name: &str, st: &ErrorStats) -> Value {
    let scored = st.count > 0;
    json!({
        "name": name,
        "rmse_m": num(st.rmse_m()),
        "mean_error_m": num(st.mean_m()),
        "final_error_m": if scored { num(st.final_m) } else { Value::Null },
        "max_error_m": if scored { num(st.max_m) } else { Value::Null },
        "nees_mean": num(st.nees_mean()),
        "nees_band": onebeacon::nav::evaluation::chi_square_band(st.nees_count, 2).map(num),
        "nees_within_95_pct": num(100.0 * st.nees_within_95_fraction()),
    })
}

/// A Rauch-Tung-Striebel pass's entry (`smooth`): named `<estimator>+rts`, with its
/// calibration at the start (what the smoothed run says the log began with).
pub fn rts_summary(run: &crate::replay::rts::RtsRun) -> Value {
    let mut v = error_fields(&format!("{}+rts", run.name), &run.stats);
    v["rts_of"] = json!(run.name);
    if let Some(e) = run.estimates.first() {
        for (k, x) in e.calibration.keys() {
            v[k] = num(x);
        }
    }
    v
}

/// Each beacon's corrections by one estimator: counts, mean NIS, the range residual's
/// mean and RMS (m) and its mean over the predicted sigma, and whether the gate shut
/// most of them out.
fn per_beacon_fields(p: &onebeacon::nav::diagnosis::PerBeacon) -> Value {
    let beacon = |b: &onebeacon::nav::diagnosis::BeaconStats| {
        json!({
            "corrections": b.count,
            "rejected": b.rejected,
            "nis_mean": num(b.nis_mean()),
            "range_residual_mean_m": num(b.residual_mean_m()),
            "range_residual_rms_m": num(b.residual_rms_m()),
            "range_residual_mean_sigma": num(b.normalised_mean()),
            "gated_out": b.gated_out(),
        })
    };
    Value::Object(p.0.iter().map(|(id, b)| (id.to_string(), beacon(b))).collect())
}

/// A planar noise in the keys of a description (degrees where the key says so).
pub fn noise_keys(n: &onebeacon::nav::PlanarNoise) -> Value {
    json!({
        "range_sigma_m": n.range_sigma_m,
        "doppler_sigma_m_s": n.doppler_sigma_m_s,
        "heading_sigma_deg": n.heading_sigma_rad.to_degrees(),
        "distance_sigma_frac": n.distance_sigma_frac,
        "heading_change_sigma_frac": n.heading_change_sigma_frac,
        "heading_walk_deg_per_sqrt_m": n.heading_walk_rad_per_sqrt_m.to_degrees(),
        "speed_sigma_m_s": n.speed_sigma_m_s,
        "bias_walk_m_per_sqrt_s": n.bias_walk_m_per_sqrt_s,
        "position_walk_m_per_sqrt_s": n.position_walk_m_per_sqrt_s,
    })
}

/// `replay --json`, the replay's summary.json.
pub fn replay_summary(log: &Log, used: &[u32], r: &Replay, wall_s: f64) -> Value {
    let s = &r.session;
    let floor = s.rmse_floor_m();
    let finals = s.final_estimates();
    let estimators: Vec<Value> = s
        .names
        .iter()
        .zip(&s.stats)
        .zip(&finals)
        .zip(s.beacon_offsets())
        .zip(&s.beacon_stats)
        .map(|((((name, st), e), offsets), per_beacon)| {
            let (x, y, _) = log.frame.from_ned(&nalgebra::Vector3::new(e.north_m(), e.east_m(), 0.0));
            let mut v = error_fields(name, st);
            for (k, val) in [
                ("rejected", json!(st.rejected)),
                ("failed_updates", json!(st.failed)),
                ("reinitialised", json!(st.reinitialised)),
                ("nis_mean", num(st.nis_mean())),
                ("nis_band", json!(onebeacon::nav::evaluation::chi_square_band(st.nis_count, 1).map(num))),
                ("nis_within_95_pct", num(100.0 * st.nis_within_95_fraction())),
                (
                    "final",
                    json!({"t_s": e.t_s, "x_m": x, "y_m": y, "heading_rad": log.frame.heading_from_ned(e.heading_rad())}),
                ),
            ] {
                v[k] = val;
            }
            for (k, x) in e.calibration.keys() {
                v[k] = num(x);
            }
            if !offsets.is_empty() {
                let per_beacon =
                    offsets.iter().map(|(b, o, sigma)| (b.to_string(), json!({"offset_m": o, "sigma_m": sigma})));
                v["beacon_offsets"] = Value::Object(per_beacon.collect());
            }
            v["per_beacon"] = per_beacon_fields(per_beacon);
            // the RMSE less the reference's share (errors independent: rmse^2 = e^2 + floor^2)
            if floor > 0.0 {
                v["rmse_less_reference_m"] = num((st.rmse_m().powi(2) - floor * floor).max(0.0).sqrt());
            }
            v
        })
        .collect();
    let (north, east, psi) = r.start.pose;
    let (x, y, _) = log.frame.from_ned(&nalgebra::Vector3::new(north, east, 0.0));
    json!({
        "log": log.description.name,
        "beacons": used,
        "start": {
            "from": match log.description.initial.from {
                InitialFrom::GroundTruth => "ground_truth",
                InitialFrom::Given => "given",
                InitialFrom::Ranges => "ranges",
            },
            "t_s": r.start.t0_s,
            "x_m": x,
            "y_m": y,
            "heading_rad": log.frame.heading_from_ned(psi),
            "position_sigma_m": r.start.position_sigma_m,
        },
        "items": r.items,
        "skipped_before_start": s.before_start,
        "left_out": s.left_out,
        "screened": s.screened,
        "dropped_rows": r.dropped.iter().map(|d| (d.file.clone(), json!(d.dropped))).collect::<serde_json::Map<_, _>>(),
        "warnings": r.warnings(log.has_truth()),
        "noise": log.description.noise,
        "reference": {
            "rows": s.reference_rows,
            "sigma_rms_m": s.reference_sigma_m(),
            "rmse_floor_m": s.rmse_floor_m(),
        },
        "wall_s": wall_s,
        "estimators": estimators,
    })
}
