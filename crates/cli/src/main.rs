//! `vworks`, the command-line front end.
//!
//! - `vworks check FILE…`: compile each program and print every diagnostic; exit 1 on any
//!   error. Given a workcell (`cell.toml`, or a folder holding one), check the whole cell
//!   without running it (module `check`).
//! - `vworks build FILE [-o OUT.wslb]`: compile one program to bytecode.
//! - `vworks disasm FILE.wslb|FILE.wsl`: list the bytecode with the source beside it.
//!
//! - `vworks run CELL [--log run.mcap]`: simulate a workcell (a `cell.toml`, or a folder
//!   holding one) and print the summary.
//! - `vworks log info|events FILE.mcap`: read a run's log.
//! - `vworks report FILE.mcap [-o report.html]`: the run's HTML report.
//! - `vworks new NAME [--model M]`: a new workcell folder, ready to run.
//! - `vworks sweep SWEEP.toml`: run the variants of a workcell (module `sweep`).
//! - `vworks completions SHELL`: a shell completion script.

use std::io::IsTerminal;
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use vworks_se::CellNames;

use clap::{Parser, Subcommand};

mod check;
mod files;
mod output;
mod report;
mod sweep;
mod view;
use files::{cell_file, display, is_cell, read, read_bytes};
use output::{out, plural, secs};
use report::write_report;
use view::view;
use vworks_log::issue::issue_json as json_issue;
use vworks_vm::Module;
use vworks_vm::bytecode::disassemble;
use vworks_wslc::{Language, Sources, render};

#[derive(Parser, Debug)]
#[command(
    name = "vworks",
    version,
    about = "Offline-programming simulation of robot cells written in WSL"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
    /// Never colour the output (also: the NO_COLOR environment variable).
    #[arg(long, global = true)]
    no_color: bool,
}

#[derive(Subcommand, Debug)]
enum Command {
    /// Compile programs, or check a whole workcell without running it, and report every
    /// problem found (exit 1 if any is an error).
    Check {
        /// The program files (.wsl, or RAPID .mod/.modx/.sys/.prg), or workcells (a
        /// cell.toml, or a folder holding one): its models, programs, homes, constant
        /// targets and the bodies at the start are checked.
        #[arg(required = true)]
        files: Vec<PathBuf>,
        /// Check the files as one robot's program (a RAPID task's modules, a WSL program
        /// and its library files) instead of each on its own.
        #[arg(long)]
        task: bool,
        /// For a workcell: print the problems as one JSON object.
        #[arg(long)]
        json: bool,
    },
    /// Compile one program (one file, or the files of one robot task) to a bytecode file.
    Build {
        /// The program's files, in order (.wsl, or RAPID .mod/.modx/.sys/.prg).
        #[arg(required = true)]
        files: Vec<PathBuf>,
        /// Output file (default: the first file with extension .wslb).
        #[arg(short, long)]
        output: Option<PathBuf>,
    },
    /// List the bytecode of a .wslb file (or compile a program's files and list it).
    Disasm {
        /// A .wslb file, or a program's files.
        #[arg(required = true)]
        files: Vec<PathBuf>,
    },
    /// Simulate a workcell and print a summary (exit 1 on collision stop, deadlock or error).
    Run {
        /// The workcell file (cell.toml), or a folder holding one.
        cell: PathBuf,
        /// Stop at this simulated time ("10s", "250ms", or seconds).
        #[arg(long, allow_hyphen_values = true)]
        until: Option<String>,
        /// Print the result as one JSON object.
        #[arg(long)]
        json: bool,
        /// Print the event trace, one line per event, times in seconds
        /// (`7.220474304 s r1 set gopartsready=1 r1.mod:37:7`); the summary goes to stderr.
        #[arg(long, conflicts_with = "json")]
        trace: bool,
        /// Print the event trace with times in integer nanoseconds (`7220474304 r1 set …`):
        /// the format of `vworks log events` and the golden files.
        #[arg(long, conflicts_with_all = ["trace", "json"])]
        trace_ns: bool,
        /// Write the run to this MCAP file (events, cycle states, geometry; opens in Foxglove).
        #[arg(long)]
        log: Option<PathBuf>,
        /// Log the state of every N-th cycle only (events are never thinned).
        #[arg(long, default_value_t = 1, value_parser = every_nth)]
        log_every: u64,
        /// No progress bar (it shows on a terminal for runs longer than a second) and no
        /// `log` lines of the programs (they print as they happen, before the summary).
        #[arg(short, long)]
        quiet: bool,
        /// Change a value of the workcell for this run, by its dotted path as a sweep names
        /// it: `--set robot.r2.base.xyz.0=650mm` (repeatable; `vworks sweep --variables
        /// CELL` lists them).
        #[arg(long = "set", value_name = "PATH=VALUE")]
        set: Vec<String>,
    },
    /// Write a run's report, one self-contained HTML file: the cell in 3D played back over
    /// a timeline, a Gantt chart per robot, cycle times, collisions, warnings and the event
    /// table.
    Report {
        /// The MCAP log of the run (`vworks run CELL --log run.mcap`).
        log: PathBuf,
        /// The HTML file to write (default: the log's name with extension .html).
        #[arg(short, long)]
        output: Option<PathBuf>,
    },
    /// Write a run's report to a temporary file and open it in the browser ($BROWSER, or the
    /// system's default), or print its path where no browser can be opened.
    View {
        /// The MCAP log of the run (`vworks run CELL --log run.mcap`).
        log: PathBuf,
    },
    /// Run every variant of a sweep file (a workcell with values varied) on all cores, and
    /// write the table (CSV or JSON lines) and a page with the objective charted; prints the
    /// best variants. `--variables CELL` lists what a sweep may vary.
    Sweep(sweep::Args),
    /// Create a new workcell folder: one robot, its program and a README, ready to run.
    New {
        /// The folder to create (its name becomes the cell's name).
        name: PathBuf,
        /// The robot's model: a built-in arm (irb120, kr6r900, lrmate200id, ur5).
        #[arg(long, default_value = "irb120")]
        model: String,
    },
    /// Print a shell completion script (e.g. `vworks completions bash > ~/.local/share/bash-completion/completions/vworks`).
    Completions {
        /// The shell.
        shell: clap_complete::Shell,
    },
    /// Read an MCAP log written by `vworks run --log`.
    Log {
        #[command(subcommand)]
        what: LogCommand,
    },
}

