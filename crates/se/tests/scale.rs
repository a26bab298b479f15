//! The collider's setup is linear in bodies: a cell of 1,000 robots and a robot of 2,000
//! links set up holding a few pair entries per body, and allocating a few kilobytes per
//! body — not a table of every pair (1,000 robots took 0.54 GB; 10,000 aborted).
//! Counted by a global allocator that counts (`stats_alloc`): one test, as the counts are
//! process-wide.

#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)] // tests fail by panicking

use std::alloc::System;
use std::path::Path;

use stats_alloc::{INSTRUMENTED_SYSTEM, Region, StatsAlloc};
use vworks_cell::MemoryFiles;
use vworks_se::Collider;

#[global_allocator]
static GLOBAL: &StatsAlloc<System> = &INSTRUMENTED_SYSTEM;

/// Bodies of a cell (every collision shape of every link, devices, parts).
fn bodies(cell: &vworks_cell::Cell) -> usize {
    let links: usize = cell
        .robots
        .iter()
        .flat_map(|r| &r.model.links)
        .map(|l| l.shapes.len())
        .sum();
    links + cell.devices.len() + cell.parts.len()
}

/// Sets the collider of `cell` up: (pair entries, bytes allocated) per body.
fn per_body(cell: &vworks_cell::Cell) -> (f64, f64) {
    let n = bodies(cell) as f64;
    let region = Region::new(GLOBAL);
    let collider = Collider::new(cell);
    let bytes = region.change().bytes_allocated as f64;
    (collider.pair_entries() as f64 / n, bytes / n)
}

fn robots(n: usize) -> vworks_cell::Cell {
    let mut files = MemoryFiles::default();
    let mut toml = String::from("name = \"many\"\nallow_collision = [[\"r0\", \"r1\"]]\n");
    for k in 0..n {
        // Robots 3 m apart on a square grid; r0 and r1 may touch (an allowed pair).
        let (x, y) = ((k % 32) * 3, (k / 32) * 3);
        toml += &format!(
            "[[robot]]\nname = \"r{k}\"\nmodel = \"irb120\"\nprogram = \"p.wsl\"\nbase = {{ xyz = [\"{x}m\", \"{y}m\", \"0m\"] }}\n"
        );
    }
    files.insert(Path::new("c/cell.toml"), toml.into_bytes());
    files.insert(
        Path::new("c/p.wsl"),
        b"proc main() { delay 10ms; }\n".to_vec(),
    );
    vworks_cell::load_with(Path::new("c/cell.toml"), &files).unwrap()
}

/// One robot: a chain of `n` links, each a capsule touching its neighbours' (joined, so
/// never checked) and, folded back on itself every 10 links, the links beside it.
fn chain(n: usize) -> vworks_cell::Cell {
    let mut urdf = String::from("<?xml version=\"1.0\"?><robot name=\"chain\">");
    for i in 0..n {
        urdf += &format!(
            "<link name=\"l{i}\"><collision><origin xyz=\"0 0 0.025\"/><geometry><capsule radius=\"0.02\" length=\"0.03\"/></geometry></collision></link>"
        );
    }
    for i in 1..n {
        let (kind, limit) = if i <= 6 {
            (
                "revolute",
                "<axis xyz=\"0 1 0\"/><limit lower=\"-3\" upper=\"3\" velocity=\"1\" effort=\"1\"/>",
            )
        } else {
            ("fixed", "")
        };
        // Every 10th joint turns the chain back alongside itself, 3 cm farther along x
        // (each turn flips the frame's x).
        let origin = if i % 10 == 0 {
            let x = if i % 20 == 0 { 0.03 } else { -0.03 };
            format!("<origin xyz=\"{x} 0 0.05\" rpy=\"0 3.141592653589793 0\"/>")
        } else {
            "<origin xyz=\"0 0 0.05\"/>".to_string()
        };
        urdf += &format!(
            "<joint name=\"j{i}\" type=\"{kind}\"><parent link=\"l{}\"/><child link=\"l{i}\"/>{origin}{limit}</joint>",
            i - 1
        );
    }
    urdf += "</robot>";
    let mut files = MemoryFiles::default();
    files.insert(Path::new("c/chain.urdf"), urdf.into_bytes());
    files.insert(
        Path::new("c/cell.toml"),
        b"name = \"chain\"\n[[robot]]\nname = \"r1\"\nurdf = \"chain.urdf\"\nprogram = \"p.wsl\"\n"
            .to_vec(),
    );
    files.insert(
        Path::new("c/p.wsl"),
        b"proc main() { delay 10ms; }\n".to_vec(),
    );
    vworks_cell::load_with(Path::new("c/cell.toml"), &files).unwrap()
}

#[test]
fn setup_holds_pair_state_linear_in_bodies() {
    // 1,000 robots of 7 bodies: 49 million pairs.
    let cell = robots(1000);
    assert_eq!(bodies(&cell), 7000);
    let (entries, bytes) = per_body(&cell);
    eprintln!("1,000 robots: {entries:.2} pair entries and {bytes:.0} bytes per body");
    assert!(entries <= 4.0, "{entries} pair entries per body");
    assert!(bytes <= 4096.0, "{bytes} bytes allocated per body");
    // A chain of 2,000 links folded on itself: 2 million pairs in one robot.
    let cell = chain(2000);
    assert_eq!(bodies(&cell), 2000);
    let (entries, bytes) = per_body(&cell);
    eprintln!("a 2,000-link chain: {entries:.2} pair entries and {bytes:.0} bytes per body");
    assert!(
        (0.5..=8.0).contains(&entries),
        "{entries} pair entries per body (the folds touch)"
    );
    assert!(bytes <= 4096.0, "{bytes} bytes allocated per body");
}
