//! The RAPID front-end over a corpus of modules (`tests/rapid/corpus/`, and the folder
//! `VWORKS_RAPID_CORPUS` names, else the repository's other RAPID files): every file either compiles to a module that
//! round-trips through `.wslb`, or fails with diagnostics that each have a code and a
//! line — never a panic, never an internal error (E0900). Both are counted.

#![allow(clippy::panic, clippy::unwrap_used, clippy::expect_used)] // tests fail by panicking

use std::path::{Path, PathBuf};

use vworks_wslc::{Code, Language, compile_as};

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