#[derive(Subcommand, Debug)]
enum LogCommand {
    /// Topics, message counts and the simulated span.
    Info {
        /// The .mcap file.
        file: PathBuf,
    },
    /// The event trace, in the same format as `run --trace-ns` (integer ns; `--seconds`:
    /// as `run --trace`).
    Events {
        /// The .mcap file.
        file: PathBuf,
        /// Only events of this kind (e.g. motion_start).
        #[arg(long)]
        kind: Option<String>,
        /// Only events of this robot.
        #[arg(long)]
        robot: Option<String>,
        /// Times in seconds (`7.220474304 s`, `duration=1.3 s`) instead of nanoseconds,
        /// as `run --trace` prints them.
        #[arg(long)]
        seconds: bool,
    },
}

/// `--log-every N`: a whole number, 1 or more.
fn every_nth(s: &str) -> Result<u64, String> {
    match s.parse::<u64>() {
        Ok(n) if n >= 1 => Ok(n),
        _ => Err(format!(
            "`{s}` is not a whole number of cycles from 1 up; write 1 to log every cycle, 10 for every 10th"
        )),
    }
}

fn main() -> ExitCode {
    let cli = Cli::try_parse().unwrap_or_else(|e| with_suggestion(e).exit());
    let color =
        !cli.no_color && std::env::var_os("NO_COLOR").is_none() && std::io::stderr().is_terminal();
    match run(cli.command, color) {
        Ok(code) => code,
        Err(msg) => {
            eprintln!("error: {msg}");
            ExitCode::FAILURE
        }
    }
}

/// clap's error for an unknown subcommand, with the nearest subcommand suggested where
/// clap's own similarity finds none (`vworks rn`: `run`).
fn with_suggestion(mut e: clap::Error) -> clap::Error {
    use clap::error::{ContextKind, ContextValue, ErrorKind};
    if e.kind() != ErrorKind::InvalidSubcommand || e.get(ContextKind::SuggestedSubcommand).is_some()
    {
        return e;
    }
    let Some(ContextValue::String(typed)) = e.get(ContextKind::InvalidSubcommand) else {
        return e;
    };
    use clap::CommandFactory as _;
    let cmd = Cli::command();
    let names = cmd.get_subcommands().map(|c| c.get_name());
    if let Some(near) = vworks_wslc::nearest(&typed.to_ascii_lowercase(), names) {
        let near = near.to_string();
        e.insert(
            ContextKind::SuggestedSubcommand,
            ContextValue::Strings(vec![near]),
        );
    }
    e
}

