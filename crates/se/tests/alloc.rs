//! The hot loop allocates nothing in steady state: per cycle (FK, the boundary check, the
//! sweep, adaptive checking) and per event, apart from the trace's amortised growth; a
//! remote call allocates only its argument slots (made by the caller's VM, moved to the
//! serving robot's request). Counted by a global allocator that counts (`stats_alloc`).

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
    remote_calls_allocate_only_their_arguments();
}

fn four_arms_run_for_thousands_of_cycles_without_allocating() {
    let cell = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../bench/cells/grid4/cell.toml");
    let cell = Arc::new(vworks_cell::load(&cell).unwrap());
    let mut sim = vworks_se::Simulation::new(cell);
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
    let mut sim = vworks_se::Simulation::new(cell);
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

/// A cell of two robots: `caller` runs `main` of `caller_program`, `server` serves the
/// remote work `server_program` defines. Loaded from a temporary folder.
fn two_robots(name: &str, caller_program: &str, server_program: &str) -> vworks_cell::Cell {
    let dir = std::env::temp_dir().join(format!("vworks-alloc-{name}-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(dir.join("caller.wsl"), caller_program).unwrap();
    std::fs::write(dir.join("server.wsl"), server_program).unwrap();
    let toml = "name = \"remote\"\ncycle = \"4ms\"\n[[robot]]\nname = \"caller\"\nmodel = \"irb120\"\nprogram = \"caller.wsl\"\n[[robot]]\nname = \"server\"\nmodel = \"irb120\"\nprogram = \"server.wsl\"\nbase = { xyz = [\"3000mm\", \"0mm\", \"0mm\"] }\n";
    std::fs::write(dir.join("cell.toml"), toml).unwrap();
    let cell = vworks_cell::load(&dir.join("cell.toml")).unwrap();
    let _ = std::fs::remove_dir_all(&dir);
    cell
}

/// Steps `cell` past its start, then counts the allocations of the next `steps` steps and
/// the remote calls among them: (allocations, remote calls).
fn remote_calls_counted(cell: vworks_cell::Cell, steps: usize) -> (u64, usize) {
    let mut sim = vworks_se::Simulation::new(Arc::new(cell));
    for _ in 0..2_000 {
        sim.step(None);
    }
    let before = sim.trace().len();
    let region = Region::new(GLOBAL);
    let mut done = 0;
    while done < steps && sim.step(None) {
        done += 1;
    }
    let change = region.change();
    assert_eq!(done, steps, "the run ended early");
    let calls = sim.trace()[before..]
        .iter()
        .filter(|e| e.kind == vworks_log::trace::Kind::RemoteCall)
        .count();
    ((change.allocations + change.reallocations) as u64, calls)
}

fn remote_calls_allocate_only_their_arguments() {
    // Remote work without arguments: request, start, end, answer — nothing allocated.
    let (allocations, calls) = remote_calls_counted(
        two_robots(
            "bare",
            "proc main() {\n    for i in 0..5000 {\n        parallel {\n            remote server.work();\n        }\n    }\n}\n",
            "proc main() {}\nproc work() { delay 1ms; }\n",
        ),
        20_000,
    );
    assert!(calls > 2_000, "{calls} remote calls");
    assert!(
        allocations <= 6,
        "{allocations} allocations over {calls} remote calls without arguments"
    );
    // With arguments: the argument slots, which the engine moves to the serving robot
    // (it copied them twice before: 4 allocations per call). The caller's VM makes them
    // twice: when it describes the call, and in the copy of the event `next_event` hands
    // out (the VM keeps its own).
    let (allocations, calls) = remote_calls_counted(
        two_robots(
            "args",
            "proc main() {\n    for i in 0..5000 {\n        parallel {\n            remote server.work(i, 2mm);\n        }\n    }\n}\n",
            "proc main() {}\nproc work(n: int, len: length) { delay len / 1000mm/s; }\n",
        ),
        20_000,
    );
    assert!(calls > 2_000, "{calls} remote calls");
    assert!(
        allocations <= 2 * calls as u64 + 6,
        "{allocations} allocations over {calls} remote calls with arguments"
    );
}
