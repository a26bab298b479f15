//! Python bindings of vworks: the `vworks._vworks` extension module, re-exported by the
//! `vworks` package (`crates/py/python/vworks`). Built with maturin (`pip install
//! ./crates/py`, or `maturin develop` in a virtualenv).
//!
//! What Python sees: `compile` → `Module`; `load_cell` → `Cell`; `Cell.run` → `Result`;
//! `Cell.simulation` → `Simulation` (stepping, robot state, globals, events); `read_log`;
//! `write_report`.
//! Times are seconds (floats) with `_ns` twins (integers); lengths metres, angles
//! radians. Errors are `vworks.Error` and its subclasses, never a crash: the library
//! does not panic on input, and a panic that slipped through would surface as pyo3's
//! `PanicException`, not an abort. Simulating releases the GIL; Ctrl-C ends a run
//! (`interrupt`) with `KeyboardInterrupt`.

use std::path::PathBuf;
use std::sync::Arc;
use std::sync::atomic::AtomicBool;

use pyo3::exceptions::{PyIndexError, PyKeyError, PyRuntimeError, PyRuntimeWarning, PyValueError};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList, PySlice};
use vworks_cell::CellError as WorkcellError;
use vworks_cell::Files as _;
use vworks_log::issue::Issue;
use vworks_log::mcaplog::LoggedEvent;
use vworks_log::result::{Outcome, RunResult};
use vworks_log::trace::{TraceEvent, Value};

mod errors;
mod interrupt;
mod place;
mod program;
mod sweep;
mod units;

use errors::{CellError, CompileError, Error, LinkError, SimulationError};
use program::{Diagnostic, Module, compile, compile_files, diagnostic, program_error};
use units::{secs, to_ns};

/// A loaded workcell: robots with their models and compiled, linked programs; devices;
/// parts. Run it whole (`run`) or step by step (`simulation`); a cell can be run many times.
#[pyclass(frozen, module = "vworks")]
struct Cell {
    cell: Arc<vworks_cell::Cell>,
}

/// Loads the workcell file at `path` (TOML). Raises `CellError` for a wrong workcell or
/// robot model, `CompileError` or `LinkError` (with `.diagnostics`) for its programs.
#[pyfunction]
fn load_cell(py: Python<'_>, path: PathBuf) -> PyResult<Cell> {
    let source = || {
        vworks_app::load(vworks_app::CellSource::File {
            path: &path,
            overrides: &[],
        })
    };
    match py.detach(source) {
        Ok(cell) => Ok(Cell { cell }),
        Err(WorkcellError::Program {
            stage,
            diagnostics,
            rendered,
        }) => {
            let mut sources = vworks_wslc::Sources::new();
            for d in &diagnostics {
                // Read as the loader read it: a regular file, within the size limit.
                let bytes = vworks_cell::Disk.read(std::path::Path::new(&d.at.file));
                let text = bytes
                    .ok()
                    .and_then(|b| vworks_wslc::source_text_of(&d.at.file, b).ok());
                if let Some(text) = text {
                    sources.add(&d.at.file, &text);
                }
            }
            let link = stage == vworks_cell::Stage::Link;
            let diags = diagnostics
                .iter()
                .map(|d| diagnostic(d, &sources))
                .collect();
            Err(program_error(py, link, rendered, diags))
        }
        Err(e) => Err(CellError::new_err(e.to_string())),
    }
}

#[pymethods]
impl Cell {
    /// The cell's name.
    #[getter]
    fn name(&self) -> String {
        self.cell.name.clone()
    }

    /// The workcell file.
    #[getter]
    fn file(&self) -> PathBuf {
        self.cell.file.clone()
    }

    /// The cycle (s): collisions are checked and states logged at every multiple of it.
    #[getter]
    fn cycle(&self) -> f64 {
        secs(self.cell.cycle_ns)
    }

    /// The robots' names, in workcell order.
    #[getter]
    fn robots(&self) -> Vec<String> {
        self.cell.robots.iter().map(|r| r.name.clone()).collect()
    }

    /// The devices' names.
    #[getter]
    fn devices(&self) -> Vec<String> {
        self.cell.devices.iter().map(|d| d.name.clone()).collect()
    }

    /// The parts' names.
    #[getter]
    fn parts(&self) -> Vec<String> {
        self.cell.parts.iter().map(|p| p.name.clone()).collect()
    }

