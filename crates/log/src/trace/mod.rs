//! The run's event vocabulary: one typed event for everything a run reports, from the
//! engine's queue to the log file, the report, the CLI and Python.
//!
//! - [`Kind`]: what happened (`motion_start`, `set`, `collision_start`, `warning`, …).
//! - [`TraceEvent`]: an event as the engine records it — indices into the cell and the
//!   robot's module, nothing formatted, so that recording a VM event allocates nothing.
//! - [`Event`]: the same event resolved with the cell's names ([`TraceEvent::resolve`]), or
//!   read back from a log ([`crate::mcaplog::read_log`]): names instead of indices, the typed
//!   [`Data`] and the details text of a trace line. This is what leaves the engine.
//!
//! The trace line `time_ns robot kind details file:line:col` (the golden files, `vworks
//! log events`) is rendered from these types ([`TraceEvent::line`], [`Event::line`]); no
//! consumer parses it back.

use serde::{Deserialize, Serialize};
use serde_json::{Value as Json, json};
/// Names from a workcell or a log as a terminal may print them (control characters
/// escaped as in log texts' `{:?}`): the CLI's summary and `log info` use it too.
pub use vworks_model::text::escape_controls;
use vworks_model::text::escape_controls_owned;
use vworks_vm::bytecode::{Module, SrcPos};
use vworks_vm::machine::{EVENT_NAMES, EventKind};
use vworks_vm::types::fmt_quantity;
use vworks_vm::{Dim, Type};

use crate::cell::Names;
use crate::issue::{Issue, IssueKind};
use crate::place::{Contact, LogLine, RobotMotion, file_name};

/// How a trace line writes times: integer nanoseconds (the contract's format: golden files,
/// `vworks log events`, `run --trace-ns`) or seconds for people (`run --trace`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
#[non_exhaustive]
pub enum Times {
    /// `7220474304 r1 set …`, `duration=1300000000`.
    #[default]
    Nanoseconds,
    /// `7.220474304 s r1 set …`, `duration=1.3 s`: exact, trailing zeros dropped.
    Seconds,
}

impl Times {
    /// A time (or duration) in ns written in this style.
    pub fn write(self, ns: i64) -> String {
        match self {
            Times::Nanoseconds => ns.to_string(),
            Times::Seconds => seconds(ns),
        }
    }
}

/// `ns` as exact seconds for people: `7.220474304 s`, `1.3 s`, `0 s`, `-0.5 s`.
pub fn seconds(ns: i64) -> String {
    let sign = if ns < 0 { "-" } else { "" };
    let a = ns.unsigned_abs();
    let (whole, frac) = (a / 1_000_000_000, a % 1_000_000_000);
    if frac == 0 {
        return format!("{sign}{whole} s");
    }
    let digits = format!("{frac:09}");
    format!("{sign}{whole}.{} s", digits.trim_end_matches('0'))
}

/// Where a collision started, as its trace details show it: `depth=0.4mm point=(0.5200,
/// 0.1000, 0.4000)` (the point in m).
pub fn contact_text(depth_m: f64, point_m: &[f64; 3]) -> String {
    format!(
        "depth={} point=({:.4}, {:.4}, {:.4})",
        fmt_quantity(depth_m, Dim::LENGTH),
        point_m[0],
        point_m[1],
        point_m[2]
    )
}

/// What an event is: its kind, as trace lines and the log name it ([`Kind::name`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
#[non_exhaustive]
pub enum Kind {
    /// A motion begins.
    MotionStart,
    /// A motion reached its target.
    MotionEnd,
    /// A `delay` begins.
    Delay,
    /// A `delay` is over.
    DelayEnd,
    /// A global is assigned.
    Set,
    /// A `wait_until` begins (a condition or a signal).
    WaitUntil,
    /// A wait is over (released or timed out).
    WaitEnd,
    /// A signal is sent.
    Signal,
    /// A part is gripped.
    Grip,
    /// A part is released.
    Release,
    /// A `log` statement.
    Log,
    /// A runtime error, `fail`, or an error the engine finds (deadlock, livelock).
    Error,
    /// A `when` handler is enabled.
    EnableWhen,
    /// Handlers are disabled.
    DisableWhen,
    /// A handler fires.
    WhenFire,
    /// A handler finished.
    WhenEnd,
    /// A remote request is made.
    RemoteCall,
    /// The robot waits for its `parallel` block's remote work.
    Join,
    /// The robot starts serving a remote request.
    RemoteStart,
    /// The robot finished serving a remote request.
    RemoteEnd,
    /// The robot's program ended.
    End,
    /// The engine re-tests a robot's wait condition after a set.
    CheckWait,
    /// The engine re-tests a robot's condition handlers after a set.
    CheckWhen,
    /// Two bodies started touching.
    CollisionStart,
    /// Two bodies stopped touching.
    CollisionEnd,
    /// A warning of the run (race, near miss, slowdown, …).
    Warning,
}

