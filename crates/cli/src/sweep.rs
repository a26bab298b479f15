//! `vworks sweep`: runs every variant of a sweep file on all cores (or `--jobs N`), with a
//! progress bar on a terminal, and writes the table (CSV, or JSON lines for `.jsonl`) and
//! the page (a chart of the objective and the best variants) beside the sweep file. See
//! `docs/sweep.md`.

use std::io::IsTerminal;
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};

use vworks_cell::{Disk, Loader};
use vworks_sweep::run::RunOptions;
use vworks_sweep::{Sweep, Table, run_variants};

/// What `vworks sweep` was asked.
#[derive(clap::Args, Debug)]
pub(crate) struct Args {
    /// The sweep file (sweep.toml; see docs/sweep.md), or with --variables the workcell.
    pub(crate) file: PathBuf,
    /// Threads (default: one per core).
    #[arg(short, long, default_value_t = 0)]
    pub(crate) jobs: usize,
    /// The table to write: .csv, or .jsonl for JSON lines (default: beside the sweep
    /// file, SWEEP.csv).
    #[arg(short, long)]
    pub(crate) out: Option<PathBuf>,
    /// The page to write (default: SWEEP.html beside the sweep file).
    #[arg(long)]
    pub(crate) html: Option<PathBuf>,
    /// Write each variant's MCAP log into this folder (variant-00000.mcap, …).
    #[arg(long)]
    pub(crate) keep_logs: Option<PathBuf>,
    /// The column to minimize among completed runs without collision (default: the
    /// sweep file's `minimize`, else end_time).
    #[arg(long)]
    pub(crate) minimize: Option<String>,
    /// How many best variants to print.
    #[arg(long, default_value_t = 5)]
    pub(crate) best: usize,
    /// No progress bar.
    #[arg(short, long)]
    pub(crate) quiet: bool,
    /// List every value of the workcell FILE a sweep may vary, and stop.
    #[arg(long)]
    pub(crate) variables: bool,
}

fn write(path: &Path, text: &str) -> Result<(), String> {
    std::fs::write(path, text).map_err(|e| {
        format!(
            "cannot write `{}`: {e}; check that its folder exists and is writable",
            path.display()
        )
    })
}

/// `vworks sweep --variables CELL`: every value a sweep may vary, one per line.
fn list_variables(cell: &Path) -> Result<ExitCode, String> {
    let loader = Loader::new(cell, &Disk).map_err(|e| e.to_string())?;
    for v in loader.variables() {
        crate::out!("{v}");
    }
    Ok(ExitCode::SUCCESS)
}

pub(crate) fn sweep(a: Args) -> Result<ExitCode, String> {
    if a.variables {
        return list_variables(&a.file);
    }
    let sweep = Sweep::read(&a.file, &Disk).map_err(|e| e.to_string())?;
    let loader = Loader::new(&sweep.cell, &Disk).map_err(|e| e.to_string())?;
    for p in sweep.variables.iter().flat_map(|v| &v.paths) {
        loader.check(p).map_err(|e| e.to_string())?;
    }
    let variants = sweep.variants();
    if let Some(dir) = &a.keep_logs {
        std::fs::create_dir_all(dir)
            .map_err(|e| format!("cannot create `{}`: {e}", dir.display()))?;
    }
    let options = RunOptions {
        jobs: a.jobs,
        until_ns: sweep.until_ns,
        keep_logs: a.keep_logs.clone(),
        ..RunOptions::default()
    };
    let stop = Arc::new(AtomicBool::new(false));
    let flag = Arc::clone(&stop);
    let _ = ctrlc::set_handler(move || flag.store(true, Ordering::Relaxed));
    let bar = (!a.quiet && std::io::stderr().is_terminal()).then(|| {
        let style = indicatif::ProgressStyle::with_template(
            "{bar:40} {pos}/{len} variants, {per_sec}, {eta} left",
        )
        .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar());
        indicatif::ProgressBar::new(variants.len() as u64).with_style(style)
    });
    let started = std::time::Instant::now();
    let rows = run_variants(
        &loader,
        &variants,
        &options,
        &|done| {
            if let Some(b) = &bar {
                b.set_position(done as u64);
            }
        },
        Some(&stop),
    );
    let seconds = started.elapsed().as_secs_f64();
    if let Some(b) = &bar {
        b.finish_and_clear();
    }
    let names: Vec<String> = sweep.variables.iter().map(|v| v.path.clone()).collect();
    let table = Table::of_cell(&names, loader.base(), &rows);
    let feasible: Vec<bool> = rows.iter().map(vworks_sweep::Row::feasible).collect();
    let objective = a.minimize.clone().unwrap_or(sweep.minimize.clone());
    let best = table.best(&objective, a.best, &feasible)?;
    let stem = a.file.with_extension("");
    let out = a.out.clone().unwrap_or_else(|| stem.with_extension("csv"));
    let is_jsonl = out.extension().is_some_and(|e| e == "jsonl" || e == "json");
    write(
        &out,
        &if is_jsonl {
            table.json_lines()
        } else {
            table.csv()
        },
    )?;
    let html = a
        .html
        .clone()
        .unwrap_or_else(|| stem.with_extension("html"));
    let title = a.file.display().to_string();
    write(
        &html,
        &vworks_sweep::html::page(&title, &table, &names, &objective, &feasible, &best),
    )?;
    let count = |o: &str| rows.iter().filter(|r| r.outcome == o).count();
    let jobs = match a.jobs {
        0 => std::thread::available_parallelism().map_or(1, usize::from),
        n => n,
    };
    eprintln!(
        "{} variants in {seconds:.2} s ({:.0} variants/s, {jobs} jobs): {} completed, {} with a collision, {} deadlocked, {} with an error, {} stopped at `until`, {} invalid{}",
        rows.len(),
        rows.len() as f64 / seconds.max(1e-9),
        rows.iter()
            .filter(|r| r.outcome == "completed" && r.collisions == 0)
            .count(),
        rows.iter().filter(|r| r.collisions > 0).count(),
        count("deadlock"),
        count("error"),
        count("until"),
        count("invalid"),
        if rows.len() < variants.len() {
            " (interrupted)"
        } else {
            ""
        },
    );
    eprintln!("wrote {} and {}", out.display(), html.display());
    let k = table.column(&objective).unwrap_or(0);
    if best.is_empty() {
        crate::out!("no variant completed without a collision");
    } else {
        crate::out!("best by {objective} (completed, no collision):");
        for i in &best {
            let row = &table.rows[*i];
            let values: Vec<String> = names
                .iter()
                .filter_map(|n| table.column(n))
                .map(|c| format!("{} = {}", table.columns[c], cell(&row[c])))
                .collect();
            crate::out!(
                "  variant {}: {objective} {}  ({})",
                cell(&row[0]),
                cell(&row[k]),
                values.join(", ")
            );
        }
    }
    Ok(if stop.load(Ordering::Relaxed) {
        ExitCode::from(130)
    } else {
        ExitCode::SUCCESS
    })
}

fn cell(v: &vworks_sweep::table::Value) -> String {
    match v {
        vworks_sweep::table::Value::Num(x) => format!("{}", (x * 1e9).round() / 1e9),
        vworks_sweep::table::Value::Int(i) => i.to_string(),
        vworks_sweep::table::Value::Text(s) => s.clone(),
        vworks_sweep::table::Value::Empty => "–".into(),
    }
}