/// Compiles one file, printing its diagnostics; `None` if it had errors.
/// Compiles the files of one program (one file, or a robot task's files in order),
/// printing its diagnostics: the module if it compiled, and the counts of errors and
/// warnings.
fn compile_program(
    paths: &[PathBuf],
    color: bool,
) -> Result<(Option<Module>, usize, usize), String> {
    let mut texts = Vec::with_capacity(paths.len());
    for p in paths {
        texts.push((display(p), read(p)?));
    }
    let names: Vec<&str> = texts.iter().map(|(p, _)| p.as_str()).collect();
    let language = Language::of_files(&names).map_err(|(_, why)| why)?;
    let mut sources = Sources::new();
    for (name, src) in &texts {
        sources.add(name, src);
    }
    let files: Vec<(&str, &str)> = texts
        .iter()
        .map(|(p, t)| (p.as_str(), t.as_str()))
        .collect();
    match vworks_wslc::compile_program(language, &files, None) {
        Ok(out) => {
            eprint!("{}", render(&out.warnings, &sources, color));
            Ok((Some(out.module), 0, out.warnings.len()))
        }
        Err(e) => {
            eprint!("{}", render(&e.diagnostics, &sources, color));
            let errors = e.diagnostics.iter().filter(|d| d.is_error()).count();
            Ok((None, errors, e.diagnostics.len() - errors))
        }
    }
}

fn parse_time(s: &str) -> Result<i64, String> {
    if s.trim().starts_with('-') {
        return Err(format!(
            "--until `{s}` is before the run starts; give a time from 0, e.g. 10s"
        ));
    }
    let quantity = vworks_wslc::units::parse_quantity(s).map(|q| q.si(vworks_vm::Dim::TIME));
    let Some(Ok(secs)) = quantity else {
        return Err(format!(
            "--until `{s}` is not a time; write e.g. 10s or 250ms"
        ));
    };
    vworks_app::until_ns(secs).map_err(|e| match e {
        vworks_app::UntilError::Negative => {
            format!("--until `{s}` is before the run starts; give a time from 0, e.g. 10s")
        }
        vworks_app::UntilError::OutOfRange => {
            format!("--until `{s}` is past the simulation's clock range (146 years); give e.g. 10s")
        }
    })
}

fn read_log(what: LogCommand) -> Result<ExitCode, String> {
    let file = match &what {
        LogCommand::Info { file } | LogCommand::Events { file, .. } => file.clone(),
    };
    // A log cut short (the process was killed) still has every chunk written before the
    // kill: what was read is printed, and the damage is a warning and exit code 1.
    let log = vworks_log::mcaplog::read_log(&file).map_err(|e| e.to_string())?;
    match &what {
        LogCommand::Events {
            kind,
            robot,
            seconds,
            ..
        } => {
            let times = if *seconds {
                vworks_log::trace::Times::Seconds
            } else {
                vworks_log::trace::Times::Nanoseconds
            };
            for e in &log.events {
                if kind.as_deref().is_some_and(|want| want != e.kind.name())
                    || robot
                        .as_deref()
                        .is_some_and(|want| Some(want) != e.robot.as_deref())
                {
                    continue;
                }
                out!("{}", e.line_as(times));
            }
        }
        LogCommand::Info { .. } => {
            out!("{}", file.display());
            for (topic, n) in &log.counts {
                let topic = vworks_log::trace::escape_controls(topic);
                let word = if *n == 1 { "message" } else { "messages" };
                out!("  {topic:<10} {n:>8} {word}");
            }
            if let Some((first, last)) = log.span {
                out!(
                    "  simulated span {} .. {}",
                    secs(first as i64),
                    secs(last as i64)
                );
            }
            if log.damage.is_some() {
                out!("  unfinished: only the messages before the damage are counted");
            }
        }
    }
    if let Some((read, e)) = log.damage {
        eprintln!(
            "warning: {} is unfinished or damaged after {read} messages ({e}); everything before that was read. \
             The run was probably killed: `mcap recover {} -o fixed.mcap` (the mcap CLI) rebuilds the index, or run the cell again.",
            file.display(),
            file.display()
        );
        return Ok(ExitCode::FAILURE);
    }
    Ok(ExitCode::SUCCESS)
}

