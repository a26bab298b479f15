//! Cycle times of the bundled workcells with every motion flying by its points
//! (`default_zone = "10mm"` for every robot) against stopping at them (`"fine"`); zones
//! written in the programs are kept either way. The table in BENCHMARKS.md ("Zones") is
//! this program's output:
//!
//! ```text
//! cargo run --release -p vworks-se --example zone_cycle_times
//! ```

use std::path::Path;
use std::sync::Arc;

use vworks_se::Simulation;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../workcells");
    let mut names: Vec<String> = std::fs::read_dir(&root)?
        .filter_map(|e| e.ok())
        .filter(|e| e.path().join("cell.toml").is_file())
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    println!("| cell | outcome | fine (s) | zone 10mm (s) | difference |");
    println!("|---|---|---:|---:|---:|");
    for name in names {
        let cell = vworks_cell::load(&root.join(&name).join("cell.toml"))?;
        let mut end = [0i64; 2];
        let mut outcome = String::new();
        for (k, zone) in [None, Some(0.01)].into_iter().enumerate() {
            let mut c = cell.clone();
            for r in &mut c.robots {
                r.default_zone = zone;
            }
            let r = Simulation::new(Arc::new(c)).run(None);
            end[k] = r.end_time_ns;
            outcome = r.outcome.name().to_string();
        }
        let (fine, zoned) = (end[0] as f64 / 1e9, end[1] as f64 / 1e9);
        println!(
            "| {name} | {outcome} | {fine:.3} | {zoned:.3} | {:+.3} s ({:+.1} %) |",
            zoned - fine,
            100.0 * (zoned - fine) / fine
        );
    }
    Ok(())
}
