//! `vworks sweep`: checks a sweep file (its variables, its objective, where it writes),
//! runs every variant on all cores (or `--jobs N`) with a progress bar on a terminal,
//! streams the table (CSV, or JSON lines for `.jsonl`) as rows finish, then writes the
//! page (a chart of the objective and the best variants) from the table and prints the
//! best. The table file states its columns' units (`robot.r2.base.xyz.0 [mm]`,
//! `end_time [s]`) and shows a variable in the unit its values were written in. With
//! `--keep-logs DIR` it writes the variants' logs, or only some (`--keep-logs-variants
//! 3,7,10-12`, `--keep-logs-best N`: a log leaves the folder as soon as its variant has
//! dropped out of the best N, so the folder never holds many more than N). Every output
//! goes through a temporary file (`vworks_model::output`). It takes a folder holding a
//! sweep file, and says what to do when given a workcell instead ([`Kind`]: `run` and
//! `check` say so of a sweep file). See `docs/sweep.md`.

use std::collections::BTreeSet;
use std::io::IsTerminal;
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex, PoisonError};
use std::time::Duration;

use vworks_app::inputs_of;
use vworks_cell::{Cell, Disk, Loader};
use vworks_log::result::Outcome;
use vworks_model::output::{Output, OutputError};
use vworks_sweep::run::{RunOptions, VariantSet};
use vworks_sweep::stream::{Format, TableFile, TableWriter};
use vworks_sweep::table::{self, Best, Value};
use vworks_sweep::{Row, RowOutcome, Sweep, Unit, per_second, run_streamed};

use crate::files::{self, Kind, kind_of};
use crate::output::out;

/// What `vworks sweep` was asked.
#[derive(clap::Args, Debug)]
pub(crate) struct Args {
    /// The sweep file (sweep.toml; see docs/sweep.md) or a folder holding one, or with
    /// --variables the workcell (a cell.toml, or a folder holding one).
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
    #[arg(long, value_name = "DIR")]
    pub(crate) keep_logs: Option<PathBuf>,
    /// With --keep-logs: keep only the logs of the N best variants by the objective
    /// (and of --keep-logs-variants); the others are removed as the sweep goes.
    #[arg(long, value_name = "N", requires = "keep_logs", value_parser = clap::value_parser!(u64).range(1..))]
    pub(crate) keep_logs_best: Option<u64>,
    /// With --keep-logs: write only these variants' logs, e.g. 3,7,10-12.
    #[arg(long, value_name = "LIST", requires = "keep_logs")]
    pub(crate) keep_logs_variants: Option<String>,
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
    /// List every value of the workcell FILE a sweep may vary, with its value, and stop.
    #[arg(long)]
    pub(crate) variables: bool,
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

/// `vworks sweep --variables CELL`: every value a sweep may vary, one per line, with
/// its value: as the workcell file writes it (`robot.r2.base.xyz.0 = 600mm`), else the
/// value it has without it, marked `(not in the file)` (a param's, as its program
/// declares it).
fn list_variables(cell: &Path) -> Result<ExitCode, String> {
    let loader = Loader::new(cell, &Disk).map_err(|e| e.to_string())?;
    // The loader read it just now; read again for the values as written.
    let text = std::fs::read_to_string(cell)
        .map_err(|e| format!("cannot read `{}`: {e}", cell.display()))?;
    let file: toml::Table = text
        .parse()
        .map_err(|e: toml::de::Error| format!("{}: {}", cell.display(), e.message()))?;
    for v in loader.variables() {
        match written_at(&file, v) {
            Some(x) => out!("{v} = {}", as_written(x)),
            None => out!("{v} = {}  (not in the file)", default_of(loader.base(), v)),
        }
    }
    Ok(ExitCode::SUCCESS)
}

/// The value at a variable's dotted path in the workcell file, if the file writes it
/// (robots, devices and parts found by name, arrays by index).
fn written_at<'t>(file: &'t toml::Table, path: &str) -> Option<&'t toml::Value> {
    let parts: Vec<&str> = path.split('.').collect();
    let (mut at, rest) = match parts.as_slice() {
        [section @ ("robot" | "device" | "part"), name, rest @ ..] => (
            file.get(*section)?
                .as_array()?
                .iter()
                .find(|i| i.get("name").and_then(toml::Value::as_str) == Some(*name))?,
            rest,
        ),
        [first, rest @ ..] => (file.get(*first)?, rest),
        [] => return None,
    };
    for key in rest {
        at = match at {
            toml::Value::Table(t) => t.get(*key)?,
            toml::Value::Array(items) => items.get(key.parse::<usize>().ok()?)?,
            _ => return None,
        };
    }
    Some(at)
}

