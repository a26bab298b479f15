//! What a compilation gives: the module and its warnings, or every diagnostic found. Every
//! front-end returns these (WSL's and RAPID's), so they live apart from the entry points
//! that call the front-ends.

use crate::diag::Diagnostic;
use vworks_vm::Module;

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
