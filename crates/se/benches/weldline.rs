//! The weldline cell with collision checks: simulated seconds per wall second (target
//! ≥ 1000× real time). Criterion reports the wall time of one whole run; the ratio is
//! printed once.

#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)] // benches fail by panicking

use std::path::PathBuf;
use std::sync::Arc;

use criterion::{Criterion, criterion_group, criterion_main};
use vworks_se::Simulation;

fn weldline(c: &mut Criterion) {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../workcells/weldline/cell.toml");
    let cell = Arc::new(vworks_cell::load(&path).unwrap());
    let probe = Simulation::new(Arc::clone(&cell)).run(None);
    let t0 = std::time::Instant::now();
    let runs = 5;
    for _ in 0..runs {
        std::hint::black_box(Simulation::new(Arc::clone(&cell)).run(None));
    }
    let wall = t0.elapsed().as_secs_f64() / runs as f64;
    println!(
        "weldline: {:.3} simulated s in {:.2} ms wall: {:.0}x real time ({} cycles, {} collision queries)",
        probe.end_time_ns as f64 / 1e9,
        wall * 1e3,
        probe.end_time_ns as f64 / 1e9 / wall,
        probe.cycles,
        probe.queries
    );
    let mut g = c.benchmark_group("simulation");
    g.sample_size(20);
    g.bench_function("weldline_with_collisions", |b| {
        b.iter(|| Simulation::new(Arc::clone(&cell)).run(None))
    });
    g.finish();
}

criterion_group!(benches, weldline);
criterion_main!(benches);
