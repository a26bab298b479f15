//! `wslc`, the WSL compiler.
//!
//! WSL is the workcell simulation language of vworks (see `docs/language.md`). One `.wsl`
//! file is one module; [`compile`] turns its text into a verified
//! [`vworks_vm::Module`] of bytecode, or into every problem it found, each with a stable
//! code and a `file:line:col` position. [`link`] checks a set of modules against a workcell
//! (robots, axis counts, parts) before a simulation starts.
//!
//! [`Language`] says which language a file is in, and [`compile_program`] compiles a
//! program's files with that language's front-end (WSL, or [`rapid`]); the front-ends'
//! parsers share one kit (`frontend`: the token cursor, reporting, recovery, the nesting
//! limit, a program's files joined).
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
mod frontend;
mod language;
pub mod lexer;
pub mod link;
mod lower;
mod output;
pub mod parser;
pub mod rapid;
mod suggest;
pub mod syntax;
pub mod units;

use frontend::program::ProgramText;

pub use diag::{Code, Diagnostic, Severity, Sources, Stage, render};
pub use language::Language;
pub use output::{CompileError, Compiled};
pub use suggest::nearest;

/// Every built-in function as (name, signature, result), in the order of
/// docs/language.md's table: for editors, completions and documentation tools.
pub fn builtin_functions() -> impl Iterator<Item = (&'static str, &'static str, &'static str)> {
    lower::BUILTINS
        .iter()
        .map(|b| (b.name, b.signature, b.returns))
}
pub use vworks_vm::Module;

/// A program file's bytes that are not UTF-8 text: where the first bad byte is.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("line {line}, column {col}: byte 0x{byte:02X} is not UTF-8 text; save the file as UTF-8")]
pub struct NotUtf8 {
    /// 1-based line of the byte.
    pub line: u32,
    /// 1-based column (in characters) of the byte.
    pub col: u32,
    /// The byte.
    pub byte: u8,
}

/// A program file's text from its bytes: UTF-8, without a leading byte-order mark.
pub fn source_text(bytes: Vec<u8>) -> Result<String, NotUtf8> {
    let text = match String::from_utf8(bytes) {
        Ok(t) => t,
        Err(e) => {
            let bytes = e.as_bytes();
            let at = e.utf8_error().valid_up_to();
            // The part before the bad byte is valid: count its lines and characters.
            let before = std::str::from_utf8(&bytes[..at]).unwrap_or_default();
            let line_start = before.rfind('\n').map_or(0, |i| i + 1);
            return Err(NotUtf8 {
                line: before.matches('\n').count() as u32 + 1,
                col: before[line_start..].chars().count() as u32 + 1,
                byte: bytes[at],
            });
        }
    };
    Ok(match text.strip_prefix('\u{feff}') {
        Some(rest) => rest.to_string(),
        None => text,
    })
}

/// A program file's text from its bytes, as its language's files are written: UTF-8
/// (without a leading byte-order mark) for every language; a RAPID file that is not UTF-8
/// is Latin-1 (ISO-8859-1: what controllers and RobotStudio write, accented comments and
/// all), each byte one character, so every line and column is the file's own. A WSL file
/// that is not UTF-8 is an error ([`source_text`]).
pub fn source_text_in(language: Language, bytes: Vec<u8>) -> Result<String, NotUtf8> {
    match (language, std::str::from_utf8(&bytes).is_ok()) {
        (Language::Rapid, false) => Ok(bytes.iter().map(|b| char::from(*b)).collect()),
        _ => source_text(bytes),
    }
}

/// [`source_text_in`] the language of the file `path` names (by its extension: WSL for
/// any other).
pub fn source_text_of(path: &str, bytes: Vec<u8>) -> Result<String, NotUtf8> {
    source_text_in(Language::of_path(path), bytes)
}

/// Compiles one module. `path` names the file in diagnostics and in the module.
pub fn compile(path: &str, source: &str) -> Result<Compiled, CompileError> {
    compile_files(&[(path, source)])
}

/// Compiles a WSL program of several files ((path, text), in order) into one module, as
/// if their declarations were written one after another in one file: a robot's main
/// file with the library files it uses. Each file is lexed and parsed on its own;
/// positions and diagnostics name their own file.
pub fn compile_files(files: &[(&str, &str)]) -> Result<Compiled, CompileError> {
    let program = ProgramText::new(files);
    let mut diags = Vec::new();
    let mut ast = syntax::SourceModule {
        items: Vec::new(),
        texts: false,
    };
    for (_, file) in program.parse_each(&mut diags, lexer::lex, parser::parse) {
        ast.items.extend(file.items);
    }
    let syntax_ok = !diags.iter().any(Diagnostic::is_error);
    lower::finish(&program, syntax_ok.then_some(&ast), diags)
}

/// Compiles a program in the given language.
pub fn compile_as(language: Language, path: &str, source: &str) -> Result<Compiled, CompileError> {
    compile_program(language, &[(path, source)], None)
}

/// Compiles a program of several files ((path, text), in order) in `language`: the one
/// entry point that picks the front-end. A RAPID task's modules go to
/// [`rapid::compile_files`] with the robot's I/O signals `io` (`None`: any signal by
/// name); a WSL program's files to [`compile_files`] (WSL has no I/O signals: `io` is not
/// read).
pub fn compile_program(
    language: Language,
    files: &[(&str, &str)],
    io: Option<&[rapid::IoSignal]>,
) -> Result<Compiled, CompileError> {
    match language {
        Language::Wsl => compile_files(files),
        Language::Rapid => rapid::compile_files(files, io),
    }
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]

    use super::*;

    /// A RAPID file that is not UTF-8 is Latin-1, one character per byte (every byte
    /// from 0x80 to 0xFF is the code point of the same number); UTF-8 stays UTF-8 (its
    /// "é" is one character, not two); a WSL file that is not UTF-8 is the error it was.
    #[test]
    fn rapid_files_that_are_not_utf8_are_latin1() {
        let latin1: Vec<u8> = b"! caf\xe9 \xff\x80".to_vec();
        let text = source_text_of("a/M.MOD", latin1.clone()).unwrap();
        assert_eq!(text, "! caf\u{e9} \u{ff}\u{80}");
        assert_eq!(text.chars().count(), latin1.len());
        assert_eq!(
            source_text_of("m.mod", "! café".as_bytes().to_vec()).unwrap(),
            "! café"
        );
        let err = source_text_of("p.wsl", latin1).unwrap_err();
        assert_eq!((err.line, err.col, err.byte), (1, 6, 0xE9));
    }
}
