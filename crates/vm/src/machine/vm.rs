//! [`Vm`], one robot: the segment interface the engine drives (`next_event`/`perform`),
//! running segments within the instant's budgets, performing events, ending programs. It
//! holds components that own their state — the interpreter's (`interp`), the motions
//! (`arm`), the handlers, the waits, the remote work, the pulses — and calls their
//! methods; the public interface answers from them.

use std::sync::Arc;

use vworks_model::RobotModel;
use vworks_model::math::Iso;

use super::arm::Arm;
use super::blend::stop_point_reason;
use super::describe::{self, describe};
use super::handlers::Handlers;
use super::interp::{self, Interp};
use super::plan::{Capped, MotionOperands};
use super::pulses::Pulses;
use super::remote::{Remote, Request};
use super::state::{Source, State};
use super::view::Sight;
use super::waits::Waits;
use super::{Event, EventKind, Next, TIME_LIMIT_NS, VmConfig, Warning, WarningKind, span_ns};
use crate::MAX_AXES;
use crate::bytecode::{Instr, Module, SrcPos};
use crate::exec::{RuntimeError, Stop, Thread};
use crate::motion::NS;
use crate::types::{Dim, fmt_quantity};

/// The VM of one robot.
#[derive(Debug)]
pub struct Vm {
    m: Arc<Module>,
    cfg: VmConfig,
    /// The main program's thread (or the remote work's) and where it stands.
    main: Thread,
    state: State,
    /// The time of the last event performed.
    time: i64,
    /// Variables, globals, reads, the condition thread, the instant's budgets.
    interp: Interp,
    /// The robot's motions and tool.
    arm: Arm,
    handlers: Handlers,
    waits: Waits,
    remote: Remote,
    pulses: Pulses,
    /// Which context produced the event `next_event` returned last.
    source: Source,
    /// Warnings to report (e.g. a move slowed by an axis speed limit).
    warnings: Vec<Warning>,
    /// Statements already warned about, and what about (`warn_once`).
    warned: Vec<(u32, WarningKind)>,
}

/// A [`Sight`] of the VM's parts, borrowed field by field (so that the interpreter's
/// state can be borrowed mutably beside it).
macro_rules! sight {
    ($vm:expr) => {
        Sight {
            m: &$vm.m,
            arm: &$vm.arm,
            cycle_ns: $vm.cfg.cycle_ns,
            timed_out: $vm.waits.timed_out(),
        }
    };
}

