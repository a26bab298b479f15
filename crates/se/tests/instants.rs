//! One instant, one serial order (docs/engine.md): random programs of `=`, `+=` and `-=`
//! on shared globals, with delays that put several robots at the same instants, give the
//! trace of the robots run one after the other in turn order. Every `set` writes what the
//! robot's statement computes from the globals as the sets before it in the trace left
//! them (no update is lost), the final globals are those of that serial run, and a robot's
//! events at an instant are consecutive (no other robot's code runs inside its turn).

#![allow(clippy::panic, clippy::unwrap_used, clippy::expect_used)] // tests fail by panicking

use std::path::Path;
use std::sync::Arc;

use proptest::prelude::*;
use vworks_cell::{MemoryFiles, load_with};
use vworks_log::result::Outcome;
use vworks_log::trace::Kind;
use vworks_se::CellNames;
use vworks_se::Simulation;

const GLOBALS: [&str; 2] = ["a", "b"];

/// One statement of a generated program.
#[derive(Clone, Debug)]
enum Step {
    /// `delay N ms;` (0, 10 or 20: robots meet at the same instants).
    Delay(u32),
    /// `g = other + c;` (reads the other global).
    Assign(usize, i64),
    /// `g += c;`
    Add(usize, i64),
    /// `g -= c;`
    Sub(usize, i64),
}

impl Step {
    fn wsl(&self) -> String {
        match self {
            Step::Delay(ms) => format!("delay {ms}ms;"),
            Step::Assign(g, c) => format!("{} = {} + {c};", GLOBALS[*g], GLOBALS[1 - g]),
            Step::Add(g, c) => format!("{} += {c};", GLOBALS[*g]),
            Step::Sub(g, c) => format!("{} -= {c};", GLOBALS[*g]),
        }
    }

    /// The global it sets and the value it writes, from the globals as they are.
    fn apply(&self, globals: &[i64; 2]) -> Option<(usize, i64)> {
        match *self {
            Step::Delay(_) => None,
            Step::Assign(g, c) => Some((g, globals[1 - g] + c)),
            Step::Add(g, c) => Some((g, globals[g] + c)),
            Step::Sub(g, c) => Some((g, globals[g] - c)),
        }
    }
}

fn step() -> impl Strategy<Value = Step> {
    prop_oneof![
        prop_oneof![Just(0u32), Just(10), Just(20)].prop_map(Step::Delay),
        (0..2usize, -5i64..6).prop_map(|(g, c)| Step::Assign(g, c)),
        (0..2usize, 1i64..6).prop_map(|(g, c)| Step::Add(g, c)),
        (0..2usize, 1i64..6).prop_map(|(g, c)| Step::Sub(g, c)),
    ]
}

fn run_and_check(programs: &[Vec<Step>]) {
    let mut files = MemoryFiles::default();
    let mut toml = String::from("name = \"instants\"\n");
    for (i, steps) in programs.iter().enumerate() {
        toml.push_str(&format!(
            "[[robot]]\nname = \"r{i}\"\nmodel = \"turntable\"\nprogram = \"r{i}.wsl\"\nbase = {{ xyz = [\"{}m\", \"0m\", \"0m\"] }}\n",
            2 * i
        ));
        let body: Vec<String> = steps.iter().map(|s| format!("    {}", s.wsl())).collect();
        files.insert(
            format!("/c/r{i}.wsl"),
            format!(
                "global a = 0;\nglobal b = 0;\nproc main() {{\n{}\n}}\n",
                body.join("\n")
            ),
        );
    }
    files.insert("/c/cell.toml", toml);
    let cell = Arc::new(load_with(Path::new("/c/cell.toml"), &files).unwrap());
    let r = Simulation::new(Arc::clone(&cell)).run(None);
    assert_eq!(r.outcome, Outcome::Completed, "{:?}", r.errors);

    // Replay the trace as one serial run: each robot's next statement that sets.
    let mut globals = [0i64; 2];
    let mut next: Vec<usize> = vec![0; programs.len()];
    // The robots that have had their turn at the current instant, and whose turn it is.
    let (mut instant, mut done, mut current) = (-1i64, vec![false; programs.len()], None);
    for e in &r.trace {
        let Some(robot) = e.robot else { continue };
        if matches!(
            e.kind,
            Kind::CheckWait | Kind::CheckWhen | Kind::Warning | Kind::Log
        ) {
            continue;
        }
        if e.time != instant {
            instant = e.time;
            done.iter_mut().for_each(|d| *d = false);
            current = None;
        }
        if current != Some(robot) {
            if let Some(c) = current {
                done[c] = true;
            }
            assert!(
                !done[robot],
                "r{robot} acts again at {instant} ns after another robot's turn:\n{}",
                lines(&cell, &r)
            );
            current = Some(robot);
        }
        if e.kind != Kind::Set {
            continue;
        }
        let steps = &programs[robot];
        while steps[next[robot]].apply(&globals).is_none() {
            next[robot] += 1;
        }
        let (g, value) = steps[next[robot]].apply(&globals).unwrap();
        next[robot] += 1;
        let want = format!("{}={value}", GLOBALS[g]);
        assert_eq!(
            e.details(&CellNames(&cell)),
            want,
            "r{robot}'s set at {} ns is not the serial run's:\n{}",
            e.time,
            lines(&cell, &r)
        );
        globals[g] = value;
    }
    let finals: Vec<(String, String)> = GLOBALS
        .iter()
        .zip(globals)
        .map(|(n, v)| (n.to_string(), v.to_string()))
        .collect();
    assert_eq!(r.globals, finals);
}

fn lines(cell: &vworks_cell::Cell, r: &vworks_log::result::RunResult) -> String {
    r.trace
        .iter()
        .map(|e| e.line(&CellNames(cell)) + "\n")
        .collect()
}

#[test]
fn four_robots_counting_at_the_same_instants_lose_no_update() {
    // The case: each robot adds 1 five times, 10 ms apart.
    let program: Vec<Step> = (0..5)
        .flat_map(|_| [Step::Add(0, 1), Step::Delay(10)])
        .collect();
    run_and_check(&vec![program; 4]);
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(96))]

    #[test]
    fn same_instant_work_is_one_serial_order_of_the_robots(
        programs in prop::collection::vec(prop::collection::vec(step(), 1..10), 2..5),
    ) {
        run_and_check(&programs);
    }
}
