//! The text functions of a translation from RAPID ([`SourceModule::texts`]): RAPID's
//! string functions (`StrLen`, `StrPart`, `NumToStr`, …) as the RAPID front-end calls them,
//! by names WSL source cannot write (they end in `'`), each one text instruction
//! (docs/bytecode.md). WSL itself has no text values.

use super::*;

/// A parameter's or result's type.
#[derive(Clone, Copy)]
enum T {
    Text,
    Num,
    Bool,
}

impl T {
    fn ty(self) -> Ty {
        match self {
            T::Text => Ty::Text,
            T::Num => Ty::Num(Dim::PLAIN),
            T::Bool => Ty::Bool,
        }
    }
}

/// (name, parameters, result, instruction).
const TEXT_FUNCTIONS: &[(&str, &[T], T, Instr)] = &[
    ("strlen'", &[T::Text], T::Num, Instr::TextLen),
    (
        "strpart'",
        &[T::Text, T::Num, T::Num],
        T::Text,
        Instr::TextPart,
    ),
    (
        "strfind'",
        &[T::Text, T::Num, T::Text],
        T::Num,
        Instr::TextFind(false),
    ),
    (
        "strfind_not'",
        &[T::Text, T::Num, T::Text],
        T::Num,
        Instr::TextFind(true),
    ),
    (
        "strmatch'",
        &[T::Text, T::Num, T::Text],
        T::Num,
        Instr::TextMatch,
    ),
    (
        "strmemb'",
        &[T::Text, T::Num, T::Text],
        T::Bool,
        Instr::TextMemb,
    ),
    (
        "strmap'",
        &[T::Text, T::Text, T::Text],
        T::Text,
        Instr::TextMap,
    ),
    ("numtostr'", &[T::Num, T::Num], T::Text, Instr::NumToText),
    ("valtostr_bool'", &[T::Bool], T::Text, Instr::ValText(0)),
    ("valtostr_num'", &[T::Num], T::Text, Instr::ValText(1)),
    ("strisnum'", &[T::Text], T::Bool, Instr::TextIsNum),
    ("strnum'", &[T::Text], T::Num, Instr::TextNum),
];

impl Compiler<'_> {
    /// A call of a text function, if `name` is one and texts are allowed.
    pub(super) fn text_function(&mut self, name: &Ident, args: &[Expr], sp: Span) -> Option<Out> {
        if !self.texts {
            return None;
        }
        let n = name.name.as_str();
        let &(_, params, ret, instr) = TEXT_FUNCTIONS.iter().find(|(f, ..)| *f == n)?;
        if args.len() != params.len() {
            self.err(Diagnostic::error(
                Code::E0013,
                format!(
                    "`{n}` takes {} arguments, {} given",
                    params.len(),
                    args.len()
                ),
                sp,
            ));
            return Some(Out::err());
        }
        let mut ok = true;
        for (k, (a, p)) in args.iter().zip(params).enumerate() {
            let o = self.expr(a);
            let o = self.coerce(o, p.ty(), a.span, &format!("argument {} of `{n}`", k + 1));
            ok &= !o.ty.is_err();
        }
        if !ok {
            return Some(Out::err());
        }
        self.emit(instr, sp);
        Some(Out::of(ret.ty()))
    }
}