/// A workcell value as its file writes it: `600mm` (a string without its quotes), `0.6`.
fn as_written(v: &toml::Value) -> String {
    match v {
        toml::Value::String(s) => s.clone(),
        other => other.to_string(),
    }
}

/// A variable's value when the workcell file does not write it: the loaded workcell's (a
/// default, or a param's value as its program declares it).
fn default_of(cell: &Cell, path: &str) -> String {
    use vworks_vm::Dim;
    let parts: Vec<&str> = path.split('.').collect();
    let robot = |name: &str| cell.robots.iter().find(|r| r.name == name);
    let pose = |iso: &vworks_model::math::Iso, part: &str, k: &str| -> Option<String> {
        let k = k.parse::<usize>().ok().filter(|k| *k < 3)?;
        Some(match part {
            "xyz" => quantity(iso.t[k], Dim::LENGTH),
            "rpy" => quantity(iso.rpy()[k], Dim::ANGLE),
            _ => return None,
        })
    };
    let param = |r: &vworks_cell::Robot, name: &str| {
        vworks_cell::params::declared(&r.module)
            .into_iter()
            .find(|(n, ..)| n == name)
            .map(|(_, ty, value)| match (ty, value) {
                (vworks_vm::Type::Num(dim), vworks_vm::ConstValue::Num(x)) => quantity(x, dim),
                (_, vworks_vm::ConstValue::Int(i)) => i.to_string(),
                (_, vworks_vm::ConstValue::Bool(b)) => b.to_string(),
                (_, other) => format!("{other:?}"),
            })
    };
    let found = match parts.as_slice() {
        ["cycle"] => Some(quantity(cell.cycle_ns as f64 / 1e9, Dim::TIME)),
        ["clearance"] => Some(quantity(cell.clearance, Dim::LENGTH)),
        ["grip_distance"] => Some(quantity(cell.grip_distance, Dim::LENGTH)),
        ["params", name] => {
            let each: Vec<String> = cell
                .robots
                .iter()
                .filter_map(|r| Some(format!("{} in {}'s program", param(r, name)?, r.name)))
                .collect();
            (!each.is_empty()).then(|| each.join(", "))
        }
        ["robot", name, rest @ ..] => robot(name).and_then(|r| match rest {
            ["params", p] => param(r, p),
            ["default_speed"] => Some(quantity(r.default_speed, Dim::SPEED)),
            ["default_zone"] => Some(
                r.default_zone
                    .map_or("fine".into(), |z| quantity(z, Dim::LENGTH)),
            ),
            ["grip_distance"] => Some(quantity(r.grip_distance, Dim::LENGTH)),
            ["base", part, k] => pose(&r.base, part, k),
            ["tool", part, k] => pose(&r.tool, part, k),
            _ => None,
        }),
        [section @ ("device" | "part"), name, "pose", part, k] => {
            let bodies = if *section == "device" {
                &cell.devices
            } else {
                &cell.parts
            };
            bodies
                .iter()
                .find(|b| b.name == *name)
                .and_then(|b| pose(&b.pose, part, k))
        }
        _ => None,
    };
    found.unwrap_or_else(|| "–".into())
}

/// An SI value in the unit a workcell file would use for its dimension (mm, deg, mm/s, s).
fn quantity(x: f64, dim: vworks_vm::Dim) -> String {
    use vworks_vm::Dim;
    let (scale, unit) = match dim {
        Dim::LENGTH => (1e3, "mm"),
        Dim::ANGLE => (180.0 / std::f64::consts::PI, "deg"),
        Dim::SPEED => (1e3, "mm/s"),
        Dim::TIME if x.abs() < 1.0 => (1e3, "ms"),
        Dim::TIME => (1.0, "s"),
        Dim::PLAIN => (1.0, ""),
        _ => return format!("{x} ({dim} in SI)"),
    };
    // 12 significant digits: no noise of the conversion (0.1 m is 100mm, not 100.00000000000001).
    let v: f64 = format!("{:.11e}", x * scale).parse().unwrap_or(x * scale);
    format!("{}{unit}", v + 0.0)
}

/// What the rows said, counted as they pass, and the best kept.
struct Tally {
    rows: usize,
    feasible: usize,
    collided: usize,
    /// Rows by outcome, at [`RowOutcome::index`].
    outcomes: [usize; RowOutcome::ALL.len()],
    logs_failed: usize,
    best: Best,
}

