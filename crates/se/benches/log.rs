//! What the MCAP log costs: the largest bundled example (handoff: 63 simulated seconds,
//! 15,855 cycle boundaries) run without a log and with the full log (every boundary), with
//! `/state` and `/tf` as protobuf (the default) and as JSON. Prints the overhead and the log's size per
//! simulated minute once, then lets criterion time each.

#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)] // benches fail by panicking

use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::time::Instant;

use criterion::{Criterion, criterion_group, criterion_main};
use vworks_se::engine::{RunResult, Simulation};
use vworks_se::mcaplog::{Encoding, LogOptions, McapLog};
use vworks_se::workcell::{Cell, load};

fn logged(cell: &Arc<Cell>, path: &Path, encoding: Encoding) -> RunResult {
    let log = McapLog::create_with(path, cell, LogOptions::new(1, encoding)).unwrap();
    Simulation::new(Arc::clone(cell)).with_log(log).run(None)
}

fn mean_secs(runs: u32, mut f: impl FnMut()) -> f64 {
    let t0 = Instant::now();
    for _ in 0..runs {
        f();
    }
    t0.elapsed().as_secs_f64() / f64::from(runs)
}

fn log_overhead(c: &mut Criterion) {
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../..");
    let cell = Arc::new(load(&root.join("workcells/handoff/cell.toml")).unwrap());
    let path = std::env::temp_dir().join(format!("vworks-bench-{}.mcap", std::process::id()));
    // Under `cargo test` (no `--bench`) criterion runs each function once: skip the report.
    let runs = if std::env::args().any(|a| a == "--bench") {
        10
    } else {
        1
    };
    let plain = mean_secs(runs, || {
        std::hint::black_box(Simulation::new(Arc::clone(&cell)).run(None));
    });
    println!("handoff: {:.1} ms without log", plain * 1e3);
    let encodings = [(Encoding::Protobuf, "protobuf"), (Encoding::Json, "json")];
    for (tf, name) in encodings {
        let mut end = 0;
        let wall = mean_secs(runs, || end = logged(&cell, &path, tf).end_time_ns);
        let mb = std::fs::metadata(&path).unwrap().len() as f64 / 1e6;
        println!(
            "handoff, full log, {name}: {:.1} ms (+{:.0} %, {:.0}x real time); {mb:.2} MB = {:.2} MB per simulated minute",
            wall * 1e3,
            (wall / plain - 1.0) * 100.0,
            end as f64 / 1e9 / wall,
            mb / (end as f64 / 60e9),
        );
    }
    let mut g = c.benchmark_group("log");
    g.sample_size(10);
    g.bench_function("handoff_without_log", |b| {
        b.iter(|| Simulation::new(Arc::clone(&cell)).run(None))
    });
    for (tf, name) in encodings {
        g.bench_function(format!("handoff_full_log_{name}"), |b| {
            b.iter(|| logged(&cell, &path, tf))
        });
    }
    g.finish();
    let _ = std::fs::remove_file(&path);
}

criterion_group!(benches, log_overhead);
criterion_main!(benches);
