//! What a run produced ([`RunResult`]) and how it ended ([`Outcome`]), and their one JSON
//! form: `vworks run --json` prints it, Python's `Result.to_json` returns it
//! (docs/engine.md, "Results").

use std::collections::BTreeMap;

use serde_json::{Value as Json, json};

use crate::issue::Issue;
use crate::place::{Contact, LogLine};
use crate::stats::RobotStats;
use crate::trace::{TraceEvent, Value};

/// How the run ended.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Outcome {
    /// Every robot's program ended and no remote work is queued.
    Completed,
    /// A collision with `on_collision = "stop"`.
    Collision,
    /// Every unfinished robot waits and no timed event is pending.
    Deadlock,
    /// A runtime error.
    Error,
    /// The `until` time was reached.
    Until,
    /// Stopped from outside (Ctrl-C) through the engine's `Simulation::with_stop`.
    Interrupted,
}

impl Outcome {
    /// As in `run --json`.
    pub fn name(self) -> &'static str {
        match self {
            Outcome::Completed => "completed",
            Outcome::Collision => "collision",
            Outcome::Deadlock => "deadlock",
            Outcome::Error => "error",
            Outcome::Until => "until",
            Outcome::Interrupted => "interrupted",
        }
    }
}

/// What a run produced.
#[derive(Clone, Debug)]
pub struct RunResult {
    /// How it ended.
    pub outcome: Outcome,
    /// Simulated end time (ns).
    pub end_time_ns: i64,
    /// Per robot.
    pub robots: Vec<RobotStats>,
    /// Collisions that started.
    pub collisions: Vec<Contact>,
    /// Warnings.
    pub warnings: Vec<Issue>,
    /// Errors (runtime errors, deadlock).
    pub errors: Vec<Issue>,
    /// Final values of the globals, by name, formatted with units (as `run` prints them).
    pub globals: Vec<(String, String)>,
    /// Final values of the globals, by name.
    pub global_values: Vec<(String, Value)>,
    /// The event trace.
    pub trace: Vec<TraceEvent>,
    /// The lines the programs logged, in order (also in the trace, as `log` events).
    pub logs: Vec<LogLine>,
    /// Cycle boundaries passed and collision queries made.
    pub cycles: u64,
    /// Narrow-phase queries made.
    pub queries: u64,
    /// Messages written per topic by the run's sinks (the MCAP log; empty without one).
    pub log_counts: BTreeMap<&'static str, u64>,
    /// Why a sink (the log) could not be written completely, if one could not.
    pub log_error: Option<String>,
}

impl RunResult {
    /// The result as JSON (`cell`: the cell's name): the contract's fields (outcome,
    /// end time, robots, collisions, warnings, errors, globals as JSON values of their
    /// type), the run's counts, and `log` if a log was written to `log_file`.
    pub fn to_json(&self, cell: &str, log_file: Option<&str>) -> Json {
        json!({
            "cell": cell,
            "outcome": self.outcome.name(),
            "end_time_ns": self.end_time_ns,
            "robots": self.robots.iter().map(|s| json!({
                "name": s.name, "moving_ns": s.moving_ns, "waiting_ns": s.waiting_ns, "idle_ns": s.idle_ns,
                "motions": s.motions, "end_time_ns": s.end_time_ns, "ended": s.ended.name(),
            })).collect::<Vec<_>>(),
            "collisions": self.collisions.iter().map(Contact::to_json).collect::<Vec<_>>(),
            "warnings": self.warnings.iter().map(Issue::to_json).collect::<Vec<_>>(),
            "errors": self.errors.iter().map(Issue::to_json).collect::<Vec<_>>(),
            "logs": self.logs.iter().map(LogLine::to_json).collect::<Vec<_>>(),
            "globals": self.global_values.iter().map(|(k, v)| (k.clone(), v.to_json())).collect::<serde_json::Map<_, _>>(),
            "cycles": self.cycles,
            "collision_queries": self.queries,
            // Narrow-phase queries per cycle boundary (adaptive checking and the sweep
            // between boundaries included).
            "queries_per_cycle": if self.cycles > 0 { self.queries as f64 / self.cycles as f64 } else { 0.0 },
            "events": self.trace.len(),
            "log": log_file.map(|f| json!({
                "file": f,
                "messages": self.log_counts,
                "error": self.log_error,
            })),
        })
    }
}