impl Tally {
    fn count(&self, outcome: RowOutcome) -> usize {
        self.outcomes[outcome.index()]
    }
}

pub(crate) fn sweep(mut a: Args) -> Result<ExitCode, String> {
    if a.variables {
        return list_variables(&files::cell_file(&a.file, "sweep --variables")?);
    }
    // A folder: its sweep file, as `run` takes a cell's folder.
    a.file = sweep_file(&a.file)?;
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
    let objective = sweep
        .check_objective(&objective, &robots)
        .map_err(|m| match a.minimize {
            Some(_) => format!("--minimize: {m}"),
            None => format!("{}: minimize: {m}", a.file.display()),
        })?;
    let variant_timeout = a.variant_timeout.as_deref().map(timeout).transpose()?;
    let count = sweep.count();
    let keep_list = a
        .keep_logs_variants
        .as_deref()
        .map(VariantSet::parse)
        .transpose()
        .map_err(|m| format!("--keep-logs-variants: {m}"))?;
    if let Some(last) = keep_list.as_ref().and_then(VariantSet::last)
        && last >= count
    {
        return Err(format!(
            "--keep-logs-variants: variant {last} is not one of this sweep's {count} (0 to {})",
            count.saturating_sub(1)
        ));
    }
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
    let names = sweep.names();
    let units = sweep.units();
    let columns = table::columns(&names, &robots);
    // The file's header states the units; the rows are matched by `columns`.
    let headers = table::headers(&names, &units, &robots);
    let format = Format::of_path(&out);
    let table_error = |e: std::io::Error| OutputError::write(&out, &e).to_string();
    let mut writer = TableWriter::new(table_out, format, headers.clone());
    // A table that cannot be written does not stop the sweep: the best are still printed.
    let mut write_error = writer.start().err();
    let options = RunOptions {
        jobs: a.jobs,
        until_ns: sweep.until_ns,
        keep_logs: a.keep_logs.clone(),
        // The best are known only as rows pass: every log is written, the others removed.
        keep_logs_of: if a.keep_logs_best.is_some() {
            None
        } else {
            keep_list.clone()
        },
        variant_timeout,
    };
    let mut pruner = match (&a.keep_logs, a.keep_logs_best) {
        (Some(dir), Some(n)) => Some(Pruner {
            dir: dir.clone(),
            best: Best::new(
                &columns,
                &objective,
                usize::try_from(n).unwrap_or(usize::MAX),
            ),
            list: keep_list.clone(),
            failed: Vec::new(),
        }),
        _ => None,
    };
    // Variants started whose row has not passed yet: those left at the end were stopped
    // (Ctrl-C), and their logs go too.
    let running: Mutex<BTreeSet<usize>> = Mutex::new(BTreeSet::new());
    let pruning = pruner.is_some();
    let stop = Arc::new(AtomicBool::new(false));
    let flag = Arc::clone(&stop);
    let _ = ctrlc::set_handler(move || flag.store(true, Ordering::Relaxed));
    let bar = (!a.quiet && std::io::stderr().is_terminal())
        .then(|| indicatif::ProgressBar::new(count as u64).with_style(progress_style()));
    let mut tally = Tally {
        rows: 0,
        feasible: 0,
        collided: 0,
        outcomes: [0; RowOutcome::ALL.len()],
        logs_failed: 0,
        best: Best::new(&columns, &objective, a.best),
    };
    let started = std::time::Instant::now();
    run_streamed(
        &loader,
        count,
        &|i| {
            if pruning {
                running
                    .lock()
                    .unwrap_or_else(PoisonError::into_inner)
                    .insert(i);
            }
            sweep.variant(i)
        },
        &options,
        &|done| {
            if let Some(b) = &bar {
                b.set_position(done as u64);
            }
        },
        Some(&stop),
        &mut |row: Row| {
            let values = table::row_values_in(&names, &units, &robots, &row);
            tally.rows += 1;
            tally.feasible += usize::from(row.feasible());
            tally.collided += usize::from(row.collisions > 0);
            tally.outcomes[row.outcome.index()] += 1;
            tally.logs_failed += usize::from(row.log_failed);
            tally.best.offer(&columns, &values);
            if write_error.is_none() {
                write_error = writer.write(&values).err();
            }
            if let Some(p) = &mut pruner {
                running
                    .lock()
                    .unwrap_or_else(PoisonError::into_inner)
                    .remove(&row.index);
                p.offer(row.index, &columns, &values);
            }
        },
    );
    if let Some(p) = &mut pruner {
        let stopped = std::mem::take(&mut *running.lock().unwrap_or_else(PoisonError::into_inner));
        stopped.into_iter().for_each(|i| p.remove(i));
    }
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
                headers.clone(),
                &header_of(&names, &headers),
                &headers[columns.iter().position(|c| *c == objective).unwrap_or(0)],
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
    if let Some(dir) = &a.keep_logs {
        let list = a.keep_logs_variants.as_deref().unwrap_or_default();
        match &pruner {
            Some(p) => {
                let best: Vec<String> = p.kept().iter().map(usize::to_string).collect();
                eprintln!(
                    "kept in {} the logs of the {} best variants by {objective}{}{}",
                    dir.display(),
                    best.len(),
                    if best.is_empty() {
                        String::new()
                    } else {
                        format!(" ({})", best.join(", "))
                    },
                    if list.is_empty() {
                        String::new()
                    } else {
                        format!(" and of variants {list}")
                    },
                );
                for m in &p.failed {
                    fail(m.clone());
                }
            }
            None if !list.is_empty() => {
                eprintln!("kept in {} the logs of variants {list}", dir.display());
            }
            None => {}
        }
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
        "{} variants in {seconds:.2} s ({} variants/s, {jobs} jobs): {} completed, {} with a collision, {} deadlocked, {} with an error, {} stopped at `until`, {} timed out, {} invalid{}",
        tally.rows,
        per_second(tally.rows as f64 / seconds.max(1e-9)),
        tally.feasible,
        tally.collided,
        tally.count(RowOutcome::Run(Outcome::Deadlock)),
        tally.count(RowOutcome::Run(Outcome::Error)),
        tally.count(RowOutcome::Run(Outcome::Until)),
        tally.count(RowOutcome::Timeout),
        tally.count(RowOutcome::Invalid),
        if interrupted { " (interrupted)" } else { "" },
    );
    let none = no_best(&tally, &sweep, &a.file, interrupted);
    print_best(&columns, &names, &units, &objective, &tally.best, &none);
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

/// The progress bar: the rate with three significant digits (`466/s`, `12.5/s`).
fn progress_style() -> indicatif::ProgressStyle {
    indicatif::ProgressStyle::with_template("{bar:40} {pos}/{len} variants, {rate}, {eta} left")
        .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar())
        .with_key(
            "rate",
            |state: &indicatif::ProgressState, w: &mut dyn std::fmt::Write| {
                let _ = write!(w, "{}/s", per_second(state.per_sec()));
            },
        )
}

