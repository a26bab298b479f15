//! One robot's virtual machine: the paper's VM, driven by the simulation engine.
//!
//! The VM runs a stretch of independent work at once and stops *before* the next event.
//! [`Vm::next_event`] returns that event (kind, time, source position) without performing
//! it, and returns the same event until [`Vm::perform`] executes it, when the SE decides
//! it is that event's turn. Zero-time work never advances time; time passes only in
//! motions, delays and waits. The robot's joints are a pure function of time inside a
//! motion ([`Vm::joints_at`]), so the SE can sample every robot at every cycle boundary.

use std::sync::Arc;

use vworks_model::math::Iso;
use vworks_model::{IkError, RobotModel};

use crate::MAX_AXES;
use crate::bytecode::{Instr, LogPart, Module, MoveFlags, SrcPos};
use crate::exec::{Reader, RuntimeError, Stop, Thread};
use crate::motion::{NS, Path, Profile, cartesian_at};
use crate::types::{Dim, Type, fmt_quantity};

mod blend;
mod describe;
mod handlers;
mod names;
mod plan;
mod pulses;
mod view;
mod waits;

use blend::{Fading, Planned};
pub use names::{EVENT_NAMES, WarningKind};
use plan::Trajectory;
use view::View;

/// The latest simulated time an event may have: 2^62 ns, about 146 years. A delay, a
/// timeout, a motion or a handler period that would end later is a runtime error at its
/// statement, so that event times never overflow.
pub const TIME_LIMIT_NS: i64 = 1 << 62;

/// Settings of one VM.
#[derive(Clone, Debug)]
pub struct VmConfig {
    /// Instructions the robot may run at one simulated instant without time passing,
    /// over all its segments at that instant (default 10 million).
    pub budget: u64,
    /// Events the robot may perform at one simulated instant (default 100,000): a
    /// zero-time loop that emits events (`g = g + 1;`, a `log`, a handshake with another
    /// robot that never lets time pass) becomes a runtime error naming the loop.
    pub instant_events: u64,
    /// Deepest call nesting (default 256).
    pub max_depth: usize,
    /// The cycle period (ns), for `cycle()`.
    pub cycle_ns: i64,
    /// Speed of `move_l`/`move_c` without `speed` (m/s).
    pub default_speed: f64,
    /// Zone radius of motions without `zone` (m; `None`: `fine`, stop at the point).
    pub default_zone: Option<f64>,
    /// TCP in the tool-link frame.
    pub tool: Iso,
    /// Joints at the start.
    pub start_joints: Vec<f64>,
    /// This robot's index in the cell (copied into every event).
    pub robot: u32,
}

impl Default for VmConfig {
    fn default() -> VmConfig {
        VmConfig {
            budget: 10_000_000,
            instant_events: 100_000,
            max_depth: 256,
            cycle_ns: 4_000_000,
            default_speed: 0.25,
            default_zone: None,
            tool: Iso::IDENTITY,
            start_joints: Vec::new(),
            robot: 0,
        }
    }
}

