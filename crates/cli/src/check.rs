//! `vworks check CELL`: a whole workcell checked without running it.
//!
//! The workcell is loaded as `vworks run` loads it, but with programs that do not compile
//! left out (`vworks_cell::load_checking`: every key, the models, the homes within the
//! joint limits, the programs compiled and linked), and then what a run would only find
//! later but can be known exactly beforehand:
//!
//! - each `move_j`/`move_l`/`move_c` whose target is a constant (`pose(…)`, `joints(…)`,
//!   a `const`, or an expression of constants the compiler folded): a `move_j` to joints
//!   outside the axes' limits (every such axis named), and a pose target that no
//!   configuration of the arm reaches within its limits (arms with an analytic solver:
//!   every solution is known), with the motion's TCP: its own constant `tool` operand
//!   (RAPID's `tool0`, a `PERS tooldata` never assigned), else the workcell's tool if no
//!   motion of the program changes it (otherwise not checked);
//! - the bodies at the start: every robot at its home against the other robots, devices
//!   and parts, as the run's first collision check sees them (the same pairs skipped and
//!   allowed): a collision at 0 s is an error, a near miss within the clearance a warning,
//!   one problem per two robots, devices or parts, at the key that placed them (a robot's
//!   `base`, else its `home`, else its `[[robot]]` line). A robot touching a part its
//!   program grips is left to the run (the grip may come first).
//!
//! Every problem names its file and line (the workcell key's line, the statement's line),
//! what is wrong and what to do. The loader stops at the first workcell problem, except
//! that every unknown key is reported; the programs' diagnostics are all reported.

use std::ops::Range;
use std::path::{Path, PathBuf};
use std::process::ExitCode;

use vworks_cell::{Cell, CellError};
use vworks_log::issue::issue_json;
use vworks_model::math::Iso;
use vworks_se::{Collider, CollisionEvent};
use vworks_vm::bytecode::{MoveFlags, ProcInfo};
use vworks_vm::{ConstValue, Instr, Module};

use crate::files::{self, is_cell, is_program};
use crate::output::{out, plural};

/// One problem found, at a place in a file (line 0: the file as a whole).
struct Problem {
    error: bool,
    /// What kind: `workcell`, `reach`, `limits`, `collision`, `near_miss`.
    kind: &'static str,
    robot: Option<String>,
    file: String,
    line: u32,
    col: u32,
    /// Characters to underline from `col` (at least 1).
    width: usize,
    message: String,
}

/// What checking one cell found.
struct Report {
    name: String,
    programs: usize,
    problems: Vec<Problem>,
    /// The programs' compile and link diagnostics, rendered with their source lines.
    rendered: String,
    /// The same diagnostics, as JSON issues, and their counts.
    diagnostics: Vec<(bool, serde_json::Value)>,
    /// The texts of the files the problems name: (path, text).
    sources: Vec<(String, String)>,
}

/// `vworks check CELL…`: each workcell checked; exit 1 if any has an error.
pub(crate) fn check_cells(
    files: &[PathBuf],
    task: bool,
    json: bool,
    color: bool,
) -> Result<ExitCode, String> {
    if task {
        return Err("--task is for program files; a workcell's `program` says which files make each robot's program: `vworks check CELL`".into());
    }
    if let Some(p) = files.iter().find(|f| !is_cell(f)) {
        return Err(format!(
            "`{}` is not a workcell: check workcells (cell.toml, or a folder holding one) and program files in separate commands",
            p.display()
        ));
    }
    let mut failed = false;
    let mut out = Vec::new();
    for f in files {
        programs_without_cell(f)?;
        let path = files::cell_file(f, "check")?;
        let r = check_cell(&path, color);
        let errors = r.problems.iter().filter(|p| p.error).count()
            + r.diagnostics.iter().filter(|(e, _)| *e).count();
        let warnings = r.problems.len() + r.diagnostics.len() - errors;
        failed |= errors > 0;
        if json {
            let issue = |p: &Problem| {
                let mut v = issue_json(
                    p.kind,
                    &p.message,
                    p.robot.as_deref(),
                    Some(&p.file),
                    p.line,
                    p.col,
                );
                v["severity"] = if p.error { "error" } else { "warning" }.into();
                (p.error, v)
            };
            let all: Vec<(bool, serde_json::Value)> = r
                .diagnostics
                .iter()
                .cloned()
                .chain(r.problems.iter().map(issue))
                .collect();
            let pick = |e: bool| -> Vec<serde_json::Value> {
                all.iter()
                    .filter(|(x, _)| *x == e)
                    .map(|(_, v)| v.clone())
                    .collect()
            };
            out.push(serde_json::json!({
                "cell": r.name,
                "file": path.display().to_string(),
                "programs": r.programs,
                "errors": pick(true),
                "warnings": pick(false),
            }));
            continue;
        }
        eprint!("{}", r.rendered);
        for p in &r.problems {
            eprint!("{}", render(p, &r.sources, color));
        }
        eprintln!(
            "checked cell {}: {}, {}, {}",
            vworks_log::trace::escape_controls(&r.name),
            plural(r.programs, "program"),
            plural(errors, "error"),
            plural(warnings, "warning")
        );
    }
    if json {
        let v = match out.len() {
            1 => out.swap_remove(0),
            _ => serde_json::Value::Array(out),
        };
        out!("{}", serde_json::to_string_pretty(&v).unwrap_or_default());
    }
    Ok(if failed {
        ExitCode::FAILURE
    } else {
        ExitCode::SUCCESS
    })
}