    /// Runs the cell to the end, or to `until` seconds, releasing the GIL meanwhile.
    /// `log`: write an MCAP log there (every `log_every`-th cycle state). With `check`
    /// (the default) a runtime error raises `SimulationError` (its `.result` is the run)
    /// and a log that could not be written raises `Error`; without, both are in the result
    /// (`outcome == "error"`, `errors`, `log_error`). Collisions and deadlocks are results,
    /// not exceptions. Ctrl-C ends the run (its log finished) and raises
    /// `KeyboardInterrupt`.
    #[pyo3(signature = (until = None, log = None, log_every = 1, check = true))]
    fn run(
        &self,
        py: Python<'_>,
        until: Option<f64>,
        log: Option<PathBuf>,
        log_every: u64,
        check: bool,
    ) -> PyResult<RunReport> {
        let until = until.map(|t| to_ns(t, "until")).transpose()?;
        if log_every == 0 {
            return Err(PyValueError::new_err("log_every must be 1 or more"));
        }
        let stop = Arc::new(AtomicBool::new(false));
        let request = vworks_app::RunRequest {
            cell: vworks_app::CellSource::Loaded(Arc::clone(&self.cell)),
            until_ns: until,
            log: log.as_deref().map(|path| vworks_app::LogRequest {
                path,
                every: log_every,
            }),
            stop: Some(Arc::clone(&stop)),
        };
        let run = vworks_app::start(request).map_err(|e| Error::new_err(e.to_string()))?;
        let mut interrupted = None;
        let out = run.simulate(|sim| {
            let (r, i) = interrupt::interruptible(py, &stop, || sim.run(until));
            interrupted = i;
            r
        });
        if let Some(e) = interrupted {
            return Err(e);
        }
        let log_file = log.as_ref().map(|p| p.display().to_string());
        let failed = out.result.outcome == Outcome::Error;
        let report = RunReport::new(&self.cell, out.result, log_file.as_deref());
        if check && failed {
            return Err(report.simulation_error(py));
        }
        if let (true, Some(e)) = (check, &report.log_error) {
            // The log asked for is missing or incomplete.
            return Err(Error::new_err(e.clone()));
        }
        Ok(report)
    }

    /// A simulation of the cell at time 0, to step (`step_event`, `step_cycle`,
    /// `run_until`) and inspect (`robot(name)`, `globals`, `events_since`).
    fn simulation(&self) -> Simulation {
        let stop = Arc::new(AtomicBool::new(false));
        Simulation {
            cell: Arc::clone(&self.cell),
            sim: Some(
                vworks_se::Simulation::new(Arc::clone(&self.cell)).with_stop(Arc::clone(&stop)),
            ),
            result: None,
            stop,
        }
    }

    fn __repr__(&self) -> String {
        format!(
            "<Cell {} ({} robots, cycle {} s)>",
            self.cell.name,
            self.cell.robots.len(),
            secs(self.cell.cycle_ns)
        )
    }
}

/// One event of a run: a trace line's fields, and its typed details (`data`).
#[pyclass(frozen, module = "vworks")]
#[derive(Clone)]
struct Event {
    e: LoggedEvent,
}

#[pymethods]
impl Event {
    /// Simulated time (s).
    #[getter]
    fn time(&self) -> f64 {
        secs(self.e.time_ns)
    }

    /// Simulated time (ns).
    #[getter]
    fn time_ns(&self) -> i64 {
        self.e.time_ns
    }

    /// The robot, or `None` for cell events (a collision, a deadlock).
    #[getter]
    fn robot(&self) -> Option<&str> {
        self.e.robot.as_deref()
    }

    /// Kind, e.g. `motion_start`, `set`, `wait_until`, `collision_start`, `end`.
    #[getter]
    fn kind(&self) -> &'static str {
        self.e.kind.name()
    }

    /// What the trace line shows between kind and position (may be empty).
    #[getter]
    fn details(&self) -> &str {
        &self.e.details
    }

    /// The WSL file, if the event has a source position.
    #[getter]
    fn file(&self) -> Option<&str> {
        self.e.file.as_deref()
    }

    /// Its line (0 if none).
    #[getter]
    fn line(&self) -> u32 {
        self.e.line
    }

    /// Its column (0 if none).
    #[getter]
    fn col(&self) -> u32 {
        self.e.col
    }

    /// The event as a trace line: `time_ns robot kind details file:line:col`, `-` for an
    /// empty field (the golden traces' and `vworks log events`' format).
    fn trace_line(&self) -> String {
        self.e.line()
    }

    /// The typed details as a dict (keys by kind, as in the log's `/events` `data`:
    /// docs/log.md), or `None` for events without details.
    #[getter]
    fn data(&self, py: Python<'_>) -> PyResult<Py<PyAny>> {
        json_object(py, &self.e.data.to_json().to_string())
    }

    fn __repr__(&self) -> String {
        format!("<Event {}>", self.trace_line())
    }
}