/// What an event is.
#[derive(Clone, Debug, PartialEq)]
pub enum EventKind {
    /// A motion begins; its `motion_end` comes `duration_ns` later.
    MotionStart {
        /// `move_j`, `move_l` or `move_c`.
        command: &'static str,
        /// Exact time to its `motion_end`.
        duration_ns: i64,
        /// Its zone radius as programmed (or the workcell's default); `None`: `fine`.
        zone_m: Option<f64>,
        /// It starts inside the corner of the previous zoned point, which it blends out
        /// of within this radius (m).
        blend_m: Option<f64>,
    },
    /// The motion reached its target — or, for a zoned one, the TCP entered its zone
    /// (the robot goes on moving; the program runs ahead).
    MotionEnd {
        /// The zone radius its end was placed with (the programmed one, at most half the
        /// motion), for a zoned motion.
        zone_m: Option<f64>,
        /// The zone radius programmed, for a zoned motion.
        programmed_m: Option<f64>,
    },
    /// The robot holds still for `duration_ns`.
    Delay {
        /// How long.
        duration_ns: i64,
    },
    /// The delay is over.
    DelayEnd,
    /// A global is assigned (module global index and the new value's slot bits).
    Set {
        /// Index in the module's global table.
        global: u32,
        /// The value.
        value: u64,
        /// Its type.
        ty: Type,
    },
    /// The robot starts waiting for a condition (index into the module's conditions).
    WaitUntil {
        /// The condition.
        cond: u32,
        /// Deadline (absolute ns) if a timeout was given.
        deadline: Option<i64>,
        /// The poll period (ns) of a polled wait: it is released only on its grid.
        poll_ns: Option<i64>,
    },
    /// The robot starts waiting for a signal (string index of its name).
    WaitSignal {
        /// Signal name (string index).
        name: u32,
        /// Deadline (absolute ns) if a timeout was given.
        deadline: Option<i64>,
    },
    /// The robot arrives at a sync point (sync site index) and waits for the other tasks
    /// of its list.
    WaitSync {
        /// The sync site (sync point and task list).
        site: u32,
        /// Deadline (absolute ns) if a timeout was given.
        deadline: Option<i64>,
    },
    /// The wait is over.
    WaitEnd {
        /// It ended by timeout.
        timed_out: bool,
    },
    /// A signal is sent (signal site index).
    Signal {
        /// The site (receiver and name).
        site: u32,
    },
    /// A part is attached to the tool (part site index).
    Grip {
        /// The site.
        site: u32,
    },
    /// A part is detached (part site index).
    Release {
        /// The site.
        site: u32,
    },
    /// A `log` message.
    Log {
        /// The text.
        text: String,
    },
    /// A runtime error or `fail`: the simulation stops.
    Error {
        /// The message.
        message: String,
    },
    /// A `when` handler is enabled (module handler index).
    EnableWhen {
        /// The handler.
        handler: u32,
    },
    /// Handlers calling procedure `proc` are disabled.
    DisableWhen {
        /// The handler procedure.
        proc: u32,
    },
    /// A handler fires (module handler index); its events follow, then `WhenEnd`.
    WhenFire {
        /// The handler.
        handler: u32,
    },
    /// The handler finished.
    WhenEnd {
        /// The handler.
        handler: u32,
    },
    /// This robot asks another to run a procedure (remote site index); `req` identifies
    /// the request in `remote_done`.
    RemoteCall {
        /// The remote site.
        site: u32,
        /// Request number (per caller).
        req: u64,
        /// Argument slots.
        args: Vec<u64>,
    },
    /// This robot waits for the remote work of its `parallel` block.
    Join,
    /// This robot starts serving a remote request (procedure index).
    RemoteStart {
        /// The procedure.
        proc: u32,
    },
    /// This robot finished a remote request.
    RemoteEnd {
        /// The procedure.
        proc: u32,
    },
    /// The program ended.
    End,
}

/// An event of this VM.
#[derive(Clone, Debug, PartialEq)]
pub struct Event {
    /// Simulated time (ns).
    pub time: i64,
    /// The robot (its index in the cell, from [`VmConfig::robot`]).
    pub robot: u32,
    /// What.
    pub kind: EventKind,
    /// The statement that caused it.
    pub pos: SrcPos,
}

/// A warning about the program's motions, for the SE to report.
#[derive(Clone, Debug, PartialEq)]
pub struct Warning {
    /// When.
    pub time: i64,
    /// The statement.
    pub pos: SrcPos,
    /// What kind of warning.
    pub kind: WarningKind,
    /// What happened and what to do.
    pub message: String,
}

/// What the VM does after its current event.
#[derive(Clone, Debug, PartialEq)]
pub enum Next {
    /// This event, at its time.
    Event(Event),
    /// Nothing until the SE releases a wait (a condition or a signal).
    Blocked,
    /// The program has ended; the robot serves remote requests when they come.
    Idle,
    /// The program failed (or the VM was stopped): nothing more will happen.
    Done,
}

#[derive(Clone, Debug, PartialEq)]
enum State {
    /// Must run code to find the next event.
    Run,
    /// Stopped before this event.
    At(Event),
    /// Moving until `end`.
    Moving { end: i64, pos: SrcPos },
    /// Holding still until `end`.
    Delaying { end: i64, pos: SrcPos },
    /// Waiting for a condition or a signal.
    Waiting {
        cond: Option<u32>,
        signal: Option<u32>,
        /// A sync site: waiting at its sync point until the engine releases the meeting.
        sync: Option<u32>,
        deadline: Option<i64>,
        /// A polled wait's start and period (ns).
        poll: Option<(i64, i64)>,
        pos: SrcPos,
    },
    /// Released from a wait at `time`; `timed`: the wait had a timeout (only those set
    /// `timed_out()`).
    Released {
        time: i64,
        timed_out: bool,
        timed: bool,
        pos: SrcPos,
    },
    /// Waiting for the remote work of the `parallel` block at this depth.
    Joining { depth: u32, pos: SrcPos },
    /// The program ended; serving remote requests.
    Idle,
    /// Failed or stopped for good.
    Done,
}

