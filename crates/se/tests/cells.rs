//! Small cells written by the tests: the paper's figure-3 order, races, workcell errors,
//! and the contract's workcell example as written.

#![allow(clippy::panic, clippy::unwrap_used, clippy::expect_used)] // tests fail by panicking

use std::path::PathBuf;
use std::sync::Arc;

use vworks_cell::{Cell, CellError, Stage, load};
use vworks_log::issue::IssueKind;
use vworks_log::result::{Outcome, RunResult};
use vworks_log::stats::Ending;
use vworks_log::trace::Kind;
use vworks_se::CellNames;
use vworks_se::Simulation;

/// Writes the files into a fresh directory and returns the path of `cell.toml`.
fn write_cell(name: &str, files: &[(&str, &str)]) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("vworks-se-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    for (f, text) in files {
        std::fs::write(dir.join(f), text).unwrap();
    }
    dir.join("cell.toml")
}

fn run(path: &std::path::Path) -> (Arc<Cell>, RunResult) {
    let cell = Arc::new(load(path).unwrap_or_else(|e| panic!("{e}")));
    let r = Simulation::new(Arc::clone(&cell)).run(None);
    (cell, r)
}

const TWO_ROBOTS: &str = r#"
cycle = "4ms"
[[robot]]
name = "a"
model = "turntable"
program = "a.wsl"
[[robot]]
name = "b"
model = "turntable"
base = { xyz = ["2m", "0m", "0m"] }
program = "b.wsl"
"#;

#[test]
fn a_set_queues_check_when_behind_events_already_due() {
    let path = write_cell(
        "fig3",
        &[
            ("cell.toml", TWO_ROBOTS),
            ("a.wsl", "global g = 0;\nproc main() { delay 1s; g = 1; }\n"),
            (
                "b.wsl",
                "global g = 0;\nproc tick() { log \"tick\"; }\nproc on() { log \"on\"; }\nproc main() {\n    when every 1s do tick();\n    when g == 1 do on();\n    delay 2s;\n}\n",
            ),
        ],
    );
    let (cell, r) = run(&path);
    assert_eq!(r.outcome, Outcome::Completed);
    let at_1s: Vec<String> = r
        .trace
        .iter()
        .filter(|e| e.time == 1_000_000_000)
        .map(|e| {
            format!(
                "{} {} {}",
                e.robot.map_or("-".into(), |i| cell.robots[i].name.clone()),
                e.kind,
                e.details(&CellNames(&cell))
            )
        })
        .collect();
    // A's entry was due first, and its whole zero-time work at 1 s is one turn (delay_end,
    // set, end: "One instant, one serial order"). Then B's handler, already due before the
    // set, runs to its end in B's turn; then the check_when the set queued behind it
    // (figure 3), and the edge fires.
    assert_eq!(
        at_1s,
        [
            "a delay_end ",
            "a set g=1",
            "a end ",
            "b when_fire tick",
            "b log \"tick\"",
            "b when_end tick",
            "b check_when g",
            "b when_fire on",
            "b log \"on\"",
            "b when_end on",
        ]
    );
}

#[test]
fn two_robots_setting_a_global_at_one_instant_is_a_race() {
    let path = write_cell(
        "race",
        &[
            ("cell.toml", TWO_ROBOTS),
            (
                "a.wsl",
                "global g = 0;\nproc main() {\n    delay 1s;\n    g = 1;\n}\n",
            ),
            (
                "b.wsl",
                "global g = 0;\nproc main() {\n    delay 1s;\n    g = 2;\n}\n",
            ),
        ],
    );
    let (_, r) = run(&path);
    let race: Vec<_> = r
        .warnings
        .iter()
        .filter(|w| w.kind == IssueKind::Race)
        .collect();
    assert_eq!(race.len(), 1, "{:?}", r.warnings);
    assert!(
        race[0].message.contains("a (a.wsl:4:5) and b (b.wsl:4:5)"),
        "{}",
        race[0].message
    );
}