impl Kind {
    /// Every kind, in declaration order.
    pub const ALL: [Kind; 26] = [
        Kind::MotionStart,
        Kind::MotionEnd,
        Kind::Delay,
        Kind::DelayEnd,
        Kind::Set,
        Kind::WaitUntil,
        Kind::WaitEnd,
        Kind::Signal,
        Kind::Grip,
        Kind::Release,
        Kind::Log,
        Kind::Error,
        Kind::EnableWhen,
        Kind::DisableWhen,
        Kind::WhenFire,
        Kind::WhenEnd,
        Kind::RemoteCall,
        Kind::Join,
        Kind::RemoteStart,
        Kind::RemoteEnd,
        Kind::End,
        Kind::CheckWait,
        Kind::CheckWhen,
        Kind::CollisionStart,
        Kind::CollisionEnd,
        Kind::Warning,
    ];

    /// The names of the kinds the engine adds to the VM's (`check_wait` … `warning`), in
    /// declaration order after the VM's.
    const ENGINE_NAMES: [&'static str; 5] = [
        "check_wait",
        "check_when",
        "collision_start",
        "collision_end",
        "warning",
    ];

    /// The kind's name in trace lines and logs: the VM's kinds are named by the VM's table
    /// ([`EVENT_NAMES`], in the same order), the engine's own after them.
    pub fn name(self) -> &'static str {
        let i = self as usize;
        match EVENT_NAMES.get(i) {
            Some(name) => name,
            None => Self::ENGINE_NAMES[i - EVENT_NAMES.len()],
        }
    }

    /// The kind named `name` ([`Kind::name`]), if there is one.
    pub fn from_name(name: &str) -> Option<Kind> {
        Kind::ALL.into_iter().find(|k| k.name() == name)
    }

    /// The kind of a VM event (the VM's kinds come first, in the order of its table).
    #[inline]
    pub fn of(kind: &EventKind) -> Kind {
        Kind::ALL[kind.index()]
    }
}

impl std::fmt::Display for Kind {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

/// The value of a global. Its JSON (derived) is the bare value: `true`, `3`, `0.25`
/// (`null` if not finite, which a global never is).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(untagged)]
#[non_exhaustive]
pub enum Value {
    /// A `bool` global.
    Bool(bool),
    /// An `int` global.
    Int(i64),
    /// A `num` global, in SI units (m, rad, s, …).
    Num(f64),
}

impl Value {
    /// A global's value from its slot bits and type (globals are scalars).
    pub fn of(bits: u64, ty: Type) -> Value {
        match ty {
            Type::Bool => Value::Bool(bits != 0),
            Type::Int => Value::Int(bits as i64),
            _ => Value::Num(f64::from_bits(bits)),
        }
    }

    /// As JSON: `true`/`false`, an integer, or a number in SI units (`null` if not finite,
    /// which a global never is).
    pub fn to_json(self) -> Json {
        serde_json::to_value(self).unwrap_or(Json::Null)
    }

