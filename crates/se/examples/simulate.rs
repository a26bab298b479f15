//! Runs a workcell N times and prints the real-time factor: `cargo run --release -p
//! vworks-se --example simulate -- workcells/weldline/cell.toml 20` (for profiling).

fn main() {
    let mut args = std::env::args().skip(1);
    let Some(path) = args.next() else {
        eprintln!("usage: simulate CELL.toml [RUNS]");
        std::process::exit(2);
    };
    let runs: u32 = args.next().and_then(|n| n.parse().ok()).unwrap_or(10);
    let cell = match vworks_cell::load(std::path::Path::new(&path)) {
        Ok(c) => std::sync::Arc::new(c),
        Err(e) => {
            eprintln!("error: {e}");
            std::process::exit(1);
        }
    };
    let t0 = std::time::Instant::now();
    let mut end = 0;
    for _ in 0..runs {
        end = vworks_se::Simulation::new(std::sync::Arc::clone(&cell))
            .run(None)
            .end_time_ns;
    }
    let wall = t0.elapsed().as_secs_f64() / f64::from(runs);
    println!(
        "{:.3} simulated s, {:.2} ms wall per run: {:.0}x real time",
        end as f64 / 1e9,
        wall * 1e3,
        end as f64 / 1e9 / wall
    );
}
