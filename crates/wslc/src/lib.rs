//! `wslc`, the WSL compiler.
//!
//! WSL is the workcell simulation language of vworks (see `docs/language.md`). One `.wsl`
//! file is one module; [`compile`] turns its text into a verified
//! [`vworks_vm::Module`] of bytecode, or into every problem it found, each with a stable
//! code and a `file:line:col` position. [`link`] checks a set of modules against a workcell
//! (robots, axis counts, parts) before a simulation starts.
//!
//! Passes, in order:
//! - [`lexer`]: text → tokens (units resolved to SI with dimensions);
//! - [`parser`]: tokens → [`syntax`] tree, recovering after errors;
//! - `lower`: names, types, units and the language's rules, with code generation;
//! - the VM crate's verifier, run on every module produced (a failure is a compiler bug,
//!   reported as `E0900`, never a panic).
//!
//! ```
//! let src = "global parts = 0;\nproc main() { parts = parts + 1; }\n";
//! let out = vworks_wslc::compile("r1.wsl", src).expect("compiles");
//! assert_eq!(out.module.globals.len(), 1);
//! ```

pub mod diag;
pub mod lexer;
pub mod link;
mod lower;
pub mod parser;
pub mod syntax;

pub use diag::{Code, Diagnostic, Severity, Sources, render};
pub use vworks_vm::Module;

/// A successful compilation.
#[derive(Debug, Clone)]
pub struct Compiled {
    /// The verified bytecode module.
    pub module: Module,
    /// Warnings (never errors).
    pub warnings: Vec<Diagnostic>,
}

/// A failed compilation: every diagnostic found, errors and warnings, in source order.
#[derive(Debug, Clone, thiserror::Error)]
#[error("{}", summary(.diagnostics))]
pub struct CompileError {
    /// All diagnostics, sorted by position.
    pub diagnostics: Vec<Diagnostic>,
}

fn summary(d: &[Diagnostic]) -> String {
    let errors: Vec<String> = d
        .iter()
        .filter(|d| d.is_error())
        .map(Diagnostic::short)
        .collect();
    errors.join("\n")
}

/// Compiles one module. `path` names the file in diagnostics and in the module.
pub fn compile(path: &str, source: &str) -> Result<Compiled, CompileError> {
    let mut diags = Vec::new();
    let toks = lexer::lex(source, &mut diags);
    let ast = parser::parse(source, toks, &mut diags);
    let syntax_ok = !diags.iter().any(Diagnostic::is_error);
    let mut module = if syntax_ok {
        Some(lower::lower(path, source, &ast, &mut diags))
    } else {
        None
    };
    if let Some(m) = module.as_mut()
        && !diags.iter().any(Diagnostic::is_error)
        && let Err(e) = m.verify()
    {
        diags.push(
            Diagnostic::error(
                Code::E0900,
                format!("the compiler produced invalid bytecode: {e}"),
                syntax::Span::default(),
            )
            .with_help(
                "this is a bug in vworks; please report it with the program that triggers it",
            ),
        );
    }
    let index = diag::LineIndex::new(source);
    for d in &mut diags {
        d.resolve(path, &index);
    }
    diags.sort_by_key(|d| (d.at.line, d.at.col));
    match module {
        Some(module) if !diags.iter().any(Diagnostic::is_error) => Ok(Compiled {
            module,
            warnings: diags,
        }),
        _ => Err(CompileError { diagnostics: diags }),
    }
}
