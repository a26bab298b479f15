//! The link step: checks the modules of a cell against each other and the workcell.
//!
//! The SE calls [`link`] when it loads a workcell, before any simulation. It resolves
//! every cross-module reference — globals by name, `remote` targets, `signal` receivers,
//! gripped parts — into indices, and checks what the compiler could not know alone:
//! globals agree in type and initial value across the cell (both files are named on a
//! mismatch), remote procedures exist with matching parameters, signal receivers exist
//! (a warning if the receiver never waits for that signal), parts exist, every
//! `joints(…)` has one value per axis of the robot that runs it, and each robot's entry
//! procedure exists (unless the robot only serves remote requests).
//!
//! All outputs are in a deterministic order that does not depend on the robots' order in
//! the workcell: cell globals are sorted by name.

use std::collections::BTreeMap;

use vworks_vm::bytecode::{ProcKind, SrcPos};
use vworks_vm::{ConstValue, Dim, Module, Type};

use crate::diag::{Code, Diagnostic};

/// One robot of the cell, as the linker needs to know it.
#[derive(Debug, Clone, Copy)]
pub struct RobotSpec<'a> {
    /// The robot's name in the workcell.
    pub name: &'a str,
    /// The name of the task it runs, as sync points' task lists name it (RAPID's
    /// `T_ROB1`; the workcell's `task`, else the robot's name). Matched ignoring case.
    pub task: &'a str,
    /// The module it runs.
    pub module: &'a Module,
    /// Number of axes.
    pub axes: usize,
    /// Bit i set: axis i is prismatic (its joint value is a length).
    pub linear_axes: u16,
    /// The entry procedure (`main` when `None`).
    pub entry: Option<&'a str>,
    /// The robot only serves remote requests and needs no entry procedure.
    pub serve_only: bool,
}

impl<'a> RobotSpec<'a> {
    /// A robot with revolute axes only, starting at `main`.
    pub fn new(name: &'a str, module: &'a Module, axes: usize) -> RobotSpec<'a> {
        RobotSpec {
            name,
            task: name,
            module,
            axes,
            linear_axes: 0,
            entry: None,
            serve_only: false,
        }
    }
}

/// What the linker checks a cell against.
#[derive(Debug, Clone, Default)]
pub struct CellSpec<'a> {
    /// Robots, in workcell order.
    pub robots: Vec<RobotSpec<'a>>,
    /// Names of the parts robots may grip.
    pub parts: Vec<&'a str>,
}

/// A global of the whole cell.
#[derive(Debug, Clone, PartialEq)]
pub struct CellGlobal {
    /// Name.
    pub name: String,
    /// Type.
    pub ty: Type,
    /// Initial value.
    pub init: ConstValue,
}

/// A sync point of the cell: a barrier where the robots of its task list meet.
#[derive(Debug, Clone, PartialEq)]
pub struct CellSync {
    /// Its name, as the first program (in robot order) wrote it.
    pub name: String,
    /// The robots that meet there (robot indices, ascending).
    pub members: Vec<u32>,
}

/// The resolved cross-references of one robot, indexed like its module's tables.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct RobotLinks {
    /// Module global index → cell global index.
    pub globals: Vec<u32>,
    /// Remote site → (robot index, procedure index in that robot's module).
    pub remotes: Vec<(u32, u32)>,
    /// Signal site → receiving robot index.
    pub signals: Vec<u32>,
    /// Part site → part index.
    pub parts: Vec<u32>,
    /// Sync site → index in [`Linked::syncs`].
    pub syncs: Vec<u32>,
    /// The entry procedure's index, or `None` for a serve-only robot.
    pub entry: Option<u32>,
}

/// A linked cell.
#[derive(Debug, Clone, PartialEq)]
pub struct Linked {
    /// Every global of the cell, sorted by name.
    pub globals: Vec<CellGlobal>,
    /// Per robot, in workcell order.
    pub robots: Vec<RobotLinks>,
    /// The cell's sync points (barriers), sorted by name.
    pub syncs: Vec<CellSync>,
    /// Warnings (never errors).
    pub warnings: Vec<Diagnostic>,
}

/// Linking failed: every problem found, errors and warnings.
#[derive(Debug, Clone, thiserror::Error)]
#[error("{}", .diagnostics.iter().filter(|d| d.is_error()).map(Diagnostic::short).collect::<Vec<_>>().join("\n"))]
pub struct LinkError {
    /// All diagnostics.
    pub diagnostics: Vec<Diagnostic>,
}

