//! The sweep's table: one row per variant, the same columns for every row —
//! `variant`, each variable, `outcome`, `end_time` (s), `cycle_time.ROBOT` (s) for each
//! robot, `collisions`, `min_clearance` (m), `error` — written as CSV or JSON lines, and
//! the best variants by an objective.
//!
//! A [`Table`] (what Python's `vworks.sweep` returns) names its columns without units and
//! holds SI numbers. The table file that `vworks sweep` writes states the units in its
//! header ([`headers`]: `robot.r2.base.xyz.0 [mm]`, `end_time [s]`) and shows a variable
//! written with a unit in that unit ([`row_values_in`]: `"500mm"` is 500), as the sweep
//! file wrote it.

use std::fmt::Write as _;

use crate::Row;
use crate::run::RowOutcome;
use vworks_log::result::Outcome;

/// A value of the table.
#[derive(Clone, Debug, PartialEq)]
pub enum Value {
    /// An integer.
    Int(i64),
    /// A number.
    Num(f64),
    /// Text.
    Text(String),
    /// Nothing (a robot that did not end, no near miss).
    Empty,
}

impl Value {
    /// The number, if it is one.
    pub fn number(&self) -> Option<f64> {
        match self {
            Value::Int(i) => Some(*i as f64),
            Value::Num(x) => Some(*x),
            _ => None,
        }
    }

    fn csv(&self) -> String {
        match self {
            Value::Int(i) => i.to_string(),
            Value::Num(x) => format!("{x}"),
            Value::Text(s) if s.contains([',', '"', '\n', '\r']) => {
                format!("\"{}\"", s.replace('"', "\"\""))
            }
            Value::Text(s) => s.clone(),
            Value::Empty => String::new(),
        }
    }

    fn json(&self) -> serde_json::Value {
        match self {
            Value::Int(i) => serde_json::json!(i),
            Value::Num(x) if x.is_finite() => serde_json::json!(x),
            Value::Text(s) => serde_json::json!(s),
            _ => serde_json::Value::Null,
        }
    }
}

/// The table of a sweep.
#[derive(Clone, Debug, PartialEq)]
pub struct Table {
    /// Column names.
    pub columns: Vec<String>,
    /// Rows, in variant order; each as many values as columns.
    pub rows: Vec<Vec<Value>>,
}

/// A variable's value as the table shows it: an SI number for a quantity, else its text.
fn shown(v: &toml::Value) -> Value {
    match v {
        toml::Value::Integer(i) => Value::Int(*i),
        toml::Value::Float(x) => Value::Num(*x),
        toml::Value::Boolean(b) => Value::Text(b.to_string()),
        toml::Value::String(s) => match vworks_cell::parse_quantity(s) {
            Some(vworks_cell::Quantity::Number(x) | vworks_cell::Quantity::WithUnit(x, _)) => {
                Value::Num(x)
            }
            None => Value::Text(s.clone()),
        },
        other => Value::Text(other.to_string()),
    }
}

/// The unit a variable's values were written in, in which the table file and the page
/// show them: its name as written and the size of one of it in SI.
#[derive(Clone, Debug, PartialEq)]
pub struct Unit {
    /// As written: `mm`, `deg`, `mm/s`, `%`.
    pub name: String,
    /// One of it in SI (`mm`: 0.001, `deg`: π/180).
    pub si: f64,
    dim: vworks_vm::Dim,
}

impl Unit {
    /// The unit of these values (a variable's list, or a range's two ends): of the
    /// dimension that most of the values written with a unit have (ties: the first
    /// written), the first unit written; `None` if no value has a unit (the values are
    /// shown as they are). The other values do not change it: a plain number is SI (shown
    /// converted), and a word (`"fine"`), a unit vworks does not know (`"0.5cm"`) or a
    /// quantity of another dimension (`"5deg"` among lengths) is shown as written.
    pub fn of_values(values: &[toml::Value]) -> Option<Unit> {
        let units: Vec<Unit> = values
            .iter()
            .filter_map(|v| match v {
                toml::Value::String(s) => written(s).map(|(_, u)| u),
                _ => None,
            })
            .collect();
        let count = |u: &Unit| units.iter().filter(|o| o.dim == u.dim).count();
        // The most values; among as many, the first written (the first of its dimension).
        units
            .iter()
            .enumerate()
            .max_by_key(|(i, u)| (count(u), std::cmp::Reverse(*i)))
            .map(|(_, u)| u.clone())
    }
}

