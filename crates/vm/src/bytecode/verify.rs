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

/// What in a module is inconsistent, and where: the table entry, or the procedure and
/// instruction offset. Its text is the verifier's message ("invalid module: …" in a
/// [`LoadError`]); tests and callers match the variant.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum VerifyError {
    /// A table entry names a string past the string table.
    #[error("{user} names string {index}, but there are {count}")]
    StringIndex {
        /// Whose string it is.
        user: StringUser,
        /// The string index named.
        index: u32,
        /// How many strings the module has.
        count: usize,
    },
    /// A constant's value is not a finite value of its type.
    #[error("constant {index} does not hold a finite {ty}")]
    Constant {
        /// The constant's index.
        index: usize,
        /// Its declared type.
        ty: Type,
    },
    /// A global is not a scalar, or its initial value is not a finite value of its type.
    #[error("global {index} has type {ty} or a value of another type")]
    Global {
        /// The global's index.
        index: usize,
        /// Its declared type.
        ty: Type,
    },
    /// A module variable's slots lie outside the variable area.
    #[error("module variable {index} lies outside the variable area")]
    VariableOutsideArea {
        /// The variable's index.
        index: usize,
    },
    /// A remote call site passes a text, which is its robot's own.
    #[error("a remote call site passes a text, which cannot cross to another robot")]
    RemoteText,
    /// A module variable's initial value is not a finite value of its type.
    #[error("module variable {index} has an initial value of another type")]
    VariableInit {
        /// The variable's index.
        index: usize,
    },
    /// Procedures do not lie back to back in index order.
    #[error(
        "procedure {index} starts at instruction {start}, but the previous one ends at {expected}"
    )]
    ProcedureGap {
        /// The procedure's index.
        index: usize,
        /// Where it starts.
        start: u32,
        /// Where the previous one ends.
        expected: u64,
    },
    /// The procedures do not cover the code section exactly.
    #[error("the procedures cover {covered} instructions, but the code has {code}")]
    CodeCoverage {
        /// Instructions inside procedures.
        covered: u64,
        /// Instructions in the code section.
        code: u64,
    },
    /// A procedure's code range is empty or past the code.
    #[error("procedure {index} has an empty or out-of-range code range")]
    CodeRange {
        /// The procedure's index.
        index: usize,
    },
    /// A procedure's frame is smaller than its parameters or larger than [`MAX_FRAME`].
    #[error("procedure {index} has a frame of {slots} slots")]
    FrameSize {
        /// The procedure's index.
        index: usize,
        /// Its frame size.
        slots: u32,
    },
    /// A procedure's return type does not fit its kind.
    #[error("procedure {index} has the wrong return type for a {}", kind.keyword())]
    ReturnType {
        /// The procedure's index.
        index: usize,
        /// Its kind.
        kind: ProcKind,
    },
    /// A condition or handler names a procedure that is missing or of the wrong kind.
    #[error("{user} refers to procedure {procedure}, which is missing or of the wrong kind")]
    ProcedureRef {
        /// The condition or handler.
        user: RuleRef,
        /// The procedure index named.
        procedure: u32,
    },
    /// A condition's captures do not match its procedure's parameters.
    #[error("condition {index} captures do not match its parameters")]
    ConditionCaptures {
        /// The condition's index.
        index: usize,
    },
    /// A condition's global list is out of range or unsorted.
    #[error("condition {index} lists globals out of range or unsorted")]
    ConditionGlobals {
        /// The condition's index.
        index: usize,
    },
    /// A handler's captures do not match its action's parameters.
    #[error("handler {index} captures do not match its action's parameters")]
    HandlerCaptures {
        /// The handler's index.
        index: usize,
    },
    /// A handler's trigger names a missing condition.
    #[error("handler {index} refers to a missing condition {condition}")]
    HandlerCondition {
        /// The handler's index.
        index: usize,
        /// The condition index named.
        condition: u32,
    },
    /// A joints site has no values or more than `MAX_AXES`.
    #[error("a joints site has no values or more than {MAX_AXES}")]
    JointsSiteCount,
    /// A source position names a file the module does not list.
    #[error("a source position names file {file} but the module has {files} files")]
    SourceFile {
        /// The file index named.
        file: u32,
        /// How many files the module lists.
        files: usize,
    },
    /// The line table is unsorted or points past the code.
    #[error("the line table is unsorted or points past the code")]
    LineTable,
    /// An instruction of a procedure is wrong.
    #[error("procedure {procedure} ({name}), instruction {offset}: {problem}")]
    Code {
        /// The procedure's index.
        procedure: usize,
        /// The procedure's name.
        name: String,
        /// The instruction's offset inside the procedure.
        offset: usize,
        /// What is wrong there.
        problem: CodeProblem,
    },
}

