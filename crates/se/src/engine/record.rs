//! The run's recording ([`Recording`]): the trace, the warnings, errors and collisions, the
//! time per robot folded over the events as they are recorded, and the sinks every event
//! and boundary goes to (the MCAP log).

use std::collections::BTreeMap;

use vworks_cell::Cell;
use vworks_vm::bytecode::SrcPos;

use crate::world::World;
use vworks_log::issue::{Issue, IssueKind};
use vworks_log::place::Contact;
use vworks_log::sink::{RunEnd, RunSink};
use vworks_log::stats::{Fold, RobotStats};
use vworks_log::trace::{Detail, Kind, TraceEvent};

use super::limit::EVENT_LIMIT;

/// What the run recorded, as the run goes.
pub(super) struct Recording {
    trace: Vec<TraceEvent>,
    warnings: Vec<Issue>,
    errors: Vec<Issue>,
    collisions: Vec<Contact>,
    /// Time per robot, folded over the events as they are recorded.
    fold: Fold,
    /// Consumers of the run (the MCAP log), and the first error one of them had (a sink
    /// that fails is dropped).
    sinks: Vec<Box<dyn RunSink>>,
    log_error: Option<String>,
    /// How many events the trace may hold (see `Simulation::with_event_limit`).
    event_limit: u64,
}

impl std::fmt::Debug for Recording {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Recording")
            .field("events", &self.trace.len())
            .field("warnings", &self.warnings.len())
            .field("errors", &self.errors.len())
            .field("sinks", &self.sinks.len())
            .finish()
    }
}

/// What a finished recording hands to the run's result.
pub(super) struct Recorded {
    pub(super) trace: Vec<TraceEvent>,
    pub(super) warnings: Vec<Issue>,
    pub(super) errors: Vec<Issue>,
    pub(super) collisions: Vec<Contact>,
    pub(super) robots: Vec<RobotStats>,
    pub(super) log_counts: BTreeMap<&'static str, u64>,
    pub(super) log_error: Option<String>,
}

impl Recording {
    /// An empty recording of `cell`'s run: its warnings open with the programs' compile
    /// and link warnings (kind: the code).
    pub(super) fn new(cell: &Cell) -> Recording {
        let warnings = cell
            .warnings
            .iter()
            .map(|d| Issue {
                kind: IssueKind::Compiler(d.code.as_str().to_string()),
                message: d.message.clone(),
                robot: None,
                file: Some(d.at.file.clone()),
                line: d.at.line,
                col: d.at.col,
                distance_m: None,
                motions: Vec::new(),
            })
            .collect();
        Recording {
            trace: Vec::new(),
            warnings,
            errors: Vec::new(),
            collisions: Vec::new(),
            fold: Fold::new(cell.robots.iter().map(|r| r.name.clone()).collect(), false),
            sinks: Vec::new(),
            log_error: None,
            event_limit: EVENT_LIMIT,
        }
    }

    /// Hands every event and boundary to `sink` as well.
    pub(super) fn add_sink(&mut self, sink: Box<dyn RunSink>) {
        self.sinks.push(sink);
    }

    /// Whether a sink is attached.
    pub(super) fn has_sinks(&self) -> bool {
        !self.sinks.is_empty()
    }

    /// Whether a sink records every boundary.
    pub(super) fn records_cycles(&self) -> bool {
        self.sinks.iter().any(|s| s.records_cycles())
    }

    /// How many events the trace may hold.
    pub(super) fn set_event_limit(&mut self, limit: u64) {
        self.event_limit = limit.max(1);
    }

    /// How many events the trace may hold.
    pub(super) fn event_limit(&self) -> u64 {
        self.event_limit
    }

    /// Whether the trace holds as many events as it may.
    pub(super) fn is_full(&self) -> bool {
        self.trace.len() as u64 >= self.event_limit
    }

    /// The trace so far.
    pub(super) fn trace(&self) -> &[TraceEvent] {
        &self.trace
    }

    /// The warnings so far.
    pub(super) fn warnings(&self) -> &[Issue] {
        &self.warnings
    }

    /// The errors so far.
    pub(super) fn errors(&self) -> &[Issue] {
        &self.errors
    }

    /// An event that counts in robot `robot`'s time (see [`Fold::event`]), not recorded.
    pub(super) fn count(&mut self, time: i64, robot: Option<usize>, kind: Kind) {
        self.fold.event(time, robot, kind);
    }

