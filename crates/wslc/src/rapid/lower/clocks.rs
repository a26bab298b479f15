//! Clocks: RAPID's stopwatches (`VAR clock c;`, `ClkReset`, `ClkStart`, `ClkStop`,
//! `ClkRead`), read from the simulated time.
//!
//! A clock is three WSL variables (its leaves, [`Ty::Clock`]): `c.started`, the time it
//! last started; `c.before`, the time it ran before that; `c.running`. `ClkRead` is a
//! generated function of the three and `now()`, in whole milliseconds as the controller
//! reads it (`\HighRes`: the simulated time's own resolution).

use vworks_vm::Dim;

use super::data::{Ty, build as b};
use super::table::Call;
use super::{Tr, Val, block};
use crate::diag::Code;
use crate::syntax::{self as w, Span};

impl Tr<'_> {
    /// The leaf names (`started`, `before`, `running`) of the clock `c.pos[0]` names.
    fn clock_leaves(&mut self, c: &Call<'_>) -> Option<[w::Expr; 3]> {
        let e = c.pos[0];
        let (d, idx) = self.place(e)?;
        if d.ty != Ty::Clock {
            self.error(
                Code::E0020,
                format!(
                    "{} takes a clock, not {}",
                    c.name.text,
                    super::expr::article(d.ty)
                ),
                e.span,
            );
            return None;
        }
        let names = self.leaf_names(&d, idx);
        let leaf = |k: usize| b::name(&names[k], e.span);
        Some([leaf(0), leaf(1), leaf(2)])
    }

    /// `ClkReset c;`, `ClkStart c;`, `ClkStop c;`.
    pub(crate) fn clock(&mut self, c: &Call<'_>, out: &mut Vec<w::Stmt>) {
        let span = c.span;
        let Some([started, before, running]) = self.clock_leaves(c) else {
            return;
        };
        let set = |target: w::Expr, op: Option<w::BinOp>, value: w::Expr| w::Stmt {
            kind: w::StmtKind::Assign { target, op, value },
            span,
        };
        let now = || b::call("now", Vec::new(), span);
        let when = |cond: w::Expr, then: Vec<w::Stmt>| w::Stmt {
            kind: w::StmtKind::If {
                branches: vec![(cond, block(then, span))],
                els: None,
            },
            span,
        };
        match c.key {
            // To zero; a running clock runs on from zero.
            "clkreset" => {
                out.push(set(before, None, b::quantity(0.0, Dim::TIME, span)));
                out.push(set(started, None, now()));
            }
            // A running clock runs on.
            "clkstart" => out.push(when(
                b::not(running.clone()),
                vec![
                    set(started, None, now()),
                    set(running, None, b::expr(w::ExprKind::Bool(true), span)),
                ],
            )),
            _ => out.push(when(
                running.clone(),
                vec![
                    set(
                        before,
                        Some(w::BinOp::Add),
                        b::bin(w::BinOp::Sub, now(), started),
                    ),
                    set(running, None, b::expr(w::ExprKind::Bool(false), span)),
                ],
            )),
        }
    }

    /// `ClkRead(c [\HighRes])`: seconds.
    pub(crate) fn clock_read(&mut self, c: &Call<'_>) -> Option<Val> {
        let span = c.span;
        let [started, before, running] = self.clock_leaves(c)?;
        self.clock_read_helper(span);
        let s = b::without_unit(
            b::call("clkread'", vec![started, before, running], span),
            Dim::TIME,
        );
        let read = if c.opts.is_empty() {
            // Whole milliseconds, rounded down (the time is never negative).
            let ms = b::bin(w::BinOp::Mul, s, b::num(1000.0, span));
            b::bin(
                w::BinOp::Div,
                b::call("num", vec![b::call("int", vec![ms], span)], span),
                b::num(1000.0, span),
            )
        } else {
            s
        };
        Some(Val::one(Ty::Num, read))
    }

    /// `func clkread'(started: time, before: time, running: bool) -> time`, once.
    fn clock_read_helper(&mut self, span: Span) {
        if !self.helpers.insert("clkread'".into()) {
            return;
        }
        let name = |n: &str| b::name(n, span);
        let ret = |e: w::Expr| w::Stmt {
            kind: w::StmtKind::Return(Some(e)),
            span,
        };
        let ran = b::bin(
            w::BinOp::Add,
            name("before"),
            b::bin(
                w::BinOp::Sub,
                b::call("now", Vec::new(), span),
                name("started"),
            ),
        );
        let body = vec![
            w::Stmt {
                kind: w::StmtKind::If {
                    branches: vec![(name("running"), block(vec![ret(ran)], span))],
                    els: None,
                },
                span,
            },
            ret(name("before")),
        ];
        let param = |n: &str, t: &str| w::Param {
            name: b::ident(n, span),
            ty: b::ident(t, span),
        };
        self.items.push(w::Item::Proc(w::ProcDecl {
            is_func: true,
            name: b::ident("clkread'", span),
            params: vec![
                param("started", "time"),
                param("before", "time"),
                param("running", "bool"),
            ],
            ret: Some(b::ident("time", span)),
            body: block(body, span),
            handler: None,
            span,
        }));
    }
}