#[test]
fn wait_and_set_at_one_instant_is_a_race() {
    let path = write_cell(
        "race2",
        &[
            ("cell.toml", TWO_ROBOTS),
            (
                "a.wsl",
                "global g = 0;\nproc main() {\n    delay 1s;\n    g = 1;\n}\n",
            ),
            (
                "b.wsl",
                "global g = 0;\nproc main() {\n    delay 1s;\n    wait_until g == 0 timeout 1s;\n}\n",
            ),
        ],
    );
    let (_, r) = run(&path);
    assert!(
        r.warnings
            .iter()
            .any(|w| w.kind == IssueKind::Race && w.message.contains("`g`")),
        "{:?}",
        r.warnings
    );
}

#[test]
fn a_handshake_at_one_instant_is_not_a_race() {
    // A sets `done`; B, released by that set, clears it at the same instant, and A's next
    // wait (which blocks) reads it at that instant too. Every order of the ties gives the
    // same result, so nothing is reported. (Both would be flagged without causality.)
    let path = write_cell(
        "handshake",
        &[
            ("cell.toml", TWO_ROBOTS),
            (
                "a.wsl",
                "global done = 0;\nproc main() {\n    delay 1s;\n    done = 1;\n    wait_until done == 0;\n    done = 1;\n}\n",
            ),
            (
                "b.wsl",
                "global done = 0;\nproc main() {\n    wait_until done == 1;\n    done = 0;\n    wait_until done == 1;\n}\n",
            ),
        ],
    );
    let (_, r) = run(&path);
    assert_eq!(r.outcome, Outcome::Completed, "{:?}", r.errors);
    assert!(r.warnings.is_empty(), "{:?}", r.warnings);
    assert_eq!(r.end_time_ns, 1_000_000_000);
}

#[test]
fn robots_taking_turns_at_one_instant_do_not_race() {
    // Three robots pass a turn counter round at t = 0: each waits for its turn, then
    // advances it. Every set and read follows, through the others' releases, the ones
    // before it (happens-before is transitive): no order of the ties changes anything, and
    // no race is reported. (Before vector clocks, 1,400 false warnings for 8 robots.)
    let three = format!(
        "{TWO_ROBOTS}[[robot]]\nname = \"c\"\nmodel = \"turntable\"\nbase = {{ xyz = [\"4m\", \"0m\", \"0m\"] }}\nprogram = \"c.wsl\"\n"
    );
    let program = |k: usize| {
        format!(
            "global turn = 0;\nproc main() {{\n    for i in 0..20 {{\n        wait_until turn == i * 3 + {k};\n        turn += 1;\n    }}\n}}\n"
        )
    };
    let (pa, pb, pc) = (program(0), program(1), program(2));
    let path = write_cell(
        "ring",
        &[
            ("cell.toml", &three),
            ("a.wsl", &pa),
            ("b.wsl", &pb),
            ("c.wsl", &pc),
        ],
    );
    let (_, r) = run(&path);
    assert_eq!(r.outcome, Outcome::Completed, "{:?}", r.errors);
    assert_eq!(r.globals, vec![("turn".to_string(), "60".to_string())]);
    assert!(r.warnings.is_empty(), "{:?}", r.warnings);
}

/// The contract's workcell example (../shared/spec/engine.md), copied verbatim into
/// `tests/data/contract-cell.toml` so the test below runs on any checkout.
fn contract_cell() -> String {
    let copy = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/data/contract-cell.toml");
    std::fs::read_to_string(copy).unwrap()
}

#[test]
fn the_copy_of_the_contracts_workcell_example_is_the_contracts() {
    let spec = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../../shared/spec/engine.md");
    let Ok(text) = std::fs::read_to_string(&spec) else {
        // Outside the project's checkout layout the contract is not at hand; CI has it.
        assert!(
            std::env::var_os("CI").is_none(),
            "CI must have ../shared/spec/engine.md"
        );
        return;
    };
    let toml = text
        .split("```toml\n")
        .nth(1)
        .and_then(|s| s.split("```").next())
        .unwrap();
    assert_eq!(
        toml,
        contract_cell(),
        "the contract's workcell example changed: update tests/data/contract-cell.toml"
    );
}