/// JSON text as the Python object `json.loads` gives.
fn json_object(py: Python<'_>, json: &str) -> PyResult<Py<PyAny>> {
    Ok(py.import("json")?.call_method1("loads", (json,))?.unbind())
}

fn event(cell: &vworks_cell::Cell, e: &TraceEvent) -> Event {
    Event {
        e: e.resolve(&vworks_se::CellNames(cell)),
    }
}

/// A sequence of `Event`s (indexable, sliceable, iterable), with `to_pandas()`.
#[pyclass(frozen, sequence, module = "vworks")]
struct EventList {
    events: Vec<Event>,
}

#[pymethods]
impl EventList {
    fn __len__(&self) -> usize {
        self.events.len()
    }

    fn __getitem__(&self, py: Python<'_>, index: &Bound<'_, PyAny>) -> PyResult<Py<PyAny>> {
        if let Ok(slice) = index.cast::<PySlice>() {
            let ix = slice.indices(self.events.len() as isize)?;
            let mut events = Vec::new();
            let mut i = ix.start;
            while (ix.step > 0 && i < ix.stop) || (ix.step < 0 && i > ix.stop) {
                if let Some(e) = usize::try_from(i).ok().and_then(|i| self.events.get(i)) {
                    events.push(e.clone());
                }
                i += ix.step;
            }
            return Ok(Py::new(py, EventList { events })?.into_any());
        }
        let i: isize = index.extract()?;
        let n = self.events.len() as isize;
        let at = if i < 0 { i + n } else { i };
        match usize::try_from(at).ok().and_then(|a| self.events.get(a)) {
            Some(e) => Ok(Py::new(py, e.clone())?.into_any()),
            None => Err(PyIndexError::new_err(format!(
                "event index {i} out of range ({n} events)"
            ))),
        }
    }

    fn __iter__(slf: PyRef<'_, Self>) -> PyResult<Py<PyAny>> {
        let py = slf.py();
        let list = PyList::new(py, slf.events.iter().cloned())?;
        Ok(list.try_iter()?.into_any().unbind())
    }

    /// The events as a pandas DataFrame (columns: time, time_ns, robot, kind, details,
    /// file, line, col). Needs pandas (`pip install pandas`).
    fn to_pandas(&self, py: Python<'_>) -> PyResult<Py<PyAny>> {
        let pandas = py.import("pandas").map_err(|_| {
            pyo3::exceptions::PyImportError::new_err(
                "to_pandas needs pandas; install it with `pip install pandas`",
            )
        })?;
        let columns = PyDict::new(py);
        let e: Vec<&LoggedEvent> = self.events.iter().map(|e| &e.e).collect();
        columns.set_item(
            "time",
            e.iter().map(|e| secs(e.time_ns)).collect::<Vec<_>>(),
        )?;
        columns.set_item("time_ns", e.iter().map(|e| e.time_ns).collect::<Vec<_>>())?;
        columns.set_item(
            "robot",
            e.iter().map(|e| e.robot.clone()).collect::<Vec<_>>(),
        )?;
        columns.set_item("kind", e.iter().map(|e| e.kind.name()).collect::<Vec<_>>())?;
        columns.set_item(
            "details",
            e.iter().map(|e| e.details.clone()).collect::<Vec<_>>(),
        )?;
        columns.set_item("file", e.iter().map(|e| e.file.clone()).collect::<Vec<_>>())?;
        columns.set_item("line", e.iter().map(|e| e.line).collect::<Vec<_>>())?;
        columns.set_item("col", e.iter().map(|e| e.col).collect::<Vec<_>>())?;
        Ok(pandas.getattr("DataFrame")?.call1((columns,))?.unbind())
    }

    fn __repr__(&self) -> String {
        format!("<EventList of {} events>", self.events.len())
    }
}

/// Time spent by one robot.
#[pyclass(frozen, module = "vworks", get_all)]
#[derive(Clone)]
struct RobotStats {
    /// The robot.
    name: String,
    /// Seconds in motion.
    moving: f64,
    /// Seconds waiting (conditions, signals, joins).
    waiting: f64,
    /// Seconds neither moving nor waiting, from 0 to the run's end (delays, and after
    /// the program ended).
    idle: f64,
    /// Motions started.
    motions: u32,
    /// When its program ended (s): its cycle time.
    end_time: f64,
    /// The same in ns.
    end_time_ns: i64,
    /// How it ended: `ended`, `error`, `waiting`, `running`.
    ended: String,
}

