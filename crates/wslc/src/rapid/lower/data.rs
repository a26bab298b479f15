//! RAPID's data types and how each is held in WSL values: the type table, the predefined
//! data (`v100`, `z10`, `fine`, `tool0`, `wobj0`, …), the unit conversions (RAPID's
//! millimetres, degrees and seconds to WSL's SI quantities) and the WSL expressions the
//! front-end builds.
//!
//! A RAPID value is held as zero or more WSL values, its **leaves**: a `num` is one WSL
//! `num`, a `robtarget` one `pose`, a `speeddata` a `speed` and an `angspeed`. Data that
//! only a real controller uses (`loaddata`, `confdata`, external axes) has no leaves: it is
//! type-checked and dropped, as docs/rapid.md says.
//!
//! This is the one place RAPID's types meet WSL's: [`TYPES`] names RAPID's types, and
//! [`Ty::leaves`] gives each one's leaves in the shared vocabulary of the checker and the
//! VM ([`vworks_vm::Type`], with its [`Dim`]); the WSL type written in the tree is that
//! type's one spelling ([`Type::name`]). The WSL checker then checks the leaves as it
//! checks WSL.

use vworks_vm::{Dim, Type};

use crate::syntax::{self as w, Span};

/// A RAPID data type the front-end knows.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Ty {
    Num,
    Bool,
    Str,
    Pos,
    Orient,
    Pose,
    Robtarget,
    Jointtarget,
    /// A jointtarget's robot axes (`robax`): six angles in degrees.
    Robjoint,
    Speed,
    Zone,
    Tool,
    Wobj,
    Load,
    Conf,
    Extax,
    Intnum,
    /// An optional parameter that is only given or not (`\switch On`).
    Switch,
    /// A stopwatch (`ClkStart`, `ClkRead`): when it last started, the time it ran before,
    /// and whether it runs.
    Clock,
    /// A `RECORD` of the task (its index among the task's records).
    Record(u16),
    /// A MultiMove synchronisation point (`WaitSyncTask`).
    Syncident,
    /// A task name, in the task lists of `WaitSyncTask`.
    Tasks,
}

/// RAPID's type names the front-end knows, each with its type (the first name of a type
/// is how messages write it; `dnum` is a `num`). Declarations may name the ones before
/// `syncident` anywhere; `syncident` and `tasks` are MultiMove's.
pub(crate) const TYPES: &[(&str, Ty)] = &[
    ("num", Ty::Num),
    ("dnum", Ty::Num),
    ("bool", Ty::Bool),
    ("string", Ty::Str),
    ("pos", Ty::Pos),
    ("orient", Ty::Orient),
    ("pose", Ty::Pose),
    ("robtarget", Ty::Robtarget),
    ("jointtarget", Ty::Jointtarget),
    ("robjoint", Ty::Robjoint),
    ("speeddata", Ty::Speed),
    ("zonedata", Ty::Zone),
    ("tooldata", Ty::Tool),
    ("wobjdata", Ty::Wobj),
    ("loaddata", Ty::Load),
    ("confdata", Ty::Conf),
    ("extjoint", Ty::Extax),
    ("intnum", Ty::Intnum),
    ("errnum", Ty::Num),
    ("clock", Ty::Clock),
    ("switch", Ty::Switch),
    ("syncident", Ty::Syncident),
    ("tasks", Ty::Tasks),
];

/// A num's leaf: a plain WSL number.
const NUM: Type = Type::Num(Dim::PLAIN);

impl Ty {
    /// The type of a RAPID type name (any case).
    pub(crate) fn from_name(name: &str) -> Option<Ty> {
        TYPES
            .iter()
            .find(|(n, _)| n.eq_ignore_ascii_case(name))
            .map(|(_, t)| *t)
    }

