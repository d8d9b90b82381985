//! `onebeacon._native`: the Python extension module of the `onebeacon` package (its
//! Python side, docstrings and type stubs are in `python/onebeacon`). Every result is
//! built by the same code as the CLI's (`onebeacon_sim::json`, `run::trajectory`), so
//! the numbers are the CLI's bit for bit; errors are `onebeacon.InputError` (a
//! `ValueError`) with the CLI's one-line messages.

mod logs;
mod navigator;

use numpy::{PyArray1, PyReadonlyArray2};
use onebeacon_sim::Scenario;
use onebeacon_sim::budget::{Budget, concurrent_runs};
use onebeacon_sim::chain::Chain;
use onebeacon_sim::montecarlo::Progress;
use onebeacon_sim::montecarlo::monte_carlo;
use onebeacon_sim::run::{StepRecord, simulate, trajectory};
use onebeacon_sim::scenario::{self, BUILTINS, ping::PingConfig};
use pyo3::exceptions::{PyRuntimeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::{PyBool, PyDict, PyFloat, PyList, PyString, PyTuple};
use serde_json::Value;
use std::path::PathBuf;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::time::Duration;

pyo3::create_exception!(
    onebeacon,
    InputError,
    PyValueError,
    "Input that the caller can fix (a scenario, a log, a configuration, an argument): the message is the CLI's one line, naming what is wrong and what is allowed."
);

fn input_error(e: impl std::fmt::Display) -> PyErr {
    InputError::new_err(e.to_string())
}

/// `message` as a Python `UserWarning` (a stream's notes, a replay's warnings).
fn user_warning(py: Python<'_>, message: String) -> PyResult<()> {
    PyErr::warn(py, &py.get_type::<pyo3::exceptions::PyUserWarning>(), &std::ffi::CString::new(message)?, 1)
}

/// JSON to Python: null None, numbers int or float as JSON has them, objects dicts.
fn to_py<'py>(py: Python<'py>, v: &Value) -> PyResult<Bound<'py, PyAny>> {
    Ok(match v {
        Value::Null => py.None().into_bound(py),
        Value::Bool(b) => PyBool::new(py, *b).to_owned().into_any(),
        Value::Number(n) => match (n.as_i64(), n.as_u64()) {
            (Some(i), _) => i.into_pyobject(py)?.into_any(),
            (None, Some(u)) => u.into_pyobject(py)?.into_any(),
            _ => PyFloat::new(py, n.as_f64().unwrap_or(f64::NAN)).into_any(),
        },
        Value::String(s) => PyString::new(py, s).into_any(),
        Value::Array(a) => {
            let list = PyList::empty(py);
            for x in a {
                list.append(to_py(py, x)?)?;
            }
            list.into_any()
        }
        Value::Object(o) => {
            let dict = PyDict::new(py);
            for (k, x) in o {
                dict.set_item(k, to_py(py, x)?)?;
            }
            dict.into_any()
        }
    })
}

/// How deep dicts and lists may nest in what Python gives (a scenario is 4 deep).
const MAX_DEPTH: usize = 64;

/// Python to JSON (dicts with str keys, lists and tuples, str, bool, int, finite float,
/// None; numpy scalars and arrays too); `at` names the place in errors.
fn from_py(obj: &Bound<'_, PyAny>, at: &str) -> PyResult<Value> {
    from_py_at(obj, at, 0)
}

