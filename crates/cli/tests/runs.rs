//! Whole runs of small cells, and what vworks answers: data-driven, like `errors.rs`.
//! Each `tests/runs/NAME.case` holds a command (usually `vworks run cell.toml --trace-ns`, the trace in integer nanoseconds)
//! and the files it works on; the expected exit code and output are in `NAME.out` beside
//! it (`UPDATE_EXPECT=1 cargo test -p vworks-cli --test runs` rewrites them; review them in
//! the diff).
//!
//! The expected times were computed by hand from docs/language.md before the first run:
//! each case says so in its `# expect: TEXT` lines, which the output must contain, and its
//! `# expect-not: TEXT` lines, which it must not (the
//! `.out` file alone would only say what vworks did, not what it should do). The speed
//! of the run (`Nx real time`) is masked.

#![allow(clippy::panic, clippy::unwrap_used, clippy::expect_used)] // tests fail by panicking

mod common;
use std::path::Path;

use common::{mask_speed, parse, run, test_every_case};

fn main() {
    test_every_case(
        "tests/runs",
        10,
        runs_give_the_times_and_outcomes_the_language_reference_promises,
    )
}

fn runs_give_the_times_and_outcomes_the_language_reference_promises(dir: &Path, name: &str) {
    let text = std::fs::read_to_string(dir.join(format!("{name}.case"))).unwrap();
    let case = parse(&text);
    let (code, stdout, stderr) = run(name, &case);
    let (stdout, stderr) = (mask_speed(&stdout), mask_speed(&stderr));
    let mut got = format!("exit {code}\n");
    if !stderr.is_empty() {
        got.push_str("--- stderr\n");
        got.push_str(&stderr);
    }
    if !stdout.is_empty() {
        got.push_str("--- stdout\n");
        got.push_str(&stdout);
    }
    assert!(!stderr.contains("panicked"), "{name}: panicked:\n{stderr}");
    let expects: Vec<&str> = text
        .lines()
        .take_while(|l| !l.starts_with("$ vworks"))
        .filter_map(|l| l.strip_prefix("# expect: "))
        .collect();
    assert!(!expects.is_empty(), "{name}: no `# expect:` line");
    for e in expects {
        assert!(
            got.contains(e),
            "{name}: expected (by hand) `{e}` in:\n{got}"
        );
    }
    let header = text.lines().take_while(|l| !l.starts_with("$ vworks"));
    for e in header.filter_map(|l| l.strip_prefix("# expect-not: ")) {
        assert!(
            !got.contains(e),
            "{name}: expected (by hand) no `{e}` in:\n{got}"
        );
    }
    expect_test::expect_file![dir.join(format!("{name}.out"))].assert_eq(&got);
}