    /// The name as RAPID writes it.
    pub(crate) fn name(self) -> &'static str {
        if let Ty::Record(_) = self {
            return "record";
        }
        TYPES
            .iter()
            .find(|(_, t)| *t == self)
            .map_or("?", |(n, _)| n)
    }

    /// Its WSL leaves: (suffix of the WSL name, the leaf's type).
    pub(crate) fn leaves(self) -> &'static [(&'static str, Type)] {
        match self {
            Ty::Num | Ty::Intnum => &[("", NUM)],
            Ty::Bool => &[("", Type::Bool)],
            Ty::Pos | Ty::Orient | Ty::Pose | Ty::Robtarget => &[("", Type::Pose)],
            Ty::Jointtarget | Ty::Robjoint => &[("", Type::Joints)],
            Ty::Speed => &[
                (".v_tcp", Type::Num(Dim::SPEED)),
                (".v_ori", Type::Num(Dim::ANGSPEED)),
            ],
            Ty::Zone => &[
                (".pzone_tcp", Type::Num(Dim::LENGTH)),
                (".pzone_ori", Type::Num(Dim::LENGTH)),
                (".zone_ori", Type::Num(Dim::ANGLE)),
            ],
            Ty::Tool => &[(".tframe", Type::Pose)],
            Ty::Clock => &[
                (".started", Type::Num(Dim::TIME)),
                (".before", Type::Num(Dim::TIME)),
                (".running", Type::Bool),
            ],
            Ty::Wobj => &[(".uframe", Type::Pose), (".oframe", Type::Pose)],
            Ty::Str => &[("", Type::Text)],
            Ty::Load
            | Ty::Conf
            | Ty::Extax
            | Ty::Syncident
            | Ty::Tasks
            | Ty::Switch
            | Ty::Record(_) => &[],
        }
    }

    /// Held in one WSL pose.
    pub(crate) fn is_posed(self) -> bool {
        matches!(self, Ty::Pos | Ty::Orient | Ty::Pose | Ty::Robtarget)
    }
}

/// RAPID's error numbers the engine raises or a program names, with vworks's own numbers
/// (a program compares `ERRNO` with the names; RAISE of a program's own error takes 1 to
/// 90, `BookErrNo` books from 90 down).
pub(crate) const ERRORS: &[(&str, i32)] = &[
    ("ERR_WAIT_MAXTIME", 1001),
    ("ERR_WAITSYNCTASK", 1002),
    ("ERR_INDEX", 1003),
    ("ERR_DIVZERO", 1004),
    ("ERR_STRTOOLNG", vworks_vm::texts::ERR_STRTOOLNG as i32),
    ("ERR_OUTOFBND", vworks_vm::texts::ERR_OUTOFBND as i32),
    ("ERR_NOTPRES", 1007),
    ("ERR_EXCRTYMAX", 1008),
    ("ERR_TP_MAXTIME", 1009),
    ("ERR_TP_NO_CLIENT", 1010),
    // Errors of the controller that vworks never raises: a handler may test for them.
    ("ERR_ARGNOTPER", 1011),
    ("ERR_ARGNOTVAR", 1012),
    ("ERR_CALLPROC", 1013),
    ("ERR_CNTNOTVAR", 1014),
    ("ERR_EXECPHR", 1015),
    ("ERR_REFUNKPRC", 1016),
    ("ERR_TP_DIBREAK", 1017),
    ("ERR_TP_DOBREAK", 1018),
    ("ERR_UNKPROC", 1019),
    ("ERR_AO_LIM", 1020),
    ("ERR_NORUNUNIT", 1021),
    ("ERR_SIG_NOT_VALID", 1022),
    ("ERR_PATH_STOP", 1023),
    ("ERR_ROBLIMIT", 1024),
    ("ERR_SIGSUPSEARCH", 1025),
    ("ERR_WHLSEARCH", 1026),
    ("ERR_CALC_NEG", 1027),
    ("ERR_NUM_LIMIT", 1028),
    ("ERR_ACC_TOO_LOW", 1029),
    ("ERR_USE_PROF", 1030),
    ("ERR_INOMAX", 1031),
    ("ERR_ALRDYCNT", 1032),
    ("ERR_ALRDY_MOVING", 1033),
    ("ERR_COLL_STOP", 1034),
    ("ERR_CONC_MAX", 1035),
    ("ERR_NO_SGUN", 1036),
    ("ERR_SC_WRITE", 1037),
    ("ERR_STARTMOVE", 1038),
    ("ERR_ARGVALERR", 1039),
    ("ERR_ILLRAISE", 1040),
];

/// Predefined `speeddata`: (name, v_tcp mm/s, v_ori deg/s), as the RAPID reference lists
/// them (`vmax` is 5000 mm/s, as on most arms).
pub(crate) const SPEEDS: &[(&str, f64, f64)] = &[
    ("v5", 5.0, 500.0),
    ("v10", 10.0, 500.0),
    ("v20", 20.0, 500.0),
    ("v30", 30.0, 500.0),
    ("v40", 40.0, 500.0),
    ("v50", 50.0, 500.0),
    ("v60", 60.0, 500.0),
    ("v80", 80.0, 500.0),
    ("v100", 100.0, 500.0),
    ("v150", 150.0, 500.0),
    ("v200", 200.0, 500.0),
    ("v300", 300.0, 500.0),
    ("v400", 400.0, 500.0),
    ("v500", 500.0, 500.0),
    ("v600", 600.0, 500.0),
    ("v800", 800.0, 500.0),
    ("v1000", 1000.0, 500.0),
    ("v1500", 1500.0, 500.0),
    ("v2000", 2000.0, 500.0),
    ("v2500", 2500.0, 500.0),
    ("v3000", 3000.0, 500.0),
    ("v4000", 4000.0, 500.0),
    ("v5000", 5000.0, 500.0),
    ("v6000", 6000.0, 500.0),
    ("v7000", 7000.0, 500.0),
    ("vmax", 5000.0, 500.0),
];