    /// From JSON as [`Value::to_json`] writes it (an integer is an `Int`, any other
    /// number a `Num`).
    pub fn from_json(v: &Json) -> Option<Value> {
        Value::deserialize(v).ok()
    }
}

/// A global's value as trace lines and `run` print it: numbers in display units
/// (`250mm`, `90deg`, `2s`).
pub fn format_value(bits: u64, ty: Type) -> String {
    match ty {
        Type::Bool => (bits != 0).to_string(),
        Type::Int => (bits as i64).to_string(),
        Type::Num(d) => fmt_quantity(f64::from_bits(bits), d),
        _ => format!("{bits:#x}"),
    }
}

/// One event as the engine records it. Recording one allocates nothing for a VM event:
/// its details are kept as indices ([`Detail`]) and resolved with the cell's names on
/// demand ([`TraceEvent::resolve`], [`TraceEvent::line`]).
#[derive(Clone, Debug, PartialEq)]
pub struct TraceEvent {
    /// Time (ns).
    pub time: i64,
    /// Robot index, if the event belongs to one.
    pub robot: Option<usize>,
    /// What happened.
    pub kind: Kind,
    /// What the event says beyond its kind.
    pub detail: Detail,
    /// Source position in the robot's program (see [`TraceEvent::file`]).
    pub pos: Option<SrcPos>,
}

/// The details of a recorded event: indices into the cell and the robot's module.
#[derive(Clone, Debug, PartialEq)]
#[non_exhaustive]
pub enum Detail {
    /// No details.
    None,
    /// An event of the robot's VM (module indices).
    Vm(EventKind),
    /// A set of cell global `global`: its value bits before and after (its type is the
    /// cell global's).
    Set {
        /// Cell global index.
        global: u32,
        /// The value before.
        old: u64,
        /// The value set.
        new: u64,
    },
    /// `check_wait` / `check_when`: the cell global whose change caused it.
    Global(u32),
    /// A collision started.
    Collision(Box<Contact>),
    /// A collision ended: the two bodies.
    CollisionEnd(Box<(String, String)>),
    /// A warning or an error the engine found.
    Issue(Box<Issue>),
}

/// An event's typed details, with names: what `/events` carries in its `data` field and
/// what programs should read instead of the details text.
#[derive(Clone, Debug, PartialEq)]
#[non_exhaustive]
pub enum Data {
    /// No details (`motion_end`, `delay_end`, `join`, `end`), or a log written before
    /// events carried typed details.
    None,
    /// `motion_start`: the command (`move_j`, `move_l`, `move_c`), the exact time to its
    /// `motion_end`, its zone and how it blends out of the previous zoned point.
    Motion {
        /// `move_j`, `move_l` or `move_c`.
        command: String,
        /// Time to its `motion_end` (ns).
        duration_ns: i64,
        /// Its zone radius as programmed (m); `None`: `fine`.
        zone_m: Option<f64>,
        /// It starts inside the corner of the previous zoned point and stays within this
        /// radius of it (m; 0: the corner could not overlap within the limits, so the
        /// robot reached the point first).
        blend_m: Option<f64>,
    },
    /// `motion_end` of a zoned motion: the TCP entered the zone, of this radius (the
    /// programmed one, reduced to at most half the motion); the robot moves on.
    MotionEnd {
        /// The radius used (m).
        zone_m: f64,
        /// The radius programmed (m).
        programmed_m: f64,
    },
    /// `delay`: its duration.
    Delay {
        /// Duration (ns).
        duration_ns: i64,
    },
    /// `set`: the global, its value before and the value set.
    Set {
        /// The global's name.
        global: String,
        /// The value before.
        old: Value,
        /// The value set.
        new: Value,
    },
    /// `wait_until` on a condition: the globals it reads, and the deadline if any.
    WaitCondition {
        /// The globals the condition reads.
        globals: Vec<String>,
        /// Absolute deadline (ns), with a timeout.
        deadline_ns: Option<i64>,
    },
    /// `wait_until` on a signal: its name, and the deadline if any.
    WaitSignal {
        /// The signal's name.
        signal: String,
        /// Absolute deadline (ns), with a timeout.
        deadline_ns: Option<i64>,
    },
    /// `wait_until` at a sync point: its name, the tasks that meet there, and the
    /// deadline if any.
    WaitSync {
        /// The sync point's name.
        sync: String,
        /// The tasks of its list, as the program names them.
        tasks: Vec<String>,
        /// Absolute deadline (ns), with a timeout.
        deadline_ns: Option<i64>,
    },
    /// `wait_end`: whether the wait timed out.
    WaitEnd {
        /// It ended by timeout.
        timed_out: bool,
    },
    /// `signal`: the receiving robot and the signal's name.
    Signal {
        /// The receiver.
        robot: String,
        /// The signal.
        signal: String,
    },
    /// `grip` / `release`: the part.
    Part {
        /// The part's name.
        part: String,
    },
    /// `log`: the text.
    Text {
        /// The text logged.
        text: String,
    },
    /// `enable_when`, `disable_when`, `when_fire`, `when_end`, `remote_start`,
    /// `remote_end`: the procedure.
    Procedure {
        /// The procedure's name.
        procedure: String,
    },
    /// `remote_call`: the robot asked and the procedure.
    Remote {
        /// The robot that serves the request.
        robot: String,
        /// The procedure.
        procedure: String,
    },
    /// `check_wait` / `check_when`: the global whose set caused it.
    Global {
        /// The global's name.
        global: String,
    },
    /// `collision_start` / `collision_end`: the two bodies; for a start, the depth and a
    /// contact point.
    Collision {
        /// First body (`r1.link_4`, `table`, `part1`).
        a: String,
        /// Second body.
        b: String,
        /// For a start: penetration depth (m) and a contact point in the cell (m).
        contact: Option<(f64, [f64; 3])>,
        /// For a start: each robot whose body is in the pair, and the motion it was making.
        motions: Vec<RobotMotion>,
    },
    /// `warning` / `error`: its kind (`race`, `near_miss`, `runtime`, `deadlock`, a
    /// compiler code), message, and for a near miss the distance (m).
    Issue {
        /// What kind of warning or error.
        kind: IssueKind,
        /// The message.
        message: String,
        /// For a near miss, how close the bodies came (m).
        distance_m: Option<f64>,
        /// For a near miss, each robot whose body is in the pair, and its motion.
        motions: Vec<RobotMotion>,
    },
}

/// An event with the cell's names: what a run hands out and a log holds.
#[derive(Clone, Debug, PartialEq)]
pub struct Event {
    /// Simulated time (ns).
    pub time_ns: i64,
    /// The robot, if the event belongs to one.
    pub robot: Option<String>,
    /// What happened.
    pub kind: Kind,
    /// The details as the trace line shows them (may be empty).
    pub details: String,
    /// The details, typed.
    pub data: Data,
    /// The WSL source file, if known.
    pub file: Option<String>,
    /// Line (0 if unknown).
    pub line: u32,
    /// Column (0 if unknown).
    pub col: u32,
}

impl Event {
    /// `file:line:col` with the file's name only, if the event has a source position.
    pub fn position(&self) -> Option<String> {
        let f = self.file.as_ref()?;
        Some(format!("{}:{}:{}", file_name(f), self.line, self.col))
    }

