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

use crate::collide::{Collider, Contact};
pub use crate::result::{Outcome, RunResult};
use crate::sink::{RunEnd, RunSink};
use crate::stats::Fold;
pub use crate::stats::{Ending, RobotStats};
use crate::trace::format_value;
pub use crate::trace::{Detail, Issue, Kind, TraceEvent, Value};
use vworks_cell::Cell;

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Entry {
    /// The robot's next event (robot, generation).
    Vm(usize, u64),
    /// Re-test the robot's wait condition after a set of a global (cell index).
    CheckWait(usize, u32),
    /// Re-test the robot's condition handlers after a set of a global (cell index).
    CheckWhen(usize, u32),
}

impl Entry {
    /// The entry in 64 bits: kind (2 bits), robot (22 bits), generation or global (40
    /// bits), so that a queued entry is 24 bytes.
    fn pack(self) -> u64 {
        let (kind, r, payload) = match self {
            Entry::Vm(r, g) => (0, r, g),
            Entry::CheckWait(r, g) => (1, r, u64::from(g)),
            Entry::CheckWhen(r, g) => (2, r, u64::from(g)),
        };
        (payload << 24) | ((r as u64 & 0x3f_ffff) << 2) | kind
    }

    fn unpack(x: u64) -> Entry {
        let (r, payload) = (((x >> 2) & 0x3f_ffff) as usize, x >> 24);
        match x & 3 {
            0 => Entry::Vm(r, payload),
            1 => Entry::CheckWait(r, payload as u32),
            _ => Entry::CheckWhen(r, payload as u32),
        }
    }
}

/// An event-queue entry: the earliest time first, then by `key` (the robot's tie rank,
/// then the order queued), 24 bytes.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
struct Queued {
    time: i64,
    /// Tie rank (high 20 bits) and sequence number (low 44 bits).
    key: u64,
    entry: u64,
}

/// A running simulation of a cell.
#[derive(Debug)]
pub struct Simulation {
    cell: Arc<Cell>,
    vms: Vec<Vm>,
    files: Vec<Arc<str>>,
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
    /// Whether every robot has been queued (the first step does it).
    started: bool,
    /// Time up to which contacts between boundaries have been swept for.
    swept: i64,
    /// Whether to sweep between boundaries at all (see [`Simulation::with_sweep`]).
    sweep: bool,
    /// Set from outside to stop the run between two events.
    stop: Option<Arc<AtomicBool>>,
    /// The instant being simulated, the queue entries handled at it, and how many the
    /// cell may handle at one instant ([`Simulation::with_instant_limit`]).
    instant: i64,
    instant_entries: u64,
    instant_limit: u64,
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
}