/// A folder holding programs but no workcell: the programs to check one by one, or
/// `vworks new`.
fn programs_without_cell(dir: &Path) -> Result<(), String> {
    if !dir.is_dir() || dir.join("cell.toml").is_file() {
        return Ok(());
    }
    let mut names: Vec<PathBuf> = std::fs::read_dir(dir)
        .map(|entries| entries.filter_map(Result::ok).map(|e| e.path()).collect())
        .unwrap_or_default();
    names.sort();
    if names
        .iter()
        .any(|p| p.extension().is_some_and(|e| e == "toml"))
    {
        return Ok(());
    }
    let programs: Vec<String> = names
        .iter()
        .filter(|p| p.is_file() && is_program(p))
        .map(|p| format!("`vworks check {}`", files::display(p)))
        .collect();
    if programs.is_empty() {
        return Ok(());
    }
    Err(format!(
        "`{}` is a folder without a cell.toml, but it holds {}: check each on its own ({}), or write a cell.toml naming the robots and their programs (`vworks new NAME` creates a workcell folder to start from)",
        files::display(dir),
        plural(programs.len(), "program"),
        programs.join(", ")
    ))
}

/// The robots of the workcell text and their program files (as the loader joins them to
/// the workcell's folder `dir`), in file order, as far as the text parses.
fn robots_of(text: &str, dir: &Path) -> Vec<(String, Vec<String>)> {
    let Ok(t) = text.parse::<toml::Table>() else {
        return Vec::new();
    };
    let robots = t.get("robot").and_then(|r| r.as_array());
    robots
        .into_iter()
        .flatten()
        .map(|r| {
            let name = r.get("name").and_then(|n| n.as_str()).unwrap_or_default();
            let files = match r.get("program") {
                Some(toml::Value::String(p)) => vec![p.as_str()],
                Some(toml::Value::Array(list)) => list.iter().filter_map(|p| p.as_str()).collect(),
                _ => Vec::new(),
            };
            let files = files
                .iter()
                .map(|p| dir.join(p).display().to_string())
                .collect();
            (name.to_string(), files)
        })
        .collect()
}

/// Checks the workcell file `path`.
fn check_cell(path: &Path, color: bool) -> Report {
    let file = path.display().to_string();
    let text = files::read(path).unwrap_or_default();
    let stem = path
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_default();
    let dir = path.parent().map(Path::to_path_buf).unwrap_or_default();
    let robots = robots_of(&text, &dir);
    let mut report = Report {
        name: stem,
        programs: 0,
        problems: Vec::new(),
        rendered: String::new(),
        diagnostics: Vec::new(),
        sources: vec![(file.clone(), text.clone())],
    };
    // Programs that do not compile or link are reported, and the workcell is checked on.
    let (loaded, programs) = vworks_cell::load_checking(path);
    if let Some(e) = programs {
        workcell_error(e, path, &text, &robots, &mut report);
    }
    let cell = match loaded {
        Ok(cell) => cell,
        Err(e) => {
            // What the file says, as far as it parses: the name and the programs.
            if let Ok(t) = text.parse::<toml::Table>()
                && let Some(n) = t.get("name").and_then(|n| n.as_str())
            {
                report.name = n.to_string();
            }
            let mut programs: Vec<&Vec<String>> = robots.iter().map(|(_, f)| f).collect();
            programs.sort();
            programs.dedup();
            report.programs = programs.len();
            workcell_error(e, path, &text, &robots, &mut report);
            return report;
        }
    };
    report.name = cell.name.clone();
    let mut programs: Vec<&[String]> = cell.robots.iter().map(|r| &r.module.files[..]).collect();
    programs.sort();
    programs.dedup();
    report.programs = programs.len();
    report.rendered.push_str(&cell.render_warnings(color));
    report.diagnostics.extend(
        cell.warnings
            .iter()
            .map(|d| (false, diagnostic_json(d, &robots))),
    );
    for source in &cell.sources {
        if !report.sources.iter().any(|(f, _)| *f == source.0) {
            report.sources.push(source.clone());
        }
    }
    targets(&cell, &mut report.problems);
    at_the_start(&cell, &text, &mut report.problems);
    report
}

