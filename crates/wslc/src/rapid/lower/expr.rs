//! RAPID expressions: their types, and the WSL expressions that compute their leaves.
//! Aggregates (`[500, 0, 400]`) take their type from where they stand. A call goes to the
//! function table ([`super::table::FUNCTIONS`], lowered in `functions.rs`) or to a FUNC
//! of the task; the arguments of every built-in are checked here (`split_args`).

use vworks_vm::Dim;

use super::data::{Ty, build as b, quat_rpy};
use super::{Data, Sym, Tr, Val};
use crate::diag::Code;
use crate::rapid::catalog::Kind;
use crate::rapid::syntax::{self as r, Arg};
use crate::syntax::{self as w, Span};

impl Tr<'_> {
    /// An expression that must have type `want` (aggregates are read as `want`).
    pub(crate) fn value(&mut self, e: &r::Expr, want: Ty) -> Option<Val> {
        if let r::ExprKind::Aggregate(items) = &e.kind {
            return self.aggregate(items, want, e.span);
        }
        let v = self.expr(e)?;
        // (`intnum` is an alias of `num`, its properties and all: each is the other.)
        let nums = [Ty::Num, Ty::Intnum];
        if v.ty == want || (nums.contains(&v.ty) && nums.contains(&want)) {
            return Some(Val { ty: want, ..v });
        }
        // A pose-like value where another pose-like one is wanted: RAPID converts none of
        // them, and neither does vworks.
        self.error(
            Code::E0020,
            format!("expected {} here, found {}", article(want), article(v.ty)),
            e.span,
        );
        None
    }

    /// An expression of any type.
    pub(crate) fn expr(&mut self, e: &r::Expr) -> Option<Val> {
        let span = e.span;
        match &e.kind {
            r::ExprKind::Num(x) => Some(Val::one(Ty::Num, b::num(*x, span))),
            r::ExprKind::Bool(v) => Some(Val::one(Ty::Bool, b::expr(w::ExprKind::Bool(*v), span))),
            r::ExprKind::Str(s) => {
                let n = s.chars().count();
                if n > vworks_vm::texts::MAX_CHARS {
                    self.error(
                        Code::E0025,
                        format!(
                            "a string of {n} characters: RAPID's strings hold at most {}",
                            vworks_vm::texts::MAX_CHARS
                        ),
                        span,
                    );
                    return None;
                }
                Some(Val::text(s.clone(), span))
            }
            r::ExprKind::Name(n) => self.name_value(n),
            r::ExprKind::Aggregate(_) => {
                self.error(
                    Code::E0020,
                    "the type of this `[…]` is not known here",
                    span,
                )
                .help = Some("declare the value as data of a named type, and use its name".into());
                None
            }
            r::ExprKind::Unary(op, x) => {
                let v = self.expr(x)?;
                match (op, v.ty) {
                    (r::UnOp::Neg, Ty::Num) => Some(Val::one(Ty::Num, b::neg(v.leaf()))),
                    (r::UnOp::Plus, Ty::Num) => Some(v),
                    (r::UnOp::Not, Ty::Bool) => Some(Val::one(Ty::Bool, b::not(v.leaf()))),
                    (_, t) => {
                        let sym = match op {
                            r::UnOp::Neg => "-",
                            r::UnOp::Plus => "+",
                            r::UnOp::Not => "NOT",
                        };
                        self.error(
                            Code::E0022,
                            format!("`{sym}` does not apply to {}", article(t)),
                            span,
                        );
                        None
                    }
                }
            }
            r::ExprKind::Binary(op, l, rr) => self.binary(*op, l, rr, span),
            r::ExprKind::Call(f, args) => self.function(f, args, span),
            r::ExprKind::Field(x, f) => self.field_value(x, f, span),
            r::ExprKind::Index(x, idx) => self.element(x, idx, span),
            r::ExprKind::Error => None,
        }
    }

    fn name_value(&mut self, n: &r::Name) -> Option<Val> {
        match self.lookup(&n.key()) {
            Some(Sym::Data(d)) => {
                if d.len.is_some() {
                    self.error(
                        Code::E0020,
                        format!(
                            "`{}` is an array; give an element, `{}{{1}}`",
                            n.text, n.text
                        ),
                        n.span,
                    );
                    return None;
                }
                Some(self.data_value(&d, None, n.span))
            }
            Some(Sym::Routine(_)) => {
                self.error(
                    Code::E0033,
                    format!("`{}` is a routine, not data", n.text),
                    n.span,
                );
                None
            }
            None => {
                if let Some(v) = self.signal_value(n) {
                    return Some(v);
                }
                self.unknown_name(n);
                None
            }
        }
    }

    pub(crate) fn unknown_name(&mut self, n: &r::Name) {
        if self.not_run(n, &[Kind::Data]) {
            return;
        }
        let key = n.key();
        let names: Vec<String> = self
            .locals
            .iter()
            .flat_map(|s| s.keys().cloned())
            .chain(
                self.module_scope
                    .keys()
                    .filter(|(m, _)| *m == self.module)
                    .map(|(_, k)| k.clone()),
            )
            .chain(self.scope.keys().cloned())
            .collect();
        let near = crate::suggest::nearest(&key, names.iter().map(String::as_str)).map(|m| {
            self.spelled
                .get(m)
                .cloned()
                .unwrap_or_else(|| m.to_string())
        });
        let elsewhere = self.local_elsewhere(&key);
        let d = self.error(Code::E0010, format!("unknown name `{}`", n.text), n.span);
        d.notes.extend(elsewhere);
        if let Some(m) = near {
            d.help = Some(format!("did you mean `{m}`?"));
        } else {
            d.help = Some("declare it with VAR, PERS or CONST".into());
        }
    }

    /// An argument that must be the name of data `fits` accepts (`what` describes it:
    /// "a loaddata"): its name and the data, or a diagnostic.
    pub(crate) fn data_arg<'e>(
        &mut self,
        e: &'e r::Expr,
        what: &str,
        fits: impl Fn(&Data) -> bool,
    ) -> Option<(&'e r::Name, Data)> {
        let r::ExprKind::Name(n) = &e.kind else {
            self.error(Code::E0020, format!("expected the name of {what}"), e.span);
            return None;
        };
        match self.lookup(&n.key()) {
            Some(Sym::Data(d)) if fits(&d) => Some((n, d)),
            Some(_) => {
                self.error(Code::E0020, format!("`{}` is not {what}", n.text), n.span);
                None
            }
            None => {
                self.unknown_name(n);
                None
            }
        }
    }

    /// The leaves of data `d` (element `index` of an array, 1-based).
    pub(crate) fn data_value(&mut self, d: &Data, index: Option<u32>, span: Span) -> Val {
        // (An intnum's value is a num: the alias's properties are num's.)
        let ty = if d.ty == Ty::Intnum { Ty::Num } else { d.ty };
        if let Some(parts) = &d.inline {
            return Val {
                ty,
                parts: parts
                    .iter()
                    .map(|p| w::Expr {
                        kind: p.kind.clone(),
                        span,
                    })
                    .collect(),
                text: None,
            };
        }
        Val {
            ty,
            parts: self
                .leaf_names(d, index)
                .iter()
                .map(|n| b::name(n, span))
                .collect(),
            text: d.text.clone(),
        }
    }

    /// `a{i}`.
    fn element(&mut self, x: &r::Expr, idx: &[r::Expr], span: Span) -> Option<Val> {
        let r::ExprKind::Name(n) = &x.kind else {
            self.unsupported(
                "indexing anything but an array's name",
                span,
                "index the array by its name",
            );
            return None;
        };
        let d = match self.lookup(&n.key()) {
            Some(Sym::Data(d)) if d.len.is_some() => d,
            Some(_) => {
                self.error(Code::E0022, format!("`{}` is not an array", n.text), n.span);
                return None;
            }
            None => {
                self.unknown_name(n);
                return None;
            }
        };
        let index = match self.flat_index(n, &d, idx)? {
            super::arrays::Flat::Const(k) => return Some(self.data_value(&d, Some(k), span)),
            super::arrays::Flat::Var(e) => e,
        };
        if d.local {
            self.unsupported(
                "a routine's local array indexed by a variable",
                span,
                "declare the array at module level (VAR, PERS or CONST), where vworks generates its accessor",
            );
            return None;
        }

        let parts = self
            .leaves(d.ty)
            .iter()
            .map(|(suffix, _)| {
                b::call(
                    &format!("{}{{}}{suffix}", d.base),
                    vec![index.clone()],
                    span,
                )
            })
            .collect();
        Some(Val {
            ty: d.ty,
            parts,
            text: None,
        })
    }

    fn binary(&mut self, op: r::BinOp, l: &r::Expr, rr: &r::Expr, span: Span) -> Option<Val> {
        use r::BinOp as O;
        let a = self.expr(l)?;
        let c = self.expr(rr)?;
        let wop = |op: O| match op {
            O::Add => w::BinOp::Add,
            O::Sub => w::BinOp::Sub,
            O::Mul => w::BinOp::Mul,
            O::Div => w::BinOp::Div,
            O::Eq => w::BinOp::Eq,
            O::Ne => w::BinOp::Ne,
            O::Lt => w::BinOp::Lt,
            O::Le => w::BinOp::Le,
            O::Gt => w::BinOp::Gt,
            O::Ge => w::BinOp::Ge,
            O::And => w::BinOp::And,
            O::Or => w::BinOp::Or,
            O::IntDiv | O::Mod | O::Xor => w::BinOp::Mod,
        };
        match (a.ty, c.ty, op) {
            // Texts known when compiling are joined and compared then; others at run time.
            (Ty::Str, Ty::Str, O::Add) => match (&a.text, &c.text) {
                (Some(x), Some(y)) => Some(Val::text(format!("{x}{y}"), span)),
                _ => Some(Val::one(Ty::Str, b::bin(w::BinOp::Add, a.leaf(), c.leaf()))),
            },
            (Ty::Str, Ty::Str, O::Eq | O::Ne) => match (&a.text, &c.text) {
                (Some(x), Some(y)) => Some(Val::one(
                    Ty::Bool,
                    b::expr(w::ExprKind::Bool((x == y) == (op == O::Eq)), span),
                )),
                _ => Some(Val::one(Ty::Bool, b::bin(wop(op), a.leaf(), c.leaf()))),
            },
            (Ty::Num, Ty::Num, O::Add | O::Sub | O::Mul | O::Div) => {
                Some(Val::one(Ty::Num, b::bin(wop(op), a.leaf(), c.leaf())))
            }
            (Ty::Num, Ty::Num, O::IntDiv | O::Mod) => {
                // Integer division and remainder of the operands (RAPID requires whole
                // numbers), as a num again.
                let ai = b::call("int", vec![a.leaf()], l.span);
                let ci = b::call("int", vec![c.leaf()], rr.span);
                let o = if op == O::Mod {
                    w::BinOp::Mod
                } else {
                    w::BinOp::Div
                };
                Some(Val::one(
                    Ty::Num,
                    b::call("num", vec![b::bin(o, ai, ci)], span),
                ))
            }
            (Ty::Num, Ty::Num, O::Eq | O::Ne | O::Lt | O::Le | O::Gt | O::Ge)
            | (Ty::Bool, Ty::Bool, O::Eq | O::Ne) => {
                Some(Val::one(Ty::Bool, b::bin(wop(op), a.leaf(), c.leaf())))
            }
            (Ty::Bool, Ty::Bool, O::And | O::Or) => {
                Some(Val::one(Ty::Bool, b::bin(wop(op), a.leaf(), c.leaf())))
            }
            (Ty::Bool, Ty::Bool, O::Xor) => {
                let (x, y) = (a.leaf(), c.leaf());
                let either = b::bin(w::BinOp::Or, x.clone(), y.clone());
                let both = b::bin(w::BinOp::And, x, y);
                Some(Val::one(
                    Ty::Bool,
                    b::bin(w::BinOp::And, either, b::not(both)),
                ))
            }
            (Ty::Pos, Ty::Pos, O::Add | O::Sub) => {
                let (p, q) = (a.leaf(), c.leaf());
                let d = |f: &str| {
                    let e = b::field(q.clone(), f);
                    if op == O::Sub { b::neg(e) } else { e }
                };
                Some(Val::one(
                    Ty::Pos,
                    b::call("offset", vec![p, d("x"), d("y"), d("z")], span),
                ))
            }
            (Ty::Pos, Ty::Num, O::Mul) | (Ty::Num, Ty::Pos, O::Mul) => {
                let (p, k) = if a.ty == Ty::Pos {
                    (a.leaf(), c.leaf())
                } else {
                    (c.leaf(), a.leaf())
                };
                Some(Val::one(
                    Ty::Pos,
                    self.pos_of(p, span, |e| b::bin(w::BinOp::Mul, e, k.clone())),
                ))
            }
            (x, y, _) => {
                self.error(
                    Code::E0022,
                    format!("`{}` does not apply to {} and {}", op.symbol(), article(x), article(y)),
                    span,
                )
                .help = Some(
                    "RAPID's arithmetic is on num (and + - on pos, * of pos by num); comparisons on num, = and <> on bool".into(),
                );
                None
            }
        }
    }

    /// A pos (a pose without rotation) from a pose's x, y, z mapped by `f`.
    pub(crate) fn pos_of(&self, p: w::Expr, span: Span, f: impl Fn(w::Expr) -> w::Expr) -> w::Expr {
        let zero = b::quantity(0.0, Dim::ANGLE, span);
        b::pose(
            [
                f(b::field(p.clone(), "x")),
                f(b::field(p.clone(), "y")),
                f(b::field(p, "z")),
                zero.clone(),
                zero.clone(),
                zero,
            ],
            span,
        )
    }

    /// `e.field` read.
    fn field_value(&mut self, x: &r::Expr, f: &r::Name, span: Span) -> Option<Val> {
        let v = self.expr(x)?;
        if let Ty::Record(_) = v.ty {
            return self.record_field(v, f);
        }
        let key = f.key();
        let num_of = |e: w::Expr, dim: Dim| Some(Val::one(Ty::Num, b::without_unit(e, dim)));
        match (v.ty, key.as_str()) {
            (Ty::Robtarget | Ty::Pose, "trans") => {
                let p = v.leaf();
                Some(Val::one(Ty::Pos, self.pos_of(p, span, |e| e)))
            }
            (Ty::Robtarget | Ty::Pose, "rot") => {
                let p = v.leaf();
                let zero = b::quantity(0.0, Dim::LENGTH, span);
                Some(Val::one(
                    Ty::Orient,
                    b::pose(
                        [
                            zero.clone(),
                            zero.clone(),
                            zero,
                            b::field(p.clone(), "rx"),
                            b::field(p.clone(), "ry"),
                            b::field(p, "rz"),
                        ],
                        span,
                    ),
                ))
            }
            (Ty::Pos, "x" | "y" | "z") => num_of(b::field(v.leaf(), &key), Dim::LENGTH),
            (Ty::Orient, "q1" | "q2" | "q3" | "q4") => {
                Some(Val::one(Ty::Num, quaternion_part(v.leaf(), &key, span)))
            }
            (Ty::Speed, "v_tcp") => num_of(v.parts[0].clone(), Dim::SPEED),
            (Ty::Speed, "v_ori") => num_of(v.parts[1].clone(), Dim::ANGSPEED),
            (Ty::Zone, "pzone_tcp") => num_of(v.parts[0].clone(), Dim::LENGTH),
            (Ty::Zone, "pzone_ori") => num_of(v.parts[1].clone(), Dim::LENGTH),
            (Ty::Zone, "zone_ori") => num_of(v.parts[2].clone(), Dim::ANGLE),
            (Ty::Tool, "tframe") => Some(Val::one(Ty::Pose, v.leaf())),
            (Ty::Wobj, "uframe") => Some(Val::one(Ty::Pose, v.parts[0].clone())),
            (Ty::Wobj, "oframe") => Some(Val::one(Ty::Pose, v.parts[1].clone())),
            (Ty::Jointtarget, "robax") => Some(Val::one(Ty::Robjoint, v.leaf())),
            _ => {
                // `r.rax_3`, `jt.robax.rax_3`
                if let (Ty::Robjoint, Some(n)) = (v.ty, key.strip_prefix("rax_"))
                    && let Ok(k @ 1..=6) = n.parse::<i64>()
                {
                    let j = b::expr(
                        w::ExprKind::Index(
                            Box::new(v.leaf()),
                            Box::new(b::expr(w::ExprKind::Int(k - 1), f.span)),
                        ),
                        span,
                    );
                    return num_of(j, Dim::ANGLE);
                }
                self.unsupported(
                    &format!("the component `{}` of {}", f.text, article(v.ty)),
                    f.span,
                    "docs/rapid.md lists the components vworks reads: trans, rot, x, y, z, q1…q4, robax.rax_1…6, v_tcp, v_ori, pzone_tcp, pzone_ori, zone_ori, tframe, uframe, oframe",
                );
                None
            }
        }
    }

    /// An aggregate read as type `want`.
    fn aggregate(&mut self, items: &[r::Expr], want: Ty, span: Span) -> Option<Val> {
        let need = |n: usize| -> Result<(), String> {
            if items.len() == n {
                Ok(())
            } else {
                Err(format!(
                    "{} is written with {n} values in `[…]`, not {}",
                    article(want),
                    items.len()
                ))
            }
        };
        let count = match want {
            Ty::Pos => 3,
            Ty::Orient | Ty::Conf => 4,
            Ty::Pose => 2,
            Ty::Robtarget => 4,
            Ty::Jointtarget => 2,
            Ty::Robjoint => 6,
            Ty::Speed => 4,
            Ty::Zone => 7,
            Ty::Tool => 3,
            Ty::Wobj => 5,
            Ty::Load => 6,
            Ty::Extax => 6,
            Ty::Tasks => 1,
            Ty::Record(_) => return self.record_aggregate(items, want, span),
            Ty::Num | Ty::Bool | Ty::Str | Ty::Intnum | Ty::Syncident | Ty::Clock | Ty::Switch => {
                self.error(
                    Code::E0020,
                    format!("expected {}, found `[…]`", article(want)),
                    span,
                );
                return None;
            }
        };
        if let Err(m) = need(count) {
            self.error(Code::E0013, m, span);
            return None;
        }
        let nums = |t: &mut Self, from: usize, n: usize| -> Option<Vec<w::Expr>> {
            items[from..from + n]
                .iter()
                .map(|e| t.value(e, Ty::Num).map(Val::leaf))
                .collect()
        };
        match want {
            Ty::Pos => {
                let v = nums(self, 0, 3)?;
                let [x, y, z] = <[w::Expr; 3]>::try_from(v).ok()?;
                let zero = b::quantity(0.0, Dim::ANGLE, span);
                Some(Val::one(
                    Ty::Pos,
                    b::pose(
                        [
                            b::with_unit(x, Dim::LENGTH),
                            b::with_unit(y, Dim::LENGTH),
                            b::with_unit(z, Dim::LENGTH),
                            zero.clone(),
                            zero.clone(),
                            zero,
                        ],
                        span,
                    ),
                ))
            }
            Ty::Orient => {
                let v = nums(self, 0, 4)?;
                let q: Option<Vec<f64>> = v.iter().map(b::literal).collect();
                let Some(q) = q else {
                    self.unsupported(
                        "an orient computed at run time from quaternion components",
                        span,
                        "write the quaternion's four numbers, or use OrientZYX",
                    );
                    return None;
                };
                let Some(rpy) = quat_rpy([q[0], q[1], q[2], q[3]]) else {
                    self.error(
                        Code::E0025,
                        "the quaternion [0, 0, 0, 0] is no orientation",
                        span,
                    )
                    .help = Some(
                        "an orient is a unit quaternion [q1, q2, q3, q4], e.g. [1, 0, 0, 0]".into(),
                    );
                    return None;
                };
                let zero = b::quantity(0.0, Dim::LENGTH, span);
                let [rx, ry, rz] = rpy.map(|a| b::quantity(a, Dim::ANGLE, span));
                Some(Val::one(
                    Ty::Orient,
                    b::pose([zero.clone(), zero.clone(), zero, rx, ry, rz], span),
                ))
            }
            Ty::Pose | Ty::Robtarget => {
                let t = self.value(&items[0], Ty::Pos)?.leaf();
                let o = self.value(&items[1], Ty::Orient)?.leaf();
                if want == Ty::Robtarget {
                    self.value(&items[2], Ty::Conf)?;
                    self.value(&items[3], Ty::Extax)?;
                }
                Some(Val::one(want, merge_pose(t, o, span)))
            }
            Ty::Jointtarget | Ty::Robjoint => {
                let ax = if want == Ty::Robjoint {
                    items
                } else {
                    let r::ExprKind::Aggregate(ax) = &items[0].kind else {
                        self.error(
                            Code::E0020,
                            "robax is written `[a1, a2, a3, a4, a5, a6]` (degrees)",
                            items[0].span,
                        );
                        return None;
                    };
                    ax
                };
                if ax.len() != 6 {
                    self.error(
                        Code::E0013,
                        format!("robax has 6 values, not {}", ax.len()),
                        items[0].span,
                    );
                    return None;
                }
                if want == Ty::Jointtarget {
                    self.value(&items[1], Ty::Extax)?;
                }
                let mut vals = Vec::new();
                for e in ax {
                    vals.push(self.value(e, Ty::Num)?.leaf());
                }
                // Unused axes are 9E9: an arm with fewer axes than six ends there.
                while vals.last().and_then(b::literal).is_some_and(|x| x >= 9e8) {
                    vals.pop();
                }
                let vals = vals
                    .into_iter()
                    .map(|e| b::with_unit(e, Dim::ANGLE))
                    .collect();
                Some(Val::one(want, b::call("joints", vals, span)))
            }
            Ty::Speed => {
                let v = nums(self, 0, 4)?;
                Some(Val {
                    ty: Ty::Speed,
                    parts: vec![
                        b::with_unit(v[0].clone(), Dim::SPEED),
                        b::with_unit(v[1].clone(), Dim::ANGSPEED),
                    ],
                    text: None,
                })
            }
            Ty::Zone => {
                // [finep, pzone_tcp, pzone_ori, pzone_eax, zone_ori, zone_leax, zone_reax]
                let finep = self.value(&items[0], Ty::Bool)?.leaf();
                let v = nums(self, 1, 6)?;
                let parts = match finep.kind {
                    w::ExprKind::Bool(true) => vec![
                        b::quantity(0.0, Dim::LENGTH, span),
                        b::quantity(0.0, Dim::LENGTH, span),
                        b::quantity(0.0, Dim::ANGLE, span),
                    ],
                    w::ExprKind::Bool(false) => vec![
                        b::with_unit(v[0].clone(), Dim::LENGTH),
                        b::with_unit(v[1].clone(), Dim::LENGTH),
                        b::with_unit(v[3].clone(), Dim::ANGLE),
                    ],
                    _ => {
                        self.unsupported(
                            "a zonedata whose finep is not TRUE or FALSE",
                            items[0].span,
                            "write TRUE or FALSE",
                        );
                        return None;
                    }
                };
                Some(Val {
                    ty: Ty::Zone,
                    parts,
                    text: None,
                })
            }
            Ty::Tool => {
                self.robhold(
                    &items[0],
                    true,
                    "a stationary tool (robhold FALSE)",
                    "hold the tool on the robot (robhold TRUE)",
                )?;
                let frame = self.value(&items[1], Ty::Pose)?.leaf();
                self.value(&items[2], Ty::Load)?;
                Some(Val::one(Ty::Tool, frame))
            }
            Ty::Wobj => {
                self.robhold(
                    &items[0],
                    false,
                    "a work object held by the robot (robhold TRUE)",
                    "use a fixed work object (robhold FALSE)",
                )?;
                self.value(&items[1], Ty::Bool)?;
                let mech = self.expr(&items[2])?;
                if mech.ty != Ty::Str {
                    self.error(
                        Code::E0020,
                        "ufmec is a string (\"\" for a fixed frame)",
                        items[2].span,
                    );
                    return None;
                }
                let u = self.value(&items[3], Ty::Pose)?.leaf();
                let o = self.value(&items[4], Ty::Pose)?.leaf();
                Some(Val {
                    ty: Ty::Wobj,
                    parts: vec![u, o],
                    text: None,
                })
            }
            Ty::Load => {
                self.value(&items[0], Ty::Num)?;
                self.value(&items[1], Ty::Pos)?;
                self.value(&items[2], Ty::Orient)?;
                nums(self, 3, 3)?;
                Some(Val {
                    ty: Ty::Load,
                    parts: Vec::new(),
                    text: None,
                })
            }
            Ty::Conf | Ty::Extax => {
                nums(self, 0, count)?;
                Some(Val {
                    ty: want,
                    parts: Vec::new(),
                    text: None,
                })
            }
            Ty::Tasks => {
                let name = self.expr(&items[0])?;
                if name.ty != Ty::Str {
                    self.error(
                        Code::E0020,
                        "a task is written `[\"T_ROB1\"]`",
                        items[0].span,
                    );
                    return None;
                }
                Some(Val {
                    ty: Ty::Tasks,
                    parts: Vec::new(),
                    text: name.text,
                })
            }
            Ty::Num
            | Ty::Bool
            | Ty::Str
            | Ty::Intnum
            | Ty::Syncident
            | Ty::Clock
            | Ty::Switch
            | Ty::Record(_) => None,
        }
    }

    /// A record's `robhold`, which vworks runs only as `want` (E0300 otherwise).
    fn robhold(&mut self, e: &r::Expr, want: bool, what: &str, help: &str) -> Option<()> {
        let v = self.value(e, Ty::Bool)?.leaf();
        if v.kind == w::ExprKind::Bool(want) {
            return Some(());
        }
        self.unsupported(what, e.span, help);
        None
    }

    /// A function call in an expression: RAPID's built-in functions, or a FUNC.
    fn function(&mut self, f: &r::Name, args: &[Arg], span: Span) -> Option<Val> {
        let key = f.key();
        if let Some(v) = self.builtin_function(&key, f, args, span) {
            return v;
        }
        match self.lookup(&key) {
            Some(Sym::Routine(sig)) if sig.kind == r::RoutineKind::Func => {
                if sig.by_ref.iter().any(Option::is_some) {
                    self.unsupported(
                        &format!("calling `{}`, a FUNC with `VAR`/`PERS`/`INOUT` parameters, in an expression", f.text),
                        f.span,
                        "make it a PROC that writes its result to a VAR parameter",
                    );
                    return None;
                }
                let wargs = self.call_args(f, &sig, args, span)?;
                let ret = sig.ret.unwrap_or(Ty::Num);
                // (A FUNC of a type held in more than one WSL value, a speeddata or a
                // zonedata, is E0300 where it is declared: no value here.)
                self.leaf_type(ret)?;
                Some(Val::one(ret, b::call(&sig.wsl, wargs, span)))
            }
            Some(Sym::Routine(_)) => {
                self.error(
                    Code::E0033,
                    format!(
                        "`{}` is a PROC or TRAP, not a FUNC: it has no value",
                        f.text
                    ),
                    f.span,
                );
                None
            }
            Some(Sym::Data(_)) => {
                self.error(
                    Code::E0011,
                    format!("`{}` is data, not a function", f.text),
                    f.span,
                );
                None
            }
            None if self.not_run(f, &[Kind::Function]) => None,
            None => {
                let elsewhere = self.local_elsewhere(&f.key());
                let d = self.error(
                    Code::E0011,
                    format!("unknown function `{}`", f.text),
                    f.span,
                );
                d.help = Some("docs/rapid.md lists RAPID's functions that vworks runs".into());
                d.notes.extend(elsewhere);
                None
            }
        }
    }

    /// The WSL arguments of a call of a PROC or FUNC of signature `sig`: the required
    /// arguments' leaves, then for each optional parameter its leaves and whether it is
    /// given (`\\x:=e`; a switch `\\On`; `\\x?y` as the caller's own optional `y` is;
    /// not given: its type's zero and FALSE).
    pub(crate) fn call_args(
        &mut self,
        f: &r::Name,
        sig: &super::Sig,
        args: &[Arg],
        span: Span,
    ) -> Option<Vec<w::Expr>> {
        let params = &sig.params;
        let mut pos = Vec::new();
        let mut given: Vec<(&r::Name, &Arg)> = Vec::new();
        for a in args {
            match a {
                Arg::Pos(e) => pos.push(e),
                Arg::Opt(n, _) | Arg::Cond(n, _) => {
                    if !sig.optional.iter().any(|o| o.key == n.key()) {
                        let known: Vec<String> = sig
                            .optional
                            .iter()
                            .map(|o| format!("\\{}", o.spelled))
                            .collect();
                        let near = crate::suggest::nearest(
                            &n.key(),
                            sig.optional.iter().map(|o| o.key.as_str()),
                        )
                        .and_then(|k| sig.optional.iter().find(|o| o.key == k))
                        .map(|o| format!("did you mean `\\{}`? ", o.spelled))
                        .unwrap_or_default();
                        self.error(
                            Code::E0301,
                            format!("`{}` has no optional parameter `\\{}`", f.text, n.text),
                            n.span,
                        )
                        .help = Some(if known.is_empty() {
                            format!("`{}` has no optional parameters", f.text)
                        } else {
                            format!("{near}its optional parameters: {}", known.join(", "))
                        });
                        return None;
                    }
                    given.push((n, a));
                }
            }
        }
        if pos.len() != params.len() {
            self.error(
                Code::E0013,
                format!(
                    "`{}` takes {} argument{}, {} given",
                    f.text,
                    params.len(),
                    if params.len() == 1 { "" } else { "s" },
                    pos.len()
                ),
                span,
            );
            return None;
        }
        let mut out = Vec::new();
        for ((e, t), by_ref) in pos.into_iter().zip(params).zip(&sig.by_ref) {
            // (An argument by reference is copied in and out around the call.)
            if by_ref.is_none() {
                out.extend(self.value(e, *t)?.parts);
            }
        }
        for o in &sig.optional {
            let leaves = self.leaves(o.ty);
            let zero = |sp: Span| -> Vec<w::Expr> {
                leaves.iter().map(|(_, t)| b::zero(*t, sp)).collect()
            };
            let yes = |v: bool, sp: Span| b::expr(w::ExprKind::Bool(v), sp);
            match given.iter().find(|(n, _)| n.key() == o.key) {
                None => {
                    out.extend(zero(span));
                    out.push(yes(false, span));
                }
                Some((n, Arg::Opt(_, None))) => {
                    if o.ty != Ty::Switch {
                        self.error(
                            Code::E0301,
                            format!("`\\{}` needs a value: `\\{}:=…`", n.text, n.text),
                            n.span,
                        );
                        return None;
                    }
                    out.push(yes(true, n.span));
                }
                Some((n, Arg::Opt(_, Some(e)))) => {
                    if o.ty == Ty::Switch {
                        self.error(
                            Code::E0301,
                            format!("`\\{}` is a switch: it takes no value", n.text),
                            e.span,
                        );
                        return None;
                    }
                    out.extend(self.value(e, o.ty)?.parts);
                    out.push(yes(true, n.span));
                }
                Some((_, Arg::Cond(_, x))) => {
                    let d = match self.lookup(&x.key()) {
                        Some(Sym::Data(d)) if d.optional => d,
                        _ => {
                            self.error(
                                Code::E0020,
                                format!(
                                    "`{}` is not an optional parameter of this routine",
                                    x.text
                                ),
                                x.span,
                            )
                            .help = Some("`\\name?x` passes the routine's own optional parameter `x` on, if it was given".into());
                            return None;
                        }
                    };
                    if d.ty != o.ty {
                        self.error(
                            Code::E0020,
                            format!(
                                "`\\{}` is {}, `{}` {}",
                                o.spelled,
                                article(o.ty),
                                x.text,
                                article(d.ty)
                            ),
                            x.span,
                        );
                        return None;
                    }
                    out.extend(self.leaf_names(&d, None).iter().map(|n| b::name(n, x.span)));
                    out.push(b::name(&d.present(), x.span));
                }
                Some((_, Arg::Pos(_))) => {}
            }
        }
        Some(out)
    }

    /// `Present(x)`: whether the optional parameter `x` of this routine was given.
    pub(crate) fn present(&mut self, c: &super::table::Call<'_>) -> Option<Val> {
        let e = c.pos[0];
        let d = match &e.kind {
            r::ExprKind::Name(n) => match self.lookup(&n.key()) {
                Some(Sym::Data(d)) if d.optional => Some(d),
                _ => None,
            },
            _ => None,
        };
        let Some(d) = d else {
            self.error(
                Code::E0020,
                "Present takes an optional parameter of this routine",
                e.span,
            )
            .help = Some(
                "a required parameter is always present; declare it `\\num x` to make it optional"
                    .into(),
            );
            return None;
        };
        Some(Val::one(Ty::Bool, b::name(&d.present(), e.span)))
    }

    /// The value of the optional argument `key` (lower case) among `opts`: `Ok(None)` if
    /// it is not given, E0301 (`Err`) if it is given without `:=` (`example` shows one).
    pub(crate) fn opt_value<'e>(
        &mut self,
        opts: &[(String, &r::Name, Option<&'e r::Expr>)],
        key: &str,
        example: &str,
    ) -> Result<Option<&'e r::Expr>, ()> {
        match opts.iter().find(|(k, _, _)| k == key) {
            None => Ok(None),
            Some((_, _, Some(e))) => Ok(Some(*e)),
            Some((_, n, None)) => {
                self.error(
                    Code::E0301,
                    format!("`\\{}` is written `\\{}:={example}`", n.text, n.text),
                    n.span,
                );
                Err(())
            }
        }
    }

    /// The positional arguments and the optional ones of a built-in, checked against
    /// `count` and the optional names it takes.
    pub(crate) fn split_args<'a>(
        &mut self,
        f: &r::Name,
        args: &'a [Arg],
        count: std::ops::RangeInclusive<usize>,
        optional: &[&str],
        span: Span,
    ) -> Option<SplitArgs<'a>> {
        let mut pos = Vec::new();
        let mut opts = Vec::new();
        for a in args {
            match a {
                Arg::Pos(e) => pos.push(e),
                Arg::Cond(n, _) => {
                    self.unsupported(
                        &format!("the conditional argument `\\{}?…` of a built-in", n.text),
                        n.span,
                        "pass the argument, or leave it out, in an IF on Present(…)",
                    );
                    return None;
                }
                Arg::Opt(n, v) => {
                    let k = n.key();
                    if !optional.iter().any(|o| o.eq_ignore_ascii_case(&k)) {
                        let known = if optional.is_empty() {
                            "none".to_string()
                        } else {
                            optional
                                .iter()
                                .map(|o| format!("\\{o}"))
                                .collect::<Vec<_>>()
                                .join(", ")
                        };
                        self.error(
                            Code::E0301,
                            format!(
                                "`{}` has no optional argument `\\{}` that vworks runs",
                                f.text, n.text
                            ),
                            n.span,
                        )
                        .help = Some(format!("the optional arguments vworks runs here: {known}"));
                        return None;
                    }
                    opts.push((k, n, v.as_ref()));
                }
            }
        }
        if !count.contains(&pos.len()) {
            let want = if count.start() == count.end() {
                count.start().to_string()
            } else {
                format!("{} to {}", count.start(), count.end())
            };
            self.error(
                Code::E0013,
                format!("`{}` takes {want} arguments, {} given", f.text, pos.len()),
                span,
            );
            return None;
        }
        Some((pos, opts))
    }
}

