//! Deeply nested workcell TOML is an error naming the file, never a stack overflow: the
//! `toml` crate bounds nesting itself (80 levels, unless its `unbounded` feature is on,
//! which this test would catch).

#![allow(clippy::panic, clippy::unwrap_used, clippy::expect_used)] // tests fail by panicking

use std::path::Path;

use vworks_cell::{Loader, MemoryFiles, load_with};

#[test]
fn twenty_thousand_nested_arrays_are_an_error_not_a_crash() {
    let n = 20_000;
    let text = format!("name = \"t\"\nx = {}{}\n", "[".repeat(n), "]".repeat(n));
    let mut files = MemoryFiles::default();
    files.insert(Path::new("c/cell.toml"), text.into_bytes());
    let e = load_with(Path::new("c/cell.toml"), &files)
        .err()
        .unwrap()
        .to_string();
    assert!(e.contains("cell.toml") && e.contains("recursion"), "{e}");
    // The variants' loader reads the file as a table first.
    let e = Loader::new(Path::new("c/cell.toml"), &files)
        .err()
        .unwrap()
        .to_string();
    assert!(e.contains("cell.toml") && e.contains("recursion"), "{e}");
}