/// A diagnostic as a JSON issue; its robot, if one robot's program has its file.
fn diagnostic_json(
    d: &vworks_wslc::Diagnostic,
    robots: &[(String, Vec<String>)],
) -> serde_json::Value {
    let mut owners = robots.iter().filter(|(_, f)| f.contains(&d.at.file));
    let robot = match (owners.next(), owners.next()) {
        (Some((r, _)), None) => Some(r.as_str()),
        _ => None,
    };
    let mut v = issue_json(
        d.code.as_str(),
        &d.message,
        robot,
        Some(&d.at.file),
        d.at.line,
        d.at.col,
    );
    v["severity"] = if d.is_error() { "error" } else { "warning" }.into();
    v
}

/// The robot a workcell key is in: `robot[1] \`r2\`.home[0]` names it; a place (`line 7,
/// column 1`) is in the robot whose `[[robot]]` table holds that line.
fn robot_of_key(key: &str, text: &str, robots: &[(String, Vec<String>)]) -> Option<String> {
    if let Some(rest) = key.strip_prefix("robot[") {
        let i: usize = rest.split(']').next()?.trim().parse().ok()?;
        return robots.get(i).map(|(n, _)| n.clone());
    }
    let line: usize = key.strip_prefix("line ")?.split(',').next()?.parse().ok()?;
    let before: Vec<(usize, String)> = headers(text)
        .into_iter()
        .take_while(|(at, _)| *at <= line)
        .collect();
    let (_, last) = before.last()?;
    if last != "[[robot]]" && !last.starts_with("[robot.") {
        return None;
    }
    let nth = before.iter().filter(|(_, h)| h == "[[robot]]").count();
    robots.get(nth.checked_sub(1)?).map(|(n, _)| n.clone())
}

/// The table headers of a TOML text (`[[robot]]`, `[robot.params]`), without spaces or
/// comments, with their 1-based lines.
fn headers(text: &str) -> Vec<(usize, String)> {
    text.lines()
        .enumerate()
        .filter_map(|(i, l)| {
            let l = l.split('#').next().unwrap_or_default().trim();
            l.starts_with('[')
                .then(|| (i + 1, l.chars().filter(|c| !c.is_whitespace()).collect()))
        })
        .collect()
}

/// A workcell that does not load: the loader's error, placed at its key's line.
fn workcell_error(
    e: CellError,
    path: &Path,
    text: &str,
    robots: &[(String, Vec<String>)],
    report: &mut Report,
) {
    let file = path.display().to_string();
    let mut at = |key: Option<&str>, message: String| {
        let (line, col, width) = key
            .and_then(|k| locate(text, k))
            .map_or((0, 0, 1), |r| line_col(text, r));
        report.problems.push(Problem {
            error: true,
            kind: "workcell",
            robot: key.and_then(|k| robot_of_key(k, text, robots)),
            file: file.clone(),
            line,
            col,
            width,
            message,
        });
    };
    match e {
        CellError::Program {
            diagnostics,
            rendered,
            ..
        } => {
            report.rendered = rendered;
            report.diagnostics = diagnostics
                .iter()
                .map(|d| (d.is_error(), diagnostic_json(d, robots)))
                .collect();
        }
        // An unknown key: every one of the file (the loader stops at the first).
        CellError::Invalid { key, message, .. }
            if key.starts_with("line ") && message.starts_with("unknown field") =>
        {
            let all = vworks_cell::unknown_keys(path, text);
            if all.is_empty() {
                at(Some(&key), message);
            }
            for e in all {
                if let CellError::Invalid { key, message, .. } = e {
                    at(Some(&key), message);
                }
            }
        }
        // A TOML syntax error's key is its place, which the location line shows.
        CellError::Invalid { key, message, .. } if key.starts_with("line ") => {
            at(Some(&key), message);
        }
        CellError::Invalid { key, message, .. } => {
            at(Some(&key), format!("{key}: {message}"));
        }
        CellError::Model { robot, source, .. } => {
            let key = robot_key(text, &robot, "urdf");
            at(key.as_deref(), format!("robot `{robot}`: {source}"));
        }
        other => at(None, other.to_string()),
    }
}

/// The key of robot `name`'s `field` (`robot[1].urdf`), if the file has that robot.
fn robot_key(text: &str, name: &str, field: &str) -> Option<String> {
    let t = text.parse::<toml::Table>().ok()?;
    let robots = t.get("robot")?.as_array()?;
    let i = robots
        .iter()
        .position(|r| r.get("name").and_then(|n| n.as_str()) == Some(name))?;
    Some(format!("robot[{i}].{field}"))
}