/// A quantity as written, `"450mm"`: the number as written (450) and its unit (`mm`);
/// `None` for anything else (a plain number, not a quantity).
fn written(text: &str) -> Option<(f64, Unit)> {
    use vworks_cell::{Quantity, parse_quantity};
    let Some(Quantity::WithUnit(_, dim)) = parse_quantity(text) else {
        return None;
    };
    let t = text.trim();
    let (sign, body) = match t.strip_prefix('-') {
        Some(rest) => (-1.0, rest.trim_start()),
        None => (1.0, t),
    };
    // The number as written is the longest start of it that reads as one (`450`, `2.5`,
    // `1e3`); the unit follows. (`parse_quantity` has checked that the text is a quantity.)
    let (end, number) = (1..=body.len())
        .rev()
        .filter(|&i| body.is_char_boundary(i))
        .find_map(|i| body[..i].parse::<f64>().ok().map(|x| (i, x)))?;
    let name = body[end..].trim().to_string();
    let si = match parse_quantity(&format!("1{name}"))? {
        Quantity::WithUnit(x, _) => x,
        Quantity::Number(_) => return None,
    };
    Some((sign * number, Unit { name, si, dim }))
}

/// A number without the noise of a unit conversion (`0.3 / 0.001` is
/// 299.99999999999994): rounded to 12 significant digits.
fn tidy(x: f64) -> f64 {
    format!("{x:.11e}").parse().unwrap_or(x)
}

/// A variable's value as the table file shows it in `unit`: the number as written if it
/// was written in that unit (`"500mm"`: 500), else its SI value converted (0.5 or
/// `"0.5m"`: 500); a value that is not a quantity of the unit's dimension (`"fine"`,
/// `"0.5cm"`, `"5deg"` among lengths) as written, as text.
pub fn in_unit(v: &toml::Value, unit: Option<&Unit>) -> Value {
    let Some(unit) = unit else {
        return shown(v);
    };
    if let toml::Value::String(s) = v
        && let Some((x, u)) = written(s)
    {
        return if u.name == unit.name {
            Value::Num(x)
        } else if u.dim == unit.dim {
            Value::Num(tidy(x * u.si / unit.si))
        } else {
            Value::Text(s.clone())
        };
    }
    use vworks_cell::Quantity;
    let si = match v {
        toml::Value::Integer(i) => Some(*i as f64),
        toml::Value::Float(x) => Some(*x),
        toml::Value::String(s) => match vworks_cell::parse_quantity(s) {
            Some(Quantity::Number(x)) => Some(x),
            Some(Quantity::WithUnit(x, d)) if d == unit.dim => Some(x),
            _ => None,
        },
        _ => None,
    };
    match (si, v) {
        (Some(x), _) => Value::Num(tidy(x / unit.si)),
        (None, toml::Value::String(s)) => Value::Text(s.clone()),
        (None, other) => shown(other),
    }
}

/// The unit of a column that is not a variable's: `s` for `end_time` and
/// `cycle_time.ROBOT`, `m` for `min_clearance`; `None` for the others.
pub fn fixed_unit(column: &str) -> Option<&'static str> {
    if column == "end_time" || column.starts_with("cycle_time.") {
        Some("s")
    } else if column == "min_clearance" {
        Some("m")
    } else {
        None
    }
}

/// A column's header in the table file: its name, and its unit in brackets if it has one
/// (`end_time [s]`).
pub fn header(name: &str, unit: Option<&str>) -> String {
    match unit {
        Some(u) if !u.is_empty() => format!("{name} [{u}]"),
        _ => name.to_string(),
    }
}

/// The table file's header: [`columns`] with their units (each variable's `units`, and
/// the [`fixed_unit`]s).
pub fn headers(variables: &[String], units: &[Option<Unit>], robots: &[String]) -> Vec<String> {
    columns(variables, robots)
        .iter()
        .enumerate()
        .map(|(k, c)| {
            let unit = if (1..=variables.len()).contains(&k) {
                units
                    .get(k - 1)
                    .and_then(Option::as_ref)
                    .map(|u| u.name.as_str())
            } else {
                fixed_unit(c)
            };
            header(c, unit)
        })
        .collect()
}

/// The column a user named, by its name (`end_time`) or its header (`end_time [s]`).
pub fn find_column(columns: &[String], headers: &[String], name: &str) -> Option<usize> {
    let name = name.trim();
    columns
        .iter()
        .position(|c| c == name)
        .or_else(|| headers.iter().position(|h| h == name))
}

