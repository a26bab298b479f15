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

use std::cmp::Reverse;
use std::collections::{BTreeMap, BinaryHeap};
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};

use vworks_model::math::Iso;
use vworks_vm::Type;
use vworks_vm::bytecode::SrcPos;
use vworks_vm::machine::{Event, EventKind, Next, Vm, VmConfig};
use vworks_vm::types::fmt_quantity;

use crate::collide::Collider;
use crate::describe::{CellNames, statement_at};
use vworks_cell::Cell;
use vworks_log::issue::{Issue, IssueKind};
use vworks_log::mcaplog::McapLog;
use vworks_log::place::{Contact, RobotMotion};
use vworks_log::result::{Outcome, RunResult};
use vworks_log::sink::{RunEnd, RunSink};
use vworks_log::stats::{Ending, Fold};
use vworks_log::trace::{Detail, Kind, TraceEvent, Value, format_value};

mod limit;
mod queue;
mod races;
mod route;

pub use limit::EVENT_LIMIT;

use queue::{Entry, Queued, SortedSet};
use races::Seen;

/// A running simulation of a cell.
#[derive(Debug)]
pub struct Simulation {
    cell: Arc<Cell>,
    vms: Vec<Vm>,
    queue: BinaryHeap<Reverse<Queued>>,
    seq: u64,
    /// Tie-break rank per robot for same-time entries of different robots (all 0 normally:
    /// first queued, first served). Tests permute it to prove the results do not depend on it.
    rank: Vec<u64>,
    generation: Vec<u64>,
    queued_at: Vec<Option<i64>>,
    /// Per robot: the event its queue entry stands for, as its VM gave it at the requeue
    /// (so performing it does not ask the VM again).
    pending: Vec<Option<Event>>,
    /// Cell globals: value bits and type.
    globals: Vec<(u64, Type)>,
    /// Per robot: cell global index → module global index.
    to_module: Vec<Vec<Option<u32>>>,
    /// Per cell global: the last set and the last condition read at a wait start that
    /// passed at once: (time, robot, pos, the robot's own clock entry at that action).
    last_set: Vec<Option<(i64, usize, SrcPos, u64)>>,
    last_read: Vec<Option<(i64, usize, SrcPos, u64)>>,
    /// Happens-before, for race warnings: a vector clock per robot (`clock[r * n + q]`: how
    /// many of robot q's actions robot r has seen, directly or through others). A robot
    /// sees another's actions when that robot's set, signal or remote work releases it.
    clock: Vec<u64>,
    /// Per cell global: the setter's clock at the last set (what a robot it releases sees).
    set_clock: Vec<u64>,
    /// The paper's WAIT list: per cell global, the robots whose wait condition reads it.
    wait_list: Vec<SortedSet<usize>>,
    /// The paper's WHEN list: per cell global, the (robot, handler procedure) of each
    /// enabled condition handler reading it.
    when_list: Vec<SortedSet<(usize, u32)>>,
    /// Per robot and signal site: the receiving robot and the signal's index in its VM
    /// (`None`: the receiver never waits for it).
    signal_to: Vec<Vec<(usize, Option<u32>)>>,
    /// Remote requests each robot serves, in order: (caller, request number).
    serving: Vec<std::collections::VecDeque<(usize, u64)>>,
    /// Time per robot, folded over the events as they are recorded.
    fold: Fold,
    collider: Collider,
    next_boundary: i64,
    time: i64,
    trace: Vec<TraceEvent>,
    warnings: Vec<Issue>,
    errors: Vec<Issue>,
    collisions: Vec<Contact>,
    outcome: Option<Outcome>,
    cycles: u64,
    /// Consumers of the run (the MCAP log), and the first error one of them had (a sink
    /// that fails is dropped).
    sinks: Vec<Box<dyn RunSink>>,
    log_error: Option<String>,
    /// Whether each robot moves at the boundary being processed (reused).
    moving: Vec<bool>,
    /// Each robot's last `motion_start`: the statement a collision or near miss names.
    last_motion: Vec<Option<SrcPos>>,
    /// Whether every robot has been queued (the first step does it).
    started: bool,
    /// Time up to which contacts between boundaries have been swept for.
    swept: i64,
    /// Whether to sweep between boundaries at all (see [`Simulation::with_sweep`]).
    sweep: bool,
    /// The robot whose turn it is at `time`: the entries it queues for itself at that
    /// instant go before every other (see `queue`).
    turn: Option<usize>,
    /// Set from outside to stop the run between two events.
    stop: Option<Arc<AtomicBool>>,
    /// The instant being simulated, the queue entries handled at it, and how many the
    /// cell may handle at one instant ([`Simulation::with_instant_limit`]).
    instant: i64,
    instant_entries: u64,
    instant_limit: u64,
    /// How many events the trace may hold ([`Simulation::with_event_limit`]).
    event_limit: u64,
    /// Reads of globals a robot's segment made (reused; see [`Vm::take_reads`]).
    reads: Vec<(u32, SrcPos)>,
    /// Per robot: the last remote request made to it (time, caller, position, stamp).
    last_request: Vec<Option<(i64, usize, SrcPos, u64)>>,
    /// Per robot: the last signal sent to it (time, sender, position, stamp), and the
    /// last time one of its signal waits timed out (time, position).
    last_signal: Vec<Option<(i64, usize, SrcPos, u64)>>,
    signal_timeout: Vec<Option<(i64, SrcPos)>>,
    /// Per cell global: the last wait on it that timed out (time, robot, position).
    last_timeout: Vec<Option<(i64, usize, SrcPos)>>,
    /// Per sync point of the cell (`Linked::syncs`), per member: whether it has arrived
    /// at the meeting under way; per robot, the sync point it waits at.
    sync_arrived: Vec<Vec<bool>>,
    at_sync: Vec<Option<usize>>,
    /// Per robot: the instant of its `check_wait` and of its `check_when` still queued, if
    /// any (a set at that instant needs no second one: the queued check comes after it and
    /// tests the values it leaves).
    check_pending: Vec<(Option<i64>, Option<i64>)>,
    /// Per sync point: the last wait there that timed out (time, robot, position).
    sync_timeout: Vec<Option<(i64, usize, SrcPos)>>,
}