/// The constant motion targets of every robot's program, checked against its model.
fn targets(cell: &Cell, problems: &mut Vec<Problem>) {
    for r in &cell.robots {
        let m = &r.module;
        // A motion with a `tool` operand (every RAPID motion) sets the TCP from there on:
        // a motion without one then has a TCP only the run knows.
        let tool_changes = m.code.iter().any(|i| {
            matches!(i, Instr::MoveJ(f) | Instr::MoveL(f) | Instr::MoveC(f) if f.has(MoveFlags::TOOL))
        });
        let n = r.model.dof();
        for proc in &m.procs {
            let start = proc.code_start as usize;
            let end = start + proc.code_len as usize;
            for pc in start..end.min(m.code.len()) {
                let (f, joint_move) = match m.code[pc] {
                    Instr::MoveJ(f) => (f, true),
                    Instr::MoveL(f) | Instr::MoveC(f) => (f, false),
                    _ => continue,
                };
                let Some(target) = constant_target(m, proc, pc, f) else {
                    continue;
                };
                // The motion's TCP: its own `tool` if a constant gives it, else the
                // workcell's if no motion of the program changes it.
                let tool = if f.has(MoveFlags::TOOL) {
                    let above = u32::from(f.has(MoveFlags::DURATION));
                    match constant_operand(m, proc, pc, above, 6) {
                        Some(ConstValue::Pose(t)) => {
                            Some(Iso::from_xyz_rpy([t[0], t[1], t[2]], [t[3], t[4], t[5]]))
                        }
                        _ => None,
                    }
                } else {
                    (!tool_changes).then_some(r.tool)
                };
                let pos = m.pos_of(pc as u32);
                let mut problem = |kind: &'static str, message: String| {
                    let file = m.file_of(pos).to_string();
                    let p = Problem {
                        error: true,
                        kind,
                        robot: Some(r.name.clone()),
                        file,
                        line: pos.line,
                        col: pos.col,
                        width: 1,
                        message: format!(
                            "robot `{}` ({}): {message}",
                            vworks_log::trace::escape_controls(&r.name),
                            r.model.name
                        ),
                    };
                    // A program shared by robots of one model: said once per robot.
                    if !problems
                        .iter()
                        .any(|q| q.file == p.file && q.line == p.line && q.message == p.message)
                    {
                        problems.push(p);
                    }
                };
                match target {
                    ConstValue::Joints(q) if joint_move => {
                        // Every axis outside its limits, in one problem.
                        let outside: Vec<String> = q
                            .iter()
                            .enumerate()
                            .take(n)
                            .filter_map(|(i, v)| {
                                let j = r.model.axis(i);
                                (!(j.lower - 1e-9..=j.upper + 1e-9).contains(v)).then(|| {
                                    format!(
                                        "axis {} `{}` would go to {}, outside its range {} to {}",
                                        i + 1,
                                        j.name,
                                        j.display(*v),
                                        j.display(j.lower),
                                        j.display(j.upper)
                                    )
                                })
                            })
                            .collect();
                        if !outside.is_empty() {
                            let (what, ranges) = match outside.len() {
                                1 => ("joint limit exceeded", "the range"),
                                _ => ("joint limits exceeded", "the ranges"),
                            };
                            problem(
                                "limits",
                                format!(
                                    "{what}: {}; choose a target within {ranges}",
                                    outside.join("; ")
                                ),
                            );
                        }
                    }
                    ConstValue::Pose(p) if tool.is_some() => {
                        let tool = tool.unwrap_or(r.tool);
                        let tcp = Iso::from_xyz_rpy([p[0], p[1], p[2]], [p[3], p[4], p[5]]);
                        let flange = tcp.mul(&tool.inverse());
                        let mut out = [[0.0; 6]; 8];
                        if let Some(Err(e)) = r.model.ik_analytic_all(&flange, &r.home, &mut out) {
                            problem(
                                "reach",
                                format!("unreachable pose: {}", e.at_position(tcp.t)),
                            );
                        }
                    }
                    _ => {}
                }
            }
        }
    }
}

