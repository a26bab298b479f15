//! The verifier: proves a module safe to run before the VM sees it.
//!
//! After [`Module::verify`] succeeds: the procedures tile the code section exactly; in
//! every instruction, reachable or not, every table index and string index is in range; every
//! local, module-variable, global and constant access is inside its area; every jump lands
//! inside its procedure; no procedure falls off its end; and the operand-stack height is
//! the same on every path into each instruction, never negative, zero at `Ret` and exactly
//! the return width at `RetVal`. Every number in constants, initial values and `PushNum`
//! is finite. Functions and conditions (zero-time code) call only
//! functions and contain no scheduling events. Each procedure's `max_stack` is filled in.

use super::instr::Instr;
use super::*;
use crate::types::{MAX_AXES, Type};

/// The deepest operand stack a procedure may need, in slots.
pub const MAX_STACK: u32 = 1 << 16;

/// The most slots a procedure's frame (parameters and locals) may have.
pub const MAX_FRAME: u32 = 1 << 20;

fn bad(msg: String) -> LoadError {
    LoadError::Invalid(msg)
}

impl Module {
    /// Checks the module's internal consistency (see the module docs) and fills in each
    /// procedure's `max_stack`. The compiler's output always passes; decoded bytes must.
    pub fn verify(&mut self) -> Result<(), LoadError> {
        let nstr = self.strings.len();
        let s = |i: u32, what: &str| -> Result<(), LoadError> {
            if (i as usize) < nstr {
                Ok(())
            } else {
                Err(bad(format!(
                    "{what} names string {i}, but there are {nstr}"
                )))
            }
        };
        for (i, c) in self.consts.iter().enumerate() {
            if let Some(n) = c.name {
                s(n, &format!("constant {i}"))?;
            }
            if !c.value.fits(c.ty) || !c.value.is_finite() {
                return Err(bad(format!("constant {i} does not hold a finite {}", c.ty)));
            }
        }
        for (i, g) in self.globals.iter().enumerate() {
            s(g.name, &format!("global {i}"))?;
            if !g.ty.is_scalar() || !g.init.fits(g.ty) || !g.init.is_finite() {
                return Err(bad(format!(
                    "global {i} has type {} or a value of another type",
                    g.ty
                )));
            }
        }
        for (i, v) in self.vars.iter().enumerate() {
            s(v.name, &format!("module variable {i}"))?;
            if u64::from(v.slot) + u64::from(v.ty.width()) > u64::from(self.var_slots) {
                return Err(bad(format!(
                    "module variable {i} lies outside the variable area"
                )));
            }
            if !v.init.fits(v.ty) || !v.init.is_finite() {
                return Err(bad(format!(
                    "module variable {i} has an initial value of another type"
                )));
            }
        }
        let ncode = self.code.len() as u64;
        // Procedures lie back to back in index order and cover all the code: no
        // instruction is outside a procedure, none belongs to two.
        let mut next = 0u64;
        for (i, p) in self.procs.iter().enumerate() {
            if u64::from(p.code_start) != next {
                return Err(bad(format!(
                    "procedure {i} starts at instruction {}, but the previous one ends at {next}",
                    p.code_start
                )));
            }
            next += u64::from(p.code_len);
        }
        if next != ncode {
            return Err(bad(format!(
                "the procedures cover {next} instructions, but the code has {ncode}"
            )));
        }
        for (i, p) in self.procs.iter().enumerate() {
            s(p.name, &format!("procedure {i}"))?;
            for a in &p.params {
                s(a.name, &format!("a parameter of procedure {i}"))?;
            }
            if u64::from(p.code_start) + u64::from(p.code_len) > ncode || p.code_len == 0 {
                return Err(bad(format!(
                    "procedure {i} has an empty or out-of-range code range"
                )));
            }
            if p.frame_slots < p.param_width() || p.frame_slots > MAX_FRAME {
                return Err(bad(format!(
                    "procedure {i} has a frame of {} slots",
                    p.frame_slots
                )));
            }
            let ret_ok = match p.kind {
                ProcKind::Proc | ProcKind::Handler => p.ret.is_none(),
                ProcKind::Func => p.ret.is_some(),
                ProcKind::Cond => p.ret == Some(Type::Bool),
            };
            if !ret_ok {
                return Err(bad(format!(
                    "procedure {i} has the wrong return type for a {}",
                    p.kind.keyword()
                )));
            }
        }
        let proc_of_kind =
            |i: u32, kinds: &[ProcKind], what: &str| -> Result<&ProcInfo, LoadError> {
                match self.procs.get(i as usize) {
                    Some(p) if kinds.contains(&p.kind) => Ok(p),
                    _ => Err(bad(format!(
                        "{what} refers to procedure {i}, which is missing or of the wrong kind"
                    ))),
                }
            };
        for (i, c) in self.conds.iter().enumerate() {
            let f = proc_of_kind(c.func, &[ProcKind::Cond], &format!("condition {i}"))?;
            if captures_width(&c.captures) != u64::from(f.param_width()) {
                return Err(bad(format!(
                    "condition {i} captures do not match its parameters"
                )));
            }
            if c.globals.iter().any(|g| *g as usize >= self.globals.len())
                || c.globals.windows(2).any(|w| w[0] >= w[1])
            {
                return Err(bad(format!(
                    "condition {i} lists globals out of range or unsorted"
                )));
            }
        }
        for (i, h) in self.handlers.iter().enumerate() {
            let a = proc_of_kind(h.action, &[ProcKind::Handler], &format!("handler {i}"))?;
            if captures_width(&h.captures) != u64::from(a.param_width()) {
                return Err(bad(format!(
                    "handler {i} captures do not match its action's parameters"
                )));
            }
            proc_of_kind(h.target, &[ProcKind::Proc], &format!("handler {i}"))?;
            if let Trigger::Condition(c) = h.trigger
                && c as usize >= self.conds.len()
            {
                return Err(bad(format!(
                    "handler {i} refers to a missing condition {c}"
                )));
            }
        }
        for r in &self.remotes {
            s(r.robot, "a remote site")?;
            s(r.proc, "a remote site")?;
        }
        for x in &self.signals_sent {
            s(x.robot, "a signal site")?;
            s(x.name, "a signal site")?;
        }
        for x in &self.signals_awaited {
            s(*x, "the awaited-signal list")?;
        }
        for x in &self.syncs {
            s(x.name, "a sync site")?;
            for t in &x.tasks {
                s(*t, "a sync site's task list")?;
            }
        }
        for x in &self.parts {
            s(x.part, "a part site")?;
        }
        if self
            .joints_sites
            .iter()
            .any(|j| j.count as usize > MAX_AXES || j.count == 0)
        {
            return Err(bad(format!(
                "a joints site has no values or more than {MAX_AXES}"
            )));
        }
        for f in &self.log_formats {
            for p in &f.parts {
                if let LogPart::Text(t) = p {
                    s(*t, "a log format")?;
                }
            }
        }
        let nfiles = self.files.len().max(1) as u64;
        let positions = (self.procs.iter().map(|x| x.pos))
            .chain(self.consts.iter().map(|x| x.pos))
            .chain(self.globals.iter().map(|x| x.pos))
            .chain(self.vars.iter().map(|x| x.pos))
            .chain(self.conds.iter().map(|x| x.pos))
            .chain(self.handlers.iter().map(|x| x.pos))
            .chain(self.remotes.iter().map(|x| x.pos))
            .chain(self.signals_sent.iter().map(|x| x.pos))
            .chain(self.syncs.iter().map(|x| x.pos))
            .chain(self.parts.iter().map(|x| x.pos))
            .chain(self.joints_sites.iter().map(|x| x.pos))
            .chain(self.lines.iter().map(|x| x.pos));
        if let Some(p) = positions.into_iter().find(|p| u64::from(p.file) >= nfiles) {
            return Err(bad(format!(
                "a source position names file {} but the module has {} files",
                p.file,
                self.files.len()
            )));
        }
        if self.lines.windows(2).any(|w| w[0].pc >= w[1].pc)
            || self
                .lines
                .last()
                .is_some_and(|l| u64::from(l.pc) >= ncode.max(1))
        {
            return Err(bad(
                "the line table is unsorted or points past the code".into()
            ));
        }
        let mut max_stacks = Vec::with_capacity(self.procs.len());
        for (i, p) in self.procs.iter().enumerate() {
            max_stacks.push(self.verify_code(i, p)?);
        }
        for (p, m) in self.procs.iter_mut().zip(max_stacks) {
            p.max_stack = m;
        }
        Ok(())
    }