/// The files `vworks new` writes: (name, text); `{name}` is the cell's name.
const NEW_CELL: &[(&str, &str)] = &[
    (
        "cell.toml",
        r#"# A workcell: its robots, devices and parts. See docs/engine.md for every key.
name = {name_toml}
cycle = "4ms"          # collision checks at every 4 ms boundary (and between them)
clearance = "5mm"      # closer than this is a near-miss warning

[[robot]]
name = "r1"
model = "{model}"{pad} # built in: irb120, kr6r900, lrmate200id, ur5, turntable, track
program = "r1.wsl"
home = {home}
{extra}

[[device]]
name = "table"
box = ["600mm", "800mm", "20mm"]
pose = { xyz = ["500mm", "0mm", "-10mm"] }
"#,
    ),
    (
        "r1.wsl",
        r#"// r1's program: two straight-line moves above the table, three times.
const above = pose(400mm, -150mm, 300mm, 180deg, 0deg, 0deg);

proc main() {
    var i = 0;
    while i < 3 {
        move_l above speed 250mm/s;
        move_l offset(above, 0mm, 300mm, 0mm) speed 250mm/s;
        i += 1;
    }
    log "done";
}
"#,
    ),
    (
        "README.md",
        "# {name}\n\nA vworks workcell: `vworks check {name}` checks it without running it; `vworks run {name} --log run.mcap` runs it, then `vworks report run.mcap`.\n",
    ),
];

/// The arms `vworks new --model` can start a cell with, and a home for each: the tool
/// pointing down above the table, from where the program's targets are straight-line
/// moves within reach and the joint limits (`cli.rs` runs the new cell of each); and
/// lines the robot's table needs besides.
const NEW_ARMS: &[(&str, &str, &str)] = &[
    (
        "irb120",
        r#"["0deg", "-30deg", "30deg", "0deg", "60deg", "0deg"]"#,
        "",
    ),
    (
        "kr6r900",
        r#"["0deg", "-75deg", "140deg", "0deg", "25deg", "0deg"]"#,
        "",
    ),
    (
        "lrmate200id",
        r#"["0deg", "0deg", "-35deg", "0deg", "-55deg", "0deg"]"#,
        "",
    ),
    (
        "ur5",
        r#"["0deg", "-95deg", "-90deg", "-95deg", "90deg", "0deg"]"#,
        "# The model's base and upper-arm shapes lie 1 mm apart by design (closer than the\n# clearance): not a near miss to warn of.\nallow_collision = [[\"r1.base_link\", \"r1.upper_arm_link\"]]\n",
    ),
];

fn new_cell(dir: &Path, model: &str) -> Result<ExitCode, String> {
    let arms: Vec<&str> = NEW_ARMS.iter().map(|(m, _, _)| *m).collect();
    // (`IRB120` is the irb120.)
    let lower = model.to_lowercase();
    let Some((model, home, extra)) = NEW_ARMS.iter().find(|(m, _, _)| *m == lower) else {
        let what = if vworks_model::builtin::names().contains(&lower.as_str()) {
            format!("`{model}` is not an arm (a new cell's program moves a tool over a table)")
        } else {
            // The arm it begins (`kr6`), else the nearest in spelling.
            let mut begun = arms
                .iter()
                .filter(|a| !lower.is_empty() && a.starts_with(&lower));
            let near = match (begun.next(), begun.next()) {
                (Some(a), None) => Some(*a),
                _ => vworks_wslc::nearest(&lower, arms.iter().copied()),
            };
            let hint = near
                .map(|n| format!(" (did you mean {n}?)"))
                .unwrap_or_default();
            format!("`{model}` is not a built-in model{hint}")
        };
        return Err(format!(
            "--model {}: {what}; choose one of the arms {} (a URDF robot: write its `urdf` in cell.toml after `vworks new`)",
            vworks_model::text::escape_controls(model),
            arms.join(", ")
        ));
    };
    let name = dir
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .filter(|n| !n.is_empty() && !n.starts_with('.'))
        .ok_or_else(|| {
            format!(
                "`{}` is not a folder name for a new cell; write e.g. `vworks new mycell`",
                dir.display()
            )
        })?;
    if dir.exists() && std::fs::read_dir(dir).map_or(true, |mut entries| entries.next().is_some()) {
        return Err(format!(
            "`{}` already exists and is not empty; choose another name, or delete it first",
            dir.display()
        ));
    }
    std::fs::create_dir_all(dir)
        .map_err(|e| format!("cannot create the folder `{}`: {e}", dir.display()))?;
    for (file, text) in NEW_CELL {
        let path = dir.join(file);
        let text = text
            // The name as a TOML string (quotes and backslashes escaped).
            .replace(
                "{name_toml}",
                &toml::Value::String(name.clone()).to_string(),
            )
            .replace("{name}", &name)
            .replace("{model}", model)
            .replace("{pad}", &" ".repeat(12usize.saturating_sub(model.len())))
            .replace("{home}", home)
            .replace("{extra}\n", extra);
        std::fs::write(&path, text)
            .map_err(|e| format!("cannot write `{}`: {e}", path.display()))?;
    }
    eprintln!(
        "created {}: cell.toml (one {model} and a table), r1.wsl, README.md\nrun it: vworks run {}",
        dir.display(),
        dir.display()
    );
    Ok(ExitCode::SUCCESS)
}