/// The headers (with units) of the variable columns `names`.
fn header_of(names: &[String], headers: &[String]) -> Vec<String> {
    // The variables are the columns after `variant`, in order.
    headers.iter().skip(1).take(names.len()).cloned().collect()
}

/// `--keep-logs-best N`: the logs of the N best variants so far stay in the folder (and
/// those of `--keep-logs-variants`); a variant's log is removed as soon as its row passes
/// without being among them, or when a later one pushes it out.
struct Pruner {
    dir: PathBuf,
    best: Best,
    list: Option<VariantSet>,
    /// Logs that could not be removed (the message).
    failed: Vec<String>,
}

impl Pruner {
    /// The variants among the best, best first.
    fn kept(&self) -> Vec<usize> {
        self.best
            .rows()
            .iter()
            .filter_map(|r| match r.first() {
                Some(Value::Int(i)) => usize::try_from(*i).ok(),
                _ => None,
            })
            .collect()
    }

    fn offer(&mut self, index: usize, columns: &[String], values: &[Value]) {
        let before = self.kept();
        self.best.offer(columns, values);
        let after = self.kept();
        for i in before.into_iter().chain([index]) {
            if !after.contains(&i) {
                self.remove(i);
            }
        }
    }

    /// Removes variant `i`'s log, unless it is listed to keep.
    fn remove(&mut self, i: usize) {
        if self.list.as_ref().is_some_and(|l| l.contains(i)) {
            return;
        }
        let path = self.dir.join(format!("variant-{i:05}.mcap"));
        match std::fs::remove_file(&path) {
            Ok(()) => {}
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => {}
            Err(e) => self.failed.push(format!(
                "cannot remove `{}` (--keep-logs-best): {e}",
                path.display()
            )),
        }
    }
}