/// How many queue entries the cell may handle at one simulated instant by default: far
/// more than any program needs, few enough to stop a zero-time livelock of several
/// robots in well under a second.
pub const INSTANT_LIMIT: u64 = 1_000_000;

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
        let globals = cell
            .linked
            .globals
            .iter()
            .map(|g| {
                let mut s = [0u64];
                g.init.write_slots(&mut s);
                (s[0], g.ty)
            })
            .collect::<Vec<_>>();
        let mut to_module = vec![vec![None; globals.len()]; n];
        for (r, links) in cell.linked.robots.iter().enumerate() {
            for (mg, cg) in links.globals.iter().enumerate() {
                to_module[r][*cg as usize] = Some(mg as u32);
            }
        }
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
        let fold = Fold::new(cell.robots.iter().map(|r| r.name.clone()).collect(), false);
        let collider = Collider::new(&cell);
        // The programs' compile and link warnings open the run's warnings (kind: the code).
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
        Simulation {
            vms,
            signal_to,
            queue: BinaryHeap::new(),
            seq: 0,
            rank: vec![0; n],
            generation: vec![0; n],
            queued_at: vec![None; n],
            pending: vec![None; n],
            last_set: vec![None; globals.len()],
            last_read: vec![None; globals.len()],
            clock: vec![0; n * n],
            set_clock: vec![0; globals.len() * n],
            globals,
            to_module,
            wait_list: vec![Default::default(); cell.linked.globals.len()],
            when_list: vec![Default::default(); cell.linked.globals.len()],
            serving: vec![Default::default(); n],
            fold,
            collider,
            next_boundary: 0,
            time: 0,
            trace: Vec::new(),
            warnings,
            errors: Vec::new(),
            collisions: Vec::new(),
            outcome: None,
            cycles: 0,
            sinks: Vec::new(),
            log_error: None,
            moving: Vec::with_capacity(cell.robots.len()),
            last_motion: vec![None; n],
            started: false,
            swept: 0,
            sweep: true,
            stop: None,
            turn: None,
            instant: -1,
            instant_entries: 0,
            instant_limit: INSTANT_LIMIT,
            event_limit: EVENT_LIMIT,
            reads: Vec::new(),
            last_request: vec![None; n],
            last_signal: vec![None; n],
            signal_timeout: vec![None; n],
            last_timeout: vec![None; cell.linked.globals.len()],
            sync_arrived: cell
                .linked
                .syncs
                .iter()
                .map(|s| vec![false; s.members.len()])
                .collect(),
            at_sync: vec![None; n],
            check_pending: vec![(None, None); n],
            sync_timeout: vec![None; cell.linked.syncs.len()],
            cell,
        }
    }

    /// Writes the run to an MCAP log (see [`vworks_log::mcaplog`]).
    pub fn with_log(self, log: McapLog) -> Simulation {
        self.with_sink(Box::new(log))
    }

    /// Hands every event and cycle boundary of the run to `sink` as well (see
    /// [`RunSink`]); sinks are called in the order they were attached.
    pub fn with_sink(mut self, sink: Box<dyn RunSink>) -> Simulation {
        self.sinks.push(sink);
        self
    }

    /// With `false`, collisions are checked at cycle boundaries only, as in the paper: a
    /// body that passes through another between two boundaries goes unnoticed. The default
    /// (`true`) also sweeps the time between boundaries ([`Collider::sweep`]). For
    /// comparison and testing.
    pub fn with_sweep(mut self, sweep: bool) -> Simulation {
        self.sweep = sweep;
        self
    }

    /// With `false`, every pair near enough to be checked is queried at every boundary;
    /// the default (`true`) skips a pair's queries while the current motions' speed bounds
    /// prove it cannot come within the clearance ([`Collider::set_adaptive`]). The results
    /// are the same (tested); for comparison and testing.
    pub fn with_adaptive(mut self, adaptive: bool) -> Simulation {
        self.collider.set_adaptive(adaptive);
        self
    }

    /// How many queue entries (every robot's events, `check_wait`, `check_when`) the cell
    /// may handle at one simulated instant before the run stops with an error (default
    /// [`INSTANT_LIMIT`]). Each robot is bounded on its own too
    /// ([`VmConfig::instant_events`]).
    pub fn with_instant_limit(mut self, limit: u64) -> Simulation {
        self.instant_limit = limit.max(1);
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
        self.event_limit = limit.max(1);
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
        &self.trace
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
            match self.queue.peek() {
                // Nothing left to do: the step ends the run (completed or deadlock).
                None => {
                    self.step(None);
                    return self.outcome.is_none();
                }
                Some(Reverse(q)) if q.time <= t => {
                    self.step(None);
                }
                Some(_) => break,
            }
        }
        self.advance_cycles(t);
        if self.outcome.is_some() || self.sweep_until(t) {
            return false;
        }
        self.time = self.time.max(t);
        true
    }

    /// The time of the next cycle boundary still to be processed.
    pub fn next_boundary(&self) -> i64 {
        self.next_boundary
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
            .zip(&self.globals)
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
        &self.warnings
    }

    /// The errors so far (runtime errors, a deadlock).
    pub fn errors(&self) -> &[Issue] {
        &self.errors
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

    fn record(
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

    /// Logs the state at boundary `b` (only when a log is written); runs after the
    /// collision check at `b`, whose link frames it reuses.
    fn log_cycle(&mut self, b: i64) {
        if self.sinks.is_empty() {
            return;
        }
        let world = self.collider.world();
        let failed = &mut self.log_error;
        self.sinks.retain_mut(|s| match s.cycle(b, world) {
            Ok(()) => true,
            Err(err) => {
                failed.get_or_insert(err);
                false
            }
        });
    }

    fn issue(
        &self,
        kind: IssueKind,
        message: String,
        robot: Option<usize>,
        pos: Option<SrcPos>,
    ) -> Issue {
        Issue {
            kind,
            message,
            robot: robot.map(|r| self.cell.robots[r].name.clone()),
            file: robot
                .zip(pos)
                .map(|(r, p)| self.cell.robots[r].module.file_of(p).to_string()),
            line: pos.map_or(0, |p| p.line),
            col: pos.map_or(0, |p| p.col),
            distance_m: None,
            motions: Vec::new(),
        }
    }

    /// The robots that move bodies `a` and `b` (each once, in that order), and the motion
    /// each was making at `t`, or last made.
    fn motions_of(&self, a: &str, b: &str, t: i64) -> Vec<RobotMotion> {
        let ra = self.collider.robot_moving(a);
        let rb = self.collider.robot_moving(b).filter(|r| Some(*r) != ra);
        [ra, rb]
            .into_iter()
            .flatten()
            .map(|r| {
                let robot = self.cell.robots[r].name.clone();
                match self.last_motion[r] {
                    Some(pos) => RobotMotion {
                        robot,
                        moving: self.vms[r].moving_at(t),
                        file: Some(self.cell.robots[r].module.file_of(pos).to_string()),
                        line: pos.line,
                        col: pos.col,
                        statement: statement_at(&self.cell, r, pos),
                    },
                    None => RobotMotion::not_moved(robot),
                }
            })
            .collect()
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
        let Some(Reverse(Queued { time: t, entry, .. })) = self.queue.pop() else {
            self.end_without_events();
            return false;
        };
        // A stale entry (the robot's next event changed since) is dropped unseen: it must
        // not move the clock (a wait released early leaves its deadline behind).
        if let Entry::Vm(r, g) | Entry::Resume(r, g) = Entry::unpack(entry)
            && g != self.generation[r]
        {
            return true;
        }
        // The turn ends with the entry before: the boundaries before this one belong to
        // no robot.
        self.turn = None;
        if let Some(u) = until
            && t > u
        {
            self.advance_cycles(u);
            if self.outcome.is_some() || self.sweep_until(u) {
                return false;
            }
            self.time = u;
            self.outcome = Some(Outcome::Until);
            return false;
        }
        self.advance_cycles(t);
        if self.outcome.is_some() || self.sweep_until(t) {
            return false;
        }
        self.time = t;
        if t != self.instant {
            self.instant = t;
            self.instant_entries = 0;
        }
        self.instant_entries += 1;
        if self.instant_entries > self.instant_limit {
            self.livelock(t);
            return false;
        }
        if self.trace.len() as u64 >= self.event_limit {
            self.too_many_events(t);
            return false;
        }
        let entry = Entry::unpack(entry);
        self.turn = Some(entry.robot());
        match entry {
            Entry::Resume(r, _) => {
                // The robot's code runs now, in its turn; the event it stops before is
                // the next entry if it is due at once, and this step handles it too (a
                // step is never only a resume, which records nothing).
                self.queued_at[r] = None;
                self.requeue(r);
                if self.queued_at[r] == Some(t) {
                    return self.outcome.is_none() && self.step(until);
                }
            }
            Entry::Vm(r, _) => {
                self.queued_at[r] = None;
                self.perform(r);
            }
            Entry::CheckWait(r, cg) => {
                self.check_pending[r].0 = None;
                self.record(t, Some(r), Kind::CheckWait, Detail::Global(cg), None);
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
                    self.push(poll, Entry::CheckWait(r, cg));
                }
            }
            Entry::CheckWhen(r, cg) => {
                self.check_pending[r].1 = None;
                self.record(t, Some(r), Kind::CheckWhen, Detail::Global(cg), None);
                if self.vms[r].check_when(t) > 0 {
                    // The handlers it fires follow the sets of every global their
                    // conditions read (all of r's condition handlers were tested).
                    for g in 0..self.when_list.len() {
                        if self.when_list[g].0.iter().any(|(q, _)| *q == r) {
                            self.merge_clock(r, Seen::Set(g));
                        }
                    }
                    self.requeue(r);
                }
            }
        }
        self.outcome.is_none()
    }

    /// Records a collision that started; true if the run stops on it.
    fn collision_started(&mut self, mut contact: Contact) -> bool {
        let t = contact.time_ns;
        contact.motions = self.motions_of(&contact.a, &contact.b, t);
        let detail = Detail::Collision(Box::new(contact.clone()));
        self.record(t, None, Kind::CollisionStart, detail, None);
        self.collisions.push(contact);
        if self.cell.stop_on_collision {
            self.time = t;
            self.outcome = Some(Outcome::Collision);
            return true;
        }
        false
    }

    /// Sweeps the time since the last sweep up to (not including) `t` for contacts
    /// between boundaries (see [`Collider::sweep`]); runs before every boundary and
    /// before every event, so motions do not change within a swept stretch. True if the
    /// run stopped on a contact.
    fn sweep_until(&mut self, t: i64) -> bool {
        if !self.sweep || t <= self.swept {
            return false;
        }
        // Nothing can touch before the collider's horizon: no sweep to do.
        if t <= self.collider.horizon() {
            self.swept = t;
            return false;
        }
        let contacts = self.collider.sweep(&self.cell, &self.vms, self.swept, t);
        self.swept = t;
        for contact in contacts {
            if self.collision_started(contact) {
                return true;
            }
        }
        false
    }

    /// Processes every cycle boundary up to and including `t`.
    fn advance_cycles(&mut self, t: i64) {
        let c = self.cell.cycle_ns;
        while self.next_boundary <= t {
            let b = self.next_boundary;
            // Before the collider's horizon no pair can come within the clearance: the
            // boundary has nothing to check (unless a log records every boundary's state).
            if b < self.collider.horizon() && self.sinks.is_empty() {
                self.swept = self.swept.max(b);
                self.next_boundary += c;
                self.cycles += 1;
                continue;
            }
            // A contact before the boundary may end the run before it is reached.
            if self.sweep_until(b) {
                return;
            }
            self.next_boundary += c;
            self.cycles += 1;
            self.moving.clear();
            self.moving.extend(self.vms.iter().map(|v| v.moving_at(b)));
            let events = self.collider.check(&self.cell, &self.vms, b, &self.moving);
            self.log_cycle(b);
            for ev in events {
                match ev {
                    crate::collide::CollisionEvent::Start(contact) => {
                        if self.collision_started(contact) {
                            return;
                        }
                    }
                    crate::collide::CollisionEvent::End(a, bname) => {
                        let detail = Detail::CollisionEnd(Box::new((a, bname)));
                        self.record(b, None, Kind::CollisionEnd, detail, None)
                    }
                    crate::collide::CollisionEvent::NearMiss(a, bname, dist) => {
                        // Hundredths of a millimetre in words; the exact distance in
                        // `Issue::distance_m` (JSON, Python).
                        let m = format!(
                            "near miss: {a} and {bname} come within {:.2} mm",
                            dist * 1e3
                        );
                        let mut issue = self.issue(IssueKind::NearMiss, m, None, None);
                        issue.distance_m = Some(dist);
                        issue.motions = self.motions_of(&a, &bname, b);
                        // The warning's own place: the first robot moving (else the
                        // first robot's last motion).
                        let main = issue.motions.iter().find(|m| m.moving);
                        if let Some(first) = main.or(issue.motions.first()) {
                            issue.robot = Some(first.robot.clone());
                            issue.file.clone_from(&first.file);
                            (issue.line, issue.col) = (first.line, first.col);
                        }
                        self.add_issue(b, None, None, Kind::Warning, issue);
                    }
                }
            }
            // With nothing queued before the next boundary and nothing moving, skip ahead.
            // (Not when a sink records every boundary.)
            if !self.sinks.iter().any(|s| s.records_cycles()) && !self.moving.iter().any(|m| *m) {
                let next_event = self.queue.peek().map_or(t, |Reverse(q)| q.time).min(t);
                if next_event > self.next_boundary {
                    let skip = (next_event - self.next_boundary) / c;
                    self.next_boundary += skip * c;
                    self.cycles += skip as u64;
                }
            }
        }
    }

    fn perform(&mut self, r: usize) {
        let Some(e) = self.pending[r].take() else {
            return;
        };
        self.vms[r].perform();
        let kind = Kind::of(&e.kind);
        self.account(r, &e, kind);
        self.route(r, &e, kind);
        // Found while the VM described this event (or planned it): at its time at the
        // earliest, so the trace stays in time order.
        for w in self.vms[r].take_warnings() {
            self.warning(
                w.time.max(e.time),
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
        // and the errors the engine finds in them (`error`); check_wait, check_when,
        // collisions and warnings never change it.
        // (Not a zoned motion's `motion_end`: the robot moves on; see `Fold::event`.)
        if !matches!(
            e.kind,
            EventKind::MotionEnd {
                zone_m: Some(_),
                ..
            }
        ) {
            self.fold.event(e.time, Some(r), kind);
        }
        if let EventKind::MotionStart { .. } = e.kind {
            self.last_motion[r] = Some(e.pos);
            // Speed bounds behind skipped collision queries change with the motion.
            self.collider.motion_started(r);
        }
    }

    /// A `warning` trace event and the run's warning of `kind`.
    fn warning(
        &mut self,
        t: i64,
        robot: Option<usize>,
        pos: Option<SrcPos>,
        kind: IssueKind,
        message: String,
    ) {
        let issue = self.issue(kind, message, robot, pos);
        self.add_issue(t, robot, pos, Kind::Warning, issue);
    }

    /// A `warning` or `error` trace event (`severity`) and the run's warning or error
    /// `issue`. An error counts in its robot's statistics (it ends the robot).
    fn add_issue(
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

    /// An `error` trace event (the message quoted) and the run's error of `kind`. The
    /// caller sets the outcome.
    fn error(
        &mut self,
        t: i64,
        robot: Option<usize>,
        pos: Option<SrcPos>,
        kind: IssueKind,
        message: String,
    ) {
        let issue = self.issue(kind, message, robot, pos);
        self.add_issue(t, robot, pos, Kind::Error, issue);
    }

    /// The cell handled more than `instant_limit` entries at instant `t`: robots that
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
            self.instant_limit,
            fmt_quantity(t as f64 / 1e9, vworks_vm::Dim::TIME),
            parts.join(", ")
        );
        let robot = busy.first().map(|&(_, r)| r);
        let pos = robot.map(|r| self.vms[r].loop_position());
        self.error(t, robot, pos, IssueKind::Runtime, m);
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
            if let Some(cs) = self.at_sync[*r] {
                what = self.sync_missing(cs);
            }
            parts.push(format!(
                "{} waits for {what} ({}:{pos})",
                self.cell.robots[*r].name,
                self.short(*r, pos)
            ));
        }
        let m = format!("deadlock: {}", parts.join("; "));
        self.error(self.time, None, None, IssueKind::Deadlock, m);
        self.outcome = Some(Outcome::Deadlock);
    }

    /// A sync point and the tasks of its list that have not arrived at its meeting.
    fn sync_missing(&self, cs: usize) -> String {
        let sync = &self.cell.linked.syncs[cs];
        let missing: Vec<String> = sync
            .members
            .iter()
            .zip(&self.sync_arrived[cs])
            .filter(|(_, arrived)| !**arrived)
            .map(|(q, _)| {
                let robot = &self.cell.robots[*q as usize];
                if robot.task == robot.name {
                    format!("`{}`", robot.name)
                } else {
                    format!("`{}` (robot {})", robot.task, robot.name)
                }
            })
            .collect();
        format!(
            "the other tasks at sync point `{}`; never arrived: {}",
            sync.name,
            missing.join(", ")
        )
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
            .zip(&self.globals)
            .map(|(g, (v, ty))| (g.name.clone(), format_value(*v, *ty)))
            .collect();
        let (robots, _) = self.fold.finish(end, &|r| endings.get(r).copied());
        let outcome = self.outcome.unwrap_or(Outcome::Completed);
        let run_end = RunEnd {
            outcome,
            end_time_ns: end,
            robots: &robots,
        };
        let mut log_counts = BTreeMap::new();
        for mut sink in self.sinks {
            match sink.finish(&run_end) {
                Ok(c) => log_counts.extend(c),
                Err(e) => {
                    self.log_error.get_or_insert(e);
                }
            }
        }
        RunResult {
            log_counts,
            log_error: self.log_error,
            outcome,
            end_time_ns: end,
            robots,
            collisions: self.collisions,
            warnings: self.warnings,
            errors: self.errors,
            global_values,
            globals,
            logs: self
                .trace
                .iter()
                .filter_map(|e| e.log_line(&CellNames(&self.cell)))
                .collect(),
            trace: self.trace,
            cycles: self.cycles,
            queries: self.collider.queries,
        }
    }
}
