//! Workcell files (TOML): robots, devices, parts and settings, loaded into a [`Cell`]
//! ready to simulate — models loaded, programs compiled and linked, shapes built.
//!
//! Plain numbers are SI (m, rad, s); strings carry units exactly as in WSL (`"4ms"`,
//! `"250mm/s"`, `"90deg"`). Paths are relative to the workcell file. Every problem is a
//! [`CellError`] naming the file, the key and what to do.
//!
//! A workcell sets its programs' `param`s (`[params]`, `[robot.params]`: module
//! [`params`]), and [`Loader`] loads many variants of one workcell, each with a few values
//! changed by their dotted paths (`robot.r2.base.xyz.0`), compiling each program and
//! loading each model once (module [`variants`]).

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::sync::Arc;

use parry3d::shape::SharedShape;
use serde::Deserialize;
pub use vworks_model::files::{Disk, Files, MemoryFiles};
use vworks_model::math::Iso;
use vworks_model::model::Geometry;
use vworks_model::text::{escape_controls, escape_controls_owned};
use vworks_model::urdf::{LoadOptions, load_file_with};
use vworks_model::{RobotModel, builtin};
use vworks_vm::{Dim, Module};
pub use vworks_wslc::Stage;
use vworks_wslc::link::{CellSpec, Linked, RobotSpec, link};
use vworks_wslc::{Diagnostic, Sources};

mod io;
mod paths;
use paths::{program_files, read_hint, ros_package_paths};
pub mod params;
pub mod variants;

use variants::{Cache, Compiled, ModelKey, ProgramKey};
pub use variants::{Loader, Override};
/// Quantities as a workcell reads them (`"250mm"`, `0.25`), with WSL's units.
pub use vworks_wslc::units::{Quantity, parse_quantity};

/// Why a workcell could not be loaded.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum CellError {
    /// A file could not be read.
    #[error("cannot read `{file}`: {reason}")]
    Read {
        /// The file.
        file: String,
        /// Why.
        reason: String,
    },
    /// The workcell file is wrong at a key.
    #[error("{file}: {key}: {message}")]
    Invalid {
        /// The workcell file.
        file: String,
        /// Where in it, e.g. `robot[0].default_speed`.
        key: String,
        /// What is wrong and what to do.
        message: String,
    },
    /// A robot model failed to load.
    #[error("{file}: robot `{robot}`: {source}")]
    Model {
        /// The workcell file.
        file: String,
        /// The robot.
        robot: String,
        /// The model error (it names the URDF file and element).
        source: Box<vworks_model::ModelError>,
    },
    /// Programs did not compile or link: every diagnostic, rendered with its source.
    #[error("{rendered}")]
    Program {
        /// Whether a program did not compile, or the cell's programs did not link.
        stage: Stage,
        /// The diagnostics.
        diagnostics: Vec<Diagnostic>,
        /// The same, rendered with source lines.
        rendered: String,
    },
}

#[derive(Deserialize, Debug, Default)]
#[serde(deny_unknown_fields)]
struct PoseFile {
    xyz: Option<Vec<toml::Value>>,
    rpy: Option<Vec<toml::Value>>,
}

#[derive(Deserialize, Debug)]
#[serde(deny_unknown_fields)]
struct RobotFile {
    name: String,
    model: Option<String>,
    urdf: Option<String>,
    tool_link: Option<String>,
    #[serde(default)]
    package_path: Vec<String>,
    base: Option<PoseFile>,
    tool: Option<PoseFile>,
    /// One file, or a list of files (a RAPID task's modules).
    program: Option<toml::Value>,
    entry: Option<String>,
    task: Option<String>,
    serve_only: Option<bool>,
    default_speed: Option<toml::Value>,
    default_zone: Option<toml::Value>,
    grip_distance: Option<toml::Value>,
    jerk: Option<toml::Value>,
    home: Option<Vec<toml::Value>>,
    /// Values of its program's `param`s (`[robot.params]`).
    #[serde(default)]
    params: BTreeMap<String, toml::Value>,
    /// Allowed pairs may follow any table (TOML puts a key after `[[robot]]` into it).
    #[serde(default)]
    allow_collision: Vec<Vec<String>>,
}

