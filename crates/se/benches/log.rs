//! What the MCAP log costs: the largest bundled example (handoff: 63 simulated seconds,
//! 15,855 cycle boundaries) run without a log and with the full log (every boundary).
//! Prints the ratio and the log's size per simulated minute once, then lets criterion
//! time both.

#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)] // benches fail by panicking

use std::path::PathBuf;
use std::sync::Arc;
use std::time::Instant;

use criterion::{Criterion, criterion_group, criterion_main};
use vworks_se::engine::Simulation;
use vworks_se::mcaplog::McapLog;
use vworks_se::workcell::{Cell, load};

fn logged(cell: &Arc<Cell>, path: &std::path::Path) -> vworks_se::engine::RunResult {
    let log = McapLog::create(path, cell, 1).unwrap();
    Simulation::new(Arc::clone(cell)).with_log(log).run(None)
}

fn log_overhead(c: &mut Criterion) {
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../..");
    let cell = Arc::new(load(&root.join("workcells/handoff/cell.toml")).unwrap());
    let path = std::env::temp_dir().join(format!("vworks-bench-{}.mcap", std::process::id()));
    let runs = 5;
    let t0 = Instant::now();
    for _ in 0..runs {
        std::hint::black_box(Simulation::new(Arc::clone(&cell)).run(None));
    }
    let plain = t0.elapsed().as_secs_f64() / runs as f64;
    let t0 = Instant::now();
    let mut r = None;
    for _ in 0..runs {
        r = Some(logged(&cell, &path));
    }
    let with_log = t0.elapsed().as_secs_f64() / runs as f64;
    let r = r.unwrap();
    let bytes = std::fs::metadata(&path).unwrap().len() as f64;
    let minutes = r.end_time_ns as f64 / 60e9;
    println!(
        "handoff: {:.1} ms without log, {:.1} ms with the full log (+{:.0} %); log {:.2} MB = {:.2} MB per simulated minute; {:?}",
        plain * 1e3,
        with_log * 1e3,
        (with_log / plain - 1.0) * 100.0,
        bytes / 1e6,
        bytes / 1e6 / minutes,
        r.log_counts
    );
    let mut g = c.benchmark_group("log");
    g.sample_size(10);
    g.bench_function("handoff_without_log", |b| {
        b.iter(|| Simulation::new(Arc::clone(&cell)).run(None))
    });
    g.bench_function("handoff_with_full_log", |b| b.iter(|| logged(&cell, &path)));
    g.finish();
    let _ = std::fs::remove_file(&path);
}

criterion_group!(benches, log_overhead);
criterion_main!(benches);