    /// The trace line `time_ns robot kind details file:line:col`, `-` for an empty field
    /// and the file's name only: the golden traces' format. Control characters (in a name
    /// from the log) are escaped as in log texts.
    pub fn line(&self) -> String {
        self.line_as(Times::Nanoseconds)
    }

    /// The trace line with times written as `times` says.
    pub fn line_as(&self, times: Times) -> String {
        let details = self.details_as(times);
        let details = if details.is_empty() { "-" } else { &details };
        let pos = self.position().unwrap_or_else(|| "-".into());
        escape_controls_owned(format!(
            "{} {} {} {details} {pos}",
            times.write(self.time_ns),
            self.robot.as_deref().unwrap_or("-"),
            self.kind
        ))
    }

    /// The details text with durations and deadlines written as `times` says (a set's
    /// value stays in display units, as recorded).
    pub fn details_as(&self, times: Times) -> String {
        match (&self.data, times) {
            (
                Data::Motion { .. }
                | Data::Delay { .. }
                | Data::WaitCondition { .. }
                | Data::WaitSignal { .. }
                | Data::WaitSync { .. },
                Times::Seconds,
            ) => self.data.text_as(times),
            _ => self.details.clone(),
        }
    }

    /// The event as the JSON object of the log's `/events` topic (schema in
    /// `docs/log.md`). By hand, as [`Event::from_json`] is: `data` is [`Data::to_json`],
    /// whose form the kind decides.
    pub fn to_json(&self) -> Json {
        json!({
            "time_ns": self.time_ns,
            "robot": self.robot,
            "kind": self.kind.name(),
            "details": self.details,
            "file": self.file,
            "line": self.line,
            "col": self.col,
            "data": self.data.to_json(),
        })
    }

    /// An event from the JSON object [`Event::to_json`] writes. An object without
    /// `data` (a log of vworks before log version 2) gives [`Data::None`]. By hand: a
    /// derived reader would refuse what this one reads leniently (absent fields of old
    /// logs as defaults, a line past `u32` as `u32::MAX`).
    pub fn from_json(v: &Json) -> Result<Event, String> {
        let text = |k: &str| v[k].as_str().map(str::to_string);
        let int = |k: &str| u32::try_from(v[k].as_u64().unwrap_or(0)).unwrap_or(u32::MAX);
        let name = v["kind"].as_str().unwrap_or("");
        let kind = Kind::from_name(name)
            .ok_or_else(|| format!("an event has the unknown kind `{name}`"))?;
        let data = match v.get("data") {
            None | Some(Json::Null) => Data::None,
            Some(d) => Data::from_json(kind, d)
                .ok_or_else(|| format!("a `{name}` event's data does not fit its kind: {d}"))?,
        };
        Ok(Event {
            time_ns: v["time_ns"].as_i64().unwrap_or(0),
            robot: text("robot"),
            kind,
            details: text("details").unwrap_or_default(),
            data,
            file: text("file"),
            line: int("line"),
            col: int("col"),
        })
    }
}

impl Data {
    /// The details as a trace line shows them (empty for [`Data::None`]). A set's value is
    /// written in SI units here; [`TraceEvent::details`] writes it in display units.
    pub fn text(&self) -> String {
        self.text_as(Times::Nanoseconds)
    }