#[derive(Deserialize, Debug)]
#[serde(deny_unknown_fields)]
struct BodyFile {
    name: String,
    #[serde(rename = "box")]
    box_: Option<Vec<toml::Value>>,
    cylinder: Option<Vec<toml::Value>>,
    sphere: Option<toml::Value>,
    mesh: Option<String>,
    scale: Option<f64>,
    pose: Option<PoseFile>,
    #[serde(default)]
    allow_collision: Vec<Vec<String>>,
}

#[derive(Deserialize, Debug)]
#[serde(deny_unknown_fields)]
struct CellFile {
    name: Option<String>,
    cycle: Option<toml::Value>,
    clearance: Option<toml::Value>,
    grip_distance: Option<toml::Value>,
    on_collision: Option<String>,
    #[serde(default)]
    robot: Vec<RobotFile>,
    #[serde(default)]
    device: Vec<BodyFile>,
    #[serde(default)]
    part: Vec<BodyFile>,
    #[serde(default)]
    allow_collision: Vec<Vec<String>>,
    /// Values of the programs' `param`s (`[params]`), for every program that declares them.
    #[serde(default)]
    params: BTreeMap<String, toml::Value>,
    /// The I/O wiring (`[[io]]`).
    #[serde(default)]
    io: Vec<io::IoFile>,
}

/// A robot of the cell.
#[derive(Debug, Clone)]
pub struct Robot {
    /// Its name.
    pub name: String,
    /// Its model.
    pub model: Arc<RobotModel>,
    /// Base frame in the cell.
    pub base: Iso,
    /// TCP in the tool-link frame.
    pub tool: Iso,
    /// Its compiled program.
    pub module: Arc<Module>,
    /// The program file (the first, for a program of several files: the module's
    /// `files` lists them all, and positions name their own).
    pub program: String,
    /// Entry procedure (`None`: serve-only).
    pub entry: Option<u32>,
    /// Speed of `move_l`/`move_c` without `speed` (m/s).
    pub default_speed: f64,
    /// Zone radius of motions without `zone` (m; `None`: `fine`).
    pub default_zone: Option<f64>,
    /// How far a part may be from this robot's gripper (its TCP, or a collision body of
    /// its tool link) for `grip` to take it (m): its own `grip_distance`, else the cell's.
    pub grip_distance: f64,
    /// Joints at the start.
    pub home: Vec<f64>,
    /// The task it runs, as sync points' task lists name it (`task`; default: its name).
    pub task: String,
    /// A RAPID robot's wired I/O signals as (cell global, the name its program gives the
    /// signal), sorted: messages name what the program wrote (`diFromR2`), not the wire's
    /// global (`dotor1`). Empty for WSL robots, whose programs name the globals.
    pub signal_names: Vec<(String, String)>,
}

/// A static or movable body: a device or a part.
#[derive(Debug, Clone)]
pub struct Body {
    /// Its name.
    pub name: String,
    /// What it is.
    pub geometry: Geometry,
    /// Its parry shape.
    pub shape: SharedShape,
    /// Shape pose in the body frame (cylinders turned onto z).
    pub local: Iso,
    /// Body pose in the cell.
    pub pose: Iso,
}

/// A loaded workcell.
#[derive(Debug, Clone)]
pub struct Cell {
    /// Its name.
    pub name: String,
    /// The workcell file.
    pub file: PathBuf,
    /// Cycle period (ns).
    pub cycle_ns: i64,
    /// Near-miss distance (m).
    pub clearance: f64,
    /// The cell's `grip_distance` (m; [`DEFAULT_GRIP_DISTANCE`] unless the file sets
    /// it): each robot's [`Robot::grip_distance`] unless the robot sets its own.
    pub grip_distance: f64,
    /// Stop at the first collision.
    pub stop_on_collision: bool,
    /// Robots, in file order.
    pub robots: Vec<Robot>,
    /// Static bodies.
    pub devices: Vec<Body>,
    /// Movable bodies.
    pub parts: Vec<Body>,
    /// Pairs allowed to touch: body names (`r1.link_6`, `r1` for all its links, `part1`).
    pub allowed: Vec<(String, String)>,
    /// The linked programs.
    pub linked: Linked,
    /// The workcell file and every program: (path, text).
    pub sources: Vec<(String, String)>,
    /// Every other file the run read: each URDF and each mesh, (path, bytes), in load order.
    pub files: Vec<(String, Vec<u8>)>,
    /// The programs' compile warnings (in robot order, each program once) and the link
    /// warnings: `vworks run` prints them as `vworks check` does, and every run's result
    /// lists them (`vworks_log::result::RunResult::warnings`).
    pub warnings: Vec<Diagnostic>,
    /// The values a [`Loader`] changed from the workcell file: (path, value as TOML), in
    /// order (empty for the file as written).
    pub overrides: Vec<(String, String)>,
}

