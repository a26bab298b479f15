//! The engine on the example workcells: golden event traces, determinism, robot-order
//! invariance, tie-order independence, and the paper's figure-3 ordering.

#![allow(clippy::panic, clippy::unwrap_used, clippy::expect_used)] // tests fail by panicking

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::sync::Arc;

use expect_test::expect_file;
use proptest::prelude::*;
use vworks_cell::{Cell, load};
use vworks_log::issue::IssueKind;
use vworks_log::result::{Outcome, RunResult};
use vworks_log::trace::Kind;
use vworks_se::CellNames;
use vworks_se::Simulation;

const EXAMPLES: &[(&str, Outcome)] = &[
    ("handoff", Outcome::Completed),
    ("weldline", Outcome::Completed),
    ("monitor", Outcome::Completed),
    ("crash", Outcome::Collision),
    ("deadlock", Outcome::Deadlock),
    ("track", Outcome::Completed),
    ("palletize", Outcome::Completed),
    ("rapid_handoff", Outcome::Completed),
];

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../..")
}

fn cell(name: &str) -> Arc<Cell> {
    Arc::new(
        load(&root().join("workcells").join(name).join("cell.toml"))
            .unwrap_or_else(|e| panic!("{name}: {e}")),
    )
}

fn trace(cell: &Cell, r: &RunResult) -> String {
    let mut s: String = r
        .trace
        .iter()
        .map(|e| e.line(&CellNames(cell)) + "\n")
        .collect();
    s.push_str(&format!(
        "# outcome {} at {} ns\n",
        r.outcome.name(),
        r.end_time_ns
    ));
    s
}

/// Per robot name: its events as (time, kind, details).
fn per_robot(cell: &Cell, r: &RunResult) -> BTreeMap<String, Vec<(i64, String, String)>> {
    let mut m: BTreeMap<String, Vec<(i64, String, String)>> = BTreeMap::new();
    for e in &r.trace {
        if let Some(i) = e.robot
            && !matches!(e.kind, Kind::CheckWait | Kind::CheckWhen)
        {
            m.entry(cell.robots[i].name.clone()).or_default().push((
                e.time,
                e.kind.to_string(),
                e.details(&CellNames(cell)),
            ));
        }
    }
    m
}

#[test]
fn golden_traces_of_every_example() {
    for (name, outcome) in EXAMPLES {
        let c = cell(name);
        let r = Simulation::new(Arc::clone(&c)).run(None);
        assert_eq!(
            r.outcome, *outcome,
            "{name}: {:?} {:?}",
            r.errors, r.collisions
        );
        expect_file![root().join("tests/golden").join(format!("{name}.trace"))]
            .assert_eq(&trace(&c, &r));
    }
}

#[test]
fn two_runs_give_identical_traces() {
    for (name, _) in EXAMPLES {
        let c = cell(name);
        let a = trace(&c, &Simulation::new(Arc::clone(&c)).run(None));
        let b = trace(&c, &Simulation::new(Arc::clone(&c)).run(None));
        assert_eq!(a, b, "{name}");
    }
}

/// The disk, but for one file served from memory: the reversed cell file, at a path beside
/// the original (its programs found as from there), never written to the repository.
struct Overlay {
    path: PathBuf,
    text: String,
}

impl vworks_cell::Files for Overlay {
    fn read(&self, path: &Path) -> std::io::Result<Vec<u8>> {
        if path == self.path {
            return Ok(self.text.clone().into_bytes());
        }
        vworks_cell::Files::read(&vworks_cell::Disk, path)
    }
}

/// The cell file with its [[robot]] tables in reverse order, as if next to the original.
fn reversed_copy(name: &str) -> Overlay {
    let dir = root().join("workcells").join(name);
    let text = std::fs::read_to_string(dir.join("cell.toml")).unwrap();
    let mut head = String::new();
    let mut robots: Vec<String> = Vec::new();
    let mut tail = String::new();
    let mut section = 0; // 0 head, 1 robots, 2 rest
    for line in text.lines() {
        if line.starts_with("[[robot]]") {
            section = 1;
            robots.push(String::new());
        } else if line.starts_with("[[") {
            section = 2;
        }
        let target = match section {
            0 => &mut head,
            1 => robots.last_mut().unwrap(),
            _ => &mut tail,
        };
        target.push_str(line);
        target.push('\n');
    }
    robots.reverse();
    Overlay {
        path: dir.join("reversed.toml"),
        text: format!("{head}{}{tail}", robots.concat()),
    }
}

#[test]
fn robot_order_does_not_change_any_event_time() {
    for (name, _) in EXAMPLES {
        let c = cell(name);
        let a = Simulation::new(Arc::clone(&c)).run(None);
        let reversed = reversed_copy(name);
        assert!(!reversed.path.exists(), "{}", reversed.path.display());
        let rc = Arc::new(vworks_cell::load_with(&reversed.path, &reversed).unwrap());
        assert_eq!(
            rc.robots.first().map(|r| &r.name),
            c.robots.last().map(|r| &r.name)
        );
        let b = Simulation::new(Arc::clone(&rc)).run(None);
        assert_eq!(per_robot(&c, &a), per_robot(&rc, &b), "{name}");
        assert_eq!(a.end_time_ns, b.end_time_ns, "{name}");
    }
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 12, ..ProptestConfig::default() })]

    #[test]
    fn tie_order_between_robots_does_not_change_results(seed in any::<u64>()) {
        for (name, _) in EXAMPLES {
            let c = cell(name);
            let base = Simulation::new(Arc::clone(&c)).run(None);
            if base.warnings.iter().any(|w| w.kind == IssueKind::Race) {
                continue;
            }
            // A permutation of the robots from the seed.
            let n = c.robots.len();
            let mut rank: Vec<u64> = (0..n as u64).collect();
            let mut s = seed | 1;
            for i in (1..n).rev() {
                s ^= s << 13;
                s ^= s >> 7;
                s ^= s << 17;
                rank.swap(i, (s % (i as u64 + 1)) as usize);
            }
            let mut sim = Simulation::new(Arc::clone(&c));
            sim.set_tie_ranks(rank);
            let shuffled = sim.run(None);
            prop_assert_eq!(per_robot(&c, &base), per_robot(&c, &shuffled), "{}", name);
            prop_assert_eq!(base.outcome, shuffled.outcome);
        }
    }
}
