//! `vworks sweep`: checks a sweep file (its variables, its objective, where it writes),
//! runs every variant on all cores (or `--jobs N`) with a progress bar on a terminal,
//! streams the table (CSV, or JSON lines for `.jsonl`) as rows finish, then writes the
//! page (a chart of the objective and the best variants) from the table and prints the
//! best. Every output goes through a temporary file (`vworks_model::output`). See
//! `docs/sweep.md`.

use std::io::IsTerminal;
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Duration;

use vworks_cell::{Cell, Disk, Loader};
use vworks_model::output::{Output, OutputError};
use vworks_sweep::run::RunOptions;
use vworks_sweep::stream::{Format, TableFile, TableWriter};
use vworks_sweep::table::{self, Best, Value};
use vworks_sweep::{Row, Sweep, run_streamed};

/// What `vworks sweep` was asked.
#[derive(clap::Args, Debug)]
pub(crate) struct Args {
    /// The sweep file (sweep.toml; see docs/sweep.md), or with --variables the workcell
    /// (a cell.toml, or a folder holding one).
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
    /// Stop a variant that runs longer than this wall time (e.g. 30s): its row's outcome
    /// is `timeout`.
    #[arg(long, value_name = "TIME")]
    pub(crate) variant_timeout: Option<String>,
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

/// Every file a workcell was read from: what no output may overwrite.
pub(crate) fn inputs_of(cell: &Cell) -> Vec<PathBuf> {
    std::iter::once(cell.file.clone())
        .chain(
            cell.sources
                .iter()
                .map(|(p, _)| p)
                .chain(cell.files.iter().map(|(p, _)| p))
                .map(PathBuf::from),
        )
        .collect()
}

/// `--variant-timeout`: a wall time above 0.
fn timeout(s: &str) -> Result<Duration, String> {
    let secs = vworks_wslc::units::parse_quantity(s).and_then(|q| q.si(vworks_vm::Dim::TIME).ok());
    match secs {
        Some(t) if t > 0.0 && t < 1e9 => Ok(Duration::from_secs_f64(t)),
        _ => Err(format!(
            "--variant-timeout `{s}` is not a time above 0; write e.g. 30s or 500ms"
        )),
    }
}

/// `vworks sweep --variables CELL`: every value a sweep may vary, one per line.
fn list_variables(cell: &Path) -> Result<ExitCode, String> {
    let loader = Loader::new(cell, &Disk).map_err(|e| e.to_string())?;
    for v in loader.variables() {
        crate::out!("{v}");
    }
    Ok(ExitCode::SUCCESS)
}

/// What the rows said, counted as they pass, and the best kept.
struct Tally {
    rows: usize,
    feasible: usize,
    collided: usize,
    outcomes: std::collections::BTreeMap<String, usize>,
    logs_failed: usize,
    best: Best,
}

impl Tally {
    fn count(&self, outcome: &str) -> usize {
        self.outcomes.get(outcome).copied().unwrap_or(0)
    }
}

pub(crate) fn sweep(a: Args) -> Result<ExitCode, String> {
    if a.variables {
        return list_variables(&crate::cell_file(&a.file, "sweep --variables")?);
    }
    // Everything is checked before the first variant runs.
    let sweep = Sweep::read(&a.file, &Disk).map_err(|e| e.to_string())?;
    let loader = Loader::new(&sweep.cell, &Disk).map_err(|e| e.to_string())?;
    for p in sweep.variables.iter().flat_map(|v| &v.paths) {
        loader.check(p).map_err(|e| e.to_string())?;
    }
    let robots: Vec<String> = loader
        .base()
        .robots
        .iter()
        .map(|r| r.name.clone())
        .collect();
    let objective = a.minimize.clone().unwrap_or(sweep.minimize.clone());
    sweep
        .check_objective(&objective, &robots)
        .map_err(|m| match a.minimize {
            Some(_) => format!("--minimize: {m}"),
            None => format!("{}: minimize: {m}", a.file.display()),
        })?;
    let variant_timeout = a.variant_timeout.as_deref().map(timeout).transpose()?;
    let stem = a.file.with_extension("");
    let out = a.out.clone().unwrap_or_else(|| stem.with_extension("csv"));
    let html = a
        .html
        .clone()
        .unwrap_or_else(|| stem.with_extension("html"));
    let mut inputs = inputs_of(loader.base());
    inputs.push(a.file.clone());
    let table_out = Output::create(&out, &inputs).map_err(|e| e.to_string())?;
    inputs.push(out.clone());
    let page_out = Output::create(&html, &inputs).map_err(|e| e.to_string())?;
    if let Some(dir) = &a.keep_logs {
        std::fs::create_dir_all(dir)
            .map_err(|e| format!("cannot create `{}`: {e}", dir.display()))?;
    }
    let names: Vec<String> = sweep.variables.iter().map(|v| v.path.clone()).collect();
    let columns = table::columns(&names, &robots);
    let format = Format::of_path(&out);
    let table_error = |e: std::io::Error| OutputError::write(&out, &e).to_string();
    let mut writer = TableWriter::new(table_out, format, columns.clone());
    // A table that cannot be written does not stop the sweep: the best are still printed.
    let mut write_error = writer.start().err();
    let options = RunOptions {
        jobs: a.jobs,
        until_ns: sweep.until_ns,
        keep_logs: a.keep_logs.clone(),
        variant_timeout,
    };
    let stop = Arc::new(AtomicBool::new(false));
    let flag = Arc::clone(&stop);
    let _ = ctrlc::set_handler(move || flag.store(true, Ordering::Relaxed));
    let count = sweep.count();
    let bar = (!a.quiet && std::io::stderr().is_terminal()).then(|| {
        let style = indicatif::ProgressStyle::with_template(
            "{bar:40} {pos}/{len} variants, {per_sec}, {eta} left",
        )
        .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar());
        indicatif::ProgressBar::new(count as u64).with_style(style)
    });
    let mut tally = Tally {
        rows: 0,
        feasible: 0,
        collided: 0,
        outcomes: std::collections::BTreeMap::new(),
        logs_failed: 0,
        best: Best::new(&columns, &objective, a.best),
    };
    let started = std::time::Instant::now();
    run_streamed(
        &loader,
        count,
        &|i| sweep.variant(i),
        &options,
        &|done| {
            if let Some(b) = &bar {
                b.set_position(done as u64);
            }
        },
        Some(&stop),
        &mut |row: Row| {
            let values = table::row_values(&names, &robots, &row);
            tally.rows += 1;
            tally.feasible += usize::from(row.feasible());
            tally.collided += usize::from(row.collisions > 0);
            *tally.outcomes.entry(row.outcome.clone()).or_default() += 1;
            tally.logs_failed += usize::from(row.log_failed);
            tally.best.offer(&columns, &values);
            if write_error.is_none() {
                write_error = writer.write(&values).err();
            }
        },
    );
    let seconds = started.elapsed().as_secs_f64();
    if let Some(b) = &bar {
        b.finish_and_clear();
    }
    let interrupted = stop.load(Ordering::Relaxed);
    let mut failed = false;
    let mut fail = |m: String| {
        eprintln!("error: {m}");
        failed = true;
    };
    // The table, then the page made from it (the old files stay if either fails).
    let table_written = match write_error {
        Some(e) => Err(table_error(e)),
        None => writer.into_inner().commit().map_err(|e| e.to_string()),
    };
    match &table_written {
        Ok(()) if std::fs::metadata(&out).is_ok_and(|m| m.is_file()) => {
            match write_page(
                page_out,
                &a.file,
                &out,
                format,
                columns.clone(),
                &names,
                &objective,
                &tally.best,
            ) {
                Ok(()) => eprintln!("wrote {} and {}", out.display(), html.display()),
                Err(m) => fail(m),
            }
        }
        Ok(()) => eprintln!(
            "wrote {}; no page: it is made from the table, which is not a file",
            out.display()
        ),
        Err(m) => fail(format!(
            "{m}; the page is made from the table: not written either"
        )),
    }
    if tally.logs_failed > 0 {
        fail(format!(
            "the logs of {} variants could not be written (`--keep-logs`): their rows say why",
            tally.logs_failed
        ));
    }
    let jobs = match a.jobs {
        0 => std::thread::available_parallelism().map_or(1, usize::from),
        n => n,
    };
    eprintln!(
        "{} variants in {seconds:.2} s ({:.0} variants/s, {jobs} jobs): {} completed, {} with a collision, {} deadlocked, {} with an error, {} stopped at `until`, {} timed out, {} invalid{}",
        tally.rows,
        tally.rows as f64 / seconds.max(1e-9),
        tally.feasible,
        tally.collided,
        tally.count("deadlock"),
        tally.count("error"),
        tally.count("until"),
        tally.count("timeout"),
        tally.count("invalid"),
        if interrupted { " (interrupted)" } else { "" },
    );
    print_best(&columns, &names, &objective, &tally.best);
    Ok(if failed {
        ExitCode::FAILURE
    } else if interrupted {
        ExitCode::from(130)
    } else {
        ExitCode::SUCCESS
    })
}

