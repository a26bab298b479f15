//! Compile time of a generated 10,000-line module (target: under 100 ms).

#![allow(clippy::panic, clippy::unwrap_used, clippy::expect_used)] // tests fail by panicking

use criterion::{Criterion, criterion_group, criterion_main};

mod generator {
    include!("gen.rs");
}

fn compile_10k(c: &mut Criterion) {
    let src = generator::program(10_000);
    let lines = src.lines().count();
    assert!(lines >= 10_000, "generated {lines} lines");
    assert!(
        vworks_wslc::compile("bench.wsl", &src).is_ok(),
        "the benchmark program must compile"
    );
    let mut g = c.benchmark_group("compile");
    g.sample_size(30);
    g.bench_function(format!("generated_{lines}_lines"), |b| {
        b.iter(|| vworks_wslc::compile("bench.wsl", std::hint::black_box(&src)))
    });
    g.finish();
}

criterion_group!(benches, compile_10k);
criterion_main!(benches);