/// Predefined `zonedata`: (name, pzone_tcp mm, pzone_ori mm, zone_ori degrees), as the
/// RAPID reference lists them (`pzone_eax`, `zone_leax` and `zone_reax`, for external
/// axes, are not simulated); `fine` stops at the point. The same fifteen, value for value,
/// are tabulated by RobotComponents (`RobotComponents/Actions/ZoneData.cs`), an open RAPID
/// generator.
pub(crate) const ZONES: &[(&str, f64, f64, f64)] = &[
    ("fine", 0.0, 0.0, 0.0),
    ("z0", 0.3, 0.3, 0.03),
    ("z1", 1.0, 1.0, 0.1),
    ("z5", 5.0, 8.0, 0.8),
    ("z10", 10.0, 15.0, 1.5),
    ("z15", 15.0, 23.0, 2.3),
    ("z20", 20.0, 30.0, 3.0),
    ("z30", 30.0, 45.0, 4.5),
    ("z40", 40.0, 60.0, 6.0),
    ("z50", 50.0, 75.0, 7.5),
    ("z60", 60.0, 90.0, 9.0),
    ("z80", 80.0, 120.0, 12.0),
    ("z100", 100.0, 150.0, 15.0),
    ("z150", 150.0, 225.0, 23.0),
    ("z200", 200.0, 300.0, 30.0),
];

/// RAPID's unit of a dimension, as an SI factor: mm, degrees, seconds.
pub(crate) fn unit(dim: Dim) -> f64 {
    let mm = 0.001_f64;
    let deg = std::f64::consts::PI / 180.0;
    mm.powi(i32::from(dim.length)) * deg.powi(i32::from(dim.angle))
}

/// WSL expression builders; every node gets the span of the RAPID construct it comes from.
pub(crate) mod build {
    use super::*;

    pub(crate) fn expr(kind: w::ExprKind, span: Span) -> w::Expr {
        w::Expr { kind, span }
    }
    pub(crate) fn num(x: f64, span: Span) -> w::Expr {
        expr(w::ExprKind::Num(x), span)
    }
    pub(crate) fn quantity(x: f64, dim: Dim, span: Span) -> w::Expr {
        expr(w::ExprKind::Quantity(x, dim), span)
    }
    pub(crate) fn name(n: &str, span: Span) -> w::Expr {
        expr(w::ExprKind::Name(n.to_string()), span)
    }
    /// The WSL type name of `t` (its one spelling, `Type::name`).
    pub(crate) fn type_name(t: Type, span: Span) -> w::Ident {
        ident(&t.name(), span)
    }
    pub(crate) fn ident(n: &str, span: Span) -> w::Ident {
        w::Ident {
            name: n.to_string(),
            span,
        }
    }
    pub(crate) fn call(f: &str, args: Vec<w::Expr>, span: Span) -> w::Expr {
        expr(w::ExprKind::Call(ident(f, span), args), span)
    }
    pub(crate) fn bin(op: w::BinOp, a: w::Expr, b: w::Expr) -> w::Expr {
        let span = a.span.to(b.span);
        expr(w::ExprKind::Binary(op, Box::new(a), Box::new(b)), span)
    }
    pub(crate) fn field(e: w::Expr, f: &str) -> w::Expr {
        let span = e.span;
        expr(w::ExprKind::Field(Box::new(e), ident(f, span)), span)
    }
    pub(crate) fn not(e: w::Expr) -> w::Expr {
        let span = e.span;
        expr(w::ExprKind::Unary(w::UnOp::Not, Box::new(e)), span)
    }
    pub(crate) fn neg(e: w::Expr) -> w::Expr {
        let span = e.span;
        match e.kind {
            w::ExprKind::Num(x) => num(-x, span),
            w::ExprKind::Quantity(x, d) => quantity(-x, d, span),
            kind => expr(
                w::ExprKind::Unary(w::UnOp::Neg, Box::new(expr(kind, span))),
                span,
            ),
        }
    }