/// Rows of a table, visited in order: a [`Table`] in memory, or a table file read back
/// (`stream::TableFile`) so the page never holds every row.
pub trait Rows {
    /// The column names.
    fn columns(&self) -> &[String];
    /// Calls `f` with each row in order.
    fn for_each_row(&self, f: &mut dyn FnMut(&[Value])) -> std::io::Result<()>;
}

impl Rows for Table {
    fn columns(&self) -> &[String] {
        &self.columns
    }

    fn for_each_row(&self, f: &mut dyn FnMut(&[Value])) -> std::io::Result<()> {
        self.rows.iter().for_each(|r| f(r));
        Ok(())
    }
}

/// Completed without a collision (a candidate for the best), read from the row's
/// `outcome` and `collisions`: the same as [`Row::feasible`].
pub fn feasible(columns: &[String], row: &[Value]) -> bool {
    let at = |name: &str| {
        columns
            .iter()
            .position(|c| c == name)
            .and_then(|k| row.get(k))
    };
    matches!(at("outcome"), Some(Value::Text(o))
        if RowOutcome::from_name(o) == Some(RowOutcome::Run(Outcome::Completed)))
        && at("collisions").and_then(Value::number) == Some(0.0)
}

/// The columns of a sweep's table: `variant`, each variable, `outcome`, `end_time`, each
/// robot's `cycle_time.ROBOT`, `collisions`, `min_clearance`, `error`.
pub fn columns(variables: &[String], robots: &[String]) -> Vec<String> {
    let mut columns = vec!["variant".to_string()];
    columns.extend(variables.iter().cloned());
    columns.extend(["outcome".to_string(), "end_time".to_string()]);
    columns.extend(robots.iter().map(|r| format!("cycle_time.{r}")));
    columns.extend(["collisions", "min_clearance", "error"].map(String::from));
    columns
}

/// The numeric columns of such a table, known before any variant runs: `variant`, the
/// variables whose every value is a number, `end_time`, `cycle_time.ROBOT`,
/// `collisions`, `min_clearance` — what an objective may be.
pub fn numeric_columns(variables: &[(String, bool)], robots: &[String]) -> Vec<String> {
    let mut out = vec!["variant".to_string()];
    out.extend(variables.iter().filter(|(_, n)| *n).map(|(v, _)| v.clone()));
    out.push("end_time".into());
    out.extend(robots.iter().map(|r| format!("cycle_time.{r}")));
    out.extend(["collisions", "min_clearance"].map(String::from));
    out
}

/// Whether a variable's value shows as a number in the table.
pub fn is_numeric(v: &toml::Value) -> bool {
    shown(v).number().is_some()
}

/// One row of the table with these `variables` and `robots`.
pub fn row_values(variables: &[String], robots: &[String], r: &Row) -> Vec<Value> {
    let mut out = vec![Value::Int(r.index as i64)];
    for v in variables {
        out.push(
            r.values
                .iter()
                .rev()
                .find(|(p, _)| p == v)
                .map_or(Value::Empty, |(_, x)| shown(x)),
        );
    }
    out.push(Value::Text(r.outcome.name().to_string()));
    out.push(if r.outcome == RowOutcome::Invalid {
        Value::Empty
    } else {
        Value::Num(r.end_time)
    });
    for robot in robots {
        out.push(
            r.cycle_times
                .iter()
                .find(|(n, _)| n == robot)
                .and_then(|(_, t)| *t)
                .map_or(Value::Empty, Value::Num),
        );
    }
    out.push(Value::Int(r.collisions as i64));
    out.push(r.min_clearance.map_or(Value::Empty, Value::Num));
    out.push(Value::Text(r.error.clone()));
    out
}

/// One row of the table file: [`row_values`], each variable shown in its unit
/// ([`in_unit`]).
pub fn row_values_in(
    variables: &[String],
    units: &[Option<Unit>],
    robots: &[String],
    r: &Row,
) -> Vec<Value> {
    let mut out = row_values(variables, robots, r);
    for (k, (v, unit)) in variables.iter().zip(units).enumerate() {
        if let Some(x) = r.values.iter().rev().find(|(p, _)| p == v).map(|(_, x)| x) {
            out[k + 1] = in_unit(x, unit.as_ref());
        }
    }
    out
}

/// A CSV line (RFC 4180) of `values`, with its newline.
pub fn csv_line(values: &[Value]) -> String {
    let cells: Vec<String> = values.iter().map(Value::csv).collect();
    format!("{}\n", cells.join(","))
}

