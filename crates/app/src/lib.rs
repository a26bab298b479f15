//! The application layer: what `vworks run`, Python's `Cell.run` and every variant of a
//! sweep do with a workcell, written once. A [`RunRequest`] goes in — the cell (a workcell
//! file with `--set` overrides, a variant of a [`Loader`], or a cell already loaded), the
//! time to stop at, the log to write, a stop flag — and a [`RunOutcome`] comes out: the
//! loaded cell, the run's result, the log written (or a typed [`RunError`]: the workcell
//! or its programs did not load, the log could not be created).
//!
//! The rules the callers used to decide each on their own are decided here:
//!
//! - **`until`** is a time from 0 ([`until_ns`]): `until = 0` runs what the cell does at
//!   its start (the zero-time work, the start's collision check) and stops there, outcome
//!   `until` — from the command line, from Python and in a sweep alike. A negative time, a
//!   time that is not finite or one past the engine's clock range is refused.
//! - **The log** is written to a temporary file beside its path and renamed when the run
//!   ends ([`vworks_model::output`]): never over one of the cell's input files, and a
//!   failed log leaves no half-written file; its errors name the path asked for.
//!
//! How a caller steps the simulation (a progress bar, programs' `log` lines, Ctrl-C on a
//! thread of its own) stays the caller's: [`start`] gives a [`Run`], and
//! [`Run::simulate`] hands its [`Simulation`] to the caller's loop.

use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::sync::atomic::AtomicBool;

use vworks_cell::{Cell, CellError, Disk, Loader, Override};
use vworks_log::mcaplog::McapLog;
use vworks_log::result::RunResult;
use vworks_se::Simulation;

/// The latest time a run may be asked to stop at (ns): the engine's clock range.
pub const UNTIL_LIMIT_NS: i64 = 1 << 62;

/// Why a time is not one to stop a run at.
#[derive(Clone, Copy, Debug, PartialEq, Eq, thiserror::Error)]
pub enum UntilError {
    /// Before the run starts.
    #[error("the time is before the run starts")]
    Negative,
    /// Not a number, or past the engine's clock range.
    #[error("the time is not finite or is past the engine's clock range")]
    OutOfRange,
}

/// A time to stop a run at, in seconds, as integer nanoseconds: any time from 0 (0 stops
/// the run after the work of its first instant) to [`UNTIL_LIMIT_NS`]. The one rule the
/// CLI, Python and sweep files apply; each words its own message.
pub fn until_ns(seconds: f64) -> Result<i64, UntilError> {
    if seconds.is_nan() || seconds == f64::INFINITY {
        return Err(UntilError::OutOfRange);
    }
    if seconds < 0.0 {
        return Err(UntilError::Negative);
    }
    let ns = (seconds * 1e9).round();
    if ns > UNTIL_LIMIT_NS as f64 {
        return Err(UntilError::OutOfRange);
    }
    Ok(ns as i64)
}

/// The workcell to run.
#[derive(Debug)]
pub enum CellSource<'a> {
    /// A workcell file, loaded from disk with these overrides (`--set PATH=VALUE`; none:
    /// the file as it is).
    File {
        /// The workcell file.
        path: &'a Path,
        /// Values changed by dotted path.
        overrides: &'a [Override],
    },
    /// A variant of a workcell loaded once (a sweep's [`Loader`]).
    Variant {
        /// The loader of the workcell.
        loader: &'a Loader<'a>,
        /// The variant's values.
        overrides: &'a [Override],
    },
    /// A cell already loaded (Python's `Cell`).
    Loaded(Arc<Cell>),
}

/// The log to write.
#[derive(Clone, Copy, Debug)]
pub struct LogRequest<'a> {
    /// Where.
    pub path: &'a Path,
    /// Every `every`-th cycle state (1: all).
    pub every: u64,
}

/// A run asked for.
#[derive(Debug)]
pub struct RunRequest<'a> {
    /// The workcell.
    pub cell: CellSource<'a>,
    /// Stop at this time (ns; see [`until_ns`]), or run to the end.
    pub until_ns: Option<i64>,
    /// Write an MCAP log.
    pub log: Option<LogRequest<'a>>,
    /// Set from outside (Ctrl-C, a watchdog) to end the run between two events.
    pub stop: Option<Arc<AtomicBool>>,
}

