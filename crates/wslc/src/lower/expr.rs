//! Expressions: names, operators with their types and units, calls; constant folding
//! (each expression yields its type and, when constant, its value), coercions and the
//! diagnostics for unknown names.

use super::*;

impl Compiler<'_> {
    pub(super) fn expect_bool(&mut self, o: &Out, span: Span, what: &str) {
        if !matches!(o.ty, Ty::Bool | Ty::Error) {
            self.err(
                Diagnostic::error(
                    Code::E0024,
                    format!("{what} must be a bool, found {}", o.ty.described()),
                    span,
                )
                .with_help("compare it, e.g. `parts >= 3`"),
            );
        }
    }

    /// Converts `o` to `want` where allowed (int → num, a literal 0 to any unit), else reports.
    pub(super) fn coerce(&mut self, o: Out, want: Ty, span: Span, what: &str) -> Out {
        if o.ty == want || o.ty.is_err() || want.is_err() {
            return o;
        }
        match (o.ty, want) {
            (Ty::Int, Ty::Num(d)) if d.is_plain() || o.is_zero_literal() => {
                self.emit(Instr::IntToNum, span);
                let k = match o.k {
                    Some(ConstValue::Int(i)) => Some(ConstValue::Num(i as f64)),
                    _ => None,
                };
                Out {
                    ty: want,
                    k,
                    bare: o.bare,
                }
            }
            (Ty::Num(_), Ty::Num(_)) if o.is_zero_literal() => Out { ty: want, ..o },
            (Ty::Int | Ty::Num(_), Ty::Num(d)) => {
                let found = if o.ty == Ty::Int {
                    Dim::PLAIN
                } else if let Ty::Num(f) = o.ty {
                    f
                } else {
                    Dim::PLAIN
                };
                let mut diag = Diagnostic::error(
                    Code::E0021,
                    format!(
                        "{what} must be {}, found {}",
                        d.described(),
                        if o.ty == Ty::Int {
                            "an int".to_string()
                        } else {
                            found.described()
                        }
                    ),
                    span,
                )
                .with_label(format!("expected {}", d.described()));
                if o.bare
                    && let Some(u) = default_unit(d)
                {
                    let text = match o.k {
                        Some(ConstValue::Int(i)) => i.to_string(),
                        Some(ConstValue::Num(x)) => vworks_vm::types::fmt_num(x),
                        _ => "2".into(),
                    };
                    diag = diag.with_help(format!("write {text}{u}"));
                } else if d.is_plain() && !found.is_plain() {
                    diag = diag.with_help(format!(
                        "divide by a unit to get a plain number, e.g. `x / 1{}`",
                        default_unit(found).unwrap_or("s")
                    ));
                }
                self.err(diag);
                Out::err()
            }
            _ => {
                self.err(
                    Diagnostic::error(
                        Code::E0020,
                        format!(
                            "{what} must be {}, found {}",
                            want.described(),
                            o.ty.described()
                        ),
                        span,
                    )
                    .with_label(format!("expected {}", want.described())),
                );
                Out::err()
            }
        }
    }

    pub(super) fn unknown_name(&mut self, name: &str, span: Span) {
        let mut candidates: Vec<String> = self.symbols.keys().cloned().collect();
        if let Some(f) = self.fns.last() {
            candidates.extend(f.scopes.iter().flatten().map(|l| l.name.clone()));
        }
        let best = crate::suggest::nearest(name, candidates.iter().map(String::as_str));
        let mut d = Diagnostic::error(Code::E0010, format!("unknown name `{name}`"), span)
            .with_label("not declared");
        d = match best {
            Some(c) => d.with_help(format!("did you mean `{c}`?")),
            None => d.with_help("declare it with `var`, `const` or `global` before using it"),
        };
        self.err(d);
    }

    pub(super) fn unknown_proc(&mut self, name: &str, span: Span) {
        let names = self
            .sigs
            .iter()
            .map(|s| s.name.as_str())
            .chain(BUILTINS.iter().map(|b| b.name));
        let best = crate::suggest::nearest(name, names);
        let mut d = Diagnostic::error(
            Code::E0011,
            format!("unknown procedure or function `{name}`"),
            span,
        );
        if let Some(c) = best {
            d = d.with_help(format!("did you mean `{c}`?"));
        }
        self.err(d);
    }

    pub(super) fn note_impure(&mut self, what: &str, span: Span) {
        match self.fk() {
            FnKind::Cond => self.err(
                Diagnostic::error(Code::E0042, format!("a condition may not read {what}"), span)
                    .with_help("a condition is re-checked only when a global it reads is set; make it a `global`, or copy it into a local before waiting"),
            ),
            FnKind::Init => {}
            _ => {
                let f = self.facts();
                if f.impure.is_none() {
                    f.impure = Some((what.to_string(), span));
                }
            }
        }
    }

    pub(super) fn state_read(&mut self, name: &str, span: Span) {
        if self.fk() == FnKind::Cond {
            let help = match name {
                "now" | "cycle" => {
                    "time passes without any `set`: use `timeout`, `after` or `every` instead"
                }
                _ => {
                    "robot state changes without a `set` event, so the condition would never be re-checked"
                }
            };
            self.err(
                Diagnostic::error(
                    Code::E0041,
                    format!("`{name}()` is not allowed in a condition"),
                    span,
                )
                .with_help(help),
            );
        } else {
            self.note_impure(&format!("`{name}()`"), span);
        }
    }

    /// Checks and compiles an expression, folding constants.
    pub(super) fn expr(&mut self, e: &Expr) -> Out {
        let start = self.here();
        let out = self.expr_inner(e);
        if out.k.as_ref().is_some_and(|k| !k.is_finite()) {
            self.err(
                Diagnostic::error(
                    Code::E0026,
                    "this constant is too large to be a number",
                    e.span,
                )
                .with_help("numbers must stay below about 1.8e308 in magnitude"),
            );
            return Out::err();
        }
        if let Some(k) = &out.k
            && self.here() > start + 1
        {
            let k = k.clone();
            self.truncate(start);
            self.push_const(&k, out.ty, e.span);
        }
        out
    }

    pub(super) fn expr_inner(&mut self, e: &Expr) -> Out {
        let sp = e.span;
        let konst = |this: &mut Self, v: ConstValue, ty: Ty, bare: bool| {
            this.push_const(&v, ty, sp);
            Out {
                ty,
                k: Some(v),
                bare,
            }
        };
        match &e.kind {
            ExprKind::Error => Out::err(),
            ExprKind::Int(i) => konst(self, ConstValue::Int(*i), Ty::Int, true),
            ExprKind::Num(x) => konst(self, ConstValue::Num(*x), Ty::Num(Dim::PLAIN), true),
            ExprKind::Quantity(x, d) => konst(self, ConstValue::Num(*x), Ty::Num(*d), false),
            ExprKind::Bool(b) => konst(self, ConstValue::Bool(*b), Ty::Bool, false),
            ExprKind::Str(s) if self.texts => {
                let k = self.str(s);
                konst(self, ConstValue::Text(k), Ty::Text, false)
            }
            ExprKind::Str(_) => {
                self.err(
                    Diagnostic::error(
                        Code::E0034,
                        "text can only be written in `log` and `fail`",
                        sp,
                    )
                    .with_help("write `log \"message\", value;`"),
                );
                Out::err()
            }
            ExprKind::Name(n) => self.name(n, sp),
            ExprKind::Unary(op, x) => {
                let o = self.expr(x);
                match (op, o.ty) {
                    (_, Ty::Error) => Out::err(),
                    (UnOp::Neg, Ty::Int) => {
                        self.emit(Instr::NegI, sp);
                        let k = match o.k {
                            Some(ConstValue::Int(i)) => i.checked_neg().map(ConstValue::Int),
                            _ => None,
                        };
                        Out {
                            ty: Ty::Int,
                            k,
                            bare: o.bare,
                        }
                    }
                    (UnOp::Neg, Ty::Num(d)) => {
                        self.emit(Instr::NegF, sp);
                        let k = match o.k {
                            Some(ConstValue::Num(x)) => Some(ConstValue::Num(-x)),
                            _ => None,
                        };
                        Out {
                            ty: Ty::Num(d),
                            k,
                            bare: o.bare,
                        }
                    }
                    (UnOp::Not, Ty::Bool) => {
                        self.emit(Instr::Not, sp);
                        let k = match o.k {
                            Some(ConstValue::Bool(b)) => Some(ConstValue::Bool(!b)),
                            _ => None,
                        };
                        Out {
                            ty: Ty::Bool,
                            k,
                            bare: false,
                        }
                    }
                    (op, t) => {
                        let sym = if *op == UnOp::Neg { "-" } else { "not" };
                        self.err(Diagnostic::error(
                            Code::E0022,
                            format!("`{sym}` cannot be applied to {}", t.described()),
                            sp,
                        ));
                        Out::err()
                    }
                }
            }
            ExprKind::Binary(op, l, r) => {
                if matches!(op, BinOp::And | BinOp::Or) {
                    return self.logic(*op, l, r, sp);
                }
                let lo = self.expr(l);
                let ro = self.expr(r);
                self.binary_typed(*op, lo, ro, sp, r.span)
            }
            ExprKind::Call(name, args) => self.call(name, args, sp, false),
            ExprKind::Field(base, field) => {
                let o = self.expr(base);
                if o.ty.is_err() {
                    return Out::err();
                }
                if o.ty != Ty::Pose {
                    self.err(
                        Diagnostic::error(
                            Code::E0022,
                            format!("{} has no field `{}`", o.ty.described(), field.name),
                            field.span,
                        )
                        .with_help(if o.ty == Ty::Joints {
                            "index joints with j[i]"
                        } else {
                            "only poses have fields: x, y, z, rx, ry, rz"
                        }),
                    );
                    return Out::err();
                }
                let Some((fi, fty)) = self.pose_field(field) else {
                    return Out::err();
                };
                // A field of a pose variable is one slot: load it directly.
                let last = self.fns.last().and_then(|f| f.code.last().copied());
                let is_name = matches!(base.kind, ExprKind::Name(_));
                if let (true, Some(Instr::LoadLocalN(s, 6))) = (is_name, last) {
                    let start = self.here() - 1;
                    self.truncate(start);
                    self.emit(Instr::LoadLocal(s + u32::from(fi)), sp);
                } else if let (true, Some(Instr::LoadVarN(s, 6))) = (is_name, last) {
                    let start = self.here() - 1;
                    self.truncate(start);
                    self.emit(Instr::LoadVar(s + u32::from(fi)), sp);
                } else {
                    self.emit(Instr::PoseGet(fi), sp);
                }
                let k = match o.k {
                    Some(ConstValue::Pose(p)) => Some(ConstValue::Num(p[fi as usize])),
                    _ => None,
                };
                Out {
                    ty: fty,
                    k,
                    bare: false,
                }
            }
            ExprKind::Index(base, idx) => {
                let o = self.expr(base);
                let i = self.expr(idx);
                let i = self.coerce(i, Ty::Int, idx.span, "an index");
                if o.ty.is_err() {
                    return Out::err();
                }
                if o.ty != Ty::Joints {
                    self.err(
                        Diagnostic::error(
                            Code::E0022,
                            format!("{} cannot be indexed", o.ty.described()),
                            sp,
                        )
                        .with_help("only joints values are indexed: j[0] is the first axis"),
                    );
                    return Out::err();
                }
                self.emit(Instr::JointsGet, sp);
                self.joint_index(o, i, idx.span, Dim::ANGLE)
            }
        }
    }

    pub(super) fn joint_index(&mut self, o: Out, i: Out, span: Span, dim: Dim) -> Out {
        let k = match (&o.k, &i.k) {
            (Some(ConstValue::Joints(v)), Some(ConstValue::Int(i))) => match usize::try_from(*i)
                .ok()
                .and_then(|i| v.get(i))
            {
                Some(x) => Some(ConstValue::Num(*x)),
                None => {
                    self.err(
                        Diagnostic::error(
                            Code::E0025,
                            format!("index {i} is out of range for joints of {} values", v.len()),
                            span,
                        )
                        .with_help("axes are numbered from 0"),
                    );
                    return Out::err();
                }
            },
            (_, Some(ConstValue::Int(i))) if *i < 0 || *i >= MAX_AXES as i64 => {
                self.err(Diagnostic::error(
                    Code::E0025,
                    format!(
                        "index {i} is out of range: axes are numbered 0 to {}",
                        MAX_AXES - 1
                    ),
                    span,
                ));
                return Out::err();
            }
            _ => None,
        };
        Out {
            ty: Ty::Num(dim),
            k,
            bare: false,
        }
    }

    pub(super) fn pose_field(&mut self, field: &Ident) -> Option<(u8, Ty)> {
        let i = ["x", "y", "z", "rx", "ry", "rz"]
            .iter()
            .position(|f| *f == field.name);
        match i {
            Some(i) => Some((
                i as u8,
                Ty::Num(if i < 3 { Dim::LENGTH } else { Dim::ANGLE }),
            )),
            None => {
                self.err(
                    Diagnostic::error(
                        Code::E0022,
                        format!("a pose has no field `{}`", field.name),
                        field.span,
                    )
                    .with_help("the fields are x, y, z (lengths) and rx, ry, rz (angles)"),
                );
                None
            }
        }
    }

    pub(super) fn name(&mut self, n: &str, sp: Span) -> Out {
        if let Some(l) = self.lookup_local(n) {
            self.load_local(l.slot, l.ty, sp);
            return Out::of(l.ty);
        }
        match self.symbols.get(n).map(|s| s.0.clone()) {
            Some(Sym::Const(ty, v)) => {
                self.push_const(&v, ty, sp);
                Out {
                    ty,
                    k: Some(v),
                    bare: false,
                }
            }
            Some(sym @ (Sym::Var(slot, ty) | Sym::Param(slot, ty))) => {
                let param = matches!(sym, Sym::Param(..));
                if self.fk() == FnKind::Init {
                    let what = if param {
                        "a parameter (a workcell may set it)"
                    } else {
                        "a module variable"
                    };
                    return self.not_const(n, what, sp);
                }
                // A parameter is fixed for the whole run: reading it is pure (functions,
                // conditions); a module variable is not.
                if !param {
                    self.note_impure(&format!("the module variable `{n}`"), sp);
                }
                let w = ty.width();
                self.emit(
                    if w == 1 {
                        Instr::LoadVar(slot)
                    } else {
                        Instr::LoadVarN(slot, w)
                    },
                    sp,
                );
                Out::of(ty)
            }
            Some(Sym::Global(g, ty)) => {
                if self.fk() == FnKind::Init {
                    return self.not_const(n, "a global", sp);
                }
                self.facts().globals.insert(g);
                self.emit(Instr::LoadGlobal(g), sp);
                Out::of(ty)
            }
            Some(Sym::Proc(_)) => {
                self.err(
                    Diagnostic::error(
                        Code::E0033,
                        format!("`{n}` is a procedure, not a value"),
                        sp,
                    )
                    .with_help(format!("call it: `{n}(…)`")),
                );
                Out::err()
            }
            None => {
                self.unknown_name(n, sp);
                Out::err()
            }
        }
    }

    pub(super) fn not_const(&mut self, n: &str, what: &str, sp: Span) -> Out {
        self.err(
            Diagnostic::error(Code::E0080, format!("`{n}` is {what}, not a constant"), sp)
                .with_help("module-level initial values may use only literals and constants declared above"),
        );
        Out::err()
    }

    pub(super) fn logic(&mut self, op: BinOp, l: &Expr, r: &Expr, sp: Span) -> Out {
        let lo = self.expr(l);
        self.expect_bool(&lo, l.span, &format!("the left side of `{}`", op.symbol()));
        let j1 = self.emit(
            if op == BinOp::And {
                Instr::JumpIfFalse(0)
            } else {
                Instr::JumpIfTrue(0)
            },
            sp,
        );
        let ro = self.expr(r);
        self.expect_bool(&ro, r.span, &format!("the right side of `{}`", op.symbol()));
        let j2 = self.emit(Instr::Jump(0), sp);
        let short = self.here();
        self.patch(j1, short);
        self.emit(Instr::PushBool(op == BinOp::Or), sp);
        let end = self.here();
        self.patch(j2, end);
        let k = match (&lo.k, &ro.k) {
            (Some(ConstValue::Bool(a)), Some(ConstValue::Bool(b))) => {
                Some(ConstValue::Bool(if op == BinOp::And {
                    *a && *b
                } else {
                    *a || *b
                }))
            }
            _ => None,
        };
        if lo.ty.is_err() || ro.ty.is_err() {
            return Out::err();
        }
        Out {
            ty: Ty::Bool,
            k,
            bare: false,
        }
    }

    /// Type rules and code of `l op r`, both operands already on the stack.
    pub(super) fn binary_typed(
        &mut self,
        op: BinOp,
        lo: Out,
        ro: Out,
        sp: Span,
        rspan: Span,
    ) -> Out {
        use BinOp::*;
        if lo.ty.is_err() || ro.ty.is_err() {
            return Out::err();
        }
        let mismatch = |this: &mut Self, msg: String, help: Option<String>| {
            let mut d = Diagnostic::error(Code::E0021, msg, sp);
            if let Some(h) = help {
                d = d.with_help(h);
            }
            this.err(d);
            Out::err()
        };
        // A literal 0 takes the unit of the other side: `x > 0`, `0 < x`.
        let zero_ok = matches!(op, Add | Sub | Eq | Ne | Lt | Le | Gt | Ge);
        let (lo, ro) = match (lo.ty, ro.ty) {
            (Ty::Num(d), Ty::Int | Ty::Num(_))
                if zero_ok && ro.is_zero_literal() && ro.ty != lo.ty =>
            {
                if ro.ty == Ty::Int {
                    self.emit(Instr::IntToNum, sp);
                }
                let k = Some(ConstValue::Num(0.0));
                (
                    lo,
                    Out {
                        ty: Ty::Num(d),
                        k,
                        bare: true,
                    },
                )
            }
            (Ty::Int | Ty::Num(_), Ty::Num(d))
                if zero_ok && lo.is_zero_literal() && ro.ty != lo.ty =>
            {
                if lo.ty == Ty::Int {
                    self.emit(Instr::IntToNumBelow, sp);
                }
                let k = Some(ConstValue::Num(0.0));
                (
                    Out {
                        ty: Ty::Num(d),
                        k,
                        bare: true,
                    },
                    ro,
                )
            }
            _ => (lo, ro),
        };
        // Promote an int to a plain num beside a num.
        let (lt, rt) = (lo.ty, ro.ty);
        let (lt, rt, lk, rk) = match (lt, rt) {
            (Ty::Int, Ty::Num(d)) if d.is_plain() || matches!(op, Mul | Div) => {
                self.emit(Instr::IntToNumBelow, sp);
                (Ty::Num(Dim::PLAIN), rt, to_num(&lo.k), ro.k.clone())
            }
            (Ty::Num(d), Ty::Int) if d.is_plain() || matches!(op, Mul | Div) => {
                self.emit(Instr::IntToNum, sp);
                (lt, Ty::Num(Dim::PLAIN), lo.k.clone(), to_num(&ro.k))
            }
            _ => (lt, rt, lo.k.clone(), ro.k.clone()),
        };
        let bare = lo.bare && ro.bare;
        let cmp = cmp_of;
        match (op, lt, rt) {
            // Texts (a translation from RAPID): `+` joins, `=`/`<>` compare.
            (Add, Ty::Text, Ty::Text) => {
                self.emit(Instr::TextCat, sp);
                Out::of(Ty::Text)
            }
            (Eq | Ne, Ty::Text, Ty::Text) => {
                self.emit(Instr::CmpT(cmp(op)), sp);
                Out::of(Ty::Bool)
            }
            (Add | Sub | Mul | Div | Mod, Ty::Int, Ty::Int) => {
                self.emit(
                    match op {
                        Add => Instr::AddI,
                        Sub => Instr::SubI,
                        Mul => Instr::MulI,
                        Div => Instr::DivI,
                        _ => Instr::ModI,
                    },
                    sp,
                );
                let k = match (lk, rk) {
                    (Some(ConstValue::Int(a)), Some(ConstValue::Int(b))) => {
                        let v = match op {
                            Add => a.checked_add(b),
                            Sub => a.checked_sub(b),
                            Mul => a.checked_mul(b),
                            Div => a.checked_div(b),
                            _ => a.checked_rem(b),
                        };
                        match v {
                            Some(v) => Some(ConstValue::Int(v)),
                            None => {
                                let why = if b == 0 && matches!(op, Div | Mod) {
                                    "division by zero"
                                } else {
                                    "integer overflow"
                                };
                                self.err(Diagnostic::error(
                                    Code::E0026,
                                    format!("{why} in a constant expression"),
                                    sp,
                                ));
                                return Out::err();
                            }
                        }
                    }
                    _ => None,
                };
                Out {
                    ty: Ty::Int,
                    k,
                    bare,
                }
            }
            (Add | Sub, Ty::Num(a), Ty::Num(b)) => {
                if a != b {
                    let word = if op == Add { "add" } else { "subtract" };
                    return mismatch(
                        self,
                        format!("cannot {word} {} and {}", a.described(), b.described()),
                        (ro.bare && default_unit(a).is_some())
                            .then(|| format!("write the unit: {}", default_unit(a).unwrap_or(""))),
                    );
                }
                self.emit(if op == Add { Instr::AddF } else { Instr::SubF }, sp);
                let k = num2(&lk, &rk, |x, y| if op == Add { x + y } else { x - y });
                Out {
                    ty: Ty::Num(a),
                    k,
                    bare,
                }
            }
            (Mul | Div, Ty::Num(a), Ty::Num(b)) => {
                let d = if op == Mul { a.times(b) } else { a.per(b) };
                let Some(d) = d else {
                    return mismatch(
                        self,
                        "the unit of this product is out of range".into(),
                        None,
                    );
                };
                if op == Div
                    && let Some(ConstValue::Num(y)) = rk
                    && y == 0.0
                {
                    self.err(Diagnostic::error(
                        Code::E0026,
                        "division by zero in a constant expression",
                        rspan,
                    ));
                    return Out::err();
                }
                self.emit(if op == Mul { Instr::MulF } else { Instr::DivF }, sp);
                let k = num2(&lk, &rk, |x, y| if op == Mul { x * y } else { x / y });
                Out {
                    ty: Ty::Num(d),
                    k,
                    bare,
                }
            }
            (Eq | Ne | Lt | Le | Gt | Ge, Ty::Int, Ty::Int) => {
                self.emit(Instr::CmpI(cmp(op)), sp);
                let k = match (lk, rk) {
                    (Some(ConstValue::Int(a)), Some(ConstValue::Int(b))) => {
                        Some(ConstValue::Bool(cmp_of(op).holds(a.cmp(&b))))
                    }
                    _ => None,
                };
                Out {
                    ty: Ty::Bool,
                    k,
                    bare: false,
                }
            }
            (Eq | Ne | Lt | Le | Gt | Ge, Ty::Num(a), Ty::Num(b)) => {
                if a != b && !ro.is_zero_literal() {
                    return mismatch(
                        self,
                        format!("cannot compare {} with {}", a.described(), b.described()),
                        (ro.bare && default_unit(a).is_some())
                            .then(|| format!("write the unit: {}", default_unit(a).unwrap_or(""))),
                    );
                }
                self.emit(Instr::CmpF(cmp(op)), sp);
                let k = match (lk, rk) {
                    (Some(ConstValue::Num(x)), Some(ConstValue::Num(y))) => x
                        .partial_cmp(&y)
                        .map(|o| ConstValue::Bool(cmp_of(op).holds(o))),
                    _ => None,
                };
                Out {
                    ty: Ty::Bool,
                    k,
                    bare: false,
                }
            }
            (Eq | Ne, Ty::Bool, Ty::Bool) => {
                self.emit(Instr::CmpB(cmp(op)), sp);
                let k = match (lk, rk) {
                    (Some(ConstValue::Bool(a)), Some(ConstValue::Bool(b))) => {
                        Some(ConstValue::Bool((a == b) == (op == Eq)))
                    }
                    _ => None,
                };
                Out {
                    ty: Ty::Bool,
                    k,
                    bare: false,
                }
            }
            (Mod, Ty::Num(_), _) | (Mod, _, Ty::Num(_)) => {
                self.err(
                    Diagnostic::error(Code::E0022, "`mod` works on ints", sp)
                        .with_help("convert with int(x)"),
                );
                Out::err()
            }
            (_, Ty::Num(a), Ty::Int) | (_, Ty::Int, Ty::Num(a)) => mismatch(
                self,
                format!(
                    "cannot combine {} with an int using `{}`",
                    a.described(),
                    op.symbol()
                ),
                Some(if bare || lo.bare || ro.bare {
                    format!(
                        "write the unit on the number, e.g. 2{}",
                        default_unit(a).unwrap_or("")
                    )
                } else {
                    "convert with num(i)".into()
                }),
            ),
            (op, l, r) => {
                self.err(Diagnostic::error(
                    Code::E0022,
                    format!(
                        "`{}` cannot be applied to {} and {}",
                        op.symbol(),
                        l.described(),
                        r.described()
                    ),
                    sp,
                ));
                Out::err()
            }
        }
    }

    pub(super) fn call_args(&mut self, callee: u32, args: &[Expr], sp: Span) {
        let sig = self.sigs[callee as usize].clone();
        if args.len() != sig.params.len() {
            self.err(
                Diagnostic::error(
                    Code::E0013,
                    format!(
                        "`{}` takes {} argument{}, but {} {} given",
                        sig.name,
                        sig.params.len(),
                        if sig.params.len() == 1 { "" } else { "s" },
                        args.len(),
                        if args.len() == 1 { "was" } else { "were" }
                    ),
                    sp,
                )
                .with_related(sig.span, "declared here"),
            );
            for a in args {
                self.expr(a);
            }
            return;
        }
        for (a, (pname, pty)) in args.iter().zip(&sig.params) {
            let o = self.expr(a);
            self.coerce(
                o,
                *pty,
                a.span,
                &format!("argument `{pname}` of `{}`", sig.name),
            );
        }
    }

    /// A call to a user procedure/function or a built-in.
    pub(super) fn call(&mut self, name: &Ident, args: &[Expr], sp: Span, statement: bool) -> Out {
        if let Some(Sym::Proc(p)) = self.symbols.get(&name.name).map(|s| s.0.clone()) {
            let sig = self.sigs[p as usize].clone();
            if !sig.is_func {
                if !statement {
                    self.err(
                        Diagnostic::error(
                            Code::E0033,
                            format!("`{}` is a procedure and has no value", name.name),
                            sp,
                        )
                        .with_help(
                            "call it as a statement, or make it a `func` that returns a value",
                        ),
                    );
                    return Out::err();
                }
                if !self.not_in_func(&format!("call the procedure `{}`", name.name), sp) {
                    return Out::err();
                }
            }
            if self.fk() == FnKind::Init {
                return self.not_const(&name.name, "a function", sp);
            }
            self.call_args(p, args, sp);
            self.facts().calls.push((p, name.span));
            self.emit(Instr::Call(p), sp);
            return Out::of(sig.ret);
        }
        if self.lookup_local(&name.name).is_some() || self.symbols.contains_key(&name.name) {
            self.err(Diagnostic::error(
                Code::E0022,
                format!("`{}` is a value, not a function", name.name),
                name.span,
            ));
            return Out::err();
        }
        self.builtin(name, args, sp)
    }

    pub(super) fn arity(
        &mut self,
        name: &Ident,
        args: &[Expr],
        n: usize,
        sp: Span,
        sig: &str,
    ) -> bool {
        if args.len() == n {
            return true;
        }
        self.err(
            Diagnostic::error(
                Code::E0013,
                format!(
                    "`{}` takes {n} argument{}, but {} {} given",
                    name.name,
                    if n == 1 { "" } else { "s" },
                    args.len(),
                    if args.len() == 1 { "was" } else { "were" }
                ),
                sp,
            )
            .with_help(format!("write `{sig}`")),
        );
        for a in args {
            self.expr(a);
        }
        false
    }
}
