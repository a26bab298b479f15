//! Cells built for benchmarking (issue 8): N irb120 arms on a grid, each looping between
//! two poses. Prints, once:
//! - (a) the cost per cycle of `bench/cells/grid4` (4 robots) with every pair the
//!   broadphase keeps queried at every boundary (no sweep, no adaptive checking): joint
//!   interpolation, FK and collision checks — what `bench/compare.py` sets against
//!   Pinocchio+coal and PyBullet;
//! - (b) a 60-simulated-second program of 4 robots with 4 ms cycles and collision checks
//!   (`bench/cells/grid4`), without and with the full log: wall time and × real time;
//! - (d) the cost per cycle for 1, 4, 16 and 64 robots (4 simulated seconds each), and the
//!   ratio of 64 to 4.
//!
//! Then criterion times the 4-robot minute without a log. Under `cargo test` (no `--bench`)
//! the cells are built and run once.

#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)] // benches fail by panicking

use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::time::Instant;

use criterion::{Criterion, criterion_group, criterion_main};
use vworks_cell::{Cell, load};
use vworks_log::mcaplog::McapLog;
use vworks_se::Simulation;

/// A cell of `n` arms 1.2 m apart on a square grid; each moves back and forth `rounds`
/// times (about 2.9 s per round).
fn grid_cell(dir: &Path, n: usize, rounds: u32) -> Arc<Cell> {
    std::fs::create_dir_all(dir).unwrap();
    let side = (n as f64).sqrt().ceil() as usize;
    let mut toml = String::from("name = \"grid\"\ncycle = \"4ms\"\nclearance = \"5mm\"\n");
    for i in 0..n {
        let (x, y) = ((i % side) as f64 * 1200.0, (i / side) as f64 * 1200.0);
        toml += &format!(
            "[[robot]]\nname = \"r{i}\"\nmodel = \"irb120\"\nprogram = \"arm.wsl\"\nbase = {{ xyz = [\"{x}mm\", \"{y}mm\", \"0mm\"] }}\n"
        );
    }
    std::fs::write(dir.join("cell.toml"), toml).unwrap();
    let program = format!(
        "proc main() {{\n    var i = 0;\n    while i < {rounds} {{\n        move_j joints(40deg, -20deg, 30deg, 0deg, 60deg, 0deg) speed 30%;\n        move_l pose(300mm, -150mm, 350mm, 180deg, 0deg, 0deg) speed 400mm/s;\n        i += 1;\n    }}\n}}\n"
    );
    std::fs::write(dir.join("arm.wsl"), program).unwrap();
    Arc::new(load(&dir.join("cell.toml")).unwrap_or_else(|e| panic!("{e}")))
}

fn seconds(runs: u32, mut f: impl FnMut()) -> f64 {
    let t0 = Instant::now();
    for _ in 0..runs {
        f();
    }
    t0.elapsed().as_secs_f64() / f64::from(runs)
}

fn scaling(c: &mut Criterion) {
    let bench = std::env::args().any(|a| a == "--bench");
    let runs = if bench { 5 } else { 1 };
    let tmp = std::env::temp_dir().join(format!("vworks-scaling-{}", std::process::id()));
    // (b) Four robots for a simulated minute: the committed cell is the generator's.
    let grid4 = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../bench/cells/grid4");
    let generated = grid_cell(&tmp.join("minute"), 4, 21);
    let minute = Arc::new(load(&grid4.join("cell.toml")).unwrap_or_else(|e| panic!("{e}")));
    assert_eq!(
        std::fs::read_to_string(grid4.join("arm.wsl")).unwrap(),
        std::fs::read_to_string(tmp.join("minute/arm.wsl")).unwrap()
    );
    assert_eq!(
        (minute.robots.len(), minute.cycle_ns),
        (generated.robots.len(), generated.cycle_ns)
    );
    // (a) Every kept pair at every boundary, over the first 4 simulated seconds.
    let until = Some(4_000_000_000);
    let exhaustive = || {
        Simulation::new(Arc::clone(&minute))
            .with_sweep(false)
            .with_adaptive(false)
            .run(until)
    };
    let probe = exhaustive();
    let wall = seconds(runs, || {
        std::hint::black_box(exhaustive());
    });
    println!(
        "(a) 4 robots, every kept pair at every boundary: {:.2} µs per cycle ({} cycles, {:.1} queries per cycle)",
        wall / probe.cycles as f64 * 1e6,
        probe.cycles,
        probe.queries as f64 / probe.cycles as f64
    );
    let probe = Simulation::new(Arc::clone(&minute)).run(None);
    let sim_s = probe.end_time_ns as f64 / 1e9;
    let plain = seconds(runs, || {
        std::hint::black_box(Simulation::new(Arc::clone(&minute)).run(None));
    });
    let log_path: PathBuf = tmp.join("minute.mcap");
    let logged = seconds(runs, || {
        let _ = std::fs::remove_file(&log_path);
        let log = McapLog::create(&log_path, &Arc::new(vworks_se::describe(&minute)), 1).unwrap();
        std::hint::black_box(Simulation::new(Arc::clone(&minute)).with_log(log).run(None));
    });
    println!(
        "(b) 4 robots, {sim_s:.1} simulated s, 4 ms cycles, {} cycles, {} queries: {:.1} ms = {:.0}x real time; with the full log {:.1} ms = {:.0}x real time",
        probe.cycles,
        probe.queries,
        plain * 1e3,
        sim_s / plain,
        logged * 1e3,
        sim_s / logged
    );
    // (d) Cost per cycle against the number of robots.
    let mut per_cycle = Vec::new();
    for n in [1usize, 4, 16, 64] {
        let cell = grid_cell(&tmp.join(format!("n{n}")), n, 2);
        let until = Some(4_000_000_000);
        let probe = Simulation::new(Arc::clone(&cell)).run(until);
        let wall = seconds(runs, || {
            std::hint::black_box(Simulation::new(Arc::clone(&cell)).run(until));
        });
        let cost = wall / probe.cycles as f64;
        per_cycle.push((n, cost));
        println!(
            "(d) {n:>2} robots: {:.2} µs per cycle ({} cycles, {:.1} queries per cycle)",
            cost * 1e6,
            probe.cycles,
            probe.queries as f64 / probe.cycles as f64
        );
    }
    if let (Some((_, four)), Some((_, sixty_four))) = (per_cycle.get(1), per_cycle.get(3)) {
        println!(
            "(d) 64 robots cost {:.1}x the per-cycle cost of 4",
            sixty_four / four
        );
    }
    let mut g = c.benchmark_group("scaling");
    g.sample_size(10);
    g.bench_function("four_robots_one_minute", |b| {
        b.iter(|| Simulation::new(Arc::clone(&minute)).run(None))
    });
    g.finish();
    let _ = std::fs::remove_dir_all(&tmp);
}

criterion_group!(benches, scaling);
criterion_main!(benches);