    /// [`Data::text`] with durations and deadlines written as `times` says.
    pub fn text_as(&self, times: Times) -> String {
        let deadline =
            |d: &Option<i64>| d.map_or(String::new(), |d| format!(" deadline={}", times.write(d)));
        match self {
            Data::None => String::new(),
            Data::Motion {
                command,
                duration_ns,
                zone_m,
                blend_m,
            } => {
                let mut s = format!("{command} duration={}", times.write(*duration_ns));
                if let Some(z) = zone_m {
                    s += &format!(" zone={}", fmt_quantity(*z, Dim::LENGTH));
                }
                if let Some(b) = blend_m {
                    s += &format!(" blend={}", fmt_quantity(*b, Dim::LENGTH));
                }
                s
            }
            Data::MotionEnd {
                zone_m,
                programmed_m,
            } => {
                if zone_m < programmed_m {
                    format!(
                        "zone={} (reduced from {}: at most half the motion)",
                        fmt_quantity(*zone_m, Dim::LENGTH),
                        fmt_quantity(*programmed_m, Dim::LENGTH)
                    )
                } else {
                    format!("zone={}", fmt_quantity(*zone_m, Dim::LENGTH))
                }
            }
            Data::Delay { duration_ns } => format!("duration={}", times.write(*duration_ns)),
            Data::Set { global, new, .. } => match new {
                Value::Bool(b) => format!("{global}={b}"),
                Value::Int(i) => format!("{global}={i}"),
                Value::Num(x) => format!("{global}={x}"),
            },
            Data::WaitCondition {
                globals,
                deadline_ns,
            } => format!("condition({}){}", globals.join(","), deadline(deadline_ns)),
            Data::WaitSignal {
                signal,
                deadline_ns,
            } => format!("signal={signal}{}", deadline(deadline_ns)),
            Data::WaitSync {
                sync,
                tasks,
                deadline_ns,
            } => format!("sync={sync}({}){}", tasks.join(","), deadline(deadline_ns)),
            Data::WaitEnd { timed_out } => (if *timed_out { "timeout" } else { "released" }).into(),
            Data::Signal { robot, signal } => format!("{robot}.{signal}"),
            Data::Remote { robot, procedure } => format!("{robot}.{procedure}"),
            Data::Part { part } => part.clone(),
            Data::Procedure { procedure } => procedure.clone(),
            Data::Global { global } => global.clone(),
            Data::Text { text } => format!("{text:?}"),
            Data::Issue {
                message, motions, ..
            } => format!("{message:?}{}", RobotMotion::trace_suffix(motions)),
            Data::Collision {
                a,
                b,
                contact,
                motions,
            } => match contact {
                Some((depth, p)) => format!(
                    "{a} {b} {}{}",
                    contact_text(*depth, p),
                    RobotMotion::trace_suffix(motions)
                ),
                None => format!("{a} {b}"),
            },
        }
    }

