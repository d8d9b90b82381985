//! `onebeacon.Navigator`: a stream configuration's estimators fed one measurement at a
//! time, as `onebeacon stream` runs them.

use crate::{from_py, input_error, to_py, user_warning};
use numpy::{PyArray1, PyArray2};
use onebeacon::io::stream::{Lines, Note};
use onebeacon::log::stream_setup;
use onebeacon::nav::session::Session;
use onebeacon::vehicle::unit::Unit;
use onebeacon_sim::budget::Budget;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyString};
use std::path::PathBuf;

/// The estimators of a stream configuration, step by step: what `onebeacon stream`
/// runs, for a Python backseat node (ROS 2, MOOS). `feed` takes one measurement (a dict
/// or a JSON line, docs/logs.md) and returns the estimates line `stream` would print
/// (None before the start); `estimates()` gives each estimator's state with its
/// covariance as arrays. A bad item raises InputError and leaves the filters as they were.
#[pyclass(name = "Navigator", module = "onebeacon")]
pub(crate) struct PyNavigator {
    /// Behind a lock: a navigator's filters are sent between threads, never shared.
    unit: std::sync::Mutex<Unit>,
    lines: Lines,
}

impl PyNavigator {
    /// The setup (a panic of another thread left it as it was).
    fn unit(&self) -> std::sync::MutexGuard<'_, Unit> {
        self.unit.lock().unwrap_or_else(std::sync::PoisonError::into_inner)
    }
}

#[pymethods]
impl PyNavigator {
    /// The navigator of a stream configuration (a log description's TOML file: frame,
    /// beacons, initial state, estimators; its sources are ignored).
    #[new]
    fn new(config: PathBuf) -> PyResult<Self> {
        let budget = Budget::resolve(None).map_err(input_error)?;
        let unit = stream_setup(&config, |s| budget.check_stream(s)).map_err(input_error)?;
        Ok(Self { unit: std::sync::Mutex::new(unit), lines: Lines::default() })
    }

    /// The estimators' names.
    #[getter]
    fn names(&self) -> Vec<String> {
        self.unit().session(0).names.clone()
    }

    /// Whether the estimators have started (a given pose, or the first ground truth).
    #[getter]
    fn started(&self) -> bool {
        self.unit().sessions().iter().all(|s| s.started())
    }

    /// Feeds one item (a dict or a JSON string, in the configuration's frame, SI units):
    /// the `stream` output line as a dict, or None before the start. Raises InputError for
    /// an item that is not valid or is screened out; notes (waiting for the start, an
    /// estimator restarted) are Python warnings.
    fn feed<'py>(&mut self, py: Python<'py>, item: &Bound<'py, PyAny>) -> PyResult<Option<Bound<'py, PyAny>>> {
        let line = match item.cast::<PyString>() {
            Ok(s) => s.to_str()?.to_string(),
            Err(_) => from_py(item, "item")?.to_string(),
        };
        let mut unit = self.unit.lock().unwrap_or_else(std::sync::PoisonError::into_inner);
        let max = unit.session(0).limits().max_line_bytes;
        let mut skipped = None;
        let mut infos = Vec::new();
        let out = self.lines.push(&mut unit, line.as_bytes(), line.len() > max, |_, note| match note {
            Note::Skipped(m) => skipped = Some(m),
            other => infos.push(other.message().to_string()),
        });
        for m in infos {
            user_warning(py, m)?;
        }
        if let Some(m) = skipped {
            return Err(input_error(m));
        }
        // before the start (and with no controller's decision to report): None
        let waiting =
            |v: &serde_json::Value| v.get("started") == Some(&serde_json::json!(false)) && v.get("decided").is_none();
        out.filter(|v| !waiting(v)).map(|v| to_py(py, &v)).transpose()
    }

    /// Each estimator's estimate (NED, SI): a dict with `name`, `t_s`, `position_ned_m`
    /// (array of 3), `covariance_m2` (2 x 2 array, north and east), `heading_rad`,
    /// `sigma_heading_rad`, `speed_m_s` (None without the state) and the calibration
    /// states.
    fn estimates<'py>(&self, py: Python<'py>) -> PyResult<Vec<Bound<'py, PyDict>>> {
        estimates(py, self.unit().session(0))
    }

    /// The controller's current command (`[controller]`), as the `command` of a `stream`
    /// line (a dict, in the configuration's frame), or None before its first decision or
    /// without a controller.
    fn command<'py>(&self, py: Python<'py>) -> PyResult<Option<Bound<'py, PyAny>>> {
        let unit = self.unit();
        unit.command().map(|c| to_py(py, &onebeacon::io::jsonl::command_json(&c, unit.plan(), unit.frame))).transpose()
    }

    fn __repr__(&self) -> String {
        let unit = self.unit();
        let s = unit.session(0);
        format!("Navigator({:?}, started={})", s.names, s.started())
    }
}

fn estimates<'py>(py: Python<'py>, session: &Session) -> PyResult<Vec<Bound<'py, PyDict>>> {
    session
        .names
        .iter()
        .zip(session.final_estimates())
        .map(|(name, e)| {
            let d = PyDict::new(py);
            d.set_item("name", name)?;
            d.set_item("t_s", e.t_s)?;
            d.set_item("position_ned_m", PyArray1::from_slice(py, e.position_ned_m.as_slice()))?;
            let p = e.horizontal_cov_m2;
            let cov = PyArray2::from_vec2(py, &[vec![p[(0, 0)], p[(0, 1)]], vec![p[(1, 0)], p[(1, 1)]]])?;
            d.set_item("covariance_m2", cov)?;
            d.set_item("heading_rad", e.heading_rad())?;
            d.set_item("sigma_heading_rad", e.sigma_heading_rad())?;
            d.set_item("speed_m_s", e.speed_m_s)?;
            for (k, x) in e.calibration.keys() {
                d.set_item(k, x)?;
            }
            Ok(d)
        })
        .collect()
}