/// A built-in's positional arguments, and its optional ones as (lower-case name, name as
/// written, value).
pub(crate) type SplitArgs<'a> = (
    Vec<&'a r::Expr>,
    Vec<(String, &'a r::Name, Option<&'a r::Expr>)>,
);

/// A pose from a pos's translation and an orient's rotation.
pub(crate) fn merge_pose(t: w::Expr, o: w::Expr, span: Span) -> w::Expr {
    // Literal pos and orient fold into one `pose(…)` of literals.
    if let (w::ExprKind::Call(tf, ta), w::ExprKind::Call(of, oa)) = (&t.kind, &o.kind)
        && tf.name == "pose"
        && of.name == "pose"
        && ta.len() == 6
        && oa.len() == 6
    {
        return b::pose(
            [
                ta[0].clone(),
                ta[1].clone(),
                ta[2].clone(),
                oa[3].clone(),
                oa[4].clone(),
                oa[5].clone(),
            ],
            span,
        );
    }
    b::pose(
        [
            b::field(t.clone(), "x"),
            b::field(t.clone(), "y"),
            b::field(t, "z"),
            b::field(o.clone(), "rx"),
            b::field(o.clone(), "ry"),
            b::field(o, "rz"),
        ],
        span,
    )
}

/// "a num", "an orient".
pub(crate) fn article(t: Ty) -> String {
    let n = t.name();
    if n.starts_with(['a', 'e', 'i', 'o', 'u']) {
        format!("an {n}")
    } else {
        format!("a {n}")
    }
}

