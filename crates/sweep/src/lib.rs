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
//! A variant is a list of [`Override`]s, made when it runs ([`Sweep::variant`]); the same
//! sweep file gives the same variants, the same runs and the same table, whatever the
//! number of threads. Sizes are checked before anything is made ([`MAX_VARIANTS`]), rows
//! are streamed to the table in variant order ([`run_streamed`], [`stream`]), so a sweep's
//! memory does not grow with its number of variants.

use std::path::{Path, PathBuf};

use serde::Deserialize;
pub use vworks_cell::Override;
use vworks_cell::{CellError, Files};

pub mod html;
pub mod run;
pub mod stream;
pub mod table;

pub use run::{Row, RowOutcome, run_streamed, run_variants};
pub use table::{Table, Unit};

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
    steps: u64,
}

#[derive(Deserialize, Debug)]
#[serde(deny_unknown_fields)]
struct RandomFile {
    from: toml::Value,
    to: toml::Value,
    count: u64,
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
    pub values: Values,
    /// The unit its values were written in (`"450mm"`: mm), in which the table and the
    /// page show them; `None` for plain numbers (shown as they are). See
    /// [`Unit::of_values`].
    pub unit: Option<Unit>,
}

impl Variable {
    /// Every value shows as a number in the table file, in the variable's unit (not
    /// `"fine"` nor `"5deg"` among lengths): a column an objective may be.
    pub fn numeric(&self) -> bool {
        match &self.values {
            Values::List(v) => v
                .iter()
                .all(|x| table::in_unit(x, self.unit.as_ref()).number().is_some()),
            Values::Range { .. } | Values::Random { .. } => true,
        }
    }
}

/// A variable's values: a list, or made when asked for (a range or random samples of
/// millions of values take no memory).
#[derive(Clone, Debug, PartialEq)]
pub enum Values {
    /// The values given.
    List(Vec<toml::Value>),
    /// `steps` values evenly spaced from `from` to `to`, both included.
    Range {
        /// The first value (SI).
        from: f64,
        /// The last value (SI).
        to: f64,
        /// How many (at least 2).
        steps: usize,
        /// Integers (both ends were).
        integer: bool,
    },
    /// `count` uniform samples in [`from`, `to`), each from the variable's own stream.
    Random {
        /// The low end (SI).
        from: f64,
        /// The high end (SI).
        to: f64,
        /// How many (at least 1).
        count: usize,
        /// Integers (both ends were).
        integer: bool,
        /// The stream's seed: the file's seed and the variable's index.
        seed: u64,
    },
}

impl Values {
    /// How many values.
    pub fn len(&self) -> usize {
        match self {
            Values::List(v) => v.len(),
            Values::Range { steps, .. } => *steps,
            Values::Random { count, .. } => *count,
        }
    }

    /// No values (a sweep file never gives a variable none).
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The `k`-th value (`k < len()`).
    pub fn get(&self, k: usize) -> toml::Value {
        match self {
            Values::List(v) => v.get(k).cloned().unwrap_or(toml::Value::Integer(0)),
            Values::Range {
                from,
                to,
                steps,
                integer,
            } => value(
                from + (to - from) * k as f64 / (steps.saturating_sub(1).max(1)) as f64,
                *integer,
            ),
            Values::Random {
                from,
                to,
                integer,
                seed,
                ..
            } => value(from + (to - from) * splitmix64_unit(*seed, k), *integer),
        }
    }

    /// Every value, in order.
    pub fn to_vec(&self) -> Vec<toml::Value> {
        (0..self.len()).map(|k| self.get(k)).collect()
    }