    /// The `data` object of a `/events` message (`null` for [`Data::None`]).
    ///
    /// Written by hand, not derived: the object carries no tag (the event's `kind`, outside
    /// it, says which variant it is, and a `wait_until`'s fields say which wait), a
    /// collision's contact is two fields (`depth_m`, `point_m`) only for a start, and the
    /// motions are left out when there are none. Serde's enum representations give other
    /// bytes.
    pub fn to_json(&self) -> Json {
        match self {
            Data::None => Json::Null,
            Data::Motion {
                command,
                duration_ns,
                zone_m,
                blend_m,
            } => {
                let mut o = json!({"command": command, "duration_ns": duration_ns});
                if let Some(z) = zone_m {
                    o["zone_m"] = json!(z);
                }
                if let Some(b) = blend_m {
                    o["blend_m"] = json!(b);
                }
                o
            }
            Data::MotionEnd {
                zone_m,
                programmed_m,
            } => json!({"zone_m": zone_m, "programmed_m": programmed_m}),
            Data::Delay { duration_ns } => json!({"duration_ns": duration_ns}),
            Data::Set { global, old, new } => {
                json!({"global": global, "old": old.to_json(), "new": new.to_json()})
            }
            Data::WaitCondition {
                globals,
                deadline_ns,
            } => json!({"globals": globals, "deadline_ns": deadline_ns}),
            Data::WaitSignal {
                signal,
                deadline_ns,
            } => json!({"signal": signal, "deadline_ns": deadline_ns}),
            Data::WaitSync {
                sync,
                tasks,
                deadline_ns,
            } => json!({"sync": sync, "tasks": tasks, "deadline_ns": deadline_ns}),
            Data::WaitEnd { timed_out } => json!({"timed_out": timed_out}),
            Data::Signal { robot, signal } => json!({"robot": robot, "signal": signal}),
            Data::Part { part } => json!({"part": part}),
            Data::Text { text } => json!({"text": text}),
            Data::Procedure { procedure } => json!({"procedure": procedure}),
            Data::Remote { robot, procedure } => json!({"robot": robot, "procedure": procedure}),
            Data::Global { global } => json!({"global": global}),
            Data::Collision {
                a,
                b,
                contact,
                motions,
            } => {
                let mut o = match contact {
                    Some((depth, point)) => {
                        json!({"a": a, "b": b, "depth_m": depth, "point_m": point})
                    }
                    None => json!({"a": a, "b": b}),
                };
                RobotMotion::put_list(&mut o, motions);
                o
            }
            Data::Issue {
                kind,
                message,
                distance_m,
                motions,
            } => {
                let mut o =
                    json!({"kind": kind.name(), "message": message, "distance_m": distance_m});
                RobotMotion::put_list(&mut o, motions);
                o
            }
        }
    }

