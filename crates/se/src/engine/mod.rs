//! The simulation management module: the paper's algorithm (section 3.2, figure 3).
//!
//! 1. Every VM runs to its first event, which goes into the event queue.
//! 2. The earliest entry (time, then the sequence number given when it was queued) is
//!    taken; its VM performs the event.
//! 3. On `set`, `check_wait`/`check_when` entries are queued for exactly the robots whose
//!    wait condition or condition handlers read that global — queued, not called, so
//!    events already due for those robots run first.
//! 4. The VM's next event is queued. Repeat until every robot has ended, a collision
//!    stops the run, a runtime error, a deadlock, or `until`.
//!
//! Cycle boundaries k·cycle are synchronisation points: before any event at or after a
//! boundary, every robot's state at the boundary is sampled and collisions are checked
//! ([`crate::collide`]). A VM's queued entry carries a generation number; when the VM's
//! next event changes (a wait released, a request arrived), the old entry is skipped.
//!
//! [`Simulation`] is the loop and the dispatcher; its state lives in components that own
//! it: the event queue (`queue`), the WAIT and WHEN lists (`lists`), the race detector
//! (`races`), the cell globals (`globals`), the remote queues (`remote`), the sync points
//! (`sync`), the run's recording (`record`: trace, fold, sinks), the boundary clock with
//! the collider (`boundary`) and the run's limits (`limit`). `route` routes a performed
//! event through them.

use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};

use vworks_model::math::Iso;
use vworks_vm::bytecode::SrcPos;
use vworks_vm::machine::{Event, EventKind, Next, Vm, VmConfig};
use vworks_vm::types::fmt_quantity;

use vworks_cell::Cell;
use vworks_log::issue::{Issue, IssueKind};
use vworks_log::result::{Outcome, RunResult};
use vworks_log::sink::RunSink;
use vworks_log::stats::Ending;
use vworks_log::trace::format_value;
use vworks_log::trace::{Detail, Kind, TraceEvent, Value};

mod boundary;
mod globals;
mod limit;
mod lists;
mod queue;
mod races;
mod record;
mod remote;
mod route;
mod sync;

pub use limit::{EVENT_LIMIT, INSTANT_LIMIT};

use boundary::Boundaries;
use globals::CellGlobals;
use limit::InstantLimit;
use lists::WaitLists;
use queue::{Entry, EventQueue};
use races::{RaceDetector, Seen};
use record::Recording;
use remote::RemoteQueues;
use sync::SyncPoints;

/// A running simulation of a cell.
#[derive(Debug)]
pub struct Simulation {
    cell: Arc<Cell>,
    vms: Vec<Vm>,
    queue: EventQueue,
    /// The paper's WAIT and WHEN lists.
    lists: WaitLists,
    races: RaceDetector,
    globals: CellGlobals,
    /// Per robot and signal site: the receiving robot and the signal's index in its VM
    /// (`None`: the receiver never waits for it).
    signal_to: Vec<Vec<(usize, Option<u32>)>>,
    remotes: RemoteQueues,
    syncs: SyncPoints,
    recording: Recording,
    /// The cycle boundaries, the collision checks at them and the sweeps between them.
    boundaries: Boundaries,
    /// The queue entries handled at one instant, against the limit.
    instants: InstantLimit,
    time: i64,
    outcome: Option<Outcome>,
    /// Whether every robot has been queued (the first step does it).
    started: bool,
    /// Set from outside to stop the run between two events.
    stop: Option<Arc<AtomicBool>>,
}

/// A VM per robot of `cell`, in the workcell's order, each at its home with the cell's
/// cycle and the robot's defaults and tool (none has run yet): what a simulation starts
/// from, and what `vworks check` looks at the cell's start with.
pub fn robot_vms(cell: &Cell) -> Vec<Vm> {
    cell.robots
        .iter()
        .enumerate()
        .map(|(i, r)| {
            let cfg = VmConfig {
                cycle_ns: cell.cycle_ns,
                default_speed: r.default_speed,
                default_zone: r.default_zone,
                tool: r.tool,
                start_joints: r.home.clone(),
                robot: i as u32,
                ..VmConfig::default()
            };
            Vm::new(Arc::clone(&r.module), Arc::clone(&r.model), cfg, r.entry)
        })
        .collect()
}

