//! `when` handlers ([`Handlers`]): the enabled ones (with their triggers checked), their
//! firings by cycles, time or a condition's rising edge, the one running (its thread and
//! state), disabling, and ending them with the activation that enabled them.

use super::state::State;
use super::{TIME_LIMIT_NS, span_ns};
use crate::bytecode::{Capture, Module, Trigger};
use crate::exec::Thread;
use crate::motion::NS;
use crate::types::{Dim, fmt_quantity};

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

/// The robot's `when` handlers.
#[derive(Debug)]
pub(super) struct Handlers {
    /// The thread of the handler now running.
    pub(super) thread: Thread,
    /// Its state.
    pub(super) state: State,
    /// The running handler: (enabled index, firing time).
    running: Option<(usize, i64)>,
    /// The module handler index of the running handler.
    running_handler: u32,
    /// Enabled handlers, in enabling order.
    enabled: Vec<Enabled>,
    /// Condition handlers whose edge was seen: (time, enabled index).
    fires: Vec<(i64, usize)>,
}

impl Default for Handlers {
    fn default() -> Handlers {
        Handlers {
            thread: Thread::default(),
            state: State::Done,
            running: None,
            running_handler: 0,
            enabled: Vec::new(),
            fires: Vec::new(),
        }
    }
}

impl Handlers {
    /// The firing time of the handler running, if one is.
    pub(super) fn running_since(&self) -> Option<i64> {
        self.running.map(|(_, t)| t)
    }

    /// The module handler index of the handler running (or that ran last).
    pub(super) fn running_handler(&self) -> u32 {
        self.running_handler
    }

    /// Whether the running handler must run code to find its next event.
    pub(super) fn needs_run(&self) -> bool {
        self.running.is_some() && self.state == State::Run
    }

    /// The module handler index of enabled handler `i`.
    pub(super) fn handler_of(&self, i: usize) -> u32 {
        self.enabled[i].handler
    }

    /// The globals (module indices) the enabled condition handlers read.
    pub(super) fn when_globals<'a>(&'a self, m: &'a Module) -> impl Iterator<Item = u32> + 'a {
        self.enabled
            .iter()
            .filter_map(|e| match m.handlers[e.handler as usize].trigger {
                Trigger::Condition(c) => Some(&m.conds[c as usize].globals),
                _ => None,
            })
            .flatten()
            .copied()
    }