impl State {
    /// Released at `time` (not by a timeout) from the wait at `pos`; `deadline`: the wait's,
    /// if it had a timeout.
    fn released(time: i64, deadline: Option<i64>, pos: SrcPos) -> State {
        State::Released {
            time,
            timed_out: false,
            timed: deadline.is_some(),
            pos,
        }
    }
}

/// When an enabled handler fires.
#[derive(Clone, Debug)]
enum Firing {
    /// At `next`, then every `period` if any.
    Timer { next: i64, period: Option<i64> },
    /// On each false→true edge of its condition; `last` is the value last seen.
    Edge { last: bool },
}

/// An enabled `when` handler.
#[derive(Clone, Debug)]
struct Enabled {
    handler: u32,
    target: u32,
    /// Captured slots for the action and for the condition.
    args: Vec<u64>,
    cond_args: Vec<u64>,
    firing: Firing,
}

/// A remote request waiting to be served.
#[derive(Clone, Debug)]
struct Request {
    proc: u32,
    args: Vec<u64>,
    time: i64,
}

/// Which context produced the event `next_event` returned last.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Source {
    Main,
    Handler,
    Fire(usize),
    /// The end of a pulse (an index into `pulses`).
    Pulse(usize),
    None,
}

/// The VM of one robot.
#[derive(Debug)]
pub struct Vm {
    /// Cartesian paths sampled, by the bits of their joints, poses and speed
    /// (`plan::PathSamples`): a program repeating its moves samples each once.
    path_memo: Vec<([u64; plan::PATH_KEY], plan::PathSamples)>,
    /// A polled wait's next poll the SE should check at (taken once), and the last one
    /// asked for (not asked twice).
    poll_check: Option<i64>,
    poll_requested: Option<i64>,
    /// The TCP in the tool link's frame: the workcell's tool, then the last motion's
    /// `tool`.
    tool: Iso,
    m: Arc<Module>,
    model: Arc<RobotModel>,
    cfg: VmConfig,
    main: Thread,
    vars: Vec<u64>,
    state: State,
    time: i64,
    /// Joints when not moving (at `time`, or at the start of the current motion).
    rest: [f64; MAX_AXES],
    /// The current motion (its start time is `start`).
    motion: Option<Planned>,
    /// The motion planned by `next_event`, started by `perform`.
    pending_motion: Option<Planned>,
    /// The rest of a zoned motion after its `motion_end`, while the robot finishes it.
    fading: Option<Fading>,
    /// Statements already warned about their zoned points (`blend::warn_once`).
    zone_warned: Vec<u32>,
    timed_out: bool,
    /// Scratch thread for evaluating conditions.
    cond_thread: Thread,
    /// The thread of the handler now running, its state, and (enabled index, firing time).
    handler: Thread,
    hstate: State,
    hrun: Option<(usize, i64)>,
    /// The module handler index of the running handler.
    hrun_handler: u32,
    /// Enabled handlers, in enabling order.
    enabled: Vec<Enabled>,
    /// Condition handlers whose edge was seen: (time, enabled index).
    fires: Vec<(i64, usize)>,
    /// Pulses under way, in the order they started.
    pulses: Vec<pulses::PulseEnd>,
    /// Outstanding remote requests: (parallel depth, request number).
    join: Vec<(u32, u64)>,
    par_depth: u32,
    next_req: u64,
    /// Remote requests waiting for this robot, and the one being served.
    queue: std::collections::VecDeque<Request>,
    serving: Option<u32>,
    source: Source,
    /// Pending signals: (name string index, count).
    signals: Vec<(u32, u32)>,
    /// Globals as the SE last gave them (slot bits by module global index).
    globals: Vec<u64>,
    /// Warnings to report (e.g. a move slowed by an axis speed limit).
    warnings: Vec<Warning>,
    /// The simulated instant the budgets below count for, the instructions left at it and
    /// the events performed at it.
    instant: i64,
    instant_budget: u64,
    instant_events: u64,
    /// Reads of globals by the main program and handlers, for race warnings.
    read_log: ReadLog,
}

/// Which globals the main program and handlers read at the current instant.
#[derive(Debug, Default)]
struct ReadLog {
    /// Per module global: the instant it was last read.
    at: Vec<i64>,
    /// The globals first read at their instant since the SE last took them, and where.
    new: Vec<(u32, SrcPos)>,
}

/// `secs` seconds from instant `t` in whole nanoseconds (rounded), if they end by
/// [`TIME_LIMIT_NS`]; else what is wrong with `what`. `secs` is not negative.
fn span_ns(secs: f64, t: i64, what: &str) -> Result<i64, String> {
    let ns = (secs * NS).round();
    if ns.is_nan() || ns > (TIME_LIMIT_NS - t) as f64 {
        return Err(format!(
            "{what} of {} would end after the last instant the simulator can represent (2^62 ns, about 146 years); use a shorter time",
            fmt_quantity(secs, Dim::TIME)
        ));
    }
    Ok(ns as i64)
}