impl Simulation {
    /// A simulation of `cell` at time 0, every VM created (none has run yet).
    pub fn new(cell: Arc<Cell>) -> Simulation {
        let n = cell.robots.len();
        let vms = robot_vms(&cell);
        let signal_to = (0..n)
            .map(|r| {
                let m = &cell.robots[r].module;
                cell.linked.robots[r]
                    .signals
                    .iter()
                    .zip(&m.signals_sent)
                    .map(|(target, sent)| {
                        let target = *target as usize;
                        let idx = vms
                            .get(target)
                            .and_then(|v: &Vm| v.signal_index(m.str(sent.name)));
                        (target, idx)
                    })
                    .collect()
            })
            .collect();
        let globals = cell.linked.globals.len();
        Simulation {
            vms,
            signal_to,
            queue: EventQueue::new(n),
            lists: WaitLists::new(globals, n),
            races: RaceDetector::new(n, globals, cell.linked.syncs.len()),
            globals: CellGlobals::new(&cell),
            remotes: RemoteQueues::new(n),
            syncs: SyncPoints::new(&cell),
            recording: Recording::new(&cell),
            boundaries: Boundaries::new(&cell),
            instants: InstantLimit::new(),
            time: 0,
            outcome: None,
            started: false,
            stop: None,
            cell,
        }
    }

    /// Writes the run to an MCAP log (see [`vworks_log::mcaplog`]).
    pub fn with_log(self, log: vworks_log::mcaplog::McapLog) -> Simulation {
        self.with_sink(Box::new(log))
    }

    /// Hands every event and cycle boundary of the run to `sink` as well (see
    /// [`RunSink`]); sinks are called in the order they were attached.
    pub fn with_sink(mut self, sink: Box<dyn RunSink>) -> Simulation {
        self.recording.add_sink(sink);
        self
    }

    /// With `false`, collisions are checked at cycle boundaries only, as in the paper: a
    /// body that passes through another between two boundaries goes unnoticed. The default
    /// (`true`) also sweeps the time between boundaries ([`crate::collide::Collider::sweep`]).
    /// For comparison and testing.
    pub fn with_sweep(mut self, sweep: bool) -> Simulation {
        self.boundaries.set_sweep(sweep);
        self
    }

    /// With `false`, every pair near enough to be checked is queried at every boundary;
    /// the default (`true`) skips a pair's queries while the current motions' speed bounds
    /// prove it cannot come within the clearance
    /// ([`crate::collide::Collider::set_adaptive`]). The results are the same (tested);
    /// for comparison and testing.
    pub fn with_adaptive(mut self, adaptive: bool) -> Simulation {
        self.boundaries.collider_mut().set_adaptive(adaptive);
        self
    }

    /// How many queue entries (every robot's events, `check_wait`, `check_when`) the cell
    /// may handle at one simulated instant before the run stops with an error (default
    /// [`INSTANT_LIMIT`]). Each robot is bounded on its own too
    /// ([`VmConfig::instant_events`]).
    pub fn with_instant_limit(mut self, limit: u64) -> Simulation {
        self.instants.set_limit(limit);
        self
    }

    /// How many events each robot may perform at one simulated instant (default
    /// [`VmConfig::instant_events`], 100,000): lower for a fuzzer or a quick check.
    pub fn with_robot_instant_limit(mut self, limit: u64) -> Simulation {
        for vm in &mut self.vms {
            vm.set_instant_events(limit.max(1));
        }
        self
    }

    /// How many events the run may record (default [`EVENT_LIMIT`]): the trace is kept in
    /// memory, so a run that would record more stops with an error naming what records
    /// them (a handler firing every nanosecond, a loop of short delays).
    pub fn with_event_limit(mut self, limit: u64) -> Simulation {
        self.recording.set_event_limit(limit);
        self
    }

    /// Stops the run (outcome `interrupted`, log finished) when `flag` becomes true.
    pub fn with_stop(mut self, flag: Arc<AtomicBool>) -> Simulation {
        self.stop = Some(flag);
        self
    }