/// The target of the motion at `pc` if a constant pushed it (`PushConst` of a pose or
/// joints, the operands above it pushed by straight-line code: no jump lands between).
fn constant_target(m: &Module, proc: &ProcInfo, pc: usize, f: MoveFlags) -> Option<ConstValue> {
    let effect = m.code[pc].stack_effect(m, proc)?;
    let width = if f.has(MoveFlags::TARGET_JOINTS) {
        vworks_vm::MAX_AXES as u32
    } else {
        6
    };
    let via = match m.code[pc] {
        Instr::MoveC(_) if f.has(MoveFlags::VIA_JOINTS) => vworks_vm::MAX_AXES as u32,
        Instr::MoveC(_) => 6,
        _ => 0,
    };
    // Slots above the target's top: the speed, zone, tool … operands.
    let above = effect.pops.checked_sub(width + via)?;
    constant_operand(m, proc, pc, above, width)
}

/// The operand of `width` slots of the instruction at `pc`, `above` slots below the top
/// of the stack, if it is a constant: a pose or joints pushed by `PushConst`, or a module
/// variable no instruction of the program writes (a RAPID `PERS tooldata`'s frame) read by
/// `LoadVarN` — the slots above it pushed by straight-line code (no jump lands between).
fn constant_operand(
    m: &Module,
    proc: &ProcInfo,
    pc: usize,
    mut above: u32,
    width: u32,
) -> Option<ConstValue> {
    let start = proc.code_start as usize;
    let lands = |at: usize| {
        m.code
            .get(start..start + proc.code_len as usize)
            .unwrap_or_default()
            .iter()
            .any(|i| i.jump_target().is_some_and(|t| start + t as usize == at))
    };
    let mut k = pc;
    while k > start {
        if lands(k) {
            return None;
        }
        k -= 1;
        let ins = m.code[k];
        if ins.ends_block() || ins.jump_target().is_some() {
            return None;
        }
        let e = ins.stack_effect(m, proc)?;
        if above < e.pushes {
            // This instruction pushed the operand's top slot: a constant of the operand's
            // width, with nothing of it below, or something only the run knows.
            let value = match ins {
                Instr::PushConst(c) if above == 0 && e.pushes == width => {
                    m.consts.get(c as usize)?.value.clone()
                }
                Instr::LoadVarN(slot, n) if above == 0 && u32::from(n) == width => {
                    let var = m.vars.iter().find(|v| v.slot == slot)?;
                    let slots = slot..slot + width;
                    let written = m.code.iter().any(|i| match *i {
                        Instr::StoreVar(s) => slots.contains(&s),
                        Instr::StoreVarN(s, n) => s < slots.end && slots.start < s + u32::from(n),
                        Instr::StoreVarJoint(s) => {
                            s < slots.end && slots.start < s + vworks_vm::MAX_AXES as u32
                        }
                        _ => false,
                    });
                    if written {
                        return None;
                    }
                    var.init.clone()
                }
                _ => return None,
            };
            return matches!(value, ConstValue::Pose(_) | ConstValue::Joints(_)).then_some(value);
        }
        above = above - e.pushes + e.pops;
    }
    None
}