fn to_iso(p: &[u64]) -> Iso {
    let v = |i: usize| f64::from_bits(p[i]);
    Iso::from_xyz_rpy([v(0), v(1), v(2)], [v(3), v(4), v(5)])
}

impl Vm {
    /// A VM for `module` on `model`, about to run procedure `entry`; with `None` the robot
    /// only serves remote requests (`serve_only`).
    pub fn new(m: Arc<Module>, model: Arc<RobotModel>, cfg: VmConfig, entry: Option<u32>) -> Vm {
        let initial_tool = cfg.tool;
        let mut vars = vec![0u64; m.var_slots as usize];
        for v in &m.vars {
            let w = v.ty.width() as usize;
            v.init
                .write_slots(&mut vars[v.slot as usize..v.slot as usize + w]);
        }
        let globals: Vec<u64> = m
            .globals
            .iter()
            .map(|g| {
                let mut s = [0u64];
                g.init.write_slots(&mut s);
                s[0]
            })
            .collect();
        let mut rest = [0.0; MAX_AXES];
        for (r, q) in rest.iter_mut().zip(&cfg.start_joints) {
            *r = *q;
        }
        let mut main = Thread::default();
        main.reserve(&m, cfg.max_depth);
        if let Some(entry) = entry {
            main.start(&m, entry, &[]);
        }
        Vm {
            m,
            model,
            cfg,
            main,
            vars,
            state: if entry.is_some() {
                State::Run
            } else {
                State::Idle
            },
            time: 0,
            rest,
            motion: None,
            pending_motion: None,
            fading: None,
            zone_warned: Vec::new(),
            timed_out: false,
            cond_thread: Thread::default(),
            handler: Thread::default(),
            hstate: State::Done,
            hrun: None,
            hrun_handler: 0,
            enabled: Vec::new(),
            fires: Vec::new(),
            pulses: Vec::new(),
            join: Vec::new(),
            par_depth: 0,
            next_req: 0,
            queue: std::collections::VecDeque::new(),
            serving: None,
            source: Source::None,
            signals: Vec::new(),
            read_log: ReadLog {
                at: vec![-1; globals.len()],
                new: Vec::with_capacity(4),
            },
            globals,
            warnings: Vec::new(),
            path_memo: Vec::with_capacity(plan::PATH_MEMO),
            poll_check: None,
            poll_requested: None,
            tool: initial_tool,
            instant: -1,
            instant_budget: 0,
            instant_events: 0,
        }
    }

    /// The module.
    pub fn module(&self) -> &Module {
        &self.m
    }

    /// The VM's clock: the time of the last event it performed.
    pub fn time(&self) -> i64 {
        self.time
    }

    /// Tells the VM a global's current value (module global index, slot bits). The SE
    /// calls this for every robot whose module has the global, after each `set`.
    pub fn set_global(&mut self, g: u32, value: u64) {
        if let Some(v) = self.globals.get_mut(g as usize) {
            *v = value;
        }
    }

    /// Moves into `out` the globals (module indices) that the main program or a handler
    /// read for the first time at the current instant since the last call, with the
    /// reading statement's position: the SE warns of a race when another robot sets one
    /// at the same instant.
    pub fn take_reads(&mut self, out: &mut Vec<(u32, SrcPos)>) {
        out.append(&mut self.read_log.new);
    }

    /// Whether [`Vm::take_reads`] has anything to give.
    #[inline]
    pub fn has_reads(&self) -> bool {
        !self.read_log.new.is_empty()
    }

    /// Sets how many events the robot may perform at one instant
    /// ([`VmConfig::instant_events`]).
    pub fn set_instant_events(&mut self, limit: u64) {
        self.cfg.instant_events = limit;
    }

    /// Stops the VM for good: the SE found a runtime error in the event it just performed
    /// (a part gripped twice). Its next event is [`Next::Done`].
    pub fn halt(&mut self) {
        self.state = State::Done;
        self.hrun = None;
        self.hstate = State::Done;
        self.enabled.clear();
        self.fires.clear();
    }

    /// How many events the robot performed at instant `t` (0 unless its last events were
    /// at `t`).
    pub fn events_at(&self, t: i64) -> u64 {
        if self.instant == t {
            self.instant_events
        } else {
            0
        }
    }

