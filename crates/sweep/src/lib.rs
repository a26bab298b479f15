//! Many variants of one workcell: the sweep file, the variants it describes, running them
//! in parallel and the table of their results — what `vworks sweep` and Python's
//! `vworks.sweep` do. See `docs/sweep.md`.
//!
//! ```toml
//! cell = "cell.toml"                  # relative to the sweep file
//! combine = "product"                 # or "zip": the i-th value of every variable together
//! seed = 1                            # for `random` variables
//! until = "120s"                      # optional: stop each run there
//! minimize = "end_time"               # the summary's objective (a column of the table)
//!
//! [[variable]]
//! path = "robot.r2.base.xyz.0"        # a dotted path into the workcell (vworks_cell::Loader)
//! range = { from = "500mm", to = "700mm", steps = 5 }
//!
//! [[variable]]                        # tied paths: every one takes the same value
//! path = ["robot.r2.base.xyz.1", "robot.r2.params.base_y"]
//! values = ["550mm", "600mm"]
//!
//! [[variable]]
//! path = "params.speed"
//! values = ["200mm/s", "250mm/s"]     # or random = { from = …, to = …, count = 10 }
//! ```
//!
//! A variant is a list of [`Override`]s; the same sweep file gives the same variants, the
//! same runs and the same table, whatever the number of threads.

use std::path::{Path, PathBuf};

use serde::Deserialize;
pub use vworks_cell::Override;
use vworks_cell::{CellError, Files};

pub mod html;
pub mod run;
pub mod table;

pub use run::{Row, run_variants};
pub use table::Table;

/// Why a sweep could not be set up (a run that fails is a row of the table, not this).
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum SweepError {
    /// The sweep file cannot be read.
    #[error("cannot read `{file}`: {reason}")]
    Read {
        /// The sweep file.
        file: String,
        /// Why.
        reason: String,
    },
    /// The sweep file is wrong at a key.
    #[error("{file}: {key}: {message}")]
    Invalid {
        /// The sweep file.
        file: String,
        /// Where in it.
        key: String,
        /// What is wrong and what to do.
        message: String,
    },
    /// The workcell does not load (or a variable is not one of its values).
    #[error(transparent)]
    Cell(#[from] CellError),
}

#[derive(Deserialize, Debug)]
#[serde(deny_unknown_fields)]
struct SweepFile {
    cell: String,
    #[serde(default)]
    combine: Option<String>,
    #[serde(default)]
    seed: u64,
    until: Option<toml::Value>,
    minimize: Option<String>,
    #[serde(default)]
    variable: Vec<VariableFile>,
}

#[derive(Deserialize, Debug)]
#[serde(deny_unknown_fields)]
struct VariableFile {
    path: toml::Value,
    values: Option<Vec<toml::Value>>,
    range: Option<RangeFile>,
    random: Option<RandomFile>,
}

#[derive(Deserialize, Debug)]
#[serde(deny_unknown_fields)]
struct RangeFile {
    from: toml::Value,
    to: toml::Value,
    steps: usize,
}

#[derive(Deserialize, Debug)]
#[serde(deny_unknown_fields)]
struct RandomFile {
    from: toml::Value,
    to: toml::Value,
    count: usize,
}

/// How the variables' values combine into variants.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Combine {
    /// Every combination (the first variable changes slowest).
    Product,
    /// The i-th value of every variable together (they need as many values).
    Zip,
}

/// A variable of a sweep: its path and its values, in order.
#[derive(Clone, Debug, PartialEq)]
pub struct Variable {
    /// The dotted path into the workcell (the first of `paths`: the table's column).
    pub path: String,
    /// Every path it sets (more than one when tied: a base and the param that tells the
    /// program where it is).
    pub paths: Vec<String>,
    /// Its values, as the workcell file would write them.
    pub values: Vec<toml::Value>,
}

/// A sweep: the workcell, its variables and how they combine.
#[derive(Clone, Debug, PartialEq)]
pub struct Sweep {
    /// The workcell file.
    pub cell: PathBuf,
    /// The variables.
    pub variables: Vec<Variable>,
    /// How they combine.
    pub combine: Combine,
    /// Stop each run at this time (ns), if set.
    pub until_ns: Option<i64>,
    /// The summary's objective: a column of the table, minimized among completed runs.
    pub minimize: String,
}