impl Vm {
    /// A VM for `module` on `model`, about to run procedure `entry`; with `None` the robot
    /// only serves remote requests (`serve_only`).
    pub fn new(m: Arc<Module>, model: Arc<RobotModel>, cfg: VmConfig, entry: Option<u32>) -> Vm {
        let mut main = Thread::default();
        main.reserve(&m, cfg.max_depth);
        if let Some(entry) = entry {
            main.start(&m, entry, &[]);
        }
        Vm {
            interp: Interp::new(&m),
            arm: Arm::new(model, &cfg.start_joints, cfg.tool),
            m,
            cfg,
            main,
            state: if entry.is_some() {
                State::Run
            } else {
                State::Idle
            },
            time: 0,
            handlers: Handlers::default(),
            waits: Waits::default(),
            remote: Remote::default(),
            pulses: Pulses::default(),
            source: Source::None,
            warnings: Vec::new(),
            warned: Vec::new(),
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
        self.interp.set_global(g, value);
    }

    /// Moves into `out` the globals (module indices) that the main program or a handler
    /// read for the first time at the current instant since the last call, with the
    /// reading statement's position: the SE warns of a race when another robot sets one
    /// at the same instant.
    pub fn take_reads(&mut self, out: &mut Vec<(u32, SrcPos)>) {
        self.interp.take_reads(out);
    }

    /// Whether [`Vm::take_reads`] has anything to give.
    #[inline]
    pub fn has_reads(&self) -> bool {
        self.interp.has_reads()
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
        self.handlers.stop_running();
        self.handlers.clear();
    }

    /// How many events the robot performed at instant `t` (0 unless its last events were
    /// at `t`).
    pub fn events_at(&self, t: i64) -> u64 {
        self.interp.events_at(t)
    }

    /// Where the main program is, for a report of a zero-time loop: the innermost loop
    /// around its current statement (or around the call that leads there), else the
    /// statement.
    pub fn loop_position(&self) -> SrcPos {
        let pc = self.main.pc;
        self.m
            .pos_of(interp::loop_start(&self.m, pc, &self.main).unwrap_or(pc))
    }

    /// True while a motion is in progress at time `t`.
    pub fn moving_at(&self, t: i64) -> bool {
        self.arm.moving_at(t, self.state.moving_until())
    }

    /// Warnings produced so far; the SE drains them.
    pub fn take_warnings(&mut self) -> Vec<Warning> {
        std::mem::take(&mut self.warnings)
    }

    /// While the robot finishes a zoned motion after its `motion_end` (the next motion,
    /// if any, superposed on it): the time it reaches that point and the point's TCP
    /// position.
    pub fn zoned_point(&self) -> Option<(i64, [f64; 3])> {
        self.arm.zoned_point()
    }

    /// The joints at time `t` (inside or after the current motion, through a corner).
    pub fn joints_at(&self, t: i64) -> [f64; MAX_AXES] {
        self.arm.joints_at(t)
    }

    /// The TCP pose at time `t`.
    pub fn tcp_at(&self, t: i64) -> Iso {
        self.arm.tcp_at(t)
    }

    /// The TCP in the tool link's frame at `t`: the tool of the motion the robot is in
    /// (a tool change never blends: the next motion starts at the point), else the last
    /// motion's (or the workcell's, before any).
    pub fn tool_at(&self, t: i64) -> Iso {
        self.arm.tool_at(t)
    }

    /// Per axis, a bound on its speed during the current motion (rad/s or m/s; 0 when
    /// not moving): for a joint motion exact; for a Cartesian one the largest speed at the
    /// samples its axis speeds were checked at (between samples it can be somewhat higher;
    /// the collision sweep adds a margin). Through a corner, the two motions' bounds add.
    pub fn axis_rate_bounds(&self) -> [f64; MAX_AXES] {
        self.arm.axis_rate_bounds()
    }

    /// The globals (module indices) the enabled condition handlers read.
    pub fn when_globals(&self) -> impl Iterator<Item = u32> + '_ {
        self.handlers.when_globals(&self.m)
    }

    /// The period of handler `handler` (its index in the module's table) as it is enabled
    /// now, if it fires by time or by cycles (ns; `None` for a condition handler, an
    /// `after` handler, or one not enabled).
    pub fn handler_period_ns(&self, handler: u32) -> Option<i64> {
        self.handlers.period_ns(handler)
    }