#[pymethods]
impl RobotStats {
    fn __repr__(&self) -> String {
        format!(
            "<RobotStats {}: moving {:.3} s, waiting {:.3} s, idle {:.3} s, ended at {:.3} s>",
            self.name, self.moving, self.waiting, self.idle, self.end_time
        )
    }
}

/// A collision that started.
#[pyclass(frozen, module = "vworks", get_all)]
#[derive(Clone)]
struct Collision {
    /// When (s).
    time: f64,
    /// When (ns).
    time_ns: i64,
    /// First body (`r1.link_4`, a device or a part).
    a: String,
    /// Second body.
    b: String,
    /// Penetration depth (m).
    depth: f64,
    /// A contact point in the cell (m).
    point: (f64, f64, f64),
    /// Each robot whose body is in the pair and the motion it was making.
    motions: Vec<place::PyRobotMotion>,
}

#[pymethods]
impl Collision {
    fn __repr__(&self) -> String {
        format!(
            "<Collision {} {} at {:.3} s, depth {:.4} m>",
            self.a, self.b, self.time, self.depth
        )
    }
}

/// A warning or an error of a run.
#[pyclass(frozen, module = "vworks", get_all, name = "Issue")]
#[derive(Clone)]
struct PyIssue {
    /// `race`, `near_miss`, `slowdown`, `runtime`, `deadlock`, …
    kind: String,
    /// The message.
    message: String,
    /// The robot, if one.
    robot: Option<String>,
    /// The WSL file, if known.
    file: Option<String>,
    /// Line (0 if unknown).
    line: u32,
    /// Column (0 if unknown).
    col: u32,
    /// For a near miss, how close the bodies came (m).
    distance_m: Option<f64>,
    /// For a near miss, each robot in the pair and the motion it was making.
    motions: Vec<place::PyRobotMotion>,
}

#[pymethods]
impl PyIssue {
    fn __repr__(&self) -> String {
        format!("<Issue {}: {}>", self.kind, self.message)
    }
}

fn issue(i: &Issue) -> PyIssue {
    PyIssue {
        kind: i.kind.name().to_string(),
        message: i.message.clone(),
        robot: i.robot.clone(),
        file: i.file.clone(),
        line: i.line,
        col: i.col,
        distance_m: i.distance_m,
        motions: place::motions(&i.motions),
    }
}

fn value_object(py: Python<'_>, v: Value) -> PyResult<Py<PyAny>> {
    Ok(match v {
        Value::Bool(b) => b.into_pyobject(py)?.to_owned().into_any().unbind(),
        Value::Int(i) => i.into_pyobject(py)?.into_any().unbind(),
        Value::Num(x) => x.into_pyobject(py)?.into_any().unbind(),
        _ => py.None(),
    })
}

/// What a run produced.
#[pyclass(frozen, module = "vworks", name = "Result")]
struct RunReport {
    outcome: String,
    end_time_ns: i64,
    robots: Vec<RobotStats>,
    collisions: Vec<Collision>,
    warnings: Vec<PyIssue>,
    errors: Vec<PyIssue>,
    globals: Vec<(String, Value)>,
    events: Vec<Event>,
    logs: Vec<place::PyLogLine>,
    cycles: u64,
    log_counts: Vec<(String, u64)>,
    log_error: Option<String>,
    /// The result as `vworks run --json` prints it.
    json: String,
}

impl RunReport {
    fn new(cell: &vworks_cell::Cell, r: RunResult, log_file: Option<&str>) -> RunReport {
        RunReport {
            json: r.to_json(&cell.name, log_file).to_string(),
            outcome: r.outcome.name().to_string(),
            end_time_ns: r.end_time_ns,
            robots: r
                .robots
                .iter()
                .map(|s| RobotStats {
                    name: s.name.clone(),
                    moving: secs(s.moving_ns),
                    waiting: secs(s.waiting_ns),
                    idle: secs(s.idle_ns),
                    motions: s.motions,
                    end_time: secs(s.end_time_ns),
                    end_time_ns: s.end_time_ns,
                    ended: s.ended.name().to_string(),
                })
                .collect(),
            collisions: r
                .collisions
                .iter()
                .map(|c| Collision {
                    time: secs(c.time_ns),
                    time_ns: c.time_ns,
                    a: c.a.clone(),
                    b: c.b.clone(),
                    depth: c.depth,
                    point: (c.point[0], c.point[1], c.point[2]),
                    motions: place::motions(&c.motions),
                })
                .collect(),
            warnings: r.warnings.iter().map(issue).collect(),
            errors: r.errors.iter().map(issue).collect(),
            globals: r.global_values.clone(),
            events: r.trace.iter().map(|e| event(cell, e)).collect(),
            logs: r.logs.iter().map(place::log_line).collect(),
            cycles: r.cycles,
            log_counts: r
                .log_counts
                .iter()
                .map(|(k, v)| (k.to_string(), *v))
                .collect(),
            log_error: r.log_error.clone(),
        }
    }