    /// Where the main program is, for a report of a zero-time loop: the innermost loop
    /// around its current statement (or around the call that leads there), else the
    /// statement.
    pub fn loop_position(&self) -> SrcPos {
        let pc = self.main.pc;
        self.m.pos_of(self.loop_start(pc, &self.main).unwrap_or(pc))
    }

    /// True while a motion is in progress at time `t`.
    pub fn moving_at(&self, t: i64) -> bool {
        matches!(self.state, State::Moving { end, .. } if t < end)
            && self.motion.as_ref().is_some_and(|m| t > m.start)
            || self
                .fading
                .as_ref()
                .is_some_and(|f| t > f.motion.start && t < f.end())
    }

    /// Warnings produced so far; the SE drains them.
    pub fn take_warnings(&mut self) -> Vec<Warning> {
        std::mem::take(&mut self.warnings)
    }

    fn error_event(&self, e: &RuntimeError, time: i64) -> Event {
        Event {
            robot: self.cfg.robot,
            time,
            kind: EventKind::Error {
                message: e.message.clone(),
            },
            pos: e.pos,
        }
    }

    /// The next event of this VM (performing nothing). Calling it again returns the same
    /// event until [`Vm::perform`] executes it. A running handler's events come first;
    /// then whichever is earlier of the main program's next event and the next handler
    /// firing (a handler first on a tie).
    pub fn next_event(&mut self) -> Next {
        if let Some((_, t)) = self.hrun {
            if self.hstate == State::Run {
                let e = self.run_segment(true, t);
                self.hstate = State::At(e);
            }
            if let State::At(e) = &self.hstate {
                self.source = Source::Handler;
                return Next::Event(e.clone());
            }
        }
        let main = self.main_event();
        let fire = self.next_fire();
        if let Some(pulse_end) = self.pulse_event(&main, fire) {
            return pulse_end;
        }
        match (main, fire) {
            (Next::Event(e), Some((t, i))) if t <= e.time => self.fire_event(t, i),
            (Next::Event(e), _) => {
                self.source = Source::Main;
                Next::Event(e)
            }
            (Next::Done, _) => Next::Done,
            (other, Some((t, i))) => {
                let _ = other;
                self.fire_event(t, i)
            }
            (other, None) => {
                self.source = Source::None;
                other
            }
        }
    }

    fn main_event(&mut self) -> Next {
        match &self.state {
            State::Done => Next::Done,
            State::At(e) => Next::Event(e.clone()),
            State::Moving { end, pos } => Next::Event(Event {
                robot: self.cfg.robot,
                time: *end,
                kind: EventKind::MotionEnd {
                    zone_m: self.motion.as_ref().map(|m| m.zone).filter(|z| *z > 0.0),
                    programmed_m: self.motion.as_ref().and_then(|m| m.programmed),
                },
                pos: *pos,
            }),
            State::Delaying { end, pos } => Next::Event(Event {
                robot: self.cfg.robot,
                time: *end,
                kind: EventKind::DelayEnd,
                pos: *pos,
            }),
            State::Waiting {
                deadline: Some(d),
                pos,
                ..
            } => Next::Event(Event {
                robot: self.cfg.robot,
                time: *d,
                kind: EventKind::WaitEnd { timed_out: true },
                pos: *pos,
            }),
            State::Waiting { .. } | State::Joining { .. } => Next::Blocked,
            State::Released {
                time,
                timed_out,
                pos,
                ..
            } => Next::Event(Event {
                robot: self.cfg.robot,
                time: *time,
                kind: EventKind::WaitEnd {
                    timed_out: *timed_out,
                },
                pos: *pos,
            }),
            State::Idle => match self.queue.front() {
                Some(r) => {
                    let p = &self.m.procs[r.proc as usize];
                    let e = Event {
                        robot: self.cfg.robot,
                        time: r.time.max(self.time),
                        kind: EventKind::RemoteStart { proc: r.proc },
                        pos: p.pos,
                    };
                    self.state = State::At(e.clone());
                    Next::Event(e)
                }
                None => Next::Idle,
            },
            State::Run => {
                let e = self.run_segment(false, self.time);
                self.state = State::At(e.clone());
                Next::Event(e)
            }
        }
    }