fn from_py_at(obj: &Bound<'_, PyAny>, at: &str, depth: usize) -> PyResult<Value> {
    if depth > MAX_DEPTH {
        let at: String = at.chars().take(80).collect();
        return Err(input_error(format!("{at}...: nested more than {MAX_DEPTH} deep; no onebeacon input nests so")));
    }
    if obj.is_none() {
        return Ok(Value::Null);
    }
    if let Ok(b) = obj.cast::<PyBool>() {
        return Ok(Value::Bool(b.is_true()));
    }
    if let Ok(s) = obj.cast::<PyString>() {
        return Ok(Value::String(s.to_str()?.to_string()));
    }
    if let Ok(d) = obj.cast::<PyDict>() {
        let mut map = serde_json::Map::new();
        for (k, v) in d.iter() {
            let key: String = k.extract().map_err(|_| input_error(format!("{at}: key {k}: keys must be strings")))?;
            let here = if at.is_empty() { key.clone() } else { format!("{at}.{key}") };
            map.insert(key, from_py_at(&v, &here, depth + 1)?);
        }
        return Ok(Value::Object(map));
    }
    // sequences (lists, tuples, numpy arrays of any length, one included) before
    // numbers: a one-element array also converts to a float
    if let Ok(len) = obj.len() {
        let mut values = Vec::with_capacity(len);
        for (i, x) in obj.try_iter()?.enumerate() {
            values.push(from_py_at(&x?, &format!("{at}[{i}]"), depth + 1)?);
        }
        return Ok(Value::Array(values));
    }
    // ints (numpy's too, through __index__) before floats, which do not convert to i64
    if let Ok(i) = obj.extract::<i64>() {
        return Ok(Value::from(i));
    }
    if let Ok(x) = obj.extract::<f64>() {
        return serde_json::Number::from_f64(x)
            .map(Value::Number)
            .ok_or_else(|| input_error(format!("{at} = {x}: not a finite number")));
    }
    Err(input_error(format!(
        "{at}: {} is not a TOML value (dict, list, str, bool, int, float)",
        obj.get_type().name()?
    )))
}

/// A dict as TOML text (None values left out: TOML has no null).
fn dict_to_toml(d: &Bound<'_, PyAny>, what: &str) -> PyResult<String> {
    fn drop_nulls(v: Value) -> Value {
        match v {
            Value::Object(o) => {
                Value::Object(o.into_iter().filter(|(_, v)| !v.is_null()).map(|(k, v)| (k, drop_nulls(v))).collect())
            }
            Value::Array(a) => Value::Array(a.into_iter().map(drop_nulls).collect()),
            v => v,
        }
    }
    let v = drop_nulls(from_py(d, "")?);
    if !v.is_object() {
        return Err(input_error(format!("{what} must be a dict")));
    }
    let table: toml::Table = serde_json::from_value(v).map_err(|e| input_error(format!("{what}: {e}")))?;
    toml::to_string(&table).map_err(|e| input_error(format!("{what}: {e}")))
}

/// A scenario: a built-in by name, a TOML file, TOML text or a dict, parsed and validated.
///
/// Build one with `Scenario.builtin(name)`, `Scenario.from_file(path)`,
/// `Scenario.from_toml(text)` or `Scenario.from_dict(d)`; `to_dict()` gives every key
/// back (`Scenario.from_dict(s.to_dict()) == s`).
#[pyclass(name = "Scenario", module = "onebeacon", frozen, eq)]
#[derive(Clone, PartialEq)]
struct PyScenario {
    inner: Scenario,
}

#[pymethods]
impl PyScenario {
    /// The built-in scenario `name` (see `onebeacon.scenarios()`).
    #[staticmethod]
    fn builtin(name: &str) -> PyResult<Self> {
        scenario::load_builtin(name).map(Self::from).map_err(input_error)
    }

    /// The scenario of a TOML file.
    #[staticmethod]
    fn from_file(path: PathBuf) -> PyResult<Self> {
        scenario::load_file(&path).map(Self::from).map_err(input_error)
    }

    /// The scenario of TOML text; `source` names it in errors.
    #[staticmethod]
    #[pyo3(signature = (text, source = "scenario TOML"))]
    fn from_toml(text: &str, source: &str) -> PyResult<Self> {
        scenario::parse(text, source).map(Self::from).map_err(input_error)
    }

    /// The scenario of a dict with the keys of a scenario file (docs/scenarios.md).
    #[staticmethod]
    fn from_dict(d: &Bound<'_, PyAny>) -> PyResult<Self> {
        let text = dict_to_toml(d, "scenario dict")?;
        scenario::parse(&text, "scenario dict").map(Self::from).map_err(input_error)
    }

