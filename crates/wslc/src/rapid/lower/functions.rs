//! RAPID's built-in functions lowered to WSL expressions (the rows of
//! [`super::table::FUNCTIONS`]): poses (`Offs`, `RelTool`, `PoseMult`, `PoseInv`), the
//! robot's state (`CRobT`, `CPos`, `CJointT`), arithmetic in RAPID's units (`Sin` of
//! degrees, `ATan2` in degrees, `Round` half away from zero), `OrientZYX`, `Dim`. Each
//! gets its arguments already checked against its row.

use vworks_vm::Dim;

use super::data::{Ty, build as b};
use super::expr::article;
use super::table::Call;
use super::{Tr, Val};
use crate::diag::Code;
use crate::rapid::syntax as r;
use crate::syntax::{self as w, Span};

impl Tr<'_> {
    /// The TCP now (`current_pose()`), or with `\Tool:=t` among `opts` the TCP of tool
    /// `t`: the flange (the TCP less the active tool) · t's `tframe`.
    fn tcp_with_tool(
        &mut self,
        opts: &[(String, &r::Name, Option<&r::Expr>)],
        span: Span,
    ) -> Option<w::Expr> {
        let pose = b::call("current_pose", vec![], span);
        let Some(e) = self.opt_value(opts, "tool", "tool1").ok()? else {
            return Some(pose);
        };
        let tool = self.value(e, Ty::Tool)?;
        let active = b::call(
            "pose_inv",
            vec![b::call("current_tool", vec![], span)],
            span,
        );
        let flange = b::call("pose_mul", vec![pose, active], span);
        Some(b::call(
            "pose_mul",
            vec![flange, tool.parts[0].clone()],
            span,
        ))
    }

    /// Each of `es` as a num's leaf.
    fn nums(&mut self, es: &[&r::Expr]) -> Option<Vec<w::Expr>> {
        es.iter()
            .map(|e| self.value(e, Ty::Num).map(Val::leaf))
            .collect()
    }

    /// `Offs(p, x, y, z)`.
    pub(crate) fn offs(&mut self, c: &Call<'_>) -> Option<Val> {
        let span = c.span;
        let p = &c.pos;
        let base = self.expr(p[0])?;
        if !base.ty.is_posed() || base.ty == Ty::Orient {
            self.error(
                Code::E0020,
                format!("Offs moves a robtarget, not {}", article(base.ty)),
                p[0].span,
            );
            return None;
        }
        let d = self.nums(&p[1..])?;
        let d: Vec<w::Expr> = d
            .into_iter()
            .map(|e| b::with_unit(e, Dim::LENGTH))
            .collect();
        let mut a = vec![base.clone().leaf()];
        a.extend(d);
        Some(Val::one(base.ty, b::call("offset", a, span)))
    }

    /// `RelTool(p, x, y, z [\\Rx] [\\Ry] [\\Rz])`.
    pub(crate) fn rel_tool(&mut self, c: &Call<'_>) -> Option<Val> {
        let span = c.span;
        let p = &c.pos;
        let opts = &c.opts;
        let base = self.value(p[0], Ty::Robtarget)?.leaf();
        let d = self.nums(&p[1..])?;
        let mut a = vec![base];
        a.extend(d.into_iter().map(|e| b::with_unit(e, Dim::LENGTH)));
        let mut out = b::call("tool_offset", a, span);
        // Rotations about the tool's x, then the new y, then the new z.
        for axis in ["rx", "ry", "rz"] {
            let Some(e) = self.opt_value(opts, axis, "degrees").ok()? else {
                continue;
            };
            let angle = b::with_unit(self.value(e, Ty::Num)?.leaf(), Dim::ANGLE);
            let zero_l = || b::quantity(0.0, Dim::LENGTH, span);
            let zero_a = || b::quantity(0.0, Dim::ANGLE, span);
            let rot = match axis {
                "rx" => [zero_l(), zero_l(), zero_l(), angle, zero_a(), zero_a()],
                "ry" => [zero_l(), zero_l(), zero_l(), zero_a(), angle, zero_a()],
                _ => [zero_l(), zero_l(), zero_l(), zero_a(), zero_a(), angle],
            };
            out = b::call("pose_mul", vec![out, b::pose(rot, span)], span);
        }
        Some(Val::one(Ty::Robtarget, out))
    }

    /// `PoseMult(a, b)`, `PoseInv(p)`.
    pub(crate) fn pose_op(&mut self, c: &Call<'_>) -> Option<Val> {
        let (key, span) = (c.key, c.span);
        let p = &c.pos;
        let mut a = Vec::new();
        for e in p {
            a.push(self.value(e, Ty::Pose)?.leaf());
        }
        let g = if key == "posemult" {
            "pose_mul"
        } else {
            "pose_inv"
        };
        Some(Val::one(Ty::Pose, b::call(g, a, span)))
    }

    /// `CRobT()`.
    pub(crate) fn c_rob_t(&mut self, c: &Call<'_>) -> Option<Val> {
        let span = c.span;
        let opts = &c.opts;
        let mut pose = self.tcp_with_tool(opts, span)?;
        // In a work object: (uframe · oframe)⁻¹ · the TCP.
        if let Some(e) = self.opt_value(opts, "wobj", "wobj1").ok()? {
            let w = self.value(e, Ty::Wobj)?;
            let frame = b::call(
                "pose_mul",
                vec![w.parts[0].clone(), w.parts[1].clone()],
                span,
            );
            pose = b::call(
                "pose_mul",
                vec![b::call("pose_inv", vec![frame], span), pose],
                span,
            );
        }
        Some(Val::one(Ty::Robtarget, pose))
    }

    /// `CJointT()`.
    pub(crate) fn c_joint_t(&mut self, c: &Call<'_>) -> Option<Val> {
        let span = c.span;
        Some(Val::one(
            Ty::Jointtarget,
            b::call("current_joints", vec![], span),
        ))
    }

    /// `CPos()`.
    pub(crate) fn c_pos(&mut self, c: &Call<'_>) -> Option<Val> {
        let span = c.span;
        let opts = &c.opts;
        let p = self.tcp_with_tool(opts, span)?;
        Some(Val::one(Ty::Pos, self.pos_of(p, span, |e| e)))
    }

    /// `Abs(x)`, `Sqrt(x)`.
    pub(crate) fn num_function(&mut self, c: &Call<'_>) -> Option<Val> {
        let (key, span) = (c.key, c.span);
        let p = &c.pos;
        let x = self.nums(p)?.remove(0);
        num(b::call(key, vec![x], span))
    }

    /// `Sin(x)`, `Cos(x)`, `Tan(x)` of degrees.
    pub(crate) fn trig(&mut self, c: &Call<'_>) -> Option<Val> {
        let (key, span) = (c.key, c.span);
        let p = &c.pos;
        let x = b::with_unit(self.nums(p)?.remove(0), Dim::ANGLE);
        if key == "tan" {
            let s = b::call("sin", vec![x.clone()], span);
            let c = b::call("cos", vec![x], span);
            return num(b::bin(w::BinOp::Div, s, c));
        }
        num(b::call(key, vec![x], span))
    }

    /// `ATan2(y, x)`, `ATan(x)`, `ASin(x)`, `ACos(x)` in degrees.
    pub(crate) fn arc(&mut self, c: &Call<'_>) -> Option<Val> {
        let (key, span) = (c.key, c.span);
        let p = &c.pos;
        let v = self.nums(p)?;
        let one = || b::num(1.0, span);
        let x0 = v[0].clone();
        let root = || {
            // sqrt(1 - x²)
            b::call(
                "sqrt",
                vec![b::bin(
                    w::BinOp::Sub,
                    one(),
                    b::bin(w::BinOp::Mul, x0.clone(), x0.clone()),
                )],
                span,
            )
        };
        let (y, x) = match key {
            "atan2" => (v[0].clone(), v[1].clone()),
            "atan" => (v[0].clone(), one()),
            "asin" => (v[0].clone(), root()),
            _ => (root(), v[0].clone()),
        };
        num(b::without_unit(
            b::call("atan2", vec![y, x], span),
            Dim::ANGLE,
        ))
    }

    /// `Round(x)`, `Trunc(x)`.
    pub(crate) fn round_trunc(&mut self, c: &Call<'_>) -> Option<Val> {
        let (key, f, span) = (c.key, c.name, c.span);
        let p = &c.pos;
        let opts = &c.opts;
        // `\Dec:=n`: n decimals, by scaling by 10^n (a constant whole number 0 to 15).
        let scale = match opts.first() {
            None => None,
            Some((_, n, e)) => match e.map(|e| (e, self.const_num(e))) {
                Some((_, Some(d))) if (0.0..=15.0).contains(&d) && d.fract() == 0.0 => {
                    Some(10f64.powi(d as i32))
                }
                Some((e, Some(_))) => {
                    self.error(
                        Code::E0025,
                        format!(
                            "{}'s `\\Dec` is a whole number of decimals, 0 to 15",
                            f.text
                        ),
                        e.span,
                    );
                    return None;
                }
                _ => {
                    self.unsupported(
                        &format!("{}'s `\\Dec` of a value known only when running", f.text),
                        n.span,
                        "give the number of decimals as a constant",
                    );
                    return None;
                }
            },
        };
        let x = self.nums(p)?.remove(0);
        let x = match scale {
            Some(k) => b::bin(w::BinOp::Mul, x, b::num(k, span)),
            None => x,
        };
        let unscale = |e: w::Expr| match scale {
            Some(k) => b::bin(w::BinOp::Div, e, b::num(k, span)),
            None => e,
        };
        if key == "trunc" {
            return num(unscale(b::call(
                "num",
                vec![b::call("int", vec![x], span)],
                span,
            )));
        }
        self.round_helper(span);
        num(unscale(b::call("round'", vec![x], span)))
    }

    /// `OrientZYX(z, y, x)`.
    pub(crate) fn orient_zyx(&mut self, c: &Call<'_>) -> Option<Val> {
        let span = c.span;
        let p = &c.pos;
        let v = self.nums(p)?;
        let zero = b::quantity(0.0, Dim::LENGTH, span);
        let a = |e: &w::Expr| b::with_unit(e.clone(), Dim::ANGLE);
        Some(Val::one(
            Ty::Orient,
            b::pose(
                [
                    zero.clone(),
                    zero.clone(),
                    zero,
                    a(&v[2]),
                    a(&v[1]),
                    a(&v[0]),
                ],
                span,
            ),
        ))
    }

    /// `Dim(a, k)`: the size of dimension `k` (a constant).
    pub(crate) fn dim(&mut self, c: &Call<'_>) -> Option<Val> {
        let span = c.span;
        let p = &c.pos;
        let (_, d) = self.data_arg(p[0], "an array", |d| d.len.is_some())?;
        let k = self.const_num(p[1]);
        let size = k
            .filter(|k| k.fract() == 0.0 && *k >= 1.0)
            .and_then(|k| d.dims.get(k as usize - 1));
        let Some(&len) = size else {
            self.error(
                Code::E0025,
                format!(
                    "the array has {} dimension{}: Dim(a, 1){}",
                    d.dims.len(),
                    if d.dims.len() == 1 { "" } else { "s" },
                    if d.dims.len() > 1 {
                        format!(" to Dim(a, {})", d.dims.len())
                    } else {
                        String::new()
                    }
                ),
                p[1].span,
            );
            return None;
        };
        Some(Val::one(Ty::Num, b::num(f64::from(len), span)))
    }

    /// `round'(x)`: RAPID's Round, half away from zero, generated once.
    fn round_helper(&mut self, span: Span) {
        if !self.helpers.insert("round'".into()) {
            return;
        }
        let x = || b::name("x", span);
        let half = || b::num(0.5, span);
        let r = |e: w::Expr| b::call("num", vec![b::call("int", vec![e], span)], span);
        let up = w::Stmt {
            kind: w::StmtKind::Return(Some(r(b::bin(w::BinOp::Add, x(), half())))),
            span,
        };
        let down = w::Stmt {
            kind: w::StmtKind::Return(Some(b::neg(r(b::bin(w::BinOp::Sub, half(), x()))))),
            span,
        };
        let cond = b::bin(w::BinOp::Ge, x(), b::num(0.0, span));
        let body = vec![
            w::Stmt {
                kind: w::StmtKind::If {
                    branches: vec![(cond, super::block(vec![up], span))],
                    els: None,
                },
                span,
            },
            down,
        ];
        self.items.push(w::Item::Proc(w::ProcDecl {
            is_func: true,
            name: b::ident("round'", span),
            params: vec![w::Param {
                name: b::ident("x", span),
                ty: b::ident("num", span),
            }],
            ret: Some(b::ident("num", span)),
            body: super::block(body, span),
            handler: None,
            span,
        }));
    }
}

/// A num's value.
fn num(e: w::Expr) -> Option<Val> {
    Some(Val::one(Ty::Num, e))
}
