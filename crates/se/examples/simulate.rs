//! Runs a workcell N times and prints the real-time factor: `cargo run --release -p
//! vworks-se --example simulate -- workcells/weldline/cell.toml 20` (for profiling);
//! `--log FILE` writes the full log of every run (each run rewrites it).

use std::path::PathBuf;
use std::sync::Arc;

fn main() {
    let mut path = None;
    let mut runs: u32 = 10;
    let mut log: Option<PathBuf> = None;
    let mut args = std::env::args().skip(1);
    while let Some(a) = args.next() {
        if a == "--log" {
            log = args.next().map(PathBuf::from);
        } else if path.is_none() {
            path = Some(a);
        } else {
            runs = a.parse().unwrap_or(runs);
        }
    }
    let Some(path) = path else {
        eprintln!("usage: simulate CELL.toml [RUNS] [--log FILE]");
        std::process::exit(2);
    };
    let cell = match vworks_cell::load(std::path::Path::new(&path)) {
        Ok(c) => Arc::new(c),
        Err(e) => {
            eprintln!("error: {e}");
            std::process::exit(1);
        }
    };
    let info = Arc::new(vworks_se::describe(&cell));
    let t0 = std::time::Instant::now();
    let mut end = 0;
    for _ in 0..runs {
        let mut sim = vworks_se::Simulation::new(Arc::clone(&cell));
        if let Some(file) = &log {
            match vworks_log::mcaplog::McapLog::create(file, &info, 1) {
                Ok(l) => sim = sim.with_log(l),
                Err(e) => {
                    eprintln!("error: {e}");
                    std::process::exit(1);
                }
            }
        }
        end = sim.run(None).end_time_ns;
    }
    let wall = t0.elapsed().as_secs_f64() / f64::from(runs.max(1));
    println!(
        "{:.3} simulated s, {:.2} ms wall per run: {:.0}x real time",
        end as f64 / 1e9,
        wall * 1e3,
        end as f64 / 1e9 / wall
    );
}