    /// Records an event: into the trace and to every sink (positions only for robots'
    /// events, and only real ones).
    pub(super) fn record(
        &mut self,
        time: i64,
        robot: Option<usize>,
        kind: Kind,
        detail: Detail,
        pos: Option<SrcPos>,
    ) {
        let pos = match (robot, pos) {
            (Some(_), Some(p)) if p.line > 0 => Some(p),
            _ => None,
        };
        self.trace.push(TraceEvent {
            time,
            robot,
            kind,
            detail,
            pos,
        });
        if !self.sinks.is_empty()
            && let Some(e) = self.trace.last()
        {
            let failed = &mut self.log_error;
            self.sinks.retain_mut(|s| match s.event(e) {
                Ok(()) => true,
                Err(err) => {
                    failed.get_or_insert(err);
                    false
                }
            });
        }
    }

    /// Hands the state at boundary `b` to the sinks (only when one is attached).
    pub(super) fn log_cycle(&mut self, b: i64, world: &World) {
        if self.sinks.is_empty() {
            return;
        }
        let failed = &mut self.log_error;
        self.sinks.retain_mut(|s| match s.cycle(b, world) {
            Ok(()) => true,
            Err(err) => {
                failed.get_or_insert(err);
                false
            }
        });
    }

    /// An issue of `kind` found in robot `robot`'s program at `pos` (or in the cell).
    pub(super) fn issue(
        cell: &Cell,
        kind: IssueKind,
        message: String,
        robot: Option<usize>,
        pos: Option<SrcPos>,
    ) -> Issue {
        Issue {
            kind,
            message,
            robot: robot.map(|r| cell.robots[r].name.clone()),
            file: robot
                .zip(pos)
                .map(|(r, p)| cell.robots[r].module.file_of(p).to_string()),
            line: pos.map_or(0, |p| p.line),
            col: pos.map_or(0, |p| p.col),
            distance_m: None,
            motions: Vec::new(),
        }
    }

    /// A `warning` or `error` trace event (`severity`) and the run's warning or error
    /// `issue`. An error counts in its robot's statistics (it ends the robot).
    pub(super) fn add_issue(
        &mut self,
        t: i64,
        robot: Option<usize>,
        pos: Option<SrcPos>,
        severity: Kind,
        issue: Issue,
    ) {
        if severity == Kind::Error {
            self.errors.push(issue.clone());
            self.fold.event(t, robot, Kind::Error);
        } else {
            self.warnings.push(issue.clone());
        }
        self.record(t, robot, severity, Detail::Issue(Box::new(issue)), pos);
    }

    /// A `warning` trace event and the run's warning of `kind`.
    pub(super) fn warning(
        &mut self,
        cell: &Cell,
        t: i64,
        robot: Option<usize>,
        pos: Option<SrcPos>,
        kind: IssueKind,
        message: String,
    ) {
        let issue = Recording::issue(cell, kind, message, robot, pos);
        self.add_issue(t, robot, pos, Kind::Warning, issue);
    }

    /// An `error` trace event (the message quoted) and the run's error of `kind`.
    pub(super) fn error(
        &mut self,
        cell: &Cell,
        t: i64,
        robot: Option<usize>,
        pos: Option<SrcPos>,
        kind: IssueKind,
        message: String,
    ) {
        let issue = Recording::issue(cell, kind, message, robot, pos);
        self.add_issue(t, robot, pos, Kind::Error, issue);
    }

    /// A runtime error a VM reported in its own event (already recorded as that event):
    /// the run's error only.
    pub(super) fn vm_error(&mut self, issue: Issue) {
        self.errors.push(issue);
    }

    /// A collision started: a `collision_start` event and the run's collision.
    pub(super) fn collision(&mut self, contact: Contact) {
        let detail = Detail::Collision(Box::new(contact.clone()));
        self.record(contact.time_ns, None, Kind::CollisionStart, detail, None);
        self.collisions.push(contact);
    }

    /// Ends the recording at `end`: the time per robot (`ending`: how each robot ended),
    /// every sink finished with the run's end.
    pub(super) fn finish(
        self,
        end: i64,
        outcome: vworks_log::result::Outcome,
        ending: &dyn Fn(usize) -> Option<vworks_log::stats::Ending>,
    ) -> Recorded {
        let (robots, _) = self.fold.finish(end, ending);
        let run_end = RunEnd {
            outcome,
            end_time_ns: end,
            robots: &robots,
        };
        let mut log_counts = BTreeMap::new();
        let mut log_error = self.log_error;
        for mut sink in self.sinks {
            match sink.finish(&run_end) {
                Ok(c) => log_counts.extend(c),
                Err(e) => {
                    log_error.get_or_insert(e);
                }
            }
        }
        Recorded {
            trace: self.trace,
            warnings: self.warnings,
            errors: self.errors,
            collisions: self.collisions,
            robots,
            log_counts,
            log_error,
        }
    }
}
