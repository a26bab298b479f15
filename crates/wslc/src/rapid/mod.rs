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

mod catalog;
pub mod lexer;
mod lower;
pub mod parser;
pub mod syntax;

use crate::diag::Diagnostic;
use crate::output::{CompileError, Compiled};

/// File extensions of RAPID modules: `.mod`, `.modx`, `.sys`, `.sysx`, `.prg`
/// ([`crate::Language::of_source_file`] reads them).
pub const EXTENSIONS: &[&str] = &["mod", "modx", "sys", "sysx", "prg"];

/// RAPID's instructions the front-end knows, as (name, what it does in vworks), in
/// docs/rapid.md's order: for editors, completions and documentation tools. (Those
/// vworks does not run say `E0300`.)
pub fn instructions() -> impl Iterator<Item = (&'static str, &'static str)> {
    lower::table::INSTRUCTIONS.iter().map(|r| (r.name, r.doc))
}

/// RAPID's functions the front-end knows, as [`instructions`] lists the instructions.
pub fn functions() -> impl Iterator<Item = (&'static str, &'static str)> {
    lower::table::FUNCTIONS.iter().map(|r| (r.name, r.doc))
}

/// The kind of an I/O signal.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum SignalKind {
    /// A digital input (0 or 1).
    Di,
    /// A digital output (0 or 1).
    Do,
    /// A group input (a whole number).
    Gi,
    /// A group output (a whole number).
    Go,
}

impl SignalKind {
    /// The kind from its name in a workcell (`di`, `do`, `gi`, `go`, any case).
    pub fn from_name(s: &str) -> Option<SignalKind> {
        Some(match s.to_ascii_lowercase().as_str() {
            "di" => SignalKind::Di,
            "do" => SignalKind::Do,
            "gi" => SignalKind::Gi,
            "go" => SignalKind::Go,
            _ => return None,
        })
    }
    /// `di`, `do`, `gi` or `go`.
    pub fn name(self) -> &'static str {
        match self {
            SignalKind::Di => "di",
            SignalKind::Do => "do",
            SignalKind::Gi => "gi",
            SignalKind::Go => "go",
        }
    }
    /// An output (written by `SetDO`, `SetGO`, …).
    pub fn is_output(self) -> bool {
        matches!(self, SignalKind::Do | SignalKind::Go)
    }
}

/// An I/O signal as one robot task sees it: the workcell wires it to one of the cell's
/// globals (signals are levels; a `SetDO` is a `set` of that global).
#[derive(Clone, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct IoSignal {
    /// Its name in this task's programs.
    pub name: String,
    /// Its kind.
    pub kind: SignalKind,
    /// The cell's global (int) that holds its value: the name of the output that drives it.
    pub global: String,
    /// Its value at the start.
    pub init: i64,
}

/// Compiles one RAPID file (one or more `MODULE … ENDMODULE`) into a verified module.
/// Its I/O signals need no workcell: a signal an I/O instruction names is the cell's
/// global of that name (`SetDO doReady, 1;` sets `doready`). Within a workcell, the
/// loader calls [`compile_with_io`] with the robot's wired signals.
pub fn compile(path: &str, source: &str) -> Result<Compiled, CompileError> {
    compile_with_io(path, source, None)
}

/// Compiles one RAPID file for a robot whose I/O signals are `io` (the workcell's
/// `[[io]]`); a signal outside it is error E0302. `None`: any signal an I/O instruction
/// names, as [`compile`].
pub fn compile_with_io(
    path: &str,
    source: &str,
    io: Option<&[IoSignal]>,
) -> Result<Compiled, CompileError> {
    compile_files(&[(path, source)], io)
}

/// Compiles a robot task of several RAPID files ((path, text), in order; each one or
/// more whole modules) into one module, with the task's I/O signals `io` as
/// [`compile_with_io`]. The modules of all files are one task: a `PROC` of one file calls
/// a `PROC` of another, and data declared in one module is seen by the others (`LOCAL`
/// keeps it to its own module). Each file is lexed and parsed on its own, so a module
/// cannot run on into the next file; positions and diagnostics name their own file.
pub fn compile_files(
    files: &[(&str, &str)],
    io: Option<&[IoSignal]>,
) -> Result<Compiled, CompileError> {
    let program = crate::frontend::program::ProgramText::new(files);
    let mut diags: Vec<Diagnostic> = Vec::new();
    let mut modules = Vec::new();
    let mut empty = Vec::new();
    for (start, found) in program.parse_each(&mut diags, lexer::lex, parser::parse) {
        if found.is_empty() {
            empty.push(start);
        }
        modules.extend(found);
    }
    // A construct the parser recognised but vworks does not run (E0300: `RECORD`) does
    // not stop the translation, which reports the others.
    let syntax_error = diags
        .iter()
        .any(|d| d.is_error() && d.code != crate::Code::E0300);
    let ast = if syntax_error {
        None
    } else {
        for start in empty {
            diags.push(
                Diagnostic::error(
                    crate::Code::E0005,
                    "this file has no `MODULE … ENDMODULE`",
                    crate::syntax::Span::new(start, start),
                )
                .with_help("a RAPID program is one or more modules: `MODULE name … ENDMODULE`"),
            );
        }
        Some(lower::translate(&modules, io, &mut diags))
    };
    crate::lower::finish(&program, ast.as_ref(), diags)
}