    /// The `SimulationError` for this run's first error (its `.result` is the run).
    fn simulation_error(self, py: Python<'_>) -> PyErr {
        let first = self.errors.first().cloned();
        match Py::new(py, self) {
            Ok(report) => simulation_error(py, first.as_ref(), report.into_any()),
            Err(e) => e,
        }
    }
}

/// A `SimulationError` for the run's first error `first`, with its robot, file, line and
/// column as attributes and `result` (a `Result`, or None).
fn simulation_error(py: Python<'_>, first: Option<&PyIssue>, result: Py<PyAny>) -> PyErr {
    let message = first.map_or_else(|| "a robot's program failed".to_string(), error_text);
    let err = SimulationError::new_err(message);
    let set = || -> PyResult<()> {
        let v = err.value(py);
        v.setattr("robot", first.and_then(|i| i.robot.clone()))?;
        v.setattr("file", first.and_then(|i| i.file.clone()))?;
        v.setattr("line", first.map_or(0, |i| i.line))?;
        v.setattr("col", first.map_or(0, |i| i.col))?;
        v.setattr("result", result)?;
        Ok(())
    };
    match set() {
        Ok(()) => err,
        Err(e) => e,
    }
}

fn error_text(i: &PyIssue) -> String {
    match (&i.robot, &i.file) {
        (Some(r), Some(f)) => format!("{r}: {f}:{}:{}: {}", i.line, i.col, i.message),
        (Some(r), None) => format!("{r}: {}", i.message),
        _ => i.message.clone(),
    }
}

#[pymethods]
impl RunReport {
    /// How the run ended: `completed`, `collision`, `deadlock`, `error`, `until`.
    #[getter]
    fn outcome(&self) -> String {
        self.outcome.clone()
    }

    /// Simulated end time (s).
    #[getter]
    fn end_time(&self) -> f64 {
        secs(self.end_time_ns)
    }

    /// Simulated end time (ns).
    #[getter]
    fn end_time_ns(&self) -> i64 {
        self.end_time_ns
    }

    /// Per robot, in workcell order: time moving, waiting, idle, motions, cycle time.
    #[getter]
    fn robots(&self) -> Vec<RobotStats> {
        self.robots.clone()
    }

    /// The collisions that started, in order.
    #[getter]
    fn collisions(&self) -> Vec<Collision> {
        self.collisions.clone()
    }

    /// Warnings (races, near misses, slowdowns).
    #[getter]
    fn warnings(&self) -> Vec<PyIssue> {
        self.warnings.clone()
    }

    /// Errors (runtime errors, a deadlock).
    #[getter]
    fn errors(&self) -> Vec<PyIssue> {
        self.errors.clone()
    }

    /// The result as a dict, exactly as `vworks run --json` prints it (times in ns,
    /// globals as values of their type).
    fn to_dict(&self, py: Python<'_>) -> PyResult<Py<PyAny>> {
        json_object(py, &self.json)
    }

    /// Final values of the globals by name (bool, int, or float in SI units).
    #[getter]
    fn globals<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let d = PyDict::new(py);
        for (name, v) in &self.globals {
            d.set_item(name, value_object(py, *v)?)?;
        }
        Ok(d)
    }

    /// Every event of the run, in order (an `EventList`: `to_pandas()` for a DataFrame).
    #[getter]
    fn events(&self) -> EventList {
        EventList {
            events: self.events.clone(),
        }
    }

    /// The lines the programs logged, in order (`log` statements; also in `events`).
    #[getter]
    fn logs(&self) -> Vec<place::PyLogLine> {
        self.logs.clone()
    }

    /// Cycle boundaries passed.
    #[getter]
    fn cycles(&self) -> u64 {
        self.cycles
    }

    /// Messages written per log topic (empty without a log).
    #[getter]
    fn log_counts<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let d = PyDict::new(py);
        for (k, v) in &self.log_counts {
            d.set_item(k, v)?;
        }
        Ok(d)
    }

    /// Why the log could not be written, if it could not.
    #[getter]
    fn log_error(&self) -> Option<String> {
        self.log_error.clone()
    }

    fn __repr__(&self) -> String {
        format!(
            "<Result {} at {:.3} s: {} events, {} collisions>",
            self.outcome,
            secs(self.end_time_ns),
            self.events.len(),
            self.collisions.len()
        )
    }
}

