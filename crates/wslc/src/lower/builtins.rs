//! Built-in functions: the table (name, signature, result, the instructions it compiles
//! to, the note docs/language.md gives — the one place they are listed; the language
//! reference's table is checked against it) and their type rules, code and constant
//! folding.

use super::*;

/// A built-in function.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Builtin {
    Now,
    Cycle,
    TimedOut,
    CurrentJoints,
    CurrentPose,
    CurrentTool,
    Offset,
    ToolOffset,
    PoseMul,
    PoseInv,
    Abs,
    Min,
    Max,
    Sqrt,
    Sin,
    Cos,
    Atan2,
    Int,
    Num,
    Joints,
    Pose,
    AxisLength,
}

/// One row of the built-in table.
#[derive(Debug)]
pub(crate) struct BuiltinInfo {
    /// The name as written in WSL.
    pub(crate) name: &'static str,
    pub(crate) builtin: Builtin,
    /// How a call is written (arity messages show it; docs/language.md lists it).
    pub(crate) signature: &'static str,
    /// The result, as docs/language.md describes it.
    pub(crate) returns: &'static str,
    /// The instructions a call compiles to (by operand type where there are several).
    pub(crate) instrs: &'static [Instr],
}

/// Every built-in function, in the order docs/language.md lists them.
pub(crate) const BUILTINS: &[BuiltinInfo] = &[
    row("now", Builtin::Now, "now()", "time", &[Instr::Now]),
    row("cycle", Builtin::Cycle, "cycle()", "int", &[Instr::Cycle]),
    row(
        "timed_out",
        Builtin::TimedOut,
        "timed_out()",
        "bool",
        &[Instr::TimedOut],
    ),
    row(
        "current_joints",
        Builtin::CurrentJoints,
        "current_joints()",
        "joints",
        &[Instr::CurrentJoints],
    ),
    row(
        "current_pose",
        Builtin::CurrentPose,
        "current_pose()",
        "pose",
        &[Instr::CurrentPose],
    ),
    row(
        "current_tool",
        Builtin::CurrentTool,
        "current_tool()",
        "pose",
        &[Instr::CurrentTool],
    ),
    row(
        "offset",
        Builtin::Offset,
        "offset(p, dx, dy, dz)",
        "pose",
        &[Instr::Offset],
    ),
    row(
        "tool_offset",
        Builtin::ToolOffset,
        "tool_offset(p, dx, dy, dz)",
        "pose",
        &[Instr::ToolOffset],
    ),
    row(
        "pose_mul",
        Builtin::PoseMul,
        "pose_mul(a, b)",
        "pose",
        &[Instr::PoseMul],
    ),
    row(
        "pose_inv",
        Builtin::PoseInv,
        "pose_inv(p)",
        "pose",
        &[Instr::PoseInv],
    ),
    row(
        "abs",
        Builtin::Abs,
        "abs(x)",
        "same as argument",
        &[Instr::AbsI, Instr::AbsF],
    ),
    row(
        "min",
        Builtin::Min,
        "min(a, b)",
        "same as argument",
        &[Instr::MinI, Instr::MinF],
    ),
    row(
        "max",
        Builtin::Max,
        "max(a, b)",
        "same as argument",
        &[Instr::MaxI, Instr::MaxF],
    ),
    row(
        "sqrt",
        Builtin::Sqrt,
        "sqrt(x)",
        "half the dimension",
        &[Instr::Sqrt],
    ),
    row("sin", Builtin::Sin, "sin(a)", "plain num", &[Instr::Sin]),
    row("cos", Builtin::Cos, "cos(a)", "plain num", &[Instr::Cos]),
    row(
        "atan2",
        Builtin::Atan2,
        "atan2(y, x)",
        "angle",
        &[Instr::Atan2],
    ),
    row("int", Builtin::Int, "int(x)", "int", &[Instr::NumToInt]),
    row(
        "num",
        Builtin::Num,
        "num(i)",
        "plain num",
        &[Instr::IntToNum],
    ),
    row(
        "joints",
        Builtin::Joints,
        "joints(a1, …)",
        "joints",
        &[Instr::MakeJoints(0)],
    ),
    row(
        "pose",
        Builtin::Pose,
        "pose(x, y, z, rx, ry, rz)",
        "pose",
        &[],
    ),
    row(
        "axis_length",
        Builtin::AxisLength,
        "axis_length(j, i)",
        "length",
        &[Instr::JointsGet],
    ),
];