impl Cell {
    /// The compile and link warnings, rendered with their source lines as `vworks check`
    /// prints them (empty if there are none).
    pub fn render_warnings(&self, color: bool) -> String {
        if self.warnings.is_empty() {
            return String::new();
        }
        let mut sources = Sources::new();
        for (path, text) in &self.sources {
            sources.add(path, text);
        }
        vworks_wslc::render(&self.warnings, &sources, color)
    }
}

struct Ctx<'a> {
    file: &'a str,
    files: &'a dyn Files,
}

impl Ctx<'_> {
    /// The error at `key`; control characters in names the key or message quote (from
    /// the workcell) escaped as log texts are, so they cannot drive a terminal.
    fn bad(&self, key: &str, message: impl Into<String>) -> CellError {
        CellError::Invalid {
            file: self.file.to_string(),
            key: escape_controls(key).into_owned(),
            message: escape_controls_owned(message.into()),
        }
    }

    /// A robot's `jerk`: one value for every axis, or a list with one per axis (each
    /// an angular jerk for a revolute axis, a jerk for a prismatic one; plain numbers are
    /// SI). Replaces the URDF's `jerk` limits.
    fn override_jerk(
        &self,
        model: &mut RobotModel,
        v: &toml::Value,
        key: &str,
    ) -> Result<(), CellError> {
        let n = model.dof();
        let values: Vec<(&toml::Value, String)> = match v {
            toml::Value::Array(list) => {
                if list.len() != n {
                    return Err(self.bad(
                        key,
                        format!(
                            "has {} values but the robot has {n} axes; give one per axis, or one value for all",
                            list.len()
                        ),
                    ));
                }
                list.iter()
                    .enumerate()
                    .map(|(k, x)| (x, format!("{key}[{k}]")))
                    .collect()
            }
            one => (0..n).map(|_| (one, key.to_string())).collect(),
        };
        for (k, (x, at)) in values.into_iter().enumerate() {
            let dim = if (model.linear_axes() >> k) & 1 == 1 {
                Dim::JERK
            } else {
                Dim::ANGJERK
            };
            let hint: &dyn Fn() -> &'static str = &|| {
                if dim == Dim::JERK {
                    "\"5000mm/s3\" or 5 (m/s³)"
                } else {
                    "\"2000deg/s3\" or 34.9 (rad/s³)"
                }
            };
            let j = self.quantity_unchecked(x, dim, &at, hint)?;
            if !(j.is_finite() && j > 0.0) {
                return Err(self.bad(
                    &at,
                    format!(
                        "axis {} `{}`: a jerk limit must be greater than 0 and finite; write {}",
                        k + 1,
                        model.axis(k).name,
                        hint()
                    ),
                ));
            }
            let joint = model.axes[k];
            model.joints[joint].max_jerk = Some(j);
        }
        Ok(())
    }

    /// A quantity of dimension `dim`: a number (SI) or a string with a unit.
    fn quantity(&self, v: &toml::Value, dim: Dim, key: &str) -> Result<f64, CellError> {
        let unit_hint = || match dim {
            Dim::LENGTH => "\"250mm\" or 0.25 (metres)",
            Dim::ANGLE => "\"90deg\" or 1.5708 (radians)",
            Dim::TIME => "\"4ms\" or 0.004 (seconds)",
            Dim::SPEED => "\"250mm/s\" or 0.25 (m/s)",
            _ => "a number",
        };
        let x = self.quantity_unchecked(v, dim, key, &unit_hint)?;
        if dim == Dim::LENGTH && x.abs() > MAX_LENGTH {
            return Err(self.bad(
                key,
                format!(
                    "{x:.3e} m is out of range: lengths in a workcell are within ±10 km; write {}",
                    unit_hint()
                ),
            ));
        }
        Ok(x)
    }

    /// A quantity of dimension `dim`, finite (`nan`, `inf` and `"1e999mm"` are errors),
    /// not checked against any range.
    fn quantity_unchecked(
        &self,
        v: &toml::Value,
        dim: Dim,
        key: &str,
        unit_hint: &dyn Fn() -> &'static str,
    ) -> Result<f64, CellError> {
        let x = self.quantity_any(v, dim, key, unit_hint)?;
        if !x.is_finite() {
            return Err(self.bad(
                key,
                format!(
                    "{} is not a finite number; write {}",
                    match v {
                        toml::Value::String(s) => format!("`{s}`"),
                        _ => x.to_string(),
                    },
                    unit_hint()
                ),
            ));
        }
        Ok(x)
    }

    /// A quantity of dimension `dim`, NaN and infinities included.
    fn quantity_any(
        &self,
        v: &toml::Value,
        dim: Dim,
        key: &str,
        unit_hint: &dyn Fn() -> &'static str,
    ) -> Result<f64, CellError> {
        match v {
            toml::Value::Integer(i) => Ok(*i as f64),
            toml::Value::Float(x) => Ok(*x),
            toml::Value::String(s) => match parse_quantity(s) {
                Some(q) => q.si(dim).map_err(|d| {
                    self.bad(
                        key,
                        format!(
                            "`{s}` is {}, but {key} is {}; write {}",
                            d.described(),
                            dim.described(),
                            unit_hint()
                        ),
                    )
                }),
                None => Err(self.bad(
                    key,
                    format!("`{s}` is not a quantity; write {}", unit_hint()),
                )),
            },
            other => Err(self.bad(
                key,
                format!("expected {}, found {}", unit_hint(), other.type_str()),
            )),
        }
    }

    /// A `grip_distance` (the cell's or a robot's): a length, at least 0.
    fn grip_distance(&self, v: &toml::Value, key: &str) -> Result<f64, CellError> {
        let d = self.quantity(v, Dim::LENGTH, key)?;
        if d < 0.0 {
            return Err(self.bad(
                key,
                "cannot be negative: it is how far from the robot's gripper (its TCP and its tool link's collision bodies) a part can be gripped; write e.g. \"5mm\", or 0 for parts the gripper touches",
            ));
        }
        Ok(d)
    }

    fn pose(&self, p: Option<&PoseFile>, key: &str) -> Result<Iso, CellError> {
        let Some(p) = p else { return Ok(Iso::IDENTITY) };
        let vec3 =
            |v: &Option<Vec<toml::Value>>, dim: Dim, sub: &str| -> Result<[f64; 3], CellError> {
                let Some(v) = v else { return Ok([0.0; 3]) };
                if v.len() != 3 {
                    return Err(self.bad(
                        &format!("{key}.{sub}"),
                        format!("needs 3 values, found {}", v.len()),
                    ));
                }
                let mut out = [0.0; 3];
                for (i, x) in v.iter().enumerate() {
                    out[i] = self.quantity(x, dim, &format!("{key}.{sub}[{i}]"))?;
                }
                Ok(out)
            };
        Ok(Iso::from_xyz_rpy(
            vec3(&p.xyz, Dim::LENGTH, "xyz")?,
            vec3(&p.rpy, Dim::ANGLE, "rpy")?,
        ))
    }

    fn body(&self, b: &BodyFile, key: &str, dir: &Path) -> Result<Body, CellError> {
        let files = self.files;
        let given = [
            b.box_.is_some(),
            b.cylinder.is_some(),
            b.sphere.is_some(),
            b.mesh.is_some(),
        ]
        .iter()
        .filter(|x| **x)
        .count();
        if given != 1 {
            return Err(self.bad(
                key,
                format!(
                    "`{}` needs exactly one shape: box, cylinder, sphere or mesh",
                    b.name
                ),
            ));
        }
        let len = |v: &toml::Value, k: &str| -> Result<f64, CellError> {
            let x = self.quantity(v, Dim::LENGTH, k)?;
            if x > 0.0 {
                Ok(x)
            } else {
                Err(self.bad(k, "must be greater than zero"))
            }
        };
        let geometry = if let Some(bx) = &b.box_ {
            if bx.len() != 3 {
                return Err(self.bad(&format!("{key}.box"), "needs 3 sizes: [x, y, z]"));
            }
            let mut half = [0.0; 3];
            for (i, v) in bx.iter().enumerate() {
                half[i] = len(v, &format!("{key}.box[{i}]"))? / 2.0;
            }
            Geometry::Box { half }
        } else if let Some(c) = &b.cylinder {
            if c.len() != 2 {
                return Err(self.bad(&format!("{key}.cylinder"), "needs [radius, length]"));
            }
            Geometry::Cylinder {
                radius: len(&c[0], &format!("{key}.cylinder[0]"))?,
                length: len(&c[1], &format!("{key}.cylinder[1]"))?,
            }
        } else if let Some(r) = &b.sphere {
            Geometry::Sphere {
                radius: len(r, &format!("{key}.sphere"))?,
            }
        } else {
            let mesh = b.mesh.as_deref().unwrap_or_default();
            let path = dir.join(mesh);
            let bytes = files.read(&path).map_err(|e| {
                self.bad(
                    &format!("{key}.mesh"),
                    format!("cannot read `{}`: {e}{}", path.display(), read_hint(&e)),
                )
            })?;
            let s = b.scale.unwrap_or(1.0);
            if !(s.is_finite() && s > 0.0 && s <= MAX_LENGTH) {
                return Err(self.bad(
                    &format!("{key}.scale"),
                    format!("{s} is not a usable scale; give a number greater than 0 (1 keeps the mesh's size)"),
                ));
            }
            let points = vworks_model::mesh::read_vertices(&bytes, mesh, [s; 3]).map_err(|e| {
                self.bad(&format!("{key}.mesh"), format!("`{}`: {e}", path.display()))
            })?;
            Geometry::Hull {
                source: path.display().to_string(),
                points,
            }
        };
        let shaped = vworks_model::urdf::build_shape(geometry, Iso::IDENTITY, self.file, key)
            .map_err(|e| self.bad(key, e.to_string()))?;
        let local = match shaped.geometry {
            Geometry::Cylinder { .. } => {
                Iso::from_xyz_rpy([0.0; 3], [std::f64::consts::FRAC_PI_2, 0.0, 0.0])
            }
            _ => Iso::IDENTITY,
        };
        Ok(Body {
            name: b.name.clone(),
            geometry: shaped.geometry,
            shape: shaped.shape,
            local,
            pose: self.pose(b.pose.as_ref(), &format!("{key}.pose"))?,
        })
    }
}