/// What the summary says when no variant is among the best: what became of them, and
/// what to do (`no variant completed: 4 stopped at \`until\` (1s); …`).
fn no_best(tally: &Tally, sweep: &Sweep, file: &Path, interrupted: bool) -> String {
    if tally.rows == 0 {
        return "no variant finished: the sweep was interrupted before the first".into();
    }
    let collided_completed = tally
        .count(RowOutcome::Run(Outcome::Completed))
        .saturating_sub(tally.feasible);
    let until = sweep.until_ns.map_or_else(String::new, |ns| {
        format!(" ({})", quantity(ns as f64 / 1e9, vworks_vm::Dim::TIME))
    });
    let mut what = Vec::new();
    let mut todo = Vec::new();
    for (n, said) in [
        (collided_completed, "completed with a collision".to_string()),
        (
            tally.count(RowOutcome::Run(Outcome::Collision)),
            "stopped at a collision".into(),
        ),
        (
            tally.count(RowOutcome::Run(Outcome::Deadlock)),
            "deadlocked".into(),
        ),
        (
            tally.count(RowOutcome::Run(Outcome::Error)),
            "ended with an error".into(),
        ),
        (
            tally.count(RowOutcome::Run(Outcome::Until)),
            format!("stopped at `until`{until}"),
        ),
        (
            tally.count(RowOutcome::Timeout),
            "timed out (--variant-timeout)".into(),
        ),
        (tally.count(RowOutcome::Invalid), "invalid".into()),
    ] {
        if n > 0 {
            what.push(format!("{n} {said}"));
        }
    }
    if tally.count(RowOutcome::Run(Outcome::Until)) > 0 {
        todo.push(format!(
            "raise `until` in {} (or remove it) for them to complete",
            file.display()
        ));
    }
    if tally.count(RowOutcome::Timeout) > 0 {
        todo.push("raise --variant-timeout".into());
    }
    if tally.collided > 0 {
        todo.push(format!(
            "`vworks run {} --set PATH=VALUE` runs one variant with its trace, to see where it collides",
            sweep.cell.display()
        ));
    }
    if tally.count(RowOutcome::Run(Outcome::Deadlock))
        + tally.count(RowOutcome::Run(Outcome::Error))
        + tally.count(RowOutcome::Invalid)
        > 0
    {
        todo.push("the rows' `error` says why the others did not complete".into());
    }
    format!(
        "no variant completed{}: {}{}; the best are ranked among the variants that completed without a collision{}",
        if tally.count(RowOutcome::Run(Outcome::Completed)) > 0 {
            " without a collision"
        } else {
            ""
        },
        what.join(", "),
        if interrupted { " (interrupted)" } else { "" },
        if todo.is_empty() {
            String::new()
        } else {
            format!(": {}", todo.join("; "))
        },
    )
}

