//! Many variants of one workcell: [`Loader`] reads and checks the workcell once, then
//! loads it again with a few values changed ([`Override`]s), each named by its dotted path
//! into the workcell — `cycle`, `params.speed`, `robot.r2.params.speed`,
//! `robot.r2.base.xyz.0` (an index into an array), `device.table.pose.xyz.2`. Robots,
//! devices and parts are found by name. Every program is compiled once and every model
//! loaded once for all variants (a cache the loader keeps); a variant costs a copy of the parsed file,
//! the overrides, and the rest of loading (params, bodies, link).

use std::path::{Path, PathBuf};

use serde::Deserialize;
use vworks_model::files::Files;

use crate::cache::Cache;
use crate::cell::Cell;
use crate::error::CellError;
use crate::file::CellFile;
use crate::load::{load_parsed, read_cell_file};
/// One changed value: the dotted path of a workcell value and what it becomes (as the
/// workcell file would write it: a number in SI units, or a string with its unit).
#[derive(Clone, Debug, PartialEq)]
pub struct Override {
    /// E.g. `robot.r2.base.xyz.0`.
    pub path: String,
    /// E.g. `"650mm"` or `0.65`.
    pub value: toml::Value,
}

impl Override {
    /// `path = value`.
    pub fn new(path: impl Into<String>, value: impl Into<toml::Value>) -> Override {
        Override {
            path: path.into(),
            value: value.into(),
        }
    }
}

/// Loads variants of one workcell (see the module docs).
pub struct Loader<'f> {
    path: PathBuf,
    text: String,
    table: toml::Table,
    files: &'f (dyn Files + Sync),
    cache: Cache,
    base: Cell,
    variables: Vec<String>,
}

impl std::fmt::Debug for Loader<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Loader")
            .field("path", &self.path)
            .field("variables", &self.variables.len())
            .finish_non_exhaustive()
    }
}