fn at(m: &Module, code: Code, msg: String, pos: SrcPos) -> Diagnostic {
    Diagnostic::at_pos(code, msg, m.file_of(pos), pos.line, pos.col)
}

fn compatible(arg: Type, param: Type) -> bool {
    arg == param || (arg == Type::Int && param == Type::Num(Dim::PLAIN))
}

fn describe(t: Type) -> String {
    match t {
        Type::Int => "an int".into(),
        Type::Bool => "a bool".into(),
        Type::Num(d) => d.described(),
        Type::Joints => "joints".into(),
        Type::Pose => "a pose".into(),
        Type::Text => "a text".into(),
    }
}

/// Links the modules of a cell. See the module documentation for what is checked.
pub fn link(cell: &CellSpec<'_>) -> Result<Linked, LinkError> {
    let mut diags = Vec::new();
    let robot_index: BTreeMap<&str, usize> = cell
        .robots
        .iter()
        .enumerate()
        .map(|(i, r)| (r.name, i))
        .collect();
    let robot_list = || {
        cell.robots
            .iter()
            .map(|r| r.name)
            .collect::<Vec<_>>()
            .join(", ")
    };

    // Globals: one per name; every declaration must agree with the first (in name order
    // of the files, so the message does not depend on robot order).
    let mut decls: BTreeMap<&str, Vec<(&Module, usize)>> = BTreeMap::new();
    for r in &cell.robots {
        for (gi, g) in r.module.globals.iter().enumerate() {
            let list = decls.entry(r.module.str(g.name)).or_default();
            if !list.iter().any(|(m, _)| std::ptr::eq(*m, r.module)) {
                list.push((r.module, gi));
            }
        }
    }
    let mut globals = Vec::new();
    for (name, mut list) in decls {
        list.sort_by(|a, b| a.0.source_path().cmp(b.0.source_path()));
        let (m0, g0) = list[0];
        let first = &m0.globals[g0];
        for (m, gi) in &list[1..] {
            let g = &m.globals[*gi];
            let what = if g.ty != first.ty {
                Some(format!(
                    "type {} here but {} in {}",
                    g.ty,
                    first.ty,
                    m0.source_path()
                ))
            } else if g.init != first.init {
                Some(format!(
                    "initial value {} here but {} in {}",
                    g.init.display(g.ty),
                    first.init.display(first.ty),
                    m0.source_path()
                ))
            } else {
                None
            };
            if let Some(what) = what {
                diags.push(
                    at(m, Code::E0100, format!("global `{name}` has {what}"), g.pos)
                        .with_related_pos(m0.file_of(first.pos), first.pos.line, first.pos.col, "the other declaration")
                        .with_help("every module that declares a global must give it the same type and initial value"),
                );
            }
        }
        globals.push(CellGlobal {
            name: name.to_string(),
            ty: first.ty,
            init: first.init.clone(),
        });
    }

    let mut robots = Vec::new();
    for r in &cell.robots {
        let m = r.module;
        let mut links = RobotLinks {
            globals: m
                .globals
                .iter()
                .map(|g| {
                    globals
                        .iter()
                        .position(|c| c.name == m.str(g.name))
                        .unwrap_or(0) as u32
                })
                .collect(),
            ..RobotLinks::default()
        };
        for site in &m.remotes {
            let target = m.str(site.robot);
            let pname = m.str(site.proc);
            let Some(&ti) = robot_index.get(target) else {
                diags.push(
                    at(
                        m,
                        Code::E0101,
                        format!("`remote {target}.{pname}(…)`: the cell has no robot `{target}`"),
                        site.pos,
                    )
                    .with_help(format!("the robots are: {}", robot_list())),
                );
                links.remotes.push((0, 0));
                continue;
            };
            let tm = cell.robots[ti].module;
            let Some(pi) = tm
                .proc_index(pname)
                .filter(|&p| tm.procs[p as usize].kind == ProcKind::Proc)
            else {
                diags.push(
                    at(
                        m,
                        Code::E0102,
                        format!(
                            "robot `{target}` runs {}, which has no procedure `{pname}`",
                            tm.source_path()
                        ),
                        site.pos,
                    )
                    .with_help(format!("declare `proc {pname}(…)` in {}", tm.source_path())),
                );
                links.remotes.push((ti as u32, 0));
                continue;
            };
            let proc = &tm.procs[pi as usize];
            let params: Vec<Type> = proc.params.iter().map(|p| p.ty).collect();
            if params.len() != site.args.len()
                || site
                    .args
                    .iter()
                    .zip(&params)
                    .any(|(a, p)| !compatible(*a, *p))
            {
                let want: Vec<String> = proc
                    .params
                    .iter()
                    .map(|p| format!("{}: {}", tm.str(p.name), p.ty))
                    .collect();
                let got: Vec<String> = site.args.iter().map(|t| describe(*t)).collect();
                diags.push(
                    at(
                        m,
                        Code::E0103,
                        format!(
                            "`remote {target}.{pname}` is given ({}) but `{pname}` takes ({})",
                            got.join(", "),
                            want.join(", ")
                        ),
                        site.pos,
                    )
                    .with_related_pos(
                        tm.file_of(proc.pos),
                        proc.pos.line,
                        proc.pos.col,
                        "declared here",
                    ),
                );
            }
            links.remotes.push((ti as u32, pi));
        }
        for site in &m.signals_sent {
            let target = m.str(site.robot);
            let name = m.str(site.name);
            match robot_index.get(target) {
                None => {
                    diags.push(
                        at(
                            m,
                            Code::E0101,
                            format!("`signal {target}.{name}`: the cell has no robot `{target}`"),
                            site.pos,
                        )
                        .with_help(format!("the robots are: {}", robot_list())),
                    );
                    links.signals.push(0);
                }
                Some(&ti) => {
                    let tm = cell.robots[ti].module;
                    if !tm.signals_awaited.iter().any(|s| tm.str(*s) == name) {
                        diags.push(
                            at(
                                m,
                                Code::W0003,
                                format!(
                                    "robot `{target}` ({}) never waits for the signal `{name}`",
                                    tm.source_path()
                                ),
                                site.pos,
                            )
                            .with_help(format!(
                                "add `wait_signal {name};` to {}, or remove this signal",
                                tm.source_path()
                            )),
                        );
                    }
                    links.signals.push(ti as u32);
                }
            }
        }
        for site in &m.parts {
            let name = m.str(site.part);
            match cell.parts.iter().position(|p| *p == name) {
                Some(i) => links.parts.push(i as u32),
                None => {
                    let known = if cell.parts.is_empty() {
                        "the cell has no parts".to_string()
                    } else {
                        format!("the parts are: {}", cell.parts.join(", "))
                    };
                    diags.push(
                        at(m, Code::E0104, format!("robot `{}` grips or releases `{name}`, which is not a part of the cell", r.name), site.pos)
                            .with_help(format!("add a [[part]] named `{name}` to the workcell; {known}")),
                    );
                    links.parts.push(0);
                }
            }
        }
        for site in &m.joints_sites {
            if site.count as usize != r.axes {
                diags.push(
                    at(
                        m,
                        Code::E0105,
                        format!(
                            "joints(…) has {} values, but robot `{}` has {} axes",
                            site.count, r.name, r.axes
                        ),
                        site.pos,
                    )
                    .with_help("give one value per axis"),
                );
            } else {
                let wrong =
                    (0..r.axes).find(|i| (site.linear_mask >> i) & 1 != (r.linear_axes >> i) & 1);
                if let Some(i) = wrong {
                    let (want, got) = if (r.linear_axes >> i) & 1 == 1 {
                        ("a length", "an angle")
                    } else {
                        ("an angle", "a length")
                    };
                    diags.push(at(
                        m,
                        Code::E0105,
                        format!("the value for axis {i} is {got}, but axis {i} of robot `{}` needs {want}", r.name),
                        site.pos,
                    ).with_help("revolute axes take angles (30deg), linear axes lengths (500mm)"));
                }
            }
        }
        let entry = r.entry.unwrap_or("main");
        if r.serve_only {
            links.entry = None;
        } else {
            match m.proc_index(entry).map(|p| (p, &m.procs[p as usize])) {
                Some((p, info)) if info.kind == ProcKind::Proc && info.params.is_empty() => links.entry = Some(p),
                Some((_, info)) => diags.push(
                    at(m, Code::E0106, format!("the entry `{entry}` of robot `{}` must be a procedure without parameters", r.name), info.pos)
                        .with_help(format!("declare `proc {entry}() {{ … }}`")),
                ),
                None => diags.push(
                    Diagnostic::at_pos(Code::E0106, format!("robot `{}` starts at `{entry}`, but {} has no `proc {entry}()`", r.name, m.source_path()), m.source_path(), 1, 1)
                        .with_help(format!("add `proc {entry}() {{ … }}`, name another entry in the workcell, or mark the robot `serve_only = true`")),
                ),
            }
        }
        robots.push(links);
    }
    let syncs = link_syncs(cell, &mut robots, &mut diags);
    if diags.iter().any(Diagnostic::is_error) {
        return Err(LinkError { diagnostics: diags });
    }
    Ok(Linked {
        globals,
        robots,
        syncs,
        warnings: diags,
    })
}