/// The bodies at the start (every robot at its home): collisions and near misses, as the
/// run's first collision check finds them.
fn at_the_start(cell: &Cell, text: &str, problems: &mut Vec<Problem>) {
    let vms = vworks_se::robot_vms(cell);
    let mut collider = Collider::new(cell);
    let moving = vec![false; vms.len()];
    let file = cell.file.display().to_string();
    let table = text.parse::<toml::Table>().unwrap_or_default();
    // A robot touching a part its program grips: the grip may come before the first check.
    let grips = |a: &str, b: &str| {
        let Some(p) = cell.parts.iter().find(|p| p.name == b) else {
            return false;
        };
        cell.robots.iter().any(|r| {
            a.strip_prefix(&r.name).is_some_and(|l| l.starts_with('.'))
                && r.module
                    .parts
                    .iter()
                    .any(|s| r.module.str(s.part) == p.name)
        })
    };
    // The touching (or near) pairs of bodies, by the pair of robots, devices and parts
    // they belong to, in the order first found: (owners, collision, [(a, b, depth or gap)]).
    type Pairs = Vec<(String, String, f64)>;
    let mut groups: Vec<((Owner, Owner), bool, Pairs)> = Vec::new();
    for event in collider.check(cell, &vms, 0, &moving) {
        let (a, b, x, collision) = match event {
            CollisionEvent::Start(c) if !(grips(&c.a, &c.b) || grips(&c.b, &c.a)) => {
                (c.a, c.b, c.depth, true)
            }
            CollisionEvent::NearMiss(a, b, d) => (a, b, d, false),
            _ => continue,
        };
        let (Some(oa), Some(ob)) = (Owner::of(cell, &a), Owner::of(cell, &b)) else {
            continue;
        };
        let key = if oa <= ob { (oa, ob) } else { (ob, oa) };
        let (a, b) = if oa <= ob { (a, b) } else { (b, a) };
        match groups
            .iter_mut()
            .find(|(k, c, _)| *k == key && *c == collision)
        {
            Some((_, _, pairs)) => pairs.push((a, b, x)),
            None => groups.push((key, collision, vec![(a, b, x)])),
        }
    }
    // (Bodies that overlap are not also said to come near.)
    let touching: Vec<(Owner, Owner)> = groups.iter().filter(|g| g.1).map(|g| g.0).collect();
    groups.retain(|(k, collision, _)| *collision || !touching.contains(k));
    let esc = |s: &str| vworks_log::trace::escape_controls(s).into_owned();
    for ((oa, ob), collision, mut pairs) in groups {
        // The deepest first; the nearest first for near misses.
        pairs.sort_by(|x, y| {
            let order = if collision {
                y.2.total_cmp(&x.2)
            } else {
                x.2.total_cmp(&y.2)
            };
            order.then_with(|| (&x.0, &x.1).cmp(&(&y.0, &y.1)))
        });
        let how = if collision { "by" } else { "apart:" };
        let named = |(a, b, x): &(String, String, f64)| {
            format!("`{}` and `{}` {how} {:.1} mm", esc(a), esc(b), x * 1e3)
        };
        let mut listed: Vec<String> = pairs.iter().take(3).map(named).collect();
        if pairs.len() > 3 {
            let more = pairs.len() - 3;
            listed.push(format!(
                "and {more} more {}",
                if more == 1 { "pair" } else { "pairs" }
            ));
        }
        let listed = listed.join(", ");
        // Pointed at what most likely placed them wrong (see `Owner::blame`).
        let blamed = Owner::blame(oa, ob, &table);
        let (line, col, width) = blamed.place(&table, text);
        let robot = [blamed, oa, ob].into_iter().find_map(|o| match o {
            Owner::Robot(i) => Some(cell.robots[i].name.clone()),
            _ => None,
        });
        let (wa, wb) = (oa.words(cell), ob.words(cell));
        let message = if collision {
            let then = if cell.stop_on_collision {
                "the run would stop with a collision at 0 s"
            } else {
                "the run would report a collision at 0 s"
            };
            let allow = match pairs.as_slice() {
                [(a, b, _)] => format!("[[\"{}\", \"{}\"]]", esc(a), esc(b)),
                _ => format!("[[\"{}\", \"{}\"]]", esc(oa.name(cell)), esc(ob.name(cell))),
            };
            format!(
                "{wa} and {wb} overlap at the start ({listed}): {then}; place them apart (change {}, or {}), or allow the pair (`allow_collision = {allow}`)",
                oa.keys(cell),
                ob.keys(cell)
            )
        } else {
            format!(
                "{wa} and {wb} come within the cell's clearance of {:.1} mm at the start ({listed})",
                cell.clearance * 1e3
            )
        };
        problems.push(Problem {
            error: collision,
            kind: if collision { "collision" } else { "near_miss" },
            robot,
            file: file.clone(),
            line,
            col,
            width,
            message,
        });
    }
}

/// What a body at the start belongs to: a robot, a device or a part (by index).
#[derive(Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Debug)]
enum Owner {
    Robot(usize),
    Device(usize),
    Part(usize),
}

impl Owner {
    /// The owner of the body `name` (`r1.link_2`, `table`).
    fn of(cell: &Cell, body: &str) -> Option<Owner> {
        let of_robot = |name: &str| {
            body == name
                || body
                    .strip_prefix(name)
                    .is_some_and(|rest| rest.starts_with('.'))
        };
        if let Some(i) = cell.robots.iter().position(|r| of_robot(&r.name)) {
            return Some(Owner::Robot(i));
        }
        if let Some(i) = cell.devices.iter().position(|d| d.name == body) {
            return Some(Owner::Device(i));
        }
        cell.parts
            .iter()
            .position(|p| p.name == body)
            .map(Owner::Part)
    }

    fn name(self, cell: &Cell) -> &str {
        match self {
            Owner::Robot(i) => &cell.robots[i].name,
            Owner::Device(i) => &cell.devices[i].name,
            Owner::Part(i) => &cell.parts[i].name,
        }
    }

    /// `robot \`r1\``, `device \`table\``.
    fn words(self, cell: &Cell) -> String {
        let what = match self {
            Owner::Robot(_) => "robot",
            Owner::Device(_) => "device",
            Owner::Part(_) => "part",
        };
        format!(
            "{what} `{}`",
            vworks_log::trace::escape_controls(self.name(cell))
        )
    }

    /// The keys that place it: `` `r1`'s `base` or `home` ``, `` `table`'s `pose` ``.
    fn keys(self, cell: &Cell) -> String {
        let name = vworks_log::trace::escape_controls(self.name(cell)).into_owned();
        match self {
            Owner::Robot(_) => format!("`{name}`'s `base` or `home`"),
            _ => format!("`{name}`'s `pose`"),
        }
    }