    /// The simulated time.
    pub fn time(&self) -> i64 {
        self.time
    }

    /// The VM of robot `i`.
    pub fn vm(&self, i: usize) -> &Vm {
        &self.vms[i]
    }

    /// The cell.
    pub fn cell(&self) -> &Cell {
        &self.cell
    }

    /// The trace so far.
    pub fn trace(&self) -> &[TraceEvent] {
        self.recording.trace()
    }

    /// Handles every queue entry and cycle boundary at or before `t` and moves the clock to
    /// `t`, unless the run ends first. Unlike `run(Some(t))` the run can go on afterwards.
    /// Returns false once the run is over.
    pub fn advance_to(&mut self, t: i64) -> bool {
        self.start();
        loop {
            if self.outcome.is_some() {
                return false;
            }
            match self.queue.next_time() {
                // Nothing left to do: the step ends the run (completed or deadlock).
                None => {
                    self.step(None);
                    return self.outcome.is_none();
                }
                Some(time) if time <= t => {
                    self.step(None);
                }
                Some(_) => break,
            }
        }
        if self.advance_cycles(t) || self.sweep_until(t) {
            return false;
        }
        self.time = self.time.max(t);
        true
    }

    /// The time of the next cycle boundary still to be processed.
    pub fn next_boundary(&self) -> i64 {
        self.boundaries.next()
    }

    /// How the run ended, once it has.
    pub fn outcome(&self) -> Option<Outcome> {
        self.outcome
    }

    /// Every cell global's current value, in the linked cell's order (sorted by name).
    pub fn global_values(&self) -> Vec<(&str, Value)> {
        self.cell
            .linked
            .globals
            .iter()
            .zip(self.globals.values())
            .map(|(g, (v, ty))| (g.name.as_str(), Value::of(*v, *ty)))
            .collect()
    }

    /// Robot `r`'s joints now (one per axis; rad or m); empty if there is no robot `r`.
    pub fn joints(&self, r: usize) -> Vec<f64> {
        match (self.vms.get(r), self.cell.robots.get(r)) {
            (Some(vm), Some(robot)) => vm.joints_at(self.time)[..robot.model.dof()].to_vec(),
            _ => Vec::new(),
        }
    }

    /// Robot `r`'s TCP in the cell now (base × the TCP in its base frame, with the tool
    /// its program moves with: the workcell's, or the last motion's `tool`); identity if
    /// there is no robot `r`.
    pub fn tcp(&self, r: usize) -> Iso {
        match (self.vms.get(r), self.cell.robots.get(r)) {
            (Some(vm), Some(robot)) => {
                let q = vm.joints_at(self.time);
                robot.base.mul(
                    &robot
                        .model
                        .tcp(&q[..robot.model.dof()], &vm.tool_at(self.time)),
                )
            }
            _ => Iso::IDENTITY,
        }
    }

    /// The warnings so far.
    pub fn warnings(&self) -> &[Issue] {
        self.recording.warnings()
    }

    /// The errors so far (runtime errors, a deadlock).
    pub fn errors(&self) -> &[Issue] {
        self.recording.errors()
    }

    /// Ends the run where it is and gives its result (statistics up to now; the log, if
    /// any, is finished).
    pub fn into_result(self) -> RunResult {
        self.finish()
    }

    /// The file of robot `r`'s program that `pos` is in, as messages name it (its file
    /// name).
    fn short(&self, r: usize, pos: SrcPos) -> &str {
        self.cell.robots[r].module.file_name_of(pos)
    }

    /// Runs to the end (or to `until` ns).
    pub fn run(mut self, until: Option<i64>) -> RunResult {
        while self.step(until) {}
        self.finish()
    }

    /// Queues every robot's first event, once.
    fn start(&mut self) {
        if !self.started {
            self.started = true;
            for r in 0..self.vms.len() {
                self.requeue(r);
            }
        }
    }

    /// Breaks ties between robots' same-time entries by `rank` (a permutation) instead of
    /// queueing order. Each robot's own entries keep their order. For testing that no
    /// result depends on tie order.
    pub fn set_tie_ranks(&mut self, rank: Vec<u64>) {
        self.queue.set_tie_ranks(rank);
    }

