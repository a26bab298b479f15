//! Data-driven golden tests, in the style of rust-analyzer's and ruff's fixtures.
//!
//! Programs are WSL (`.wsl`) or ABB RAPID (`.mod`), compiled by the front-end their
//! extension names.
//!
//! - `test_data/ok/NAME.wsl` (or `.mod`) must compile; its disassembly (with the source beside it) is
//!   compared with `NAME.disasm`, and its `.wslb` encoding must decode to the same module.
//! - `test_data/err/NAME.wsl` (or `.mod`) must fail (or warn); the rendered diagnostics
//!   are compared with `NAME.stderr`. Each file's first line says which code it is about
//!   (`// E0021: …`, in RAPID `! E0300: …`) and that code must be among its diagnostics.
//! - `test_data/link/NAME/` holds modules and a `cell.txt`; the link diagnostics are
//!   compared with `expected.txt`.
//!
//! Together the `err` and `link` cases must exercise every diagnostic code.
//! Run with `UPDATE_EXPECT=1` to (re)write the expected files after a deliberate change.

#![allow(clippy::panic, clippy::unwrap_used, clippy::expect_used)] // tests fail by panicking

use std::collections::BTreeSet;
use std::path::{Path, PathBuf};

use expect_test::expect_file;
use vworks_vm::Module;
use vworks_vm::bytecode::disassemble;
use vworks_wslc::link::{CellSpec, RobotSpec, link};
use vworks_wslc::rapid::{IoSignal, SignalKind};
use vworks_wslc::{Code, Language, Sources, Stage, compile_as, render};

fn dir(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("test_data")
        .join(name)
}

/// The programs of a fixture directory, WSL and RAPID.
fn programs(name: &str) -> Vec<PathBuf> {
    let mut v = files(name, "wsl");
    v.extend(files(name, "mod"));
    v.sort();
    v
}

/// Compiles a fixture. A RAPID fixture with a `NAME.io` beside it is compiled with those
/// I/O signals (one per line: `name kind global init`), as a workcell's `[[io]]` gives.
fn compile(name: &str, src: &str) -> Result<vworks_wslc::Compiled, vworks_wslc::CompileError> {
    let io_file = dir("").join(name).with_extension("io");
    if Language::of_path(name) == Language::Rapid && io_file.exists() {
        let io: Vec<IoSignal> = read(&io_file)
            .lines()
            .filter(|l| !l.trim().is_empty())
            .map(|l| {
                let f: Vec<&str> = l.split_whitespace().collect();
                IoSignal {
                    name: f[0].to_string(),
                    kind: SignalKind::from_name(f[1]).unwrap(),
                    global: f[2].to_string(),
                    init: f[3].parse().unwrap(),
                }
            })
            .collect();
        return vworks_wslc::rapid::compile_with_io(name, src, Some(&io));
    }
    compile_as(Language::of_path(name), name, src)
}

fn files(name: &str, ext: &str) -> Vec<PathBuf> {
    let mut v: Vec<PathBuf> = std::fs::read_dir(dir(name))
        .unwrap_or_else(|e| panic!("{name}: {e}"))
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|x| x == ext))
        .collect();
    v.sort();
    v
}

fn read(p: &Path) -> String {
    std::fs::read_to_string(p).unwrap_or_else(|e| panic!("{}: {e}", p.display()))
}

fn rel(p: &Path) -> String {
    format!(
        "{}/{}",
        p.parent()
            .and_then(|d| d.file_name())
            .unwrap_or_default()
            .to_string_lossy(),
        p.file_name().unwrap_or_default().to_string_lossy()
    )
}

/// One test per fixture (named `ok/NAME.wsl`, `err/NAME.wsl`, `link/NAME`), so a failing
/// fixture names itself, as ruff's fixture tests do; and the tests that hold over all of
/// them: the folders are not emptied, and every diagnostic code has a fixture.
fn main() {
    use libtest_mimic::{Arguments, Failed, Trial};
    let args = Arguments::from_args();
    let ok = programs("ok");
    let err = programs("err");
    let link = link_case_dirs();
    let mut trials = Vec::new();
    for p in ok.clone() {
        trials.push(Trial::test(rel(&p), move || {
            ok_program_compiles_to_the_expected_bytecode(&p);
            Ok(())
        }));
    }
    for p in err.clone() {
        trials.push(Trial::test(rel(&p), move || {
            bad_program_gives_the_expected_diagnostics(&p);
            Ok(())
        }));
    }
    for case in link.clone() {
        trials.push(Trial::test(rel(&case), move || {
            link_case_gives_the_expected_diagnostics(&case);
            Ok(())
        }));
    }
    let ok_count = ok.len();
    trials.push(Trial::test(
        "the ok corpus holds at least 8 programs",
        move || {
            if ok_count >= 8 {
                Ok(())
            } else {
                Err(Failed::from(format!("ok/ holds {ok_count} programs")))
            }
        },
    ));
    trials.push(Trial::test(
        "every diagnostic code has a fixture",
        move || {
            let mut covered = BTreeSet::new();
            for p in &err {
                covered.extend(diagnostics_of(p).1);
            }
            for case in &link {
                covered.extend(
                    link_diagnostics(case)
                        .0
                        .iter()
                        .map(|d| d.code.as_str().to_string()),
                );
            }
            let missing: Vec<&str> = Code::ALL
                .iter()
                .map(|c| c.as_str())
                .filter(|c| *c != "E0900" && !covered.contains(*c))
                .collect();
            if missing.is_empty() {
                Ok(())
            } else {
                Err(Failed::from(format!("no golden test gives {missing:?}")))
            }
        },
    ));
    libtest_mimic::run(&args, trials).exit()
}

