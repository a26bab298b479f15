//! Describing the next event before it is performed: its kind and details from the
//! instruction the interpreter stopped before (`describe`; a motion's are the planner's),
//! and `log` text (`format`).

use vworks_model::RobotModel;

use super::handlers::check_trigger;
use super::waits::deadline;
use super::{EventKind, span_ns};
use crate::bytecode::{Instr, LogPart, Module};
use crate::texts::Texts;
use crate::types::{Dim, Type, fmt_quantity};

/// What [`describe`] reads besides the instruction.
pub(super) struct Context<'a> {
    pub(super) m: &'a Module,
    pub(super) model: &'a RobotModel,
    /// The texts the run made, for `log` and `fail` of a text.
    pub(super) texts: &'a Texts,
    /// The stack of the thread that stopped (the main program's or a handler's), and the
    /// main program's.
    pub(super) stack: &'a [u64],
    pub(super) main_stack: &'a [u64],
    pub(super) cycle_ns: i64,
    /// The number of the next remote request.
    pub(super) next_req: u64,
    /// What `stop` ends: the remote work being served, or the program.
    pub(super) end_kind: EventKind,
}

/// The slot `depth` below the top of `stack`.
fn top(stack: &[u64], depth: usize) -> u64 {
    stack[stack.len() - 1 - depth]
}

/// The event a (non-motion) instruction stands for, reached at `t`, from the operands on
/// the stack (not popped).
pub(super) fn describe(
    cx: Context<'_>,
    ins: Instr,
    t: i64,
    in_handler: bool,
) -> Result<EventKind, String> {
    if in_handler && ins.takes_time() {
        return Err(format!(
            "a `when` handler runs in zero time and may not take time (`{}`)",
            ins.name()
        ));
    }
    Ok(match ins {
        Instr::StoreGlobal(g) => EventKind::Set {
            global: g,
            value: top(cx.stack, 0),
            ty: cx.m.globals[g as usize].ty,
        },
        Instr::PulseGlobal(g) => {
            let secs = f64::from_bits(top(cx.stack, 0));
            if secs.is_nan() || secs < 0.0 {
                return Err(format!(
                    "a pulse must last 0 s or more (got {})",
                    fmt_quantity(secs, Dim::TIME)
                ));
            }
            span_ns(secs, t, "the pulse")?;
            EventKind::Set {
                global: g,
                value: 1,
                ty: cx.m.globals[g as usize].ty,
            }
        }
        Instr::When(h) => {
            if cx.m.handlers[h as usize].trigger.has_operand() {
                check_trigger(cx.m, cx.cycle_ns, h, top(cx.stack, 0), t)?;
            }
            EventKind::EnableWhen { handler: h }
        }
        Instr::Disable(p) => EventKind::DisableWhen { proc: p },
        Instr::Remote(r) => {
            let w = cx.m.remotes[r as usize].arg_width() as usize;
            let st = cx.main_stack;
            EventKind::RemoteCall {
                site: r,
                req: cx.next_req,
                args: st[st.len() - w..].to_vec(),
            }
        }
        Instr::ParJoin => EventKind::Join,
        Instr::Delay => {
            let d = f64::from_bits(top(cx.main_stack, 0));
            if d.is_nan() || d < 0.0 {
                return Err(format!(
                    "a delay cannot be negative ({})",
                    fmt_quantity(d, Dim::TIME)
                ));
            }
            EventKind::Delay {
                duration_ns: span_ns(d, t, "the delay")?,
            }
        }
        Instr::WaitUntil(c, timeout) => EventKind::WaitUntil {
            cond: c,
            deadline: deadline(timeout.then(|| top(cx.main_stack, 0)), t)?,
            poll_ns: None,
        },
        Instr::WaitPoll(c, timeout) => {
            let p = f64::from_bits(top(cx.main_stack, 0));
            if p.is_nan() || p <= 0.0 {
                return Err(format!(
                    "the poll period must be more than 0 ({})",
                    fmt_quantity(p, Dim::TIME)
                ));
            }
            let poll = span_ns(p, t, "the poll period")?.max(1);
            EventKind::WaitUntil {
                cond: c,
                deadline: deadline(timeout.then(|| top(cx.main_stack, 1)), t)?,
                poll_ns: Some(poll),
            }
        }
        Instr::WaitSignal(s, timeout) => EventKind::WaitSignal {
            name: s,
            deadline: deadline(timeout.then(|| top(cx.main_stack, 0)), t)?,
        },
        Instr::WaitSync(s, timeout) => EventKind::WaitSync {
            site: s,
            deadline: deadline(timeout.then(|| top(cx.main_stack, 0)), t)?,
        },
        Instr::Signal(s) => EventKind::Signal { site: s },
        Instr::Grip(s) => EventKind::Grip { site: s },
        Instr::Release(s) => EventKind::Release { site: s },
        Instr::Log(f) | Instr::Fail(f) => {
            let text = format(cx.m, cx.model, cx.texts, cx.stack, f);
            if matches!(ins, Instr::Fail(_)) {
                EventKind::Error { message: text }
            } else {
                EventKind::Log { text }
            }
        }
        // `stop` in remote work ends the remote work (the caller's join goes on). (In a
        // handler `run_segment` has made it the handler's end.)
        Instr::Stop => cx.end_kind,
        other => {
            return Err(format!(
                "`{}` is not supported by this VM yet",
                other.name()
            ));
        }
    })
}

/// The text of a `log`/`fail` message whose values are on top of the stack.
/// The text of a `log`/`fail` message whose values are on top of stack `s`.
pub(super) fn format(m: &Module, model: &RobotModel, texts: &Texts, s: &[u64], f: u32) -> String {
    let fmt = &m.log_formats[f as usize];
    let width = fmt.value_width() as usize;
    let mut at = s.len() - width;
    let mut out = String::new();
    for p in &fmt.parts {
        match p {
            LogPart::Text(i) => out.push_str(m.str(*i)),
            LogPart::Value(ty) => {
                let w = ty.width() as usize;
                let v = &s[at..at + w];
                at += w;
                let num = |x: u64| f64::from_bits(x);
                match ty {
                    Type::Bool => out.push_str(if v[0] != 0 { "true" } else { "false" }),
                    Type::Int => out.push_str(&(v[0] as i64).to_string()),
                    Type::Text => out.push_str(texts.get(m, v[0]).unwrap_or("<no such text>")),
                    Type::Num(d) => out.push_str(&fmt_quantity(num(v[0]), *d)),
                    Type::Pose => {
                        let parts: Vec<String> = (0..6)
                            .map(|k| {
                                fmt_quantity(
                                    num(v[k]),
                                    if k < 3 { Dim::LENGTH } else { Dim::ANGLE },
                                )
                            })
                            .collect();
                        out.push_str(&format!("pose({})", parts.join(", ")));
                    }
                    Type::Joints => {
                        let n = model.dof();
                        let parts: Vec<String> = (0..n)
                            .map(|k| {
                                fmt_quantity(
                                    num(v[k]),
                                    if (model.linear_axes() >> k) & 1 == 1 {
                                        Dim::LENGTH
                                    } else {
                                        Dim::ANGLE
                                    },
                                )
                            })
                            .collect();
                        out.push_str(&format!("joints({})", parts.join(", ")));
                    }
                }
            }
        }
    }
    out
}