    /// The enabled condition handlers: (handler procedure, the module globals the
    /// condition reads), for the SE's when list.
    pub fn condition_handlers(&self) -> impl Iterator<Item = (u32, &[u32])> + '_ {
        self.handlers.condition_handlers(&self.m)
    }

    /// The SE's `check_when` at time `t`: re-tests every condition handler; each
    /// false→true edge schedules a firing at `t`. Returns how many will fire.
    pub fn check_when(&mut self, t: i64) -> usize {
        let sight = sight!(self);
        let (interp, cfg) = (&mut self.interp, &self.cfg);
        self.handlers.check_edges(&self.m, t, |func, args| {
            interp.eval_cond(&sight, cfg, func, args, t)
        })
    }

    /// What the robot waits for, when it is blocked: for deadlock reports.
    pub fn waiting_for(&self) -> Option<(String, SrcPos)> {
        self.state.waiting_for(&self.m)
    }

    /// The signal (its name's string index) the robot is blocked waiting for, if one.
    pub fn waited_signal(&self) -> Option<u32> {
        self.state.waited_signal()
    }

    /// The deadline of the wait the robot is blocked in, if it has a timeout.
    pub fn wait_deadline(&self) -> Option<i64> {
        self.state.wait_deadline()
    }

    /// The globals (module indices) the robot's current wait condition reads.
    pub fn wait_globals(&self) -> &[u32] {
        match self.state.waiting_cond() {
            Some(c) => &self.m.conds[c as usize].globals,
            None => &[],
        }
    }

    /// The sync site this VM waits at, if it waits at a sync point.
    pub fn waiting_sync(&self) -> Option<u32> {
        self.state.waiting_sync()
    }

    /// The engine's release of a meeting at a sync point: every task of its list has
    /// arrived. Returns true if this VM waited there (its next event becomes `wait_end`
    /// at `t`).
    pub fn release_sync(&mut self, t: i64) -> bool {
        if let State::Waiting {
            sync: Some(_),
            pos,
            deadline,
            ..
        } = self.state
        {
            self.state = State::released(t, deadline, pos);
            return true;
        }
        false
    }

    /// The condition (index in the module's conditions) this VM waits on, if it waits
    /// for one.
    pub fn waiting_cond(&self) -> Option<u32> {
        self.state.waiting_cond()
    }

    /// Whether the next `next_event` would run zero-time code (the main program's or a
    /// running handler's) before it knows the event: that code reads the cell's globals,
    /// so the engine calls it only in the robot's own turn at the instant.
    pub fn needs_turn(&self) -> bool {
        matches!(self.state, State::Run) || self.handlers.needs_run()
    }

    /// Whether the VM is blocked in a `wait_until` or `wait_signal` (not released yet).
    pub fn waits(&self) -> bool {
        matches!(self.state, State::Waiting { .. })
    }

    /// The SE's `check_wait` at time `t`: re-tests the condition this VM waits on.
    /// Returns true if the VM is released (its next event becomes `wait_end` at `t`).
    /// A polled wait (`wait_until … poll p`) is released only on its grid (its start plus
    /// a whole number of periods): when the condition holds between two polls, the VM asks
    /// for a check at the next one ([`Vm::take_poll_check`]), where it is tested again.
    pub fn check_wait(&mut self, t: i64) -> bool {
        let State::Waiting {
            cond: Some(c),
            pos,
            deadline,
            poll,
            ..
        } = self.state
        else {
            return false;
        };
        if !self.eval_cond(c, t) {
            return false;
        }
        match poll {
            Some((start, period)) if (t - start) % period != 0 => {
                let next = start + ((t - start) / period + 1) * period;
                // A timeout at or before the next poll ends the wait first.
                self.waits.ask_poll(next, deadline);
                false
            }
            _ => {
                self.state = State::released(t, deadline, pos);
                true
            }
        }
    }

    /// The time of the next poll of a polled wait whose condition held between polls, once:
    /// the SE queues a `check_wait` then.
    pub fn take_poll_check(&mut self) -> Option<i64> {
        self.waits.take_poll_check()
    }

    /// Delivers a signal named `name` at time `t`: releases a matching wait, or is counted
    /// until one consumes it. Returns true if it released a wait.
    pub fn deliver_signal(&mut self, name: &str, t: i64) -> bool {
        match self.signal_index(name) {
            Some(idx) => self.deliver_signal_index(idx, t),
            None => false,
        }
    }

    /// The index under which this VM knows the signal `name` (its string index), for
    /// [`Vm::deliver_signal_index`]; `None` if its program never mentions it (a signal it
    /// can never wait for).
    pub fn signal_index(&self, name: &str) -> Option<u32> {
        self.m
            .strings
            .iter()
            .position(|s| s == name)
            .map(|i| i as u32)
    }

    /// [`Vm::deliver_signal`] with the name already looked up by [`Vm::signal_index`].
    pub fn deliver_signal_index(&mut self, idx: u32, t: i64) -> bool {
        if let State::Waiting {
            signal: Some(s),
            pos,
            deadline,
            ..
        } = self.state
            && s == idx
        {
            self.state = State::released(t, deadline, pos);
            return true;
        }
        self.waits.count_signal(idx);
        false
    }

    /// Queues a remote request to run procedure `proc` with `args` (arriving at `t`).
    /// It starts when the robot is idle, in arrival order.
    pub fn request_remote(&mut self, proc: u32, args: Vec<u64>, t: i64) {
        self.remote.push(Request {
            proc,
            args,
            time: t,
        });
    }

    /// Tells the caller that its remote request `req` ended at `t`; releases its join when
    /// it was the last of its `parallel` block.
    pub fn remote_done(&mut self, req: u64, t: i64) {
        let joining = match self.state {
            State::Joining { depth, pos } => Some((depth, pos)),
            _ => None,
        };
        if self.remote.done(req, joining.map(|(d, _)| d))
            && let Some((_, pos)) = joining
        {
            self.state = State::released(t, None, pos);
        }
    }

    /// Evaluates condition `c` at `t` with the locals it captures from the main thread's
    /// frame.
    fn eval_cond(&mut self, c: u32, t: i64) -> bool {
        let mut args = [0u64; 64];
        let n = interp::captured(&self.m, c, &self.main, &mut args);
        let func = self.m.conds[c as usize].func;
        let sight = sight!(self);
        self.interp
            .eval_cond(&sight, &self.cfg, func, &args[..n], t)
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
        if let Some(t) = self.handlers.running_since() {
            if self.handlers.state == State::Run {
                let e = self.run_segment(true, t);
                self.handlers.state = State::At(e);
            }
            if let State::At(e) = &self.handlers.state {
                self.source = Source::Handler;
                return Next::Event(e.clone());
            }
        }
        let main = self.main_event();
        let fire = self.handlers.next_fire();
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
            (_, Some((t, i))) => self.fire_event(t, i),
            (other, None) => {
                self.source = Source::None;
                other
            }
        }
    }

    /// The firing of enabled handler `i` at `t`, as the next event.
    fn fire_event(&mut self, t: i64, i: usize) -> Next {
        self.source = Source::Fire(i);
        let handler = self.handlers.handler_of(i);
        Next::Event(Event {
            robot: self.cfg.robot,
            time: t,
            kind: EventKind::WhenFire { handler },
            pos: self.m.handlers[handler as usize].pos,
        })
    }

    /// The end of the earliest pulse (the first started, on a tie), if it comes before
    /// `main` (the main program's next event) and `fire` (the next handler firing): the
    /// I/O acts first at an instant. A failed robot (`Next::Done`) ends no pulse.
    fn pulse_event(&mut self, main: &Next, fire: Option<(i64, usize)>) -> Option<Next> {
        let (p, i) = self.pulses.earliest()?;
        let t = p.end;
        if matches!(main, Next::Done)
            || fire.is_some_and(|(tf, _)| tf < t)
            || matches!(main, Next::Event(e) if e.time < t)
        {
            return None;
        }
        self.source = Source::Pulse(i);
        Some(Next::Event(Event {
            robot: self.cfg.robot,
            time: t,
            kind: EventKind::Set {
                global: p.global,
                value: 0,
                ty: self.m.globals[p.global as usize].ty,
            },
            pos: p.pos,
        }))
    }

    fn main_event(&mut self) -> Next {
        match &self.state {
            State::Done => Next::Done,
            State::At(e) => Next::Event(e.clone()),
            State::Moving { end, pos } => {
                let (zone_m, programmed_m) = self.arm.current_zone();
                Next::Event(Event {
                    robot: self.cfg.robot,
                    time: *end,
                    kind: EventKind::MotionEnd {
                        zone_m,
                        programmed_m,
                    },
                    pos: *pos,
                })
            }
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
            State::Idle => match self.remote.front() {
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
        self.interp.enter_instant(t, self.cfg.budget);
        if self.interp.events_spent(self.cfg.instant_events) {
            let th = self.thread(in_handler);
            let e = interp::zero_time_loop(
                &self.m,
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
            let sight = sight!(self);
            let thread = if in_handler {
                &mut self.handlers.thread
            } else {
                &mut self.main
            };
            let stop = self.interp.run(thread, &sight, &self.cfg, t, true);
            let pc = thread.pc;
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
            let running = self.handlers.running_since().is_some();
            let kind = match stop {
                Err(e) => return self.error_event(&e, t),
                Ok(Stop::Finished) => match (in_handler, running, self.remote.serving()) {
                    (true, true, _) => EventKind::WhenEnd {
                        handler: self.handlers.running_handler(),
                    },
                    (false, _, Some(proc)) => EventKind::RemoteEnd { proc },
                    _ => EventKind::End,
                },
                Ok(Stop::Event(Instr::ParBegin)) if !in_handler => {
                    // Not an event: the start of a join group.
                    self.remote.begin_parallel();
                    self.main.pc = pc + 1;
                    continue;
                }
                // `stop` in a handler: the handler ends first (`when_end`), then the
                // program (`end`, see `perform_handler`).
                Ok(Stop::Event(Instr::Stop)) if in_handler && running => EventKind::WhenEnd {
                    handler: self.handlers.running_handler(),
                },
                Ok(Stop::Event(ins)) => match self.describe(ins, t, in_handler) {
                    Ok(k) => k,
                    Err(message) => EventKind::Error { message },
                },
            };
            // A motion may start later, within the corner of the zoned point before it.
            let time = match (&kind, self.arm.pending_start()) {
                (EventKind::MotionStart { .. }, Some(start)) => start,
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

    /// The event instruction `ins` of the main thread (or the handler thread) stands for,
    /// reached at `t`: a motion is planned (it starts on `perform`).
    fn describe(&mut self, ins: Instr, t: i64, in_handler: bool) -> Result<EventKind, String> {
        if let Instr::MoveJ(_) | Instr::MoveL(_) | Instr::MoveC(_) = ins {
            if in_handler {
                return Err(format!(
                    "a `when` handler runs in zero time and may not take time (`{}`)",
                    ins.name()
                ));
            }
            return self.plan_motion(ins);
        }
        describe(
            describe::Context {
                m: &self.m,
                model: self.arm.model(),
                texts: &self.interp.texts,
                stack: &self.thread(in_handler).stack,
                main_stack: &self.main.stack,
                cycle_ns: self.cfg.cycle_ns,
                next_req: self.remote.next_req(),
                end_kind: self.end_kind(),
            },
            ins,
            t,
            in_handler,
        )
    }

    /// Plans motion `ins` of the main thread from the robot's state now: its
    /// `motion_start`, the motion pending until `perform` starts it; warnings of what the
    /// planner found.
    fn plan_motion(&mut self, ins: Instr) -> Result<EventKind, String> {
        let ops = MotionOperands::read(&self.main.stack, ins);
        let (p, notes) = self
            .arm
            .plan(
                &ops,
                self.time,
                self.cfg.default_zone,
                self.cfg.default_speed,
            )
            .map_err(|e| e.to_string())?;
        let (start, point_ns) = (p.start, p.point_ns);
        let kind = EventKind::MotionStart {
            command: match ins {
                Instr::MoveJ(_) => "move_j",
                Instr::MoveL(_) => "move_l",
                _ => "move_c",
            },
            duration_ns: p.end_ns,
            zone_m: p.programmed,
            blend_m: p.blend,
        };
        let pos = self.m.pos_of(self.main.pc);
        if let Some(l) = notes.longer {
            self.warnings.push(Warning {
                time: self.time,
                pos,
                kind: WarningKind::Duration,
                message: format!(
                    "the motion takes {}, longer than the {} asked: it cannot be faster {}",
                    fmt_quantity(l.lasts as f64 / NS, Dim::TIME),
                    fmt_quantity(l.want as f64 / NS, Dim::TIME),
                    l.how
                ),
            });
        }
        // (Once per statement: a loop repeats the motion every round.)
        if notes.slowed.is_some() || notes.capped.is_some() {
            let (slowed, capped) = (notes.slowed, notes.capped);
            self.warn_once(self.main.pc, self.time, WarningKind::Slowdown, |vm| {
                let mut parts = Vec::new();
                if let Some(Capped { speed: Some((asked, max)), .. }) = capped {
                    parts.push(format!(
                        "the programmed TCP speed {} is above the robot's TCP speed {} (its model's `<tcp_limits speed>` or the workcell's `tcp_speed`): the TCP moves at most that fast",
                        fmt_quantity(asked, Dim::SPEED),
                        fmt_quantity(max, Dim::SPEED),
                    ));
                }
                if let Some(Capped { accel: Some((asked, max)), .. }) = capped {
                    parts.push(format!(
                        "the programmed acceleration {} is above the robot's TCP acceleration {} (its model's `<tcp_limits acceleration>` or the workcell's `tcp_acceleration`): the TCP accelerates at most that hard",
                        fmt_quantity(asked, Dim::ACCEL),
                        fmt_quantity(max, Dim::ACCEL),
                    ));
                }
                if let Some(s) = slowed {
                    parts.push(format!(
                        "axis {} `{}` reaches its speed limit and slows the TCP below its programmed speed: the motion takes {}, {} without that limit",
                        s.axis + 1,
                        vm.arm.model().axis(s.axis).name,
                        fmt_quantity(s.lasts as f64 / NS, Dim::TIME),
                        fmt_quantity(s.would as f64 / NS, Dim::TIME),
                    ));
                }
                parts.join("; ")
            });
        }
        if let Some((point, at)) = notes.corner_failure {
            self.warn_once(self.main.pc, point, WarningKind::Corner, |vm| {
                // (With jerk limits, S-curves that ramp an axis the same way at its full jerk
                // add their jerks wherever they overlap: no zone lets them.)
                let model = vm.arm.model();
                let jerky = (0..model.dof()).any(|i| model.axis(i).max_jerk.is_some());
                let hint = if jerky {
                    "with jerk limits, two motions that ramp an axis the same way at its full jerk cannot overlap (their jerks add up): a zone helps where the axes reverse, or between motions that do not ramp at full jerk"
                } else {
                    "a larger zone, a lower speed or a jerk limit can let it fly by"
                };
                format!(
                    "this motion cannot start inside the zone of the motion at line {} of {} within the zone and the TCP's and axes' limits (or faster than stopping): the robot stops at that point first (a corner path failure); {hint}",
                    at.line,
                    vm.m.file_name_of(at)
                )
            });
        }
        if point_ns < 0 || point_ns > TIME_LIMIT_NS - start {
            return Err("the motion would end after the last instant the simulator can represent (2^62 ns, about 146 years); check its speed".into());
        }
        Ok(kind)
    }

    /// A warning about the statement at `pc`, at `time`, once per statement and kind (a
    /// loop repeats it every round); its `message` is made only the first time.
    fn warn_once(
        &mut self,
        pc: u32,
        time: i64,
        kind: WarningKind,
        message: impl FnOnce(&Self) -> String,
    ) {
        if self.warned.contains(&(pc, kind)) {
            return;
        }
        let message = message(self);
        self.warned.push((pc, kind));
        self.warnings.push(Warning {
            time,
            pos: self.m.pos_of(pc),
            kind,
            message,
        });
    }

    /// The time of the main program's event at instruction `ins` (`None`: the program's
    /// end) reached at `t`: a statement that takes time without moving, grips or releases,
    /// or ends the program makes a zoned point still ahead a stop point, so its event comes
    /// when the robot is there — with a warning, once per statement.
    fn stop_point(&mut self, ins: Option<Instr>, pc: u32, t: i64) -> i64 {
        let Some(what) = stop_point_reason(ins, self.remote.serving().is_some()) else {
            return t;
        };
        let Some((end, at)) = self.arm.zoned_point_ahead(t) else {
            return t;
        };
        // `delay 0s` says it: it waits for the robot and nothing else (RAPID's `WaitRob`).
        let zero_delay =
            ins == Some(Instr::Delay) && self.main.stack.last() == Some(&0f64.to_bits());
        if zero_delay {
            return end;
        }
        // Warned at the stop point's time, where the trace shows the statement's event.
        self.warn_once(pc, end, WarningKind::StopPoint, |vm| {
            format!(
                "{what} makes the zoned point of the motion at line {} of {} a stop point: the robot reaches it first; make that motion stop at its point to say so (`zone fine`; in RAPID, `fine`)",
                at.line,
                vm.m.file_name_of(at)
            )
        });
        end
    }

    fn thread(&self, in_handler: bool) -> &Thread {
        if in_handler {
            &self.handlers.thread
        } else {
            &self.main
        }
    }

    /// Performs the event [`Vm::next_event`] returned last.
    pub fn perform(&mut self) {
        match std::mem::replace(&mut self.source, Source::None) {
            Source::Main => self.perform_main(),
            Source::Handler => self.perform_handler(),
            Source::Fire(i) => {
                if let Some(t) = self.handlers.fire(&self.m, i) {
                    self.time = self.time.max(t);
                }
            }
            Source::Pulse(i) => {
                if let Some(p) = self.pulses.take(i) {
                    self.time = self.time.max(p.end);
                    self.set_global(p.global, 0);
                }
            }
            Source::None => return,
        }
        self.arm.forget_faded(self.time);
        self.interp.enter_instant(self.time, self.cfg.budget);
        self.interp.count_event();
    }

    /// Effects shared by the main program and handlers: set, log, enable, disable.
    fn apply_zero_time(&mut self, e: &Event, ins: Instr, in_handler: bool) {
        let th = if in_handler {
            &mut self.handlers.thread
        } else {
            &mut self.main
        };
        match &e.kind {
            EventKind::Set { global, value, .. } => {
                let top = th.stack.pop();
                self.interp.set_global(*global, *value);
                if let (Instr::PulseGlobal(g), Some(secs)) = (ins, top) {
                    // (Checked when the event was described.)
                    let secs = f64::from_bits(secs);
                    let end = e
                        .time
                        .saturating_add(span_ns(secs, e.time, "the pulse").unwrap_or(0));
                    self.pulses.start(g, end, e.pos);
                }
            }
            EventKind::Log { .. } => {
                if let Instr::Log(f) = ins {
                    let w = self.m.log_formats[f as usize].value_width() as usize;
                    let l = th.stack.len() - w;
                    th.stack.truncate(l);
                }
            }
            EventKind::EnableWhen { handler } => {
                let sight = sight!(self);
                let (interp, cfg, t) = (&mut self.interp, &self.cfg, e.time);
                let th = if in_handler {
                    &mut self.handlers.thread
                } else {
                    &mut self.main
                };
                // The handler thread is moved out while it enables (the handlers hold it).
                let mut own = std::mem::take(th);
                self.handlers.enable(
                    &self.m,
                    cfg.cycle_ns,
                    *handler,
                    &mut own,
                    t,
                    |func, args| interp.eval_cond(&sight, cfg, func, args, t),
                );
                if in_handler {
                    self.handlers.thread = own;
                } else {
                    self.main = own;
                }
            }
            EventKind::DisableWhen { proc } => self.handlers.disable(*proc),
            _ => {}
        }
    }

    /// The program or the remote work being served ended: its handlers go (a handler
    /// belongs to the activation that enabled it, and every enabled handler was enabled by
    /// the one ending: remote work starts only once the program has ended), and the robot
    /// serves remote requests.
    fn end_program(&mut self) {
        self.remote.end_serving();
        self.handlers.clear();
        self.state = State::Idle;
    }

    /// `stop` ran in a handler at `t`: whatever the main thread was doing (a motion, a
    /// wait) is abandoned, the robot holds still where it is, and the program ends (`end`)
    /// — or, in remote work, the remote work ends (`remote_end`).
    fn stop_program(&mut self, t: i64, pos: SrcPos) {
        self.arm.halt_at(t);
        self.state = State::At(Event {
            robot: self.cfg.robot,
            time: t,
            kind: self.end_kind(),
            pos,
        });
    }

    /// What `stop` ends: the remote work being served, or the program.
    fn end_kind(&self) -> EventKind {
        match self.remote.serving() {
            Some(proc) => EventKind::RemoteEnd { proc },
            None => EventKind::End,
        }
    }

    fn perform_handler(&mut self) {
        let State::At(e) = std::mem::replace(&mut self.handlers.state, State::Run) else {
            return;
        };
        let pc = self.handlers.thread.pc;
        let ins = self.m.code.get(pc as usize).copied().unwrap_or(Instr::Stop);
        match e.kind {
            EventKind::WhenEnd { .. } => {
                // The handler stopped at `stop`: the program ends after it.
                let stopping = !self.handlers.thread.frames.is_empty() && ins == Instr::Stop;
                self.handlers.end_running();
                if stopping {
                    self.stop_program(e.time, e.pos);
                }
                return;
            }
            EventKind::Error { .. } => {
                self.handlers.stop_running();
                self.state = State::Done;
                return;
            }
            EventKind::End => {
                // `stop` in a handler ends the robot's program.
                self.handlers.stop_running();
                self.end_program();
                return;
            }
            _ => {}
        }
        self.apply_zero_time(&e, ins, true);
        self.handlers.thread.pc = pc + 1;
    }

    fn perform_main(&mut self) {
        let state = std::mem::replace(&mut self.state, State::Run);
        match state {
            State::At(e) => {
                self.time = e.time;
                let pc = self.main.pc;
                let ins = self.m.code.get(pc as usize).copied().unwrap_or(Instr::Stop);
                if !self.perform_main_at(&e, ins) {
                    return;
                }
                self.main.pc = pc + 1;
            }
            State::Moving { end, pos } => {
                self.time = end;
                self.arm.end_current(pos);
            }
            State::Delaying { end, .. } => self.time = end,
            State::Waiting {
                deadline: Some(d), ..
            } => {
                self.time = d;
                self.waits.set_timed_out(true);
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
                    self.waits.set_timed_out(timed_out);
                }
            }
            other => self.state = other,
        }
    }

    /// Performs event `e` of the main thread, stopped before instruction `ins`; false if
    /// the thread does not go on past it (it ended, failed, or starts remote work).
    fn perform_main_at(&mut self, e: &Event, ins: Instr) -> bool {
        match &e.kind {
            EventKind::Error { .. } => {
                self.state = State::Done;
                return false;
            }
            EventKind::End | EventKind::RemoteEnd { .. } => {
                self.end_program();
                return false;
            }
            EventKind::MotionStart { duration_ns, .. } => {
                let width = MotionOperands::read(&self.main.stack, ins).width;
                let l = self.main.stack.len() - width;
                self.main.stack.truncate(l);
                // (Planned to start at this event's time.)
                self.arm.start_pending();
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
                self.waits.start_polling();
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
                self.state = if self.waits.consume_signal(*name) {
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
                // The engine keeps the sync point: it releases the meeting when every task
                // of the list has arrived (`release_sync`).
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
                self.remote.called(*req);
            }
            EventKind::Join => {
                self.state = match self.remote.join() {
                    Some(depth) => State::Joining { depth, pos: e.pos },
                    None => State::released(e.time, None, e.pos),
                };
            }
            EventKind::RemoteStart { proc } => {
                if let Some(r) = self.remote.serve(*proc) {
                    self.main.start(&self.m, *proc, &r.args);
                    self.state = State::Run;
                }
                return false;
            }
            _ => self.apply_zero_time(e, ins, false),
        }
        true
    }
}