/// A program's `log` line as a plain run prints it: `[11.156 s] r1: done`.
fn log_line(l: &vworks_log::place::LogLine) -> String {
    use vworks_log::trace::escape_controls as esc;
    format!("[{}] {}: {}", secs(l.time_ns), esc(&l.robot), esc(&l.text))
}

/// Runs the simulation to its end (or `until`). With `progress` (the run's start), a bar on
/// stderr shows the simulated time done and the speed, once the run has taken a second:
/// against `until` when there is one, else as a spinner (the end is not known ahead).
/// With `print_logs`, the programs' `log` lines print on stdout as they happen (above the
/// bar).
fn simulate(
    mut sim: vworks_se::Simulation,
    until: Option<i64>,
    progress: Option<std::time::Instant>,
    print_logs: bool,
) -> vworks_log::result::RunResult {
    if progress.is_none() && !print_logs {
        return sim.run(until);
    }
    let mut bar: Option<indicatif::ProgressBar> = None;
    let mut steps = 0u32;
    let mut seen = 0;
    loop {
        let more = sim.step(until);
        if print_logs && sim.trace().len() > seen {
            for e in &sim.trace()[seen..] {
                if let Some(l) = e.log_line(&CellNames(sim.cell())) {
                    match &bar {
                        Some(bar) => bar.suspend(|| out!("{}", log_line(&l))),
                        None => out!("{}", log_line(&l)),
                    }
                }
            }
            seen = sim.trace().len();
        }
        if !more {
            break;
        }
        let Some(started) = progress else {
            continue;
        };
        steps = steps.wrapping_add(1);
        // The clock is read every few thousand steps: the bar costs nothing measurable.
        if !steps.is_multiple_of(4096) {
            continue;
        }
        let wall = started.elapsed().as_secs_f64();
        if wall < 1.0 {
            continue;
        }
        let done = sim.time().max(0) as u64;
        let bar = bar.get_or_insert_with(|| {
            let style = |template: &str| {
                indicatif::ProgressStyle::with_template(template)
                    .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar())
            };
            match until {
                Some(u) => indicatif::ProgressBar::new(u.max(1) as u64)
                    .with_style(style("{spinner} [{bar:30}] {msg}")),
                None => indicatif::ProgressBar::new_spinner().with_style(style("{spinner} {msg}")),
            }
        });
        bar.set_position(done);
        bar.set_message(format!(
            "simulated {:.1} s, {:.0}x real time",
            done as f64 / 1e9,
            done as f64 / 1e9 / wall
        ));
        bar.tick();
    }
    if let Some(bar) = bar {
        bar.finish_and_clear();
    }
    sim.into_result()
}

/// How `vworks run` was asked to run a cell.
struct RunOptions<'a> {
    /// `PATH=VALUE` overrides (`--set`).
    set: &'a [String],
    until: Option<&'a str>,
    json: bool,
    /// `--trace` (seconds) or `--trace-ns`: print the event trace in this style.
    trace: Option<vworks_log::trace::Times>,
    log: Option<&'a Path>,
    log_every: u64,
    /// Show a progress bar (stderr is a terminal and not `--quiet`).
    progress: bool,
    /// `--quiet`: no progress bar, no `log` lines.
    quiet: bool,
    color: bool,
}

