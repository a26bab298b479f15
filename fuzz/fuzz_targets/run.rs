//! A whole run: a mutated cell and programs (the `.case` format, in memory), simulated to
//! at most 5 simulated seconds within a wall-clock budget. Asserts no panic, no hang (the
//! budget, and libFuzzer's -timeout for a single step), event times that never go back or
//! below zero, and a log that reads back with exactly the run's events.
#![no_main]

use std::sync::Arc;
use std::time::{Duration, Instant};

use libfuzzer_sys::fuzz_target;
use vworks_se::CellNames;

#[path = "cellfiles.rs"]
mod cellfiles;

const UNTIL_NS: i64 = 5_000_000_000;
const WALL: Duration = Duration::from_secs(10);
/// A run of many events is not a hang: it stops here (a `when every 1e-9s` over five
/// simulated seconds is five billion of them).
const MAX_STEPS: u64 = 200_000;

fuzz_target!(|data: &[u8]| {
    let files = cellfiles::files_of(data);
    let Ok(cell) = vworks_cell::load_with(cellfiles::cell_path(), &files) else { return };
    // Small cells only: the point is the engine, not 64 robots' FK.
    if cell.robots.len() > 4 || cell.devices.len() + cell.parts.len() > 8 {
        return;
    }
    let cell = Arc::new(cell);
    let log_path = std::env::temp_dir().join(format!("vworks-fuzz-run-{}.mcap", std::process::id()));
    let log = vworks_log::mcaplog::McapLog::create(&log_path, &Arc::new(vworks_se::describe(&cell)), 1).expect("a log file in the temp folder");
    // Zero-time loops end at a tenth of the default bounds: the point is that they end.
    let mut sim = vworks_se::Simulation::new(Arc::clone(&cell))
        .with_log(log)
        .with_robot_instant_limit(10_000)
        .with_instant_limit(100_000);
    let started = Instant::now();
    let mut steps = 0u64;
    while sim.step(Some(UNTIL_NS)) {
        steps += 1;
        if steps >= MAX_STEPS {
            break;
        }
        if steps % 256 == 0 {
            assert!(started.elapsed() < WALL, "the run took more than {WALL:?} of wall-clock time ({steps} steps, at {} ns)", sim.time());
        }
    }
    let result = sim.into_result();
    let mut last = 0i64;
    for e in &result.trace {
        assert!(e.time >= 0, "negative event time: {}", e.line(&CellNames(&cell)));
        assert!(e.time >= last, "event time went back: {}", e.line(&CellNames(&cell)));
        last = e.time;
    }
    assert!(result.end_time_ns >= 0 && result.end_time_ns <= UNTIL_NS.max(last));
    assert!(result.log_error.is_none(), "{:?}", result.log_error);
    let contents = vworks_log::mcaplog::read_log(&log_path).expect("the run's log reads back");
    assert!(contents.damage.is_none(), "{:?}", contents.damage);
    assert_eq!(contents.events.len(), result.trace.len());
    let _ = std::fs::remove_file(&log_path);
});