impl<'f> Loader<'f> {
    /// Reads and loads the workcell at `path` (every error as [`crate::load_with`] gives
    /// it), ready to load variants of it.
    pub fn new(path: &Path, files: &'f (dyn Files + Sync)) -> Result<Loader<'f>, CellError> {
        let (text, cf) = read_cell_file(path, files)?;
        let table: toml::Table = text
            .parse()
            .map_err(|e: toml::de::Error| CellError::Invalid {
                file: path.display().to_string(),
                key: "file".into(),
                message: e.message().to_string(),
            })?;
        let cache = Cache::default();
        let base = load_parsed(path, &text, cf, files, &cache, None)?;
        let variables = variables(&table, &base);
        Ok(Loader {
            path: path.to_path_buf(),
            text,
            table,
            files,
            cache,
            base,
            variables,
        })
    }

    /// The workcell as its file says (no override).
    pub fn base(&self) -> &Cell {
        &self.base
    }

    /// Every path a variant may change, sorted: the numbers and quantities in the file,
    /// the params the programs declare, and the poses, speeds and zones the file could
    /// hold.
    pub fn variables(&self) -> &[String] {
        &self.variables
    }

    /// Whether `path` names a variable; if not, an error that lists the nearest ones.
    pub fn check(&self, path: &str) -> Result<(), CellError> {
        if self
            .variables
            .binary_search_by(|v| v.as_str().cmp(path))
            .is_ok()
        {
            return Ok(());
        }
        let mut near: Vec<(usize, &String)> = self
            .variables
            .iter()
            .map(|v| (edit_distance(v, path), v))
            .collect();
        near.sort();
        let near: Vec<&str> = near.iter().take(4).map(|(_, v)| v.as_str()).collect();
        Err(CellError::Invalid {
            file: self.path.display().to_string(),
            key: path.to_string(),
            message: format!(
                "not a value of this workcell; the nearest are {} (every one: `vworks sweep --variables {}`)",
                near.join(", "),
                self.path.display()
            ),
        })
    }

    /// The workcell with `overrides` applied (in order; a later one of the same path wins).
    pub fn load(&self, overrides: &[Override]) -> Result<Cell, CellError> {
        if overrides.is_empty() {
            return Ok(self.base.clone());
        }
        let mut table = self.table.clone();
        for o in overrides {
            self.check(&o.path)?;
            set(&mut table, &o.path, o.value.clone());
        }
        let file = self.path.display().to_string();
        let cf =
            CellFile::deserialize(toml::Value::Table(table)).map_err(|e| CellError::Invalid {
                file: file.clone(),
                key: overrides
                    .iter()
                    .map(|o| o.path.as_str())
                    .collect::<Vec<_>>()
                    .join(", "),
                message: format!(
                    "with these values the workcell does not read: {}",
                    e.message()
                ),
            })?;
        let mut cell = load_parsed(&self.path, &self.text, cf, self.files, &self.cache, None)?;
        cell.overrides = overrides
            .iter()
            .map(|o| (o.path.clone(), o.value.to_string()))
            .collect();
        Ok(cell)
    }
}

/// The sections whose entries are found by name.
const NAMED: [&str; 3] = ["robot", "device", "part"];

/// Every variable of a workcell (see [`Loader::variables`]).
fn variables(table: &toml::Table, cell: &Cell) -> Vec<String> {
    let mut out = Vec::new();
    leaves("", &toml::Value::Table(table.clone()), &mut out);
    out.extend(["cycle", "clearance", "grip_distance"].map(String::from));
    let pose = |out: &mut Vec<String>, prefix: &str| {
        for part in ["xyz", "rpy"] {
            for k in 0..3 {
                out.push(format!("{prefix}.{part}.{k}"));
            }
        }
    };
    for r in &cell.robots {
        let prefix = format!("robot.{}", r.name);
        pose(&mut out, &format!("{prefix}.base"));
        pose(&mut out, &format!("{prefix}.tool"));
        out.push(format!("{prefix}.default_speed"));
        out.push(format!("{prefix}.default_zone"));
        out.push(format!("{prefix}.grip_distance"));
        out.push(format!("{prefix}.tcp_speed"));
        out.push(format!("{prefix}.tcp_acceleration"));
        for (name, ..) in crate::params::declared(&r.module) {
            out.push(format!("{prefix}.params.{name}"));
            out.push(format!("params.{name}"));
        }
    }
    for (section, bodies) in [("device", &cell.devices), ("part", &cell.parts)] {
        for b in bodies {
            pose(&mut out, &format!("{section}.{}.pose", b.name));
        }
    }
    out.sort();
    out.dedup();
    out
}

/// The paths of the numbers (and quantity strings) under `value`.
fn leaves(prefix: &str, value: &toml::Value, out: &mut Vec<String>) {
    let join = |k: &str| {
        if prefix.is_empty() {
            k.to_string()
        } else {
            format!("{prefix}.{k}")
        }
    };
    match value {
        toml::Value::Table(t) => {
            for (k, v) in t {
                if k == "allow_collision" {
                    continue;
                }
                leaves(&join(k), v, out);
            }
        }
        toml::Value::Array(items) if NAMED.contains(&prefix) => {
            for item in items {
                if let Some(name) = item.get("name").and_then(toml::Value::as_str) {
                    leaves(&join(name), item, out);
                }
            }
        }
        toml::Value::Array(items) => {
            for (k, item) in items.iter().enumerate() {
                leaves(&join(&k.to_string()), item, out);
            }
        }
        toml::Value::Integer(_) | toml::Value::Float(_) => out.push(prefix.to_string()),
        toml::Value::String(s) if vworks_wslc::units::parse_quantity(s).is_some() => {
            out.push(prefix.to_string());
        }
        _ => {}
    }
}

/// Sets the value at `path` in `table`, creating the tables and the three-number arrays
/// (`xyz`, `rpy`: zeros) that a variable may need. (`path` is one of the variables.)
fn set(table: &mut toml::Table, path: &str, value: toml::Value) {
    let parts: Vec<&str> = path.split('.').collect();
    set_in_table(table, &parts, value, true);
}

fn set_in_table(t: &mut toml::Table, parts: &[&str], value: toml::Value, top: bool) {
    let [key, rest @ ..] = parts else { return };
    if rest.is_empty() {
        t.insert((*key).to_string(), value);
        return;
    }
    if top && NAMED.contains(key) {
        let [name, rest @ ..] = rest else { return };
        let item = t
            .get_mut(*key)
            .and_then(toml::Value::as_array_mut)
            .and_then(|items| {
                items
                    .iter_mut()
                    .find(|i| i.get("name").and_then(toml::Value::as_str) == Some(*name))
            })
            .and_then(toml::Value::as_table_mut);
        if let Some(item) = item {
            set_in_table(item, rest, value, false);
        }
        return;
    }
    let next_is_index = rest[0].parse::<usize>().is_ok();
    let entry = t.entry((*key).to_string()).or_insert_with(|| {
        if next_is_index {
            toml::Value::Array(vec![toml::Value::Integer(0); 3])
        } else {
            toml::Value::Table(toml::Table::new())
        }
    });
    set_in_value(entry, rest, value);
}

fn set_in_value(v: &mut toml::Value, parts: &[&str], value: toml::Value) {
    match v {
        toml::Value::Table(t) => set_in_table(t, parts, value, false),
        toml::Value::Array(items) => {
            let [key, rest @ ..] = parts else { return };
            let Some(item) = key.parse::<usize>().ok().and_then(|i| items.get_mut(i)) else {
                return;
            };
            if rest.is_empty() {
                *item = value;
            } else {
                set_in_value(item, rest, value);
            }
        }
        _ => {}
    }
}

/// Levenshtein distance (for "the nearest are").
fn edit_distance(a: &str, b: &str) -> usize {
    let b: Vec<char> = b.chars().collect();
    let mut row: Vec<usize> = (0..=b.len()).collect();
    for (i, ca) in a.chars().enumerate() {
        let mut prev = row[0];
        row[0] = i + 1;
        for (j, cb) in b.iter().enumerate() {
            let cur = row[j + 1];
            row[j + 1] = (prev + usize::from(ca != *cb)).min(row[j] + 1).min(cur + 1);
            prev = cur;
        }
    }
    row[b.len()]
}