    /// Every key of the scenario, defaults written out.
    fn to_dict<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let table: toml::Table =
            toml::from_str(&self.inner.to_toml()).map_err(|e| PyRuntimeError::new_err(e.to_string()))?;
        to_py(py, &serde_json::to_value(table).map_err(|e| PyRuntimeError::new_err(e.to_string()))?)
    }

    /// The scenario as TOML, every key written out.
    fn to_toml(&self) -> String {
        self.inner.to_toml()
    }

    #[getter]
    fn name(&self) -> String {
        self.inner.name().to_string()
    }

    #[getter]
    fn kind(&self) -> &'static str {
        kind(&self.inner)
    }

    #[getter]
    fn description(&self) -> String {
        self.inner.description().to_string()
    }

    /// Runs per sweep cell of `mc` unless told.
    #[getter]
    fn runs(&self) -> usize {
        self.inner.runs()
    }

    /// The base seed unless told.
    #[getter]
    fn seed(&self) -> u64 {
        self.inner.seed()
    }

    /// The sweep cells of `mc`, in order: each a dict of the swept keys' values.
    #[getter]
    fn cells<'py>(&self, py: Python<'py>) -> PyResult<Vec<Bound<'py, PyAny>>> {
        self.inner.cells().iter().map(|c| to_py(py, &onebeacon_sim::json::sweep(c))).collect()
    }

    /// The (vehicle, estimator) tracks' labels, in the order of results.
    #[getter]
    fn tracks(&self) -> Vec<String> {
        self.inner.track_labels()
    }

    /// The vehicles' names.
    #[getter]
    fn vehicles(&self) -> Vec<String> {
        self.inner.vehicle_names()
    }

    fn __repr__(&self) -> String {
        format!("Scenario({:?}, kind={:?}, {} cells)", self.inner.name(), kind(&self.inner), self.inner.cells().len())
    }
}

impl From<Scenario> for PyScenario {
    fn from(inner: Scenario) -> Self {
        Self { inner }
    }
}

fn kind(s: &Scenario) -> &'static str {
    match s {
        Scenario::FixedBeacon(_) => "fixed_beacon",
        Scenario::MovingBeacon(_) => "moving_beacon",
        Scenario::PassiveUsbl(_) => "passive_usbl",
        Scenario::Fleet(_) => "fleet",
    }
}

/// A scenario from what Python gives: a Scenario, a dict, or a str or path (a built-in
/// name or a TOML file, as the CLI takes them).
fn scenario_of(obj: &Bound<'_, PyAny>) -> PyResult<Scenario> {
    if let Ok(s) = obj.cast::<PyScenario>() {
        return Ok(s.get().inner.clone());
    }
    if obj.is_instance_of::<PyDict>() {
        return PyScenario::from_dict(obj).map(|s| s.inner);
    }
    let name: PathBuf = obj.extract().map_err(|_| {
        input_error("scenario: expected a built-in name, a path of a TOML file, a dict or an onebeacon.Scenario")
    })?;
    scenario::load(&name.to_string_lossy()).map_err(input_error)
}

/// The built-in scenarios: a list of dicts with `name`, `kind` and `description`.
#[pyfunction]
fn scenarios(py: Python<'_>) -> PyResult<Vec<Bound<'_, PyDict>>> {
    BUILTINS
        .iter()
        .map(|b| {
            let s = scenario::parse(b.toml, b.name).map_err(input_error)?;
            let d = PyDict::new(py);
            d.set_item("name", b.name)?;
            d.set_item("kind", kind(&s))?;
            d.set_item("description", s.description())?;
            Ok(d)
        })
        .collect()
}

/// A recorded trajectory as a dict of 1-d float64 arrays, one per column of
/// trajectory.csv (full precision; headings in degrees, a missing speed NaN).
fn trajectory_dict<'py>(
    py: Python<'py>,
    vehicles: &[String],
    names: &[String],
    records: &[StepRecord],
) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    for (name, column) in trajectory::columns(vehicles, names, records) {
        d.set_item(name, PyArray1::from_vec(py, column))?;
    }
    Ok(d)
}

/// The progress of a sweep run for Python: runs counted, and a stop that Ctrl-C sets.
struct Ticks {
    done: AtomicUsize,
    stop: std::sync::atomic::AtomicBool,
}

impl Progress for Ticks {
    fn tick(&self) {
        self.done.fetch_add(1, Ordering::Relaxed);
    }
    fn stopped(&self) -> bool {
        self.stop.load(Ordering::Relaxed)
    }
}