    /// (Re)queues robot `r`'s next event; the previous entry becomes stale.
    fn requeue(&mut self, r: usize) {
        let g = self.queue.renew(r);
        if self.queue.turn() != Some(r) && self.vms[r].needs_turn() {
            // Its code reads the cell's globals: it runs in the robot's own turn.
            self.queue.queue_robot(r, g, None, self.time);
            return;
        }
        let next = self.vms[r].next_event();
        let to_cell = &self.cell.linked.robots[r].globals;
        self.races
            .note_reads(r, self.time, &mut self.vms[r], to_cell);
        self.report_races();
        if let Next::Event(e) = next {
            // Kept for `perform`: the VM's next event cannot change without a requeue.
            self.queue.queue_robot(r, g, Some(e), self.time);
        }
    }

    /// Handles the next queue entry (and the cycle boundaries before it). Returns false
    /// when the run is over; with `until`, the run is over (outcome `until`) once the next
    /// entry lies after it.
    pub fn step(&mut self, until: Option<i64>) -> bool {
        self.start();
        if self.outcome.is_some() {
            return false;
        }
        if self
            .stop
            .as_ref()
            .is_some_and(|f| f.load(Ordering::Relaxed))
        {
            self.outcome = Some(Outcome::Interrupted);
            return false;
        }
        let Some((t, entry)) = self.queue.pop() else {
            self.end_without_events();
            return false;
        };
        // A stale entry (the robot's next event changed since) is dropped unseen: it must
        // not move the clock (a wait released early leaves its deadline behind).
        if self.queue.is_stale(entry) {
            return true;
        }
        // The turn ends with the entry before: the boundaries before this one belong to
        // no robot.
        self.queue.set_turn(None);
        if let Some(u) = until
            && t > u
        {
            if self.advance_cycles(u) || self.sweep_until(u) {
                return false;
            }
            self.time = u;
            self.outcome = Some(Outcome::Until);
            return false;
        }
        if self.advance_cycles(t) || self.sweep_until(t) {
            return false;
        }
        self.time = t;
        if !self.instants.handle(t) {
            self.livelock(t);
            return false;
        }
        if self.recording.is_full() {
            self.too_many_events(t);
            return false;
        }
        self.queue.set_turn(Some(entry.robot()));
        match entry {
            Entry::Resume(r, _) => {
                // The robot's code runs now, in its turn; the event it stops before is
                // the next entry if it is due at once, and this step handles it too (a
                // step is never only a resume, which records nothing).
                self.queue.taken(r);
                self.requeue(r);
                if self.queue.queued_at(r) == Some(t) {
                    return self.outcome.is_none() && self.step(until);
                }
            }
            Entry::Vm(r, _) => {
                self.queue.taken(r);
                self.perform(r);
            }
            Entry::CheckWait(r, cg) => {
                self.lists.wait_checked(r);
                self.recording
                    .record(t, Some(r), Kind::CheckWait, Detail::Global(cg), None);
                let cond = self.vms[r].waiting_cond();
                if self.vms[r].check_wait(t) {
                    // What r does next follows the sets whose values released it: the
                    // condition read every one of its globals.
                    if let Some(c) = cond {
                        self.seen_condition(r, c);
                    }
                    self.requeue(r);
                } else if let Some(poll) = self.vms[r].take_poll_check() {
                    // A polled wait whose condition holds between polls: tested again at
                    // the next poll.
                    self.queue.push(poll, Entry::CheckWait(r, cg), self.time);
                }
            }
            Entry::CheckWhen(r, cg) => {
                self.lists.when_checked(r);
                self.recording
                    .record(t, Some(r), Kind::CheckWhen, Detail::Global(cg), None);
                if self.vms[r].check_when(t) > 0 {
                    // The handlers it fires follow the sets of every global their
                    // conditions read (all of r's condition handlers were tested).
                    for g in 0..self.lists.globals() {
                        if self.lists.when_reads(g, r) {
                            self.races.merge(r, Seen::Set(g));
                        }
                    }
                    self.requeue(r);
                }
            }
        }
        self.outcome.is_none()
    }

