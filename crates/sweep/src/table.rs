//! The sweep's table: one row per variant, the same columns for every row —
//! `variant`, each variable (SI numbers where the value is a quantity), `outcome`,
//! `end_time` (s), `cycle_time.ROBOT` (s) for each robot, `collisions`,
//! `min_clearance` (m), `error` — written as CSV or JSON lines, and the best variants by
//! an objective.

use std::fmt::Write as _;

use crate::Row;

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

impl Table {
    /// The table of `rows`, with a column per variable in `variables` and per robot in
    /// `robots`.
    pub fn new(variables: &[String], robots: &[String], rows: &[Row]) -> Table {
        let mut columns = vec!["variant".to_string()];
        columns.extend(variables.iter().cloned());
        columns.extend(["outcome".to_string(), "end_time".to_string()]);
        columns.extend(robots.iter().map(|r| format!("cycle_time.{r}")));
        columns.extend(["collisions", "min_clearance", "error"].map(String::from));
        let rows = rows
            .iter()
            .map(|r| {
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
                out.push(Value::Text(r.outcome.clone()));
                out.push(if r.outcome == "invalid" {
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
            })
            .collect();
        Table { columns, rows }
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
        let mut s = String::new();
        let header: Vec<String> = self
            .columns
            .iter()
            .map(|c| Value::Text(c.clone()).csv())
            .collect();
        let _ = writeln!(s, "{}", header.join(","));
        for row in &self.rows {
            let cells: Vec<String> = row.iter().map(Value::csv).collect();
            let _ = writeln!(s, "{}", cells.join(","));
        }
        s
    }

    /// JSON lines: one object per row, keys in column order.
    pub fn json_lines(&self) -> String {
        let mut s = String::new();
        for row in &self.rows {
            s.push('{');
            for (k, (c, v)) in self.columns.iter().zip(row).enumerate() {
                if k > 0 {
                    s.push(',');
                }
                let _ = write!(s, "{}:{}", serde_json::json!(c), v.json());
            }
            s.push_str("}\n");
        }
        s
    }

    /// The `n` best rows by `objective` (smallest first) among those where `feasible`
    /// (completed, no collision) holds: their indices into `rows`. `Err` names the numeric
    /// columns if `objective` is not one.
    pub fn best(&self, objective: &str, n: usize, feasible: &[bool]) -> Result<Vec<usize>, String> {
        let numeric: Vec<&str> = self
            .columns
            .iter()
            .enumerate()
            .filter(|(k, _)| self.rows.iter().any(|r| r[*k].number().is_some()))
            .map(|(_, c)| c.as_str())
            .collect();
        let Some(k) = self
            .column(objective)
            .filter(|k| numeric.contains(&self.columns[*k].as_str()))
        else {
            return Err(format!(
                "`{objective}` is not a numeric column of the table; choose one of {}",
                numeric.join(", ")
            ));
        };
        let mut candidates: Vec<(f64, usize)> = self
            .rows
            .iter()
            .enumerate()
            .filter(|(i, _)| feasible.get(*i).copied().unwrap_or(false))
            .filter_map(|(i, r)| Some((r[k].number()?, i)))
            .collect();
        candidates.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
        Ok(candidates.into_iter().take(n).map(|(_, i)| i).collect())
    }
}