/// Why a run could not start.
#[derive(Debug, thiserror::Error)]
pub enum RunError {
    /// The workcell, its models or its programs did not load
    /// ([`CellError::Program`] carries the diagnostics and whether they are compile or
    /// link errors).
    #[error(transparent)]
    Load(#[from] CellError),
    /// The log could not be created (the message names the path asked for).
    #[error("{message}")]
    Log {
        /// The loaded cell.
        cell: Arc<Cell>,
        /// Why.
        message: String,
    },
}

/// What a run gave.
#[derive(Debug)]
pub struct RunOutcome {
    /// The cell that ran.
    pub cell: Arc<Cell>,
    /// The run's result; `log_error` says if its log is missing or incomplete.
    pub result: RunResult,
    /// The log written, complete, at the path asked for (`None`: none was asked for, or
    /// it failed: see `result.log_error`).
    pub log: Option<PathBuf>,
}

/// A run ready to simulate: the cell loaded and the simulation made, with its log.
#[derive(Debug)]
pub struct Run {
    /// The cell.
    pub cell: Arc<Cell>,
    /// The time to stop at (ns), if any.
    pub until_ns: Option<i64>,
    simulation: Simulation,
    /// The log's temporary file and the path asked for.
    log: Option<(PathBuf, PathBuf)>,
}

/// Every file a workcell was read from: what no output may overwrite.
pub fn inputs_of(cell: &Cell) -> Vec<PathBuf> {
    std::iter::once(cell.file.clone())
        .chain(
            cell.sources
                .iter()
                .map(|(p, _)| p)
                .chain(cell.files.iter().map(|(p, _)| p))
                .map(PathBuf::from),
        )
        .collect()
}

/// Loads the workcell a request names.
pub fn load(source: CellSource<'_>) -> Result<Arc<Cell>, CellError> {
    match source {
        CellSource::File {
            path,
            overrides: [],
        } => vworks_cell::load(path).map(Arc::new),
        CellSource::File { path, overrides } => Loader::new(path, &Disk)
            .and_then(|l| l.load(overrides))
            .map(Arc::new),
        CellSource::Variant { loader, overrides } => loader.load(overrides).map(Arc::new),
        CellSource::Loaded(cell) => Ok(cell),
    }
}

/// Loads the cell and makes its simulation, with the log if one is asked for.
pub fn start(request: RunRequest<'_>) -> Result<Run, RunError> {
    let cell = load(request.cell)?;
    let mut simulation = Simulation::new(Arc::clone(&cell));
    if let Some(stop) = request.stop {
        simulation = simulation.with_stop(stop);
    }
    let mut log = None;
    if let Some(LogRequest { path, every }) = request.log {
        let created = vworks_model::output::temp_beside(path, &inputs_of(&cell))
            .map_err(|e| e.to_string())
            .and_then(|temp| {
                McapLog::create(&temp, &Arc::new(vworks_se::describe(&cell)), every)
                    .map_err(|e| named(&e.to_string(), &temp, path))
                    .map(|l| (temp, l))
            });
        match created {
            Ok((temp, l)) => {
                simulation = simulation.with_log(l);
                log = Some((temp, path.to_path_buf()));
            }
            Err(message) => return Err(RunError::Log { cell, message }),
        }
    }
    Ok(Run {
        cell,
        until_ns: request.until_ns,
        simulation,
        log,
    })
}

/// Loads, runs to the end (or `until`) and finishes the log: [`start`], then
/// [`Run::run_to_end`].
pub fn run(request: RunRequest<'_>) -> Result<RunOutcome, RunError> {
    start(request).map(Run::run_to_end)
}

impl Run {
    /// Runs to the end, or to `until`.
    pub fn run_to_end(self) -> RunOutcome {
        let until = self.until_ns;
        self.simulate(|sim| sim.run(until))
    }

    /// Runs the simulation in the caller's way (`step` with a progress bar, on a thread
    /// of its own, …) and finishes the log: renamed to its path, or removed if it failed,
    /// its errors naming the path asked for.
    pub fn simulate(self, f: impl FnOnce(Simulation) -> RunResult) -> RunOutcome {
        let Run {
            cell,
            simulation,
            log,
            ..
        } = self;
        let mut result = f(simulation);
        let mut written = None;
        if let Some((temp, path)) = log {
            result.log_error = result.log_error.map(|m| named(&m, &temp, &path));
            if result.log_error.is_some() {
                vworks_model::output::discard(&temp, &path);
            } else if let Err(e) = vworks_model::output::finish(&temp, &path) {
                result.log_error = Some(e.to_string());
            } else {
                written = Some(path);
            }
        }
        RunOutcome {
            cell,
            result,
            log: written,
        }
    }
}

/// A message about the temporary file, naming the path asked for instead.
fn named(message: &str, temp: &Path, path: &Path) -> String {
    message.replace(&temp.display().to_string(), &path.display().to_string())
}
