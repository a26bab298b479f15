//! RAPID arrays beyond one element at a constant index: several dimensions (`a{3, 4}`,
//! held row after row: `a{i, j}` is element `(i - 1) · 4 + j`), elements at an index known
//! only when running (read through the generated accessor `a{}`, written through an `if`
//! chain over the elements), and whole arrays assigned (`a := b;`, `a := [1, 2, 3];`). An
//! index out of the bounds is the runtime error ERR_INDEX naming them.

use super::data::build as b;
use super::{Data, Tr, block};
use crate::diag::Code;
use crate::rapid::syntax as r;
use crate::syntax::{self as w, Span};

/// An element's place among an array's elements (1-based, row after row).
pub(crate) enum Flat {
    /// Known when compiling.
    Const(u32),
    /// An int known only when running (in bounds: the accessor or the chain checks).
    Var(w::Expr),
}

impl Tr<'_> {
    /// The element of array `d` (named `n`) at `idx`, one index per dimension.
    pub(crate) fn flat_index(&mut self, n: &r::Name, d: &Data, idx: &[r::Expr]) -> Option<Flat> {
        if idx.len() != d.dims.len() {
            let want: Vec<&str> = d.dims.iter().map(|_| "i").collect();
            self.error(
                Code::E0013,
                format!(
                    "`{}` has {} dimension{}: index it `{}{{{}}}`",
                    n.text,
                    d.dims.len(),
                    if d.dims.len() == 1 { "" } else { "s" },
                    n.text,
                    want.join(", ")
                ),
                idx.first().map_or(n.span, |e| e.span),
            );
            return None;
        }
        let consts: Vec<Option<f64>> = idx.iter().map(|e| self.const_num(e)).collect();
        if consts.iter().all(Option::is_some) {
            let mut flat = 0u32;
            for ((k, e), &size) in consts.iter().flatten().zip(idx).zip(&d.dims) {
                if k.fract() != 0.0 || *k < 1.0 || *k > f64::from(size) {
                    self.error(
                        Code::E0025,
                        format!("index {k} is outside `{}`'s elements 1 to {size}", n.text),
                        e.span,
                    );
                    return None;
                }
                flat = flat * size + (*k as u32 - 1);
            }
            return Some(Flat::Const(flat + 1));
        }
        let mut ints = Vec::new();
        for e in idx {
            let v = self.value(e, super::data::Ty::Num)?.leaf();
            ints.push(b::call("int", vec![v], e.span));
        }
        let span = idx[0].span;
        if let [one] = ints.as_slice() {
            return Some(Flat::Var(one.clone()));
        }
        let f = self.index_helper(d);
        Some(Flat::Var(b::call(&f, ints, span)))
    }

    /// `func a{}at'(i1: int, …) -> int`: the element of a multi-dimensional array at the
    /// indices, each checked against its dimension (ERR_INDEX), generated once.
    fn index_helper(&mut self, d: &Data) -> String {
        let name = format!("{}{{}}at'", d.base);
        if !self.helpers.insert(name.clone()) {
            return name;
        }
        let span = d.span;
        let mut body = Vec::new();
        let mut flat = b::expr(w::ExprKind::Int(0), span);
        for (k, &size) in d.dims.iter().enumerate() {
            let i = b::name(&format!("i{k}"), span);
            let int = |v: i64| b::expr(w::ExprKind::Int(v), span);
            let out = b::bin(
                w::BinOp::Or,
                b::bin(w::BinOp::Lt, i.clone(), int(1)),
                b::bin(w::BinOp::Gt, i.clone(), int(i64::from(size))),
            );
            let fail = w::Stmt {
                kind: w::StmtKind::Fail(vec![
                    b::expr(
                        w::ExprKind::Str(format!(
                            "index out of bounds (ERR_INDEX): dimension {} of `{}` has elements 1 to {size}, the index is ",
                            k + 1,
                            d.base
                        )),
                        span,
                    ),
                    i.clone(),
                ]),
                span,
            };
            body.push(w::Stmt {
                kind: w::StmtKind::If {
                    branches: vec![(out, block(vec![fail], span))],
                    els: None,
                },
                span,
            });
            flat = b::bin(
                w::BinOp::Add,
                b::bin(w::BinOp::Mul, flat, int(i64::from(size))),
                b::bin(w::BinOp::Sub, i, int(1)),
            );
        }
        let one = b::expr(w::ExprKind::Int(1), span);
        body.push(w::Stmt {
            kind: w::StmtKind::Return(Some(b::bin(w::BinOp::Add, flat, one))),
            span,
        });
        self.items.push(w::Item::Proc(w::ProcDecl {
            is_func: true,
            name: b::ident(&name, span),
            params: (0..d.dims.len())
                .map(|k| w::Param {
                    name: b::ident(&format!("i{k}"), span),
                    ty: b::ident("int", span),
                })
                .collect(),
            ret: Some(b::ident("int", span)),
            body: block(body, span),
            handler: None,
            span,
        }));
        name
    }

    /// `a{i} := v;` at an index known only when running: the value once into temporaries,
    /// then the element it names, by an `if` chain over the elements (ERR_INDEX past them).
    pub(crate) fn assign_element(
        &mut self,
        d: &Data,
        flat: w::Expr,
        value: &r::Expr,
        span: Span,
    ) -> Vec<w::StmtKind> {
        let Some(v) = self.value(value, d.ty) else {
            return Vec::new();
        };
        let len = d.len.unwrap_or(0);
        let leaves = self.leaves(d.ty);
        let mut stmts = Vec::new();
        let var = |name: &str, ty: Option<w::Ident>, init: w::Expr| w::Stmt {
            kind: w::StmtKind::Var(w::VarDecl {
                name: b::ident(name, span),
                ty,
                init: Some(init),
                span,
            }),
            span,
        };
        let i = self.temp("index");
        stmts.push(var(&i, Some(b::ident("int", span)), flat));
        let mut temps = Vec::new();
        for ((_, t), part) in leaves.iter().zip(v.parts) {
            let name = self.temp("value");
            stmts.push(var(&name, Some(b::type_name(*t, span)), part));
            temps.push(name);
        }
        let mut branches = Vec::new();
        for k in 1..=len {
            let cond = b::bin(
                w::BinOp::Eq,
                b::name(&i, span),
                b::expr(w::ExprKind::Int(i64::from(k)), span),
            );
            let sets = self
                .leaf_names(d, Some(k))
                .iter()
                .zip(&temps)
                .map(|(leaf, t)| w::Stmt {
                    kind: b::assign(b::name(leaf, span), b::name(t, span)),
                    span,
                })
                .collect();
            branches.push((cond, block(sets, span)));
        }
        let fail = index_fail(&d.base, len, b::name(&i, span), span);
        stmts.push(w::Stmt {
            kind: w::StmtKind::If {
                branches,
                els: Some(block(vec![fail], span)),
            },
            span,
        });
        vec![w::StmtKind::Block(block(stmts, span))]
    }

    /// `a := b;` or `a := [x, y, …];`: every element of array `d`, from an array of the
    /// same type and dimensions or an aggregate of them.
    pub(crate) fn assign_array(
        &mut self,
        d: &Data,
        value: &r::Expr,
        span: Span,
    ) -> Vec<w::StmtKind> {
        let len = d.len.unwrap_or(0);
        let values: Vec<Vec<w::Expr>> = match &value.kind {
            r::ExprKind::Name(n) => match self.lookup(&n.key()) {
                Some(super::Sym::Data(src)) if src.ty == d.ty && src.dims == d.dims => (1..=len)
                    .map(|k| self.data_value(&src, Some(k), value.span).parts)
                    .collect(),
                _ => {
                    self.error(
                        Code::E0020,
                        format!(
                            "`{}` is assigned an array of the same type and dimensions",
                            d.base
                        ),
                        value.span,
                    );
                    return Vec::new();
                }
            },
            r::ExprKind::Aggregate(_) => {
                let mut out = Vec::new();
                let dims = d.dims.clone();
                if self
                    .array_values(&d.base, value, d.ty, &dims, &mut out)
                    .is_none()
                {
                    return Vec::new();
                }
                out.into_iter().map(|v| v.parts).collect()
            }
            _ => {
                self.error(
                    Code::E0020,
                    format!("`{}` is an array: assign it an array or `[…]`", d.base),
                    value.span,
                );
                return Vec::new();
            }
        };
        let mut out = Vec::new();
        for (k, parts) in (1..=len).zip(values) {
            for (leaf, p) in self.leaf_names(d, Some(k)).iter().zip(parts) {
                out.push(b::assign(b::name(leaf, span), p));
            }
        }
        out
    }

    /// An assignment to a whole array, or to an element at an index known only when
    /// running; `None` for any other target.
    pub(crate) fn assign_array_place(
        &mut self,
        target: &r::Expr,
        value: &r::Expr,
        span: Span,
    ) -> Option<Vec<w::StmtKind>> {
        let (n, idx) = match &target.kind {
            r::ExprKind::Name(n) => (n, None),
            r::ExprKind::Index(x, idx) => match &x.kind {
                r::ExprKind::Name(n) => (n, Some(idx)),
                _ => return None,
            },
            _ => return None,
        };
        let d = match self.lookup(&n.key()) {
            Some(super::Sym::Data(d)) if d.len.is_some() && !d.readonly && d.inline.is_none() => d,
            _ => return None,
        };
        match idx {
            None => Some(self.assign_array(&d, value, span)),
            Some(idx) if idx.iter().all(|e| self.const_num(e).is_some()) => None,
            Some(idx) => match self.flat_index(n, &d, idx) {
                None => Some(Vec::new()),
                Some(Flat::Var(flat)) => Some(self.assign_element(&d, flat, value, span)),
                Some(Flat::Const(_)) => None,
            },
        }
    }
}

/// The statement that stops the run at an index past array `base`'s `len` elements.
pub(crate) fn index_fail(base: &str, len: u32, index: w::Expr, span: Span) -> w::Stmt {
    w::Stmt {
        kind: w::StmtKind::Fail(vec![
            b::expr(
                w::ExprKind::Str(format!(
                    "index out of bounds (ERR_INDEX): `{base}` has elements 1 to {len}, the index is "
                )),
                span,
            ),
            index,
        ]),
        span,
    }
}
