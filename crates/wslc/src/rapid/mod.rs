//! The ABB RAPID front-end: RAPID modules compiled to the same bytecode as WSL.
//!
//! A robot task's RAPID text is lexed ([`lexer`]), parsed ([`parser`]) into
//! [`syntax`] trees, and translated (`lower`) into a WSL syntax tree, which the WSL
//! compiler checks and turns into a [`vworks_vm::Module`]. The VM and the engine do not know
//! which language a module came from: a RAPID robot and a WSL robot share globals,
//! events, waits and deadlock reports in one cell. See `docs/rapid.md` for the subset and
//! how each construct maps.
//!
//! ```
//! let src = "MODULE m\n  PERS num parts := 0;\n  PROC main()\n    WaitTime 0.5;\n    Incr parts;\n  ENDPROC\nENDMODULE\n";
//! let out = vworks_wslc::rapid::compile("r1.mod", src).expect("compiles");
//! assert_eq!(out.module.globals.len(), 1);
//! ```

pub mod lexer;
mod lower;
pub mod parser;
pub mod syntax;

use crate::diag::Diagnostic;
use crate::{CompileError, Compiled};

/// File extensions of RAPID modules: `.mod`, `.modx`, `.sys`, `.sysx`, `.prg`.
pub const EXTENSIONS: &[&str] = &["mod", "modx", "sys", "sysx", "prg"];

/// True if `path` names a RAPID module by its extension (any case).
pub fn is_rapid_path(path: &str) -> bool {
    std::path::Path::new(path)
        .extension()
        .and_then(|e| e.to_str())
        .is_some_and(|e| EXTENSIONS.iter().any(|x| x.eq_ignore_ascii_case(e)))
}

/// Compiles one RAPID file (one or more `MODULE … ENDMODULE`) into a verified module.
pub fn compile(path: &str, source: &str) -> Result<Compiled, CompileError> {
    let mut diags: Vec<Diagnostic> = Vec::new();
    let toks = lexer::lex(source, &mut diags);
    let modules = parser::parse(source, toks, &mut diags);
    let ast = if diags.iter().any(Diagnostic::is_error) {
        None
    } else {
        if modules.is_empty() {
            diags.push(
                Diagnostic::error(
                    crate::Code::E0005,
                    "this file has no `MODULE … ENDMODULE`",
                    crate::syntax::Span::default(),
                )
                .with_help("a RAPID program is one or more modules: `MODULE name … ENDMODULE`"),
            );
        }
        Some(lower::translate(&modules, &mut diags))
    };
    crate::finish(path, source, ast.as_ref(), diags)
}
