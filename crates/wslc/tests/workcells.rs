//! The programs of the bundled workcells compile without warnings and link as a cell.

#![allow(clippy::panic, clippy::unwrap_used, clippy::expect_used)] // tests fail by panicking

use std::path::PathBuf;

mod common;

use common::must_compile;
use vworks_wslc::link::{CellSpec, RobotSpec, link};

fn compile_file(path: &PathBuf) -> vworks_vm::Module {
    let src = std::fs::read_to_string(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let name = path.display().to_string();
    let out = vworks_wslc::compile(&name, &src);
    assert!(
        out.as_ref().map_or(true, |o| o.warnings.is_empty()),
        "{name}: {:?}",
        out.map(|o| o.warnings)
    );
    must_compile(&name, &src)
}

#[test]
fn handoff_programs_compile_and_link() {
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../workcells/handoff");
    let r1 = compile_file(&dir.join("r1.wsl"));
    let r2 = compile_file(&dir.join("r2.wsl"));
    let cell = CellSpec {
        robots: vec![RobotSpec::new("r1", &r1, 6), RobotSpec::new("r2", &r2, 6)],
        parts: vec!["part1"],
    };
    let linked = link(&cell).unwrap_or_else(|e| panic!("{e}"));
    assert!(linked.warnings.is_empty(), "{:?}", linked.warnings);
    let names: Vec<&str> = linked.globals.iter().map(|g| g.name.as_str()).collect();
    assert_eq!(names, ["handed"]);
    // r2's condition handler depends on exactly `handed`.
    let c = &r2.conds[0];
    assert_eq!(
        c.globals
            .iter()
            .map(|g| r2.str(r2.globals[*g as usize].name))
            .collect::<Vec<_>>(),
        ["handed"]
    );
}
