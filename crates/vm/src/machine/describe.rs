//! Describing the next event before it is performed: its kind and details from the
//! instruction the interpreter stopped before (`describe`), and `log` text (`format`).

use super::*;

impl Vm {
    /// The event an instruction stands for, from the operands on the stack (not popped).
    pub(super) fn describe(
        &mut self,
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
                value: self.top(in_handler, 0),
                ty: self.m.globals[g as usize].ty,
            },
            Instr::PulseGlobal(g) => {
                let secs = f64::from_bits(self.top(in_handler, 0));
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
                    ty: self.m.globals[g as usize].ty,
                }
            }
            Instr::When(h) => {
                if self.m.handlers[h as usize].trigger.has_operand() {
                    self.check_trigger(h, self.top(in_handler, 0), t)?;
                }
                EventKind::EnableWhen { handler: h }
            }
            Instr::Disable(p) => EventKind::DisableWhen { proc: p },
            Instr::Remote(r) => {
                let w = self.m.remotes[r as usize].arg_width() as usize;
                let st = &self.main.stack;
                EventKind::RemoteCall {
                    site: r,
                    req: self.next_req,
                    args: st[st.len() - w..].to_vec(),
                }
            }
            Instr::ParJoin => EventKind::Join,
            Instr::MoveJ(_) | Instr::MoveL(_) | Instr::MoveC(_) => {
                let p = self.plan(ins)?;
                if p.point_ns < 0 || p.point_ns > TIME_LIMIT_NS - p.start {
                    return Err("the motion would end after the last instant the simulator can represent (2^62 ns, about 146 years); check its speed".into());
                }
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
                self.pending_motion = Some(p);
                kind
            }
            Instr::Delay => {
                let d = f64::from_bits(self.top(false, 0));
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
                deadline: self.deadline(timeout, t)?,
                poll_ns: None,
            },
            Instr::WaitPoll(c, timeout) => {
                let p = f64::from_bits(self.top(false, 0));
                if p.is_nan() || p <= 0.0 {
                    return Err(format!(
                        "the poll period must be more than 0 ({})",
                        fmt_quantity(p, Dim::TIME)
                    ));
                }
                let poll = span_ns(p, t, "the poll period")?.max(1);
                EventKind::WaitUntil {
                    cond: c,
                    deadline: self.deadline_at(timeout, t, 1)?,
                    poll_ns: Some(poll),
                }
            }
            Instr::WaitSignal(s, timeout) => EventKind::WaitSignal {
                name: s,
                deadline: self.deadline(timeout, t)?,
            },
            Instr::WaitSync(s, timeout) => EventKind::WaitSync {
                site: s,
                deadline: self.deadline(timeout, t)?,
            },
            Instr::Signal(s) => EventKind::Signal { site: s },
            Instr::Grip(s) => EventKind::Grip { site: s },
            Instr::Release(s) => EventKind::Release { site: s },
            Instr::Log(f) | Instr::Fail(f) => {
                let text = self.format(f, in_handler);
                if matches!(ins, Instr::Fail(_)) {
                    EventKind::Error { message: text }
                } else {
                    EventKind::Log { text }
                }
            }
            // `stop` in remote work ends the remote work (the caller's join goes on). (In a
            // handler `run_segment` has made it the handler's end.)
            Instr::Stop => self.end_kind(),
            other => {
                return Err(format!(
                    "`{}` is not supported by this VM yet",
                    other.name()
                ));
            }
        })
    }

    /// The text of a `log`/`fail` message whose values are on top of the stack.
    pub(super) fn format(&self, f: u32, in_handler: bool) -> String {
        let fmt = &self.m.log_formats[f as usize];
        let width = fmt.value_width() as usize;
        let s = &self.thread(in_handler).stack;
        let mut at = s.len() - width;
        let mut out = String::new();
        for p in &fmt.parts {
            match p {
                LogPart::Text(i) => out.push_str(self.m.str(*i)),
                LogPart::Value(ty) => {
                    let w = ty.width() as usize;
                    let v = &s[at..at + w];
                    at += w;
                    let num = |x: u64| f64::from_bits(x);
                    match ty {
                        Type::Bool => out.push_str(if v[0] != 0 { "true" } else { "false" }),
                        Type::Int => out.push_str(&(v[0] as i64).to_string()),
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
                            let n = self.model.dof();
                            let parts: Vec<String> = (0..n)
                                .map(|k| {
                                    fmt_quantity(
                                        num(v[k]),
                                        if (self.model.linear_axes() >> k) & 1 == 1 {
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
}