    /// The data of a `kind` event from its `data` object; `None` if it does not fit.
    /// By hand for the reasons of [`Data::to_json`]: the variant comes from `kind`.
    pub fn from_json(kind: Kind, d: &Json) -> Option<Data> {
        let s = |k: &str| d.get(k)?.as_str().map(str::to_string);
        let i = |k: &str| d.get(k)?.as_i64();
        let opt_i = |k: &str| match d.get(k) {
            None | Some(Json::Null) => Some(None),
            Some(v) => v.as_i64().map(Some),
        };
        let f = |k: &str| d.get(k)?.as_f64();
        Some(match kind {
            Kind::MotionStart => Data::Motion {
                command: s("command")?,
                duration_ns: i("duration_ns")?,
                zone_m: f("zone_m"),
                blend_m: f("blend_m"),
            },
            Kind::MotionEnd if d.is_object() => Data::MotionEnd {
                zone_m: f("zone_m")?,
                programmed_m: f("programmed_m")?,
            },
            Kind::Delay => Data::Delay {
                duration_ns: i("duration_ns")?,
            },
            Kind::Set => Data::Set {
                global: s("global")?,
                old: Value::from_json(d.get("old")?)?,
                new: Value::from_json(d.get("new")?)?,
            },
            Kind::WaitUntil if d.get("sync").is_some() => Data::WaitSync {
                sync: s("sync")?,
                tasks: d
                    .get("tasks")?
                    .as_array()?
                    .iter()
                    .map(|t| t.as_str().map(str::to_string))
                    .collect::<Option<Vec<String>>>()?,
                deadline_ns: opt_i("deadline_ns")?,
            },
            Kind::WaitUntil if d.get("signal").is_some() => Data::WaitSignal {
                signal: s("signal")?,
                deadline_ns: opt_i("deadline_ns")?,
            },
            Kind::WaitUntil => Data::WaitCondition {
                globals: d
                    .get("globals")?
                    .as_array()?
                    .iter()
                    .map(|g| g.as_str().map(str::to_string))
                    .collect::<Option<_>>()?,
                deadline_ns: opt_i("deadline_ns")?,
            },
            Kind::WaitEnd => Data::WaitEnd {
                timed_out: d.get("timed_out")?.as_bool()?,
            },
            Kind::Signal => Data::Signal {
                robot: s("robot")?,
                signal: s("signal")?,
            },
            Kind::Grip | Kind::Release => Data::Part { part: s("part")? },
            Kind::Log => Data::Text { text: s("text")? },
            Kind::EnableWhen
            | Kind::DisableWhen
            | Kind::WhenFire
            | Kind::WhenEnd
            | Kind::RemoteStart
            | Kind::RemoteEnd => Data::Procedure {
                procedure: s("procedure")?,
            },
            Kind::RemoteCall => Data::Remote {
                robot: s("robot")?,
                procedure: s("procedure")?,
            },
            Kind::CheckWait | Kind::CheckWhen => Data::Global {
                global: s("global")?,
            },
            Kind::CollisionStart | Kind::CollisionEnd => Data::Collision {
                a: s("a")?,
                b: s("b")?,
                contact: match (f("depth_m"), d.get("point_m")) {
                    (Some(depth), Some(p)) => {
                        let p = p.as_array()?;
                        let c = |k: usize| p.get(k)?.as_f64();
                        Some((depth, [c(0)?, c(1)?, c(2)?]))
                    }
                    _ => None,
                },
                motions: RobotMotion::list_from_json(d.get("motions"))?,
            },
            Kind::Warning | Kind::Error => Data::Issue {
                kind: IssueKind::from_name(d.get("kind")?.as_str()?)?,
                message: s("message")?,
                distance_m: f("distance_m"),
                motions: RobotMotion::list_from_json(d.get("motions"))?,
            },
            Kind::MotionEnd | Kind::DelayEnd | Kind::Join | Kind::End => Data::None,
        })
    }
}

impl TraceEvent {
    /// The program file the source position refers to (the robot's program file that
    /// holds it).
    pub fn file<'c>(&self, names: &'c dyn Names) -> Option<&'c str> {
        let pos = self.pos?;
        self.robot
            .and_then(|r| names.module(r))
            .map(|m| m.file_of(pos))
    }

    /// The line logged, if this is a `log` event of a robot's program.
    pub fn log_line(&self, names: &dyn Names) -> Option<LogLine> {
        let Detail::Vm(EventKind::Log { text }) = &self.detail else {
            return None;
        };
        let robot = names.robot_name(self.robot?)?;
        Some(LogLine {
            time_ns: self.time,
            robot: robot.to_string(),
            text: text.clone(),
            file: self.file(names).map(str::to_string),
            line: self.pos.map_or(0, |p| p.line),
            col: self.pos.map_or(0, |p| p.col),
        })
    }

    /// The details as trace lines show them (empty when there are none).
    pub fn details(&self, names: &dyn Names) -> String {
        self.details_of(names, &self.data(names), Times::Nanoseconds)
    }

    /// The details text from the event's typed `data`: the text of [`Data`] with times as
    /// `times` says, except that a set's value is shown in display units (`250mm`), which
    /// needs the global's type.
    fn details_of(&self, names: &dyn Names, data: &Data, times: Times) -> String {
        match (&self.detail, data) {
            (Detail::Set { global, new, .. }, Data::Set { global: name, .. }) => {
                match names.global(*global as usize) {
                    Some((_, ty)) => format!("{name}={}", format_value(*new, ty)),
                    None => data.text_as(times),
                }
            }
            _ => data.text_as(times),
        }
    }

    /// The typed details with the cell's names.
    pub fn data(&self, names: &dyn Names) -> Data {
        let module = self.robot.and_then(|r| names.module(r));
        match (&self.detail, module) {
            (Detail::None, _) => Data::None,
            (Detail::Vm(kind), Some(m)) => vm_data(kind, m),
            (Detail::Vm(_), None) => Data::None,
            (Detail::Set { global, old, new }, _) => match names.global(*global as usize) {
                Some((name, ty)) => Data::Set {
                    global: name.to_string(),
                    old: Value::of(*old, ty),
                    new: Value::of(*new, ty),
                },
                None => Data::None,
            },
            (Detail::Global(g), _) => {
                names
                    .global(*g as usize)
                    .map_or(Data::None, |(name, _)| Data::Global {
                        global: name.to_string(),
                    })
            }
            (Detail::Collision(c), _) => Data::Collision {
                a: c.a.clone(),
                b: c.b.clone(),
                contact: Some((c.depth, c.point)),
                motions: c.motions.clone(),
            },
            (Detail::CollisionEnd(pair), _) => Data::Collision {
                a: pair.0.clone(),
                b: pair.1.clone(),
                contact: None,
                motions: Vec::new(),
            },
            (Detail::Issue(issue), _) => Data::Issue {
                kind: issue.kind.clone(),
                message: issue.message.clone(),
                distance_m: issue.distance_m,
                motions: issue.motions.clone(),
            },
        }
    }

    /// The event with the cell's names.
    pub fn resolve(&self, names: &dyn Names) -> Event {
        let (line, col) = self.pos.map_or((0, 0), |p| (p.line, p.col));
        let data = self.data(names);
        Event {
            time_ns: self.time,
            robot: self
                .robot
                .and_then(|r| names.robot_name(r))
                .map(str::to_string),
            kind: self.kind,
            details: self.details_of(names, &data, Times::Nanoseconds),
            data,
            file: self.file(names).map(str::to_string),
            line,
            col,
        }
    }

    /// The trace line: `time_ns robot kind details file:line:col`, `-` for empty fields;
    /// control characters (in the workcell's names) escaped as in log texts.
    pub fn line(&self, names: &dyn Names) -> String {
        self.line_as(names, Times::Nanoseconds)
    }

    /// The trace line with times written as `times` says (`run --trace` shows seconds).
    pub fn line_as(&self, names: &dyn Names, times: Times) -> String {
        let robot = self.robot.and_then(|r| names.robot_name(r)).unwrap_or("-");
        let mut details = self.details_of(names, &self.data(names), times);
        if details.is_empty() {
            details.push('-');
        }
        let pos = match (self.file(names), self.pos) {
            (Some(f), Some(p)) => format!("{}:{}:{}", file_name(f), p.line, p.col),
            _ => "-".to_string(),
        };
        escape_controls_owned(format!(
            "{} {robot} {} {details} {pos}",
            times.write(self.time),
            self.kind
        ))
    }
}

