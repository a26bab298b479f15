//! Loading a workcell: the file's settings checked, models loaded, programs compiled
//! and linked (through the cache the variants share), bodies shaped.

use std::collections::BTreeMap;
use std::path::Path;
use std::sync::Arc;

use vworks_model::builtin;
use vworks_model::files::{Disk, Files};
use vworks_model::model::Geometry;
use vworks_model::urdf::{LoadOptions, load_file_with};
use vworks_vm::{Dim, Module};
use vworks_wslc::link::{CellSpec, Linked, RobotSpec, link};
use vworks_wslc::{Sources, Stage};

use crate::cache::{Cache, Compiled, ModelKey, ProgramKey};
use crate::cell::{Cell, DEFAULT_GRIP_DISTANCE, Robot, same_link};
use crate::context::{Ctx, MAX_LENGTH, read_hint};
use crate::error::CellError;
use crate::file::CellFile;
use crate::paths::{program_files, ros_package_paths};
use crate::{io, params, paths};

/// Loads a workcell file: models, programs (compiled and linked), shapes.
pub fn load(path: &Path) -> Result<Cell, CellError> {
    load_with(path, &Disk)
}

/// Loads a workcell, reading it and every file it names (programs, URDFs, meshes) from
/// `files`: the disk, or memory ([`MemoryFiles`](crate::MemoryFiles)).
pub fn load_with(path: &Path, fs: &dyn Files) -> Result<Cell, CellError> {
    let (text, cf) = read_cell_file(path, fs)?;
    load_parsed(path, &text, cf, fs, &Cache::default(), None)
}

/// Loads a workcell as `vworks check` does, to find every problem it can: as [`load`],
/// but a program that does not compile is replaced by an empty one (no code, no entry)
/// and the loading goes on (the other robots' programs, every home, base and body), and
/// a link that fails leaves [`Cell::linked`] empty. Returns the workcell (or its first
/// problem, as [`load`] says it) and the programs' compile or link error, if any.
pub fn load_checking(path: &Path) -> (Result<Cell, CellError>, Option<CellError>) {
    let (text, cf) = match read_cell_file(path, &Disk) {
        Ok(read) => read,
        Err(e) => return (Err(e), None),
    };
    let mut programs = None;
    let cell = load_parsed(
        path,
        &text,
        cf,
        &Disk,
        &Cache::default(),
        Some(&mut programs),
    );
    (cell, programs)
}