/// The longest simulated span `run_until` runs on the calling thread (100 ms: 25 cycles
/// of 4 ms); a longer one runs on a thread of its own, so that Ctrl-C can stop it.
const INLINE_SPAN_NS: i64 = 100_000_000;

/// A running simulation of a cell: step it and look at it.
#[pyclass(module = "vworks")]
struct Simulation {
    cell: Arc<vworks_cell::Cell>,
    /// `None` once `result()` ended it.
    sim: Option<vworks_se::Simulation>,
    result: Option<Py<RunReport>>,
    /// Set by Ctrl-C during `run_until` or `run`: the run ends, outcome `interrupted`.
    stop: Arc<AtomicBool>,
}

impl Simulation {
    fn running(&self) -> PyResult<&vworks_se::Simulation> {
        self.sim
            .as_ref()
            .ok_or_else(|| Error::new_err("this simulation has ended: result() was called"))
    }

    /// Runs `f` on the simulation with the GIL released; raises `SimulationError` if a
    /// robot's program failed. Returns whether the run goes on. With `interruptible` (work
    /// that may take long), Ctrl-C ends the run (outcome `interrupted`) and raises
    /// `KeyboardInterrupt`; a single step is short and runs on this thread.
    fn drive(
        &mut self,
        py: Python<'_>,
        interruptible: bool,
        f: impl FnOnce(&mut vworks_se::Simulation) -> bool + Send,
    ) -> PyResult<bool> {
        let sim = self
            .sim
            .as_mut()
            .ok_or_else(|| Error::new_err("this simulation has ended: result() was called"))?;
        let going = if interruptible {
            let (going, interrupted) = interrupt::interruptible(py, &self.stop, || f(sim));
            if let Some(e) = interrupted {
                return Err(e);
            }
            going
        } else {
            py.detach(|| f(sim))
        };
        if sim.outcome() == Some(Outcome::Error) {
            let first = sim.errors().first().map(issue);
            return Err(simulation_error(py, first.as_ref(), py.None()));
        }
        Ok(going)
    }

    fn robot_index(&self, name: &str) -> PyResult<usize> {
        self.cell
            .robots
            .iter()
            .position(|r| r.name == name)
            .ok_or_else(|| {
                let names: Vec<&str> = self.cell.robots.iter().map(|r| r.name.as_str()).collect();
                PyKeyError::new_err(format!(
                    "no robot `{name}` in cell `{}`; its robots: {}",
                    self.cell.name,
                    names.join(", ")
                ))
            })
    }
}

#[pymethods]
impl Simulation {
    /// Handles the next event (and the cycle boundaries before it). Returns False once
    /// the run is over. Raises `SimulationError` if a robot's program fails.
    fn step_event(&mut self, py: Python<'_>) -> PyResult<bool> {
        self.drive(py, false, |s| s.step(None))
    }

    /// Runs to the next cycle boundary and processes it (collision check). Returns False
    /// once the run is over.
    fn step_cycle(&mut self, py: Python<'_>) -> PyResult<bool> {
        self.drive(py, false, |s| {
            let b = s.next_boundary();
            s.advance_to(b)
        })
    }

    /// Runs everything due up to `t` seconds and moves the clock there (unless the run
    /// ends first). Returns False once the run is over. Ctrl-C ends the run (outcome
    /// `interrupted`) and raises `KeyboardInterrupt`.
    fn run_until(&mut self, py: Python<'_>, t: f64) -> PyResult<bool> {
        let t = to_ns(t, "t")?;
        // A short span runs on this thread (a thread of its own would cost more than it):
        // Python sees a Ctrl-C as soon as it returns.
        let long = t.saturating_sub(self.running()?.time()) > INLINE_SPAN_NS;
        self.drive(py, long, move |s| s.advance_to(t))
    }

    /// Runs to the end and returns the `Result` (as `Cell.run(check=False)` would).
    /// Ctrl-C ends the run (outcome `interrupted`) and raises `KeyboardInterrupt`.
    fn run(&mut self, py: Python<'_>) -> PyResult<Py<RunReport>> {
        self.drive(py, true, |s| {
            while s.step(None) {}
            false
        })
        .or_else(|e| {
            if e.is_instance_of::<SimulationError>(py) {
                Ok(false)
            } else {
                Err(e)
            }
        })?;
        self.result(py)
    }