/// Variants at most (a product grows fast: say so instead of filling the memory).
pub const MAX_VARIANTS: usize = 10_000_000;

impl Sweep {
    /// Reads a sweep file (`files` reads it; the cell's path is relative to it).
    pub fn read(path: &Path, files: &dyn Files) -> Result<Sweep, SweepError> {
        let file = path.display().to_string();
        let bytes = files.read(path).map_err(|e| SweepError::Read {
            file: file.clone(),
            reason: e.to_string(),
        })?;
        let text = String::from_utf8(bytes).map_err(|_| SweepError::Read {
            file: file.clone(),
            reason: "not UTF-8 text".into(),
        })?;
        let bad = |key: &str, message: String| SweepError::Invalid {
            file: file.clone(),
            key: key.to_string(),
            message,
        };
        let sf: SweepFile = toml::from_str(&text).map_err(|e| {
            bad(
                "file",
                format!("{}; the sweep file format is in docs/sweep.md", e.message()),
            )
        })?;
        let combine = match sf.combine.as_deref() {
            None | Some("product") => Combine::Product,
            Some("zip") => Combine::Zip,
            Some(other) => {
                return Err(bad(
                    "combine",
                    format!("`{other}` is not a choice; write \"product\" or \"zip\""),
                ));
            }
        };
        if sf.variable.is_empty() {
            return Err(bad(
                "variable",
                "a sweep needs at least one [[variable]] with a `path` and its `values`, `range` or `random`".into(),
            ));
        }
        let mut variables = Vec::new();
        for (i, v) in sf.variable.iter().enumerate() {
            let paths: Vec<String> = match &v.path {
                toml::Value::String(p) => vec![p.clone()],
                toml::Value::Array(items) => items
                    .iter()
                    .filter_map(|p| p.as_str().map(str::to_string))
                    .collect(),
                _ => Vec::new(),
            };
            let key = format!("variable[{i}] `{}`", paths.join(", "));
            let well_formed = match &v.path {
                toml::Value::Array(items) => !items.is_empty() && items.len() == paths.len(),
                _ => paths.len() == 1,
            };
            if !well_formed {
                return Err(bad(
                    &format!("variable[{i}].path"),
                    "a path is a string (\"robot.r2.base.xyz.0\") or a list of strings that take the same value".into(),
                ));
            }
            let values = match (&v.values, &v.range, &v.random) {
                (Some(values), None, None) if !values.is_empty() => values.clone(),
                (None, Some(r), None) => {
                    let (a, b, unit) = ends(&r.from, &r.to).map_err(|m| bad(&key, m))?;
                    if r.steps < 2 {
                        return Err(bad(
                            &key,
                            "a range needs `steps` of at least 2 (its two ends)".into(),
                        ));
                    }
                    (0..r.steps)
                        .map(|k| value(a + (b - a) * k as f64 / (r.steps - 1) as f64, unit))
                        .collect()
                }
                (None, None, Some(r)) => {
                    let (a, b, unit) = ends(&r.from, &r.to).map_err(|m| bad(&key, m))?;
                    if r.count == 0 {
                        return Err(bad(&key, "`count` must be at least 1".into()));
                    }
                    // Each variable its own stream: the seed and the variable's index.
                    let mut rng =
                        SplitMix64(sf.seed ^ (i as u64).wrapping_mul(0x9E37_79B9_7F4A_7C15));
                    (0..r.count)
                        .map(|_| value(a + (b - a) * rng.unit(), unit))
                        .collect()
                }
                _ => {
                    return Err(bad(
                        &key,
                        "give exactly one of `values = [...]` (not empty), `range = { from, to, steps }` or `random = { from, to, count }`".into(),
                    ));
                }
            };
            variables.push(Variable {
                path: paths[0].clone(),
                paths,
                values,
            });
        }
        let count = match combine {
            Combine::Product => variables
                .iter()
                .try_fold(1usize, |n, v| n.checked_mul(v.values.len())),
            Combine::Zip => {
                let n = variables[0].values.len();
                if let Some(v) = variables.iter().find(|v| v.values.len() != n) {
                    return Err(bad(
                        "combine",
                        format!(
                            "\"zip\" needs as many values for every variable: `{}` has {n}, `{}` has {}",
                            variables[0].path,
                            v.path,
                            v.values.len()
                        ),
                    ));
                }
                Some(n)
            }
        };
        if count.is_none_or(|n| n > MAX_VARIANTS) {
            return Err(bad(
                "variable",
                format!("more than {MAX_VARIANTS} variants; sweep fewer values, or zip them"),
            ));
        }
        let until_ns = match &sf.until {
            None => None,
            Some(v) => Some(time_ns(v).map_err(|m| bad("until", m))?),
        };
        let dir = path.parent().map(Path::to_path_buf).unwrap_or_default();
        Ok(Sweep {
            cell: dir.join(&sf.cell),
            variables,
            combine,
            until_ns,
            minimize: sf.minimize.unwrap_or_else(|| "end_time".into()),
        })
    }

