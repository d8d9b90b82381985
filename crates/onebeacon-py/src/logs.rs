//! Real logs from Python: `replay`, `smooth` and `rts` (the CLI's commands of the same
//! names).

use crate::{input_error, interruptible, to_py, trajectory_dict, user_warning};
use numpy::PyArray1;
use onebeacon::log::{Log, LogError};
use onebeacon_sim::budget::Budget;
use onebeacon_sim::replay::{beacon_filter, replay as run_replay};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyTuple};
use std::path::PathBuf;

/// A real log through every estimator it configures (`onebeacon replay`):
/// `(trajectory, summary)` as `run` gives them, the summary that of `replay --json`.
/// `beacons`: use only these beacon ids; `estimators`: a TOML file of `[[estimators]]`
/// to run instead of the log's.
#[pyfunction]
#[pyo3(signature = (log, beacons = None, estimators = None))]
pub(crate) fn replay<'py>(
    py: Python<'py>,
    log: PathBuf,
    beacons: Option<Vec<u32>>,
    estimators: Option<PathBuf>,
) -> PyResult<Bound<'py, PyTuple>> {
    let mut l = Log::load(&log).map_err(input_error)?;
    if let Some(file) = estimators {
        l.description.use_estimators(&file).map_err(input_error)?;
    }
    let known = l.beacon_ids();
    let filter = beacon_filter(beacons, &known).map_err(|e| input_error(format!("beacons {e}")))?;
    let used: Vec<u32> = filter.clone().map_or_else(|| known.iter().copied().collect(), |f| f.into_iter().collect());
    let budget = Budget::resolve(None).map_err(input_error)?;
    budget.check_replay(&l, true).map_err(input_error)?;
    let started = std::time::Instant::now();
    let (records, r) = interruptible(py, |stop| {
        let mut records = Vec::new();
        let r = run_replay::<LogError>(&l, filter, |rec| {
            if stop.stopped() {
                // what is raised is the KeyboardInterrupt
                return Err(LogError::File { file: String::new(), message: "stopped".into() });
            }
            records.push(rec);
            Ok(())
        });
        (records, r)
    })?;
    let r = r.map_err(input_error)?;
    let summary = onebeacon_sim::json::replay_summary(&l, &used, &r, started.elapsed().as_secs_f64());
    for w in r.warnings(l.has_truth()) {
        user_warning(py, w)?;
    }
    let columns = trajectory_dict(py, &["auv".to_string()], &r.session.names, &records)?;
    PyTuple::new(py, [columns.into_any(), to_py(py, &summary)?])
}

/// A log smoothed over every pose after the dive (`onebeacon smooth`): `(poses,
/// summary)`, poses a dict of arrays per node (t_s, north_m, east_m, heading_rad,
/// sigma_north_m, sigma_east_m, and dead reckoning's dr_north_m, dr_east_m), the
/// summary the smoother's line of `smooth --json` (errors, NEES, calibration, solve).
/// `like`: weigh as this estimator of the log; `calibrate`: calibration variables by
/// name; `kernel`: none, huber, cauchy or student_t; `track_accel`: a constant-velocity
/// model for a craft without motion rows (m/s^1.5, the key track_accel_sigma_m_s2).
#[pyfunction]
#[pyo3(signature = (log, beacons = None, like = None, calibrate = None, kernel = None, track_accel = None))]
pub(crate) fn smooth<'py>(
    py: Python<'py>,
    log: PathBuf,
    beacons: Option<Vec<u32>>,
    like: Option<String>,
    calibrate: Option<Vec<String>>,
    kernel: Option<String>,
    track_accel: Option<f64>,
) -> PyResult<Bound<'py, PyTuple>> {
    let l = Log::load(&log).map_err(input_error)?;
    let filter = beacon_filter(beacons, &l.beacon_ids()).map_err(|e| input_error(format!("beacons {e}")))?;
    let cfg = onebeacon_sim::smooth::config(&l, like.as_deref(), calibrate.as_deref(), kernel.as_deref(), track_accel)
        .map_err(input_error)?;
    Budget::resolve(None).map_err(input_error)?.check_smooth(&l).map_err(input_error)?;
    let s = interruptible(py, |_| onebeacon_sim::smooth::smooth(&l, filter.as_ref(), &cfg))?.map_err(input_error)?;
    let d = PyDict::new(py);
    let column = |f: &dyn Fn(usize) -> f64| (0..s.t_s.len()).map(f).collect::<Vec<f64>>();
    let columns: [(&str, Vec<f64>); 8] = [
        ("t_s", s.t_s.clone()),
        ("north_m", column(&|k| s.poses[k][0])),
        ("east_m", column(&|k| s.poses[k][1])),
        ("heading_rad", column(&|k| onebeacon::geo::wrap_angle(s.poses[k][2]))),
        ("sigma_north_m", column(&|k| s.covariances[k][0][0].sqrt())),
        ("sigma_east_m", column(&|k| s.covariances[k][1][1].sqrt())),
        ("dr_north_m", column(&|k| s.dead_reckoning[k][0])),
        ("dr_east_m", column(&|k| s.dead_reckoning[k][1])),
    ];
    for (name, c) in columns {
        d.set_item(name, PyArray1::from_vec(py, c))?;
    }
    let summary = onebeacon_sim::json::smoother_summary("smoother", &s);
    PyTuple::new(py, [d.into_any(), to_py(py, &summary)?])
}

/// The Rauch-Tung-Striebel pass over each Gaussian filter of a log (the `+rts` lines of
/// `onebeacon smooth`): a dict from each smoothed estimator's name to `(estimates,
/// summary)`, estimates a dict of arrays, one row per interval between the filter's
/// predictions (t_s its start, north_m, east_m, heading_rad, sigma_north_m,
/// sigma_east_m; NED), the summary its line of `smooth --json`.
#[pyfunction]
#[pyo3(signature = (log, beacons = None))]
pub(crate) fn rts<'py>(py: Python<'py>, log: PathBuf, beacons: Option<Vec<u32>>) -> PyResult<Bound<'py, PyDict>> {
    let l = Log::load(&log).map_err(input_error)?;
    let filter = beacon_filter(beacons, &l.beacon_ids()).map_err(|e| input_error(format!("beacons {e}")))?;
    Budget::resolve(None).map_err(input_error)?.check_smooth(&l).map_err(input_error)?;
    let runs = interruptible(py, |_| onebeacon_sim::replay::rts::rts(&l, filter))?.map_err(input_error)?;
    let out = PyDict::new(py);
    for run in &runs {
        let d = PyDict::new(py);
        let column = |f: &dyn Fn(&onebeacon::nav::Estimate) -> f64| run.estimates.iter().map(f).collect::<Vec<f64>>();
        let columns: [(&str, Vec<f64>); 6] = [
            ("t_s", column(&|e| e.t_s)),
            ("north_m", column(&|e| e.north_m())),
            ("east_m", column(&|e| e.east_m())),
            ("heading_rad", column(&|e| e.heading_rad())),
            ("sigma_north_m", column(&|e| e.sigma_north_m())),
            ("sigma_east_m", column(&|e| e.sigma_east_m())),
        ];
        for (name, c) in columns {
            d.set_item(name, PyArray1::from_vec(py, c))?;
        }
        let summary = to_py(py, &onebeacon_sim::json::rts_summary(run))?;
        out.set_item(&run.name, PyTuple::new(py, [d.into_any(), summary])?)?;
    }
    Ok(out)
}