/// The page, from the table file just written (read back a row at a time).
#[allow(clippy::too_many_arguments)]
fn write_page(
    mut page: Output,
    sweep: &Path,
    table: &Path,
    format: Format,
    columns: Vec<String>,
    names: &[String],
    objective: &str,
    best: &Best,
) -> Result<(), String> {
    let rows = TableFile::new(table, format, columns);
    let title = sweep.display().to_string();
    vworks_sweep::html::write_page(&mut page, &title, &rows, names, objective, &best.rows())
        .map_err(|e| OutputError::write(page.path(), &e).to_string())?;
    page.commit().map_err(|e| e.to_string())
}

fn print_best(columns: &[String], names: &[String], objective: &str, best: &Best) {
    let column = |n: &str| columns.iter().position(|c| c == n);
    let best = best.rows();
    if best.is_empty() {
        crate::out!("no variant completed without a collision");
        return;
    }
    let k = column(objective).unwrap_or(0);
    crate::out!("best by {objective} (completed, no collision):");
    for row in best {
        let values: Vec<String> = names
            .iter()
            .filter_map(|n| column(n))
            .map(|c| format!("{} = {}", columns[c], cell(&row[c])))
            .collect();
        crate::out!(
            "  variant {}: {objective} {}  ({})",
            cell(&row[0]),
            cell(&row[k]),
            values.join(", ")
        );
    }
}

fn cell(v: &Value) -> String {
    match v {
        Value::Num(x) => format!("{}", (x * 1e9).round() / 1e9),
        Value::Int(i) => i.to_string(),
        Value::Text(s) => s.clone(),
        Value::Empty => "–".into(),
    }
}