fn print_best(
    columns: &[String],
    names: &[String],
    units: &[Option<Unit>],
    objective: &str,
    best: &Best,
    none: &str,
) {
    let column = |n: &str| columns.iter().position(|c| c == n);
    let best = best.rows();
    if best.is_empty() {
        out!("{none}");
        return;
    }
    let k = column(objective).unwrap_or(0);
    // The objective's unit: a fixed column's (s, m) or a variable's.
    let unit = table::fixed_unit(objective)
        .map(str::to_string)
        .or_else(|| {
            let v = names.iter().position(|n| n == objective)?;
            units.get(v)?.as_ref().map(|u| u.name.clone())
        });
    out!("best by {objective} (completed, no collision):");
    for row in best {
        let values: Vec<String> = names
            .iter()
            .zip(units)
            .filter_map(|(n, u)| Some((column(n)?, u)))
            .map(|(c, u)| {
                let unit = match (&row[c], u) {
                    (Value::Num(_) | Value::Int(_), Some(u)) => u.name.as_str(),
                    _ => "",
                };
                format!("{} = {}{unit}", columns[c], cell(&row[c]))
            })
            .collect();
        let objective_unit = match (&row[k], &unit) {
            (Value::Num(_) | Value::Int(_), Some(u)) if table::fixed_unit(objective).is_some() => {
                format!(" {u}")
            }
            (Value::Num(_) | Value::Int(_), Some(u)) => u.clone(),
            _ => String::new(),
        };
        out!(
            "  variant {}: {objective} {}{objective_unit}  ({})",
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

/// The sweep file `vworks sweep` was given as `path`: the path itself, or the sweep file
/// of a folder (its `sweep.toml`, else its one `.toml` with `[[variable]]`s). A workcell,
/// or a folder without one sweep file, is an error saying what to give instead.
fn sweep_file(path: &Path) -> Result<PathBuf, String> {
    let file = if path.is_dir() {
        let sweeps = sweep_files_in(path);
        match sweeps.as_slice() {
            [one] => one.clone(),
            [] => return Err(no_sweep_file_in(path)),
            many => {
                let named: Vec<String> =
                    many.iter().map(|p| format!("`{}`", p.display())).collect();
                return Err(format!(
                    "`{}` is a folder with {} sweep files and no sweep.toml: name the one to run: {}",
                    path.display(),
                    many.len(),
                    named.join(", ")
                ));
            }
        }
    } else {
        path.to_path_buf()
    };
    if let Kind::Workcell { robots } = kind_of(&file) {
        let dir = file.parent().unwrap_or(Path::new(""));
        let beside = match sweep_files_in(dir).as_slice() {
            [one] => format!(
                "; the sweep file beside it: `vworks sweep {}`",
                one.display()
            ),
            _ => format!(". {}", how_to_write_a_sweep_file(&file, &robots)),
        };
        return Err(format!(
            "`{}` is a workcell, but `vworks sweep` takes a sweep file: one that names a workcell and the values to vary{beside}",
            file.display()
        ));
    }
    Ok(file)
}

/// The sweep files of a folder: its `sweep.toml`, else every `.toml` that is a sweep
/// file (sorted).
fn sweep_files_in(dir: &Path) -> Vec<PathBuf> {
    let default = dir.join("sweep.toml");
    if default.is_file() {
        return vec![default];
    }
    tomls_in(dir)
        .into_iter()
        .filter(|p| matches!(kind_of(p), Kind::Sweep { .. }))
        .collect()
}

/// The `.toml` files of a folder, sorted.
fn tomls_in(dir: &Path) -> Vec<PathBuf> {
    let mut tomls: Vec<PathBuf> = std::fs::read_dir(if dir.as_os_str().is_empty() {
        Path::new(".")
    } else {
        dir
    })
    .map(|entries| {
        entries
            .filter_map(Result::ok)
            .filter(|e| e.file_name().to_string_lossy().ends_with(".toml"))
            .map(|e| dir.join(e.file_name()))
            .collect()
    })
    .unwrap_or_default();
    tomls.sort();
    tomls
}

/// A folder without a sweep file: what is there, and a sweep file for its workcell.
fn no_sweep_file_in(dir: &Path) -> String {
    let what = format!(
        "`{}` is a folder without a sweep file (a sweep.toml, or a .toml with `[[variable]]`s): `vworks sweep` takes one",
        dir.display()
    );
    let tomls = tomls_in(dir);
    let cell = tomls.iter().find_map(|p| match kind_of(p) {
        Kind::Workcell { robots } => Some((p, robots)),
        _ => None,
    });
    match cell {
        Some((cell, robots)) => format!("{what}. {}", how_to_write_a_sweep_file(cell, &robots)),
        None if tomls.is_empty() => {
            format!("{what}; there is no .toml there (`vworks new NAME` creates a workcell folder)")
        }
        None => {
            let named: Vec<String> = tomls.iter().map(|p| format!("`{}`", p.display())).collect();
            format!(
                "{what}; its .toml files are neither sweep files nor workcells: {}",
                named.join(", ")
            )
        }
    }
}

/// A minimal sweep file for the workcell `cell` (with these robots), to write beside it.
fn how_to_write_a_sweep_file(cell: &Path, robots: &[String]) -> String {
    let sweep = cell.with_file_name("sweep.toml");
    let name = cell
        .file_name()
        .map_or_else(|| "cell.toml".into(), |n| n.to_string_lossy().into_owned());
    let (path, values) = match robots.first() {
        Some(r) => (format!("robot.{r}.base.xyz.0"), "[\"500mm\", \"600mm\"]"),
        None => ("cycle".to_string(), "[\"4ms\", \"8ms\"]"),
    };
    format!(
        "Write one for the workcell `{}`, e.g. {}:\n\n    cell = \"{name}\"\n\n    [[variable]]\n    path = \"{path}\"\n    values = {values}\n\nthen `vworks sweep {}`. `vworks sweep --variables {}` lists every value a sweep may vary; docs/sweep.md has the format",
        cell.display(),
        sweep.display(),
        sweep.display(),
        cell.display()
    )
}