    /// The enabled condition handlers: (handler procedure, the module globals the
    /// condition reads).
    pub(super) fn condition_handlers<'a>(
        &'a self,
        m: &'a Module,
    ) -> impl Iterator<Item = (u32, &'a [u32])> + 'a {
        self.enabled
            .iter()
            .filter_map(|e| match m.handlers[e.handler as usize].trigger {
                Trigger::Condition(c) => Some((e.target, m.conds[c as usize].globals.as_slice())),
                _ => None,
            })
    }

    /// The period of handler `handler` as it is enabled now, if it fires by time or by
    /// cycles.
    pub(super) fn period_ns(&self, handler: u32) -> Option<i64> {
        self.enabled
            .iter()
            .filter(|e| e.handler == handler)
            .find_map(|e| match e.firing {
                Firing::Timer { period, .. } => period,
                Firing::Edge { .. } => None,
            })
    }

    /// The earliest handler firing: (time, enabled index).
    #[inline]
    pub(super) fn next_fire(&self) -> Option<(i64, usize)> {
        if self.enabled.is_empty() && self.fires.is_empty() {
            return None;
        }
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

    /// Enabled handler `i` fires (it is the next firing): its action starts on the handler
    /// thread. Returns the firing's time; `None` if it is not the next firing.
    pub(super) fn fire(&mut self, m: &Module, i: usize) -> Option<i64> {
        let (t, _) = self.next_fire().filter(|(_, j)| *j == i)?;
        self.fires.retain(|(_, j)| *j != i);
        if let Some(e) = self.enabled.get_mut(i) {
            if let Firing::Timer { next, period } = &mut e.firing {
                // Past the time limit a timer never fires again (see `next_fire`).
                match period {
                    Some(p) => *next = next.saturating_add(*p),
                    None => *next = i64::MAX,
                }
            }
            self.running_handler = e.handler;
            self.thread
                .start(m, m.handlers[e.handler as usize].action, &e.args);
            self.state = State::Run;
            self.running = Some((i, t));
        }
        Some(t)
    }

    /// The running handler ended (`when_end`): an `after` handler is gone once it has run.
    pub(super) fn end_running(&mut self) {
        if let Some((i, _)) = self.running
            && matches!(
                self.enabled.get(i).map(|x| &x.firing),
                Some(Firing::Timer { period: None, .. })
            )
        {
            self.remove(|k, _| k == i);
        }
        self.stop_running();
    }

    /// The running handler stops (it ended or failed).
    pub(super) fn stop_running(&mut self) {
        self.running = None;
        self.state = State::Done;
    }

    /// Every handler goes (the activation that enabled them ended).
    pub(super) fn clear(&mut self) {
        self.enabled.clear();
        self.fires.clear();
    }

    /// Enables handler `h` at `t` from thread `th`: pops its trigger operand and copies
    /// its captured locals; `eval(func, args)` evaluates a condition trigger's condition
    /// now (its first value, from which edges count).
    pub(super) fn enable(
        &mut self,
        m: &Module,
        cycle_ns: i64,
        h: u32,
        th: &mut Thread,
        t: i64,
        eval: impl FnOnce(u32, &[u64]) -> bool,
    ) {
        let info = &m.handlers[h as usize];
        let operand = if info.trigger.has_operand() {
            th.stack.pop().unwrap_or(0)
        } else {
            0
        };
        let base = th.frames.last().map_or(0, |f| f.base as usize);
        let grab = |caps: &[Capture]| -> Vec<u64> {
            caps.iter()
                .flat_map(|c| (0..c.width as u32).map(move |k| base + (c.slot + k) as usize))
                .map(|i| th.locals.get(i).copied().unwrap_or(0))
                .collect()
        };
        let args = grab(&info.captures);
        let (firing, cond_args) = match info.trigger {
            Trigger::EveryCycles => {
                let c = cycle_ns.max(1);
                let n = (operand as i64).max(1);
                (
                    Firing::Timer {
                        next: (t / c + n) * c,
                        period: Some(n * c),
                    },
                    Vec::new(),
                )
            }
            Trigger::Every => {
                let p = ((f64::from_bits(operand) * NS).round() as i64).max(1);
                (
                    Firing::Timer {
                        next: t + p,
                        period: Some(p),
                    },
                    Vec::new(),
                )
            }
            Trigger::After => {
                let p = ((f64::from_bits(operand) * NS).round() as i64).max(0);
                (
                    Firing::Timer {
                        next: t + p,
                        period: None,
                    },
                    Vec::new(),
                )
            }
            Trigger::Condition(c) => {
                let cargs = grab(&m.conds[c as usize].captures);
                let last = eval(m.conds[c as usize].func, &cargs);
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

    /// Disables the handlers calling procedure `proc`.
    pub(super) fn disable(&mut self, proc: u32) {
        self.remove(|_, x| x.target == proc);
    }

    /// Removes the enabled handlers `gone(index, handler)` selects, keeping the indices of
    /// pending firings and of the running handler right.
    fn remove(&mut self, gone: impl Fn(usize, &Enabled) -> bool) {
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
        if let Some((i, t)) = self.running {
            // A disabled running handler finishes; it just has no index any more.
            self.running = Some((map[i].unwrap_or(usize::MAX), t));
        }
    }

    /// The SE's `check_when` at time `t`: re-tests every condition handler with `eval`;
    /// each false→true edge schedules a firing at `t`. Returns how many will fire.
    pub(super) fn check_edges(
        &mut self,
        m: &Module,
        t: i64,
        mut eval: impl FnMut(u32, &[u64]) -> bool,
    ) -> usize {
        let mut fired = 0;
        for (i, e) in self.enabled.iter_mut().enumerate() {
            let Firing::Edge { last } = e.firing else {
                continue;
            };
            let Trigger::Condition(c) = m.handlers[e.handler as usize].trigger else {
                continue;
            };
            let now = eval(m.conds[c as usize].func, &e.cond_args);
            e.firing = Firing::Edge { last: now };
            if now && !last {
                self.fires.push((t, i));
                fired += 1;
            }
        }
        fired
    }
}

/// Checks the operand of a `when` trigger before handler `h` is enabled at `t`: a period
/// of at least 1 ns (`every T`), a count of at least 1 (`every N cycles`), a delay that is
/// not negative (`after T`), all ending within the time limit.
pub(super) fn check_trigger(
    m: &Module,
    cycle_ns: i64,
    h: u32,
    operand: u64,
    t: i64,
) -> Result<(), String> {
    match m.handlers[h as usize].trigger {
        Trigger::EveryCycles => {
            let n = operand as i64;
            if n < 1 {
                return Err(format!(
                    "`every {n} cycles` needs a count of at least 1; a handler every 0 or fewer cycles could never fire"
                ));
            }
            let c = cycle_ns.max(1);
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