    /// A RAPID number (plain, in RAPID's unit) as a WSL quantity of `dim`: a literal is
    /// converted here, anything else is multiplied by one unit.
    pub(crate) fn with_unit(e: w::Expr, dim: Dim) -> w::Expr {
        let u = unit(dim);
        match e.kind {
            w::ExprKind::Num(x) => quantity(x * u, dim, e.span),
            w::ExprKind::Int(i) => quantity(i as f64 * u, dim, e.span),
            _ => {
                let span = e.span;
                bin(w::BinOp::Mul, e, quantity(u, dim, span))
            }
        }
    }

    /// A WSL quantity of `dim` as a RAPID number in RAPID's unit.
    pub(crate) fn without_unit(e: w::Expr, dim: Dim) -> w::Expr {
        let u = unit(dim);
        match e.kind {
            w::ExprKind::Quantity(x, d) if d == dim => num(x / u, e.span),
            _ => {
                let span = e.span;
                bin(w::BinOp::Div, e, quantity(u, dim, span))
            }
        }
    }

    /// The literal number of a WSL expression, if it is one.
    pub(crate) fn literal(e: &w::Expr) -> Option<f64> {
        match e.kind {
            w::ExprKind::Num(x) => Some(x),
            w::ExprKind::Int(i) => Some(i as f64),
            w::ExprKind::Quantity(x, _) => Some(x),
            _ => None,
        }
    }

    /// `pose(x, y, z, rx, ry, rz)` from six WSL expressions.
    pub(crate) fn pose(parts: [w::Expr; 6], span: Span) -> w::Expr {
        call("pose", parts.into(), span)
    }

    /// `target = value;` (no compound operator).
    pub(crate) fn assign(target: w::Expr, value: w::Expr) -> w::StmtKind {
        w::StmtKind::Assign {
            target,
            op: None,
            value,
        }
    }

    /// The zero value of a WSL type: 0 in its unit, FALSE, the empty text, the identity
    /// pose, all-zero joints.
    pub(crate) fn zero(t: Type, span: Span) -> w::Expr {
        match t {
            Type::Bool => expr(w::ExprKind::Bool(false), span),
            Type::Int => expr(w::ExprKind::Int(0), span),
            Type::Num(d) if d.is_plain() => num(0.0, span),
            Type::Num(d) => quantity(0.0, d, span),
            Type::Text => expr(w::ExprKind::Str(String::new()), span),
            Type::Pose => identity(span),
            Type::Joints => call("joints", Vec::new(), span),
        }
    }

    /// The identity pose.
    pub(crate) fn identity(span: Span) -> w::Expr {
        let l = |_| quantity(0.0, Dim::LENGTH, span);
        let a = |_| quantity(0.0, Dim::ANGLE, span);
        let [x, y, z] = [0, 1, 2].map(l);
        let [rx, ry, rz] = [0, 1, 2].map(a);
        pose([x, y, z, rx, ry, rz], span)
    }
}

/// Roll, pitch and yaw (WSL's `pose` angles, R = Rz·Ry·Rx) of a RAPID quaternion
/// `[q1, q2, q3, q4]` (q1 the scalar part), normalised; `None` for a zero quaternion.
pub(crate) fn quat_rpy(q: [f64; 4]) -> Option<[f64; 3]> {
    vworks_vm::math::quat_rpy(q)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn quaternions_give_roll_pitch_yaw() {
        let deg = |v: [f64; 3]| v.map(f64::to_degrees);
        let near = |a: [f64; 3], b: [f64; 3]| a.iter().zip(b).all(|(x, y)| (x - y).abs() < 1e-9);
        // Tool pointing down: 180° about x (RAPID's [0,1,0,0]).
        assert!(near(
            deg(quat_rpy([0.0, 1.0, 0.0, 0.0]).unwrap_or_default()),
            [180.0, 0.0, 0.0]
        ));
        // 90° about z.
        let h = 0.5_f64.sqrt();
        assert!(near(
            deg(quat_rpy([h, 0.0, 0.0, h]).unwrap_or_default()),
            [0.0, 0.0, 90.0]
        ));
        // Not normalised: the same rotation.
        assert!(near(
            deg(quat_rpy([2.0, 0.0, 0.0, 2.0]).unwrap_or_default()),
            [0.0, 0.0, 90.0]
        ));
        assert_eq!(quat_rpy([0.0; 4]), None);
    }

    #[test]
    fn units_are_millimetres_degrees_seconds() {
        assert_eq!(unit(Dim::LENGTH), 0.001);
        assert_eq!(unit(Dim::SPEED), 0.001);
        assert!((unit(Dim::ANGSPEED) - 1f64.to_radians()).abs() < 1e-15);
        assert_eq!(unit(Dim::TIME), 1.0);
    }
}
