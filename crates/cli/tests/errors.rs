//! Every mistake a user can make, and what vworks answers: data-driven (as ruff's fixture
//! tests). Each `tests/errors/NAME.case` holds a command and the files it works on; the
//! expected exit code and output are in `NAME.out` beside it. `UPDATE_EXPECT=1 cargo test
//! -p vworks-cli --test errors` rewrites the `.out` files; review them in the diff.
//!
//! Every answer must name the file and place, say what is wrong and what to do; the test
//! below checks the parts a machine can check (an `error` line, the file named, exit 1).

#![allow(clippy::panic, clippy::unwrap_used, clippy::expect_used)] // tests fail by panicking

mod common;
use std::path::Path;

use common::{mask_speed, parse, run, test_every_case};

fn main() {
    test_every_case(
        "tests/errors",
        30,
        every_bad_input_gets_an_answer_a_person_can_act_on,
    )
}

fn every_bad_input_gets_an_answer_a_person_can_act_on(dir: &Path, name: &str) {
    let case = parse(&std::fs::read_to_string(dir.join(format!("{name}.case"))).unwrap());
    let (code, stdout, stderr) = run(name, &case);
    let (stdout, stderr) = (mask_speed(&stdout), mask_speed(&stderr));
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
    let about_an_argument =
        stderr.contains("For more information, try '--help'.") || stderr.starts_with("error: --");
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