/// The names a module's conditions read.
fn cond_globals(m: &Module, cond: u32) -> Vec<String> {
    m.conds[cond as usize]
        .globals
        .iter()
        .map(|g| m.str(m.globals[*g as usize].name).to_string())
        .collect()
}

/// A VM event's typed details, with the names of module `m`.
fn vm_data(kind: &EventKind, m: &Module) -> Data {
    let procedure = |p: u32| Data::Procedure {
        procedure: m.str(m.procs[p as usize].name).to_string(),
    };
    let handler = |h: u32| procedure(m.handlers[h as usize].target);
    match kind {
        EventKind::MotionStart {
            command,
            duration_ns,
            zone_m,
            blend_m,
        } => Data::Motion {
            command: (*command).to_string(),
            duration_ns: *duration_ns,
            zone_m: *zone_m,
            blend_m: *blend_m,
        },
        EventKind::MotionEnd {
            zone_m: Some(zone_m),
            programmed_m,
        } => Data::MotionEnd {
            zone_m: *zone_m,
            programmed_m: programmed_m.unwrap_or(*zone_m),
        },
        EventKind::Delay { duration_ns } => Data::Delay {
            duration_ns: *duration_ns,
        },
        // The engine records a set as `Detail::Set` (the cell's global and the value it
        // replaces), never as a VM event.
        EventKind::Set { .. } => Data::None,
        EventKind::WaitUntil { cond, deadline, .. } => Data::WaitCondition {
            globals: cond_globals(m, *cond),
            deadline_ns: *deadline,
        },
        EventKind::WaitSignal { name, deadline } => Data::WaitSignal {
            signal: m.str(*name).to_string(),
            deadline_ns: *deadline,
        },
        EventKind::WaitSync { site, deadline } => {
            let y = &m.syncs[*site as usize];
            Data::WaitSync {
                sync: m.str(y.name).to_string(),
                tasks: y.tasks.iter().map(|t| m.str(*t).to_string()).collect(),
                deadline_ns: *deadline,
            }
        }
        EventKind::WaitEnd { timed_out } => Data::WaitEnd {
            timed_out: *timed_out,
        },
        EventKind::Signal { site } => {
            let s = &m.signals_sent[*site as usize];
            Data::Signal {
                robot: m.str(s.robot).to_string(),
                signal: m.str(s.name).to_string(),
            }
        }
        EventKind::Grip { site } | EventKind::Release { site } => Data::Part {
            part: m.str(m.parts[*site as usize].part).to_string(),
        },
        EventKind::Log { text } => Data::Text { text: text.clone() },
        EventKind::Error { message } => Data::Issue {
            kind: IssueKind::Runtime,
            message: message.clone(),
            distance_m: None,
            motions: Vec::new(),
        },
        EventKind::EnableWhen { handler: h }
        | EventKind::WhenFire { handler: h }
        | EventKind::WhenEnd { handler: h } => handler(*h),
        EventKind::DisableWhen { proc } => procedure(*proc),
        EventKind::RemoteCall { site, .. } => {
            let s = &m.remotes[*site as usize];
            Data::Remote {
                robot: m.str(s.robot).to_string(),
                procedure: m.str(s.proc).to_string(),
            }
        }
        EventKind::RemoteStart { proc } | EventKind::RemoteEnd { proc } => procedure(*proc),
        EventKind::MotionEnd { .. } | EventKind::DelayEnd | EventKind::Join | EventKind::End => {
            Data::None
        }
    }
}

#[cfg(test)]
mod tests;
