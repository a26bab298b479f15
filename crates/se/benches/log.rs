//! What the MCAP log costs: the largest bundled example (handoff: 63 simulated seconds,
//! 15,855 cycle boundaries) run without a log and with the full log (every boundary), with
//! `/state` and `/tf` as protobuf (the default) and as JSON.
//!
//! First a paired report: runs without and with the log alternate, so a machine that
//! speeds up or slows down (a shared VM does) affects both alike; it prints the medians,
//! the median of the per-pair ratios, and the log's size per simulated minute. Then
//! criterion times each on its own.
//!
//! Logs go to the system's temp folder, or to `VWORKS_BENCH_LOG_DIR` (say `/dev/shm`, to
//! leave the disk out); the previous log is deleted before each timed run, so no run waits
//! for the page cache to drop an old file.

#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)] // benches fail by panicking

use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::time::Instant;

use criterion::{Criterion, criterion_group, criterion_main};
use vworks_cell::{Cell, load};
use vworks_log::mcaplog::{Encoding, LogOptions, McapLog};
use vworks_log::result::RunResult;
use vworks_se::Simulation;

fn logged(cell: &Arc<Cell>, path: &Path, encoding: Encoding) -> RunResult {
    let log = McapLog::create_with(
        path,
        &Arc::new(vworks_se::describe(cell)),
        LogOptions::new(1, encoding),
    )
    .unwrap();
    Simulation::new(Arc::clone(cell)).with_log(log).run(None)
}

fn seconds(f: impl FnOnce()) -> f64 {
    let t0 = Instant::now();
    f();
    t0.elapsed().as_secs_f64()
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

fn log_overhead(c: &mut Criterion) {
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../..");
    let cell = Arc::new(load(&root.join("workcells/handoff/cell.toml")).unwrap());
    let dir =
        std::env::var_os("VWORKS_BENCH_LOG_DIR").map_or_else(std::env::temp_dir, PathBuf::from);
    let path = dir.join(format!("vworks-bench-{}.mcap", std::process::id()));
    println!("logs in {}", dir.display());
    // Under `cargo test` (no `--bench`) criterion runs each function once: skip the report.
    let pairs = if std::env::args().any(|a| a == "--bench") {
        31
    } else {
        1
    };
    let encodings = [(Encoding::Protobuf, "protobuf"), (Encoding::Json, "json")];
    for (encoding, name) in encodings {
        let (mut plain, mut with_log, mut ratios) = (Vec::new(), Vec::new(), Vec::new());
        let mut end = 0;
        for _ in 0..pairs {
            let a = seconds(|| {
                std::hint::black_box(Simulation::new(Arc::clone(&cell)).run(None));
            });
            let _ = std::fs::remove_file(&path);
            let b = seconds(|| end = logged(&cell, &path, encoding).end_time_ns);
            plain.push(a);
            with_log.push(b);
            ratios.push(b / a);
        }
        let mb = std::fs::metadata(&path).unwrap().len() as f64 / 1e6;
        let (plain, with_log, ratio) = (median(plain), median(with_log), median(ratios));
        println!(
            "handoff, {pairs} pairs, full log as {name}: median {:.1} ms without log, {:.1} ms with (median ratio +{:.0} %, {:.0}x real time); {mb:.2} MB = {:.2} MB per simulated minute",
            plain * 1e3,
            with_log * 1e3,
            (ratio - 1.0) * 100.0,
            end as f64 / 1e9 / with_log,
            mb / (end as f64 / 60e9),
        );
    }
    let mut g = c.benchmark_group("log");
    g.sample_size(10);
    g.bench_function("handoff_without_log", |b| {
        b.iter(|| Simulation::new(Arc::clone(&cell)).run(None))
    });
    for (encoding, name) in encodings {
        g.bench_function(format!("handoff_full_log_{name}"), |b| {
            b.iter(|| logged(&cell, &path, encoding))
        });
    }
    g.finish();
    let _ = std::fs::remove_file(&path);
}

criterion_group!(benches, log_overhead);
criterion_main!(benches);
