//! Every mistake a user can make, and what vworks answers: data-driven (as ruff's fixture
//! tests). Each `tests/errors/NAME.case` holds a command and the files it works on; the
//! expected exit code and output are in `NAME.out` beside it. `UPDATE_EXPECT=1 cargo test
//! -p vworks-cli --test errors` rewrites the `.out` files; review them in the diff.
//!
//! Every answer must name the file and place, say what is wrong and what to do; the test
//! below checks the parts a machine can check (an `error` line, the file named, exit 1).

#![allow(clippy::panic, clippy::unwrap_used, clippy::expect_used)] // tests fail by panicking

use std::path::{Path, PathBuf};
use std::process::Command;

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

struct Case {
    args: Vec<String>,
    files: Vec<(String, String)>,
}

fn parse(text: &str) -> Case {
    let mut args = Vec::new();
    let mut files: Vec<(String, String)> = Vec::new();
    for line in text.lines() {
        if let Some(cmd) = line.strip_prefix("$ vworks") {
            args = cmd.split_whitespace().map(str::to_string).collect();
        } else if let Some(path) = line.strip_prefix("--- ") {
            files.push((path.to_string(), String::new()));
        } else if let Some((_, body)) = files.last_mut() {
            body.push_str(line);
            body.push('\n');
        }
    }
    Case { args, files }
}

fn run(name: &str, case: &Case) -> (i32, String, String) {
    let dir = std::env::temp_dir().join(format!("vworks-errors-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    for (path, body) in &case.files {
        let p = dir.join(path);
        std::fs::create_dir_all(p.parent().unwrap()).unwrap();
        std::fs::write(p, body).unwrap();
    }
    let out = Command::new(env!("CARGO_BIN_EXE_vworks"))
        .args(&case.args)
        .current_dir(&dir)
        .env("NO_COLOR", "1")
        .output()
        .unwrap();
    let dir_text = dir.display().to_string();
    let clean = |b: &[u8]| String::from_utf8_lossy(b).replace(&dir_text, "$DIR");
    let _ = std::fs::remove_dir_all(&dir);
    (
        out.status.code().unwrap_or(-1),
        clean(&out.stdout),
        clean(&out.stderr),
    )
}

#[test]
fn every_bad_input_gets_an_answer_a_person_can_act_on() {
    let dir = root().join("tests/errors");
    let mut names: Vec<String> = std::fs::read_dir(&dir)
        .unwrap()
        .filter_map(|e| {
            let p = e.unwrap().path();
            if p.extension()? != "case" {
                return None;
            }
            Some(p.file_stem()?.to_string_lossy().into_owned())
        })
        .collect();
    names.sort();
    assert!(names.len() >= 30, "{} cases", names.len());
    for name in &names {
        let case = parse(&std::fs::read_to_string(dir.join(format!("{name}.case"))).unwrap());
        let (code, stdout, stderr) = run(name, &case);
        let mut got = format!("exit {code}\n--- stderr\n{stderr}");
        if !stdout.is_empty() {
            got.push_str("--- stdout\n");
            got.push_str(&stdout);
        }
        expect_test::expect_file![dir.join(format!("{name}.out"))].assert_eq(&got);
        // What a machine can check of "file, place, what, what to do".
        assert_ne!(code, 0, "{name}: a mistake must not exit 0");
        // A runtime error is the run's outcome: the summary on stdout reports it.
        assert!(
            stderr.contains("error") || stdout.contains("error["),
            "{name}: no error line in:\n{stderr}{stdout}"
        );
        assert!(!stderr.contains("panicked"), "{name}: panicked:\n{stderr}");
        // (An argument clap rejects is named by clap: no file to name.)
        let about_an_argument = stderr.contains("For more information, try '--help'.")
            || stderr.starts_with("error: --");
        let named = case.args.iter().filter(|a| a.contains('.'));
        let files = case.files.iter().map(|(f, _)| f);
        if case.args.iter().any(|a| a.contains('.')) && !about_an_argument {
            assert!(
                named
                    .chain(files)
                    .any(|f| stderr.contains(f.as_str()) || stdout.contains(f.as_str())),
                "{name}: the message names no file:\n{stderr}"
            );
        }
    }
}
