//! The interpreter's side of the VM ([`Interp`]): module variables, the globals as the SE
//! last gave them, the reads of globals noted for race warnings, the scratch thread that
//! evaluates conditions, and the budgets of the current instant (instructions and events);
//! running a thread's zero-time code within them, and naming the loop that exhausts them.

use std::cell::RefCell;

use super::VmConfig;
use super::view::{Sight, View};
use crate::bytecode::{Module, SrcPos};
use crate::exec::{RuntimeError, Stop, Thread};
use crate::motion::NS;
use crate::texts::Texts;
use crate::types::{Dim, fmt_quantity};

/// Which globals the main program and handlers read at the current instant.
#[derive(Debug, Default)]
pub(super) struct ReadLog {
    /// Per module global: the instant it was last read.
    at: Vec<i64>,
    /// The globals first read at their instant since the SE last took them, and where.
    new: Vec<(u32, SrcPos)>,
}

impl ReadLog {
    /// Notes a read of global `g` at `t` (where: `pos`), if it is its first at `t`.
    pub(super) fn note(&mut self, g: u32, t: i64, pos: impl FnOnce() -> SrcPos) {
        if let Some(at) = self.at.get_mut(g as usize)
            && *at != t
        {
            *at = t;
            self.new.push((g, pos()));
        }
    }
}

/// The interpreter's state shared by the VM's threads.
#[derive(Debug)]
pub(super) struct Interp {
    /// Module variables (slots).
    vars: Vec<u64>,
    /// The texts the run made (RAPID's strings), which text slots hold handles of.
    pub(super) texts: Texts,
    /// Globals as the SE last gave them (slot bits by module global index).
    globals: Vec<u64>,
    /// Reads of globals by the main program and handlers, for race warnings.
    read_log: ReadLog,
    /// Scratch thread for evaluating conditions.
    cond: Thread,
    /// The simulated instant the budgets below count for, the instructions left at it and
    /// the events performed at it.
    instant: i64,
    instant_budget: u64,
    instant_events: u64,
}

impl Interp {
    /// The variables and globals of module `m` at their initial values.
    pub(super) fn new(m: &Module) -> Interp {
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
        Interp {
            vars,
            texts: Texts::default(),
            read_log: ReadLog {
                at: vec![-1; globals.len()],
                new: Vec::with_capacity(4),
            },
            globals,
            cond: Thread::default(),
            instant: -1,
            instant_budget: 0,
            instant_events: 0,
        }
    }

    /// Global `g` takes `value` (slot bits).
    pub(super) fn set_global(&mut self, g: u32, value: u64) {
        if let Some(v) = self.globals.get_mut(g as usize) {
            *v = value;
        }
    }

    /// Moves the reads noted since the last call into `out`.
    pub(super) fn take_reads(&mut self, out: &mut Vec<(u32, SrcPos)>) {
        out.append(&mut self.read_log.new);
    }

    /// Whether reads are noted that `take_reads` has not taken.
    pub(super) fn has_reads(&self) -> bool {
        !self.read_log.new.is_empty()
    }

    /// Starts counting the budgets of instant `t` if it is a new one (`budget`
    /// instructions).
    pub(super) fn enter_instant(&mut self, t: i64, budget: u64) {
        if t != self.instant {
            self.instant = t;
            self.instant_budget = budget;
            self.instant_events = 0;
        }
    }

    /// An event was performed at the current instant.
    pub(super) fn count_event(&mut self) {
        self.instant_events += 1;
    }

    /// How many events were performed at instant `t` (0 unless the last were at `t`).
    pub(super) fn events_at(&self, t: i64) -> u64 {
        if self.instant == t {
            self.instant_events
        } else {
            0
        }
    }

