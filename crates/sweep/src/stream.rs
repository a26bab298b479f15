//! The table as the sweep runs: each row written (and flushed) as soon as it and every
//! row before it are done, so a sweep that is killed leaves every row it finished, and
//! memory does not grow with the number of variants; the table file read back, row by
//! row, for the page.

use std::io::{self, BufRead, Write};
use std::path::{Path, PathBuf};

use crate::table::{Rows, Value, csv_header, csv_line, json_line};

/// The table's file format.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Format {
    /// CSV (RFC 4180), header first.
    Csv,
    /// JSON lines: one object per row.
    JsonLines,
}

impl Format {
    /// JSON lines for `.jsonl` and `.json`, else CSV.
    pub fn of_path(path: &Path) -> Format {
        match path.extension().and_then(|e| e.to_str()) {
            Some("jsonl" | "json") => Format::JsonLines,
            _ => Format::Csv,
        }
    }
}

/// Writes a table row by row.
#[derive(Debug)]
pub struct TableWriter<W: Write> {
    out: W,
    format: Format,
    columns: Vec<String>,
}

impl<W: Write> TableWriter<W> {
    /// A table of these columns, in this format, to `out` (nothing written yet).
    pub fn new(out: W, format: Format, columns: Vec<String>) -> Self {
        TableWriter {
            out,
            format,
            columns,
        }
    }

    /// Starts the table: the CSV header, flushed.
    pub fn start(&mut self) -> io::Result<()> {
        if self.format == Format::Csv {
            self.out.write_all(csv_header(&self.columns).as_bytes())?;
            self.out.flush()?;
        }
        Ok(())
    }

    /// The column names.
    pub fn columns(&self) -> &[String] {
        &self.columns
    }

    /// Writes one row and flushes it.
    pub fn write(&mut self, row: &[Value]) -> io::Result<()> {
        let line = match self.format {
            Format::Csv => csv_line(row),
            Format::JsonLines => json_line(&self.columns, row),
        };
        self.out.write_all(line.as_bytes())?;
        self.out.flush()
    }

    /// The writer.
    pub fn into_inner(self) -> W {
        self.out
    }
}

/// A table file written by [`TableWriter`], read back row by row (never whole).
#[derive(Debug)]
pub struct TableFile {
    path: PathBuf,
    format: Format,
    columns: Vec<String>,
}

impl TableFile {
    /// The table at `path`, with these columns, in this format.
    pub fn new(path: &Path, format: Format, columns: Vec<String>) -> TableFile {
        TableFile {
            path: path.to_path_buf(),
            format,
            columns,
        }
    }
}

impl Rows for TableFile {
    fn columns(&self) -> &[String] {
        &self.columns
    }

    fn for_each_row(&self, f: &mut dyn FnMut(&[Value])) -> io::Result<()> {
        let file = std::fs::File::open(&self.path)?;
        let mut lines = io::BufReader::new(file).lines();
        if self.format == Format::Csv {
            lines.next().transpose()?; // the header
        }
        let mut record = String::new();
        for line in lines {
            let line = line?;
            if !record.is_empty() {
                record.push('\n');
            }
            record.push_str(&line);
            let row = match self.format {
                // A quoted cell may hold a line break: a record ends where the quotes
                // are balanced.
                Format::Csv if record.matches('"').count() % 2 == 1 => continue,
                Format::Csv => parse_csv(&record),
                Format::JsonLines => parse_json(&record, &self.columns)?,
            };
            f(&row);
            record.clear();
        }
        Ok(())
    }
}

/// A written cell's value: an integer, a number, empty, or text.
fn typed(cell: String) -> Value {
    if cell.is_empty() {
        Value::Empty
    } else if let Ok(i) = cell.parse::<i64>() {
        Value::Int(i)
    } else if let Some(x) = cell.parse::<f64>().ok().filter(|x| x.is_finite()) {
        Value::Num(x)
    } else {
        Value::Text(cell)
    }
}

/// One CSV record (RFC 4180: quoted cells, `""` for a quote).
fn parse_csv(record: &str) -> Vec<Value> {
    let mut cells = Vec::new();
    let (mut cell, mut quoted, mut was_quoted) = (String::new(), false, false);
    let mut chars = record.chars().peekable();
    while let Some(c) = chars.next() {
        match (c, quoted) {
            ('"', true) if chars.peek() == Some(&'"') => {
                cell.push('"');
                chars.next();
            }
            ('"', true) => quoted = false,
            ('"', false) => (quoted, was_quoted) = (true, true),
            (',', false) => {
                cells.push(cell_value(std::mem::take(&mut cell), was_quoted));
                was_quoted = false;
            }
            (c, _) => cell.push(c),
        }
    }
    cells.push(cell_value(cell, was_quoted));
    cells
}

fn cell_value(cell: String, quoted: bool) -> Value {
    if quoted {
        Value::Text(cell)
    } else {
        typed(cell)
    }
}

fn parse_json(line: &str, columns: &[String]) -> io::Result<Vec<Value>> {
    let v: serde_json::Value = serde_json::from_str(line).map_err(io::Error::other)?;
    Ok(columns
        .iter()
        .map(|c| match &v[c] {
            serde_json::Value::Number(n) => n
                .as_i64()
                .map(Value::Int)
                .or_else(|| n.as_f64().map(Value::Num))
                .unwrap_or(Value::Empty),
            serde_json::Value::String(s) => Value::Text(s.clone()),
            serde_json::Value::Bool(b) => Value::Text(b.to_string()),
            _ => Value::Empty,
        })
        .collect())
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]

    use super::*;

    #[test]
    fn a_written_table_reads_back_the_same() {
        let columns: Vec<String> = ["variant", "x", "outcome", "min_clearance", "error"]
            .map(String::from)
            .to_vec();
        let rows = vec![
            vec![
                Value::Int(0),
                Value::Num(0.25),
                Value::Text("completed".into()),
                Value::Empty,
                Value::Text(String::new()),
            ],
            vec![
                Value::Int(1),
                Value::Num(0.5),
                Value::Text("invalid".into()),
                Value::Num(0.001),
                Value::Text("a \"quoted\", two-line\nreason".into()),
            ],
        ];
        for format in [Format::Csv, Format::JsonLines] {
            let path = std::env::temp_dir().join(format!(
                "vworks-stream-{format:?}-{}.table",
                std::process::id()
            ));
            let file = std::fs::File::create(&path).unwrap();
            let mut w = TableWriter::new(file, format, columns.clone());
            w.start().unwrap();
            rows.iter().for_each(|r| w.write(r).unwrap());
            drop(w);
            let mut back = Vec::new();
            TableFile::new(&path, format, columns.clone())
                .for_each_row(&mut |r| back.push(r.to_vec()))
                .unwrap();
            // An empty error reads back empty: the page shows both the same.
            let mut want = rows.clone();
            want[0][4] = match format {
                Format::Csv => Value::Empty,
                Format::JsonLines => Value::Text(String::new()),
            };
            assert_eq!(back, want, "{format:?}");
            let _ = std::fs::remove_file(&path);
        }
    }
}