    /// Its table in the workcell file (`robot`, 1) and that table.
    fn table(self, table: &toml::Table) -> (&'static str, usize, Option<&toml::Value>) {
        let (list, i) = match self {
            Owner::Robot(i) => ("robot", i),
            Owner::Device(i) => ("device", i),
            Owner::Part(i) => ("part", i),
        };
        let t = table
            .get(list)
            .and_then(|l| l.as_array())
            .and_then(|l| l.get(i));
        (list, i, t)
    }

    /// Of two owners of touching bodies, the one whose placing most likely put them
    /// there: a robot with a `base` (robots stand at the origin unless moved), the later
    /// of two such robots, else a robot; of a device and a part, the part.
    fn blame(a: Owner, b: Owner, table: &toml::Table) -> Owner {
        let based = |o: Owner| {
            matches!(o, Owner::Robot(_))
                && o.table(table).2.is_some_and(|t| t.get("base").is_some())
        };
        match (a, b) {
            (Owner::Robot(_), Owner::Robot(_)) if based(a) && !based(b) => a,
            (_, Owner::Robot(_)) => b,
            (Owner::Robot(_), _) => a,
            _ => b,
        }
    }

    /// Where the workcell file places it: a robot's `base` if written, else its `home`;
    /// a device's or part's `pose`; else its table's header (`[[robot]]`).
    fn place(self, table: &toml::Table, text: &str) -> (u32, u32, usize) {
        let (list, i, t) = self.table(table);
        let keys: &[&str] = match self {
            Owner::Robot(_) => &["base", "home"],
            _ => &["pose"],
        };
        let written = keys
            .iter()
            .find(|k| t.is_some_and(|t| t.get(**k).is_some()));
        if let Some(range) = written.and_then(|k| locate(text, &format!("{list}[{i}].{k}"))) {
            return line_col(text, range);
        }
        // The table's header: the (i+1)-th `[[robot]]`.
        let header = format!("[[{list}]]");
        if let Some((line, _)) = headers(text)
            .into_iter()
            .filter(|(_, h)| *h == header)
            .nth(i)
        {
            let src = text.lines().nth(line - 1).unwrap_or_default();
            let col = src.chars().take_while(|c| c.is_whitespace()).count();
            return (
                line as u32,
                col as u32 + 1,
                src.trim().chars().count().max(1),
            );
        }
        locate(text, list).map_or((0, 0, 1), |r| line_col(text, r))
    }
}

/// Where a workcell key the loader names (`robot[0] \`r1\`.home[2]`, `cycle`, `line 3,
/// column 5`) is written: the byte range of the deepest part of it found in `text`.
fn locate(text: &str, key: &str) -> Option<Range<usize>> {
    if let Some(rest) = key.strip_prefix("line ") {
        let (line, col) = rest.split_once(", column ")?;
        let (line, col) = (line.parse::<usize>().ok()?, col.parse::<usize>().ok()?);
        let start: usize = text
            .split_inclusive('\n')
            .take(line.saturating_sub(1))
            .map(str::len)
            .sum();
        let in_line = text.get(start..)?.chars().take(col.saturating_sub(1));
        let at = start + in_line.map(char::len_utf8).sum::<usize>();
        return Some(at..at);
    }
    enum Seg {
        Key(String),
        Index(usize),
    }
    // The key's parts; a name in backticks (`robot[0] \`r1\``) is only a reminder.
    let mut segs = Vec::new();
    let mut word = String::new();
    let mut chars = key.chars().peekable();
    let flush = |word: &mut String, segs: &mut Vec<Seg>| {
        let w = std::mem::take(word);
        if !w.trim().is_empty() {
            segs.push(Seg::Key(w.trim().to_string()));
        }
    };
    while let Some(c) = chars.next() {
        match c {
            '`' => {
                for c in chars.by_ref() {
                    if c == '`' {
                        break;
                    }
                }
            }
            '.' => flush(&mut word, &mut segs),
            '[' => {
                flush(&mut word, &mut segs);
                let digits: String = chars.by_ref().take_while(|c| *c != ']').collect();
                segs.push(Seg::Index(digits.trim().parse().ok()?));
            }
            c => word.push(c),
        }
    }
    flush(&mut word, &mut segs);
    let root = toml::de::DeTable::parse(text).ok()?;
    let mut best = None;
    let mut table = Some(root.get_ref());
    let mut value: Option<&toml::de::DeValue<'_>> = None;
    for seg in &segs {
        match seg {
            Seg::Key(k) => {
                let t = match (table, value) {
                    (Some(t), _) => t,
                    (None, Some(toml::de::DeValue::Table(t))) => t,
                    _ => break,
                };
                let Some((name, v)) = t
                    .iter()
                    .find(|(name, _)| name.get_ref().as_ref() == k.as_str())
                else {
                    break;
                };
                best = Some(name.span());
                table = None;
                value = Some(v.get_ref());
            }
            Seg::Index(i) => {
                let Some(toml::de::DeValue::Array(a)) = value else {
                    break;
                };
                let Some(e) = a.get(*i) else { break };
                // An element of an array of tables (`[[robot]]`) has no span of its own
                // worth pointing at: keep the key's.
                if !matches!(e.get_ref(), toml::de::DeValue::Table(_)) || e.span().start > 0 {
                    let s = e.span();
                    if s.end > s.start {
                        best = Some(s);
                    }
                }
                table = None;
                value = Some(e.get_ref());
            }
        }
    }
    best
}