    /// Runs zero-time code of the main thread (or the handler thread) up to its next event
    /// instruction and describes that event.
    fn run_segment(&mut self, in_handler: bool, t: i64) -> Event {
        self.enter_instant(t);
        if self.instant_events >= self.cfg.instant_events {
            let th = self.thread(in_handler);
            let e = self.zero_time_loop(
                th.pc,
                th,
                format!(
                    "{} events at {}",
                    self.cfg.instant_events,
                    fmt_quantity(t as f64 / NS, Dim::TIME)
                ),
            );
            return self.error_event(&e, t);
        }
        loop {
            let mut thread = std::mem::take(if in_handler {
                &mut self.handler
            } else {
                &mut self.main
            });
            let stop = self.run_thread(&mut thread, t, true);
            let pc = thread.pc;
            if in_handler {
                self.handler = thread;
            } else {
                self.main = thread;
            }
            // A finished thread's pc is past its last `Ret`: report the `Ret`.
            let pos = self.m.pos_of(if matches!(stop, Ok(Stop::Finished)) {
                pc.saturating_sub(1)
            } else {
                pc
            });
            // A zoned point still ahead becomes a stop point before some statements.
            let t = match (in_handler, &stop) {
                (false, Ok(Stop::Finished)) => self.stop_point(None, pc.saturating_sub(1), t),
                (false, Ok(Stop::Event(ins))) => self.stop_point(Some(*ins), pc, t),
                _ => t,
            };
            let kind = match stop {
                Err(e) => return self.error_event(&e, t),
                Ok(Stop::Finished) => match (in_handler, self.hrun, self.serving) {
                    (true, Some(_), _) => EventKind::WhenEnd {
                        handler: self.hrun_handler,
                    },
                    (false, _, Some(proc)) => EventKind::RemoteEnd { proc },
                    _ => EventKind::End,
                },
                Ok(Stop::Event(Instr::ParBegin)) if !in_handler => {
                    // Not an event: the start of a join group.
                    self.par_depth += 1;
                    self.main.pc = pc + 1;
                    continue;
                }
                // `stop` in a handler: the handler ends first (`when_end`), then the
                // program (`end`, see `perform_handler`).
                Ok(Stop::Event(Instr::Stop)) if in_handler && self.hrun.is_some() => {
                    EventKind::WhenEnd {
                        handler: self.hrun_handler,
                    }
                }
                Ok(Stop::Event(ins)) => match self.describe(ins, t, in_handler) {
                    Ok(k) => k,
                    Err(message) => EventKind::Error { message },
                },
            };
            // A motion may start later, within the corner of the zoned point before it.
            let time = match (&kind, &self.pending_motion) {
                (EventKind::MotionStart { .. }, Some(p)) => p.start,
                _ => t,
            };
            return Event {
                robot: self.cfg.robot,
                time,
                kind,
                pos,
            };
        }
    }

    fn thread(&self, in_handler: bool) -> &Thread {
        if in_handler {
            &self.handler
        } else {
            &self.main
        }
    }

    fn top(&self, in_handler: bool, depth_from_top: usize) -> u64 {
        let s = &self.thread(in_handler).stack;
        s[s.len() - 1 - depth_from_top]
    }

    /// Performs the event [`Vm::next_event`] returned last.
    pub fn perform(&mut self) {
        match std::mem::replace(&mut self.source, Source::None) {
            Source::Main => self.perform_main(),
            Source::Handler => self.perform_handler(),
            Source::Fire(i) => self.perform_fire(i),
            Source::Pulse(i) => self.perform_pulse_end(i),
            Source::None => return,
        }
        if self.fading.as_ref().is_some_and(|f| self.time >= f.end()) {
            self.fading = None;
        }
        self.enter_instant(self.time);
        self.instant_events += 1;
    }

    /// Effects shared by the main program and handlers: set, log, enable, disable.
    fn apply_zero_time(&mut self, e: &Event, ins: Instr, in_handler: bool) {
        let th = if in_handler {
            &mut self.handler
        } else {
            &mut self.main
        };
        match &e.kind {
            EventKind::Set { global, value, .. } => {
                let top = th.stack.pop();
                self.set_global(*global, *value);
                if let (Instr::PulseGlobal(g), Some(secs)) = (ins, top) {
                    self.start_pulse(g, f64::from_bits(secs), e.time, e.pos);
                }
            }
            EventKind::Log { .. } => {
                if let Instr::Log(f) = ins {
                    let w = self.m.log_formats[f as usize].value_width() as usize;
                    let l = th.stack.len() - w;
                    th.stack.truncate(l);
                }
            }
            EventKind::EnableWhen { handler } => self.enable(*handler, e.time, in_handler),
            EventKind::DisableWhen { proc } => {
                let proc = *proc;
                self.remove_enabled(|_, x| x.target == proc);
            }
            _ => {}
        }
    }

    /// The program or the remote work being served ended: its handlers go (a handler
    /// belongs to the activation that enabled it, and every enabled handler was enabled by
    /// the one ending: remote work starts only once the program has ended), and the robot
    /// serves remote requests.
    fn end_program(&mut self) {
        self.serving = None;
        self.enabled.clear();
        self.fires.clear();
        self.state = State::Idle;
    }

