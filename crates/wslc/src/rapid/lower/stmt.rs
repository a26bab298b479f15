//! RAPID statements and instructions to WSL statements: assignments (whole data, record
//! components, array elements), flow (`IF`, `WHILE`, `FOR`, `TEST`, `RETURN`, `EXIT`), the
//! motion instructions, waits and messages, and calls of the task's own routines.

use std::collections::BTreeMap;

use vworks_vm::Dim;

use super::data::{Ty, build as b};
use super::expr::article;
use super::table::Call;
use super::{Data, Sym, Tr, block};
use crate::diag::Code;
use crate::rapid::catalog::Kind;
use crate::rapid::syntax::{self as r, Arg, Storage};
use crate::syntax::{self as w, Span};

impl Tr<'_> {
    /// A statement list in a scope of its own.
    pub(crate) fn stmts(&mut self, ss: &[r::Stmt]) -> Vec<w::Stmt> {
        self.locals.push(BTreeMap::new());
        let mut out = Vec::new();
        for s in ss {
            self.stmt(s, &mut out);
        }
        self.locals.pop();
        out
    }

    fn stmt(&mut self, s: &r::Stmt, out: &mut Vec<w::Stmt>) {
        // In a routine with an error handler each statement is one for RETRY/TRYNEXT.
        if self
            .routine
            .as_ref()
            .is_some_and(|cx| cx.has_handler && !cx.in_handler)
        {
            let mut inner = Vec::new();
            self.stmt_lowered(s, &mut inner);
            out.push(w::Stmt {
                kind: w::StmtKind::Recover(block(inner, s.span)),
                span: s.span,
            });
        } else {
            self.stmt_lowered(s, out);
        }
    }

    fn stmt_lowered(&mut self, s: &r::Stmt, out: &mut Vec<w::Stmt>) {
        let span = s.span;
        let mut push = |kind| out.push(w::Stmt { kind, span });
        match &s.kind {
            r::StmtKind::Assign { target, value } => {
                for a in self.assign(target, value, span) {
                    push(a);
                }
            }
            r::StmtKind::Call { name, args } => self.call(name, args, span, out),
            r::StmtKind::If { branches, els } => {
                let mut wb = Vec::new();
                for (c, body) in branches {
                    let cond = self.condition(c);
                    let body = self.stmts(body);
                    wb.push((cond, block(body, span)));
                }
                let els = els.as_ref().map(|e| block(self.stmts(e), span));
                push(w::StmtKind::If { branches: wb, els });
            }
            r::StmtKind::While { cond, body } => {
                let cond = self.condition(cond);
                self.in_loop(1);
                let body = block(self.stmts(body), span);
                self.in_loop(-1);
                push(w::StmtKind::While { cond, body });
            }
            r::StmtKind::For {
                var,
                from,
                to,
                step,
                body,
            } => {
                self.in_loop(1);
                let k = self.for_loop(var, from, to, step.as_ref(), body, span);
                self.in_loop(-1);
                push(k);
            }
            r::StmtKind::Test {
                value,
                cases,
                default,
            } => {
                let k = self.test(value, cases, default.as_deref(), span);
                push(k);
            }
            r::StmtKind::Return(v) => {
                let ret = self.routine.as_ref().and_then(|r| r.ret);
                let kind = self.routine.as_ref().map(|r| r.kind);
                match (v, ret) {
                    (Some(e), Some(t)) => {
                        let v = self.value(e, t).map(super::Val::leaf);
                        push(w::StmtKind::Return(
                            v.or(Some(b::expr(w::ExprKind::Error, span))),
                        ));
                    }
                    (None, None) => push(w::StmtKind::Return(None)),
                    (Some(e), None) => {
                        self.error(Code::E0031, "a PROC or TRAP returns no value", e.span)
                            .help = Some("write `RETURN;`, or make the routine a FUNC".into());
                    }
                    (None, Some(t)) => {
                        let _ = kind;
                        self.error(
                            Code::E0031,
                            format!("this FUNC returns {}: give `RETURN value;`", article(t)),
                            span,
                        );
                    }
                }
            }
            r::StmtKind::Exit => push(w::StmtKind::Stop),
            // Bound for the whole task before any routine (`collect_connects`).
            r::StmtKind::Connect { .. } => {}
            r::StmtKind::Raise(errno) => {
                let in_handler = self.routine.as_ref().is_some_and(|cx| cx.in_handler);
                match errno {
                    Some(e) if in_handler => {
                        self.error(
                            Code::E0304,
                            "`RAISE` with an error number inside an error handler",
                            e.span,
                        )
                        .help = Some("write `RAISE;`: it raises the handler's error again in the calling routine".into());
                    }
                    Some(e) => {
                        if let Some(v) = self.value(e, Ty::Num) {
                            let n = b::call("int", vec![v.leaf()], e.span);
                            push(w::StmtKind::Raise(Some(n), "RAISE".into()));
                        }
                    }
                    None if in_handler => push(w::StmtKind::Raise(None, String::new())),
                    None => {
                        self.error(
                            Code::E0304,
                            "`RAISE;` without an error number outside an error handler",
                            span,
                        )
                        .help = Some("give the error's number (`RAISE ERR_MYERR;`), or move it into the routine's ERROR clause".into());
                    }
                }
            }
            r::StmtKind::Goto(label) => {
                if let Some(kind) = self.goto(label) {
                    for k in kind {
                        push(k);
                    }
                }
            }
            r::StmtKind::Label(label) => self.misplaced_label(label),
            r::StmtKind::Retry | r::StmtKind::TryNext => {
                let retry = matches!(s.kind, r::StmtKind::Retry);
                if self.routine.as_ref().is_some_and(|cx| cx.in_handler) {
                    push(if retry {
                        w::StmtKind::Retry
                    } else {
                        w::StmtKind::TryNext
                    });
                } else {
                    self.error(
                        Code::E0304,
                        format!(
                            "{} outside an error handler",
                            if retry { "RETRY" } else { "TRYNEXT" }
                        ),
                        span,
                    )
                    .help = Some("it goes in the routine's ERROR clause".into());
                }
            }
            r::StmtKind::Unsupported(what) => {
                self.unsupported(what, span, "write the program without it");
            }
            r::StmtKind::Error => {}
        }
    }

    /// A condition: a bool.
    fn condition(&mut self, c: &r::Expr) -> w::Expr {
        match self.expr(c) {
            Some(v) if v.ty == Ty::Bool => v.leaf(),
            Some(v) => {
                self.error(
                    Code::E0024,
                    format!("a condition is a bool, not {}", article(v.ty)),
                    c.span,
                );
                b::expr(w::ExprKind::Error, c.span)
            }
            None => b::expr(w::ExprKind::Error, c.span),
        }
    }

    /// The data an assignment or `Incr` writes: a name, or an array element at a
    /// constant index.
    pub(crate) fn place(&mut self, e: &r::Expr) -> Option<(Data, Option<u32>)> {
        // A component of a record: data of its own leaves.
        if let r::ExprKind::Field(x, f) = &e.kind
            && let Some(Ty::Record(_)) = self.place_type(x)
        {
            let (d, idx) = self.place(x)?;
            return Some((self.record_component_data(&d, idx, f)?, None));
        }
        let (n, idx) = match &e.kind {
            r::ExprKind::Name(n) => (n, None),
            r::ExprKind::Index(x, idx) => match &x.kind {
                r::ExprKind::Name(n) => (n, Some(idx.as_slice())),
                _ => {
                    self.unsupported(
                        "this assignment target",
                        e.span,
                        "assign a name or an array element",
                    );
                    return None;
                }
            },
            _ => {
                self.unsupported(
                    "this assignment target",
                    e.span,
                    "assign a name, a component or an array element",
                );
                return None;
            }
        };
        let d = match self.lookup(&n.key()) {
            Some(Sym::Data(d)) => d,
            Some(Sym::Routine(_)) => {
                self.error(
                    Code::E0023,
                    format!("`{}` is a routine; it cannot be assigned", n.text),
                    n.span,
                );
                return None;
            }
            None => {
                self.unknown_name(n);
                return None;
            }
        };
        if d.readonly || d.inline.is_some() {
            let what = if d.storage == Storage::Const || d.inline.is_some() {
                "a constant"
            } else {
                "a FOR loop's variable"
            };
            let e = self.error(
                Code::E0023,
                format!("`{}` is {what}; it cannot be assigned", n.text),
                n.span,
            );
            if d.span != Span::default() {
                e.related.push(crate::diag::Note {
                    at: crate::diag::Location {
                        file: String::new(),
                        span: Some(d.span),
                        line: 0,
                        col: 0,
                    },
                    message: "declared here".into(),
                });
            }
            return None;
        }
        let index = match (idx, d.len) {
            (None, None) => None,
            (Some(i), Some(_)) => match self.flat_index(n, &d, i)? {
                super::arrays::Flat::Const(k) => Some(k),
                super::arrays::Flat::Var(_) => {
                    self.unsupported(
                        "this instruction on an array element at a variable index",
                        e.span,
                        "assign the element (`a{i} := …;`), or use a constant index",
                    );
                    return None;
                }
            },
            (None, Some(_)) => {
                self.unsupported("assigning a whole array", e.span, "assign its elements");
                return None;
            }
            (Some(_), None) => {
                self.error(Code::E0022, format!("`{}` is not an array", n.text), n.span);
                return None;
            }
        };
        Some((d, index))
    }

    /// `target := value;` as WSL assignments (one per leaf).
    fn assign(&mut self, target: &r::Expr, value: &r::Expr, span: Span) -> Vec<w::StmtKind> {
        if let r::ExprKind::Field(x, f) = &target.kind
            && !matches!(self.place_type(x), Some(Ty::Record(_)))
        {
            return self.assign_component(x, f, value, span).unwrap_or_default();
        }
        if let Some(stmts) = self.str_to_val(target, value, span) {
            return stmts;
        }
        if let Some(stmts) = self.assign_array_place(target, value, span) {
            return stmts;
        }
        let Some((d, idx)) = self.place(target) else {
            return Vec::new();
        };
        let Some(v) = self.value(value, d.ty) else {
            return Vec::new();
        };
        self.leaf_names(&d, idx)
            .iter()
            .zip(v.parts)
            .map(|(n, p)| b::assign(b::name(n, target.span), p))
            .collect()
    }

    /// `p.trans.x := v`, `p.rot := o`, `s.v_tcp := v`, `j.robax.rax_2 := a`, …
    fn assign_component(
        &mut self,
        x: &r::Expr,
        f: &r::Name,
        value: &r::Expr,
        span: Span,
    ) -> Option<Vec<w::StmtKind>> {
        let key = f.key();
        // The record itself, and the path of components below it.
        let (base, path): (&r::Expr, Vec<String>) = match &x.kind {
            r::ExprKind::Field(y, g) => (y, vec![g.key(), key.clone()]),
            _ => (x, vec![key.clone()]),
        };
        let (d, idx) = self.place(base)?;
        let names = self.leaf_names(&d, idx);
        let leaf = |i: usize| b::name(&names[i], base.span);
        let path: Vec<&str> = path.iter().map(String::as_str).collect();
        let num = |t: &mut Self, dim: Dim| -> Option<w::Expr> {
            Some(b::with_unit(t.value(value, Ty::Num)?.leaf(), dim))
        };
        let set = |target: w::Expr, v: w::Expr| vec![b::assign(target, v)];
        Some(match (d.ty, path.as_slice()) {
            (Ty::Robtarget | Ty::Pose, ["trans", c @ ("x" | "y" | "z")])
            | (Ty::Pos, [c @ ("x" | "y" | "z")]) => {
                set(b::field(leaf(0), c), num(self, Dim::LENGTH)?)
            }
            (Ty::Robtarget | Ty::Pose, ["trans"]) => {
                let t = self.value(value, Ty::Pos)?.leaf();
                let p = leaf(0);
                let o = b::pose(
                    [
                        b::quantity(0.0, Dim::LENGTH, span),
                        b::quantity(0.0, Dim::LENGTH, span),
                        b::quantity(0.0, Dim::LENGTH, span),
                        b::field(p.clone(), "rx"),
                        b::field(p.clone(), "ry"),
                        b::field(p.clone(), "rz"),
                    ],
                    span,
                );
                set(p, super::expr::merge_pose(t, o, span))
            }
            (Ty::Robtarget | Ty::Pose, ["rot"]) => {
                let o = self.value(value, Ty::Orient)?.leaf();
                let p = leaf(0);
                set(p.clone(), super::expr::merge_pose(p, o, span))
            }
            (Ty::Robtarget, ["robconf" | "extax"]) => {
                // Configurations and external axes are not simulated (docs/rapid.md).
                let want = if path[0] == "robconf" {
                    Ty::Conf
                } else {
                    Ty::Extax
                };
                self.value(value, want)?;
                Vec::new()
            }
            (Ty::Speed, ["v_tcp"]) => set(leaf(0), num(self, Dim::SPEED)?),
            (Ty::Speed, ["v_ori"]) => set(leaf(1), num(self, Dim::ANGSPEED)?),
            (Ty::Speed, ["v_leax" | "v_reax"]) => {
                self.value(value, Ty::Num)?;
                Vec::new()
            }
            (Ty::Zone, ["pzone_tcp"]) => set(leaf(0), num(self, Dim::LENGTH)?),
            (Ty::Zone, ["pzone_ori"]) => set(leaf(1), num(self, Dim::LENGTH)?),
            (Ty::Zone, ["zone_ori"]) => set(leaf(2), num(self, Dim::ANGLE)?),
            (Ty::Zone, ["pzone_eax" | "zone_leax" | "zone_reax"]) => {
                // External axes are not simulated (docs/rapid.md).
                self.value(value, Ty::Num)?;
                Vec::new()
            }
            (Ty::Tool, ["tframe"]) => set(leaf(0), self.value(value, Ty::Pose)?.leaf()),
            (Ty::Wobj, ["uframe"]) => set(leaf(0), self.value(value, Ty::Pose)?.leaf()),
            (Ty::Wobj, ["oframe"]) => set(leaf(1), self.value(value, Ty::Pose)?.leaf()),
            (Ty::Jointtarget, ["robax"]) => set(leaf(0), self.value(value, Ty::Robjoint)?.leaf()),
            (Ty::Jointtarget, ["robax", rax]) | (Ty::Robjoint, [rax])
                if rax.starts_with("rax_") =>
            {
                let Ok(k @ 1..=6) = rax[4..].parse::<i64>() else {
                    self.unsupported(
                        &format!("the component `{}`", f.text),
                        f.span,
                        "use rax_1 … rax_6",
                    );
                    return None;
                };
                let j = b::expr(
                    w::ExprKind::Index(
                        Box::new(leaf(0)),
                        Box::new(b::expr(w::ExprKind::Int(k - 1), f.span)),
                    ),
                    span,
                );
                set(j, num(self, Dim::ANGLE)?)
            }
            _ => {
                self.unsupported(
                    &format!("assigning the component `{}` of {}", f.text, article(d.ty)),
                    f.span,
                    "assign the whole value, or trans.x/y/z, rot, v_tcp, v_ori, pzone_tcp, pzone_ori, zone_ori, tframe, uframe, oframe, robax.rax_1…6",
                );
                return None;
            }
        })
    }

    fn for_loop(
        &mut self,
        var: &r::Name,
        from: &r::Expr,
        to: &r::Expr,
        step: Option<&r::Expr>,
        body: &[r::Stmt],
        span: Span,
    ) -> w::StmtKind {
        let start = self.value(from, Ty::Num).map(super::Val::leaf);
        let end = self.value(to, Ty::Num).map(super::Val::leaf);
        let step_v = match step {
            Some(s) => self.value(s, Ty::Num).map(super::Val::leaf),
            None => Some(b::num(1.0, span)),
        };
        let (Some(start), Some(end), Some(step_v)) = (start, end, step_v) else {
            return w::StmtKind::Error;
        };
        let i = self.fresh_local(&super::wsl_name(var));
        let end_name = self.temp("for_end");
        let decl = |n: &str, init: w::Expr| w::Stmt {
            kind: w::StmtKind::Var(w::VarDecl {
                name: b::ident(n, span),
                ty: Some(b::ident("num", span)),
                init: Some(init),
                span,
            }),
            span,
        };
        let mut stmts = vec![decl(&i, start), decl(&end_name, end)];
        let iv = || b::name(&i, var.span);
        let ev = || b::name(&end_name, span);
        let (cond, step_e) = match b::literal(&step_v) {
            Some(s) => {
                let op = if s >= 0.0 { w::BinOp::Le } else { w::BinOp::Ge };
                (b::bin(op, iv(), ev()), step_v)
            }
            None => {
                let sn = self.temp("for_step");
                stmts.push(decl(&sn, step_v));
                let sv = || b::name(&sn, span);
                let zero = || b::num(0.0, span);
                let up = b::bin(
                    w::BinOp::And,
                    b::bin(w::BinOp::Ge, sv(), zero()),
                    b::bin(w::BinOp::Le, iv(), ev()),
                );
                let down = b::bin(
                    w::BinOp::And,
                    b::bin(w::BinOp::Lt, sv(), zero()),
                    b::bin(w::BinOp::Ge, iv(), ev()),
                );
                (b::bin(w::BinOp::Or, up, down), sv())
            }
        };
        // The loop variable is read-only in the body.
        let mut scope = BTreeMap::new();
        scope.insert(
            var.key(),
            Data {
                ty: Ty::Num,
                len: None,
                dims: Vec::new(),
                storage: Storage::Var,
                base: i.clone(),
                span: var.span,
                text: None,
                inline: None,
                local: true,
                readonly: true,
                tasks: Vec::new(),
                optional: false,
            },
        );
        self.locals.push(scope);
        let mut inner = self.stmts(body);
        self.locals.pop();
        inner.push(w::Stmt {
            kind: w::StmtKind::Assign {
                target: iv(),
                op: Some(w::BinOp::Add),
                value: step_e,
            },
            span,
        });
        stmts.push(w::Stmt {
            kind: w::StmtKind::While {
                cond,
                body: block(inner, span),
            },
            span,
        });
        w::StmtKind::Block(block(stmts, span))
    }

    fn test(
        &mut self,
        value: &r::Expr,
        cases: &[(Vec<r::Expr>, Vec<r::Stmt>)],
        default: Option<&[r::Stmt]>,
        span: Span,
    ) -> w::StmtKind {
        let Some(v) = self.expr(value) else {
            return w::StmtKind::Error;
        };
        if !matches!(v.ty, Ty::Num | Ty::Bool | Ty::Str) {
            self.unsupported(
                &format!("TEST of {}", article(v.ty)),
                value.span,
                "TEST a num, a bool or a string",
            );
            return w::StmtKind::Error;
        }
        let ty = v.ty;
        let t = self.temp("test");
        let wty = self.leaf_type(ty).map(|t| b::type_name(t, span));
        let decl = w::Stmt {
            kind: w::StmtKind::Var(w::VarDecl {
                name: b::ident(&t, span),
                ty: wty,
                init: Some(v.leaf()),
                span,
            }),
            span,
        };
        let mut branches = Vec::new();
        for (vals, body) in cases {
            let mut cond: Option<w::Expr> = None;
            for e in vals {
                let Some(c) = self.value(e, ty) else { continue };
                let eq = b::bin(w::BinOp::Eq, b::name(&t, e.span), c.leaf());
                cond = Some(match cond {
                    None => eq,
                    Some(prev) => b::bin(w::BinOp::Or, prev, eq),
                });
            }
            let body = self.stmts(body);
            branches.push((
                cond.unwrap_or_else(|| b::expr(w::ExprKind::Error, span)),
                block(body, span),
            ));
        }
        let els = default.map(|d| block(self.stmts(d), span));
        let mut stmts = vec![decl];
        if branches.is_empty() {
            if let Some(e) = els {
                stmts.push(w::Stmt {
                    kind: w::StmtKind::Block(e),
                    span,
                });
            }
        } else {
            stmts.push(w::Stmt {
                kind: w::StmtKind::If { branches, els },
                span,
            });
        }
        w::StmtKind::Block(block(stmts, span))
    }

    /// An instruction (the table's, [`super::table::INSTRUCTIONS`]) or a call of one of
    /// the task's PROCs.
    fn call(&mut self, name: &r::Name, args: &[Arg], span: Span, out: &mut Vec<w::Stmt>) {
        let key = name.key();
        if self.instruction(&key, name, args, span, out) {
            return;
        }
        let mut push = |kind| out.push(w::Stmt { kind, span });
        match self.lookup(&key) {
            Some(Sym::Routine(sig)) if sig.kind == r::RoutineKind::Proc => {
                if let Some(wargs) = self.call_args(name, &sig, args, span)
                    && let Some((copy_in, copy_out)) = self.ref_copies(&sig, args)
                {
                    copy_in.into_iter().for_each(&mut push);
                    push(w::StmtKind::Call {
                        name: b::ident(&sig.wsl, name.span),
                        args: wargs,
                    });
                    copy_out.into_iter().for_each(&mut push);
                }
            }
            Some(Sym::Routine(sig)) if sig.kind == r::RoutineKind::Func => {
                self.error(
                    Code::E0011,
                    format!("`{}` is a FUNC: use its value", name.text),
                    name.span,
                );
            }
            Some(Sym::Routine(_)) => {
                self.error(
                    Code::E0011,
                    format!(
                        "`{}` is a TRAP: it runs on an interrupt, it is not called",
                        name.text
                    ),
                    name.span,
                );
            }
            _ if self.not_run(name, &[Kind::Instruction, Kind::Function]) => {}
            _ => {
                let names: Vec<String> = self
                    .scope
                    .iter()
                    .filter(|(_, s)| matches!(s, Sym::Routine(_)))
                    .map(|(k, _)| k.clone())
                    .collect();
                let near =
                    crate::suggest::nearest(&key, names.iter().map(String::as_str)).map(|m| {
                        self.spelled
                            .get(m)
                            .cloned()
                            .unwrap_or_else(|| m.to_string())
                    });
                let elsewhere = self.local_elsewhere(&key);
                let d = self.error(
                    Code::E0011,
                    format!("unknown instruction or procedure `{}`", name.text),
                    name.span,
                );
                d.notes.extend(elsewhere);
                d.help = Some(match near {
                    Some(n) => format!("did you mean `{n}`?"),
                    None => {
                        "declare it with PROC; docs/rapid.md lists the instructions vworks runs"
                            .into()
                    }
                });
            }
        }
    }

    /// `WaitTime t;`
    pub(crate) fn wait_time(&mut self, c: &Call<'_>, out: &mut Vec<w::Stmt>) {
        if let Some(t) = self.value(c.pos[0], Ty::Num) {
            let kind = w::StmtKind::Delay(b::with_unit(t.leaf(), Dim::TIME));
            out.push(w::Stmt { kind, span: c.span });
        }
    }

    /// `WaitRob \InPos;`, `WaitRob \ZeroSpeed;`: the program waits until the robot stands
    /// at its point (a zoned point before it becomes a stop point): `delay 0s`.
    pub(crate) fn wait_rob(&mut self, c: &Call<'_>, out: &mut Vec<w::Stmt>) {
        if c.opts.len() != 1 {
            self.error(
                Code::E0013,
                "WaitRob takes one of `\\InPos` or `\\ZeroSpeed`",
                c.span,
            );
            return;
        }
        let kind = w::StmtKind::Delay(b::quantity(0.0, Dim::TIME, c.span));
        out.push(w::Stmt { kind, span: c.span });
    }

    /// `TPWrite text [\Num:=n] …;`
    pub(crate) fn tp_write(&mut self, c: &Call<'_>, out: &mut Vec<w::Stmt>) {
        let mut parts = Vec::new();
        self.text_parts(c.pos[0], &mut parts);
        for (_, _, v) in &c.opts {
            if let Some(e) = v
                && let Some(v) = self.expr(e)
            {
                parts.extend(self.printable(v, e.span));
            }
        }
        out.push(w::Stmt {
            kind: w::StmtKind::Log(parts),
            span: c.span,
        });
    }

    /// `ErrWrite header, reason …;`
    pub(crate) fn err_write(&mut self, c: &Call<'_>, out: &mut Vec<w::Stmt>) {
        let span = c.span;
        let mut parts = vec![b::expr(w::ExprKind::Str("ErrWrite: ".into()), span)];
        for (k, e) in c.pos.iter().enumerate() {
            if k > 0 {
                parts.push(b::expr(w::ExprKind::Str(" ".into()), span));
            }
            self.text_parts(e, &mut parts);
        }
        // The reason's further lines, `\RL2:=…` to `\RL4:=…`.
        for (k, _, v) in &c.opts {
            if let (true, Some(e)) = (k.starts_with("rl"), v) {
                parts.push(b::expr(w::ExprKind::Str(" ".into()), span));
                self.text_parts(e, &mut parts);
            }
        }
        out.push(w::Stmt {
            kind: w::StmtKind::Log(parts),
            span,
        });
    }

    /// `Stop;`, `Break;`: the program ends.
    pub(crate) fn stop(&mut self, c: &Call<'_>, out: &mut Vec<w::Stmt>) {
        out.push(w::Stmt {
            kind: w::StmtKind::Stop,
            span: c.span,
        });
    }

    /// `Incr x;`, `Decr x;`, `Add x, e;` on a num.
    pub(crate) fn step(&mut self, c: &Call<'_>, out: &mut Vec<w::Stmt>) {
        let (p, span) = (&c.pos, c.span);
        // An element at an index known only when running: `a{i} := a{i} + 1;`.
        if let r::ExprKind::Index(_, idx) = &p[0].kind
            && !idx.iter().all(|e| self.const_num(e).is_some())
        {
            let by = match c.key {
                "add" => p[1].clone(),
                _ => r::Expr {
                    kind: r::ExprKind::Num(1.0),
                    span,
                },
            };
            let op = if c.key == "decr" {
                r::BinOp::Sub
            } else {
                r::BinOp::Add
            };
            let value = r::Expr {
                kind: r::ExprKind::Binary(op, Box::new(p[0].clone()), Box::new(by)),
                span,
            };
            for kind in self.assign(p[0], &value, span) {
                out.push(w::Stmt { kind, span });
            }
            return;
        }
        let Some((d, idx)) = self.place(p[0]) else {
            return;
        };
        if d.ty != Ty::Num {
            self.error(
                Code::E0020,
                format!("{} changes a num, not {}", c.name.text, article(d.ty)),
                p[0].span,
            );
            return;
        }
        let by = if c.key == "add" {
            match self.value(p[1], Ty::Num) {
                Some(v) => v.leaf(),
                None => return,
            }
        } else {
            b::num(1.0, span)
        };
        let op = if c.key == "decr" {
            w::BinOp::Sub
        } else {
            w::BinOp::Add
        };
        let target = b::name(&self.leaf_names(&d, idx)[0], p[0].span);
        let kind = w::StmtKind::Assign {
            target,
            op: Some(op),
            value: by,
        };
        out.push(w::Stmt { kind, span });
    }

    /// `MoveL`, `MoveC`, `MoveJ`, `MoveAbsJ`.
    pub(crate) fn motion(&mut self, c: &Call<'_>, out: &mut Vec<w::Stmt>) {
        if let Some(kind) = self.motion_kind(c) {
            out.push(w::Stmt { kind, span: c.span });
        }
    }

    fn motion_kind(&mut self, c: &Call<'_>) -> Option<w::StmtKind> {
        let (key, span, p, opts) = (c.key, c.span, &c.pos, &c.opts);
        let circular = key == "movec";
        let n = if circular { 5 } else { 4 };
        let mut v_override = None;
        let mut z_override = None;
        let mut duration = None;
        let mut wobj = None;
        for (k, name, v) in opts {
            match k.as_str() {
                "v" | "z" | "t" => {
                    let Some(e) = v else {
                        self.error(
                            Code::E0301,
                            format!("`\\{}` needs a value: `\\{}:=…`", name.text, name.text),
                            name.span,
                        );
                        return None;
                    };
                    let x = self.value(e, Ty::Num)?.leaf();
                    match k.as_str() {
                        "v" => v_override = Some(b::with_unit(x, Dim::SPEED)),
                        "z" => z_override = Some(b::with_unit(x, Dim::LENGTH)),
                        _ => duration = Some(b::with_unit(x, Dim::TIME)),
                    }
                }
                "wobj" => {
                    let Some(e) = v else {
                        self.error(
                            Code::E0301,
                            "`\\WObj` needs a value: `\\WObj:=wobj1`",
                            name.span,
                        );
                        return None;
                    };
                    wobj = Some(self.value(e, Ty::Wobj)?);
                }
                "inpos" | "corr" => {
                    let help = if k == "inpos" {
                        "vworks's robot is at a `fine` point exactly when its motion ends: use `fine` without `\\Inpos`"
                    } else {
                        "path correction needs a sensor vworks does not simulate: remove `\\Corr`"
                    };
                    self.unsupported(
                        &format!("the motion option `\\{}`", name.text),
                        name.span,
                        help,
                    );
                    return None;
                }
                // \Conc, \ID, \TLoad, \NoEOffs: accepted; they change nothing vworks simulates.
                _ => {}
            }
        }
        let (via, target) = if circular {
            (
                Some(self.value(p[0], Ty::Robtarget)?.leaf()),
                self.value(p[1], Ty::Robtarget)?.leaf(),
            )
        } else if key == "moveabsj" {
            (None, self.value(p[0], Ty::Jointtarget)?.leaf())
        } else {
            (None, self.value(p[0], Ty::Robtarget)?.leaf())
        };
        let rest = &p[n - 3..];
        let speed = self.value(rest[0], Ty::Speed)?;
        let zone = self.value(rest[1], Ty::Zone)?;
        let tool = self.value(rest[2], Ty::Tool)?.leaf();
        // A target in a work object: uframe · oframe · p, in the base frame.
        let in_wobj = |e: w::Expr| match &wobj {
            Some(w) if !(is_identity_pose(&w.parts[0]) && is_identity_pose(&w.parts[1])) => {
                let frame = b::call(
                    "pose_mul",
                    vec![w.parts[0].clone(), w.parts[1].clone()],
                    span,
                );
                b::call("pose_mul", vec![frame, e], span)
            }
            _ => e,
        };
        let (via, target) = if key == "moveabsj" {
            (via, target)
        } else {
            (via.map(in_wobj), in_wobj(target))
        };
        let v_tcp = v_override.unwrap_or_else(|| speed.parts[0].clone());
        // (`\Z` gives the TCP zone; an orientation zone smaller than it is it.)
        let mut parts = zone.parts.into_iter();
        let (radius, ori, angle) = (parts.next(), parts.next(), parts.next());
        let radius = z_override
            .or(radius)
            .unwrap_or_else(|| b::quantity(0.0, Dim::LENGTH, span));
        let zone = match (b::literal(&radius), ori, angle) {
            (Some(0.0), ..) => w::Zone::Fine,
            (_, Some(ori), Some(angle)) => w::Zone::Extended(Box::new(w::ExtendedZone {
                radius,
                ori,
                angle: Some(angle),
            })),
            _ => w::Zone::Radius(radius),
        };
        let kind = match key {
            "movel" => w::MoveKind::L,
            "movec" => w::MoveKind::C,
            _ => w::MoveKind::J,
        };
        // MoveJ and MoveAbsJ take the TCP speed too (WSL's `move_j … speed 250mm/s`).
        // `\T` replaces the speeddata: the motion takes that long.
        let timed = duration.is_some();
        Some(w::StmtKind::Move {
            kind,
            via,
            target,
            speed: (!timed).then_some(v_tcp),
            accel: None,
            // The orientation speed of the speeddata, for the Cartesian motions.
            orient: (kind != w::MoveKind::J && !timed).then(|| speed.parts[1].clone()),
            zone: Some(zone),
            tool: Some(tool),
            duration,
        })
    }

    pub(crate) fn wait_until(&mut self, c: &Call<'_>, out: &mut Vec<w::Stmt>) {
        let cond = self.condition(c.pos[0]);
        self.timed_wait(&c.name.text, cond, &c.opts, true, c.span, out);
    }

    /// A wait until `cond` holds, with RAPID's `\MaxTime` (then `\TimeFlag` is set, or
    /// without it the wait is the error ERR_WAIT_MAXTIME) for the instruction `instr`.
    ///
    /// `polled`: as `WaitUntil`, the condition is tested every `\PollRate` (0.1 s, at
    /// least 0.04 s) from the wait's start, not when the data changes.
    pub(crate) fn timed_wait(
        &mut self,
        instr: &str,
        cond: w::Expr,
        opts: &[(String, &r::Name, Option<&r::Expr>)],
        polled: bool,
        span: Span,
        out: &mut Vec<w::Stmt>,
    ) {
        let mut timeout = None;
        let mut flag = None;
        let mut poll = polled.then(|| b::quantity(0.1, Dim::TIME, span));
        for (k, name, v) in opts {
            match (k.as_str(), v) {
                ("maxtime", Some(e)) => {
                    timeout = self
                        .value(e, Ty::Num)
                        .map(|v| b::with_unit(v.leaf(), Dim::TIME));
                }
                ("timeflag", Some(e)) => flag = self.place(e),
                ("pollrate", Some(e)) => {
                    if let Some(v) = self.value(e, Ty::Num) {
                        let p = b::with_unit(v.leaf(), Dim::TIME);
                        poll = Some(match b::literal(&p) {
                            Some(x) => b::quantity(x.max(0.04), Dim::TIME, e.span),
                            None => b::call(
                                "max",
                                vec![p, b::quantity(0.04, Dim::TIME, e.span)],
                                e.span,
                            ),
                        });
                    }
                }
                ("inpos", None) => {}
                _ => {
                    self.error(
                        Code::E0301,
                        format!("`\\{}` is written `\\{}:=value`", name.text, name.text),
                        name.span,
                    );
                }
            }
        }
        let has_timeout = timeout.is_some();
        out.push(w::Stmt {
            kind: w::StmtKind::WaitUntil {
                cond,
                timeout,
                poll,
            },
            span,
        });
        let timed_out = || b::call("timed_out", vec![], span);
        match flag {
            Some((d, idx)) if d.ty == Ty::Bool => out.push(w::Stmt {
                kind: b::assign(b::name(&self.leaf_names(&d, idx)[0], span), timed_out()),
                span,
            }),
            Some((d, _)) => {
                self.error(
                    Code::E0020,
                    format!("\\TimeFlag is a bool, not {}", article(d.ty)),
                    span,
                );
            }
            None if has_timeout => {
                // Without \TimeFlag, an expired \MaxTime is the error ERR_WAIT_MAXTIME.
                let fail = raise(
                    "ERR_WAIT_MAXTIME",
                    format!("{instr}: \\MaxTime expired (ERR_WAIT_MAXTIME)"),
                    span,
                );
                out.push(w::Stmt {
                    kind: w::StmtKind::If {
                        branches: vec![(timed_out(), block(vec![fail], span))],
                        els: None,
                    },
                    span,
                });
            }
            None => {}
        }
    }

    /// `WaitSyncTask s, tasks;`: this task arrives at sync point `s` and waits until every
    /// task of the list has arrived as often: WSL's `sync s with T_ROB1, T_ROB2;`, a
    /// barrier the engine keeps (the tasks are the workcell robots' `task` names).
    pub(crate) fn wait_sync_task(&mut self, c: &Call<'_>, out: &mut Vec<w::Stmt>) {
        let (span, p, opts) = (c.span, &c.pos, &c.opts);
        let Some((sync, _)) = self.data_arg(p[0], "a syncident declared at module level", |d| {
            d.ty == Ty::Syncident && !d.local
        }) else {
            return;
        };
        let sync = sync.clone();
        let Some((_, list)) = self.data_arg(p[1], "a task list (`tasks`)", |d| d.ty == Ty::Tasks)
        else {
            return;
        };
        let mut timeout = None;
        for (k, n, v) in opts {
            if k == "timeout" {
                match v {
                    Some(e) => {
                        timeout = self
                            .value(e, Ty::Num)
                            .map(|v| b::with_unit(v.leaf(), Dim::TIME))
                    }
                    None => {
                        self.error(
                            Code::E0301,
                            "`\\TimeOut` is written `\\TimeOut:=seconds`",
                            n.span,
                        );
                    }
                }
            }
        }
        let has_timeout = timeout.is_some();
        out.push(w::Stmt {
            kind: w::StmtKind::Sync {
                name: b::ident(&sync.text, sync.span),
                tasks: list.tasks.iter().map(|t| b::ident(t, p[1].span)).collect(),
                timeout,
            },
            span,
        });
        if has_timeout {
            let fail = raise(
                "ERR_WAITSYNCTASK",
                "WaitSyncTask: \\TimeOut expired (ERR_WAITSYNCTASK)".into(),
                span,
            );
            out.push(w::Stmt {
                kind: w::StmtKind::If {
                    branches: vec![(b::call("timed_out", vec![], span), block(vec![fail], span))],
                    els: None,
                },
                span,
            });
        }
    }

    /// The pieces of a text for TPWrite and ErrWrite: literal text, and NumToStr/ValToStr
    /// of values.
    fn text_parts(&mut self, e: &r::Expr, out: &mut Vec<w::Expr>) {
        match &e.kind {
            r::ExprKind::Binary(r::BinOp::Add, a, c) => {
                self.text_parts(a, out);
                self.text_parts(c, out);
            }
            _ => match self.expr(e) {
                Some(v) if v.ty == Ty::Str => out.extend(self.printable(v, e.span)),
                Some(v) => {
                    self.error(
                        Code::E0020,
                        format!("expected a string, found {}", article(v.ty)),
                        e.span,
                    )
                    .help = Some("turn values into text with NumToStr or ValToStr".into());
                }
                None => {}
            },
        }
    }

    /// A value as `log` pieces.
    fn printable(&mut self, v: super::Val, span: Span) -> Vec<w::Expr> {
        match v.ty {
            Ty::Num
            | Ty::Bool
            | Ty::Pos
            | Ty::Orient
            | Ty::Pose
            | Ty::Robtarget
            | Ty::Jointtarget => v.parts,
            Ty::Str => match v.text {
                Some(s) => vec![b::expr(w::ExprKind::Str(s), span)],
                None => v.parts,
            },
            t => {
                self.unsupported(
                    &format!("printing {}", article(t)),
                    span,
                    "print its components",
                );
                Vec::new()
            }
        }
    }
}

/// True if a WSL expression is the literal identity pose.
fn is_identity_pose(e: &w::Expr) -> bool {
    match &e.kind {
        w::ExprKind::Call(f, a) if f.name == "pose" => a.iter().all(|x| b::literal(x) == Some(0.0)),
        _ => false,
    }
}

/// The statement raising RAPID's error `name` (one of [`super::data::ERRORS`]) with
/// `message`, which names it if no error handler takes it.
fn raise(name: &str, message: String, span: Span) -> w::Stmt {
    let n = super::data::ERRORS
        .iter()
        .find(|(e, _)| *e == name)
        .map_or(0, |(_, n)| i64::from(*n));
    w::Stmt {
        kind: w::StmtKind::Raise(Some(b::expr(w::ExprKind::Int(n), span)), message),
        span,
    }
}