    /// Robot `r` tested condition `c` of its module: it has seen the last set of every
    /// global the condition reads.
    fn seen_condition(&mut self, r: usize, c: u32) {
        let to_cell = &self.cell.linked.robots[r].globals;
        for g in &self.cell.robots[r].module.conds[c as usize].globals {
            self.races
                .merge(r, Seen::Set(to_cell[*g as usize] as usize));
        }
    }

    /// Stops the run on a collision at `t`.
    fn stop_on_collision(&mut self, t: i64) {
        self.time = t;
        self.outcome = Some(Outcome::Collision);
    }

    /// Sweeps for contacts up to `t` (see [`Boundaries::sweep_until`]); true if the run
    /// stopped on one.
    fn sweep_until(&mut self, t: i64) -> bool {
        let stop = self
            .boundaries
            .sweep_until(&self.cell, &self.vms, &mut self.recording, t);
        if let Some(at) = stop {
            self.stop_on_collision(at);
        }
        stop.is_some()
    }

    /// Processes every cycle boundary up to and including `t`; true if the run stopped on
    /// a collision.
    fn advance_cycles(&mut self, t: i64) -> bool {
        let next_event = self.queue.next_time();
        let stop =
            self.boundaries
                .advance(&self.cell, &self.vms, &mut self.recording, t, next_event);
        if let Some(at) = stop {
            self.stop_on_collision(at);
        }
        stop.is_some()
    }

    fn perform(&mut self, r: usize) {
        let Some(mut e) = self.queue.take_pending(r) else {
            return;
        };
        self.vms[r].perform();
        let kind = Kind::of(&e.kind);
        self.account(r, &e, kind);
        self.route(r, &mut e, kind);
        // Found while the VM described this event (or planned it): at its time at the
        // earliest, so the trace stays in time order.
        for w in self.vms[r].take_warnings() {
            let t = w.time.max(e.time);
            self.recording.warning(
                &self.cell,
                t,
                Some(r),
                Some(w.pos),
                w.kind.into(),
                w.message,
            );
        }
        if self.outcome.is_none() {
            self.requeue(r);
        }
    }

    fn account(&mut self, r: usize, e: &Event, kind: Kind) {
        // Time per robot: the fold sees every event that can count — the robots' own (here)
        // and the errors the engine finds in them (`Recording::error`); check_wait,
        // check_when, collisions and warnings never change it.
        // (Not a zoned motion's `motion_end`: the robot moves on; see `Fold::event`.)
        if !matches!(
            e.kind,
            EventKind::MotionEnd {
                zone_m: Some(_),
                ..
            }
        ) {
            self.recording.count(e.time, Some(r), kind);
        }
        if let EventKind::MotionStart { .. } = e.kind {
            self.boundaries.motion_started(r, e.pos);
        }
    }

    /// The trace holds as many events as it may at `t`: stops the run with an error naming
    /// what records them (see [`limit::too_many_events`]).
    fn too_many_events(&mut self, t: i64) {
        let (robot, pos, m) = limit::too_many_events(
            self.recording.trace(),
            self.recording.event_limit(),
            &self.cell,
            &self.vms,
        );
        self.recording
            .error(&self.cell, t, robot, pos, IssueKind::Runtime, m);
        self.outcome = Some(Outcome::Error);
    }

    /// The cell handled more than its instant limit of entries at instant `t`: robots that
    /// keep waking each other without time passing. Stops the run with an error naming
    /// the busiest robots and their loops.
    fn livelock(&mut self, t: i64) {
        let mut busy: Vec<(u64, usize)> = (0..self.vms.len())
            .map(|r| (self.vms[r].events_at(t), r))
            .filter(|(k, _)| *k > 0)
            .collect();
        busy.sort_by(|a, b| b.0.cmp(&a.0).then(a.1.cmp(&b.1)));
        let parts: Vec<String> = busy
            .iter()
            .take(4)
            .map(|&(k, r)| {
                format!(
                    "{} ({k} events, the loop at {}:{})",
                    self.cell.robots[r].name,
                    self.short(r, self.vms[r].loop_position()),
                    self.vms[r].loop_position()
                )
            })
            .collect();
        let m = format!(
            "zero-time livelock: the cell handled {} events at {} without time passing: {}; add a motion, a delay or a wait that blocks inside these loops",
            self.instants.limit(),
            fmt_quantity(t as f64 / 1e9, vworks_vm::Dim::TIME),
            parts.join(", ")
        );
        let robot = busy.first().map(|&(_, r)| r);
        let pos = robot.map(|r| self.vms[r].loop_position());
        self.recording
            .error(&self.cell, t, robot, pos, IssueKind::Runtime, m);
        self.outcome = Some(Outcome::Error);
    }