/// Sync points: every task a site's list names is a robot's task (ignoring case), the
/// list holds the robot's own task, and every site of one sync point (by name, ignoring
/// case) lists the same robots. Fills each robot's `syncs` and returns the cell's sync
/// points, sorted by name.
fn link_syncs(
    cell: &CellSpec<'_>,
    robots: &mut [RobotLinks],
    diags: &mut Vec<Diagnostic>,
) -> Vec<CellSync> {
    let tasks = || {
        cell.robots
            .iter()
            .map(|r| format!("{} (robot {})", r.task, r.name))
            .collect::<Vec<_>>()
            .join(", ")
    };
    // Per sync point (lower-case name): its name as first written, its members, where.
    let mut points: BTreeMap<String, (String, Vec<u32>)> = BTreeMap::new();
    let mut sites: Vec<Vec<String>> = Vec::new();
    for (ri, r) in cell.robots.iter().enumerate() {
        let m = r.module;
        let shared = cell.robots[..ri].iter().any(|q| std::ptr::eq(q.module, m));
        let mut keys = Vec::new();
        for site in &m.syncs {
            let name = m.str(site.name);
            let mut members = Vec::new();
            let mut all_known = true;
            for t in &site.tasks {
                let t = m.str(*t);
                match cell
                    .robots
                    .iter()
                    .position(|q| q.task.eq_ignore_ascii_case(t))
                {
                    Some(q) => members.push(q as u32),
                    // (Robots that run one program report its unknown tasks once.)
                    None if shared => all_known = false,
                    None => {
                        all_known = false;
                        diags.push(
                        at(m, Code::E0107, format!("sync point `{name}`: no robot of the cell runs the task `{t}`"), site.pos)
                            .with_help(format!("the tasks are: {}; a RAPID task's name goes in its robot's `task` key of the workcell (`task = \"T_ROB1\"`)", tasks())),
                    );
                    }
                }
            }
            members.sort_unstable();
            members.dedup();
            if all_known && !members.contains(&(ri as u32)) {
                diags.push(
                    at(m, Code::E0107, format!("sync point `{name}`: the task list does not hold this robot's own task `{}`", r.task), site.pos)
                        .with_help("a task meets the others at a sync point only if its list names it too"),
                );
            }
            let key = name.to_lowercase();
            let listed = |members: &[u32]| {
                members
                    .iter()
                    .map(|q| cell.robots[*q as usize].task)
                    .collect::<Vec<_>>()
                    .join(", ")
            };
            match points.get(&key) {
                // (A list with an unknown task is reported as such, not compared.)
                _ if !all_known => {}
                Some((_, have)) if *have != members => diags.push(
                    at(m, Code::E0107, format!("sync point `{name}` lists the tasks {} here, but {} where another task meets there", listed(&members), listed(have)), site.pos)
                        .with_help("every task that meets at one sync point must list the same tasks"),
                ),
                Some(_) => {}
                None => {
                    points.insert(key.clone(), (name.to_string(), members));
                }
            }
            keys.push(key);
        }
        sites.push(keys);
    }
    let index: BTreeMap<&String, u32> = points
        .keys()
        .enumerate()
        .map(|(i, k)| (k, i as u32))
        .collect();
    for (links, keys) in robots.iter_mut().zip(&sites) {
        links.syncs = keys
            .iter()
            .map(|k| index.get(k).copied().unwrap_or(0))
            .collect();
    }
    points
        .into_values()
        .map(|(name, members)| CellSync { name, members })
        .collect()
}