/// programs and models come from `cache` when it has them.
pub(crate) fn load_parsed(
    path: &Path,
    text: &str,
    cf: CellFile,
    fs: &dyn Files,
    cache: &Cache,
    mut lenient: Option<&mut Option<CellError>>,
) -> Result<Cell, CellError> {
    let file = path.display().to_string();
    let cx = Ctx {
        file: &file,
        files: fs,
    };
    let dir = path.parent().map(Path::to_path_buf).unwrap_or_default();
    let cycle = match &cf.cycle {
        Some(v) => cx.quantity(v, Dim::TIME, "cycle")?,
        None => 0.004,
    };
    if !(1e-4..=0.1).contains(&cycle) {
        return Err(cx.bad(
            "cycle",
            format!("{cycle} s is outside the allowed 0.1 ms to 100 ms; write e.g. \"4ms\""),
        ));
    }
    let clearance = match &cf.clearance {
        Some(v) => cx.quantity(v, Dim::LENGTH, "clearance")?,
        None => 0.0,
    };
    if clearance < 0.0 {
        return Err(cx.bad("clearance", "cannot be negative"));
    }
    let grip_distance = match &cf.grip_distance {
        Some(v) => cx.grip_distance(v, "grip_distance")?,
        None => DEFAULT_GRIP_DISTANCE,
    };
    let stop_on_collision = match cf.on_collision.as_deref() {
        None | Some("stop") => true,
        Some("continue") => false,
        Some(other) => {
            return Err(cx.bad(
                "on_collision",
                format!("`{other}` is not a choice; write \"stop\" or \"continue\""),
            ));
        }
    };
    if cf.robot.is_empty() {
        return Err(cx.bad("robot", "the cell has no robot; add a [[robot]] table"));
    }
    let mut names: Vec<&str> = Vec::new();
    for (k, n) in cf
        .robot
        .iter()
        .map(|r| ("robot", r.name.as_str()))
        .chain(cf.device.iter().map(|d| ("device", d.name.as_str())))
        .chain(cf.part.iter().map(|p| ("part", p.name.as_str())))
    {
        if names.contains(&n) {
            return Err(cx.bad(
                k,
                format!(
                    "the name `{n}` is used twice; robots, devices and parts need unique names"
                ),
            ));
        }
        names.push(n);
    }

    let mut sources = vec![(file.clone(), text.to_string())];
    let mut files: Vec<(String, Vec<u8>)> = Vec::new();
    let mut robots = Vec::new();
    // Each task name (lower case), the robot that runs it and the name as written (not an
    // index into `robots`: a robot whose program has errors is never pushed there).
    let mut tasks: BTreeMap<String, (String, String)> = BTreeMap::new();
    let mut modules: Vec<(ProgramKey, Arc<Module>)> = Vec::new();
    let mut diagnostics = Vec::new();
    let mut warnings = Vec::new();
    let mut render_sources = Sources::new();
    let mut param_copies = Vec::new();
    let robot_names: Vec<&str> = cf.robot.iter().map(|r| r.name.as_str()).collect();
    let wiring = io::signals(&cx, &cf.io, &robot_names)?;
    for (i, r) in cf.robot.iter().enumerate() {
        let key = format!("robot[{i}] `{}`", r.name);
        let model_key = ModelKey {
            model: r.model.clone(),
            urdf: r.urdf.clone(),
            tool_link: r.tool_link.clone(),
            package_path: r.package_path.clone(),
            jerk: r.jerk.as_ref().map(toml::Value::to_string),
            tcp: [&r.tcp_speed, &r.tcp_acceleration]
                .map(|v| v.as_ref().map(toml::Value::to_string)),
        };
        let model = if let Some((m, urdf)) = cache.model(&model_key) {
            files.extend(urdf);
            m
        } else {
            let mut model = match (&r.model, &r.urdf) {
            (Some(m), None) => {
                builtin::load(m).map_err(|e| cx.bad(&format!("{key}.model"), e.to_string()))?
            }
            (None, Some(u)) => {
                let upath = dir.join(u);
                if let Ok(bytes) = fs.read(&upath) {
                    files.push((upath.display().to_string(), bytes));
                }
                let opts = LoadOptions {
                    tool_link: r.tool_link.clone(),
                    package_paths: r
                        .package_path
                        .iter()
                        .map(|p| dir.join(p))
                        .chain(ros_package_paths())
                        .collect(),
                };
                load_file_with(&dir.join(u), &opts, fs).map_err(|e| CellError::Model {
                    file: file.clone(),
                    robot: r.name.clone(),
                    source: Box::new(e),
                })?
            }
            _ => return Err(cx.bad(
                &key,
                "give either `model` (a built-in robot) or `urdf` (a file), not both or neither",
            )),
        };
            if let Some(jerk) = &r.jerk {
                cx.override_jerk(&mut model, jerk, &format!("{key}.jerk"))?;
            }
            // The TCP's limits, replacing the model's (a payload, a process, a safety
            // configuration can lower them).
            let tcp_limit = |value: &Option<toml::Value>, name: &str, dim, hint: &str| {
                let Some(value) = value else { return Ok(None) };
                let at = format!("{key}.{name}");
                let x = cx.quantity(value, dim, &at)?;
                if x.is_finite() && x > 0.0 {
                    Ok(Some(x))
                } else {
                    Err(cx.bad(&at, format!("must be greater than 0; write {hint}")))
                }
            };
            let speed = "\"1500mm/s\" or 1.5 (m/s)";
            if let Some(v) = tcp_limit(&r.tcp_speed, "tcp_speed", Dim::SPEED, speed)? {
                model.tcp.speed = Some(v);
            }
            let accel = "\"5m/s2\" or 5 (m/s²)";
            if let Some(a) = tcp_limit(&r.tcp_acceleration, "tcp_acceleration", Dim::ACCEL, accel)?
            {
                model.tcp.accel = Some(a);
            }
            let urdf = r.urdf.as_ref().and_then(|u| {
                let upath = dir.join(u).display().to_string();
                files.iter().find(|(f, _)| *f == upath).cloned()
            });
            cache.keep_model(model_key, Arc::new(model), urdf)
        };
        let serve_only = r.serve_only.unwrap_or(false);
        let task = match &r.task {
            None => r.name.clone(),
            Some(t) => {
                let ok = !t.is_empty()
                    && t.chars().all(|c| c.is_ascii_alphanumeric() || c == '_')
                    && !t.starts_with(|c: char| c.is_ascii_digit());
                if !ok {
                    return Err(cx.bad(
                        &format!("{key}.task"),
                        format!("`{t}` is not a task name: write a name of letters, digits and `_` (`task = \"T_ROB1\"`)"),
                    ));
                }
                t.clone()
            }
        };
        if let Some((robot, written)) = tasks.get(&task.to_ascii_lowercase()) {
            return Err(cx.bad(
                &format!("{key}.task"),
                format!(
                    "robot `{robot}` already runs the task `{written}`: give each robot a task name of its own"
                ),
            ));
        }
        tasks.insert(task.to_ascii_lowercase(), (r.name.clone(), task.clone()));
        let Some(program) = &r.program else {
            return Err(cx.bad(
                &format!("{key}.program"),
                "every robot needs a program file (`program = \"r1.wsl\"`)",
            ));
        };
        let pnames = program_files(&cx, &key, program, &dir)?;
        let pname = pnames[0].clone();
        let language = vworks_wslc::Language::of_path(&pname);
        // A RAPID program is compiled with its robot's wired signals: robots that share a
        // file but not their signals get a copy each.
        let signals = match (&wiring, language) {
            (Some(w), vworks_wslc::Language::Rapid) => w.get(i).map(Vec::as_slice),
            _ => None,
        };
        let mkey = ProgramKey {
            files: pnames.clone(),
            signals: signals.map(<[_]>::to_vec),
        };
        let mut stub = false;
        let module = match modules.iter().find(|(p, _)| *p == mkey) {
            Some((_, m)) => Arc::clone(m),
            None => {
                let compiled = match cache.program(&mkey) {
                    Some(c) => c,
                    None => {
                        let mut texts = Vec::with_capacity(pnames.len());
                        for (k, name) in pnames.iter().enumerate() {
                            let at = if pnames.len() > 1 {
                                format!("{key}.program[{k}]")
                            } else {
                                format!("{key}.program")
                            };
                            let bytes = fs.read(Path::new(name)).map_err(|e| {
                                cx.bad(&at, format!("cannot read `{name}`: {e}{}", read_hint(&e)))
                            })?;
                            let src = vworks_wslc::source_text_of(name, bytes)
                                .map_err(|e| cx.bad(&at, format!("{name}: {e}")))?;
                            texts.push((name.clone(), src));
                        }
                        let files: Vec<(&str, &str)> = texts
                            .iter()
                            .map(|(p, t)| (p.as_str(), t.as_str()))
                            .collect();
                        let result = vworks_wslc::compile_program(language, &files, signals)
                            .map(|out| (Arc::new(out.module), out.warnings))
                            .map_err(|e| e.diagnostics);
                        cache.keep_program(
                            &mkey,
                            Compiled {
                                sources: texts,
                                result,
                            },
                        )
                    }
                };
                for (path, text) in &compiled.sources {
                    render_sources.add(path, text);
                    if !sources.iter().any(|(p, _)| p == path) {
                        sources.push((path.clone(), text.clone()));
                    }
                }
                match &compiled.result {
                    Ok((m, w)) => {
                        warnings.extend(w.iter().cloned());
                        modules.push((mkey, Arc::clone(m)));
                        Arc::clone(m)
                    }
                    Err(d) => {
                        diagnostics.extend(d.iter().cloned());
                        let Some(out) = lenient.as_deref_mut() else {
                            continue;
                        };
                        let rendered = vworks_wslc::render(&diagnostics, &render_sources, false);
                        *out = Some(CellError::Program {
                            stage: Stage::Compile,
                            diagnostics: diagnostics.clone(),
                            rendered,
                        });
                        stub = true;
                        Arc::new(Module {
                            files: pnames.clone(),
                            ..Module::default()
                        })
                    }
                }
            }
        };
        // (A program that did not compile: its params are not known.)
        let module = if stub {
            module
        } else {
            params::apply(
                &cx,
                &key,
                &pname,
                module,
                &r.params,
                &cf.params,
                &mut param_copies,
            )?
        };
        let home = match &r.home {
            None => vec![0.0; model.dof()],
            Some(v) => {
                if v.len() != model.dof() {
                    return Err(cx.bad(
                        &format!("{key}.home"),
                        format!(
                            "has {} values but the robot has {} axes",
                            v.len(),
                            model.dof()
                        ),
                    ));
                }
                let mut h = Vec::new();
                for (k, x) in v.iter().enumerate() {
                    let dim = if (model.linear_axes() >> k) & 1 == 1 {
                        Dim::LENGTH
                    } else {
                        Dim::ANGLE
                    };
                    let v = cx.quantity(x, dim, &format!("{key}.home[{k}]"))?;
                    let j = model.axis(k);
                    if v < j.lower - 1e-9 || v > j.upper + 1e-9 {
                        return Err(cx.bad(
                            &format!("{key}.home[{k}]"),
                            format!(
                                "{} is outside axis {} `{}`'s range {} to {}; choose a home within the limits",
                                j.display(v),
                                k + 1,
                                j.name,
                                j.display(j.lower),
                                j.display(j.upper)
                            ),
                        ));
                    }
                    h.push(v);
                }
                h
            }
        };
        let default_speed = match &r.default_speed {
            Some(v) => cx.quantity(v, Dim::SPEED, &format!("{key}.default_speed"))?,
            None => 0.25,
        };
        if default_speed <= 0.0 {
            return Err(cx.bad(
                &format!("{key}.default_speed"),
                "must be greater than zero: it is the speed of every move_l and move_c without `speed`; write e.g. \"250mm/s\"",
            ));
        }
        let default_zone = match &r.default_zone {
            None => None,
            Some(toml::Value::String(s)) if s.trim() == "fine" => None,
            Some(v) => {
                let at = format!("{key}.default_zone");
                let hint: &dyn Fn() -> &'static str = &|| "a radius such as \"10mm\", or \"fine\"";
                let z = cx.quantity_unchecked(v, Dim::LENGTH, &at, hint)?;
                if !z.is_finite() || z > MAX_LENGTH {
                    return Err(
                        cx.bad(&at, format!("{z} m is not a zone radius; write {}", hint()))
                    );
                }
                if z < 0.0 {
                    return Err(cx.bad(
                        &at,
                        "cannot be negative: it is the zone radius of every motion without `zone`; write e.g. \"10mm\", or \"fine\" to stop at every point",
                    ));
                }
                (z > 0.0).then_some(z)
            }
        };
        let robot_grip_distance = match &r.grip_distance {
            Some(v) => cx.grip_distance(v, &format!("{key}.grip_distance"))?,
            None => grip_distance,
        };
        let mut signal_names: Vec<(String, String)> = signals
            .unwrap_or_default()
            .iter()
            .map(|sg| (sg.global.clone(), sg.name.clone()))
            .collect();
        signal_names.sort();
        let entry_name = r.entry.clone().unwrap_or_else(|| "main".into());
        let entry = if serve_only {
            None
        } else {
            module.proc_index(&entry_name)
        };
        robots.push((
            Robot {
                name: r.name.clone(),
                base: cx.pose(r.base.as_ref(), &format!("{key}.base"))?,
                tool: cx.pose(r.tool.as_ref(), &format!("{key}.tool"))?,
                model,
                module,
                program: pname,
                entry,
                default_speed,
                default_zone,
                grip_distance: robot_grip_distance,
                home,
                task,
                signal_names,
            },
            entry_name,
            serve_only,
        ));
    }
    if diagnostics.is_empty() {
        params::check_cell_params(&cx, &cf.params, modules.iter().map(|(_, m)| m))?;
    }
    if !diagnostics.is_empty() && lenient.is_none() {
        let rendered = vworks_wslc::render(&diagnostics, &render_sources, false);
        return Err(CellError::Program {
            stage: Stage::Compile,
            diagnostics,
            rendered,
        });
    }
    let devices = cf
        .device
        .iter()
        .enumerate()
        .map(|(i, d)| cx.body(d, &format!("device[{i}] `{}`", d.name), &dir))
        .collect::<Result<Vec<_>, _>>()?;
    let parts = cf
        .part
        .iter()
        .enumerate()
        .map(|(i, p)| cx.body(p, &format!("part[{i}] `{}`", p.name), &dir))
        .collect::<Result<Vec<_>, _>>()?;
    let part_names: Vec<&str> = parts.iter().map(|p| p.name.as_str()).collect();
    let spec = CellSpec {
        robots: robots
            .iter()
            .map(|(r, entry, serve)| RobotSpec {
                name: &r.name,
                task: &r.task,
                module: &r.module,
                axes: r.model.dof(),
                linear_axes: r.model.linear_axes(),
                entry: Some(entry.as_str()),
                serve_only: *serve,
            })
            .collect(),
        parts: part_names,
    };
    let no_links = || Linked {
        globals: Vec::new(),
        robots: Vec::new(),
        syncs: Vec::new(),
        warnings: Vec::new(),
    };
    // (Checking programs that did not compile: linking their stand-ins says nothing.)
    let linked = match (diagnostics.is_empty()).then(|| link(&spec)) {
        None => no_links(),
        Some(Ok(linked)) => linked,
        Some(Err(e)) => {
            let e = CellError::Program {
                stage: Stage::Link,
                rendered: vworks_wslc::render(&e.diagnostics, &render_sources, false),
                diagnostics: e.diagnostics,
            };
            match lenient {
                Some(out) => {
                    *out = Some(e);
                    no_links()
                }
                None => return Err(e),
            }
        }
    };
    let mut allowed = Vec::new();
    // `allow_collision` at the top, or written after a table (and so inside it in TOML).
    let all_pairs: Vec<&Vec<String>> = cf
        .allow_collision
        .iter()
        .chain(cf.robot.iter().flat_map(|r| r.allow_collision.iter()))
        .chain(cf.device.iter().flat_map(|d| d.allow_collision.iter()))
        .chain(cf.part.iter().flat_map(|p| p.allow_collision.iter()))
        .collect();
    for (i, pair) in all_pairs.into_iter().enumerate() {
        let [a, b] = pair.as_slice() else {
            return Err(cx.bad(
                &format!("allow_collision[{i}]"),
                "each entry is a pair: [\"r1.link_6\", \"part1\"]",
            ));
        };
        for n in [a, b] {
            let (owner, link) = n.split_once('.').unwrap_or((n.as_str(), ""));
            let known = robots.iter().any(|(r, _, _)| {
                r.name == owner
                    && (link.is_empty() || r.model.links.iter().any(|l| same_link(&l.name, link)))
            }) || (link.is_empty()
                && (cf.device.iter().any(|d| d.name == owner)
                    || cf.part.iter().any(|p| p.name == owner)));
            if !known {
                return Err(cx.bad(&format!("allow_collision[{i}]"), format!("`{n}` is not a body of the cell; name a device, a part, a robot, or a robot's link as ROBOT.LINK")));
            }
        }
        allowed.push((a.clone(), b.clone()));
    }
    // Meshes, for the log's attachments: each hull's file once, in load order.
    let hulls = robots
        .iter()
        .flat_map(|(r, _, _)| r.model.links.iter().flat_map(|l| l.shapes.iter()))
        .map(|s| &s.geometry)
        .chain(devices.iter().chain(&parts).map(|b| &b.geometry));
    for g in hulls {
        if let Geometry::Hull { source, .. } = g
            && !files.iter().any(|(f, _)| f == source)
            && let Ok(bytes) = fs.read(Path::new(source))
        {
            files.push((source.clone(), bytes));
        }
    }
    Ok(Cell {
        name: cf.name.unwrap_or_else(|| {
            path.file_stem()
                .map(|s| s.to_string_lossy().into_owned())
                .unwrap_or_default()
        }),
        file: path.to_path_buf(),
        cycle_ns: (cycle * 1e9).round() as i64,
        clearance,
        grip_distance,
        stop_on_collision,
        robots: robots.into_iter().map(|(r, _, _)| r).collect(),
        devices,
        parts,
        allowed,
        sources,
        files,
        warnings: warnings
            .into_iter()
            .chain(linked.warnings.iter().cloned())
            .collect(),
        linked,
        overrides: Vec::new(),
    })
}