/// `PATH=VALUE`: the value as TOML (`0.65`, `3`, `true`, `"650mm"`) or, if it is not,
/// as text (`650mm`).
fn parse_override(s: &str) -> Result<vworks_cell::Override, String> {
    let Some((path, value)) = s.split_once('=') else {
        return Err(format!(
            "--set `{s}`: write PATH=VALUE, e.g. --set robot.r2.base.xyz.0=650mm"
        ));
    };
    let value = value.trim();
    let parsed = format!("v = {value}")
        .parse::<toml::Table>()
        .ok()
        .and_then(|mut t| t.remove("v"))
        .unwrap_or_else(|| toml::Value::String(value.to_string()));
    Ok(vworks_cell::Override::new(path.trim(), parsed))
}

fn run_cell(path: &Path, opts: RunOptions<'_>) -> Result<ExitCode, String> {
    let RunOptions {
        set,
        until,
        json,
        trace,
        log,
        log_every,
        progress,
        quiet,
        color,
    } = opts;
    // With --json, a run that cannot start is still one JSON object on stdout; the
    // message goes to stderr as without it.
    let cannot_start = |errors: Vec<serde_json::Value>, message: String| {
        if json {
            let v = serde_json::json!({"outcome": "error", "errors": errors});
            out!("{}", serde_json::to_string_pretty(&v).unwrap_or_default());
        }
        Err(message)
    };
    // A folder runs its cell.toml; a program or a sweep file is an error saying what to give.
    let file = match cell_file(path, "run") {
        Ok(f) => f,
        Err(e) => {
            let issue = json_issue("usage", &e, None, Some(&display(path)), 0, 0);
            return cannot_start(vec![issue], e);
        }
    };
    let path = file.as_path();
    let until = match until.map(parse_time).transpose() {
        Ok(u) => u,
        Err(e) => return cannot_start(vec![json_issue("usage", &e, None, None, 0, 0)], e),
    };
    let overrides = match set
        .iter()
        .map(|s| parse_override(s))
        .collect::<Result<Vec<_>, _>>()
    {
        Ok(o) => o,
        Err(e) => return cannot_start(vec![json_issue("usage", &e, None, None, 0, 0)], e),
    };
    // Ctrl-C ends the run between two events, so the summary prints and the log is finished.
    let stop = std::sync::Arc::new(std::sync::atomic::AtomicBool::new(false));
    let request = vworks_app::RunRequest {
        cell: vworks_app::CellSource::File {
            path,
            overrides: &overrides,
        },
        until_ns: until,
        log: log.map(|path| vworks_app::LogRequest {
            path,
            every: log_every,
        }),
        stop: Some(std::sync::Arc::clone(&stop)),
    };
    let started_run = match vworks_app::start(request) {
        Ok(run) => run,
        Err(vworks_app::RunError::Load(vworks_cell::CellError::Program {
            rendered,
            diagnostics,
            ..
        })) => {
            eprint!("{rendered}");
            let errors = diagnostics
                .iter()
                .filter(|d| d.is_error())
                .map(|d| {
                    let at = &d.at;
                    json_issue(
                        d.code.as_str(),
                        &d.message,
                        None,
                        Some(&at.file),
                        at.line,
                        at.col,
                    )
                })
                .collect();
            let m = format!("{}: the programs have errors", path.display());
            return cannot_start(errors, m);
        }
        Err(vworks_app::RunError::Load(e)) => {
            let m = e.to_string();
            let file = display(path);
            return cannot_start(vec![json_issue("workcell", &m, None, Some(&file), 0, 0)], m);
        }
        Err(vworks_app::RunError::Log { cell, message }) => {
            // Compile and link warnings, as `vworks check` prints them.
            eprint!("{}", cell.render_warnings(color));
            let file = log.map(display);
            let issue = json_issue("log", &message, None, file.as_deref(), 0, 0);
            return cannot_start(vec![issue], message);
        }
    };
    let cell = std::sync::Arc::clone(&started_run.cell);
    // Compile and link warnings, as `vworks check` prints them.
    eprint!("{}", cell.render_warnings(color));
    let started = std::time::Instant::now();
    let flag = std::sync::Arc::clone(&stop);
    let _ = ctrlc::set_handler(move || flag.store(true, std::sync::atomic::Ordering::Relaxed));
    let print_logs = !json && trace.is_none() && !quiet;
    let r = started_run
        .simulate(|sim| simulate(sim, until, progress.then_some(started), print_logs))
        .result;
    if let Some(e) = &r.log_error {
        eprintln!("error: {e}");
    }
    let wall = started.elapsed().as_secs_f64();
    if let Some(times) = trace {
        for e in &r.trace {
            out!("{}", e.line_as(&CellNames(&cell), times));
        }
    }
    if json {
        let log_file = log.map(|p| p.display().to_string());
        let v = r.to_json(&cell.name, log_file.as_deref());
        out!(
            "{}",
            serde_json::to_string_pretty(&v).map_err(|e| e.to_string())?
        );
    } else {
        // With a trace on stdout, the summary goes to stderr after it (a pipe gets the
        // trace alone).
        for line in summary(&r, &cell, wall, log) {
            if trace.is_some() {
                eprintln!("{line}");
            } else {
                out!("{line}");
            }
        }
    }
    Ok(match r.outcome {
        // The run went well but the log asked for is missing or incomplete: an error.
        vworks_log::result::Outcome::Completed | vworks_log::result::Outcome::Until
            if r.log_error.is_some() =>
        {
            ExitCode::FAILURE
        }
        vworks_log::result::Outcome::Completed | vworks_log::result::Outcome::Until => {
            ExitCode::SUCCESS
        }
        vworks_log::result::Outcome::Interrupted => ExitCode::from(130),
        _ => ExitCode::FAILURE,
    })
}

