//! The rules over conditions and handlers: `wait_until` and `when` conditions compiled
//! into capture procedures, handler triggers and arguments, `log` formats, and the checks
//! closed over the call graph at the end (handlers take no time, every condition lists the
//! globals it reads, `disable` names a handler procedure).

use super::*;

impl Compiler<'_> {
    /// Compiles a `wait_until`/`when` condition into a condition function; returns its index.
    pub(super) fn condition(&mut self, cond: &Expr, what: &str) -> u32 {
        let n = self.m.conds.len();
        let func = self.new_proc(&format!("cond#{n}"), ProcKind::Cond, cond.span);
        self.m.procs[func as usize].ret = Some(Type::Bool);
        self.fns.push(FnCtx::new(func, FnKind::Cond, Ty::Bool));
        let out = self.expr(cond);
        self.expect_bool(&out, cond.span, what);
        if let Some(ConstValue::Bool(_)) = out.k {
            // Constant conditions still compile (as a push) and fail the global rule below.
        }
        self.emit(Instr::RetVal, cond.span);
        let f = self.finish_fn();
        let captures = self.set_capture_params(func, &f);
        let pos = self.pos(cond.span);
        self.m.conds.push(CondInfo {
            func,
            captures,
            globals: Vec::new(),
            pos,
        });
        self.pending_conds.push(PendingCond {
            cond: n as u32,
            span: cond.span,
        });
        n as u32
    }

    pub(super) fn set_capture_params(&mut self, proc: u32, f: &FnCtx) -> Vec<Capture> {
        let mut params = Vec::new();
        let mut caps = Vec::new();
        for (name, outer_slot, width, ty) in &f.captures {
            let n = self.str(name);
            params.push(ParamInfo {
                name: n,
                ty: ty.vm().unwrap_or(Type::Int),
            });
            caps.push(Capture {
                slot: *outer_slot,
                width: *width,
            });
        }
        self.m.procs[proc as usize].params = params;
        caps
    }

    pub(super) fn when_stmt(
        &mut self,
        trigger: &TriggerExpr,
        handler: &Ident,
        args: &[Expr],
        sp: Span,
    ) {
        if !self.not_in_func("enable handlers", sp) {
            return;
        }
        let target = match self.symbols.get(&handler.name).map(|s| s.0.clone()) {
            Some(Sym::Proc(p)) if !self.sigs[p as usize].is_func => Some(p),
            Some(Sym::Proc(_)) => {
                self.err(
                    Diagnostic::error(
                        Code::E0051,
                        format!(
                            "`{}` is a function; a handler must be a procedure",
                            handler.name
                        ),
                        handler.span,
                    )
                    .with_help("make it a `proc`"),
                );
                None
            }
            Some(_) => {
                self.err(Diagnostic::error(
                    Code::E0051,
                    format!("`{}` is not a procedure", handler.name),
                    handler.span,
                ));
                None
            }
            None => {
                self.unknown_proc(&handler.name, handler.span);
                None
            }
        };
        let trig = match trigger {
            TriggerExpr::Cond(c) => Trigger::Condition(self.condition(c, "a `when` condition")),
            TriggerExpr::EveryCycles(_) => Trigger::EveryCycles,
            TriggerExpr::Every(_) => Trigger::Every,
            TriggerExpr::After(_) => Trigger::After,
        };
        let Some(target) = target else {
            for a in args {
                self.expr(a);
            }
            return;
        };
        // The action: evaluates the arguments when the handler fires, then calls the target.
        let h = self.m.handlers.len();
        let action = self.new_proc(&format!("when#{h}"), ProcKind::Handler, sp);
        self.fns.push(FnCtx::new(action, FnKind::Handler, Ty::Void));
        self.call_args(target, args, sp);
        self.emit(Instr::Call(target), sp);
        self.facts().calls.push((target, handler.span));
        self.emit(Instr::Ret, sp);
        let f = self.finish_fn();
        let captures = self.set_capture_params(action, &f);
        self.pending_handlers
            .push(PendingHandler { target, span: sp });
        // The trigger operand, evaluated when the handler is enabled.
        match trigger {
            TriggerExpr::EveryCycles(n) => {
                let o = self.expr(n);
                let o = self.coerce(o, Ty::Int, n.span, "a cycle count");
                if let Some(ConstValue::Int(k)) = o.k
                    && k <= 0
                {
                    self.err(Diagnostic::error(
                        Code::E0025,
                        "the cycle count must be at least 1",
                        n.span,
                    ));
                }
            }
            TriggerExpr::Every(t) | TriggerExpr::After(t) => {
                let o = self.time_operand(t, "a handler period");
                if matches!(trigger, TriggerExpr::Every(_))
                    && let Some(ConstValue::Num(x)) = o.k
                    && x <= 0.0
                {
                    self.err(Diagnostic::error(
                        Code::E0025,
                        "the period must be greater than zero",
                        t.span,
                    ));
                }
            }
            TriggerExpr::Cond(_) => {}
        }
        let pos = self.pos(sp);
        self.m.handlers.push(HandlerInfo {
            trigger: trig,
            action,
            target,
            captures,
            pos,
        });
        self.emit(Instr::When(h as u32), sp);
    }

    pub(super) fn log_format(&mut self, args: &[Expr]) -> u32 {
        let mut parts = Vec::new();
        for a in args {
            if let ExprKind::Str(s) = &a.kind {
                let i = self.str(s);
                parts.push(LogPart::Text(i));
                continue;
            }
            let o = self.expr(a);
            match o.ty.vm() {
                Some(t) => parts.push(LogPart::Value(t)),
                None if o.ty.is_err() => {}
                None => self.err(Diagnostic::error(
                    Code::E0020,
                    format!("cannot write {} in a message", o.ty.described()),
                    a.span,
                )),
            }
        }
        self.m.log_formats.push(LogFormat { parts });
        (self.m.log_formats.len() - 1) as u32
    }

    /// The chain of calls from `from` to a procedure that takes time, if any.
    pub(super) fn time_path(&self, from: u32) -> Option<(Vec<u32>, String, Span)> {
        let mut seen = vec![false; self.facts.len()];
        let mut stack = vec![(from, vec![from])];
        while let Some((p, path)) = stack.pop() {
            if std::mem::replace(&mut seen[p as usize], true) {
                continue;
            }
            if let Some((what, span)) = &self.facts[p as usize].time {
                return Some((path, what.clone(), *span));
            }
            for (c, _) in self.facts[p as usize].calls.iter().rev() {
                let mut next = path.clone();
                next.push(*c);
                stack.push((*c, next));
            }
        }
        None
    }

    pub(super) fn check_handlers(&mut self) {
        let pending = std::mem::take(&mut self.pending_handlers);
        let mut reported = BTreeSet::new();
        for h in pending {
            let Some((path, what, span)) = self.time_path(h.target) else {
                continue;
            };
            if !reported.insert((h.target, h.span.start)) {
                continue;
            }
            let names: Vec<&str> = path
                .iter()
                .map(|p| self.sigs[*p as usize].name.as_str())
                .collect();
            let target = names.first().copied().unwrap_or("?").to_string();
            let mut d = Diagnostic::error(Code::E0050, format!("the handler `{target}` may {what}, but handlers run in zero time"), h.span)
                .with_label("handler enabled here")
                .with_related(span, format!("it would {what} here"))
                .with_help("a handler runs while the robot's motion goes on: set a global or send a signal, and let the main program move");
            if names.len() > 1 {
                d = d.with_note(format!("called through {}", names.join(" → ")));
            }
            self.err(d);
        }
    }

    pub(super) fn finish_conds(&mut self) {
        let pending = std::mem::take(&mut self.pending_conds);
        for pc in pending {
            let func = self.m.conds[pc.cond as usize].func;
            // Every function reachable from the condition.
            let mut globals = BTreeSet::new();
            let mut seen = vec![false; self.facts.len()];
            // (function, the function the condition itself calls on the way to it)
            let mut stack = vec![(func, None::<u32>)];
            let mut impure: Option<(String, Span, u32, u32)> = None;
            while let Some((p, top)) = stack.pop() {
                if std::mem::replace(&mut seen[p as usize], true) {
                    continue;
                }
                let f = &self.facts[p as usize];
                globals.extend(f.globals.iter().copied());
                if let (Some(top), None, Some((what, span))) = (top, &impure, &f.impure) {
                    impure = Some((what.clone(), *span, top, p));
                }
                for (c, _) in f.calls.iter().rev() {
                    stack.push((*c, top.or(Some(*c))));
                }
            }
            if let Some((what, span, top, holder)) = impure {
                let name = |p: u32| {
                    self.sigs
                        .get(p as usize)
                        .map_or(String::new(), |s| s.name.clone())
                };
                let (fname, inner) = (name(top), name(holder));
                let code = if what.starts_with("the module variable") {
                    Code::E0042
                } else {
                    Code::E0041
                };
                self.err(
                    Diagnostic::error(
                        code,
                        if fname == inner {
                            format!("this condition calls `{fname}`, which reads {what}")
                        } else {
                            format!("this condition calls `{fname}`, which (through `{inner}`) reads {what}")
                        },
                        pc.span,
                    )
                    .with_related(span, format!("read here, in `{inner}`"))
                    .with_help("a condition is re-checked only when a global it reads is set, so it may depend only on globals, constants and locals"),
                );
            } else if globals.is_empty() {
                self.err(
                    Diagnostic::error(Code::E0040, "this condition can never change: it reads no global", pc.span)
                        .with_help("a condition is re-checked when a global it reads is set; use a `global`, or `delay`/`timeout`/`after` for time"),
                );
            }
            self.m.conds[pc.cond as usize].globals = globals.into_iter().collect();
        }
    }

    pub(super) fn check_disables(&mut self) {
        let targets: BTreeSet<u32> = self.m.handlers.iter().map(|h| h.target).collect();
        for (p, span) in std::mem::take(&mut self.disabled) {
            if !targets.contains(&p) {
                let name = self.sigs[p as usize].name.clone();
                self.err(
                    Diagnostic::error(Code::W0002, format!("no `when` in this module calls `{name}`, so `disable {name}` does nothing"), span)
                        .with_help("`disable p` turns off the handlers enabled with `when … do p(…)`"),
                );
            }
        }
    }
}