    /// The queue ran dry: everyone ended, or a deadlock.
    fn end_without_events(&mut self) {
        let blocked: Vec<usize> = (0..self.vms.len())
            .filter(|r| matches!(self.vms[*r].next_event(), Next::Blocked))
            .collect();
        if blocked.is_empty() {
            self.outcome = Some(Outcome::Completed);
            return;
        }
        let mut parts = Vec::new();
        for r in &blocked {
            let (mut what, pos) = self.vms[*r]
                .waiting_for()
                .unwrap_or_else(|| ("something".into(), SrcPos::default()));
            if let Some(c) = self.vms[*r].waiting_cond() {
                let globals = &self.cell.robots[*r].module.conds[c as usize].globals;
                what = format!("a condition on {}", self.names_in_program(*r, globals));
            }
            if let Some(cs) = self.syncs.waiting_at(*r) {
                what = self.syncs.missing(&self.cell, cs);
            }
            parts.push(format!(
                "{} waits for {what} ({}:{pos})",
                self.cell.robots[*r].name,
                self.short(*r, pos)
            ));
        }
        let m = format!("deadlock: {}", parts.join("; "));
        self.recording
            .error(&self.cell, self.time, None, None, IssueKind::Deadlock, m);
        self.outcome = Some(Outcome::Deadlock);
    }

    /// Module globals of robot `r` as its program names them: a RAPID robot's wired
    /// signal by the name its program gives it (`diFromR2`), not the wire's global.
    fn names_in_program(&self, r: usize, globals: &[u32]) -> String {
        let robot = &self.cell.robots[r];
        let m = &robot.module;
        let names: Vec<&str> = globals
            .iter()
            .map(|g| {
                let global = m.str(m.globals[*g as usize].name);
                // Several of the robot's signals on one wire: the first, by name.
                let first = robot
                    .signal_names
                    .partition_point(|(w, _)| w.as_str() < global);
                match robot.signal_names.get(first) {
                    Some((w, name)) if w == global => name.as_str(),
                    _ => global,
                }
            })
            .collect();
        names.join(", ")
    }

    fn finish(mut self) -> RunResult {
        let end = self.time;
        let endings: Vec<Ending> = (0..self.vms.len())
            .map(|r| match self.vms[r].next_event() {
                Next::Idle => Ending::Ended,
                Next::Done => Ending::Error,
                Next::Blocked => Ending::Waiting,
                Next::Event(_) => Ending::Running,
            })
            .collect();
        let global_values: Vec<(String, Value)> = self
            .global_values()
            .into_iter()
            .map(|(n, v)| (n.to_string(), v))
            .collect();
        let globals = self
            .cell
            .linked
            .globals
            .iter()
            .zip(self.globals.values())
            .map(|(g, (v, ty))| (g.name.clone(), format_value(*v, *ty)))
            .collect();
        let outcome = self.outcome.unwrap_or(Outcome::Completed);
        let cycles = self.boundaries.cycles();
        let queries = self.boundaries.collider().queries;
        let recorded = self
            .recording
            .finish(end, outcome, &|r| endings.get(r).copied());
        RunResult {
            log_counts: recorded.log_counts,
            log_error: recorded.log_error,
            outcome,
            end_time_ns: end,
            robots: recorded.robots,
            collisions: recorded.collisions,
            warnings: recorded.warnings,
            errors: recorded.errors,
            global_values,
            globals,
            logs: recorded
                .trace
                .iter()
                .filter_map(|e| e.log_line(&crate::describe::CellNames(&self.cell)))
                .collect(),
            trace: recorded.trace,
            cycles,
            queries,
        }
    }
}