/// The summary of a run, line by line: the outcome, a line per robot, the collisions and
/// near misses with each robot's motion, warnings, errors, globals, counts and the log.
fn summary(
    r: &vworks_log::result::RunResult,
    cell: &vworks_cell::Cell,
    wall: f64,
    log: Option<&Path>,
) -> Vec<String> {
    let mut lines = Vec::new();
    macro_rules! line {
        ($($arg:tt)*) => { lines.push(format!($($arg)*)) };
    }
    // Names and messages from the workcell, escaped as log texts are.
    use vworks_log::trace::escape_controls as esc;
    line!(
        "cell {}: {} at {}",
        esc(&cell.name),
        r.outcome.name(),
        secs(r.end_time_ns)
    );
    line!(
        "{:<10} {:>10} {:>10} {:>10} {:>8}  ended",
        "robot",
        "moving",
        "waiting",
        "idle",
        "motions"
    );
    for s in &r.robots {
        line!(
            "{:<10} {:>10} {:>10} {:>10} {:>8}  {} at {}",
            esc(&s.name),
            secs(s.moving_ns),
            secs(s.waiting_ns),
            secs(s.idle_ns),
            s.motions,
            s.ended.name(),
            secs(s.end_time_ns)
        );
    }
    for c in &r.collisions {
        line!(
            "collision at {}: {} and {} (depth {:.1} mm)",
            secs(c.time_ns),
            esc(&c.a),
            esc(&c.b),
            c.depth * 1e3
        );
        for m in &c.motions {
            line!("  {}", esc(&m.describe()));
        }
    }
    // (The compile and link warnings, which open the list, were printed with their
    // source lines.)
    for w in r.warnings.iter().skip(cell.warnings.len()) {
        line!("warning[{}]: {}", w.kind, esc(&w.message));
        for m in &w.motions {
            line!("  {}", esc(&m.describe()));
        }
    }
    for e in &r.errors {
        let at = e.file.as_ref().map_or(String::new(), |f| {
            format!(" ({}:{}:{})", esc(f), e.line, e.col)
        });
        line!("error[{}]: {}{at}", e.kind, esc(&e.message));
    }
    if !r.globals.is_empty() {
        let g: Vec<String> = r.globals.iter().map(|(k, v)| format!("{k}={v}")).collect();
        line!("globals: {}", g.join(", "));
    }
    line!(
        "{} events, {} cycles, {} collision queries; {:.0}x real time",
        r.trace.len(),
        r.cycles,
        r.queries,
        r.end_time_ns as f64 / 1e9 / wall.max(1e-9)
    );
    if let Some(p) = log {
        if r.log_error.is_some() {
            line!("log {}: not written (see the error above)", p.display());
        } else {
            let counts: Vec<String> = r
                .log_counts
                .iter()
                .map(|(topic, n)| format!("{n} {topic}"))
                .collect();
            line!("log {}: {}", p.display(), counts.join(", "));
        }
    }
    lines
}

