//! N irb120 arms on a grid, 1.2 m apart, each looping a joint move and a straight move
//! (the cell of the `scaling` bench's (d)), run for 4 simulated seconds; prints the cost
//! per cycle. For profilers and instruction counts (`bench/instructions.sh`):
//! `cargo run --release -p vworks-se --example grid -- 64 5`.

use std::path::Path;
use std::sync::Arc;
use std::time::Instant;

fn main() {
    let mut args = std::env::args().skip(1);
    let (Some(n), runs) = (
        args.next().and_then(|a| a.parse::<usize>().ok()),
        args.next().and_then(|a| a.parse::<u32>().ok()).unwrap_or(5),
    ) else {
        eprintln!("usage: grid ROBOTS [RUNS]");
        std::process::exit(2);
    };
    let dir = std::env::temp_dir().join(format!("vworks-grid-{n}-{}", std::process::id()));
    let cell = match write_and_load(&dir, n) {
        Ok(c) => Arc::new(c),
        Err(e) => {
            eprintln!("error: {e}");
            std::process::exit(1);
        }
    };
    let _ = std::fs::remove_dir_all(&dir);
    let until = Some(4_000_000_000);
    let probe = vworks_se::Simulation::new(Arc::clone(&cell)).run(until);
    let t0 = Instant::now();
    for _ in 0..runs {
        std::hint::black_box(vworks_se::Simulation::new(Arc::clone(&cell)).run(until));
    }
    let wall = t0.elapsed().as_secs_f64() / f64::from(runs.max(1));
    println!(
        "{n} robots: {:.2} µs per cycle ({} cycles, {} queries)",
        wall / probe.cycles.max(1) as f64 * 1e6,
        probe.cycles,
        probe.queries
    );
}

fn write_and_load(dir: &Path, n: usize) -> Result<vworks_cell::Cell, String> {
    std::fs::create_dir_all(dir).map_err(|e| e.to_string())?;
    let side = (n as f64).sqrt().ceil() as usize;
    let mut toml = String::from("name = \"grid\"\ncycle = \"4ms\"\nclearance = \"5mm\"\n");
    for i in 0..n {
        let (x, y) = ((i % side) as f64 * 1200.0, (i / side) as f64 * 1200.0);
        toml += &format!(
            "[[robot]]\nname = \"r{i}\"\nmodel = \"irb120\"\nprogram = \"arm.wsl\"\nbase = {{ xyz = [\"{x}mm\", \"{y}mm\", \"0mm\"] }}\n"
        );
    }
    let program = "proc main() {\n    var i = 0;\n    while i < 2 {\n        move_j joints(40deg, -20deg, 30deg, 0deg, 60deg, 0deg) speed 30%;\n        move_l pose(300mm, -150mm, 350mm, 180deg, 0deg, 0deg) speed 400mm/s;\n        i += 1;\n    }\n}\n";
    std::fs::write(dir.join("cell.toml"), toml).map_err(|e| e.to_string())?;
    std::fs::write(dir.join("arm.wsl"), program).map_err(|e| e.to_string())?;
    vworks_cell::load(&dir.join("cell.toml")).map_err(|e| e.to_string())
}