    /// Runs a thread's zero-time code at time `t` over the module variables, within what
    /// is left of the instant's instruction budget. `record_reads`: the thread is the main
    /// program or a handler (its reads of globals are noted).
    pub(super) fn run(
        &mut self,
        th: &mut Thread,
        sight: &Sight<'_>,
        cfg: &VmConfig,
        t: i64,
        record_reads: bool,
    ) -> Result<Stop, RuntimeError> {
        self.enter_instant(t, cfg.budget);
        let mut budget = self.instant_budget;
        // Moved into a cell for the run (the view only reads), and back; not at all when
        // the module has no globals to read.
        let log = (record_reads && !self.read_log.at.is_empty())
            .then(|| RefCell::new(std::mem::take(&mut self.read_log)));
        let r = th.run(
            sight.m,
            &View {
                sight,
                globals: &self.globals,
                t,
                reads: log.as_ref(),
            },
            &mut self.vars,
            &mut self.texts,
            &mut budget,
            cfg.max_depth,
        );
        if let Some(log) = log {
            self.read_log = log.into_inner();
        }
        self.instant_budget = budget;
        match r {
            Err(e) if budget == 0 => Err(zero_time_loop(
                sight.m,
                e.pc,
                th,
                format!(
                    "{} instructions at {}",
                    cfg.budget,
                    fmt_quantity(t as f64 / NS, Dim::TIME)
                ),
            )),
            other => other,
        }
    }

    /// Runs condition function `func` with `args` at `t`; false if it fails.
    pub(super) fn eval_cond(
        &mut self,
        sight: &Sight<'_>,
        cfg: &VmConfig,
        func: u32,
        args: &[u64],
        t: i64,
    ) -> bool {
        let mut th = std::mem::take(&mut self.cond);
        th.start(sight.m, func, args);
        let r = self.run(&mut th, sight, cfg, t, false);
        let value = matches!(r, Ok(Stop::Finished)) && th.stack.last().copied().unwrap_or(0) != 0;
        self.cond = th;
        value
    }

    /// Whether the instant `t`'s event budget (`limit`) is spent.
    pub(super) fn events_spent(&self, limit: u64) -> bool {
        self.instant_events >= limit
    }
}

/// The slots condition `c` captures from the innermost frame of `th`, in `args` (at most
/// its length); how many.
pub(super) fn captured(m: &Module, c: u32, th: &Thread, args: &mut [u64]) -> usize {
    let cond = &m.conds[c as usize];
    let base = th.frames.last().map_or(0, |f| f.base as usize);
    let mut n = 0;
    for cap in &cond.captures {
        for k in 0..cap.width as usize {
            if n < args.len() {
                args[n] = th
                    .locals
                    .get(base + cap.slot as usize + k)
                    .copied()
                    .unwrap_or(0);
                n += 1;
            }
        }
    }
    n
}

/// The error of a zero-time loop at `pc` of `th`: it names the innermost loop around
/// `pc` (or around the call that leads there), or the statement if there is none.
pub(super) fn zero_time_loop(m: &Module, pc: u32, th: &Thread, what: String) -> RuntimeError {
    let (at, place) = match loop_start(m, pc, th) {
        Some(start) => (start, "this loop"),
        None => (pc, "this statement"),
    };
    RuntimeError {
        errno: None,
        message: format!(
            "{place} never lets time pass ({what}): an endless zero-time loop; add a motion, a delay or a wait that blocks inside it"
        ),
        pc: at,
        pos: m.pos_of(at),
    }
}

/// The start of the innermost loop around `pc` of `th`, or around the call that leads
/// there.
pub(super) fn loop_start(m: &Module, pc: u32, th: &Thread) -> Option<u32> {
    let calls = th.frames.iter().rev().map(|f| f.ret_pc);
    std::iter::once(pc)
        .chain(calls)
        .find_map(|at| loop_around(m, at))
}

/// The start of the innermost loop around absolute instruction `pc`: the target of the
/// shortest backward jump of the same procedure that spans it.
fn loop_around(m: &Module, pc: u32) -> Option<u32> {
    let p = &m.procs[m.proc_at(pc)? as usize];
    let code = p.code(m);
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