fn ok_program_compiles_to_the_expected_bytecode(p: &Path) {
    let src = read(p);
    let name = rel(p);
    let out = compile(&name, &src).unwrap_or_else(|e| {
        let mut s = Sources::new();
        s.add(&name, &src);
        panic!(
            "{name} should compile:\n{}",
            render(&e.diagnostics, &s, false)
        )
    });
    assert!(
        out.warnings.is_empty(),
        "{name} has warnings: {:?}",
        out.warnings
    );
    let listing = disassemble(&out.module, &[src.as_str()]);
    expect_file![p.with_extension("disasm")].assert_eq(&listing);
    // The binary form round-trips exactly.
    let back = Module::decode(&out.module.encode()).unwrap_or_else(|e| panic!("{name}: {e}"));
    assert_eq!(back, out.module, "{name}: encode/decode changed the module");
}

fn code_of_header(src: &str, name: &str) -> String {
    let first = src.lines().next().unwrap_or("");
    let code = first
        .trim_start_matches("//")
        .trim_start_matches('!')
        .trim()
        .split(':')
        .next()
        .unwrap_or("")
        .trim()
        .to_string();
    assert!(
        code.len() == 5 && (code.starts_with('E') || code.starts_with('W')),
        "{name}: the first line must be `// E0000: what this tests` (`! E0000: …` in RAPID)"
    );
    code
}

/// A bad program's diagnostics (its warnings if it compiles) and their codes.
fn diagnostics_of(p: &Path) -> (Vec<vworks_wslc::Diagnostic>, BTreeSet<String>) {
    let src = read(p);
    let name = rel(p);
    let diags = match compile(&name, &src) {
        Ok(out) => out.warnings,
        Err(e) => e.diagnostics,
    };
    let codes = diags.iter().map(|d| d.code.as_str().to_string()).collect();
    (diags, codes)
}

fn bad_program_gives_the_expected_diagnostics(p: &Path) {
    let src = read(p);
    let name = rel(p);
    let want = code_of_header(&src, &name);
    let (diags, codes) = diagnostics_of(p);
    assert!(!diags.is_empty(), "{name} should give diagnostics");
    assert!(
        diags.iter().all(|d| d.stage() == Stage::Compile),
        "{name}: a compiler diagnostic of the link stage"
    );
    assert!(
        codes.contains(&want),
        "{name} is about {want} but gave {codes:?}"
    );
    let mut s = Sources::new();
    s.add(&name, &src);
    expect_file![p.with_extension("stderr")].assert_eq(&render(&diags, &s, false));
}

/// The link cases' folders, sorted.
fn link_case_dirs() -> Vec<PathBuf> {
    let mut cases: Vec<PathBuf> = std::fs::read_dir(dir("link"))
        .unwrap_or_else(|e| panic!("link: {e}"))
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.is_dir())
        .collect();
    cases.sort();
    cases
}

fn link_case_gives_the_expected_diagnostics(case: &Path) {
    let (diags, sources) = link_diagnostics(case);
    assert!(
        diags.iter().all(|d| d.stage() == Stage::Link),
        "{case:?}: a link diagnostic of the compile stage"
    );
    expect_file![case.join("expected.txt")].assert_eq(&render(&diags, &sources, false));
}

/// Compiles a link case's modules and links its cell: the diagnostics and the sources
/// they point into.
fn link_diagnostics(case: &Path) -> (Vec<vworks_wslc::Diagnostic>, Sources) {
    {
        let cell_txt = read(&case.join("cell.txt"));
        let case_name = case
            .file_name()
            .unwrap_or_default()
            .to_string_lossy()
            .to_string();
        let mut sources = Sources::new();
        let mut modules: Vec<(String, Module)> = Vec::new();
        let mut robots = Vec::new();
        let mut parts = Vec::new();
        for line in cell_txt
            .lines()
            .filter(|l| !l.trim().is_empty() && !l.starts_with('#'))
        {
            let w: Vec<&str> = line.split_whitespace().collect();
            match w[0] {
                "robot" => {
                    let file = w[2].to_string();
                    if !modules.iter().any(|(f, _)| *f == file) {
                        let name = format!("{case_name}/{file}");
                        let src = read(&case.join(&file));
                        sources.add(&name, &src);
                        let m = compile(&name, &src)
                            .unwrap_or_else(|e| panic!("{name}: {e}"))
                            .module;
                        modules.push((file.clone(), m));
                    }
                    let axes: usize = w[3].parse().unwrap_or_else(|_| panic!("{case_name}: axes"));
                    let linear = w
                        .iter()
                        .find_map(|x| x.strip_prefix("linear="))
                        .map_or(0, |x| x.parse().unwrap_or(0));
                    let entry = w.iter().find_map(|x| x.strip_prefix("entry="));
                    robots.push((
                        w[1].to_string(),
                        file,
                        axes,
                        linear,
                        entry.map(str::to_string),
                        w.contains(&"serve_only"),
                    ));
                }
                "part" => parts.push(w[1].to_string()),
                other => panic!("{case_name}/cell.txt: unknown line kind {other}"),
            }
        }
        let cell = CellSpec {
            robots: robots
                .iter()
                .map(|(n, f, axes, linear, entry, serve)| RobotSpec {
                    name: n,
                    task: n,
                    module: &modules
                        .iter()
                        .find(|(mf, _)| mf == f)
                        .unwrap_or_else(|| panic!("{case_name}: module {f}"))
                        .1,
                    axes: *axes,
                    linear_axes: *linear,
                    entry: entry.as_deref(),
                    serve_only: *serve,
                })
                .collect(),
            parts: parts.iter().map(String::as_str).collect(),
        };
        let diags = match link(&cell) {
            Ok(l) => l.warnings,
            Err(e) => e.diagnostics,
        };
        (diags, sources)
    }
}
