//! Times `Simulation::run` of a workcell in-process (no load), five times: `cargo run
//! --release -p vworks-se --example time_run -- CELL`.
#![allow(clippy::unwrap_used)]
fn main() {
    let path = std::env::args()
        .nth(1)
        .unwrap_or_else(|| "bench/cells/grid4/cell.toml".into());
    let cell = std::sync::Arc::new(vworks_cell::load(std::path::Path::new(&path)).unwrap());
    for _ in 0..5 {
        let t = std::time::Instant::now();
        let r = vworks_se::Simulation::new(std::sync::Arc::clone(&cell)).run(None);
        let s = t.elapsed().as_secs_f64();
        println!(
            "{:.1} ms, {:.0}x real time",
            s * 1e3,
            r.end_time_ns as f64 / 1e9 / s
        );
    }
}
