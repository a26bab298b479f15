//! Code generation: the emitter every part of the walk writes through — instructions
//! with their line-table entries, jumps patched once their target is known, constants
//! pushed or pooled, strings interned, procedures opened and closed in the module's tables.

use super::*;

impl Compiler<'_> {
    pub(super) fn str(&mut self, s: &str) -> u32 {
        if let Some(&i) = self.strings.get(s) {
            return i;
        }
        let i = self.m.strings.len() as u32;
        self.m.strings.push(s.to_string());
        self.strings.insert(s.to_string(), i);
        i
    }

    pub(super) fn emit(&mut self, ins: Instr, span: Span) -> usize {
        let pos = self.pos(span);
        let f = self.f();
        let pc = f.code.len() as u32;
        if f.lines.last().is_none_or(|(_, p)| *p != pos) {
            f.lines.push((pc, pos));
        }
        f.code.push(ins);
        pc as usize
    }

    pub(super) fn here(&mut self) -> usize {
        self.f().code.len()
    }

    pub(super) fn patch(&mut self, at: usize, target: usize) {
        let t = target as u32;
        let f = self.f();
        f.code[at] = match f.code[at] {
            Instr::Jump(_) => Instr::Jump(t),
            Instr::JumpIfFalse(_) => Instr::JumpIfFalse(t),
            Instr::JumpIfTrue(_) => Instr::JumpIfTrue(t),
            other => other,
        };
    }

    /// Drops the code emitted since `start` (used when a subexpression folded to a constant).
    pub(super) fn truncate(&mut self, start: usize) {
        let f = self.f();
        f.code.truncate(start);
        while f.lines.last().is_some_and(|(pc, _)| *pc as usize >= start) {
            f.lines.pop();
        }
    }

    pub(super) fn push_const(&mut self, v: &ConstValue, ty: Ty, span: Span) {
        match v {
            ConstValue::Bool(b) => {
                self.emit(Instr::PushBool(*b), span);
            }
            ConstValue::Int(i) => {
                self.emit(Instr::PushInt(*i), span);
            }
            ConstValue::Num(x) => {
                self.emit(Instr::PushNum(*x), span);
            }
            ConstValue::Joints(_) | ConstValue::Pose(_) | ConstValue::Text(_) => {
                let k = self.pool(v, ty, span);
                self.emit(Instr::PushConst(k), span);
            }
        }
    }

    pub(super) fn pool(&mut self, v: &ConstValue, ty: Ty, span: Span) -> u32 {
        let vty = ty.vm().unwrap_or(Type::Pose);
        if let Some(i) = self
            .m
            .consts
            .iter()
            .position(|c| c.ty == vty && &c.value == v)
        {
            return i as u32;
        }
        let pos = self.pos(span);
        self.m.consts.push(ConstInfo {
            name: None,
            ty: vty,
            value: v.clone(),
            pos,
        });
        (self.m.consts.len() - 1) as u32
    }

    pub(super) fn new_proc(&mut self, name: &str, kind: ProcKind, span: Span) -> u32 {
        let name = self.str(name);
        let pos = self.pos(span);
        self.m.procs.push(ProcInfo {
            name,
            kind,
            params: Vec::new(),
            ret: None,
            frame_slots: 0,
            code_start: 0,
            code_len: 0,
            pos,
            max_stack: 0,
            handler: None,
        });
        self.facts.push(Facts::default());
        self.proc_code.push((Vec::new(), Vec::new()));
        (self.m.procs.len() - 1) as u32
    }

    pub(super) fn finish_fn(&mut self) -> FnCtx {
        let f = self
            .fns
            .pop()
            .unwrap_or_else(|| FnCtx::new(0, FnKind::Init, Ty::Void));
        if f.kind != FnKind::Init
            && let Some(p) = self.m.procs.get_mut(f.index as usize)
        {
            p.frame_slots = f.next_slot;
            self.proc_code[f.index as usize] = (f.code.clone(), f.lines.clone());
        }
        f
    }
}