/// How many queue entries the cell may handle at one simulated instant by default: far
/// more than any program needs, few enough to stop a zero-time livelock of several
/// robots in well under a second.
pub const INSTANT_LIMIT: u64 = 1_000_000;

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
        let vms: Vec<Vm> = cell
            .robots
            .iter()
            .enumerate()
            .map(|(i, r)| {
                let cfg = VmConfig {
                    cycle_ns: cell.cycle_ns,
                    default_speed: r.default_speed,
                    tool: r.tool,
                    start_joints: r.home.clone(),
                    robot: i as u32,
                    ..VmConfig::default()
                };
                Vm::new(Arc::clone(&r.module), Arc::clone(&r.model), cfg, r.entry)
            })
            .collect();
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
        let files = cell
            .robots
            .iter()
            .map(|r| Arc::<str>::from(r.program.as_str()))
            .collect();
        let fold = Fold::new(cell.robots.iter().map(|r| r.name.clone()).collect(), false);
        let collider = Collider::new(&cell);
        // The programs' compile and link warnings open the run's warnings (kind: the code).
        let warnings = cell
            .warnings
            .iter()
            .map(|d| Issue {
                kind: d.code.as_str().to_string(),
                message: d.message.clone(),
                robot: None,
                file: Some(d.at.file.clone()),
                line: d.at.line,
                col: d.at.col,
                distance_m: None,
            })
            .collect();
        Simulation {
            vms,
            signal_to,
            files,
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
            started: false,
            swept: 0,
            sweep: true,
            stop: None,
            instant: -1,
            instant_entries: 0,
            instant_limit: INSTANT_LIMIT,
            reads: Vec::new(),
            last_request: vec![None; n],
            last_signal: vec![None; n],
            signal_timeout: vec![None; n],
            last_timeout: vec![None; cell.linked.globals.len()],
            cell,
        }
    }

    /// Writes the run to an MCAP log (see [`crate::mcaplog`]).
    pub fn with_log(self, log: crate::mcaplog::McapLog) -> Simulation {
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

    /// Robot `r`'s TCP in the cell now (base × flange × tool); identity if there is no
    /// robot `r`.
    pub fn tcp(&self, r: usize) -> Iso {
        match (self.vms.get(r), self.cell.robots.get(r)) {
            (Some(vm), Some(robot)) => {
                let q = vm.joints_at(self.time);
                robot
                    .base
                    .mul(&robot.model.tcp(&q[..robot.model.dof()], &robot.tool))
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

    /// The program file of robot `r` as messages name it (its file name).
    fn short(&self, r: usize) -> String {
        let f = self.files[r].as_ref();
        std::path::Path::new(f)
            .file_name()
            .map_or(f.to_string(), |n| n.to_string_lossy().into_owned())
    }

    fn push(&mut self, time: i64, entry: Entry) {
        self.seq += 1;
        let robot = match entry {
            Entry::Vm(r, _) | Entry::CheckWait(r, _) | Entry::CheckWhen(r, _) => r,
        };
        self.queue.push(Reverse(Queued {
            time,
            key: (self.rank[robot] << 44) | (self.seq & ((1 << 44) - 1)),
            entry: entry.pack(),
        }));
    }

    /// Breaks ties between robots' same-time entries by `rank` (a permutation) instead of
    /// queueing order. Each robot's own entries keep their order. For testing that no
    /// result depends on tie order.
    pub fn set_tie_ranks(&mut self, rank: Vec<u64>) {
        if rank.len() == self.rank.len() && rank.iter().all(|r| *r < 1 << 20) {
            self.rank = rank;
        }
    }

    /// (Re)queues robot `r`'s next event; the previous entry becomes stale.
    fn requeue(&mut self, r: usize) {
        self.generation[r] += 1;
        self.queued_at[r] = None;
        let next = self.vms[r].next_event();
        self.note_reads(r);
        if let Next::Event(e) = next {
            self.queued_at[r] = Some(e.time);
            let g = self.generation[r];
            self.push(e.time, Entry::Vm(r, g));
            // Kept for `perform`: the VM's next event cannot change without a requeue.
            self.pending[r] = Some(e);
        } else {
            self.pending[r] = None;
        }
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
        self.fold.event(time, robot, kind);
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
            let cell = &self.cell;
            let failed = &mut self.log_error;
            self.sinks.retain_mut(|s| match s.event(cell, e) {
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
        let (cell, world) = (&self.cell, self.collider.world());
        let failed = &mut self.log_error;
        self.sinks.retain_mut(|s| match s.cycle(cell, b, world) {
            Ok(()) => true,
            Err(err) => {
                failed.get_or_insert(err);
                false
            }
        });
    }

    fn issue(
        &self,
        kind: &str,
        message: String,
        robot: Option<usize>,
        pos: Option<SrcPos>,
    ) -> Issue {
        Issue {
            kind: kind.into(),
            message,
            robot: robot.map(|r| self.cell.robots[r].name.clone()),
            file: robot
                .filter(|_| pos.is_some())
                .map(|r| self.files[r].to_string()),
            line: pos.map_or(0, |p| p.line),
            col: pos.map_or(0, |p| p.col),
            distance_m: None,
        }
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
        if let Entry::Vm(r, g) = Entry::unpack(entry)
            && g != self.generation[r]
        {
            return true;
        }
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
        match Entry::unpack(entry) {
            Entry::Vm(r, _) => {
                self.queued_at[r] = None;
                self.perform(r);
            }
            Entry::CheckWait(r, cg) => {
                self.record(t, Some(r), Kind::CheckWait, Detail::Global(cg), None);
                if self.vms[r].check_wait(t) {
                    // What r does next follows the set that released it.
                    self.merge_clock(r, Seen::Set(cg as usize));
                    self.requeue(r);
                }
            }
            Entry::CheckWhen(r, cg) => {
                self.record(t, Some(r), Kind::CheckWhen, Detail::Global(cg), None);
                if self.vms[r].check_when(t) > 0 {
                    // The handlers it fires follow the set that made them fire.
                    self.merge_clock(r, Seen::Set(cg as usize));
                    self.requeue(r);
                }
            }
        }
        self.outcome.is_none()
    }

    /// Records a collision that started; true if the run stops on it.
    fn collision_started(&mut self, contact: Contact) -> bool {
        let t = contact.time_ns;
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
                        let mut issue = self.issue("near_miss", m, None, None);
                        issue.distance_m = Some(dist);
                        self.add_warning(b, None, None, issue);
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
        self.account(r, &e);
        self.route(r, &e);
        for (t, pos, m) in self.vms[r].take_warnings() {
            self.warning(t, Some(r), Some(pos), "slowdown", m);
        }
        if self.outcome.is_none() {
            self.requeue(r);
        }
    }

    fn account(&mut self, r: usize, e: &Event) {
        if let EventKind::MotionStart { .. } = e.kind {
            // Speed bounds behind skipped collision queries change with the motion.
            self.collider.motion_started(r);
        }
    }

    fn route(&mut self, r: usize, e: &Event) {
        let t = e.time;
        let detail = match e.kind {
            // A set is recorded with the cell's global and the value it replaces.
            EventKind::Set { global, value, .. } => {
                let cg = self.cell.linked.robots[r].globals[global as usize];
                let old = self.globals[cg as usize].0;
                Detail::Set {
                    global: cg,
                    old,
                    new: value,
                }
            }
            _ => Detail::Vm(e.kind.clone()),
        };
        self.record(t, Some(r), Kind::of(&e.kind), detail, Some(e.pos));
        match &e.kind {
            EventKind::Set { global, value, .. } => self.on_set(r, *global, *value, t, e.pos),
            EventKind::WaitUntil { cond, .. } => {
                let cell = Arc::clone(&self.cell);
                // A later set at this instant races with this read only if the wait passed
                // at once: a wait that blocks is re-tested by that set's check_wait at the
                // same instant, so either order releases it at the same time.
                let passed = !self.vms[r].waits();
                let stamp = self.tick(r);
                for g in &cell.robots[r].module.conds[*cond as usize].globals {
                    let cg = cell.linked.robots[r].globals[*g as usize] as usize;
                    self.check_race(cg, r, t, e.pos, false);
                    if passed {
                        self.last_read[cg] = Some((t, r, e.pos, stamp));
                    }
                    self.wait_list[cg].insert(r);
                }
            }
            EventKind::WaitEnd { timed_out } => {
                if *timed_out {
                    self.timed_out_race(r, t, e.pos);
                }
                self.clear_waits(r);
            }
            EventKind::EnableWhen { handler } => {
                let m = self.vms[r].module();
                let h = &m.handlers[*handler as usize];
                if let vworks_vm::bytecode::Trigger::Condition(c) = h.trigger {
                    let target = h.target;
                    let cell = Arc::clone(&self.cell);
                    for g in &cell.robots[r].module.conds[c as usize].globals {
                        let cg = cell.linked.robots[r].globals[*g as usize] as usize;
                        self.when_list[cg].insert((r, target));
                    }
                }
            }
            EventKind::DisableWhen { proc } => {
                for w in &mut self.when_list {
                    w.remove(&(r, *proc));
                }
            }
            EventKind::End => {
                for w in &mut self.when_list {
                    w.retain(|(q, _)| *q != r);
                }
                // (`stop` in a handler may end a wait.)
                self.clear_waits(r);
            }
            EventKind::Signal { site } => {
                let (target, idx) = self.signal_to[r][*site as usize];
                let stamp = self.tick(r);
                let timing_out = self.vms[target].wait_deadline() == Some(t)
                    && idx.is_some()
                    && self.vms[target].waited_signal() == idx;
                let timed_out = self.signal_timeout[target]
                    .filter(|(ot, _)| *ot == t)
                    .map(|(_, p)| p);
                let waiting = timing_out
                    .then(|| self.vms[target].waiting_for().map(|(_, p)| p))
                    .flatten();
                if let Some(wpos) = timed_out.or(waiting) {
                    self.race(t, (target, wpos), (r, e.pos), "on a signal", "time out a wait for it and send it at the same instant; whether the signal releases the wait depends on their order");
                }
                self.last_signal[target] = Some((t, r, e.pos, stamp));
                if let Some(idx) = idx
                    && self.vms[target].deliver_signal_index(idx, t)
                {
                    // The receiver, released, has seen what the sender had.
                    self.merge_clock(target, Seen::Robot(r));
                    self.requeue(target);
                }
            }
            EventKind::RemoteCall { site, req, args } => {
                let (target, proc) = self.cell.linked.robots[r].remotes[*site as usize];
                let target = target as usize;
                // Two requests to one robot at one instant: which it serves first is only
                // the queue's tie order (a request made after seeing the other's is not).
                let stamp = self.tick(r);
                let n = self.vms.len();
                if let Some((ot, or, opos, ostamp)) = self.last_request[target]
                    && ot == t
                    && or != r
                    && self.clock[r * n + or] < ostamp
                {
                    let subject = format!("for {}'s remote work", self.cell.robots[target].name);
                    self.race(t, (or, opos), (r, e.pos), &subject, "ask for it at the same instant; which request it serves first depends on their order");
                }
                self.last_request[target] = Some((t, r, e.pos, stamp));
                self.vms[target].request_remote(proc, args.clone(), t);
                self.serving[target].push_back((r, *req));
                if self.queued_at[target].is_none() {
                    self.requeue(target);
                }
            }
            EventKind::RemoteEnd { .. } => {
                // The handlers the remote work enabled ended with it.
                self.sync_when_list(r);
                self.clear_waits(r);
                if let Some((caller, req)) = self.serving[r].pop_front() {
                    self.tick(r);
                    self.merge_clock(caller, Seen::Robot(r));
                    self.vms[caller].remote_done(req, t);
                    self.requeue(caller);
                }
            }
            EventKind::Grip { site } => {
                let part = self.cell.linked.robots[r].parts[*site as usize] as usize;
                let name = &self.cell.parts[part].name;
                match self.collider.holder(part) {
                    None => self.collider.grip(part, r, &self.vms, &self.cell, t),
                    Some(h) if h == r => {
                        let m = format!(
                            "`{name}` is already in this robot's gripper; release it before gripping it again"
                        );
                        self.runtime_error(r, t, e.pos, m);
                    }
                    Some(h) => {
                        let m = format!(
                            "`{name}` is held by {}; it must release the part before this robot can grip it",
                            self.cell.robots[h].name
                        );
                        self.runtime_error(r, t, e.pos, m);
                    }
                }
            }
            EventKind::Release { site } => {
                let part = self.cell.linked.robots[r].parts[*site as usize] as usize;
                let name = &self.cell.parts[part].name;
                match self.collider.holder(part) {
                    Some(h) if h == r => self.collider.release(part, &self.vms, &self.cell, t),
                    Some(h) => {
                        let m = format!(
                            "this robot does not hold `{name}`: {} does; only the robot holding a part can release it",
                            self.cell.robots[h].name
                        );
                        self.runtime_error(r, t, e.pos, m);
                    }
                    None => {
                        let m = format!(
                            "this robot does not hold `{name}` (no robot does); grip it before releasing it"
                        );
                        self.runtime_error(r, t, e.pos, m);
                    }
                }
            }
            EventKind::Error { message } => {
                let issue = self.issue("runtime", message.clone(), Some(r), Some(e.pos));
                self.errors.push(issue);
                self.outcome = Some(Outcome::Error);
            }
            _ => {}
        }
    }

    /// Robot `r`'s wait timed out at `t`: a race with a set (of a global its condition
    /// reads) or a signal (that it waits for) at the same instant, which would have
    /// released it had it come first. Remembers the timeout for a set or signal that
    /// comes after it at this instant.
    fn timed_out_race(&mut self, r: usize, t: i64, pos: SrcPos) {
        // A condition reads at least one global (E0040), so a wait on none was for a signal.
        if !self.wait_list.iter().any(|w| w.0.contains(&r)) {
            if let Some((st, sender, spos, _)) = self.last_signal[r]
                && st == t
            {
                self.race(t, (sender, spos), (r, pos), "on a signal", "send it and time out a wait for it at the same instant; whether the signal releases the wait depends on their order");
            }
            self.signal_timeout[r] = Some((t, pos));
            return;
        }
        let n = self.vms.len();
        for cg in 0..self.wait_list.len() {
            if !self.wait_list[cg].0.contains(&r) {
                continue;
            }
            if let Some((st, setter, spos, stamp)) = self.last_set[cg]
                && st == t
                && setter != r
                && self.clock[r * n + setter] < stamp
            {
                let name = &self.cell.linked.globals[cg].name;
                let subject = format!("on `{name}`");
                self.race(t, (setter, spos), (r, pos), &subject, "set it and time out a wait on it at the same instant; whether the set releases the wait depends on their order");
            }
            self.last_timeout[cg] = Some((t, r, pos));
        }
    }

    /// Robot `r`'s entries in the WHEN list, made anew from its VM's enabled handlers.
    fn sync_when_list(&mut self, r: usize) {
        for w in &mut self.when_list {
            w.retain(|(q, _)| *q != r);
        }
        let cell = Arc::clone(&self.cell);
        for (target, globals) in self.vms[r].condition_handlers() {
            for g in globals {
                let cg = cell.linked.robots[r].globals[*g as usize] as usize;
                self.when_list[cg].insert((r, target));
            }
        }
    }

    /// Robot `r` no longer waits: off the WAIT list.
    fn clear_waits(&mut self, r: usize) {
        for w in &mut self.wait_list {
            w.remove(&r);
        }
    }

    /// A runtime error the SE finds in robot `r`'s event at `t` (a part gripped twice):
    /// an `error` event at the statement, and the run stops.
    fn runtime_error(&mut self, r: usize, t: i64, pos: SrcPos, message: String) {
        self.error(t, Some(r), Some(pos), "runtime", message);
        self.vms[r].halt();
        self.outcome = Some(Outcome::Error);
    }

    /// Robot `r` acts: its own clock entry advances; returns it (the action's stamp).
    fn tick(&mut self, r: usize) -> u64 {
        let n = self.vms.len();
        self.clock[r * n + r] += 1;
        self.clock[r * n + r]
    }

    /// Robot `r` has now seen what `from` records: what a robot had seen (its own actions
    /// included), or what the setter of a global had seen at its last set.
    fn merge_clock(&mut self, r: usize, from: Seen) {
        let n = self.vms.len();
        for k in 0..n {
            let seen = match from {
                Seen::Robot(q) => self.clock[q * n + k],
                Seen::Set(cg) => self.set_clock[cg * n + k],
            };
            let mine = &mut self.clock[r * n + k];
            *mine = (*mine).max(seen);
        }
    }

    /// Warns of a race when another robot set (or, for a set, read in a wait that passed)
    /// global `cg` at this same instant and robot `r` has not seen that action: their order
    /// is only the queue's tie order. An action `r` has seen (it was released, directly or
    /// through others, by what followed it) comes first in every order: a handshake.
    fn check_race(&mut self, cg: usize, r: usize, t: i64, pos: SrcPos, is_set: bool) {
        let n = self.vms.len();
        let others = [
            self.last_set[cg],
            if is_set { self.last_read[cg] } else { None },
        ];
        for (ot, or, opos, stamp) in others.into_iter().flatten() {
            if ot == t && or != r && self.clock[r * n + or] < stamp {
                let name = &self.cell.linked.globals[cg].name;
                let subject = format!("on `{name}`");
                self.race(
                    t,
                    (or, opos),
                    (r, pos),
                    &subject,
                    "touch it at the same instant; the outcome depends on their order",
                );
            }
        }
    }

    /// Reports a race at `t` between robot `first`'s statement and robot `second`'s (the
    /// one acting now): `race SUBJECT at T: A (file:pos) and B (file:pos) WHAT`.
    fn race(
        &mut self,
        t: i64,
        first: (usize, SrcPos),
        second: (usize, SrcPos),
        subject: &str,
        what: &str,
    ) {
        let ((or, opos), (r, pos)) = (first, second);
        let m = format!(
            "race {subject} at {}: {} ({}:{}) and {} ({}:{}) {what}",
            fmt_quantity(t as f64 / 1e9, vworks_vm::Dim::TIME),
            self.cell.robots[or].name,
            self.short(or),
            opos,
            self.cell.robots[r].name,
            self.short(r),
            pos
        );
        self.warning(t, Some(r), Some(pos), "race", m);
    }

    /// A `warning` trace event and the run's warning of `kind`.
    fn warning(
        &mut self,
        t: i64,
        robot: Option<usize>,
        pos: Option<SrcPos>,
        kind: &str,
        message: String,
    ) {
        let issue = self.issue(kind, message, robot, pos);
        self.add_warning(t, robot, pos, issue);
    }

    /// A `warning` trace event and the run's warning `issue`.
    fn add_warning(&mut self, t: i64, robot: Option<usize>, pos: Option<SrcPos>, issue: Issue) {
        self.warnings.push(issue.clone());
        self.record(t, robot, Kind::Warning, Detail::Issue(Box::new(issue)), pos);
    }

    /// An `error` trace event (the message quoted) and the run's error of `kind`. The
    /// caller sets the outcome.
    fn error(
        &mut self,
        t: i64,
        robot: Option<usize>,
        pos: Option<SrcPos>,
        kind: &str,
        message: String,
    ) {
        let issue = self.issue(kind, message, robot, pos);
        self.errors.push(issue.clone());
        self.record(t, robot, Kind::Error, Detail::Issue(Box::new(issue)), pos);
    }

    /// The globals robot `r`'s last segment read at this instant: a race with a set of
    /// another robot at the same instant that `r` has not seen (either order), as for
    /// `wait_until` conditions.
    fn note_reads(&mut self, r: usize) {
        if !self.vms[r].has_reads() {
            return;
        }
        let mut reads = std::mem::take(&mut self.reads);
        self.vms[r].take_reads(&mut reads);
        let (t, n) = (self.time, self.vms.len());
        for (mg, pos) in reads.drain(..) {
            let cg = self.cell.linked.robots[r].globals[mg as usize] as usize;
            self.check_race(cg, r, t, pos, false);
            // Seen by whoever has seen r's next action.
            let stamp = self.clock[r * n + r] + 1;
            self.last_read[cg] = Some((t, r, pos, stamp));
        }
        self.reads = reads;
    }

    fn on_set(&mut self, r: usize, g: u32, value: u64, t: i64, pos: SrcPos) {
        let cg = self.cell.linked.robots[r].globals[g as usize] as usize;
        self.check_race(cg, r, t, pos, true);
        if let Some((ot, q, qpos)) = self.last_timeout[cg]
            && ot == t
            && q != r
        {
            let name = &self.cell.linked.globals[cg].name;
            let subject = format!("on `{name}`");
            self.race(t, (q, qpos), (r, pos), &subject, "time out a wait and set it at the same instant; whether the set releases the wait depends on their order");
        }
        let stamp = self.tick(r);
        self.last_set[cg] = Some((t, r, pos, stamp));
        let n = self.vms.len();
        self.set_clock[cg * n..(cg + 1) * n].copy_from_slice(&self.clock[r * n..(r + 1) * n]);
        self.globals[cg].0 = value;
        for q in 0..self.vms.len() {
            if let Some(mg) = self.to_module[q][cg] {
                self.vms[q].set_global(mg, value);
            }
        }
        // check_wait / check_when for exactly the robots on this global's wait and when
        // lists, queued behind what is already due (in robot order, for determinism).
        for i in 0..self.wait_list[cg].len() {
            let q = self.wait_list[cg].0[i];
            self.push(t, Entry::CheckWait(q, cg as u32));
        }
        let mut last = None;
        for i in 0..self.when_list[cg].len() {
            let q = self.when_list[cg].0[i].0;
            if last != Some(q) {
                last = Some(q);
                self.push(t, Entry::CheckWhen(q, cg as u32));
            }
        }
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
                    self.short(r),
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
        self.error(t, robot, pos, "runtime", m);
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
            let (what, pos) = self.vms[*r]
                .waiting_for()
                .unwrap_or_else(|| ("something".into(), SrcPos::default()));
            parts.push(format!(
                "{} waits for {what} ({}:{pos})",
                self.cell.robots[*r].name,
                self.short(*r)
            ));
        }
        let m = format!("deadlock: {}", parts.join("; "));
        self.error(self.time, None, None, "deadlock", m);
        self.outcome = Some(Outcome::Deadlock);
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
        let fold = std::mem::replace(&mut self.fold, Fold::new(Vec::new(), false));
        let (robots, _) = fold.finish(end, &|r| endings.get(r).copied());
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
        let outcome = self.outcome.unwrap_or(Outcome::Completed);
        let run_end = RunEnd {
            outcome,
            end_time_ns: end,
            robots: &robots,
        };
        let mut log_counts = BTreeMap::new();
        for mut sink in std::mem::take(&mut self.sinks) {
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
            trace: self.trace,
            cycles: self.cycles,
            queries: self.collider.queries,
        }
    }
}

/// Whose vector clock a released robot takes in (see [`Simulation::merge_clock`]).
#[derive(Clone, Copy, Debug)]
enum Seen {
    /// A robot's, now.
    Robot(usize),
    /// The setter's, at the last set of this cell global.
    Set(usize),
}

/// A small ordered set kept as a sorted `Vec`: iterated by index while the simulation
/// queues entries, in the same (ascending) order a `BTreeSet` would give.
#[derive(Clone, Debug)]
struct SortedSet<T>(Vec<T>);

impl<T> Default for SortedSet<T> {
    fn default() -> Self {
        SortedSet(Vec::new())
    }
}

impl<T: Ord + Copy> SortedSet<T> {
    fn insert(&mut self, x: T) {
        if let Err(i) = self.0.binary_search(&x) {
            self.0.insert(i, x);
        }
    }

    fn remove(&mut self, x: &T) {
        if let Ok(i) = self.0.binary_search(x) {
            self.0.remove(i);
        }
    }

    fn retain(&mut self, keep: impl FnMut(&T) -> bool) {
        self.0.retain(keep);
    }

    fn len(&self) -> usize {
        self.0.len()
    }
}

#[cfg(test)]
mod tests {
    use super::Entry;

    #[test]
    fn queue_entries_pack_into_64_bits_and_back() {
        for e in [
            Entry::Vm(0, 0),
            Entry::Vm(3, 1 << 39),
            Entry::Vm((1 << 22) - 1, 12_345),
            Entry::CheckWait(7, u32::MAX),
            Entry::CheckWhen(63, 5),
            Entry::CheckWait(0, 0),
        ] {
            assert_eq!(Entry::unpack(e.pack()), e);
        }
    }
}