    /// The variants, in order: each one override per variable.
    pub fn variants(&self) -> Vec<Vec<Override>> {
        let n = match self.combine {
            Combine::Zip => self.variables.first().map_or(0, |v| v.values.len()),
            Combine::Product => self.variables.iter().map(|v| v.values.len()).product(),
        };
        (0..n)
            .map(|i| {
                let mut rest = i;
                let mut picks = vec![0; self.variables.len()];
                match self.combine {
                    Combine::Zip => picks.iter_mut().for_each(|p| *p = i),
                    Combine::Product => {
                        // The last variable changes fastest.
                        for (k, v) in self.variables.iter().enumerate().rev() {
                            picks[k] = rest % v.values.len();
                            rest /= v.values.len();
                        }
                    }
                }
                self.variables
                    .iter()
                    .zip(picks)
                    .flat_map(|(v, k)| {
                        v.paths
                            .iter()
                            .map(move |p| Override::new(p.clone(), v.values[k].clone()))
                    })
                    .collect()
            })
            .collect()
    }
}

/// The two ends of a range as SI numbers, and whether both are integers (then the values
/// are integers too: `count`-like params).
fn ends(from: &toml::Value, to: &toml::Value) -> Result<(f64, f64, bool), String> {
    let (a, da) = si(from)?;
    let (b, db) = si(to)?;
    match (da, db) {
        (Some(x), Some(y)) if x != y => {
            return Err("`from` and `to` must have the same unit".into());
        }
        _ => {}
    }
    let integers = matches!(
        (from, to),
        (toml::Value::Integer(_), toml::Value::Integer(_))
    );
    Ok((a, b, integers))
}

/// A workcell value as an SI number, with its dimension if it had a unit.
fn si(v: &toml::Value) -> Result<(f64, Option<vworks_vm::Dim>), String> {
    use vworks_cell::{Quantity, parse_quantity};
    let x = match v {
        toml::Value::Integer(i) => (*i as f64, None),
        toml::Value::Float(x) => (*x, None),
        toml::Value::String(s) => match parse_quantity(s) {
            Some(Quantity::Number(x)) => (x, None),
            Some(Quantity::WithUnit(x, d)) => (x, Some(d)),
            None => {
                return Err(format!(
                    "`{s}` is not a number with a unit (e.g. \"250mm\")"
                ));
            }
        },
        other => return Err(format!("{other} is not a number")),
    };
    if !x.0.is_finite() {
        return Err(format!("{} is not a finite number", x.0));
    }
    Ok(x)
}

fn value(x: f64, integer: bool) -> toml::Value {
    if integer {
        toml::Value::Integer(x.round() as i64)
    } else {
        toml::Value::Float(x)
    }
}

fn time_ns(v: &toml::Value) -> Result<i64, String> {
    let (s, _) = si(v)?;
    if !(s > 0.0 && s < 1e9) {
        return Err(format!(
            "{s} s is not a time to stop at; write e.g. \"120s\""
        ));
    }
    Ok((s * 1e9).round() as i64)
}

/// SplitMix64: a small, well-known generator; the same seed gives the same values on every
/// machine.
struct SplitMix64(u64);

impl SplitMix64 {
    fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    /// Uniform in [0, 1).
    fn unit(&mut self) -> f64 {
        (self.next() >> 11) as f64 / (1u64 << 53) as f64
    }
}
