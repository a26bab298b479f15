//! The application layer as its callers use it: the one `until` rule, a run request on a
//! workcell file with overrides, the log written beside its path and renamed (never over
//! an input), and load errors typed with their stage. Files are written to a temporary
//! folder of the test's own.

#![allow(clippy::panic, clippy::unwrap_used, clippy::expect_used)] // tests fail by panicking

use std::path::{Path, PathBuf};
use std::sync::Arc;

use vworks_app::{
    CellSource, LogRequest, RunError, RunRequest, UNTIL_LIMIT_NS, UntilError, run, until_ns,
};
use vworks_cell::{CellError, Override, Stage};
use vworks_log::result::Outcome;

/// A fresh folder under the system's temporary folder, with these files.
fn folder(name: &str, files: &[(&str, &str)]) -> PathBuf {
    let d = std::env::temp_dir().join(format!("vworks-app-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    for (f, text) in files {
        std::fs::write(d.join(f), text).unwrap();
    }
    d
}

const CELL: &str = "[[robot]]\nname = \"r1\"\nmodel = \"irb120\"\nprogram = \"r1.wsl\"\n";
const PROGRAM: &str = "param wait = 1s;\nproc main() {\n    delay wait;\n}\n";

fn request(path: &Path) -> RunRequest<'_> {
    RunRequest {
        cell: CellSource::File {
            path,
            overrides: &[],
        },
        until_ns: None,
        log: None,
        stop: None,
    }
}

#[test]
fn until_is_a_time_from_zero() {
    assert_eq!(until_ns(0.0), Ok(0));
    assert_eq!(until_ns(2.5), Ok(2_500_000_000));
    assert_eq!(until_ns(-1.0), Err(UntilError::Negative));
    assert_eq!(until_ns(f64::NEG_INFINITY), Err(UntilError::Negative));
    assert_eq!(until_ns(f64::NAN), Err(UntilError::OutOfRange));
    assert_eq!(until_ns(f64::INFINITY), Err(UntilError::OutOfRange));
    assert_eq!(until_ns(1e300), Err(UntilError::OutOfRange));
    assert_eq!(until_ns(UNTIL_LIMIT_NS as f64 / 1e9), Ok(UNTIL_LIMIT_NS));
}

#[test]
fn until_zero_stops_at_the_start_and_overrides_apply() {
    let d = folder("until0", &[("cell.toml", CELL), ("r1.wsl", PROGRAM)]);
    let cell = d.join("cell.toml");
    let at_start = run(RunRequest {
        until_ns: Some(0),
        ..request(&cell)
    })
    .unwrap();
    assert_eq!(at_start.result.outcome, Outcome::Until);
    assert_eq!(at_start.result.end_time_ns, 0);
    // To the end: 1 s, or 2 s with the param set as `--set params.wait=2s` sets it.
    let whole = run(request(&cell)).unwrap();
    assert_eq!(
        (whole.result.outcome, whole.result.end_time_ns),
        (Outcome::Completed, 1_000_000_000)
    );
    let overrides = [Override::new("params.wait", "2s")];
    let set = run(RunRequest {
        cell: CellSource::File {
            path: &cell,
            overrides: &overrides,
        },
        ..request(&cell)
    })
    .unwrap();
    assert_eq!(set.result.end_time_ns, 2_000_000_000);
    // A loaded cell runs as its file does.
    let again = run(RunRequest {
        cell: CellSource::Loaded(Arc::clone(&whole.cell)),
        ..request(&cell)
    })
    .unwrap();
    assert_eq!(again.result.end_time_ns, whole.result.end_time_ns);
    let _ = std::fs::remove_dir_all(&d);
}

#[test]
fn the_log_is_renamed_into_place_and_never_written_over_an_input() {
    let d = folder("log", &[("cell.toml", CELL), ("r1.wsl", PROGRAM)]);
    let cell = d.join("cell.toml");
    let log = d.join("run.mcap");
    let out = run(RunRequest {
        log: Some(LogRequest {
            path: &log,
            every: 1,
        }),
        ..request(&cell)
    })
    .unwrap();
    assert_eq!(out.result.log_error, None);
    assert_eq!(out.log.as_deref(), Some(log.as_path()));
    assert!(std::fs::metadata(&log).unwrap().len() > 0);
    let mut names: Vec<String> = std::fs::read_dir(&d)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    assert_eq!(
        names,
        ["cell.toml", "r1.wsl", "run.mcap"],
        "no partial file left"
    );
    // The program as a log: refused before the run, the program unchanged.
    let program = d.join("r1.wsl");
    match run(RunRequest {
        log: Some(LogRequest {
            path: &program,
            every: 1,
        }),
        ..request(&cell)
    }) {
        Err(RunError::Log { message, .. }) => {
            assert!(message.contains("r1.wsl"), "{message}")
        }
        other => panic!("expected a log error, got {other:?}"),
    }
    assert_eq!(std::fs::read_to_string(&program).unwrap(), PROGRAM);
    let _ = std::fs::remove_dir_all(&d);
}

#[test]
fn program_errors_are_load_errors_with_their_stage() {
    let d = folder(
        "stage",
        &[
            ("cell.toml", CELL),
            ("r1.wsl", "proc main() {\n    delay 2;\n}\n"),
        ],
    );
    let cell = d.join("cell.toml");
    assert!(matches!(
        run(request(&cell)),
        Err(RunError::Load(CellError::Program {
            stage: Stage::Compile,
            ..
        }))
    ));
    std::fs::write(
        d.join("r1.wsl"),
        "proc main() {\n    parallel { remote r9.weld(); }\n}\n",
    )
    .unwrap();
    assert!(matches!(
        run(request(&cell)),
        Err(RunError::Load(CellError::Program {
            stage: Stage::Link,
            ..
        }))
    ));
    let _ = std::fs::remove_dir_all(&d);
}