/// Component `q` (`q1` the scalar part, `q2`…`q4` the vector) of the quaternion of an
/// orientation held as roll-pitch-yaw (`rx`, `ry`, `rz` of pose `p`; R = Rz·Ry·Rx): the
/// sign is the conversion's (q and −q are one orientation).
fn quaternion_part(p: w::Expr, q: &str, span: Span) -> w::Expr {
    let half = |axis: &str| b::bin(w::BinOp::Div, b::field(p.clone(), axis), b::num(2.0, span));
    let (c, s) = (
        |axis: &str| b::call("cos", vec![half(axis)], span),
        |axis: &str| b::call("sin", vec![half(axis)], span),
    );
    let prod = |a: w::Expr, bb: w::Expr, cc: w::Expr| {
        b::bin(w::BinOp::Mul, b::bin(w::BinOp::Mul, a, bb), cc)
    };
    let (cr, sr, cp, sp, cy, sy) = (c("rx"), s("rx"), c("ry"), s("ry"), c("rz"), s("rz"));
    let (first, op, second) = match q {
        "q1" => (
            prod(cr, cp.clone(), cy.clone()),
            w::BinOp::Add,
            prod(sr, sp, sy),
        ),
        "q2" => (prod(sr, cp, cy), w::BinOp::Sub, prod(cr, sp, sy)),
        "q3" => (prod(cr, sp, cy), w::BinOp::Add, prod(sr, cp, sy)),
        _ => (prod(cr, cp, sy), w::BinOp::Sub, prod(sr, sp, cy)),
    };
    b::bin(op, first, second)
}