    /// `stop` ran in a handler at `t`: whatever the main thread was doing (a motion, a
    /// wait) is abandoned, the robot holds still where it is, and the program ends (`end`)
    /// — or, in remote work, the remote work ends (`remote_end`).
    fn stop_program(&mut self, t: i64, pos: SrcPos) {
        if self.motion.is_some() || self.fading.is_some() {
            self.rest = self.joints_at(t);
            self.motion = None;
            self.fading = None;
        }
        self.pending_motion = None;
        self.state = State::At(Event {
            robot: self.cfg.robot,
            time: t,
            kind: self.end_kind(),
            pos,
        });
    }

    /// What `stop` ends: the remote work being served, or the program.
    fn end_kind(&self) -> EventKind {
        match self.serving {
            Some(proc) => EventKind::RemoteEnd { proc },
            None => EventKind::End,
        }
    }

    fn perform_main(&mut self) {
        let state = std::mem::replace(&mut self.state, State::Run);
        match state {
            State::At(e) => {
                self.time = e.time;
                let pc = self.main.pc;
                let ins = self.m.code.get(pc as usize).copied().unwrap_or(Instr::Stop);
                match &e.kind {
                    EventKind::Error { .. } => {
                        self.state = State::Done;
                        return;
                    }
                    EventKind::End => {
                        self.end_program();
                        return;
                    }
                    EventKind::RemoteEnd { .. } => {
                        self.end_program();
                        return;
                    }
                    EventKind::MotionStart { duration_ns, .. } => {
                        let width = self.motion_operands(ins).width;
                        let l = self.main.stack.len() - width;
                        self.main.stack.truncate(l);
                        // (Planned to start at this event's time.)
                        self.motion = self.pending_motion.take();
                        self.state = State::Moving {
                            end: e.time + duration_ns,
                            pos: e.pos,
                        };
                    }
                    EventKind::Delay { duration_ns } => {
                        self.main.stack.pop();
                        self.state = State::Delaying {
                            end: e.time + duration_ns,
                            pos: e.pos,
                        };
                    }
                    EventKind::WaitUntil {
                        cond,
                        deadline,
                        poll_ns,
                    } => {
                        if poll_ns.is_some() {
                            self.main.stack.pop();
                        }
                        if deadline.is_some() {
                            self.main.stack.pop();
                        }
                        self.poll_requested = None;
                        self.state = if self.eval_cond(*cond, e.time) {
                            State::released(e.time, *deadline, e.pos)
                        } else {
                            State::Waiting {
                                cond: Some(*cond),
                                signal: None,
                                sync: None,
                                deadline: *deadline,
                                poll: poll_ns.map(|p| (e.time, p)),
                                pos: e.pos,
                            }
                        };
                    }
                    EventKind::WaitSignal { name, deadline } => {
                        if deadline.is_some() {
                            self.main.stack.pop();
                        }
                        let have = self.signals.iter_mut().find(|(n, c)| n == name && *c > 0);
                        self.state = if let Some((_, c)) = have {
                            *c -= 1;
                            State::released(e.time, *deadline, e.pos)
                        } else {
                            State::Waiting {
                                cond: None,
                                signal: Some(*name),
                                sync: None,
                                deadline: *deadline,
                                poll: None,
                                pos: e.pos,
                            }
                        };
                    }
                    EventKind::WaitSync { site, deadline } => {
                        if deadline.is_some() {
                            self.main.stack.pop();
                        }
                        // The engine keeps the sync point: it releases the meeting when
                        // every task of the list has arrived (`release_sync`).
                        self.state = State::Waiting {
                            cond: None,
                            signal: None,
                            sync: Some(*site),
                            deadline: *deadline,
                            poll: None,
                            pos: e.pos,
                        };
                    }
                    EventKind::RemoteCall { req, args, .. } => {
                        let l = self.main.stack.len() - args.len();
                        self.main.stack.truncate(l);
                        self.join.push((self.par_depth, *req));
                        self.next_req += 1;
                    }
                    EventKind::Join => {
                        let d = self.par_depth;
                        self.state = if self.join.iter().any(|(depth, _)| *depth == d) {
                            State::Joining {
                                depth: d,
                                pos: e.pos,
                            }
                        } else {
                            self.par_depth = self.par_depth.saturating_sub(1);
                            State::released(e.time, None, e.pos)
                        };
                    }
                    EventKind::RemoteStart { proc } => {
                        let Some(r) = self.queue.pop_front() else {
                            return;
                        };
                        self.main.start(&self.m, *proc, &r.args);
                        self.serving = Some(*proc);
                        self.state = State::Run;
                        return;
                    }
                    _ => self.apply_zero_time(&e, ins, false),
                }
                self.main.pc = pc + 1;
            }
            State::Moving { end, pos } => {
                self.time = end;
                if let Some(motion) = self.motion.take() {
                    // Exactly the target, not the profile's last float.
                    self.rest = motion.traj.end_joints();
                    if motion.zone > 0.0 && motion.end_ns < motion.point_ns {
                        let n = self.model.dof();
                        let corner_pose = match &motion.traj {
                            Trajectory::Cartesian { to, .. } => *to,
                            _ => self.model.tcp(&self.rest[..n], &motion.tool),
                        };
                        self.fading = Some(Fading {
                            motion,
                            corner: self.rest,
                            corner_pose,
                            pos,
                        });
                    }
                }
            }
            State::Delaying { end, .. } => self.time = end,
            State::Waiting {
                deadline: Some(d), ..
            } => {
                self.time = d;
                self.timed_out = true;
            }
            State::Released {
                time,
                timed_out,
                timed,
                ..
            } => {
                self.time = time;
                // `timed_out()` reports the most recent *timed* wait.
                if timed {
                    self.timed_out = timed_out;
                }
            }
            other => self.state = other,
        }
    }