/// What is wrong with one instruction ([`VerifyError::Code`]).
#[derive(Debug, Clone, Copy, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum CodeProblem {
    /// An operand is out of range, or the instruction is not allowed in this kind of code.
    #[error("{} has an operand out of range or is not allowed in a {}", instr.name(), kind.keyword())]
    Operand {
        /// The instruction.
        instr: Instr,
        /// The kind of procedure it is in.
        kind: ProcKind,
    },
    /// An event instruction in a zero-time function or condition.
    #[error("{} is an event, not allowed in a zero-time {}", instr.name(), kind.keyword())]
    EventInZeroTime {
        /// The instruction.
        instr: Instr,
        /// The kind of procedure it is in.
        kind: ProcKind,
    },
    /// A jump outside the procedure.
    #[error("jumps to {target}, outside the procedure's {len} instructions")]
    JumpOutside {
        /// The jump's target.
        target: u32,
        /// The procedure's length.
        len: usize,
    },
    /// The error handler or one of its statements lies outside the procedure.
    #[error(
        "the error handler or one of its statements lies outside the procedure's {len} instructions"
    )]
    HandlerOutside {
        /// The procedure's length.
        len: usize,
    },
    /// Two paths reach the instruction with different stack heights.
    #[error("stack height {height} here, but {other} on another path")]
    HeightMismatch {
        /// The height on this path.
        height: u32,
        /// The height on another path.
        other: u32,
    },
    /// The instruction's stack effect needs a table entry that is missing.
    #[error("{} refers to a missing table entry", instr.name())]
    MissingEntry {
        /// The instruction.
        instr: Instr,
    },
    /// The instruction pops more than the stack holds.
    #[error("{} pops {pops} slots but the stack holds {height}", instr.name())]
    Underflow {
        /// The instruction.
        instr: Instr,
        /// Slots it pops.
        pops: u32,
        /// Slots on the stack.
        height: u32,
    },
    /// The operand stack would exceed [`MAX_STACK`].
    #[error("the operand stack exceeds {MAX_STACK} slots")]
    StackTooDeep,
    /// A return with slots left on the stack.
    #[error("returns with {left} slots left on the stack")]
    ReturnWithValues {
        /// Slots left.
        left: u32,
    },
    /// Control runs past the procedure's last instruction.
    #[error("control falls off the end of the procedure")]
    FallsOffEnd,
}

/// A table entry that names a string ([`VerifyError::StringIndex`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[non_exhaustive]
pub enum StringUser {
    /// A constant's name.
    Constant(usize),
    /// A global's name.
    Global(usize),
    /// A module variable's name.
    ModuleVariable(usize),
    /// A procedure's name.
    Procedure(usize),
    /// A parameter's name, of this procedure.
    Parameter(usize),
    /// A remote call site.
    RemoteSite,
    /// A signal site.
    SignalSite,
    /// The list of awaited signals.
    AwaitedSignals,
    /// A sync site.
    SyncSite,
    /// A sync site's task list.
    SyncTasks,
    /// A part site.
    PartSite,
    /// A log format's text.
    LogFormat,
}

impl std::fmt::Display for StringUser {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            StringUser::Constant(i) => write!(f, "constant {i}"),
            StringUser::Global(i) => write!(f, "global {i}"),
            StringUser::ModuleVariable(i) => write!(f, "module variable {i}"),
            StringUser::Procedure(i) => write!(f, "procedure {i}"),
            StringUser::Parameter(i) => write!(f, "a parameter of procedure {i}"),
            StringUser::RemoteSite => f.write_str("a remote site"),
            StringUser::SignalSite => f.write_str("a signal site"),
            StringUser::AwaitedSignals => f.write_str("the awaited-signal list"),
            StringUser::SyncSite => f.write_str("a sync site"),
            StringUser::SyncTasks => f.write_str("a sync site's task list"),
            StringUser::PartSite => f.write_str("a part site"),
            StringUser::LogFormat => f.write_str("a log format"),
        }
    }
}

/// A condition or handler naming a procedure ([`VerifyError::ProcedureRef`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum RuleRef {
    /// A condition, by index.
    Condition(usize),
    /// A handler, by index.
    Handler(usize),
}

impl std::fmt::Display for RuleRef {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            RuleRef::Condition(i) => write!(f, "condition {i}"),
            RuleRef::Handler(i) => write!(f, "handler {i}"),
        }
    }
}

impl Module {
    /// Checks the module's internal consistency (see the module docs) and fills in each
    /// procedure's `max_stack`. The compiler's output always passes; decoded bytes must.
    pub fn verify(&mut self) -> Result<(), LoadError> {
        self.verify_tables()?;
        let mut max_stacks = Vec::with_capacity(self.procs.len());
        for (i, p) in self.procs.iter().enumerate() {
            max_stacks.push(self.verify_code(i, p)?);
        }
        for (p, m) in self.procs.iter_mut().zip(max_stacks) {
            p.max_stack = m;
        }
        Ok(())
    }

