//! Programs from Python: `compile` and `compile_files` → `Module`, and the
//! `Diagnostic`s a program that does not compile or link raises with.

use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::PyList;
use vworks_wslc::Diagnostic as WslDiagnostic;

use crate::errors::{CompileError, LinkError};

/// One compiler or linker diagnostic.
#[pyclass(frozen, module = "vworks", get_all)]
#[derive(Clone)]
pub(crate) struct Diagnostic {
    /// Stable code, e.g. `E0012` or `W0003`.
    code: String,
    /// `error` or `warning`.
    severity: String,
    /// What is wrong, in a sentence.
    message: String,
    /// The file.
    file: String,
    /// 1-based line (0 if unknown).
    line: u32,
    /// 1-based column (0 if unknown).
    col: u32,
    /// What to do about it, if known.
    help: Option<String>,
    /// The diagnostic rendered with its source line and a caret, as `vworks check` prints it.
    rendered: String,
}

#[pymethods]
impl Diagnostic {
    fn __repr__(&self) -> String {
        format!(
            "<Diagnostic {} {}:{}:{}: {}>",
            self.code, self.file, self.line, self.col, self.message
        )
    }

    fn __str__(&self) -> String {
        self.rendered.clone()
    }
}

pub(crate) fn diagnostic(d: &WslDiagnostic, sources: &vworks_wslc::Sources) -> Diagnostic {
    Diagnostic {
        code: d.code.as_str().to_string(),
        severity: if d.is_error() { "error" } else { "warning" }.to_string(),
        message: d.message.clone(),
        file: d.at.file.clone(),
        line: d.at.line,
        col: d.at.col,
        help: d.help.clone(),
        rendered: vworks_wslc::render(std::slice::from_ref(d), sources, false),
    }
}

/// A `CompileError`/`LinkError` carrying `.diagnostics`.
pub(crate) fn program_error(
    py: Python<'_>,
    link: bool,
    message: String,
    diagnostics: Vec<Diagnostic>,
) -> PyErr {
    let err = if link {
        LinkError::new_err(message)
    } else {
        CompileError::new_err(message)
    };
    let set =
        PyList::new(py, diagnostics).and_then(|list| err.value(py).setattr("diagnostics", list));
    match set {
        Ok(()) => err,
        Err(e) => e,
    }
}

/// A compiled WSL module.
#[pyclass(frozen, module = "vworks")]
pub(crate) struct Module {
    module: vworks_vm::Module,
    /// The text of each of its files, in order.
    sources: Vec<String>,
    warnings: Vec<Diagnostic>,
}

#[pymethods]
impl Module {
    /// The file name given to `compile` (the first file's, for `compile_files`).
    #[getter]
    fn path(&self) -> String {
        self.module.source_path().to_string()
    }

    /// Every source file's name, in order (one for `compile`).
    #[getter]
    fn files(&self) -> Vec<String> {
        self.module.files.clone()
    }

    /// The module's globals, by name, in declaration order.
    #[getter]
    fn globals(&self) -> Vec<String> {
        let m = &self.module;
        m.globals
            .iter()
            .map(|g| m.str(g.name).to_string())
            .collect()
    }

    /// The module's procedures (`proc`) and functions (`func`), by name, in order.
    #[getter]
    fn procs(&self) -> Vec<String> {
        use vworks_vm::bytecode::ProcKind;
        let m = &self.module;
        m.procs
            .iter()
            .filter(|p| matches!(p.kind, ProcKind::Proc | ProcKind::Func))
            .map(|p| m.str(p.name).to_string())
            .collect()
    }

    /// The compiler's warnings (`Diagnostic`s; errors raise `CompileError` instead).
    #[getter]
    fn warnings(&self) -> Vec<Diagnostic> {
        self.warnings.clone()
    }

    /// The bytecode, one instruction per line, with the source line beside it (as
    /// `vworks disasm`).
    fn disasm(&self) -> String {
        let texts: Vec<&str> = self.sources.iter().map(String::as_str).collect();
        vworks_vm::bytecode::disassemble(&self.module, &texts)
    }

    /// The encoded bytecode (`.wslb`), as `vworks build` writes it.
    fn to_bytes(&self) -> Vec<u8> {
        self.module.encode()
    }

    fn __repr__(&self) -> String {
        format!("<Module {}>", self.module.source_path())
    }
}

/// The language named `language` (`"wsl"` or `"rapid"`, any case), else by the
/// extensions of `paths` (all of one language), else WSL.
fn language_of(language: Option<&str>, paths: &[&str]) -> PyResult<vworks_wslc::Language> {
    match language {
        None => {
            vworks_wslc::Language::of_files(paths).map_err(|(_, why)| PyValueError::new_err(why))
        }
        Some(name) => vworks_wslc::Language::from_name(name).map_err(PyValueError::new_err),
    }
}

/// Compiles `source`, WSL or ABB RAPID; `path` names the file in diagnostics. The
/// language is `language` (`"wsl"` or `"rapid"`), or else `path`'s extension decides
/// (`.mod`, `.modx`, `.sys`, `.sysx`, `.prg` are RAPID). Raises `CompileError` (with
/// `.diagnostics`) if it does not compile, `ValueError` for an unknown language.
#[pyfunction]
#[pyo3(signature = (source, path = None, language = None))]
pub(crate) fn compile(
    py: Python<'_>,
    source: &str,
    path: Option<&str>,
    language: Option<&str>,
) -> PyResult<Module> {
    let lang = language_of(language, path.as_slice())?;
    let path = path.unwrap_or(lang.default_path());
    compile_program(py, lang, &[(path.to_string(), source.to_string())])
}

/// Compiles one program of several files, `files` as (path, text) in order: a RAPID
/// task's modules, or a WSL program and its library files. The language is `language`,
/// or else the paths' extensions. Raises `CompileError` (with `.diagnostics`, each naming
/// its file) if it does not compile, `ValueError` for an unknown language, files of two
/// languages without `language`, or no files.
#[pyfunction]
#[pyo3(signature = (files, language = None))]
pub(crate) fn compile_files(
    py: Python<'_>,
    files: Vec<(String, String)>,
    language: Option<&str>,
) -> PyResult<Module> {
    if files.is_empty() {
        return Err(PyValueError::new_err(
            "compile_files needs at least one (path, text) pair",
        ));
    }
    let paths: Vec<&str> = files.iter().map(|(p, _)| p.as_str()).collect();
    let lang = language_of(language, &paths)?;
    compile_program(py, lang, &files)
}

fn compile_program(
    py: Python<'_>,
    lang: vworks_wslc::Language,
    files: &[(String, String)],
) -> PyResult<Module> {
    let mut sources = vworks_wslc::Sources::new();
    for (path, text) in files {
        sources.add(path, text);
    }
    let refs: Vec<(&str, &str)> = files
        .iter()
        .map(|(p, t)| (p.as_str(), t.as_str()))
        .collect();
    match vworks_wslc::compile_program(lang, &refs, None) {
        Ok(c) => Ok(Module {
            warnings: c.warnings.iter().map(|d| diagnostic(d, &sources)).collect(),
            module: c.module,
            sources: files.iter().map(|(_, t)| t.clone()).collect(),
        }),
        Err(e) => {
            let diags: Vec<Diagnostic> = e
                .diagnostics
                .iter()
                .map(|d| diagnostic(d, &sources))
                .collect();
            let message = vworks_wslc::render(&e.diagnostics, &sources, false);
            Err(program_error(py, false, message, diags))
        }
    }
}