    /// Every value is a number (the table shows it as one).
    pub fn numeric(&self) -> bool {
        match self {
            Values::List(v) => v.iter().all(table::is_numeric),
            Values::Range { .. } | Values::Random { .. } => true,
        }
    }
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
                (Some(values), None, None) if !values.is_empty() => Values::List(values.clone()),
                (None, Some(r), None) => {
                    if r.steps < 2 {
                        return Err(bad(
                            &key,
                            "a range needs `steps` of at least 2 (its two ends)".into(),
                        ));
                    }
                    let steps = at_most_max(r.steps)
                        .ok_or_else(|| bad(&format!("{key}.range.steps"), too_many(r.steps)))?;
                    let (from, to, integer) = ends(&r.from, &r.to).map_err(|m| bad(&key, m))?;
                    Values::Range {
                        from,
                        to,
                        steps,
                        integer,
                    }
                }
                (None, None, Some(r)) => {
                    if r.count == 0 {
                        return Err(bad(&key, "`count` must be at least 1".into()));
                    }
                    let count = at_most_max(r.count)
                        .ok_or_else(|| bad(&format!("{key}.random.count"), too_many(r.count)))?;
                    let (from, to, integer) = ends(&r.from, &r.to).map_err(|m| bad(&key, m))?;
                    Values::Random {
                        from,
                        to,
                        count,
                        integer,
                        // Each variable its own stream: the seed and the variable's index.
                        seed: sf.seed ^ (i as u64).wrapping_mul(GOLDEN),
                    }
                }
                _ => {
                    return Err(bad(
                        &key,
                        "give exactly one of `values = [...]` (not empty), `range = { from, to, steps }` or `random = { from, to, count }`".into(),
                    ));
                }
            };
            let unit = match (&v.values, &v.range, &v.random) {
                (Some(list), ..) => Unit::of_values(list),
                (_, Some(r), _) => Unit::of_values(&[r.from.clone(), r.to.clone()]),
                (.., Some(r)) => Unit::of_values(&[r.from.clone(), r.to.clone()]),
                _ => None,
            };
            variables.push(Variable {
                path: paths[0].clone(),
                paths,
                values,
                unit,
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
            let sizes: Vec<String> = variables
                .iter()
                .map(|v| v.values.len().to_string())
                .collect();
            return Err(bad(
                "variable",
                format!(
                    "{} values make more than {MAX_VARIANTS} variants; sweep fewer values, or zip them",
                    sizes.join(" × ")
                ),
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

    /// How many variants (at most [`MAX_VARIANTS`]: `read` checked it).
    pub fn count(&self) -> usize {
        match self.combine {
            Combine::Zip => self.variables.first().map_or(0, |v| v.values.len()),
            Combine::Product => self
                .variables
                .iter()
                .try_fold(1usize, |n, v| n.checked_mul(v.values.len()))
                .unwrap_or(usize::MAX),
        }
    }

    /// The `i`-th variant (`i < count()`): one override per path of each variable, made
    /// when asked for, so a sweep of millions of variants holds none of them.
    pub fn variant(&self, i: usize) -> Vec<Override> {
        let mut picks = vec![i; self.variables.len()];
        if self.combine == Combine::Product {
            // The last variable changes fastest.
            let mut rest = i;
            for (k, v) in self.variables.iter().enumerate().rev() {
                let n = v.values.len().max(1);
                picks[k] = rest % n;
                rest /= n;
            }
        }
        self.variables
            .iter()
            .zip(picks)
            .flat_map(|(v, k)| {
                let value = v.values.get(k);
                v.paths
                    .iter()
                    .map(move |p| Override::new(p.clone(), value.clone()))
            })
            .collect()
    }

    /// Checks that `objective` is a numeric column of the table this sweep makes of a
    /// cell with these `robots` (before any variant runs), named as the table file's
    /// header does (`end_time [s]`, `robot.r2.base.xyz.0 [mm]`) or without its unit
    /// (`end_time`); `Ok` is the column's name without the unit. `Err` names the columns.
    pub fn check_objective(&self, objective: &str, robots: &[String]) -> Result<String, String> {
        let variables: Vec<(String, bool)> = self
            .variables
            .iter()
            .map(|v| (v.path.clone(), v.numeric()))
            .collect();
        let numeric = table::numeric_columns(&variables, robots);
        let units = self.units();
        let keys = table::columns(&self.names(), robots);
        let headers = table::headers(&self.names(), &units, robots);
        if let Some(k) = table::find_column(&keys, &headers, objective)
            && numeric.contains(&keys[k])
        {
            return Ok(keys[k].clone());
        }
        Err(format!(
            "`{objective}` is not a numeric column of the table; choose one of {}",
            numeric.join(", ")
        ))
    }

    /// The variables' names (their first paths): the table's variable columns.
    pub fn names(&self) -> Vec<String> {
        self.variables.iter().map(|v| v.path.clone()).collect()
    }

    /// The unit each variable is shown in (see [`Variable::unit`]).
    pub fn units(&self) -> Vec<Option<Unit>> {
        self.variables.iter().map(|v| v.unit.clone()).collect()
    }

    /// Every variant, in order (for a few; a large sweep asks for [`Sweep::variant`]).
    pub fn variants(&self) -> Vec<Vec<Override>> {
        (0..self.count()).map(|i| self.variant(i)).collect()
    }
}

/// A rate (per second) as the progress bar and the summary show it: three significant
/// digits, and no decimals from 100 up (`467`, `12.5`, `3.21`, `0.0123`).
pub fn per_second(x: f64) -> String {
    if !x.is_finite() || x < 0.0 {
        return "–".into();
    }
    if x == 0.0 {
        return "0".into();
    }
    // The digits after the point that leave three significant ones (none from 100 up).
    let decimals = (2 - x.log10().floor() as i32).clamp(0, 12) as usize;
    let s = format!("{x:.decimals$}");
    if s.contains('.') {
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    } else {
        s
    }
}

/// More than this many values of one variable is more variants than a sweep may have.
fn at_most_max(n: u64) -> Option<usize> {
    usize::try_from(n).ok().filter(|n| *n <= MAX_VARIANTS)
}

fn too_many(n: u64) -> String {
    format!("{n} values are more than the {MAX_VARIANTS} variants a sweep may have; give fewer")
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

/// `until`: a time from 0, as `vworks run --until` and Python's `Cell.run` take it
/// ([`vworks_app::until_ns`]).
fn time_ns(v: &toml::Value) -> Result<i64, String> {
    let (s, _) = si(v)?;
    vworks_app::until_ns(s)
        .map_err(|_| format!("{s} s is not a time to stop at; give a time from 0, e.g. \"120s\""))
}

const GOLDEN: u64 = 0x9E37_79B9_7F4A_7C15;

/// The `k`-th (0-based) output of SplitMix64 seeded with `seed`, uniform in [0, 1): a
/// small, well-known generator whose state after `k + 1` steps is `seed + (k + 1) ·
/// golden`, so any sample is made directly; the same seed gives the same values on every
/// machine.
fn splitmix64_unit(seed: u64, k: usize) -> f64 {
    let mut z = seed.wrapping_add((k as u64).wrapping_add(1).wrapping_mul(GOLDEN));
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^= z >> 31;
    (z >> 11) as f64 / (1u64 << 53) as f64
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rates_have_three_significant_digits() {
        for (x, want) in [
            (466.6466, "467"),
            (1234.6, "1235"),
            (99.96, "100"),
            (65.32, "65.3"),
            (12.5, "12.5"),
            (20.0, "20"),
            (3.214, "3.21"),
            (0.012345, "0.0123"),
            (0.0, "0"),
            (f64::NAN, "–"),
        ] {
            assert_eq!(per_second(x), want, "{x}");
        }
    }
}