/// The CSV header line of `columns`.
pub fn csv_header(columns: &[String]) -> String {
    let names: Vec<Value> = columns.iter().map(|c| Value::Text(c.clone())).collect();
    csv_line(&names)
}

/// A JSON line: one object, keys in column order, with its newline.
pub fn json_line(columns: &[String], values: &[Value]) -> String {
    let mut s = String::from("{");
    for (k, (c, v)) in columns.iter().zip(values).enumerate() {
        if k > 0 {
            s.push(',');
        }
        let _ = write!(s, "{}:{}", serde_json::json!(c), v.json());
    }
    s.push_str("}\n");
    s
}

/// The best rows by an objective, kept as rows pass (at most `n` held): the smallest
/// objective first among feasible rows, ties in the order they came.
#[derive(Clone, Debug)]
pub struct Best {
    column: Option<usize>,
    n: usize,
    seen: usize,
    /// (objective, order seen, row).
    kept: Vec<(f64, usize, Vec<Value>)>,
}

impl Best {
    /// Keeps the `n` best by the column `objective` of `columns`.
    pub fn new(columns: &[String], objective: &str, n: usize) -> Best {
        Best {
            column: columns.iter().position(|c| c == objective),
            n,
            seen: 0,
            kept: Vec::new(),
        }
    }

    /// Offers a row (with the table's `columns`); kept if feasible and among the best.
    pub fn offer(&mut self, columns: &[String], row: &[Value]) {
        let order = self.seen;
        self.seen += 1;
        let Some(x) = self.column.and_then(|k| row.get(k)).and_then(Value::number) else {
            return;
        };
        if self.n == 0 || !feasible(columns, row) {
            return;
        }
        let at = self
            .kept
            .partition_point(|(v, o, _)| v.total_cmp(&x).then(o.cmp(&order)).is_lt());
        if at < self.n {
            self.kept.insert(at, (x, order, row.to_vec()));
            self.kept.truncate(self.n);
        }
    }

    /// The best rows, best first.
    pub fn rows(&self) -> Vec<&[Value]> {
        self.kept.iter().map(|(_, _, r)| r.as_slice()).collect()
    }

    /// The order (0-based, as offered) of each best row, best first.
    pub fn order(&self) -> Vec<usize> {
        self.kept.iter().map(|(_, o, _)| *o).collect()
    }
}

impl Table {
    /// The table of `rows`, with a column per variable in `variables` and per robot in
    /// `robots`.
    pub fn new(variables: &[String], robots: &[String], rows: &[Row]) -> Table {
        Table {
            columns: columns(variables, robots),
            rows: rows
                .iter()
                .map(|r| row_values(variables, robots, r))
                .collect(),
        }
    }

    /// The table of `rows` of a sweep of `cell`: a column per variable and per robot.
    pub fn of_cell(variables: &[String], cell: &vworks_cell::Cell, rows: &[Row]) -> Table {
        let robots: Vec<String> = cell.robots.iter().map(|r| r.name.clone()).collect();
        Table::new(variables, &robots, rows)
    }

    /// The column named `name`.
    pub fn column(&self, name: &str) -> Option<usize> {
        self.columns.iter().position(|c| c == name)
    }

    /// CSV (RFC 4180), header first.
    pub fn csv(&self) -> String {
        let mut s = csv_header(&self.columns);
        self.rows.iter().for_each(|r| s.push_str(&csv_line(r)));
        s
    }

    /// JSON lines: one object per row, keys in column order.
    pub fn json_lines(&self) -> String {
        self.rows
            .iter()
            .map(|r| json_line(&self.columns, r))
            .collect()
    }

    /// The `n` best rows by `objective` (smallest first) among the feasible ones
    /// (completed, no collision): their indices into `rows`. `Err` names the numeric
    /// columns if `objective` is not one.
    pub fn best(&self, objective: &str, n: usize) -> Result<Vec<usize>, String> {
        let numeric: Vec<&str> = self
            .columns
            .iter()
            .enumerate()
            .filter(|(k, _)| self.rows.iter().any(|r| r[*k].number().is_some()))
            .map(|(_, c)| c.as_str())
            .collect();
        if !numeric.contains(&objective) {
            return Err(format!(
                "`{objective}` is not a numeric column of the table; choose one of {}",
                numeric.join(", ")
            ));
        }
        let mut best = Best::new(&self.columns, objective, n);
        self.rows.iter().for_each(|r| best.offer(&self.columns, r));
        Ok(best.order())
    }
}