#[test]
fn the_contracts_workcell_example_loads_as_written() {
    let toml = contract_cell();
    let toml = toml.as_str();
    let path = write_cell(
        "spec",
        &[
            ("cell.toml", toml),
            (
                "r1.wsl",
                "proc main() { move_j joints(0deg, -30deg, 30deg, 0deg, 60deg, 0deg); grip part1; release part1; }\n",
            ),
        ],
    );
    let cell = load(&path).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(cell.name, "handoff");
    assert_eq!(cell.cycle_ns, 4_000_000);
    assert!((cell.clearance - 0.005).abs() < 1e-12);
    assert_eq!(
        cell.allowed,
        [("r1.link6".to_string(), "part1".to_string())]
    );
    assert!((cell.robots[0].default_speed - 0.25).abs() < 1e-12);
}

#[test]
fn workcell_mistakes_name_the_file_the_key_and_what_to_do() {
    let robot = "[[robot]]\nname = \"r1\"\nmodel = \"irb120\"\nprogram = \"r1.wsl\"\n";
    let cases: &[(&str, &str, &[&str])] = &[
        (
            "cycle = \"4xs\"\n",
            robot,
            &["cycle", "not a quantity", "\"4ms\""],
        ),
        ("cycle = \"4mm\"\n", robot, &["cycle", "a length", "a time"]),
        (
            "cycle = \"1s\"\n",
            robot,
            &["cycle", "outside the allowed 0.1 ms to 100 ms"],
        ),
        (
            "on_collision = \"explode\"\n",
            robot,
            &["on_collision", "\"stop\" or \"continue\""],
        ),
        (
            "",
            "[[robot]]\nname = \"r1\"\nmodle = \"irb120\"\n",
            &["unknown field `modle`"],
        ),
        (
            "",
            "[[robot]]\nname = \"r1\"\nmodel = \"irb9999\"\nprogram = \"r1.wsl\"\n",
            &["robot[0] `r1`.model", "irb9999", "irb120"],
        ),
        (
            "",
            "[[robot]]\nname = \"r1\"\nmodel = \"irb120\"\nprogram = \"missing.wsl\"\n",
            &["program", "cannot read", "missing.wsl"],
        ),
        (
            "",
            "[[robot]]\nname = \"r1\"\nmodel = \"irb120\"\n",
            &["program", "needs a program"],
        ),
        (
            "",
            "[[robot]]\nname = \"r1\"\nmodel = \"irb120\"\nprogram = \"r1.wsl\"\ndefault_speed = \"90deg\"\n",
            &["default_speed", "an angle", "a speed"],
        ),
        (
            "",
            "[[robot]]\nname = \"r1\"\nmodel = \"irb120\"\nprogram = \"r1.wsl\"\nhome = [\"0deg\"]\n",
            &["home", "1 values", "6 axes"],
        ),
        (
            "",
            &format!("{robot}[[device]]\nname = \"t\"\nbox = [\"1m\", \"1m\"]\n"),
            &["device[0] `t`.box", "3 sizes"],
        ),
        (
            "",
            &format!("{robot}[[device]]\nname = \"t\"\n"),
            &["exactly one shape"],
        ),
        (
            "",
            &format!("{robot}[[device]]\nname = \"r1\"\nsphere = \"1m\"\n"),
            &["`r1` is used twice"],
        ),
        (
            "allow_collision = [[\"r1.link_99\", \"table\"]]\n",
            robot,
            &["allow_collision[0]", "r1.link_99", "not a body"],
        ),
        ("", "", &["no robot"]),
    ];
    for (i, (head, body, needles)) in cases.iter().enumerate() {
        let path = write_cell(
            &format!("bad{i}"),
            &[
                ("cell.toml", &format!("{head}{body}")),
                ("r1.wsl", "proc main() { }\n"),
            ],
        );
        let e = match load(&path) {
            Ok(_) => panic!("case {i} should fail:\n{head}{body}"),
            Err(e) => e.to_string(),
        };
        assert!(
            e.contains("cell.toml"),
            "case {i}: the message must name the file: {e}"
        );
        for n in *needles {
            assert!(e.contains(n), "case {i}: expected {n:?} in: {e}");
        }
    }
}

