//! What only a translation from RAPID ([`SourceModule::texts`]) compiles: RAPID's string
//! functions (`StrLen`, `StrPart`, `NumToStr`, …) and `ERRNO`, which the RAPID front-end
//! calls by names WSL source cannot write (they end in `'`), each one instruction
//! (docs/bytecode.md); and error recovery (`RAISE`, `RETRY`, `TRYNEXT`), which the
//! error handlers of `crate::lower::resolve` surround. WSL itself has no text values and
//! no error handlers.

use super::*;

/// A parameter's or result's type.
#[derive(Clone, Copy)]
enum T {
    Text,
    Num,
    Bool,
    Int,
}

impl T {
    fn ty(self) -> Ty {
        match self {
            T::Text => Ty::Text,
            T::Num => Ty::Num(Dim::PLAIN),
            T::Bool => Ty::Bool,
            T::Int => Ty::Int,
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
    ("errno'", &[], T::Int, Instr::ErrNo),
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

    /// `Raise`, `Retry`, `TryNext` (they end the block).
    pub(super) fn recovery(&mut self, kind: &StmtKind, sp: Span) {
        let in_handler = self.f().in_handler;
        match kind {
            StmtKind::Raise(Some(e), message) => {
                let o = self.expr(e);
                self.coerce(o, Ty::Int, e.span, "an error number");
                let s = self.str(message);
                self.emit(Instr::Raise(s), sp);
            }
            StmtKind::Raise(None, _) if in_handler => {
                self.emit(Instr::RaiseUp, sp);
            }
            StmtKind::Retry if in_handler => {
                self.emit(Instr::Retry, sp);
            }
            StmtKind::TryNext if in_handler => {
                self.emit(Instr::TryNext, sp);
            }
            _ => {
                let what = match kind {
                    StmtKind::Retry => "RETRY",
                    StmtKind::TryNext => "TRYNEXT",
                    _ => "`RAISE;` (raising the handler's error again)",
                };
                self.err(
                    Diagnostic::error(Code::E0304, format!("{what} outside an error handler"), sp)
                        .with_help("it goes in the routine's `ERROR` clause"),
                );
            }
        }
    }
}
