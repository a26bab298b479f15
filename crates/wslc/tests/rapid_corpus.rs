//! The RAPID front-end over a corpus of modules (`tests/rapid/corpus/`, and the folder
//! `VWORKS_RAPID_CORPUS` names, else the repository's other RAPID files): every file either compiles to a module that
//! round-trips through `.wslb`, or fails with diagnostics that each have a code and a
//! line — never a panic, never an internal error (E0900). Both are counted.

#![allow(clippy::panic, clippy::unwrap_used, clippy::expect_used)] // tests fail by panicking

use std::path::{Path, PathBuf};

use vworks_wslc::{Code, Diagnostic, Language, compile_as};

/// (compiled, failed with clear diagnostics) over the RAPID files of `dir`.
fn run_corpus(dir: &Path) -> (Vec<String>, Vec<(String, Vec<String>)>) {
    let mut files: Vec<PathBuf> = std::fs::read_dir(dir)
        .unwrap_or_else(|e| panic!("{}: {e}", dir.display()))
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| Language::of_path(&p.display().to_string()) == Language::Rapid)
        .collect();
    files.sort();
    let (mut ok, mut failed) = (Vec::new(), Vec::new());
    for p in files {
        let name = p.file_name().unwrap().to_string_lossy().into_owned();
        let bytes = std::fs::read(&p).unwrap();
        // Public modules come in Latin-1 too: read as vworks reads RAPID files.
        let text = vworks_wslc::source_text_of(&name, bytes).unwrap();
        let result = std::panic::catch_unwind(|| compile_as(Language::Rapid, &name, &text));
        match result {
            Err(_) => panic!("{name}: the RAPID front-end panicked"),
            Ok(Ok(out)) => {
                let back = vworks_vm::Module::decode(&out.module.encode())
                    .unwrap_or_else(|e| panic!("{name}: {e}"));
                assert_eq!(back, out.module, "{name}: .wslb round trip");
                ok.push(name);
            }
            Ok(Err(e)) => {
                assert!(
                    !e.diagnostics.is_empty(),
                    "{name}: failed without a diagnostic"
                );
                for d in &e.diagnostics {
                    assert_ne!(d.code, Code::E0900, "{name}: internal error {}", d.short());
                    assert!(d.at.line > 0 && !d.message.is_empty(), "{name}: {d:?}");
                }
                let mut codes: Vec<String> = e
                    .diagnostics
                    .iter()
                    .filter(|d| d.is_error())
                    .map(|d| d.code.to_string())
                    .collect();
                codes.sort();
                codes.dedup();
                failed.push((name, codes));
            }
        }
    }
    (ok, failed)
}

#[test]
fn the_bundled_corpus_compiles_or_names_what_vworks_does_not_run() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../tests/rapid/corpus");
    let (ok, failed) = run_corpus(&dir);
    eprintln!(
        "bundled corpus: {} compile, {} fail: {failed:?}",
        ok.len(),
        failed.len()
    );
    // Five modules compile; `unsupported.mod` is every construct vworks does not run.
    assert_eq!(ok.len(), 5, "{ok:?} {failed:?}");
    assert_eq!(failed.len(), 1, "{failed:?}");
    assert_eq!(failed[0].0, "unsupported.mod");
    assert_eq!(failed[0].1, vec!["E0300".to_string()]);
}

/// `VWORKS_RAPID_CORPUS=DIR cargo test -p vworks-wslc --test rapid_corpus -- --nocapture`
/// runs the same checks over the modules of `DIR` and prints the counts and the codes of
/// each file that does not compile. Without it, the checks run over the repository's other
/// RAPID files, whose outcomes are known: the example workcell's two tasks and the
/// compiler's `ok` fixtures compile; each `err` fixture fails with the code its name starts
/// with (but one that needs the workcell's I/O wiring to fail).
#[test]
fn an_external_corpus_if_given_else_the_repositorys_other_rapid_files() {
    if let Some(dir) = std::env::var_os("VWORKS_RAPID_CORPUS") {
        let (ok, failed) = run_corpus(Path::new(&dir));
        eprintln!(
            "external corpus: {} compile, {} fail",
            ok.len(),
            failed.len()
        );
        for (name, codes) in &failed {
            eprintln!("  {name}: {}", codes.join(", "));
        }
        return;
    }
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let (ok, failed) = run_corpus(&root.join("../../workcells/rapid_handoff"));
    assert_eq!(
        (ok, failed),
        (vec!["r1.mod".to_string(), "r2.mod".to_string()], vec![])
    );
    let (ok, failed) = run_corpus(&root.join("test_data/ok"));
    assert_eq!(ok, vec!["rapid_flow.mod", "rapid_motions.mod"]);
    assert!(failed.is_empty(), "{failed:?}");
    // A fixture with a `.io` file beside it fails only against that wiring of the workcell
    // (E0302: a signal the cell does not give): on its own it compiles.
    let err = root.join("test_data/err");
    let (ok, failed) = run_corpus(&err);
    for name in &ok {
        assert!(
            err.join(name).with_extension("io").exists(),
            "{name} compiled"
        );
    }
    assert_eq!(ok, vec!["E0302_rapid_signal.mod"]);
    assert_eq!(failed.len(), 9, "{failed:?}");
    for (name, codes) in &failed {
        let code = &name[..5];
        assert!(codes.iter().any(|c| c == code), "{name}: {codes:?}");
    }
}