#[test]
fn program_errors_are_rendered_with_their_source() {
    let path = write_cell(
        "prog",
        &[
            (
                "cell.toml",
                "[[robot]]\nname = \"r1\"\nmodel = \"irb120\"\nprogram = \"r1.wsl\"\n",
            ),
            ("r1.wsl", "proc main() {\n    delay 2;\n}\n"),
        ],
    );
    match load(&path) {
        Err(CellError::Program {
            stage: Stage::Compile,
            rendered,
            ..
        }) => {
            assert!(
                rendered.contains("r1.wsl:2:11") && rendered.contains("write 2s"),
                "{rendered}"
            );
        }
        other => panic!("{other:?}"),
    }
    // A link error: the remote robot does not exist.
    let path = write_cell(
        "link",
        &[
            (
                "cell.toml",
                "[[robot]]\nname = \"r1\"\nmodel = \"irb120\"\nprogram = \"r1.wsl\"\n",
            ),
            (
                "r1.wsl",
                "proc main() {\n    parallel { remote r9.weld(); }\n}\n",
            ),
        ],
    );
    match load(&path) {
        Err(CellError::Program {
            stage: Stage::Link,
            rendered,
            ..
        }) => assert!(
            rendered.contains("E0101") && rendered.contains("no robot `r9`"),
            "{rendered}"
        ),
        other => panic!("{other:?}"),
    }
}

#[test]
fn with_continue_a_collision_starts_and_ends_and_a_held_part_moves_with_the_tool() {
    // The turntable's robot-less cousin: a track carriage carries nothing, but a part the
    // robot grips sweeps through a post and out again.
    let cell = r#"
cycle = "4ms"
on_collision = "continue"
[[robot]]
name = "r1"
model = "irb120"
program = "r1.wsl"
tool = { xyz = ["0mm", "0mm", "100mm"] }
home = ["0deg", "-30deg", "30deg", "0deg", "60deg", "0deg"]
[[device]]
name = "post"
box = ["20mm", "20mm", "250mm"]
pose = { xyz = ["420mm", "0mm", "125mm"] }
[[part]]
name = "block"
box = ["40mm", "40mm", "40mm"]
pose = { xyz = ["400mm", "-200mm", "180mm"] }
allow_collision = [["r1.tool0", "block"], ["r1.link_6", "block"]]
"#;
    let prog = "const p = pose(400mm, -200mm, 200mm, 180deg, 0deg, 0deg);\nproc main() {\n    move_l p speed 200mm/s;\n    grip block;\n    move_l offset(p, 0mm, 400mm, 0mm) speed 200mm/s;\n    release block;\n}\n";
    let path = write_cell("cont", &[("cell.toml", cell), ("r1.wsl", prog)]);
    let (cell, r) = run(&path);
    assert_eq!(r.outcome, Outcome::Completed, "{:?}", r.errors);
    let kinds: Vec<(&str, String)> = r
        .trace
        .iter()
        .filter(|e| matches!(e.kind, Kind::CollisionStart | Kind::CollisionEnd))
        .map(|e| (e.kind.name(), e.details(&CellNames(&cell))))
        .collect();
    // Only the carried block (gripped 200 mm away from the post) meets the post: it starts
    // touching, and stops when it has passed.
    assert_eq!(kinds.len(), 2, "{kinds:?}");
    assert_eq!(kinds[0].0, "collision_start");
    assert!(kinds[0].1.starts_with("post block"), "{kinds:?}");
    assert_eq!(kinds[1], ("collision_end", "post block".to_string()));
    // Found by the sweep between boundaries: at first touch, so no depth yet.
    assert!(r.collisions.iter().all(|c| c.depth >= 0.0));
}