    /// Ends the simulation where it is and returns its `Result` (statistics up to now).
    /// Afterwards only `result()` and `time` work.
    fn result(&mut self, py: Python<'_>) -> PyResult<Py<RunReport>> {
        if let Some(r) = &self.result {
            return Ok(r.clone_ref(py));
        }
        let sim = self
            .sim
            .take()
            .ok_or_else(|| Error::new_err("this simulation has no result"))?;
        let r = py.detach(|| sim.into_result());
        let report = Py::new(py, RunReport::new(&self.cell, r, None))?;
        self.result = Some(report.clone_ref(py));
        Ok(report)
    }

    /// Simulated time now (s).
    #[getter]
    fn time(&self, py: Python<'_>) -> PyResult<f64> {
        Ok(secs(self.time_ns(py)?))
    }

    /// Simulated time now (ns).
    #[getter]
    fn time_ns(&self, py: Python<'_>) -> PyResult<i64> {
        match (&self.sim, &self.result) {
            (Some(s), _) => Ok(s.time()),
            (None, Some(r)) => Ok(r.borrow(py).end_time_ns),
            (None, None) => Err(Error::new_err("this simulation has ended")),
        }
    }

    /// How the run ended (`completed`, `collision`, `deadlock`, `error`), or None while
    /// it goes on.
    #[getter]
    fn outcome(&self) -> PyResult<Option<String>> {
        Ok(self.running()?.outcome().map(|o| o.name().to_string()))
    }

    /// The robots' names.
    #[getter]
    fn robots(&self) -> Vec<String> {
        self.cell.robots.iter().map(|r| r.name.clone()).collect()
    }

    /// A live view of robot `name`: `.joints` and `.tcp` are read when asked.
    fn robot(slf: Bound<'_, Self>, name: &str) -> PyResult<Robot> {
        let index = reading(slf.try_borrow())?.robot_index(name)?;
        Ok(Robot {
            sim: slf.unbind(),
            index,
            name: name.to_string(),
        })
    }

    /// The cell's globals now, by name: a read-only mapping (bool, int, or float in SI
    /// units).
    #[getter]
    fn globals<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let d = PyDict::new(py);
        for (name, v) in self.running()?.global_values() {
            d.set_item(name, value_object(py, v)?)?;
        }
        py.import("types")?.getattr("MappingProxyType")?.call1((d,))
    }

    /// The events from index `i` on (0: all so far); with `len(...)` of an earlier call,
    /// the new ones.
    #[pyo3(signature = (i = 0))]
    fn events_since(&self, i: usize) -> PyResult<EventList> {
        let sim = self.running()?;
        let events = sim
            .trace()
            .get(i..)
            .unwrap_or_default()
            .iter()
            .map(|e| event(&self.cell, e))
            .collect();
        Ok(EventList { events })
    }

    fn __repr__(&self) -> String {
        match &self.sim {
            Some(s) => format!(
                "<Simulation of {} at {:.3} s>",
                self.cell.name,
                secs(s.time())
            ),
            None => format!("<Simulation of {} (ended)>", self.cell.name),
        }
    }
}

/// The simulation to read, or the `RuntimeError` pyo3 raises for a method called while
/// another thread steps it (a `Robot`'s `.joints` would otherwise panic).
fn reading<T>(borrowed: Result<T, pyo3::pycell::PyBorrowError>) -> PyResult<T> {
    borrowed.map_err(|e| {
        PyRuntimeError::new_err(format!(
            "{e}: another thread is stepping this simulation; read it between steps"
        ))
    })
}

/// A robot of a running `Simulation`.
#[pyclass(frozen, module = "vworks")]
struct Robot {
    sim: Py<Simulation>,
    index: usize,
    name: String,
}

#[pymethods]
impl Robot {
    /// Its name.
    #[getter]
    fn name(&self) -> String {
        self.name.clone()
    }

