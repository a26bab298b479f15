//! One robot's virtual machine: the paper's VM, driven by the simulation engine.
//!
//! The VM runs a stretch of independent work at once and stops *before* the next event.
//! [`Vm::next_event`] returns that event (kind, time, source position) without performing
//! it, and returns the same event until [`Vm::perform`] executes it, when the SE decides
//! it is that event's turn. Zero-time work never advances time; time passes only in
//! motions, delays and waits. The robot's joints are a pure function of time inside a
//! motion ([`Vm::joints_at`]), so the SE can sample every robot at every cycle boundary.

use vworks_model::math::Iso;

use crate::bytecode::SrcPos;
use crate::motion::NS;
use crate::types::{Dim, Type, fmt_quantity};

mod arm;
mod blend;
mod corner;
mod describe;
mod handlers;
mod interp;
mod jerks;
mod names;
mod path;
mod plan;
mod pulses;
mod quarters;
mod remote;
mod smooth;
mod state;
mod trajectory;
mod view;
mod vm;
mod waits;

pub use names::{EVENT_NAMES, WarningKind};
pub use vm::Vm;

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