/// How a task (or a file in it) fares: it compiles; it fails only with E0300 for what is
/// out of scope (sockets, files, EGM, the process options, …); or something else.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
enum Outcome {
    Compiles,
    OutOfScope,
    Other,
}

fn out_of_scope(d: &Diagnostic) -> bool {
    d.code == Code::E0300 && d.message.contains("which vworks does not simulate")
}

/// The tasks of a `tasks.tsv` (a header, then `id<TAB>paths` with paths relative to
/// `root`, separated by spaces, `%20` for a space in one): each task's outcome, and each
/// file's (from the errors in it).
/// A task's id, its outcome, and the first of its errors that are not out of scope.
type TaskRow = (String, Outcome, Vec<String>);

fn run_tasks(root: &Path) -> (Vec<TaskRow>, Vec<Outcome>) {
    let list = std::fs::read_to_string(root.join("tasks.tsv"))
        .unwrap_or_else(|e| panic!("{}: {e}", root.display()));
    let (mut tasks, mut files_out) = (Vec::new(), Vec::new());
    for line in list.lines().skip(1) {
        let Some((id, paths)) = line.split_once('\t') else {
            continue;
        };
        let paths: Vec<String> = paths
            .split(' ')
            .map(|p| p.replace("%20", " ").replace("%25", "%"))
            .collect();
        let texts: Vec<(String, String)> = paths
            .iter()
            .map(|p| {
                let bytes = std::fs::read(root.join(p)).unwrap_or_else(|e| panic!("{p}: {e}"));
                (p.clone(), vworks_wslc::source_text_of(p, bytes).unwrap())
            })
            .collect();
        let refs: Vec<(&str, &str)> = texts
            .iter()
            .map(|(p, t)| (p.as_str(), t.as_str()))
            .collect();
        let result = std::panic::catch_unwind(|| vworks_wslc::rapid::compile_files(&refs, None));
        let errors: Vec<Diagnostic> = match result {
            Err(_) => panic!("{id}: the RAPID front-end panicked"),
            Ok(Ok(_)) => Vec::new(),
            Ok(Err(e)) => e.diagnostics.into_iter().filter(|d| d.is_error()).collect(),
        };
        for d in &errors {
            assert_ne!(d.code, Code::E0900, "{id}: internal error {}", d.short());
        }
        let outcome = |es: &[&Diagnostic]| {
            if es.is_empty() {
                Outcome::Compiles
            } else if es.iter().all(|d| out_of_scope(d)) {
                Outcome::OutOfScope
            } else {
                Outcome::Other
            }
        };
        let all: Vec<&Diagnostic> = errors.iter().collect();
        for p in &paths {
            let mine: Vec<&Diagnostic> = errors.iter().filter(|d| d.at.file == *p).collect();
            files_out.push(outcome(&mine));
        }
        let mut first: Vec<String> = errors
            .iter()
            .filter(|d| !out_of_scope(d))
            .map(|d| format!("{} {}", d.code, d.message))
            .collect();
        first.dedup();
        first.truncate(3);
        tasks.push((id.to_string(), outcome(&all), first));
    }
    (tasks, files_out)
}

fn count(o: &[Outcome], which: Outcome) -> usize {
    o.iter().filter(|x| **x == which).count()
}

/// The public RAPID vendored in `tests/rapid/public/` (see its README for the sources and
/// licences): by task and by file, how many compile, fail only with out-of-scope E0300s,
/// or fail otherwise. The counts are what this front-end measures today (a test that
/// fails when one changes, so a change is seen and the numbers in docs/rapid.md kept).
#[test]
fn the_public_corpus_by_task_and_file() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../tests/rapid/public");
    let (tasks, files) = run_tasks(&root);
    let outcomes: Vec<Outcome> = tasks.iter().map(|t| t.1).collect();
    for (id, o, first) in &tasks {
        eprintln!("{o:?} {id}: {}", first.join(" | "));
    }
    let got = (
        count(&outcomes, Outcome::Compiles),
        count(&outcomes, Outcome::OutOfScope),
        count(&outcomes, Outcome::Other),
        count(&files, Outcome::Compiles),
        count(&files, Outcome::OutOfScope),
        count(&files, Outcome::Other),
    );
    eprintln!("public corpus: tasks (compile, out of scope, other) and files: {got:?}");
    assert_eq!(tasks.len(), 14);
    assert_eq!(files.len(), 25);
    assert_eq!(got, MEASURED_PUBLIC);
}

/// (tasks compiled, out of scope only, other; files the same), measured.
const MEASURED_PUBLIC: (usize, usize, usize, usize, usize, usize) = (0, 0, 14, 2, 1, 22);

/// `VWORKS_RAPID_TASKS=DIR` (a folder with a `tasks.tsv`, as `tests/rapid/public/` has):
/// the same counts over it, printed.
#[test]
fn an_external_corpus_by_task_if_given() {
    let Some(dir) = std::env::var_os("VWORKS_RAPID_TASKS") else {
        return;
    };
    let (tasks, files) = run_tasks(Path::new(&dir));
    let outcomes: Vec<Outcome> = tasks.iter().map(|t| t.1).collect();
    for (id, o, first) in &tasks {
        if *o == Outcome::Other {
            eprintln!("{id}: {}", first.join(" | "));
        }
    }
    for (what, o) in [("tasks", &outcomes), ("files", &files)] {
        eprintln!(
            "{what}: {} in all, {} compile, {} only out of scope, {} other",
            o.len(),
            count(o, Outcome::Compiles),
            count(o, Outcome::OutOfScope),
            count(o, Outcome::Other)
        );
    }
}