    /// Its joints now, one per axis (rad, or m for linear axes), as a numpy array.
    #[getter]
    fn joints<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let sim = reading(self.sim.try_borrow(py))?;
        let q = sim.running()?.joints(self.index);
        py.import("numpy")?.getattr("array")?.call1((q,))
    }

    /// Its TCP in the cell now (base × flange × tool) as a 4×4 homogeneous matrix (numpy;
    /// metres).
    #[getter]
    fn tcp<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let sim = reading(self.sim.try_borrow(py))?;
        let p = sim.running()?.tcp(self.index);
        let rows: Vec<Vec<f64>> = (0..4)
            .map(|i| {
                if i < 3 {
                    vec![p.r[i][0], p.r[i][1], p.r[i][2], p.t[i]]
                } else {
                    vec![0.0, 0.0, 0.0, 1.0]
                }
            })
            .collect();
        py.import("numpy")?.getattr("array")?.call1((rows,))
    }

    fn __repr__(&self) -> String {
        format!("<Robot {}>", self.name)
    }
}

/// The events of an MCAP log written by `vworks run --log` or `Cell.run(log=...)`. A log
/// cut short (the run was killed) gives the events before the damage, with a
/// `RuntimeWarning`. Raises `Error` for a file that is not a vworks log.
#[pyfunction]
fn read_log(py: Python<'_>, path: PathBuf) -> PyResult<EventList> {
    let log = py
        .detach(|| vworks_log::mcaplog::read_log(&path))
        .map_err(|e| Error::new_err(e.to_string()))?;
    if let Some((read, damage)) = &log.damage {
        let msg = format!(
            "{} is unfinished or damaged after {read} messages ({damage}); the events before that were read",
            path.display()
        );
        warn_runtime(py, msg)?;
    }
    Ok(EventList {
        events: log.events.into_iter().map(|e| Event { e }).collect(),
    })
}

/// Issues a Python `RuntimeWarning` with `msg` (a damaged log: what was read is returned).
fn warn_runtime(py: Python<'_>, msg: String) -> PyResult<()> {
    PyErr::warn(
        py,
        &py.get_type::<PyRuntimeWarning>(),
        &std::ffi::CString::new(msg).unwrap_or_default(),
        1,
    )
}

/// Writes the HTML report of a run from its MCAP log: the cell in 3D played back over a
/// timeline, a Gantt chart per robot, cycle times, collisions, warnings and the filterable
/// event table, in one self-contained file (what `vworks report` writes). `output`
/// defaults to the log's path with `.html`; returns the path written. Raises `Error` for a
/// file that is not a vworks log or an output that cannot be written; warns
/// (`RuntimeWarning`) for a damaged log, whose report shows what was read.
#[pyfunction]
#[pyo3(signature = (log, output=None))]
fn write_report(py: Python<'_>, log: PathBuf, output: Option<PathBuf>) -> PyResult<PathBuf> {
    let out = output.unwrap_or_else(|| log.with_extension("html"));
    let written = py
        .detach(|| vworks_report::write_report(&log, &out).map_err(|e| e.to_string()))
        .map_err(Error::new_err)?;
    if let Some((read, why)) = written.damage {
        let msg = format!(
            "{} is unfinished or damaged after {read} messages ({why}); the report shows what was read",
            log.display()
        );
        warn_runtime(py, msg)?;
    }
    Ok(out)
}

/// The `vworks._vworks` extension module.
#[pymodule]
fn _vworks(m: &Bound<'_, PyModule>) -> PyResult<()> {
    let py = m.py();
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    m.add_function(wrap_pyfunction!(compile, m)?)?;
    m.add_function(wrap_pyfunction!(compile_files, m)?)?;
    m.add_function(wrap_pyfunction!(load_cell, m)?)?;
    m.add_function(wrap_pyfunction!(read_log, m)?)?;
    m.add_function(wrap_pyfunction!(write_report, m)?)?;
    m.add_function(wrap_pyfunction!(sweep::run_variants, m)?)?;
    m.add_function(wrap_pyfunction!(sweep::cell_files, m)?)?;
    m.add_class::<Module>()?;
    m.add_class::<Diagnostic>()?;
    m.add_class::<Cell>()?;
    m.add_class::<RunReport>()?;
    m.add_class::<RobotStats>()?;
    m.add_class::<Collision>()?;
    m.add_class::<PyIssue>()?;
    m.add_class::<place::PyRobotMotion>()?;
    m.add_class::<place::PyLogLine>()?;
    m.add_class::<Event>()?;
    m.add_class::<EventList>()?;
    m.add_class::<Simulation>()?;
    m.add_class::<Robot>()?;
    m.add("Error", py.get_type::<Error>())?;
    m.add("CompileError", py.get_type::<CompileError>())?;
    m.add("LinkError", py.get_type::<LinkError>())?;
    m.add("CellError", py.get_type::<CellError>())?;
    m.add("SimulationError", py.get_type::<SimulationError>())?;
    Ok(())
}
