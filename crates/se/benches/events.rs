//! Scheduler throughput (issue 8 (c)): events per second of wall time, with no motion and
//! no collision checking in the way.
//! - ping-pong: two robots hand a signal back and forth (`signal` / `wait_signal`);
//! - set/wait_until: N robots in a ring, each waits until a shared counter reaches its
//!   turn and then advances it.
//!
//! Prints events/s once (the trace's event count over the median of 11 runs' wall time),
//! then criterion times each. `bench/compare.py` runs equivalent SimPy models.

#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)] // benches fail by panicking

use std::path::Path;
use std::sync::Arc;
use std::time::Instant;

use criterion::{Criterion, criterion_group, criterion_main};
use vworks_cell::{Cell, load};
use vworks_se::Simulation;

fn cell(dir: &Path, robots: &[(&str, String)]) -> Arc<Cell> {
    std::fs::create_dir_all(dir).unwrap();
    let mut toml = String::from("name = \"events\"\ncycle = \"4ms\"\n");
    for (i, (name, program)) in robots.iter().enumerate() {
        std::fs::write(dir.join(format!("{name}.wsl")), program).unwrap();
        toml += &format!(
            "[[robot]]\nname = \"{name}\"\nmodel = \"irb120\"\nprogram = \"{name}.wsl\"\nbase = {{ xyz = [\"{}mm\", \"0mm\", \"0mm\"] }}\n",
            i * 2000
        );
    }
    std::fs::write(dir.join("cell.toml"), toml).unwrap();
    Arc::new(load(&dir.join("cell.toml")).unwrap_or_else(|e| panic!("{e}")))
}

fn ping_pong(dir: &Path, rounds: u32) -> Arc<Cell> {
    cell(
        dir,
        &[
            (
                "a",
                format!(
                    "proc main() {{\n    for i in 0..{rounds} {{\n        signal b.ping;\n        wait_signal pong;\n    }}\n}}\n"
                ),
            ),
            (
                "b",
                format!(
                    "proc main() {{\n    for i in 0..{rounds} {{\n        wait_signal ping;\n        signal a.pong;\n    }}\n}}\n"
                ),
            ),
        ],
    )
}

fn ring(dir: &Path, n: usize, rounds: u32) -> Arc<Cell> {
    let robots: Vec<(String, String)> = (0..n)
        .map(|k| {
            (
                format!("r{k}"),
                format!(
                    "global turn = 0;\nproc main() {{\n    for i in 0..{rounds} {{\n        wait_until turn == i * {n} + {k};\n        turn += 1;\n    }}\n}}\n"
                ),
            )
        })
        .collect();
    let named: Vec<(&str, String)> = robots
        .iter()
        .map(|(a, b)| (a.as_str(), b.clone()))
        .collect();
    cell(dir, &named)
}

fn events_per_second(c: &Arc<Cell>, runs: u32) -> (usize, f64) {
    let probe = Simulation::new(Arc::clone(c)).run(None);
    assert_eq!(probe.outcome.name(), "completed", "{:?}", probe.errors);
    // The median run (as criterion reports medians): one slow run on a shared machine does
    // not move it.
    let mut walls: Vec<f64> = (0..runs)
        .map(|_| {
            let t0 = Instant::now();
            std::hint::black_box(Simulation::new(Arc::clone(c)).run(None));
            t0.elapsed().as_secs_f64()
        })
        .collect();
    walls.sort_by(f64::total_cmp);
    let wall = walls[walls.len() / 2];
    (probe.trace.len(), probe.trace.len() as f64 / wall)
}

fn events(c: &mut Criterion) {
    let bench = std::env::args().any(|a| a == "--bench");
    let (runs, rounds) = if bench { (11, 20_000) } else { (1, 200) };
    let tmp = std::env::temp_dir().join(format!("vworks-events-{}", std::process::id()));
    let pp = ping_pong(&tmp.join("pp"), rounds);
    let (n, rate) = events_per_second(&pp, runs);
    println!("(c) ping-pong: {n} events, {:.2} M events/s", rate / 1e6);
    let mut rings = Vec::new();
    for robots in [2usize, 8, 32] {
        let r = ring(
            &tmp.join(format!("ring{robots}")),
            robots,
            rounds / robots as u32,
        );
        let (n, rate) = events_per_second(&r, runs);
        println!(
            "(c) set/wait_until ring of {robots}: {n} events, {:.2} M events/s",
            rate / 1e6
        );
        rings.push((robots, r));
    }
    let mut g = c.benchmark_group("events");
    g.sample_size(10);
    g.bench_function("ping_pong", |b| {
        b.iter(|| Simulation::new(Arc::clone(&pp)).run(None))
    });
    for (robots, r) in &rings {
        g.bench_function(format!("ring_{robots}"), |b| {
            b.iter(|| Simulation::new(Arc::clone(r)).run(None))
        });
    }
    g.finish();
    let _ = std::fs::remove_dir_all(&tmp);
}

criterion_group!(benches, events);
criterion_main!(benches);
