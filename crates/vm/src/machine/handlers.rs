//! `when` handlers: enabling (with their triggers checked), firing by cycles, time or a
//! condition's rising edge, running a handler's zero-time body, disabling, and ending them
//! with the activation that enabled them.

use super::*;

impl Vm {
    /// The globals (module indices) the enabled condition handlers read.
    pub fn when_globals(&self) -> impl Iterator<Item = u32> + '_ {
        self.enabled
            .iter()
            .filter_map(|e| match self.m.handlers[e.handler as usize].trigger {
                crate::bytecode::Trigger::Condition(c) => Some(&self.m.conds[c as usize].globals),
                _ => None,
            })
            .flatten()
            .copied()
    }

    /// The period of handler `handler` (its index in the module's table) as it is enabled
    /// now, if it fires by time or by cycles (ns; `None` for a condition handler, an
    /// `after` handler, or one not enabled).
    pub fn handler_period_ns(&self, handler: u32) -> Option<i64> {
        self.enabled
            .iter()
            .filter(|e| e.handler == handler)
            .find_map(|e| match e.firing {
                Firing::Timer { period, .. } => period,
                Firing::Edge { .. } => None,
            })
    }

    pub(super) fn fire_event(&mut self, t: i64, i: usize) -> Next {
        self.source = Source::Fire(i);
        let h = &self.m.handlers[self.enabled[i].handler as usize];
        Next::Event(Event {
            robot: self.cfg.robot,
            time: t,
            kind: EventKind::WhenFire {
                handler: self.enabled[i].handler,
            },
            pos: h.pos,
        })
    }

    /// The earliest handler firing: (time, enabled index).
    pub(super) fn next_fire(&self) -> Option<(i64, usize)> {
        let timers = self
            .enabled
            .iter()
            .enumerate()
            .filter_map(|(i, e)| match e.firing {
                Firing::Timer { next, .. } if next <= TIME_LIMIT_NS => Some((next, i)),
                _ => None,
            });
        timers.chain(self.fires.iter().copied()).min()
    }

    /// Checks the operand of a `when` trigger before the handler is enabled at `t`: a
    /// period of at least 1 ns (`every T`), a count of at least 1 (`every N cycles`), a
    /// delay that is not negative (`after T`), all ending within the time limit.
    pub(super) fn check_trigger(&self, h: u32, operand: u64, t: i64) -> Result<(), String> {
        use crate::bytecode::Trigger;
        match self.m.handlers[h as usize].trigger {
            Trigger::EveryCycles => {
                let n = operand as i64;
                if n < 1 {
                    return Err(format!(
                        "`every {n} cycles` needs a count of at least 1; a handler every 0 or fewer cycles could never fire"
                    ));
                }
                let c = self.cfg.cycle_ns.max(1);
                if n > TIME_LIMIT_NS / c {
                    return Err(format!(
                        "`every {n} cycles` is longer than the simulator's time range (about 146 years)"
                    ));
                }
            }
            Trigger::Every => {
                let p = f64::from_bits(operand);
                if p.is_nan() || p * NS < 0.5 {
                    return Err(format!(
                        "`every {}` needs a period of at least 1 ns; a period of zero or less would fire without end",
                        fmt_quantity(p, Dim::TIME)
                    ));
                }
                span_ns(p, t, "the period")?;
            }
            Trigger::After => {
                let p = f64::from_bits(operand);
                if p.is_nan() || p < 0.0 {
                    return Err(format!(
                        "`after {}`: the delay cannot be negative",
                        fmt_quantity(p, Dim::TIME)
                    ));
                }
                span_ns(p, t, "the delay")?;
            }
            Trigger::Condition(_) => {}
        }
        Ok(())
    }

    pub(super) fn perform_fire(&mut self, i: usize) {
        let Some((t, _)) = self.next_fire().filter(|(_, j)| *j == i) else {
            return;
        };
        self.time = self.time.max(t);
        self.fires.retain(|(_, j)| *j != i);
        let Some(e) = self.enabled.get_mut(i) else {
            return;
        };
        if let Firing::Timer { next, period } = &mut e.firing {
            // Past the time limit a timer never fires again (see `next_fire`).
            match period {
                Some(p) => *next = next.saturating_add(*p),
                None => *next = i64::MAX,
            }
        }
        let (action, args) = (self.m.handlers[e.handler as usize].action, e.args.clone());
        self.hrun_handler = e.handler;
        self.handler.start(&self.m, action, &args);
        self.hstate = State::Run;
        self.hrun = Some((i, t));
    }

    pub(super) fn perform_handler(&mut self) {
        let State::At(e) = std::mem::replace(&mut self.hstate, State::Run) else {
            return;
        };
        let pc = self.handler.pc;
        let ins = self.m.code.get(pc as usize).copied().unwrap_or(Instr::Stop);
        match e.kind {
            EventKind::WhenEnd { .. } => {
                // The handler stopped at `stop`: the program ends after it.
                let stopping = !self.handler.frames.is_empty() && ins == Instr::Stop;
                // An `after` handler is gone once it has run.
                if let Some((i, _)) = self.hrun
                    && matches!(
                        self.enabled.get(i).map(|x| &x.firing),
                        Some(Firing::Timer { period: None, .. })
                    )
                {
                    self.remove_enabled(|k, _| k == i);
                }
                self.hrun = None;
                self.hstate = State::Done;
                if stopping {
                    self.stop_program(e.time, e.pos);
                }
                return;
            }
            EventKind::Error { .. } => {
                self.hrun = None;
                self.hstate = State::Done;
                self.state = State::Done;
                return;
            }
            EventKind::End => {
                // `stop` in a handler ends the robot's program.
                self.hrun = None;
                self.hstate = State::Done;
                self.end_program();
                return;
            }
            _ => {}
        }
        self.apply_zero_time(&e, ins, true);
        self.handler.pc = pc + 1;
    }

    /// Enables handler `h`: reads its trigger operand and copies its captured locals.
    pub(super) fn enable(&mut self, h: u32, t: i64, in_handler: bool) {
        let m = Arc::clone(&self.m);
        let info = &m.handlers[h as usize];
        let th = if in_handler {
            &mut self.handler
        } else {
            &mut self.main
        };
        let operand = if info.trigger.has_operand() {
            th.stack.pop().unwrap_or(0)
        } else {
            0
        };
        let base = th.frames.last().map_or(0, |f| f.base as usize);
        let grab = |caps: &[crate::bytecode::Capture]| -> Vec<u64> {
            caps.iter()
                .flat_map(|c| (0..c.width as u32).map(move |k| base + (c.slot + k) as usize))
                .map(|i| th.locals.get(i).copied().unwrap_or(0))
                .collect()
        };
        let args = grab(&info.captures);
        let (firing, cond_args) = match info.trigger {
            crate::bytecode::Trigger::EveryCycles => {
                let c = self.cfg.cycle_ns.max(1);
                let n = (operand as i64).max(1);
                (
                    Firing::Timer {
                        next: (t / c + n) * c,
                        period: Some(n * c),
                    },
                    Vec::new(),
                )
            }
            crate::bytecode::Trigger::Every => {
                let p = ((f64::from_bits(operand) * NS).round() as i64).max(1);
                (
                    Firing::Timer {
                        next: t + p,
                        period: Some(p),
                    },
                    Vec::new(),
                )
            }
            crate::bytecode::Trigger::After => {
                let p = ((f64::from_bits(operand) * NS).round() as i64).max(0);
                (
                    Firing::Timer {
                        next: t + p,
                        period: None,
                    },
                    Vec::new(),
                )
            }
            crate::bytecode::Trigger::Condition(c) => {
                let cargs = grab(&m.conds[c as usize].captures);
                let last = self.eval_cond_with(m.conds[c as usize].func, &cargs, t);
                (Firing::Edge { last }, cargs)
            }
        };
        self.enabled.push(Enabled {
            handler: h,
            target: info.target,
            args,
            cond_args,
            firing,
        });
    }

    /// Removes the enabled handlers `gone(index, handler)` selects, keeping the indices of
    /// pending firings and of the running handler right.
    pub(super) fn remove_enabled(&mut self, gone: impl Fn(usize, &Enabled) -> bool) {
        let mut map = Vec::with_capacity(self.enabled.len());
        let mut kept = 0;
        for (k, e) in self.enabled.iter().enumerate() {
            if gone(k, e) {
                map.push(None);
            } else {
                map.push(Some(kept));
                kept += 1;
            }
        }
        let mut k = 0;
        self.enabled.retain(|_| {
            let keep = map[k].is_some();
            k += 1;
            keep
        });
        self.fires = self
            .fires
            .iter()
            .filter_map(|(t, i)| map[*i].map(|j| (*t, j)))
            .collect();
        if let Some((i, t)) = self.hrun {
            // A disabled running handler finishes; it just has no index any more.
            self.hrun = Some((map[i].unwrap_or(usize::MAX), t));
        }
    }

    /// The enabled condition handlers: (handler procedure, the module globals the
    /// condition reads), for the SE's when list.
    pub fn condition_handlers(&self) -> impl Iterator<Item = (u32, &[u32])> + '_ {
        self.enabled
            .iter()
            .filter_map(|e| match self.m.handlers[e.handler as usize].trigger {
                crate::bytecode::Trigger::Condition(c) => {
                    Some((e.target, self.m.conds[c as usize].globals.as_slice()))
                }
                _ => None,
            })
    }

    /// The SE's `check_when` at time `t`: re-tests every condition handler; each
    /// false→true edge schedules a firing at `t`. Returns how many will fire.
    pub fn check_when(&mut self, t: i64) -> usize {
        let m = Arc::clone(&self.m);
        let mut fired = 0;
        for i in 0..self.enabled.len() {
            let Firing::Edge { last } = self.enabled[i].firing else {
                continue;
            };
            let crate::bytecode::Trigger::Condition(c) =
                m.handlers[self.enabled[i].handler as usize].trigger
            else {
                continue;
            };
            let args = std::mem::take(&mut self.enabled[i].cond_args);
            let now = self.eval_cond_with(m.conds[c as usize].func, &args, t);
            self.enabled[i].cond_args = args;
            self.enabled[i].firing = Firing::Edge { last: now };
            if now && !last {
                self.fires.push((t, i));
                fired += 1;
            }
        }
        fired
    }
}