    fn verify_code(&self, index: usize, p: &ProcInfo) -> Result<u32, LoadError> {
        let code = p.code(self);
        let n = code.len();
        let zero_time = matches!(p.kind, ProcKind::Func | ProcKind::Cond);
        let at = |pc: usize, msg: String| {
            bad(format!(
                "procedure {index} ({}), instruction {pc}: {msg}",
                self.str(p.name)
            ))
        };
        let frame = u64::from(p.frame_slots);
        let in_frame = |slot: u64, w: u64| slot + w <= frame;
        let caps_fit = |c: &[Capture]| {
            c.iter()
                .all(|c| in_frame(u64::from(c.slot), u64::from(c.width)))
        };
        // Every instruction, reachable or not: operands in range, no forbidden events,
        // jumps inside the procedure. Dead code may hold no garbage either.
        for (pc, &ins) in code.iter().enumerate() {
            let ok = match ins {
                Instr::LoadLocal(sl) | Instr::StoreLocal(sl) => in_frame(u64::from(sl), 1),
                Instr::LoadLocalN(sl, w) | Instr::StoreLocalN(sl, w) => {
                    in_frame(u64::from(sl), u64::from(w))
                }
                Instr::StoreLocalJoint(sl) => in_frame(u64::from(sl), MAX_AXES as u64),
                Instr::LoadVar(sl) | Instr::StoreVar(sl) => {
                    u64::from(sl) < u64::from(self.var_slots)
                }
                Instr::LoadVarN(sl, w) | Instr::StoreVarN(sl, w) => {
                    u64::from(sl) + u64::from(w) <= u64::from(self.var_slots)
                }
                Instr::StoreVarJoint(sl) => {
                    u64::from(sl) + MAX_AXES as u64 <= u64::from(self.var_slots)
                }
                Instr::LoadGlobal(g) => (g as usize) < self.globals.len(),
                Instr::StoreGlobal(g) => (g as usize) < self.globals.len() && !zero_time,
                Instr::PulseGlobal(g) => {
                    !zero_time
                        && self
                            .globals
                            .get(g as usize)
                            .is_some_and(|x| matches!(x.ty, Type::Int | Type::Bool))
                }
                Instr::PushConst(k) => (k as usize) < self.consts.len(),
                Instr::MakeJoints(c) => c >= 1 && c as usize <= MAX_AXES,
                Instr::PoseGet(f) => f < 6,
                Instr::PushNum(x) => x.is_finite(),
                Instr::Call(t) => match self.procs.get(t as usize) {
                    Some(c) if zero_time => c.kind == ProcKind::Func,
                    Some(c) => matches!(c.kind, ProcKind::Proc | ProcKind::Func),
                    None => false,
                },
                Instr::Ret => !zero_time,
                Instr::RetVal => zero_time,
                Instr::WaitUntil(c, _) | Instr::WaitPoll(c, _) => self
                    .conds
                    .get(c as usize)
                    .is_some_and(|c| caps_fit(&c.captures)),
                Instr::WaitSignal(sg, _) => (sg as usize) < self.strings.len(),
                Instr::Signal(x) => (x as usize) < self.signals_sent.len(),
                Instr::WaitSync(x, _) => (x as usize) < self.syncs.len(),
                Instr::Remote(x) => (x as usize) < self.remotes.len(),
                Instr::When(x) => self.handlers.get(x as usize).is_some_and(|h| {
                    caps_fit(&h.captures)
                        && match h.trigger {
                            Trigger::Condition(c) => self
                                .conds
                                .get(c as usize)
                                .is_some_and(|c| caps_fit(&c.captures)),
                            _ => true,
                        }
                }),
                Instr::Disable(x) => self
                    .procs
                    .get(x as usize)
                    .is_some_and(|t| t.kind == ProcKind::Proc),
                Instr::Grip(x) | Instr::Release(x) => (x as usize) < self.parts.len(),
                Instr::Log(f) | Instr::Fail(f) => (f as usize) < self.log_formats.len(),
                _ => true,
            };
            if !ok {
                return Err(at(
                    pc,
                    format!(
                        "{} has an operand out of range or is not allowed in a {}",
                        ins.name(),
                        p.kind.keyword()
                    ),
                ));
            }
            if zero_time && ins.is_event() && !matches!(ins, Instr::Log(_) | Instr::Fail(_)) {
                return Err(at(
                    pc,
                    format!(
                        "{} is an event, not allowed in a zero-time {}",
                        ins.name(),
                        p.kind.keyword()
                    ),
                ));
            }
            if let Some(t) = ins.jump_target()
                && t as usize >= n
            {
                return Err(at(
                    pc,
                    format!("jumps to {t}, outside the procedure's {n} instructions"),
                ));
            }
        }
        // Stack heights along every path from the entry.
        let mut height: Vec<Option<u32>> = vec![None; n];
        let mut work = vec![(0usize, 0u32)];
        let mut max = 0;
        while let Some((pc, h)) = work.pop() {
            match height[pc] {
                Some(old) if old == h => continue,
                Some(old) => {
                    return Err(at(
                        pc,
                        format!("stack height {h} here, but {old} on another path"),
                    ));
                }
                None => height[pc] = Some(h),
            }
            let ins = code[pc];
            let e = ins.stack_effect(self, p).ok_or_else(|| {
                at(
                    pc,
                    format!("{} refers to a missing table entry", ins.name()),
                )
            })?;
            if h < e.pops {
                return Err(at(
                    pc,
                    format!(
                        "{} pops {} slots but the stack holds {h}",
                        ins.name(),
                        e.pops
                    ),
                ));
            }
            let after = h - e.pops + e.pushes;
            max = max.max(after).max(h);
            if max > MAX_STACK {
                return Err(at(
                    pc,
                    format!("the operand stack exceeds {MAX_STACK} slots"),
                ));
            }
            match ins {
                Instr::Ret | Instr::RetVal if after != 0 => {
                    return Err(at(
                        pc,
                        format!("returns with {after} slots left on the stack"),
                    ));
                }
                _ => {}
            }
            if let Some(t) = ins.jump_target() {
                work.push((t as usize, after));
            }
            if !ins.ends_block() {
                if pc + 1 >= n {
                    return Err(at(pc, "control falls off the end of the procedure".into()));
                }
                work.push((pc + 1, after));
            }
        }
        Ok(max)
    }
}

fn captures_width(c: &[Capture]) -> u64 {
    c.iter().map(|c| u64::from(c.width)).sum()
}