/// Link names match ignoring `_` and case: `link6` names `link_6`.
pub fn same_link(a: &str, b: &str) -> bool {
    let norm = |s: &str| {
        s.chars()
            .filter(|c| *c != '_')
            .flat_map(char::to_lowercase)
            .collect::<String>()
    };
    a == b || norm(a) == norm(b)
}

/// The largest length a workcell may give (10 km): a size or a position beyond it is a
/// typo (a unit missing), and would break the collision geometry's arithmetic.
const MAX_LENGTH: f64 = 1e4;

/// How far a part may be from a robot's gripper for `grip` to take it when the workcell
/// does not say (m): 5 mm, a gripper closing on a part that its fingers nearly touch.
pub const DEFAULT_GRIP_DISTANCE: f64 = 0.005;

/// Loads a workcell file: models, programs (compiled and linked), shapes.
pub fn load(path: &Path) -> Result<Cell, CellError> {
    load_with(path, &Disk)
}

/// Loads a workcell, reading it and every file it names (programs, URDFs, meshes) from
/// `files`: the disk, or memory ([`MemoryFiles`]).
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

/// The workcell file's text and its parsed form (errors with line and column).
fn read_cell_file(path: &Path, fs: &dyn Files) -> Result<(String, CellFile), CellError> {
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

/// Loads a parsed workcell: `text` is the file's text (kept in [`Cell::sources`]);
/// programs and models come from `cache` when it has them.
fn load_parsed(
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
    // Each task name (lower case) and the robot that runs it.
    let mut tasks: BTreeMap<String, usize> = BTreeMap::new();
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
        if let Some(&other) = tasks.get(&task.to_ascii_lowercase()) {
            let other: &(Robot, String, bool) = &robots[other];
            return Err(cx.bad(
                &format!("{key}.task"),
                format!(
                    "robot `{}` already runs the task `{}`: give each robot a task name of its own",
                    other.0.name, other.0.task
                ),
            ));
        }
        tasks.insert(task.to_ascii_lowercase(), i);
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
                            let src = vworks_wslc::source_text(bytes)
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