    fn verify_tables(&self) -> Result<(), VerifyError> {
        use VerifyError as E;
        let count = self.strings.len();
        let s = |index: u32, user: StringUser| -> Result<(), VerifyError> {
            if (index as usize) < count {
                Ok(())
            } else {
                Err(E::StringIndex { user, index, count })
            }
        };
        for (index, c) in self.consts.iter().enumerate() {
            if let Some(n) = c.name {
                s(n, StringUser::Constant(index))?;
            }
            if !c.value.fits(c.ty) || !c.value.is_finite() {
                return Err(E::Constant { index, ty: c.ty });
            }
            if let ConstValue::Text(k) = c.value
                && k != u32::MAX
            {
                s(k, StringUser::Constant(index))?;
            }
        }
        for (index, g) in self.globals.iter().enumerate() {
            s(g.name, StringUser::Global(index))?;
            if !g.ty.is_scalar() || !g.init.fits(g.ty) || !g.init.is_finite() {
                return Err(E::Global { index, ty: g.ty });
            }
        }
        for (index, v) in self.vars.iter().enumerate() {
            s(v.name, StringUser::ModuleVariable(index))?;
            if u64::from(v.slot) + u64::from(v.ty.width()) > u64::from(self.var_slots) {
                return Err(E::VariableOutsideArea { index });
            }
            if !v.init.fits(v.ty) || !v.init.is_finite() {
                return Err(E::VariableInit { index });
            }
            if let ConstValue::Text(k) = v.init
                && k != u32::MAX
            {
                s(k, StringUser::ModuleVariable(index))?;
            }
        }
        let ncode = self.code.len() as u64;
        // Procedures lie back to back in index order and cover all the code: no
        // instruction is outside a procedure, none belongs to two.
        let mut next = 0u64;
        for (index, p) in self.procs.iter().enumerate() {
            if u64::from(p.code_start) != next {
                return Err(E::ProcedureGap {
                    index,
                    start: p.code_start,
                    expected: next,
                });
            }
            next += u64::from(p.code_len);
        }
        if next != ncode {
            return Err(E::CodeCoverage {
                covered: next,
                code: ncode,
            });
        }
        for (index, p) in self.procs.iter().enumerate() {
            s(p.name, StringUser::Procedure(index))?;
            for a in &p.params {
                s(a.name, StringUser::Parameter(index))?;
            }
            if u64::from(p.code_start) + u64::from(p.code_len) > ncode || p.code_len == 0 {
                return Err(E::CodeRange { index });
            }
            if p.frame_slots < p.param_width() || p.frame_slots > MAX_FRAME {
                return Err(E::FrameSize {
                    index,
                    slots: p.frame_slots,
                });
            }
            let ret_ok = match p.kind {
                ProcKind::Proc | ProcKind::Handler => p.ret.is_none(),
                ProcKind::Func => p.ret.is_some(),
                ProcKind::Cond => p.ret == Some(Type::Bool),
            };
            if !ret_ok {
                return Err(E::ReturnType {
                    index,
                    kind: p.kind,
                });
            }
        }
        let proc_of_kind =
            |procedure: u32, kinds: &[ProcKind], user: RuleRef| -> Result<&ProcInfo, VerifyError> {
                match self.procs.get(procedure as usize) {
                    Some(p) if kinds.contains(&p.kind) => Ok(p),
                    _ => Err(E::ProcedureRef { user, procedure }),
                }
            };
        for (index, c) in self.conds.iter().enumerate() {
            let f = proc_of_kind(c.func, &[ProcKind::Cond], RuleRef::Condition(index))?;
            if captures_width(&c.captures) != u64::from(f.param_width()) {
                return Err(E::ConditionCaptures { index });
            }
            if c.globals.iter().any(|g| *g as usize >= self.globals.len())
                || c.globals.windows(2).any(|w| w[0] >= w[1])
            {
                return Err(E::ConditionGlobals { index });
            }
        }
        for (index, h) in self.handlers.iter().enumerate() {
            let a = proc_of_kind(h.action, &[ProcKind::Handler], RuleRef::Handler(index))?;
            if captures_width(&h.captures) != u64::from(a.param_width()) {
                return Err(E::HandlerCaptures { index });
            }
            proc_of_kind(h.target, &[ProcKind::Proc], RuleRef::Handler(index))?;
            if let Trigger::Condition(condition) = h.trigger
                && condition as usize >= self.conds.len()
            {
                return Err(E::HandlerCondition { index, condition });
            }
        }
        for r in &self.remotes {
            s(r.robot, StringUser::RemoteSite)?;
            s(r.proc, StringUser::RemoteSite)?;
            // A text is its robot's own handle: it cannot be sent to another robot.
            if r.args.contains(&Type::Text) {
                return Err(E::RemoteText);
            }
        }
        for x in &self.signals_sent {
            s(x.robot, StringUser::SignalSite)?;
            s(x.name, StringUser::SignalSite)?;
        }
        for x in &self.signals_awaited {
            s(*x, StringUser::AwaitedSignals)?;
        }
        for x in &self.syncs {
            s(x.name, StringUser::SyncSite)?;
            for t in &x.tasks {
                s(*t, StringUser::SyncTasks)?;
            }
        }
        for x in &self.parts {
            s(x.part, StringUser::PartSite)?;
        }
        if self
            .joints_sites
            .iter()
            .any(|j| j.count as usize > MAX_AXES || j.count == 0)
        {
            return Err(E::JointsSiteCount);
        }
        for f in &self.log_formats {
            for p in &f.parts {
                if let LogPart::Text(t) = p {
                    s(*t, StringUser::LogFormat)?;
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
            return Err(E::SourceFile {
                file: p.file,
                files: self.files.len(),
            });
        }
        if self.lines.windows(2).any(|w| w[0].pc >= w[1].pc)
            || self
                .lines
                .last()
                .is_some_and(|l| u64::from(l.pc) >= ncode.max(1))
        {
            return Err(E::LineTable);
        }
        Ok(())
    }

    fn verify_code(&self, index: usize, p: &ProcInfo) -> Result<u32, VerifyError> {
        let code = p.code(self);
        let n = code.len();
        let zero_time = matches!(p.kind, ProcKind::Func | ProcKind::Cond);
        let at = |offset: usize, problem: CodeProblem| VerifyError::Code {
            procedure: index,
            name: self.str(p.name).to_owned(),
            offset,
            problem,
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
                Instr::Raise(x) => (x as usize) < self.strings.len(),
                _ => true,
            };
            if !ok {
                return Err(at(
                    pc,
                    CodeProblem::Operand {
                        instr: ins,
                        kind: p.kind,
                    },
                ));
            }
            if zero_time && ins.is_event() && !matches!(ins, Instr::Log(_) | Instr::Fail(_)) {
                return Err(at(
                    pc,
                    CodeProblem::EventInZeroTime {
                        instr: ins,
                        kind: p.kind,
                    },
                ));
            }
            if let Some(t) = ins.jump_target()
                && t as usize >= n
            {
                return Err(at(pc, CodeProblem::JumpOutside { target: t, len: n }));
            }
        }
        // Stack heights along every path from the entry, and from the error handler's
        // entries: the handler itself, and the statements `Retry`/`TryNext` go to, where
        // the stack is empty.
        let mut height: Vec<Option<u32>> = vec![None; n];
        let mut work = vec![(0usize, 0u32)];
        if let Some(h) = &p.handler {
            let inside = |x: u32| (x as usize) < n;
            if !inside(h.pc)
                || h.stmts
                    .iter()
                    .any(|&(s, e)| s > e || !inside(s) || !inside(e))
            {
                return Err(at(0, CodeProblem::HandlerOutside { len: n }));
            }
            work.push((h.pc as usize, 0));
            for &(s, e) in &h.stmts {
                work.push((s as usize, 0));
                work.push((e as usize, 0));
            }
        }
        let mut max = 0;
        while let Some((pc, h)) = work.pop() {
            match height[pc] {
                Some(old) if old == h => continue,
                Some(old) => {
                    return Err(at(
                        pc,
                        CodeProblem::HeightMismatch {
                            height: h,
                            other: old,
                        },
                    ));
                }
                None => height[pc] = Some(h),
            }
            let ins = code[pc];
            let e = ins
                .stack_effect(self, p)
                .ok_or_else(|| at(pc, CodeProblem::MissingEntry { instr: ins }))?;
            if h < e.pops {
                return Err(at(
                    pc,
                    CodeProblem::Underflow {
                        instr: ins,
                        pops: e.pops,
                        height: h,
                    },
                ));
            }
            let after = h - e.pops + e.pushes;
            max = max.max(after).max(h);
            if max > MAX_STACK {
                return Err(at(pc, CodeProblem::StackTooDeep));
            }
            match ins {
                Instr::Ret | Instr::RetVal if after != 0 => {
                    return Err(at(pc, CodeProblem::ReturnWithValues { left: after }));
                }
                _ => {}
            }
            if let Some(t) = ins.jump_target() {
                work.push((t as usize, after));
            }
            if !ins.ends_block() {
                if pc + 1 >= n {
                    return Err(at(pc, CodeProblem::FallsOffEnd));
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