/// The workcell file's text and its parsed form (errors with line and column).
pub(crate) fn read_cell_file(path: &Path, fs: &dyn Files) -> Result<(String, CellFile), CellError> {
    let file = path.display().to_string();
    let bytes = fs.read(path).map_err(|e| CellError::Read {
        file: file.clone(),
        reason: match e.kind() {
            std::io::ErrorKind::NotFound => format!(
                "{e}; check the path (relative to the current folder); `vworks new NAME` creates a workcell"
            ),
            _ => format!("{e}{}", read_hint(&e)),
        },
    })?;
    let text = vworks_wslc::source_text(bytes).map_err(|e| CellError::Read {
        file: file.clone(),
        reason: e.to_string(),
    })?;
    let cx = Ctx {
        file: &file,
        files: fs,
    };
    let cf: CellFile = toml::from_str(&text).map_err(|e| paths::parse_error(&cx, &text, &e))?;
    Ok((text, cf))
}

/// Every unknown or misspelt key of the workcell file `path` whose text is `text`, each
/// as the loader says it (`line 7, column 1`: "unknown field `modle`, …; did you mean
/// `model`?"), in file order: the file parsed again with each such key's line commented
/// out, as long as that leaves it valid TOML (a key whose value runs over several lines
/// ends the search). Empty if the first problem of the file is not an unknown key.
pub fn unknown_keys(path: &Path, text: &str) -> Vec<CellError> {
    let file = path.display().to_string();
    let cx = Ctx {
        file: &file,
        files: &Disk,
    };
    let mut text = text.to_string();
    let mut found = Vec::new();
    while found.len() < 100 {
        let Err(e) = toml::from_str::<CellFile>(&text) else {
            break;
        };
        let Some(start) = e.span().map(|s| s.start.min(text.len())) else {
            break;
        };
        let Some(before) = text.get(..start) else {
            break;
        };
        let line_start = before.rfind('\n').map_or(0, |i| i + 1);
        // Only a `key = value` line can go (not a table's header, not a key inside one).
        let own_line = before[line_start..].trim().is_empty();
        if !e.message().starts_with("unknown field") || !own_line {
            break;
        }
        found.push((
            before.matches('\n').count(),
            paths::parse_error(&cx, &text, &e),
        ));
        text.insert(line_start, '#');
    }
    // (serde finds them in its own order.)
    found.sort_by_key(|(line, _)| *line);
    found.into_iter().map(|(_, e)| e).collect()
}