/// The 1-based line and column (in characters) of a byte range, and its width in
/// characters on its line (at least 1).
fn line_col(text: &str, r: Range<usize>) -> (u32, u32, usize) {
    let start = r.start.min(text.len());
    let before = text.get(..start).unwrap_or_default();
    let line = before.matches('\n').count() + 1;
    let line_start = before.rfind('\n').map_or(0, |i| i + 1);
    let col = before[line_start..].chars().count() + 1;
    let end = r.end.min(text.len()).max(start);
    let piece = text.get(start..end).unwrap_or_default();
    let width = if piece.is_empty() {
        // A place, not a span (a TOML syntax error): the word there.
        let rest = text.get(start..).unwrap_or_default();
        rest.chars()
            .take_while(|c| c.is_alphanumeric() || *c == '_' || *c == '-')
            .count()
    } else {
        piece.lines().next().map_or(0, |l| l.chars().count())
    };
    let width = width.max(1);
    (line as u32, col as u32, width)
}

/// A problem as the compiler's diagnostics print: the message, the place, the source line
/// with a caret under the place.
fn render(p: &Problem, sources: &[(String, String)], color: bool) -> String {
    let (sev, on, off) = match (p.error, color) {
        (true, true) => ("error", "\x1b[1;31m", "\x1b[0m"),
        (false, true) => ("warning", "\x1b[1;33m", "\x1b[0m"),
        (true, false) => ("error", "", ""),
        (false, false) => ("warning", "", ""),
    };
    let mut s = format!("{on}{sev}[{}]{off}: {}\n", p.kind, p.message);
    if p.line == 0 {
        s.push_str(&format!("  --> {}\n\n", p.file));
        return s;
    }
    s.push_str(&format!("  --> {}:{}:{}\n", p.file, p.line, p.col));
    let source = sources
        .iter()
        .find(|(f, _)| *f == p.file)
        .and_then(|(_, t)| t.lines().nth(p.line as usize - 1));
    // (Line 0 returned above.)
    if let Some(src) = source {
        let num = p.line.to_string();
        let pad = " ".repeat(num.len());
        let src = vworks_log::trace::escape_controls(src);
        let lead: String = src
            .chars()
            .take((p.col as usize).saturating_sub(1))
            .map(|c| if c == '\t' { '\t' } else { ' ' })
            .collect();
        s.push_str(&format!(
            "{pad} |\n{num} | {src}\n{pad} | {lead}{on}{}{off}\n",
            "^".repeat(p.width)
        ));
    }
    s.push('\n');
    s
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]
    use super::*;

    const CELL: &str = "name = \"c\"\ncycle = \"4ms\"\n\n[[robot]]\nname = \"r1\"\nmodel = \"irb120\"\nhome = [\"0deg\", \"200deg\"]\n\n[[device]]\nname = \"t\"\npose = { xyz = [\"1m\", \"0m\", \"0m\"] }\n";

    fn at(key: &str) -> (u32, u32, usize) {
        line_col(CELL, locate(CELL, key).unwrap())
    }

    #[test]
    fn a_key_the_loader_names_is_found_at_its_line() {
        assert_eq!(at("cycle"), (2, 1, 5));
        assert_eq!(at("robot[0] `r1`.home[1]"), (7, 17, 8));
        assert_eq!(at("robot[0] `r1`.home"), (7, 1, 4));
        assert_eq!(at("device[0] `t`.pose.xyz[0]"), (11, 17, 4));
        // A key that is not written: its nearest written part.
        assert_eq!(at("robot[0] `r1`.base.xyz[0]").0, 4);
        assert_eq!(at("line 5, column 3"), (5, 3, 2));
        assert_eq!(at("line 4, column 3"), (4, 3, 5));
        assert!(locate(CELL, "clearance").is_none());
    }
}