const fn row(
    name: &'static str,
    builtin: Builtin,
    signature: &'static str,
    returns: &'static str,
    instrs: &'static [Instr],
) -> BuiltinInfo {
    BuiltinInfo {
        name,
        builtin,
        signature,
        returns,
        instrs,
    }
}

/// The built-in named `name`, if there is one.
pub(crate) fn builtin_named(name: &str) -> Option<&'static BuiltinInfo> {
    BUILTINS.iter().find(|b| b.name == name)
}

impl Compiler<'_> {
    pub(super) fn builtin(&mut self, name: &Ident, args: &[Expr], sp: Span) -> Out {
        if let Some(out) = self.text_function(name, args, sp) {
            return out;
        }
        let n = name.name.as_str();
        let Some(info) = builtin_named(n) else {
            self.unknown_proc(n, name.span);
            for a in args {
                self.expr(a);
            }
            return Out::err();
        };
        // Every built-in but `joints` takes as many arguments as its signature shows.
        let params = match info.signature.split_once('(') {
            Some((_, ")")) => 0,
            Some((_, list)) => list.split(',').count(),
            None => 0,
        };
        if info.builtin != Builtin::Joints && !self.arity(name, args, params, sp, info.signature) {
            return Out::err();
        }
        match info.builtin {
            Builtin::Now
            | Builtin::Cycle
            | Builtin::TimedOut
            | Builtin::CurrentJoints
            | Builtin::CurrentPose
            | Builtin::CurrentTool => {
                if self.fk() == FnKind::Init {
                    return self.not_const(n, "known only during the run", sp);
                }
                self.state_read(n, sp);
                let ty = match info.builtin {
                    Builtin::Now => Ty::Num(Dim::TIME),
                    Builtin::Cycle => Ty::Int,
                    Builtin::TimedOut => Ty::Bool,
                    Builtin::CurrentJoints => Ty::Joints,
                    _ => Ty::Pose,
                };
                self.emit(info.instrs[0], sp);
                Out::of(ty)
            }
            Builtin::Offset | Builtin::ToolOffset => {
                let p = self.expr(&args[0]);
                let p = self.coerce(
                    p,
                    Ty::Pose,
                    args[0].span,
                    &format!("the first argument of `{n}`"),
                );
                let mut ds = [0.0; 3];
                let mut all = true;
                for (i, a) in args[1..].iter().enumerate() {
                    let o = self.expr(a);
                    let o = self.coerce(
                        o,
                        Ty::Num(Dim::LENGTH),
                        a.span,
                        &format!("argument {} of `{n}`", i + 2),
                    );
                    match o.k {
                        Some(ConstValue::Num(x)) => ds[i] = x,
                        _ => all = false,
                    }
                }
                self.emit(info.instrs[0], sp);
                let k = match (p.k, all) {
                    (Some(ConstValue::Pose(p)), true) => Some(ConstValue::Pose(if n == "offset" {
                        math::offset(p, ds[0], ds[1], ds[2])
                    } else {
                        math::tool_offset(p, ds[0], ds[1], ds[2])
                    })),
                    _ => None,
                };
                Out {
                    ty: Ty::Pose,
                    k,
                    bare: false,
                }
            }
            Builtin::PoseMul | Builtin::PoseInv => {
                let mut ks = Vec::new();
                for (i, a) in args.iter().enumerate() {
                    let o = self.expr(a);
                    let o =
                        self.coerce(o, Ty::Pose, a.span, &format!("argument {} of `{n}`", i + 1));
                    ks.push(o.k);
                }
                self.emit(info.instrs[0], sp);
                let k = match ks.as_slice() {
                    [Some(ConstValue::Pose(a)), Some(ConstValue::Pose(b))] => {
                        Some(ConstValue::Pose(math::pose_mul(*a, *b)))
                    }
                    [Some(ConstValue::Pose(p))] => Some(ConstValue::Pose(math::pose_inv(*p))),
                    _ => None,
                };
                Out {
                    ty: Ty::Pose,
                    k,
                    bare: false,
                }
            }
            Builtin::Abs
            | Builtin::Sqrt
            | Builtin::Sin
            | Builtin::Cos
            | Builtin::Int
            | Builtin::Num => {
                let o = self.expr(&args[0]);
                self.unary_builtin(n, o, args[0].span, sp)
            }
            Builtin::Min | Builtin::Max | Builtin::Atan2 => {
                let a = self.expr(&args[0]);
                let b = self.expr(&args[1]);
                if a.ty.is_err() || b.ty.is_err() {
                    return Out::err();
                }
                let (ta, tb, ka, kb) = match (a.ty, b.ty) {
                    (Ty::Int, Ty::Num(d)) if d.is_plain() || n == "atan2" => {
                        self.emit(Instr::IntToNumBelow, sp);
                        (Ty::Num(Dim::PLAIN), b.ty, to_num(&a.k), b.k.clone())
                    }
                    (Ty::Num(d), Ty::Int) if d.is_plain() || n == "atan2" => {
                        self.emit(Instr::IntToNum, sp);
                        (a.ty, Ty::Num(Dim::PLAIN), a.k.clone(), to_num(&b.k))
                    }
                    (Ty::Int, Ty::Int) if n == "atan2" => {
                        self.emit(Instr::IntToNumBelow, sp);
                        self.emit(Instr::IntToNum, sp);
                        (
                            Ty::Num(Dim::PLAIN),
                            Ty::Num(Dim::PLAIN),
                            to_num(&a.k),
                            to_num(&b.k),
                        )
                    }
                    _ => (a.ty, b.ty, a.k.clone(), b.k.clone()),
                };
                match (ta, tb) {
                    (Ty::Int, Ty::Int) => {
                        self.emit(if n == "min" { Instr::MinI } else { Instr::MaxI }, sp);
                        let k = match (ka, kb) {
                            (Some(ConstValue::Int(x)), Some(ConstValue::Int(y))) => {
                                Some(ConstValue::Int(if n == "min" {
                                    x.min(y)
                                } else {
                                    x.max(y)
                                }))
                            }
                            _ => None,
                        };
                        Out {
                            ty: Ty::Int,
                            k,
                            bare: false,
                        }
                    }
                    (Ty::Num(x), Ty::Num(y)) if x == y => {
                        let (ins, ty) = match n {
                            "min" => (Instr::MinF, Ty::Num(x)),
                            "max" => (Instr::MaxF, Ty::Num(x)),
                            _ => (Instr::Atan2, Ty::Num(Dim::ANGLE)),
                        };
                        self.emit(ins, sp);
                        let k = num2(&ka, &kb, |p, q| match n {
                            "min" => p.min(q),
                            "max" => p.max(q),
                            _ => p.atan2(q),
                        });
                        Out { ty, k, bare: false }
                    }
                    (Ty::Num(x), Ty::Num(y)) => {
                        self.err(Diagnostic::error(
                            Code::E0021,
                            format!(
                                "`{n}` needs two values of the same unit, found {} and {}",
                                x.described(),
                                y.described()
                            ),
                            sp,
                        ));
                        Out::err()
                    }
                    (x, y) => {
                        self.err(Diagnostic::error(
                            Code::E0020,
                            format!(
                                "`{n}` needs two numbers, found {} and {}",
                                x.described(),
                                y.described()
                            ),
                            sp,
                        ));
                        Out::err()
                    }
                }
            }
            Builtin::Joints => {
                if args.is_empty() || args.len() > MAX_AXES {
                    self.err(Diagnostic::error(Code::E0013, format!("`joints` takes 1 to {MAX_AXES} values, but {} were given", args.len()), sp).with_help("one value per robot axis: joints(0deg, -30deg, 30deg, 0deg, 60deg, 0deg)"));
                    for a in args {
                        self.expr(a);
                    }
                    return Out::err();
                }
                let mut vals = Vec::new();
                let mut mask = 0u16;
                let mut all = true;
                for (i, a) in args.iter().enumerate() {
                    let o = self.expr(a);
                    if o.ty == Ty::Num(Dim::LENGTH) {
                        mask |= 1 << i;
                    }
                    let k = o.k.clone();
                    self.joint_value(o, a.span);
                    match k {
                        Some(ConstValue::Num(x)) => vals.push(x),
                        Some(ConstValue::Int(0)) => vals.push(0.0),
                        _ => all = false,
                    }
                }
                let pos = self.pos(sp);
                self.m.joints_sites.push(JointsSite {
                    count: args.len() as u8,
                    linear_mask: mask,
                    pos,
                });
                self.emit(Instr::MakeJoints(args.len() as u8), sp);
                Out {
                    ty: Ty::Joints,
                    k: all.then_some(ConstValue::Joints(vals)),
                    bare: false,
                }
            }
            Builtin::Pose => {
                let mut vals = [0.0; 6];
                let mut all = true;
                for (i, a) in args.iter().enumerate() {
                    let want = if i < 3 { Dim::LENGTH } else { Dim::ANGLE };
                    let o = self.expr(a);
                    let comp = ["x", "y", "z", "rx", "ry", "rz"][i];
                    let o =
                        self.coerce(o, Ty::Num(want), a.span, &format!("the `{comp}` of a pose"));
                    match o.k {
                        Some(ConstValue::Num(x)) => vals[i] = x,
                        _ => all = false,
                    }
                }
                Out {
                    ty: Ty::Pose,
                    k: all.then_some(ConstValue::Pose(vals)),
                    bare: false,
                }
            }
            Builtin::AxisLength => {
                let j = self.expr(&args[0]);
                let j = self.coerce(
                    j,
                    Ty::Joints,
                    args[0].span,
                    "the first argument of `axis_length`",
                );
                let i = self.expr(&args[1]);
                let i = self.coerce(i, Ty::Int, args[1].span, "the axis index");
                if j.ty.is_err() {
                    return Out::err();
                }
                self.emit(info.instrs[0], sp);
                self.joint_index(j, i, args[1].span, Dim::LENGTH)
            }
        }
    }

    pub(super) fn unary_builtin(&mut self, n: &str, o: Out, aspan: Span, sp: Span) -> Out {
        if o.ty.is_err() {
            return Out::err();
        }
        let fnum = |k: &Option<ConstValue>, f: fn(f64) -> f64| match k {
            Some(ConstValue::Num(x)) => Some(ConstValue::Num(f(*x))),
            _ => None,
        };
        match (n, o.ty) {
            ("abs", Ty::Int) => {
                self.emit(Instr::AbsI, sp);
                let k = match o.k {
                    Some(ConstValue::Int(i)) => i.checked_abs().map(ConstValue::Int),
                    _ => None,
                };
                Out {
                    ty: Ty::Int,
                    k,
                    bare: o.bare,
                }
            }
            ("abs", Ty::Num(d)) => {
                self.emit(Instr::AbsF, sp);
                Out {
                    ty: Ty::Num(d),
                    k: fnum(&o.k, f64::abs),
                    bare: o.bare,
                }
            }
            ("sqrt", Ty::Int | Ty::Num(_)) => {
                let o = if o.ty == Ty::Int {
                    self.coerce(o, Ty::Num(Dim::PLAIN), aspan, "the argument of `sqrt`")
                } else {
                    o
                };
                let Ty::Num(d) = o.ty else { return Out::err() };
                let Some(half) = d.sqrt() else {
                    self.err(Diagnostic::error(Code::E0021, format!("the square root of {} has no unit", d.described()), aspan).with_help("only squared units have a square root, e.g. sqrt(a*a + b*b) for lengths a and b"));
                    return Out::err();
                };
                if let Some(ConstValue::Num(x)) = o.k
                    && x < 0.0
                {
                    self.err(Diagnostic::error(
                        Code::E0025,
                        "the square root of a negative number",
                        aspan,
                    ));
                    return Out::err();
                }
                self.emit(Instr::Sqrt, sp);
                Out {
                    ty: Ty::Num(half),
                    k: fnum(&o.k, f64::sqrt),
                    bare: false,
                }
            }
            ("sin" | "cos", _) => {
                let o = self.coerce(
                    o,
                    Ty::Num(Dim::ANGLE),
                    aspan,
                    &format!("the argument of `{n}`"),
                );
                if o.ty.is_err() {
                    return Out::err();
                }
                self.emit(if n == "sin" { Instr::Sin } else { Instr::Cos }, sp);
                Out {
                    ty: Ty::Num(Dim::PLAIN),
                    k: fnum(&o.k, if n == "sin" { f64::sin } else { f64::cos }),
                    bare: false,
                }
            }
            ("int", Ty::Int) => o,
            ("int", Ty::Num(d)) => {
                if !d.is_plain() {
                    self.err(
                        Diagnostic::error(
                            Code::E0021,
                            format!("`int` takes a plain number, found {}", d.described()),
                            aspan,
                        )
                        .with_help(format!(
                            "divide by a unit first, e.g. int(t / 1{})",
                            default_unit(d).unwrap_or("s")
                        )),
                    );
                    return Out::err();
                }
                self.emit(Instr::NumToInt, sp);
                let k = match o.k {
                    Some(ConstValue::Num(x)) if x.is_finite() && x.trunc().abs() < 9.2e18 => {
                        Some(ConstValue::Int(x.trunc() as i64))
                    }
                    Some(ConstValue::Num(_)) => {
                        self.err(Diagnostic::error(
                            Code::E0026,
                            "this value does not fit in an int",
                            aspan,
                        ));
                        return Out::err();
                    }
                    _ => None,
                };
                Out {
                    ty: Ty::Int,
                    k,
                    bare: false,
                }
            }
            ("num", Ty::Int) => {
                self.emit(Instr::IntToNum, sp);
                Out {
                    ty: Ty::Num(Dim::PLAIN),
                    k: to_num(&o.k),
                    bare: false,
                }
            }
            ("num", Ty::Num(_)) => o,
            (n, t) => {
                self.err(Diagnostic::error(
                    Code::E0020,
                    format!("`{n}` cannot take {}", t.described()),
                    aspan,
                ));
                Out::err()
            }
        }
    }
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used, clippy::expect_used)]
    use super::*;

    /// docs/language.md's table of built-ins and this one say the same: every built-in's
    /// signature and result are in the reference, and the reference lists no other.
    #[test]
    fn the_language_reference_lists_every_builtin_as_the_table_does() {
        let doc = include_str!("../../../../docs/language.md");
        let section = doc
            .split("## Built-in functions")
            .nth(1)
            .and_then(|s| s.split("\n## ").next())
            .expect("docs/language.md has a built-in functions section");
        for b in BUILTINS {
            let row = section
                .lines()
                .find(|l| l.contains(&format!("`{}`", b.signature)))
                .unwrap_or_else(|| panic!("docs/language.md does not list `{}`", b.signature));
            assert!(
                row.contains(&format!("| {} |", b.returns)),
                "`{}` returns {} by the table: {row}",
                b.name,
                b.returns
            );
        }
        for line in section.lines().filter(|l| l.starts_with("| `")) {
            let first = line.split('|').nth(1).unwrap_or("");
            for call in first.split('`').skip(1).step_by(2) {
                let name = call.split('(').next().unwrap_or("");
                assert!(
                    builtin_named(name).is_some(),
                    "`{name}` in the docs is no built-in"
                );
            }
        }
        // Calls compile to the instructions the table names.
        assert!(
            BUILTINS
                .iter()
                .all(|b| b.builtin == Builtin::Pose || !b.instrs.is_empty())
        );
    }
}
