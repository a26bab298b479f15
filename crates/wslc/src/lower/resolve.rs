//! Name resolution: type names, the symbol table, procedure signatures,
//! globals, constants and module variables (their initializers evaluated at compile time),
//! and each procedure body's frame.

use super::*;

impl Compiler<'_> {
    pub(super) fn resolve_type(&mut self, t: &Ident) -> Ty {
        let d = match t.name.as_str() {
            "bool" => return Ty::Bool,
            "int" => return Ty::Int,
            "num" => Dim::PLAIN,
            "length" => Dim::LENGTH,
            "angle" => Dim::ANGLE,
            "time" => Dim::TIME,
            "speed" => Dim::SPEED,
            "angspeed" => Dim::ANGSPEED,
            "accel" => Dim::ACCEL,
            "angaccel" => Dim::ANGACCEL,
            "joints" => return Ty::Joints,
            "pose" => return Ty::Pose,
            "text" if self.texts => return Ty::Text,
            "string" => {
                self.err(
                    Diagnostic::error(
                        Code::E0014,
                        "`string` values cannot be stored or passed",
                        t.span,
                    )
                    .with_help("text is only written directly in `log` and `fail`"),
                );
                return Ty::Error;
            }
            _ => {
                self.err(
                    Diagnostic::error(Code::E0014, format!("unknown type `{}`", t.name), t.span)
                        .with_help(format!("the types are {TYPE_NAMES}")),
                );
                return Ty::Error;
            }
        };
        Ty::Num(d)
    }

    pub(super) fn declare(&mut self, name: &Ident, sym: Sym) -> bool {
        if builtin_named(&name.name).is_some() {
            self.err(
                Diagnostic::error(
                    Code::E0012,
                    format!("`{}` is a built-in function", name.name),
                    name.span,
                )
                .with_help("choose another name"),
            );
            return false;
        }
        if let Some((_, prev)) = self.symbols.get(&name.name) {
            let prev = *prev;
            self.err(
                Diagnostic::error(
                    Code::E0012,
                    format!("`{}` is declared twice", name.name),
                    name.span,
                )
                .with_label("declared again here")
                .with_related(prev, "first declared here"),
            );
            return false;
        }
        self.symbols.insert(name.name.clone(), (sym, name.span));
        true
    }

    pub(super) fn module(&mut self, ast: &SourceModule) {
        // 1. Procedure signatures, so calls may come before declarations.
        let mut bodies = Vec::new();
        for item in &ast.items {
            if let Item::Proc(p) = item {
                let params: Vec<(String, Ty)> = p
                    .params
                    .iter()
                    .map(|a| (a.name.name.clone(), self.resolve_type(&a.ty)))
                    .collect();
                for (i, a) in p.params.iter().enumerate() {
                    if p.params[..i].iter().any(|b| b.name.name == a.name.name) {
                        self.err(Diagnostic::error(
                            Code::E0012,
                            format!("parameter `{}` is declared twice", a.name.name),
                            a.name.span,
                        ));
                    }
                }
                let ret = match (&p.ret, p.is_func) {
                    (Some(t), true) => self.resolve_type(t),
                    (None, true) => {
                        self.err(
                            Diagnostic::error(
                                Code::E0014,
                                format!("function `{}` needs a return type", p.name.name),
                                p.span,
                            )
                            .with_help(format!(
                                "write `func {}(…) -> length {{ … }}`, or make it a `proc`",
                                p.name.name
                            )),
                        );
                        Ty::Error
                    }
                    (Some(t), false) => {
                        self.err(
                            Diagnostic::error(
                                Code::E0031,
                                "a `proc` does not return a value",
                                t.span,
                            )
                            .with_help(
                                "make it a `func` (which runs in zero time), or drop `-> type`",
                            ),
                        );
                        Ty::Void
                    }
                    (None, false) => Ty::Void,
                };
                let kind = if p.is_func {
                    ProcKind::Func
                } else {
                    ProcKind::Proc
                };
                let idx = self.new_proc(&p.name.name, kind, p.name.span);
                let mut pinfo = Vec::new();
                for (n, t) in &params {
                    let name = self.str(n);
                    pinfo.push(ParamInfo {
                        name,
                        ty: t.vm().unwrap_or(Type::Int),
                    });
                }
                self.m.procs[idx as usize].params = pinfo;
                self.m.procs[idx as usize].ret = if p.is_func {
                    ret.vm().or(Some(Type::Int))
                } else {
                    None
                };
                self.sigs.push(Sig {
                    name: p.name.name.clone(),
                    is_func: p.is_func,
                    params,
                    ret,
                    span: p.name.span,
                });
                if self.declare(&p.name, Sym::Proc(idx)) {
                    bodies.push((idx, p));
                }
            }
        }
        // 2. Globals, constants, module variables, in order.
        for item in &ast.items {
            match item {
                Item::Global(d) => self.global_decl(d),
                Item::Const(d) => self.const_decl(d),
                Item::Param(d) => self.param_decl(d),
                Item::Var(d) => self.var_decl(d),
                Item::Proc(_) => {}
            }
        }
        // 3. Bodies.
        for (idx, p) in bodies {
            self.proc_body(idx, p);
        }
        // 4. Whole-module rules over the call graph.
        self.check_handlers();
        self.finish_conds();
        self.check_disables();
        // 5. Lay out the code.
        for (i, (code, lines)) in self.proc_code.iter().enumerate() {
            let start = self.m.code.len() as u32;
            self.m.procs[i].code_start = start;
            self.m.procs[i].code_len = code.len() as u32;
            self.m.code.extend_from_slice(code);
            for (pc, pos) in lines {
                let pc = start + pc;
                if self.m.lines.last().is_none_or(|l| l.pos != *pos) {
                    self.m.lines.push(LineEntry { pc, pos: *pos });
                }
            }
        }
    }

    /// Evaluates a module-level initializer; `None` if it is not constant (reported).
    pub(super) fn init_value(&mut self, d: &VarDecl, what: &str) -> Option<(Ty, ConstValue)> {
        let declared = d.ty.as_ref().map(|t| self.resolve_type(t));
        let Some(init) = &d.init else {
            let ty = declared?;
            return ty.vm().map(|t| (ty, ConstValue::zero(t)));
        };
        self.fns.push(FnCtx::new(0, FnKind::Init, Ty::Void));
        let mut out = self.expr(init);
        if let Some(t) = declared {
            out = self.coerce(out, t, init.span, &format!("the {what} `{}`", d.name.name));
        }
        self.finish_fn();
        if out.ty.is_err() {
            return None;
        }
        match out.k {
            Some(v) => Some((out.ty, v)),
            None => {
                self.err(
                    Diagnostic::error(
                        Code::E0080,
                        format!("the initial value of {what} `{}` is not a constant", d.name.name),
                        init.span,
                    )
                    .with_help("module-level values are computed before the run: use literals, constants declared above, and arithmetic"),
                );
                None
            }
        }
    }

    pub(super) fn global_decl(&mut self, d: &VarDecl) {
        let Some((ty, v)) = self.init_value(d, "global") else {
            return;
        };
        if !matches!(ty, Ty::Bool | Ty::Int | Ty::Num(_)) {
            self.err(
                Diagnostic::error(Code::E0081, format!("global `{}` would be {}", d.name.name, ty.described()), d.name.span)
                    .with_help("globals are bool, int or a number (with any unit); keep poses and joints in `const` or `var`"),
            );
            return;
        }
        let idx = self.m.globals.len() as u32;
        if self.declare(&d.name, Sym::Global(idx, ty)) {
            let name = self.str(&d.name.name);
            let pos = self.pos(d.name.span);
            self.m.globals.push(GlobalInfo {
                name,
                ty: ty.vm().unwrap_or(Type::Int),
                init: v,
                pos,
            });
        }
    }

    pub(super) fn const_decl(&mut self, d: &VarDecl) {
        let Some((ty, v)) = self.init_value(d, "constant") else {
            return;
        };
        if self.declare(&d.name, Sym::Const(ty, v.clone())) {
            let name = self.str(&d.name.name);
            let pos = self.pos(d.name.span);
            let vty = ty.vm().unwrap_or(Type::Int);
            // The initializer may have put the same value in the pool: name that entry.
            if let Some(c) = self
                .m
                .consts
                .iter_mut()
                .find(|c| c.name.is_none() && c.ty == vty && c.value == v)
            {
                c.name = Some(name);
                c.pos = pos;
                return;
            }
            self.m.consts.push(ConstInfo {
                name: Some(name),
                ty: ty.vm().unwrap_or(Type::Int),
                value: v,
                pos,
            });
        }
    }

    pub(super) fn var_decl(&mut self, d: &VarDecl) {
        let Some((ty, v)) = self.init_value(d, "variable") else {
            return;
        };
        self.module_var(d, ty, v, false);
    }

    /// `param name = default;`: a module variable the program reads and the cell loader
    /// may set (a bool, an int or a number with its unit, like a global).
    pub(super) fn param_decl(&mut self, d: &VarDecl) {
        if d.init.is_none() {
            self.err(
                Diagnostic::error(
                    Code::E0083,
                    format!("parameter `{}` has no default value", d.name.name),
                    d.name.span,
                )
                .with_help(format!(
                    "give the value it has when no workcell or sweep sets it: `param {}: … = …;`",
                    d.name.name
                )),
            );
            return;
        }
        let Some((ty, v)) = self.init_value(d, "parameter") else {
            return;
        };
        if !matches!(ty, Ty::Bool | Ty::Int | Ty::Num(_)) {
            self.err(
                Diagnostic::error(Code::E0082, format!("parameter `{}` would be {}", d.name.name, ty.described()), d.name.span)
                    .with_help("parameters are bool, int or a number (with any unit), so that a workcell can set them; build poses from them in the program"),
            );
        }
        // (Declared even when wrong, so that its uses do not add `unknown name` errors.)
        self.module_var(d, ty, v, true);
    }

    fn module_var(&mut self, d: &VarDecl, ty: Ty, v: ConstValue, param: bool) {
        let slot = self.m.var_slots;
        let sym = if param {
            Sym::Param(slot, ty)
        } else {
            Sym::Var(slot, ty)
        };
        if self.declare(&d.name, sym) {
            self.m.var_slots += u32::from(ty.width());
            let name = self.str(&d.name.name);
            let pos = self.pos(d.name.span);
            self.m.vars.push(VarInfo {
                name,
                ty: ty.vm().unwrap_or(Type::Int),
                slot,
                init: v,
                pos,
                param,
            });
        }
    }

    pub(super) fn proc_body(&mut self, idx: u32, p: &ProcDecl) {
        let sig = self.sigs[idx as usize].clone();
        let kind = if p.is_func {
            FnKind::Func
        } else {
            FnKind::Proc
        };
        self.fns.push(FnCtx::new(idx, kind, sig.ret));
        if p.handler.is_some() {
            self.f().stmts = Some(Vec::new());
        }
        for (name, ty) in &sig.params {
            self.add_local(name, *ty, true);
        }
        let diverges = self.block(&p.body);
        if p.is_func {
            if !diverges && !sig.ret.is_err() {
                let end = Span::new(
                    p.body.span.end.saturating_sub(1) as usize,
                    p.body.span.end as usize,
                );
                self.err(
                    Diagnostic::error(
                        Code::E0032,
                        format!(
                            "function `{}` may end without returning a value",
                            p.name.name
                        ),
                        end,
                    )
                    .with_label("the end can be reached here")
                    .with_help("end every path with `return value;` (or `fail \"…\";`)"),
                );
            }
        } else {
            self.emit(
                Instr::Ret,
                Span::new(
                    p.body.span.end.saturating_sub(1) as usize,
                    p.body.span.end as usize,
                ),
            );
        }
        if let Some(h) = &p.handler {
            // A function's body ends in `return`; a TRYNEXT past its last statement comes
            // here, before the handler, and ends the run.
            if p.is_func {
                let end = Span::new(
                    p.body.span.end.saturating_sub(1) as usize,
                    p.body.span.end as usize,
                );
                let text = Expr {
                    kind: ExprKind::Str(format!(
                        "function `{}` ended without a value (its error handler went on after its last statement)",
                        p.name.name
                    )),
                    span: end,
                };
                let f = self.log_format(&[text]);
                self.emit(Instr::Fail(f), end);
            }
            // The error handler: after the body; reaching its end returns from the
            // procedure (a function's error goes on to its caller).
            let stmts = self.f().stmts.take().unwrap_or_default();
            let pc = self.here() as u32;
            self.f().in_handler = true;
            if !self.block(h) {
                let end = Span::new(h.span.end.saturating_sub(1) as usize, h.span.end as usize);
                self.emit(
                    if p.is_func {
                        Instr::RaiseUp
                    } else {
                        Instr::Ret
                    },
                    end,
                );
            }
            if let Some(info) = self.m.procs.get_mut(idx as usize) {
                info.handler = Some(vworks_vm::bytecode::ErrorHandler { pc, stmts });
            }
        }
        self.finish_fn();
    }

    pub(super) fn add_local(&mut self, name: &str, ty: Ty, mutable: bool) -> u32 {
        let f = self.f();
        let slot = f.next_slot;
        f.next_slot += u32::from(ty.width());
        if let Some(scope) = f.scopes.last_mut() {
            scope.push(Local {
                name: name.to_string(),
                slot,
                ty,
                mutable,
            });
        }
        slot
    }
}
