//! Statements: blocks, locals, assignments, `if`/`while`/`for`, `return`, motions and
//! their rates, `parallel`/`remote`, with the zero-time and function rules checked where
//! each statement is compiled.

use super::*;

/// Where an assignment stores.
#[derive(Debug)]
pub(super) enum Place {
    Local(u32),
    Var(u32),
    Global(u32),
}

/// Where a compound assignment loads from.
#[derive(Debug)]
pub(super) enum Load {
    Local(u32),
    Var(u32),
    Global(u32),
}

pub(super) fn place_load(p: &Place) -> Load {
    match p {
        Place::Local(s) => Load::Local(*s),
        Place::Var(s) => Load::Var(*s),
        Place::Global(g) => Load::Global(*g),
    }
}

impl Compiler<'_> {
    /// Compiles a block in a new scope; true if it never completes normally.
    pub(super) fn block(&mut self, b: &Block) -> bool {
        self.f().scopes.push(Vec::new());
        let mut diverges = false;
        for s in &b.stmts {
            if diverges {
                self.err(
                    Diagnostic::error(Code::W0004, "this statement can never run", s.span)
                        .with_help("remove it, or move it before the `return`/`break`/`stop`"),
                );
                break;
            }
            diverges = self.stmt(s);
        }
        self.f().scopes.pop();
        diverges
    }

    pub(super) fn takes_time(&mut self, what: &str, span: Span) -> bool {
        match self.fk() {
            FnKind::Func => {
                self.err(
                    Diagnostic::error(Code::E0070, format!("a function may not {what}"), span)
                        .with_label("not allowed in a `func`")
                        .with_help("functions run in zero time; make it a `proc`"),
                );
                false
            }
            _ => {
                let f = self.facts();
                if f.time.is_none() {
                    f.time = Some((what.to_string(), span));
                }
                true
            }
        }
    }

    pub(super) fn not_in_func(&mut self, what: &str, span: Span) -> bool {
        if self.fk() == FnKind::Func {
            self.err(
                Diagnostic::error(Code::E0070, format!("a function may not {what}"), span)
                    .with_label("not allowed in a `func`")
                    .with_help("functions run in zero time and have no effects outside the robot; make it a `proc`"),
            );
            return false;
        }
        true
    }

    /// Compiles a statement; true if control never continues after it. In a procedure
    /// with an error handler, its `[start, end)` is noted.
    pub(super) fn stmt(&mut self, s: &Stmt) -> bool {
        let StmtKind::Recover(b) = &s.kind else {
            return self.stmt_code(s);
        };
        let start = self.here() as u32;
        let diverges = self.block(b);
        let end = self.here() as u32;
        if let Some(v) = self.f().stmts.as_mut() {
            v.push((start, end));
        }
        diverges
    }

    fn stmt_code(&mut self, s: &Stmt) -> bool {
        let sp = s.span;
        match &s.kind {
            StmtKind::Error => {}
            StmtKind::Var(d) => self.local_var(d),
            StmtKind::Assign { target, op, value } => self.assign(target, *op, value, sp),
            StmtKind::Call { name, args } => {
                let out = self.call(name, args, sp, true);
                let w = out.ty.width();
                if w > 0 {
                    self.emit(Instr::Pop(w), sp);
                }
            }
            StmtKind::If { branches, els } => return self.if_stmt(branches, els.as_ref()),
            StmtKind::While { cond, body } => {
                let top = self.here();
                let c = self.expr(cond);
                self.expect_bool(&c, cond.span, "a `while` condition");
                let exit = self.emit(Instr::JumpIfFalse(0), cond.span);
                self.f().loops.push(Loop::default());
                self.block(body);
                let lp = self.f().loops.pop().unwrap_or_default();
                self.emit(Instr::Jump(top as u32), sp);
                let end = self.here();
                self.patch(exit, end);
                for b in lp.breaks {
                    self.patch(b, end);
                }
                for c in lp.continues {
                    self.patch(c, top);
                }
            }
            StmtKind::For {
                var,
                start,
                end,
                body,
            } => self.for_stmt(var, start, end, body, sp),
            StmtKind::Break | StmtKind::Continue => {
                let is_break = matches!(s.kind, StmtKind::Break);
                if self.f().loops.is_empty() {
                    let w = if is_break { "break" } else { "continue" };
                    self.err(
                        Diagnostic::error(Code::E0030, format!("`{w}` outside a loop"), sp)
                            .with_help("`break` and `continue` belong inside `while` or `for`"),
                    );
                    return false;
                }
                if self
                    .f()
                    .in_parallel
                    .is_some_and(|open| self.f().loops.len() <= open)
                {
                    let w = if is_break { "break" } else { "continue" };
                    self.leaves_parallel(&format!("`{w}`"), sp);
                }
                let j = self.emit(Instr::Jump(0), sp);
                if let Some(l) = self.f().loops.last_mut() {
                    if is_break {
                        l.breaks.push(j)
                    } else {
                        l.continues.push(j)
                    }
                }
                return true;
            }
            StmtKind::Return(value) => {
                if self.f().in_parallel.is_some() {
                    self.leaves_parallel("`return`", sp);
                }
                return self.return_stmt(value.as_ref(), sp);
            }
            StmtKind::Move {
                kind,
                via,
                target,
                speed,
                accel,
                orient,
                zone,
                tool,
                duration,
            } => self.move_stmt(
                *kind,
                via.as_ref(),
                target,
                MoveOptions {
                    speed: speed.as_ref(),
                    accel: accel.as_ref(),
                    orient: orient.as_ref(),
                    zone: zone.as_ref(),
                    tool: tool.as_ref(),
                    duration: duration.as_ref(),
                },
                sp,
            ),
            StmtKind::Pulse { global, length } => self.pulse_stmt(global, length, sp),
            StmtKind::Delay(t) => {
                self.takes_time("delay", sp);
                let out = self.expr(t);
                let out = self.coerce(out, Ty::Num(Dim::TIME), t.span, "`delay`");
                if let Some(ConstValue::Num(x)) = out.k
                    && x < 0.0
                {
                    self.err(Diagnostic::error(
                        Code::E0025,
                        "a delay cannot be negative",
                        t.span,
                    ));
                }
                self.emit(Instr::Delay, sp);
            }
            StmtKind::WaitUntil {
                cond,
                timeout,
                poll,
            } => {
                self.takes_time("wait", sp);
                let c = self.condition(cond, "`wait_until`");
                if let Some(t) = timeout {
                    self.time_operand(t, "a timeout");
                }
                match poll {
                    Some(p) => {
                        self.time_operand(p, "a poll period");
                        self.emit(Instr::WaitPoll(c, timeout.is_some()), sp);
                    }
                    None => {
                        self.emit(Instr::WaitUntil(c, timeout.is_some()), sp);
                    }
                }
            }
            StmtKind::WaitSignal { name, timeout } => {
                self.takes_time("wait", sp);
                if let Some(t) = timeout {
                    self.time_operand(t, "a timeout");
                }
                let n = self.str(&name.name);
                if !self.m.signals_awaited.contains(&n) {
                    self.m.signals_awaited.push(n);
                }
                self.emit(Instr::WaitSignal(n, timeout.is_some()), sp);
            }
            StmtKind::Sync {
                name,
                tasks,
                timeout,
            } => {
                self.takes_time("wait", sp);
                if let Some(t) = timeout {
                    self.time_operand(t, "a timeout");
                }
                let name = self.str(&name.name);
                let tasks = tasks.iter().map(|t| self.str(&t.name)).collect();
                let pos = self.pos(sp);
                self.m.syncs.push(SyncSite { name, tasks, pos });
                let i = (self.m.syncs.len() - 1) as u32;
                self.emit(Instr::WaitSync(i, timeout.is_some()), sp);
            }
            StmtKind::Signal { robot, name } => {
                if self.not_in_func("send signals", sp) {
                    let robot = self.str(&robot.name);
                    let name = self.str(&name.name);
                    let pos = self.pos(sp);
                    self.m.signals_sent.push(SignalSite { robot, name, pos });
                    let i = (self.m.signals_sent.len() - 1) as u32;
                    self.emit(Instr::Signal(i), sp);
                }
            }
            StmtKind::Parallel(branches) => self.parallel(branches, sp),
            StmtKind::Remote { args, .. } => {
                self.err(
                    Diagnostic::error(Code::E0060, "`remote` must stand directly inside `parallel`", sp)
                        .with_help("write `parallel { remote r2.p(…); }`: the block waits until the remote work ends"),
                );
                for a in args {
                    self.expr(a);
                }
            }
            StmtKind::When {
                trigger,
                handler,
                args,
            } => self.when_stmt(trigger, handler, args, sp),
            StmtKind::Disable(name) => {
                if self.not_in_func("disable handlers", sp) {
                    match self.symbols.get(&name.name).map(|s| s.0.clone()) {
                        Some(Sym::Proc(p)) if !self.sigs[p as usize].is_func => {
                            self.disabled.push((p, name.span));
                            self.emit(Instr::Disable(p), sp);
                        }
                        _ => self.err(
                            Diagnostic::error(
                                Code::E0011,
                                format!("`{}` is not a procedure of this module", name.name),
                                name.span,
                            )
                            .with_help("`disable p` names the procedure a `when … do p(…)` calls"),
                        ),
                    }
                }
            }
            StmtKind::Grip(part) | StmtKind::Release(part) => {
                let grip = matches!(s.kind, StmtKind::Grip(_));
                let what = if grip {
                    "grip a part"
                } else {
                    "release a part"
                };
                self.takes_time(what, sp);
                let p = self.str(&part.name);
                let pos = self.pos(part.span);
                self.m.parts.push(PartSite { part: p, pos });
                let i = (self.m.parts.len() - 1) as u32;
                self.emit(
                    if grip {
                        Instr::Grip(i)
                    } else {
                        Instr::Release(i)
                    },
                    sp,
                );
            }
            StmtKind::Log(args) => {
                let f = self.log_format(args);
                self.emit(Instr::Log(f), sp);
            }
            StmtKind::Fail(args) => {
                let f = self.log_format(args);
                self.emit(Instr::Fail(f), sp);
                return true;
            }
            StmtKind::Stop => {
                if self.not_in_func("stop the program", sp) {
                    self.emit(Instr::Stop, sp);
                }
                return true;
            }
            StmtKind::Block(b) => return self.block(b),
            StmtKind::Raise(..) | StmtKind::Retry | StmtKind::TryNext => {
                self.recovery(&s.kind, sp);
                return true;
            }
            StmtKind::Recover(b) => return self.block(b),
        }
        false
    }

    pub(super) fn local_var(&mut self, d: &VarDecl) {
        let declared = d.ty.as_ref().map(|t| self.resolve_type(t));
        let ty = match &d.init {
            Some(init) => {
                let out = self.expr(init);
                let out = match declared {
                    Some(t) => {
                        self.coerce(out, t, init.span, &format!("variable `{}`", d.name.name))
                    }
                    None => out,
                };
                match out.ty {
                    Ty::Void => {
                        self.err(Diagnostic::error(
                            Code::E0020,
                            format!("`{}` cannot hold {}", d.name.name, out.ty.described()),
                            init.span,
                        ));
                        Ty::Error
                    }
                    t => t,
                }
            }
            None => {
                let t = declared.unwrap_or(Ty::Error);
                if let Some(vt) = t.vm() {
                    let z = ConstValue::zero(vt);
                    self.push_const(&z, t, d.span);
                }
                t
            }
        };
        let in_scope = self.fns.last().and_then(|f| {
            f.scopes
                .iter()
                .flatten()
                .find(|l| l.name == d.name.name)
                .cloned()
        });
        if in_scope.is_some() {
            self.err(
                Diagnostic::error(
                    Code::E0012,
                    format!("`{}` is already a local variable here", d.name.name),
                    d.name.span,
                )
                .with_help("choose another name, or assign to the existing variable"),
            );
        } else if let Some((Sym::Global(..), gspan)) = self.symbols.get(&d.name.name) {
            let gspan = *gspan;
            self.err(
                Diagnostic::error(Code::W0001, format!("local `{}` hides the global of the same name", d.name.name), d.name.span)
                    .with_related(gspan, "the global")
                    .with_help("assignments to the local emit no `set` event; rename it if you meant the global"),
            );
        }
        let slot = self.add_local(&d.name.name, ty, true);
        self.store_local(slot, ty, d.span);
    }

    pub(super) fn store_local(&mut self, slot: u32, ty: Ty, span: Span) {
        let w = ty.width();
        let s = slot;
        match w {
            0 => {}
            1 => {
                self.emit(Instr::StoreLocal(s), span);
            }
            w => {
                self.emit(Instr::StoreLocalN(s, w), span);
            }
        }
    }

    pub(super) fn load_local(&mut self, slot: u32, ty: Ty, span: Span) {
        let s = slot;
        match ty.width() {
            0 => {}
            1 => {
                self.emit(Instr::LoadLocal(s), span);
            }
            w => {
                self.emit(Instr::LoadLocalN(s, w), span);
            }
        }
    }

    pub(super) fn lookup_local(&mut self, name: &str) -> Option<Local> {
        let n = self.fns.len();
        let f = self.fns.last()?;
        if let Some(l) = f
            .scopes
            .iter()
            .rev()
            .flat_map(|s| s.iter().rev())
            .find(|l| l.name == name)
        {
            return Some(l.clone());
        }
        if !matches!(f.kind, FnKind::Cond | FnKind::Handler) || n < 2 {
            return None;
        }
        if let Some((_, _, _, ty)) = f.captures.iter().find(|c| c.0 == name) {
            let ty = *ty;
            let slot = self.fns[n - 1]
                .scopes
                .first()
                .and_then(|s| s.iter().find(|l| l.name == name))
                .map_or(0, |l| l.slot);
            return Some(Local {
                name: name.into(),
                slot,
                ty,
                mutable: false,
            });
        }
        let outer = self.fns[n - 2]
            .scopes
            .iter()
            .rev()
            .flat_map(|s| s.iter().rev())
            .find(|l| l.name == name)?
            .clone();
        let f = &mut self.fns[n - 1];
        let slot = f.next_slot;
        f.next_slot += u32::from(outer.ty.width());
        f.captures
            .push((name.to_string(), outer.slot, outer.ty.width(), outer.ty));
        let local = Local {
            name: name.to_string(),
            slot,
            ty: outer.ty,
            mutable: false,
        };
        if let Some(s) = f.scopes.first_mut() {
            s.push(local.clone());
        }
        Some(local)
    }

    pub(super) fn assign(&mut self, target: &Expr, op: Option<BinOp>, value: &Expr, sp: Span) {
        // Resolve the base variable of the target.
        let (base_name, base_span) = match &target.kind {
            ExprKind::Name(n) => (n.clone(), target.span),
            ExprKind::Field(b, _) | ExprKind::Index(b, _) => match &b.kind {
                ExprKind::Name(n) => (n.clone(), b.span),
                _ => {
                    self.not_assignable(target.span, "this expression");
                    return;
                }
            },
            ExprKind::Error => return,
            _ => {
                self.not_assignable(target.span, "this expression");
                return;
            }
        };
        let (place, ty) = if let Some(l) = self.lookup_local(&base_name) {
            if !l.mutable {
                let what = if matches!(self.fk(), FnKind::Cond | FnKind::Handler) {
                    format!("`{base_name}` (a copy captured by the handler)")
                } else {
                    format!("the loop variable `{base_name}`")
                };
                self.not_assignable(base_span, &what);
                return;
            }
            (Place::Local(l.slot), l.ty)
        } else {
            match self.symbols.get(&base_name).map(|s| s.0.clone()) {
                Some(Sym::Var(slot, ty)) => {
                    self.note_impure(&format!("the module variable `{base_name}`"), base_span);
                    (Place::Var(slot), ty)
                }
                Some(Sym::Global(g, ty)) => {
                    if !self.not_in_func("assign a global (that is a `set` event)", sp) {
                        return;
                    }
                    if !matches!(target.kind, ExprKind::Name(_)) {
                        self.not_assignable(target.span, "a part of a global");
                        return;
                    }
                    (Place::Global(g), ty)
                }
                Some(Sym::Const(..)) => {
                    self.not_assignable(base_span, &format!("the constant `{base_name}`"));
                    return;
                }
                Some(Sym::Param(..)) => {
                    self.not_assignable(
                        base_span,
                        &format!("the parameter `{base_name}` (the workcell or a sweep sets it)"),
                    );
                    return;
                }
                Some(Sym::Proc(_)) => {
                    self.not_assignable(base_span, &format!("the procedure `{base_name}`"));
                    return;
                }
                None => {
                    self.unknown_name(&base_name, base_span);
                    self.expr(value);
                    return;
                }
            }
        };
        // What is assigned: the whole variable, a pose field or a joint.
        match &target.kind {
            ExprKind::Name(_) => {
                if let Some(op) = op {
                    self.load_place(&place_load(&place), ty, target.span);
                    let r = self.expr(value);
                    let out = self.binary_typed(op, Out::of(ty), r, sp, value.span);
                    self.coerce(out, ty, value.span, &format!("`{base_name}`"));
                } else {
                    let out = self.expr(value);
                    self.coerce(out, ty, value.span, &format!("`{base_name}`"));
                }
                match place {
                    Place::Local(s) => self.store_local(s, ty, sp),
                    Place::Var(s) => {
                        let w = ty.width();
                        self.emit(
                            if w == 1 {
                                Instr::StoreVar(s)
                            } else {
                                Instr::StoreVarN(s, w)
                            },
                            sp,
                        );
                    }
                    Place::Global(g) => {
                        self.emit(Instr::StoreGlobal(g), sp);
                    }
                }
            }
            ExprKind::Field(_, field) => {
                if ty != Ty::Pose {
                    if !ty.is_err() {
                        self.err(Diagnostic::error(
                            Code::E0022,
                            format!("`{base_name}` is {}, which has no fields", ty.described()),
                            target.span,
                        ));
                    }
                    return;
                }
                let Some((fi, fty)) = self.pose_field(field) else {
                    return;
                };
                let slot = match place {
                    Place::Local(s) | Place::Var(s) => s + u32::from(fi),
                    Place::Global(_) => return,
                };
                let is_local = matches!(place, Place::Local(_));
                if let Some(op) = op {
                    self.load_place(
                        &if is_local {
                            Load::Local(slot)
                        } else {
                            Load::Var(slot)
                        },
                        fty,
                        target.span,
                    );
                    let r = self.expr(value);
                    let out = self.binary_typed(op, Out::of(fty), r, sp, value.span);
                    self.coerce(
                        out,
                        fty,
                        value.span,
                        &format!("`{base_name}.{}`", field.name),
                    );
                } else {
                    let out = self.expr(value);
                    self.coerce(
                        out,
                        fty,
                        value.span,
                        &format!("`{base_name}.{}`", field.name),
                    );
                }
                if is_local {
                    self.store_local(slot, fty, sp);
                } else {
                    self.emit(Instr::StoreVar(slot), sp);
                }
            }
            ExprKind::Index(_, idx) => {
                if ty != Ty::Joints {
                    if !ty.is_err() {
                        self.err(Diagnostic::error(
                            Code::E0022,
                            format!(
                                "`{base_name}` is {}, which cannot be indexed",
                                ty.described()
                            ),
                            target.span,
                        ));
                    }
                    return;
                }
                if let Some(op) = op {
                    // j[i] op= v  →  v' = j[i] op v, then j[i] = v'.
                    self.load_place(&place_load(&place), Ty::Joints, target.span);
                    let i = self.expr(idx);
                    self.coerce(i, Ty::Int, idx.span, "a joint index");
                    self.emit(Instr::JointsGet, target.span);
                    let r = self.expr(value);
                    let out =
                        self.binary_typed(op, Out::of(Ty::Num(Dim::ANGLE)), r, sp, value.span);
                    self.joint_value(out, value.span);
                } else {
                    let out = self.expr(value);
                    self.joint_value(out, value.span);
                }
                let i = self.expr(idx);
                self.coerce(i, Ty::Int, idx.span, "a joint index");
                match place {
                    Place::Local(s) => {
                        self.emit(Instr::StoreLocalJoint(s), sp);
                    }
                    Place::Var(s) => {
                        self.emit(Instr::StoreVarJoint(s), sp);
                    }
                    Place::Global(_) => {}
                }
            }
            _ => {}
        }
    }

    /// A joint value must be an angle (revolute axis) or a length (prismatic axis).
    pub(super) fn joint_value(&mut self, out: Out, span: Span) {
        match out.ty {
            Ty::Num(Dim::ANGLE) | Ty::Num(Dim::LENGTH) | Ty::Error => {}
            Ty::Int if out.is_zero_literal() => {
                self.emit(Instr::IntToNum, span);
            }
            Ty::Num(_) if out.is_zero_literal() => {}
            t => {
                let mut d = Diagnostic::error(
                    Code::E0021,
                    format!(
                        "a joint value must be an angle (or a length for a linear axis), found {}",
                        t.described()
                    ),
                    span,
                );
                if out.bare {
                    d = d.with_help("write the unit, e.g. 30deg or 500mm");
                }
                self.err(d);
            }
        }
    }

    pub(super) fn not_assignable(&mut self, span: Span, what: &str) {
        self.err(
            Diagnostic::error(Code::E0023, format!("cannot assign to {what}"), span).with_help(
                "assign to a variable, a pose field (`p.z = …`) or a joint (`j[2] = …`)",
            ),
        );
    }

    /// An `if` chain; true if every path through it diverges.
    pub(super) fn if_stmt(&mut self, branches: &[(Expr, Block)], els: Option<&Block>) -> bool {
        let mut to_end = Vec::new();
        let mut all_div = true;
        for (k, (cond, then)) in branches.iter().enumerate() {
            let c = self.expr(cond);
            self.expect_bool(&c, cond.span, "an `if` condition");
            let jf = self.emit(Instr::JumpIfFalse(0), cond.span);
            let then_div = self.block(then);
            all_div &= then_div;
            let last = k + 1 == branches.len() && els.is_none();
            if !then_div && !last {
                to_end.push(self.emit(Instr::Jump(0), then.span));
            }
            let next = self.here();
            self.patch(jf, next);
        }
        match els {
            Some(b) => all_div &= self.block(b),
            None => all_div = false,
        }
        let end = self.here();
        for j in to_end {
            self.patch(j, end);
        }
        all_div
    }

    pub(super) fn for_stmt(
        &mut self,
        var: &Ident,
        start: &Expr,
        end: &Expr,
        body: &Block,
        sp: Span,
    ) {
        self.f().scopes.push(Vec::new());
        let s = self.expr(start);
        self.coerce(s, Ty::Int, start.span, "the start of a `for` range");
        let i = self.add_local(&var.name, Ty::Int, false);
        self.store_local(i, Ty::Int, start.span);
        let e = self.expr(end);
        self.coerce(e, Ty::Int, end.span, "the end of a `for` range");
        let e_slot = self.add_local("", Ty::Int, false);
        self.store_local(e_slot, Ty::Int, end.span);
        let top = self.here();
        self.load_local(i, Ty::Int, var.span);
        self.load_local(e_slot, Ty::Int, end.span);
        self.emit(Instr::CmpI(Cmp::Lt), var.span);
        let exit = self.emit(Instr::JumpIfFalse(0), var.span);
        self.f().loops.push(Loop::default());
        self.block(body);
        let lp = self.f().loops.pop().unwrap_or_default();
        let cont = self.here();
        self.load_local(i, Ty::Int, var.span);
        self.emit(Instr::PushInt(1), var.span);
        self.emit(Instr::AddI, var.span);
        self.store_local(i, Ty::Int, var.span);
        self.emit(Instr::Jump(top as u32), sp);
        let end_pc = self.here();
        self.patch(exit, end_pc);
        for b in lp.breaks {
            self.patch(b, end_pc);
        }
        for c in lp.continues {
            self.patch(c, cont);
        }
        self.f().scopes.pop();
    }

    pub(super) fn return_stmt(&mut self, value: Option<&Expr>, sp: Span) -> bool {
        let kind = self.fk();
        let ret = self.fns.last().map_or(Ty::Void, |f| f.ret);
        match (kind, value) {
            (FnKind::Func, Some(v)) => {
                let out = self.expr(v);
                self.coerce(out, ret, v.span, "the return value");
                self.emit(Instr::RetVal, sp);
            }
            (FnKind::Func, None) => {
                self.err(
                    Diagnostic::error(Code::E0031, "this function must return a value", sp)
                        .with_help(format!("write `return value;` with {}", ret.described())),
                );
            }
            (_, Some(v)) => {
                self.err(
                    Diagnostic::error(Code::E0031, "a procedure cannot return a value", v.span)
                        .with_help("write `return;`, or make it a `func`"),
                );
                self.expr(v);
            }
            (_, None) => {
                self.emit(Instr::Ret, sp);
            }
        }
        true
    }

    /// `pulse g for t;`: the global (an int or a bool) to 1 now and back to 0 after `t`
    /// (not negative), whatever the program does meanwhile.
    fn pulse_stmt(&mut self, global: &Ident, length: &Expr, sp: Span) {
        let name = &global.name;
        let sym = match self.lookup_local(name) {
            Some(_) => Err(format!("`pulse` needs a global, and `{name}` is a local")),
            None => match self.symbols.get(name).map(|s| s.0.clone()) {
                Some(Sym::Global(g, Ty::Int | Ty::Bool)) => Ok(Some(g)),
                Some(Sym::Global(_, ty)) => Err(format!(
                    "`pulse` sets a global to 1 and back to 0, but `{name}` is {}",
                    ty.described()
                )),
                Some(_) => Err(format!("`pulse` needs a global, and `{name}` is not one")),
                None => Ok(None),
            },
        };
        let g = match sym {
            Ok(Some(g)) => Some(g),
            Ok(None) => {
                self.unknown_name(name, global.span);
                None
            }
            Err(message) => {
                self.err(
                    Diagnostic::error(Code::E0020, message, global.span).with_help(
                        "pulse an int or a bool global (`global name = 0;`): a pulse is a `set` other robots see",
                    ),
                );
                None
            }
        };
        if !self.not_in_func("pulse a global (that is a `set` event)", sp) {
            return;
        }
        self.time_operand(length, "the pulse's length");
        if let Some(g) = g {
            self.emit(Instr::PulseGlobal(g), sp);
        }
    }

    pub(super) fn move_stmt(
        &mut self,
        kind: MoveKind,
        via: Option<&Expr>,
        target: &Expr,
        MoveOptions {
            speed,
            accel,
            orient,
            zone,
            tool,
            duration,
        }: MoveOptions<'_>,
        sp: Span,
    ) {
        self.takes_time("move", sp);
        let mut flags = 0;
        if let Some(v) = via {
            let o = self.expr(v);
            match o.ty {
                Ty::Joints => flags |= MoveFlags::VIA_JOINTS,
                Ty::Pose | Ty::Error => {}
                t => self.err(Diagnostic::error(
                    Code::E0020,
                    format!(
                        "the via point of `move_c` must be a pose or joints, found {}",
                        t.described()
                    ),
                    v.span,
                )),
            }
        }
        let o = self.expr(target);
        match o.ty {
            Ty::Joints => flags |= MoveFlags::TARGET_JOINTS,
            Ty::Pose | Ty::Error => {}
            t => self.err(
                Diagnostic::error(
                    Code::E0020,
                    format!(
                        "the target of `{}` must be a pose or joints, found {}",
                        kind.keyword(),
                        t.described()
                    ),
                    target.span,
                )
                .with_help("build one with pose(x, y, z, rx, ry, rz) or joints(a1, …)"),
            ),
        }
        if let Some(s) = speed {
            flags |= MoveFlags::SPEED;
            if self.motion_rate(kind, s, Dim::SPEED, "speed") {
                flags |= MoveFlags::TCP_SPEED;
            }
        }
        if let Some(a) = accel {
            flags |= MoveFlags::ACCEL;
            self.motion_rate(kind, a, Dim::ACCEL, "acceleration");
        }
        if let Some(o) = orient {
            flags |= MoveFlags::ORIENT;
            if kind == MoveKind::J {
                self.err(
                    Diagnostic::error(
                        Code::E0022,
                        "`orient` bounds how fast a `move_l` or `move_c` turns the TCP; a `move_j` has no orientation path",
                        o.span,
                    )
                    .with_help("remove `orient`, or give the speed of the axes with `speed`"),
                );
            }
            self.motion_rate(MoveKind::L, o, Dim::ANGSPEED, "orientation speed");
        }
        match zone {
            None => {}
            Some(Zone::Fine) => {
                flags |= MoveFlags::ZONE;
                self.emit(Instr::PushNum(0.0), sp);
            }
            Some(Zone::Radius(e)) => {
                flags |= MoveFlags::ZONE;
                self.zone_size(kind, e, Dim::LENGTH, "zone");
            }
            Some(Zone::Extended(z)) => {
                let ExtendedZone { radius, ori, angle } = &**z;
                flags |= MoveFlags::ZONE | MoveFlags::ZONE_ORI;
                self.zone_size(kind, radius, Dim::LENGTH, "zone");
                self.zone_size(kind, ori, Dim::LENGTH, "orientation zone");
                match angle {
                    Some(a) => self.zone_size(kind, a, Dim::ANGLE, "orientation zone's angle"),
                    // (No bound: no motion turns its tool by more than π.)
                    None => {
                        self.emit(Instr::PushNum(std::f64::consts::PI), ori.span);
                    }
                }
            }
        }
        if let Some(t) = tool {
            flags |= MoveFlags::TOOL;
            let out = self.expr(t);
            let what = format!("the tool of `{}`", kind.keyword());
            self.coerce(out, Ty::Pose, t.span, &what);
        }
        if let Some(d) = duration {
            flags |= MoveFlags::DURATION;
            if let Some(s) = speed {
                self.err(
                    Diagnostic::error(
                        Code::E0022,
                        format!(
                            "`{}` is given both a `speed` and a `duration`: the duration sets the speed",
                            kind.keyword()
                        ),
                        d.span,
                    )
                    .with_related(s.span, "the speed")
                    .with_help("keep one of them"),
                );
            }
            self.motion_rate(kind, d, Dim::TIME, "duration");
        }
        let f = MoveFlags(flags);
        self.emit(
            match kind {
                MoveKind::J => Instr::MoveJ(f),
                MoveKind::L => Instr::MoveL(f),
                MoveKind::C => Instr::MoveC(f),
            },
            sp,
        );
    }

    /// The `speed`/`accel` option of a motion: a ratio for `move_j`, else `dim` (> 0).
    /// A `move_j` may also take a TCP speed (`speed 250mm/s`): then it returns true.
    /// A zone's size `e` (a `dim`, not negative), pushed.
    fn zone_size(&mut self, kind: MoveKind, e: &Expr, dim: Dim, what: &str) {
        let out = self.expr(e);
        let what = format!("the {what} of `{}`", kind.keyword());
        let out = self.coerce(out, Ty::Num(dim), e.span, &what);
        if let Some(ConstValue::Num(x)) = out.k
            && (x.is_nan() || x < 0.0)
        {
            self.err(
                Diagnostic::error(Code::E0025, format!("{what} cannot be negative"), e.span)
                    .with_help(if what.starts_with("the zone ") {
                        "write a radius such as `zone 10mm`, or `zone fine` to stop at the point"
                    } else {
                        "write an orientation zone such as `zone 10mm ori 15mm 1.5deg`: a radius, and the most it turns the tool"
                    }),
            );
        }
    }

    pub(super) fn motion_rate(&mut self, kind: MoveKind, e: &Expr, dim: Dim, what: &str) -> bool {
        let out = self.expr(e);
        let what = format!("the {what} of `{}`", kind.keyword());
        let tcp_speed = kind == MoveKind::J && dim == Dim::SPEED && out.ty == Ty::Num(Dim::SPEED);
        if kind == MoveKind::J && !tcp_speed && (dim == Dim::SPEED || dim == Dim::ACCEL) {
            self.ratio(out, e.span, &what, "50%");
            return false;
        }
        let out = self.coerce(out, Ty::Num(dim), e.span, &what);
        if let Some(ConstValue::Num(x)) = out.k
            && x <= 0.0
        {
            self.err(Diagnostic::error(
                Code::E0025,
                format!("{what} must be greater than zero"),
                e.span,
            ));
        }
        tcp_speed
    }

    /// A ratio such as `50%`: a plain number in (0, 1], written with `%` when literal.
    pub(super) fn ratio(&mut self, out: Out, span: Span, what: &str, example: &str) {
        if out.bare {
            self.err(
                Diagnostic::error(
                    Code::E0021,
                    format!("{what} is a ratio; a bare number is ambiguous"),
                    span,
                )
                .with_label("write the unit")
                .with_help(format!("write a percentage such as {example}")),
            );
            return;
        }
        let out = self.coerce(out, Ty::Num(Dim::PLAIN), span, what);
        if let Some(ConstValue::Num(x)) = out.k
            && !(x > 0.0 && x <= 1.0)
        {
            self.err(
                Diagnostic::error(
                    Code::E0025,
                    format!("{what} must be more than 0% and at most 100%"),
                    span,
                )
                .with_help("the ratio is of each axis's maximum"),
            );
        }
    }

    pub(super) fn time_operand(&mut self, e: &Expr, what: &str) -> Out {
        let out = self.expr(e);
        let out = self.coerce(out, Ty::Num(Dim::TIME), e.span, what);
        if let Some(ConstValue::Num(x)) = out.k
            && x < 0.0
        {
            self.err(Diagnostic::error(
                Code::E0025,
                format!("{what} cannot be negative"),
                e.span,
            ));
        }
        out
    }

    /// E0063: `what` would leave a `parallel` block's local branch before its join.
    pub(super) fn leaves_parallel(&mut self, what: &str, sp: Span) {
        self.err(
            Diagnostic::error(
                Code::E0063,
                format!("{what} cannot leave a `parallel` block: its remote work would never be joined"),
                sp,
            )
            .with_help("end the local branch normally, and decide after the block (set a variable here, test it after `}`)"),
        );
    }

    pub(super) fn parallel(&mut self, branches: &[Stmt], sp: Span) {
        self.takes_time("run `parallel` work", sp);
        let mut local: Option<&Block> = None;
        let mut remotes = Vec::new();
        for b in branches {
            match &b.kind {
                StmtKind::Remote { robot, proc, args } => remotes.push((robot, proc, args, b.span)),
                StmtKind::Block(blk) => {
                    if let Some(first) = local {
                        self.err(
                            Diagnostic::error(Code::E0061, "a `parallel` block has at most one local branch", blk.span)
                                .with_related(first.span, "the first local branch")
                                .with_help("merge the local branches into one block: this robot can only do one thing at a time"),
                        );
                    } else {
                        local = Some(blk);
                    }
                }
                StmtKind::Error => {}
                _ => self.err(
                    Diagnostic::error(
                        Code::E0062,
                        "only `remote` calls and one `{ … }` block may stand in `parallel`",
                        b.span,
                    )
                    .with_help("put this robot's own statements in one `{ … }` branch"),
                ),
            }
        }
        self.emit(Instr::ParBegin, sp);
        for (robot, proc, args, bsp) in remotes {
            let mut types = Vec::new();
            for a in args {
                let o = self.expr(a);
                match o.ty.vm() {
                    Some(t) => types.push(t),
                    None => {
                        if !o.ty.is_err() {
                            self.err(Diagnostic::error(
                                Code::E0020,
                                format!("a remote argument cannot be {}", o.ty.described()),
                                a.span,
                            ));
                        }
                        types.push(Type::Int);
                    }
                }
            }
            let r = self.str(&robot.name);
            let p = self.str(&proc.name);
            let pos = self.pos(bsp);
            self.m.remotes.push(RemoteSite {
                robot: r,
                proc: p,
                args: types,
                pos,
            });
            let i = (self.m.remotes.len() - 1) as u32;
            self.emit(Instr::Remote(i), bsp);
        }
        if let Some(b) = local {
            let open = self.f().loops.len();
            let was = self.f().in_parallel.replace(open);
            self.block(b);
            self.f().in_parallel = was;
        }
        self.emit(Instr::ParJoin, sp);
    }

    pub(super) fn load_place(&mut self, l: &Load, ty: Ty, span: Span) {
        let w = ty.width();
        match *l {
            Load::Local(s) => self.load_local(s, ty, span),
            Load::Var(s) => {
                self.emit(
                    if w == 1 {
                        Instr::LoadVar(s)
                    } else {
                        Instr::LoadVarN(s, w)
                    },
                    span,
                );
            }
            Load::Global(g) => {
                self.emit(Instr::LoadGlobal(g), span);
            }
        }
    }
}

/// The options of a motion statement.
pub(super) struct MoveOptions<'a> {
    pub(super) speed: Option<&'a Expr>,
    pub(super) accel: Option<&'a Expr>,
    pub(super) orient: Option<&'a Expr>,
    pub(super) zone: Option<&'a Zone>,
    pub(super) tool: Option<&'a Expr>,
    pub(super) duration: Option<&'a Expr>,
}
