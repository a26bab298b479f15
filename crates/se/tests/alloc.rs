//! The hot loop allocates nothing in steady state: per cycle (FK, the boundary check, the
//! sweep, adaptive checking) and per event, apart from the trace's amortised growth.
//! Counted by a global allocator that counts (`stats_alloc`).

#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)] // tests fail by panicking

use std::alloc::System;
use std::path::Path;
use std::sync::Arc;

use stats_alloc::{INSTRUMENTED_SYSTEM, Region, StatsAlloc};

#[global_allocator]
static GLOBAL: &StatsAlloc<System> = &INSTRUMENTED_SYSTEM;

/// The counts are process-wide, so the measurements run in one test, one after the other:
/// with two tests, the harness reporting the end of one (it allocates) while the other
/// measured made that one fail now and then (1 run in 7).
#[test]
fn the_hot_loops_allocate_nothing_in_steady_state() {
    four_arms_run_for_thousands_of_cycles_without_allocating();
    a_ring_of_robots_handing_a_global_round_allocates_nothing_per_event();
}

fn four_arms_run_for_thousands_of_cycles_without_allocating() {
    let cell = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../bench/cells/grid4/cell.toml");
    let cell = Arc::new(vworks_cell::load(&cell).unwrap());
    let mut sim = vworks_se::engine::Simulation::new(cell);
    // Warm up: the first motions, scratch buffers sized.
    sim.advance_to(3_000_000_000);
    let events_before = sim.trace().len();
    let region = Region::new(GLOBAL);
    sim.advance_to(33_000_000_000); // 7,500 cycles
    let change = region.change();
    let events = sim.trace().len() - events_before;
    assert!(events > 100, "{events} events");
    // The trace doubles its buffer now and then: a handful of reallocations, not one per
    // cycle or event.
    let allocations = change.allocations + change.reallocations;
    assert!(
        allocations <= 4,
        "{allocations} allocations over 7,500 cycles and {events} events: {change:?}"
    );
}

fn a_ring_of_robots_handing_a_global_round_allocates_nothing_per_event() {
    // Eight robots, each waiting until a shared counter reaches its turn, then advancing it
    // (set, check_wait for every waiting robot, wait_end), and a signal ping-pong beside
    // them: scheduler events only.
    let dir = std::env::temp_dir().join(format!("vworks-alloc-ring-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let mut toml = String::from("name = \"ring\"\ncycle = \"4ms\"\n");
    for k in 0..8 {
        std::fs::write(
            dir.join(format!("r{k}.wsl")),
            format!(
                "global turn = 0;\nproc main() {{\n    for i in 0..2000 {{\n        wait_until turn == i * 8 + {k};\n        turn += 1;\n    }}\n}}\n"
            ),
        )
        .unwrap();
        toml += &format!(
            "[[robot]]\nname = \"r{k}\"\nmodel = \"irb120\"\nprogram = \"r{k}.wsl\"\nbase = {{ xyz = [\"{}mm\", \"0mm\", \"0mm\"] }}\n",
            k * 2000
        );
    }
    std::fs::write(dir.join("cell.toml"), toml).unwrap();
    let cell = Arc::new(vworks_cell::load(&dir.join("cell.toml")).unwrap());
    let _ = std::fs::remove_dir_all(&dir);
    let mut sim = vworks_se::engine::Simulation::new(cell);
    for _ in 0..5_000 {
        sim.step(None);
    }
    let region = Region::new(GLOBAL);
    let mut steps = 0;
    while steps < 50_000 && sim.step(None) {
        steps += 1;
    }
    let change = region.change();
    assert_eq!(steps, 50_000);
    // The trace and the queue grow by doubling: a few reallocations in 50,000 events.
    let allocations = change.allocations + change.reallocations;
    assert!(
        allocations <= 6,
        "{allocations} allocations over {steps} steps: {change:?}"
    );
}