#[test]
fn until_stops_the_run_at_that_time() {
    let path = write_cell(
        "until",
        &[
            ("cell.toml", TWO_ROBOTS),
            ("a.wsl", "proc main() { delay 10s; }\n"),
            ("b.wsl", "proc main() { move_j joints(180deg); }\n"),
        ],
    );
    let cell = Arc::new(load(&path).unwrap());
    let r = Simulation::new(Arc::clone(&cell)).run(Some(1_500_000_000));
    assert_eq!(r.outcome, Outcome::Until);
    assert_eq!(r.end_time_ns, 1_500_000_000);
    // b's 180° move at 90°/s takes 2.3 s: at 1.5 s it is still moving.
    assert_eq!(r.robots[1].moving_ns, 1_500_000_000);
    assert_eq!(r.robots[1].ended, Ending::Running);
}

/// The motion example of docs/language.md (the block with `zone 10mm`) runs as written on
/// an IRB 120: it completes, its zoned points fly by (zoned `motion_end`s, motions that
/// start inside the corners) and the `zone fine` at its end stops.
#[test]
fn the_language_references_motion_example_runs_with_its_zones() {
    let doc = std::fs::read_to_string(
        PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../docs/language.md"),
    )
    .unwrap();
    let block = doc
        .split("```wsl\n")
        .skip(1)
        .map(|b| &b[..b.find("```").unwrap()])
        .find(|b| b.contains("zone 10mm"))
        .unwrap();
    let path = write_cell(
        "motion-example",
        &[
            (
                "cell.toml",
                "name = \"m\"\n[[robot]]\nname = \"r1\"\nmodel = \"irb120\"\nprogram = \"r1.wsl\"\nhome = [\"0deg\", \"-30deg\", \"30deg\", \"0deg\", \"60deg\", \"0deg\"]\n",
            ),
            ("r1.wsl", block),
        ],
    );
    let (cell, r) = run(&path);
    assert_eq!(r.outcome, Outcome::Completed, "{:?}", r.errors);
    let lines: Vec<String> = r.trace.iter().map(|e| e.line(&CellNames(&cell))).collect();
    let zoned_ends = lines
        .iter()
        .filter(|l| l.contains("motion_end zone="))
        .count();
    let blended = lines.iter().filter(|l| l.contains(" blend=")).count();
    assert_eq!((zoned_ends, blended), (2, 2), "{lines:#?}");
    assert!(
        lines
            .iter()
            .any(|l| l.contains("motion_end -") && l.contains("r1.wsl:12:")),
        "{lines:#?}"
    );
}

#[test]
fn a_sync_timeout_tied_with_the_last_arrival_warns_in_either_order() {
    // r1's wait at `meet` times out at 1 s, the instant r2 arrives. Queued first, the
    // timeout wins (r1 gives up, r2 waits alone: deadlock); with the tie reversed, r2's
    // arrival completes the meeting before the deadline (both go on). Either way the
    // outcome is the tie order's: a race warning names both statements.
    let files = [
        ("cell.toml", TWO_ROBOTS),
        (
            "a.wsl",
            "proc main() {\n    sync meet with a, b timeout 1s;\n}\n",
        ),
        (
            "b.wsl",
            "proc main() {\n    delay 1s;\n    sync meet with a, b;\n}\n",
        ),
    ];
    let path = write_cell("sync-tie", &files);
    let cell = Arc::new(load(&path).unwrap_or_else(|e| panic!("{e}")));
    for (ranks, outcome) in [
        (vec![0, 1], Outcome::Deadlock),
        (vec![1, 0], Outcome::Completed),
    ] {
        let mut sim = Simulation::new(Arc::clone(&cell));
        sim.set_tie_ranks(ranks.clone());
        while sim.step(None) {}
        assert_eq!(sim.outcome(), Some(outcome), "ranks {ranks:?}");
        let races: Vec<&str> = sim
            .warnings()
            .iter()
            .filter(|w| w.kind == IssueKind::Race)
            .map(|w| w.message.as_str())
            .collect();
        assert_eq!(races.len(), 1, "ranks {ranks:?}: {races:?}");
        assert!(races[0].contains("at sync point `meet`"), "{}", races[0]);
    }
}
