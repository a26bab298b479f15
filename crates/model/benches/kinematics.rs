//! FK of all links, analytic IK, numeric IK (targets: ≤ 300 ns, ≤ 3 µs, ≤ 50 µs).

#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)] // benches fail by panicking

use criterion::{Criterion, criterion_group, criterion_main};
use std::hint::black_box;
use vworks_model::builtin;

fn kinematics(c: &mut Criterion) {
    let irb = builtin::load("irb120").unwrap();
    let ur5 = builtin::load("ur5").unwrap();
    let q = [0.3, -0.4, 0.5, 0.6, -0.7, 0.8];
    let mut frames = irb.frames_buffer();
    c.bench_function("fk_all_links/irb120", |b| {
        b.iter(|| irb.fk_into(black_box(&q), &mut frames))
    });
    let mut frames_ur = ur5.frames_buffer();
    c.bench_function("fk_all_links/ur5", |b| {
        b.iter(|| ur5.fk_into(black_box(&q), &mut frames_ur))
    });

    let target = irb.flange(&q);
    let near = [0.31, -0.41, 0.49, 0.6, -0.69, 0.8];
    let mut out = [0.0; 6];
    c.bench_function("ik_analytic/irb120", |b| {
        b.iter(|| irb.ik(black_box(&target), &near, &mut out).unwrap())
    });

    // Numeric: from the joints of the previous step (as along a move), and from home.
    let target = ur5.flange(&q);
    c.bench_function("ik_numeric/ur5_from_nearby", |b| {
        b.iter(|| ur5.ik(black_box(&target), &near, &mut out).unwrap())
    });
    c.bench_function("ik_numeric/ur5_from_home", |b| {
        b.iter(|| ur5.ik(black_box(&target), &[0.0; 6], &mut out).unwrap())
    });
}

criterion_group!(benches, kinematics);
criterion_main!(benches);
