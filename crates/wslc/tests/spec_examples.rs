//! Every example of the language contract (`shared/spec/wsl.md`) compiles as written.
//!
//! `test_data/spec/` holds the contract's two code blocks verbatim; when the contract is
//! beside the repository (as in CI) a test checks the copies still match it. The only
//! liberty taken is the contract's own placeholder `…` ("some statements"), which is
//! replaced by nothing. The statement listing is a catalogue, not one program: each line
//! is compiled in a procedure that declares the names it uses, and the line
//! `break; continue; return; return e;` is split so each statement sits where it is legal.

#![allow(clippy::panic, clippy::unwrap_used, clippy::expect_used)] // tests fail by panicking

use std::path::PathBuf;

mod common;

use common::must_compile;
use vworks_wslc::compile;
use vworks_wslc::link::{CellSpec, RobotSpec, link};

fn data(name: &str) -> String {
    let p = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("test_data/spec")
        .join(name);
    std::fs::read_to_string(&p).unwrap_or_else(|e| panic!("{}: {e}", p.display()))
}

#[test]
fn copies_match_the_contract() {
    let spec = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../../shared/spec/wsl.md");
    let Ok(text) = std::fs::read_to_string(&spec) else {
        // Outside the project's checkout layout the contract is not at hand; CI has it.
        assert!(
            std::env::var_os("CI").is_none(),
            "CI must have ../shared/spec/wsl.md beside the repository"
        );
        return;
    };
    let blocks: Vec<&str> = text
        .split("```")
        .skip(1)
        .step_by(2)
        .map(|b| b.strip_prefix('\n').unwrap_or(b))
        .collect();
    assert_eq!(
        blocks.len(),
        2,
        "the contract's code blocks changed: update test_data/spec/"
    );
    assert_eq!(blocks[0], data("declarations.wsl"));
    assert_eq!(blocks[1], data("statements.wsl"));
}

/// The declarations block, with `{ … }` bodies left empty.
fn declarations() -> String {
    data("declarations.wsl").replace('…', "")
}

#[test]
fn declarations_compile() {
    let m = must_compile("decls.wsl", &declarations());
    assert_eq!(m.globals.len(), 2);
    assert!(m.proc("main").is_some() && m.proc("weld").is_some() && m.proc("approach").is_some());
}

const PRELUDE: &str = "
global parts = 0;
global station_free = true;
const pick = pose(450mm, -200mm, 300mm, 180deg, 0deg, 0deg);
proc name(a: int) { }
proc monitor() { }
proc sample() { }
proc alarm() { }
proc report(n: int) { log n; }
";

const LOCALS: &str = "
    var args = 1;
    var c = true;
    var d = false;
    var n = 3;
    var target = pick;
    var p = pick;
    var via = offset(pick, 0mm, 50mm, 0mm);
";

#[test]
fn every_statement_compiles() {
    let listing = data("statements.wsl").replace('…', "");
    let lines: Vec<&str> = listing.lines().collect();
    let special = "break; continue; return; return e;";
    assert!(
        lines.iter().any(|l| l.starts_with(special)),
        "the listing changed"
    );
    // All lines but the special one, as one procedure body, in order.
    let body: Vec<&str> = lines
        .iter()
        .copied()
        .filter(|l| !l.starts_with(special))
        .collect();
    let src = format!(
        "{PRELUDE}\nproc example() {{{LOCALS}\n{}\n}}\n",
        body.join("\n")
    );
    let m = must_compile("statements.wsl", &src);
    // The statements the listing shows each left their mark in the module.
    assert_eq!(m.handlers.len(), 4, "four `when` statements");
    assert_eq!(m.remotes.len(), 2, "two remote calls");
    assert_eq!(m.conds.len(), 3, "two waits and one condition handler");
    assert!(
        m.code
            .iter()
            .any(|i| matches!(i, vworks_vm::Instr::MoveC(_)))
    );
    // The special line, one statement where each is legal.
    let loops = "proc loops() { while true { break; } while false { continue; } return; }\nfunc value(e: int) -> int { return e; }\n";
    must_compile("loops.wsl", loops);

    // And the listing links into a cell: r2 and r3 run the declarations module.
    let decls = must_compile("decls.wsl", &declarations());
    let cell = CellSpec {
        robots: vec![
            RobotSpec {
                name: "r1",
                task: "r1",
                module: &m,
                axes: 6,
                linear_axes: 0,
                entry: Some("example"),
                serve_only: false,
            },
            RobotSpec::new("r2", &decls, 6),
            RobotSpec::new("r3", &decls, 6),
        ],
        parts: vec!["part1"],
    };
    let linked = link(&cell).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(linked.globals.len(), 2);
    // r2 never waits for `part_ready`: one warning.
    assert_eq!(linked.warnings.len(), 1, "{:?}", linked.warnings);
}

#[test]
fn the_rules_examples_behave_as_described() {
    // `delay 2;` is a compile error with the contract's wording.
    let e = compile("d.wsl", "proc main() { delay 2; }")
        .err()
        .map(|e| e.diagnostics)
        .unwrap_or_default();
    assert_eq!(e.len(), 1);
    assert_eq!(e[0].message, "`delay` must be a time, found an int");
    assert_eq!(e[0].help.as_deref(), Some("write 2s"));
    // `200mm / 2s` is a speed.
    must_compile(
        "s.wsl",
        "proc main() { var v: speed = 200mm / 2s; move_l pose(0mm, 0mm, 0mm, 0deg, 0deg, 0deg) speed v; }",
    );
    // `90deg + 10mm` is an error.
    let e = compile("a.wsl", "proc main() { var a = 90deg + 10mm; }")
        .err()
        .map(|e| e.diagnostics)
        .unwrap_or_default();
    assert_eq!(e.len(), 1);
    assert!(
        e[0].message.contains("cannot add an angle and a length"),
        "{}",
        e[0].message
    );
    // Annotations are optional.
    must_compile("n.wsl", "proc main() { var n: int = 0; var m = 0; n = m; }");
}

/// Legal programs near the nesting limit compile (no stack overflow in any pass, even in
/// a debug build on a 2 MiB test thread), and a procedure with more locals than 16-bit
/// slot numbers could address still compiles.
#[test]
fn deep_and_large_programs_compile() {
    let depth = 80; // plus 40 blocks: just under the 128-level limit
    let expr = format!("{}1{}", "(".repeat(depth), ")".repeat(depth));
    let mut body = String::new();
    for _ in 0..40 {
        body.push_str("if true { ");
    }
    body.push_str(&format!("var x = {expr}; log x;"));
    for _ in 0..40 {
        body.push_str(" }");
    }
    must_compile("deep.wsl", &format!("proc main() {{ {body} }}"));

    let mut big = String::from("proc main() {\n");
    for i in 0..6000 {
        big.push_str(&format!("    var j{i} = current_joints();\n"));
    }
    big.push_str("    move_j j5999;\n}\n");
    let m = must_compile("big.wsl", &big);
    assert_eq!(m.procs[0].frame_slots, 6000 * 12);
}