/// Runs `work` with the GIL released, on its own thread, while this thread calls
/// `progress(done, total)` (with the GIL) as runs finish and checks for signals every
/// 0.1 s. Ctrl-C (or any signal handler's exception) stops the sweep: the runs under way
/// finish, no other starts, and the exception (KeyboardInterrupt) is raised. An exception
/// the callback raises is raised once the work is done.
fn with_progress<T: Send>(
    py: Python<'_>,
    total: usize,
    progress: Option<Py<PyAny>>,
    work: impl FnOnce(&dyn Progress) -> T + Send,
) -> PyResult<T> {
    let ticks = Ticks { done: AtomicUsize::new(0), stop: false.into() };
    let ticks = &ticks;
    let (result, raised, interrupted) = py.detach(|| {
        std::thread::scope(|scope| {
            let (tx, rx) = std::sync::mpsc::channel::<()>();
            let worker = scope.spawn(move || {
                let r = work(ticks);
                let _ = tx.send(());
                r
            });
            let mut raised: Option<PyErr> = None;
            let mut interrupted: Option<PyErr> = None;
            let mut told = usize::MAX;
            loop {
                let finished = !matches!(
                    rx.recv_timeout(Duration::from_millis(100)),
                    Err(std::sync::mpsc::RecvTimeoutError::Timeout)
                );
                Python::attach(|py| {
                    if interrupted.is_none()
                        && let Err(e) = py.check_signals()
                    {
                        ticks.stop.store(true, Ordering::Relaxed);
                        interrupted = Some(e);
                    }
                    if let (Some(callback), None, None) = (&progress, &raised, &interrupted) {
                        let now = ticks.done.load(Ordering::Relaxed);
                        if now != told {
                            told = now;
                            if let Err(e) = callback.call1(py, (now, total)) {
                                raised = Some(e);
                            }
                        }
                    }
                });
                if finished {
                    break;
                }
            }
            (worker.join(), raised, interrupted)
        })
    });
    if let Some(e) = interrupted.or(raised) {
        return Err(e);
    }
    result.map_err(|_| PyRuntimeError::new_err("the computation panicked (a bug: please report it with the scenario)"))
}

/// Runs `work` with the GIL released, checking for signals every 0.1 s
/// ([`with_progress`] without a callback): Ctrl-C raises KeyboardInterrupt once the work
/// stops, which is at once where it reads [`Progress::stopped`] (a replay, row by row),
/// else when it is done; never a half-made result.
fn interruptible<T: Send>(py: Python<'_>, work: impl FnOnce(&dyn Progress) -> T + Send) -> PyResult<T> {
    with_progress(py, 0, None, work)
}

/// The memory budget ([`onebeacon_sim::budget`]: $ONEBEACON_MEMORY_GIB, else half this
/// machine's memory) checked for `s` with `concurrent` runs at once, `recorded` of them
/// kept whole.
fn check_memory(s: &Scenario, concurrent: usize, recorded: usize) -> PyResult<()> {
    Budget::resolve(None).and_then(|b| b.check_scenario(s, concurrent, recorded)).map_err(input_error)
}

/// One recorded run of a scenario (`onebeacon run`): `(trajectory, summary)`, the
/// trajectory a dict of float64 arrays (one per trajectory.csv column; pandas.DataFrame
/// takes it as is), the summary the dict of summary.json.
#[pyfunction]
#[pyo3(signature = (scenario, seed = None, run = 0))]
fn run<'py>(
    py: Python<'py>,
    scenario: &Bound<'py, PyAny>,
    seed: Option<u64>,
    run: u64,
) -> PyResult<Bound<'py, PyTuple>> {
    let s = scenario_of(scenario)?;
    check_memory(&s, 1, 1)?;
    let seed = seed.unwrap_or(s.seed());
    let cell = s.base_cell();
    let out = interruptible(py, |_| simulate(&s, &cell, seed, run, true))?;
    let columns = trajectory_dict(py, &s.vehicle_names(), &s.track_labels(), &out.trajectory)?;
    let summary = to_py(py, &onebeacon_sim::json::run_summary(&s, seed, run, &cell, &out))?;
    PyTuple::new(py, [columns.into_any(), summary])
}

