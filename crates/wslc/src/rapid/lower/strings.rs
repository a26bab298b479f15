//! RAPID's strings at run time: the string functions (`StrLen`, `StrPart`, `StrFind`,
//! `StrMatch`, `StrMemb`, `StrMap`, `NumToStr`, `ValToStr`) lowered onto the WSL
//! compiler's text functions (`crate::lower::texts`), and `StrToVal` as an assignment.
//! A `string` is one WSL value of type `text` (its leaf, [`Ty::Str`]); texts known when
//! compiling are joined and compared then (`Val::text`).

use super::data::{Ty, build as b};
use super::expr::article;
use super::table::Call;
use super::{Tr, Val};
use crate::diag::Code;
use crate::rapid::syntax::{self as r, Arg};
use crate::syntax::{self as w, Span};

impl Tr<'_> {
    /// The arguments of `c` as the types `want` (a string, a num, …), or `None` after a
    /// diagnostic.
    fn typed_args(&mut self, c: &Call<'_>, want: &[Ty]) -> Option<Vec<w::Expr>> {
        let mut out = Vec::new();
        for (e, t) in c.pos.iter().zip(want) {
            out.push(self.value(e, *t)?.leaf());
        }
        Some(out)
    }

    /// `StrLen`, `StrPart`, `StrFind`, `StrMatch`, `StrMemb`, `StrMap`, `NumToStr`.
    pub(crate) fn string_function(&mut self, c: &Call<'_>) -> Option<Val> {
        use Ty::{Num, Str};
        let (want, f, ret): (&[Ty], &str, Ty) = match c.key {
            "strlen" => (&[Str], "strlen'", Num),
            "strpart" => (&[Str, Num, Num], "strpart'", Str),
            "strfind" if c.opts.is_empty() => (&[Str, Num, Str], "strfind'", Num),
            "strfind" => (&[Str, Num, Str], "strfind_not'", Num),
            "strmatch" => (&[Str, Num, Str], "strmatch'", Num),
            "strmemb" => (&[Str, Num, Str], "strmemb'", Ty::Bool),
            "strmap" => (&[Str, Str, Str], "strmap'", Str),
            _ => {
                if let Some((_, n, _)) = c.opts.first() {
                    self.unsupported(
                        "NumToStr's `\\Exp` (exponent notation)",
                        n.span,
                        "print the number with decimals",
                    );
                    return None;
                }
                (&[Num, Num], "numtostr'", Str)
            }
        };
        let args = self.typed_args(c, want)?;
        Some(Val::one(ret, b::call(f, args, c.span)))
    }

    /// `ValToStr(v)`: a num or bool as RAPID writes it; a string is itself.
    pub(crate) fn val_to_str(&mut self, c: &Call<'_>) -> Option<Val> {
        let v = self.expr(c.pos[0])?;
        let f = match v.ty {
            Ty::Num => "valtostr_num'",
            Ty::Bool => "valtostr_bool'",
            Ty::Str => return Some(v),
            t => {
                self.unsupported(
                    &format!("ValToStr of {}", article(t)),
                    c.pos[0].span,
                    "write its components with NumToStr",
                );
                return None;
            }
        };
        Some(Val::one(Ty::Str, b::call(f, vec![v.leaf()], c.span)))
    }

    /// `BookErrNo e;`: the errnum `e` gets a number of its own, from 90 down by the
    /// errnums' names in order, one per errnum the task books (the same each time).
    pub(crate) fn book_errno(&mut self, c: &Call<'_>, out: &mut Vec<w::Stmt>) {
        let Some((d, idx)) = self.place(c.pos[0]) else {
            return;
        };
        if d.ty != Ty::Num {
            self.error(
                Code::E0020,
                format!("BookErrNo books an errnum, not {}", article(d.ty)),
                c.pos[0].span,
            );
            return;
        }
        let name = self.leaf_names(&d, idx)[0].clone();
        // Its rank among the errnums the task books (found before any routine).
        let key = match &c.pos[0].kind {
            r::ExprKind::Name(n) => format!("bookerrno:{}", n.key()),
            _ => String::new(),
        };
        let rank = self
            .helpers
            .iter()
            .filter(|h| h.starts_with("bookerrno:"))
            .position(|h| *h == key)
            .unwrap_or(0);
        out.push(w::Stmt {
            kind: w::StmtKind::Assign {
                target: b::name(&name, c.pos[0].span),
                op: None,
                value: b::num(90.0 - rank as f64, c.span),
            },
            span: c.span,
        });
    }

    /// `StrToVal(text, x)` outside an assignment of its result: it writes `x`.
    pub(crate) fn str_to_val_here(&mut self, c: &Call<'_>) -> Option<Val> {
        self.unsupported(
            "StrToVal inside an expression",
            c.name.span,
            "write `ok := StrToVal(text, x);` and test `ok`",
        );
        None
    }

    /// `ok := StrToVal(text, x);` (`x` a num): `ok` is whether `text` writes a number,
    /// and `x` that number if it does (else `x` keeps its value). `None` if `value` is not
    /// such a call.
    pub(crate) fn str_to_val(
        &mut self,
        target: &r::Expr,
        value: &r::Expr,
        span: Span,
    ) -> Option<Vec<w::StmtKind>> {
        let r::ExprKind::Call(f, args) = &value.kind else {
            return None;
        };
        if f.key() != "strtoval" || self.lookup(&f.key()).is_some() {
            return None;
        }
        let (text, x) = match args.as_slice() {
            [Arg::Pos(t), Arg::Pos(x)] => (t, x),
            _ => {
                self.error(
                    Code::E0013,
                    "StrToVal takes a string and the num it writes",
                    value.span,
                );
                return Some(Vec::new());
            }
        };
        let Some((d, idx)) = self.place(x) else {
            return Some(Vec::new());
        };
        if d.ty != Ty::Num {
            self.unsupported(
                &format!("StrToVal into {}", article(d.ty)),
                x.span,
                "convert into a num",
            );
            return Some(Vec::new());
        }
        let Some((ok, ok_idx)) = self.place(target) else {
            return Some(Vec::new());
        };
        if ok.ty != Ty::Bool {
            self.error(
                Code::E0020,
                format!("StrToVal gives a bool, not {}", article(ok.ty)),
                target.span,
            );
            return Some(Vec::new());
        }
        let s = self.value(text, Ty::Str)?.leaf();
        let ok_name = b::name(&self.leaf_names(&ok, ok_idx)[0], target.span);
        let x_name = b::name(&self.leaf_names(&d, idx)[0], x.span);
        let set = |t: w::Expr, v: w::Expr| b::assign(t, v);
        Some(vec![
            set(ok_name.clone(), b::call("strisnum'", vec![s.clone()], span)),
            w::StmtKind::If {
                branches: vec![(
                    ok_name,
                    super::block(
                        vec![w::Stmt {
                            kind: set(x_name, b::call("strnum'", vec![s], span)),
                            span,
                        }],
                        span,
                    ),
                )],
                els: None,
            },
        ])
    }
}
