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

#[test]
fn four_arms_run_for_thousands_of_cycles_without_allocating() {
    let cell = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../bench/cells/grid4/cell.toml");
    let cell = Arc::new(vworks_se::workcell::load(&cell).unwrap());
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