/// Monte Carlo over the scenario's sweep (`onebeacon mc`): the cells of `mc --json`, a
/// list of dicts (one per cell and estimator), bit for bit the CLI's. The GIL is released
/// while it computes; `progress(done, total)` is called as runs finish.
#[pyfunction]
#[pyo3(signature = (scenario, runs = None, seed = None, threads = None, progress = None))]
fn mc<'py>(
    py: Python<'py>,
    scenario: &Bound<'py, PyAny>,
    runs: Option<usize>,
    seed: Option<u64>,
    threads: Option<usize>,
    progress: Option<Py<PyAny>>,
) -> PyResult<Bound<'py, PyAny>> {
    let s = scenario_of(scenario)?;
    let runs = runs.unwrap_or(s.runs());
    if !(1..=1_000_000).contains(&runs) {
        return Err(input_error(format!("runs = {runs}: must be 1 to 1000000")));
    }
    if threads.is_some_and(|t| !(1..=1024).contains(&t)) {
        return Err(input_error(format!("threads = {}: must be 1 to 1024", threads.unwrap_or(0))));
    }
    let seed = seed.unwrap_or(s.seed());
    check_memory(&s, concurrent_runs(threads, runs), 0)?;
    let total = runs * s.cells().len();
    let result = with_progress(py, total, progress, |tick| monte_carlo(&s, runs, seed, threads, tick))?
        .map_err(|e| PyRuntimeError::new_err(e.to_string()))?;
    let v = onebeacon_sim::json::mc(&s, &result, 0.0);
    to_py(py, &v["cells"])
}

/// The receiver chain on one capture (`onebeacon dsp process`): `samples` is a 2-d
/// array, one row per array element, starting at the transmit epoch, sampled at `fs`
/// Hz; `config` a ping configuration (a TOML file's path or a dict; defaults as `dsp
/// simulate`). Returns the dict of `dsp process --json`.
#[pyfunction]
#[pyo3(signature = (samples, fs, config = None))]
fn dsp_process<'py>(
    py: Python<'py>,
    samples: PyReadonlyArray2<'py, f64>,
    fs: f64,
    config: Option<&Bound<'py, PyAny>>,
) -> PyResult<Bound<'py, PyAny>> {
    let mut c = match config {
        None => PingConfig::default(),
        Some(d) if d.is_instance_of::<PyDict>() => {
            PingConfig::parse(&dict_to_toml(d, "ping config dict")?, "ping config dict").map_err(input_error)?
        }
        Some(p) => {
            let path: PathBuf =
                p.extract().map_err(|_| input_error("config: expected a path of a TOML file or a dict"))?;
            PingConfig::load(Some(&path.to_string_lossy())).map_err(input_error)?
        }
    };
    if !(fs.is_finite() && fs > 0.0) {
        return Err(input_error(format!("fs = {fs}: must be a positive sample rate, Hz")));
    }
    c.capture.fs_hz = fs;
    let view = samples.as_array();
    let elements = c.elements().len();
    if view.nrows() != elements {
        return Err(input_error(format!(
            "samples has {} rows; the configuration's array has {elements} elements (one row per element)",
            view.nrows()
        )));
    }
    if view.ncols() > c.capture.samples {
        return Err(input_error(format!(
            "samples has {} columns; one capture holds at most capture.samples = {} (the configuration's): cut a \
             longer recording into captures and process each (as `onebeacon dsp process` does), or set \
             capture.samples (at most 10000000)",
            view.ncols(),
            c.capture.samples
        )));
    }
    if view.iter().any(|x| !x.is_finite()) {
        return Err(input_error("samples holds NaN or infinite values"));
    }
    let captures: Vec<Vec<f64>> = view.rows().into_iter().map(|r| r.to_vec()).collect();
    let len = view.ncols();
    let found =
        interruptible(py, |_| Chain::new(c, len).map(|mut chain| chain.process(&captures)))?.map_err(input_error)?;
    to_py(py, &found.result)
}

#[pymodule]
fn _native(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    m.add("InputError", m.py().get_type::<InputError>())?;
    m.add_class::<PyScenario>()?;
    m.add_class::<navigator::PyNavigator>()?;
    m.add_function(wrap_pyfunction!(scenarios, m)?)?;
    m.add_function(wrap_pyfunction!(run, m)?)?;
    m.add_function(wrap_pyfunction!(mc, m)?)?;
    m.add_function(wrap_pyfunction!(logs::replay, m)?)?;
    m.add_function(wrap_pyfunction!(logs::smooth, m)?)?;
    m.add_function(wrap_pyfunction!(logs::rts, m)?)?;
    m.add_function(wrap_pyfunction!(dsp_process, m)?)?;
    Ok(())
}
