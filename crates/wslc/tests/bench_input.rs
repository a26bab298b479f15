//! The compile benchmark's generated program is valid and as large as claimed.

#![allow(clippy::panic, clippy::unwrap_used, clippy::expect_used)] // tests fail by panicking

mod generator {
    include!("../benches/gen.rs");
}

#[test]
fn generated_program_compiles_and_has_10k_lines() {
    let src = generator::program(10_000);
    assert!(src.lines().count() >= 10_000);
    let out = vworks_wslc::compile("bench.wsl", &src).unwrap_or_else(|e| panic!("{e}"));
    assert!(
        out.module.procs.len() > 500,
        "{} procedures",
        out.module.procs.len()
    );
}