    /// Runs a thread's zero-time code at time `t` over this VM's module variables, within
    /// what is left of the instant's instruction budget. `record_reads`: the thread is the
    /// main program or a handler (see [`Vm::take_reads`]).
    fn run_thread(
        &mut self,
        th: &mut Thread,
        t: i64,
        record_reads: bool,
    ) -> Result<Stop, RuntimeError> {
        self.enter_instant(t);
        let mut budget = self.instant_budget;
        let mut vars = std::mem::take(&mut self.vars);
        // Moved out for the run (the view borrows the VM), and back; not at all when the
        // module has no globals to read.
        let log = (record_reads && !self.read_log.at.is_empty())
            .then(|| std::cell::RefCell::new(std::mem::take(&mut self.read_log)));
        let r = th.run(
            &self.m,
            &View {
                vm: self,
                t,
                reads: log.as_ref(),
            },
            &mut vars,
            &mut budget,
            self.cfg.max_depth,
        );
        if let Some(log) = log {
            self.read_log = log.into_inner();
        }
        self.instant_budget = budget;
        self.vars = vars;
        match r {
            Err(e) if budget == 0 => Err(self.zero_time_loop(
                e.pc,
                th,
                format!(
                    "{} instructions at {}",
                    self.cfg.budget,
                    fmt_quantity(t as f64 / NS, Dim::TIME)
                ),
            )),
            other => other,
        }
    }

    /// Starts counting the budgets of instant `t` if it is a new one.
    fn enter_instant(&mut self, t: i64) {
        if t != self.instant {
            self.instant = t;
            self.instant_budget = self.cfg.budget;
            self.instant_events = 0;
        }
    }

    /// The error of a zero-time loop at `pc` of `th`: it names the innermost loop around
    /// `pc` (or around the call that leads there), or the statement if there is none.
    fn zero_time_loop(&self, pc: u32, th: &Thread, what: String) -> RuntimeError {
        let (at, place) = match self.loop_start(pc, th) {
            Some(start) => (start, "this loop"),
            None => (pc, "this statement"),
        };
        RuntimeError {
            message: format!(
                "{place} never lets time pass ({what}): an endless zero-time loop; add a motion, a delay or a wait that blocks inside it"
            ),
            pc: at,
            pos: self.m.pos_of(at),
        }
    }

    /// The start of the innermost loop around `pc` of `th`, or around the call that leads
    /// there.
    fn loop_start(&self, pc: u32, th: &Thread) -> Option<u32> {
        let calls = th.frames.iter().rev().map(|f| f.ret_pc);
        std::iter::once(pc)
            .chain(calls)
            .find_map(|at| self.loop_around(at))
    }

    /// The start of the innermost loop around absolute instruction `pc`: the target of the
    /// shortest backward jump of the same procedure that spans it.
    fn loop_around(&self, pc: u32) -> Option<u32> {
        let p = &self.m.procs[self.m.proc_at(pc)? as usize];
        let code = p.code(&self.m);
        let rel = pc - p.code_start;
        code.iter()
            .enumerate()
            .filter_map(|(j, ins)| {
                let t = ins.jump_target()?;
                (t <= rel && rel <= j as u32).then(|| (j as u32 - t, t))
            })
            .min()
            .map(|(_, t)| p.code_start + t)
    }
}