fn run(cmd: Command, color: bool) -> Result<ExitCode, String> {
    match cmd {
        Command::Check { files, task, json } => {
            if files.iter().any(|f| is_cell(f)) {
                return check::check_cells(&files, task, json, color);
            }
            if json {
                return Err(
                    "--json is for a workcell (`vworks check CELL --json`); programs are checked without it".into(),
                );
            }
            let (mut errors, mut warnings) = (0, 0);
            let programs: Vec<&[PathBuf]> = if task {
                vec![&files]
            } else {
                files.chunks(1).collect()
            };
            for program in programs {
                let (_, e, w) = compile_program(program, color)?;
                errors += e;
                warnings += w;
            }
            eprintln!(
                "checked {}: {}, {}",
                plural(files.len(), "file"),
                plural(errors, "error"),
                plural(warnings, "warning")
            );
            Ok(if errors > 0 {
                ExitCode::FAILURE
            } else {
                ExitCode::SUCCESS
            })
        }
        Command::Build { files, output } => {
            let (module, errors, _) = compile_program(&files, color)?;
            let first = &files[0];
            let Some(module) = module else {
                eprintln!("{} not built: {}", display(first), plural(errors, "error"));
                return Ok(ExitCode::FAILURE);
            };
            let out = output.unwrap_or_else(|| first.with_extension("wslb"));
            let bytes = module.encode();
            vworks_model::output::write_output(&out, &files, &bytes).map_err(|e| e.to_string())?;
            eprintln!(
                "wrote {} ({} bytes, {} instructions)",
                out.display(),
                bytes.len(),
                module.code.len()
            );
            Ok(ExitCode::SUCCESS)
        }
        Command::Run {
            cell,
            until,
            json,
            trace,
            trace_ns,
            log,
            log_every,
            quiet,
            set,
        } => run_cell(
            &cell,
            RunOptions {
                set: &set,
                until: until.as_deref(),
                json,
                trace: match (trace, trace_ns) {
                    (true, _) => Some(vworks_log::trace::Times::Seconds),
                    (_, true) => Some(vworks_log::trace::Times::Nanoseconds),
                    _ => None,
                },
                log: log.as_deref(),
                log_every,
                progress: !quiet && std::io::stderr().is_terminal(),
                quiet,
                color,
            },
        ),
        Command::Log { what } => read_log(what),
        Command::Report { log, output } => write_report(&log, output),
        Command::View { log } => view(&log),
        Command::Sweep(args) => sweep::sweep(args),
        Command::New { name, model } => new_cell(&name, &model),
        Command::Completions { shell } => {
            use clap::CommandFactory as _;
            let mut cmd = Cli::command();
            let mut buf = Vec::new();
            clap_complete::generate(shell, &mut cmd, "vworks", &mut buf);
            out!("{}", String::from_utf8_lossy(&buf).trim_end());
            Ok(ExitCode::SUCCESS)
        }
        Command::Disasm { files } => {
            let file = &files[0];
            let bytes = read_bytes(file)?;
            let (module, sources) = if bytes.starts_with(&vworks_vm::bytecode::MAGIC) {
                if files.len() > 1 {
                    return Err(format!(
                        "{} is a bytecode file: list it alone (`vworks disasm {}`)",
                        file.display(),
                        file.display()
                    ));
                }
                let m = Module::decode(&bytes).map_err(|e| {
                    format!(
                        "{}: {e}; the file is damaged or from another vworks version: build it again with `vworks build PROGRAM.wsl`",
                        file.display()
                    )
                })?;
                // The sources beside the listing, if they are where the module says or
                // beside the bytecode file.
                let sources: Vec<String> = m
                    .files
                    .iter()
                    .map(|f| {
                        let near = file
                            .parent()
                            .map(|d| d.join(Path::new(f).file_name().unwrap_or_default()));
                        read(Path::new(f))
                            .ok()
                            .or_else(|| near.and_then(|p| read(&p).ok()))
                            .unwrap_or_default()
                    })
                    .collect();
                (m, sources)
            } else {
                let (m, _, _) = compile_program(&files, color)?;
                let Some(m) = m else {
                    return Ok(ExitCode::FAILURE);
                };
                let sources = files.iter().map(|f| read(f).unwrap_or_default()).collect();
                (m, sources)
            };
            let texts: Vec<&str> = sources.iter().map(String::as_str).collect();
            let listing = disassemble(&module, &texts);
            out!("{}", listing.trim_end_matches('\n'));
            Ok(ExitCode::SUCCESS)
        }
    }
}
