//! The sweep's page: one self-contained HTML file (inline SVG, no script, nothing loaded)
//! with the objective over one variable (a scatter) or two (a heatmap), the best variants
//! and the whole table.
//!
//! - One numeric variable: the objective of each variant against it; feasible variants
//!   (completed, no collision) as blue dots, collisions as red crosses, other outcomes
//!   grey.
//! - Two or more: a heatmap over the first two, each cell the best feasible objective over
//!   the other variables (lighter is smaller), red where every variant of the cell
//!   collided, grey where none completed.

use std::collections::BTreeSet;
use std::fmt::Write as _;
use std::io::{self, Write};

use crate::table::{Rows, Table, Value, feasible};

fn esc(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
}

fn num(v: &Value) -> String {
    match v {
        Value::Num(x) => format!("{}", (x * 1e6).round() / 1e6),
        Value::Int(i) => i.to_string(),
        Value::Text(s) => esc(s),
        Value::Empty => "–".into(),
    }
}

/// The page of `table` in memory (see [`write_page`]); `best` are indices into its rows.
pub fn page(
    title: &str,
    table: &Table,
    variables: &[String],
    objective: &str,
    best: &[usize],
) -> String {
    let best: Vec<&[Value]> = best
        .iter()
        .filter_map(|i| table.rows.get(*i).map(Vec::as_slice))
        .collect();
    let mut out = Vec::new();
    // Writing to memory cannot fail.
    let _ = write_page(&mut out, title, table, variables, objective, &best);
    String::from_utf8_lossy(&out).into_owned()
}

/// Writes the page. `title` names the sweep; `variables` are the variable columns;
/// `objective` a numeric column; `best` the best rows. The rows are read a few times, one
/// at a time (never all at once): a table of millions of variants fits.
pub fn write_page(
    out: &mut dyn Write,
    title: &str,
    rows: &dyn Rows,
    variables: &[String],
    objective: &str,
    best: &[&[Value]],
) -> io::Result<()> {
    let columns = rows.columns();
    let column = |name: &str| columns.iter().position(|c| c == name);
    let vars: Vec<usize> = variables.iter().filter_map(|v| column(v)).collect();
    // First pass: how many, how many feasible, which variables are numbers.
    let (mut n, mut feasible_count) = (0usize, 0usize);
    let mut numeric = vec![true; vars.len()];
    rows.for_each_row(&mut |r| {
        n += 1;
        feasible_count += usize::from(feasible(columns, r));
        for (ok, k) in numeric.iter_mut().zip(&vars) {
            *ok &= r[*k].number().is_some();
        }
    })?;
    write!(
        out,
        r#"<!DOCTYPE html>
<html lang="en"><head><meta charset="utf-8"><title>vworks sweep: {t}</title>
<style>
body {{ font: 14px/1.4 system-ui, sans-serif; margin: 24px; color: #222; }}
table {{ border-collapse: collapse; }} th, td {{ padding: 2px 8px; border-bottom: 1px solid #eee; text-align: right; font-variant-numeric: tabular-nums; }}
th {{ background: #f6f6f6; }} .none {{ color: #888; }}
</style></head><body>
<h1>vworks sweep: {t}</h1>
<p>{n} variants · objective: {o} (smaller is better) · {feasible_count} completed without collision</p>
"#,
        t = esc(title),
        o = esc(objective),
    )?;
    let numeric: Vec<usize> = vars
        .iter()
        .zip(&numeric)
        .filter(|(_, ok)| **ok)
        .map(|(k, _)| *k)
        .collect();
    if let Some(o) = column(objective) {
        match numeric.as_slice() {
            [x] => scatter(out, rows, *x, o)?,
            [x, y, ..] => heatmap(out, rows, *x, *y, o)?,
            [] => out.write_all(b"<p class=\"none\">No numeric variable to chart.</p>\n")?,
        }
    }
    out.write_all(b"<h2>Best variants</h2>\n")?;
    if best.is_empty() {
        out.write_all(
            b"<p class=\"none\" id=\"best\">No variant completed without a collision.</p>\n",
        )?;
    } else {
        table_head(out, "best", columns)?;
        for r in best {
            table_row(out, r)?;
        }
        out.write_all(b"</table>\n")?;
    }
    out.write_all(b"<h2>Every variant</h2>\n")?;
    table_head(out, "all", columns)?;
    let mut failed = Ok(());
    rows.for_each_row(&mut |r| {
        if failed.is_ok() {
            failed = table_row(out, r);
        }
    })?;
    failed?;
    out.write_all(b"</table>\n</body></html>\n")
}

fn table_head(out: &mut dyn Write, id: &str, columns: &[String]) -> io::Result<()> {
    let mut s = format!("<table id=\"{id}\"><tr>");
    for c in columns {
        let _ = write!(s, "<th>{}</th>", esc(c));
    }
    s.push_str("</tr>\n");
    out.write_all(s.as_bytes())
}

fn table_row(out: &mut dyn Write, row: &[Value]) -> io::Result<()> {
    let mut s = String::from("<tr>");
    for v in row {
        let _ = write!(s, "<td>{}</td>", num(v));
    }
    s.push_str("</tr>\n");
    out.write_all(s.as_bytes())
}

const W: f64 = 720.0;
const H: f64 = 420.0;
const L: f64 = 80.0;
const B: f64 = 50.0;

fn span(values: impl Iterator<Item = f64>) -> (f64, f64) {
    let (lo, hi) = values.fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), x| {
        (a.min(x), b.max(x))
    });
    if !lo.is_finite() {
        (0.0, 1.0)
    } else if hi - lo < 1e-12 {
        (lo - 0.5, hi + 0.5)
    } else {
        (lo, hi)
    }
}

/// The titles of the chart's axes: `x` under it, `y` turned along its left side.
fn axis_titles(s: &mut String, x: &str, y: &str) {
    let _ = write!(
        s,
        r##"<text x="{cx:.1}" y="{ty:.1}" font-size="13" text-anchor="middle">{x}</text><text x="14" y="{cy:.1}" font-size="13" transform="rotate(-90 14 {cy:.1})" text-anchor="middle">{y}</text>"##,
        cx = (L + W - 20.0) / 2.0,
        ty = H - 12.0,
        cy = (H - B) / 2.0,
        x = esc(x),
        y = esc(y),
    );
}

/// A number ordered by `total_cmp`: a key of the sets of distinct values.
#[derive(Clone, Copy, PartialEq)]
struct Key(f64);

impl Eq for Key {}

impl PartialOrd for Key {
    fn partial_cmp(&self, other: &Self) -> Option<std::cmp::Ordering> {
        Some(self.cmp(other))
    }
}

impl Ord for Key {
    fn cmp(&self, other: &Self) -> std::cmp::Ordering {
        self.0.total_cmp(&other.0)
    }
}

/// Whether a row collided (its `collisions` above 0).
fn collided(columns: &[String], r: &[Value]) -> bool {
    columns
        .iter()
        .position(|c| c == "collisions")
        .is_some_and(|k| r[k].number().unwrap_or(0.0) > 0.0)
}

fn scatter(out: &mut dyn Write, rows: &dyn Rows, x: usize, o: usize) -> io::Result<()> {
    let columns = rows.columns();
    let none = (f64::INFINITY, f64::NEG_INFINITY);
    let (mut xr, mut yr) = (none, none);
    let widen = |r: &mut (f64, f64), v: f64| *r = (r.0.min(v), r.1.max(v));
    rows.for_each_row(&mut |r| {
        if let Some(xv) = r[x].number() {
            widen(&mut xr, xv);
            if let Some(yv) = r[o].number() {
                widen(&mut yr, yv);
            }
        }
    })?;
    let (x0, x1) = span([xr.0, xr.1].into_iter().filter(|v| v.is_finite()));
    let (y0, y1) = span([yr.0, yr.1].into_iter().filter(|v| v.is_finite()));
    let px = |v: f64| L + (W - L - 20.0) * (v - x0) / (x1 - x0);
    let py = |v: f64| H - B - (H - B - 20.0) * (v - y0) / (y1 - y0);
    let mut s = format!(
        r##"<svg id="chart" xmlns="http://www.w3.org/2000/svg" viewBox="0 0 {W} {H}" width="{W}" role="img"><rect x="{L}" y="20" width="{w}" height="{h}" fill="none" stroke="#ccc"/>"##,
        w = W - L - 20.0,
        h = H - B - 20.0
    );
    for (v, at) in [(x0, px(x0)), (x1, px(x1))] {
        let _ = write!(
            s,
            r##"<text x="{at:.1}" y="{y:.1}" font-size="11" text-anchor="middle">{v:.4}</text>"##,
            y = H - B + 16.0
        );
    }
    for (v, at) in [(y0, py(y0)), (y1, py(y1))] {
        let _ = write!(
            s,
            r##"<text x="{x:.1}" y="{at:.1}" font-size="11" text-anchor="end">{v:.4}</text>"##,
            x = L - 6.0
        );
    }
    axis_titles(&mut s, &columns[x], &columns[o]);
    out.write_all(s.as_bytes())?;
    let mut failed = Ok(());
    rows.for_each_row(&mut |r| {
        let (Some(xv), Some(yv), true) = (r[x].number(), r[o].number(), failed.is_ok()) else {
            return;
        };
        let (cx, cy) = (px(xv), py(yv));
        let i = num(&r[0]);
        let dot = if feasible(columns, r) {
            format!(
                r##"<circle class="feasible" cx="{cx:.1}" cy="{cy:.1}" r="4" fill="#2f6fdf"><title>variant {i}</title></circle>"##
            )
        } else if collided(columns, r) {
            format!(
                r##"<path class="collision" d="M{a:.1} {b:.1} l8 8 m0 -8 l-8 8" stroke="#d62728" stroke-width="2"><title>variant {i}: collision</title></path>"##,
                a = cx - 4.0,
                b = cy - 4.0
            )
        } else {
            format!(
                r##"<circle class="other" cx="{cx:.1}" cy="{cy:.1}" r="3" fill="#999"><title>variant {i}</title></circle>"##
            )
        };
        failed = out.write_all(dot.as_bytes());
    })?;
    failed?;
    out.write_all(b"</svg>\n")
}

/// Cells of a heatmap at most: more distinct values than this are not charted.
const MAX_CELLS: usize = 250_000;

fn heatmap(out: &mut dyn Write, rows: &dyn Rows, x: usize, y: usize, o: usize) -> io::Result<()> {
    let columns = rows.columns();
    let (mut xs, mut ys) = (BTreeSet::new(), BTreeSet::new());
    let mut too_many = false;
    rows.for_each_row(&mut |r| {
        if let (Some(xv), Some(yv), false) = (r[x].number(), r[y].number(), too_many) {
            xs.insert(Key(xv));
            ys.insert(Key(yv));
            too_many = xs.len().saturating_mul(ys.len()) > MAX_CELLS;
        }
    })?;
    if too_many {
        let note = format!(
            "<p class=\"none\">Too many distinct values of {} and {} to chart (more than {MAX_CELLS} cells).</p>\n",
            esc(&columns[x]),
            esc(&columns[y])
        );
        return out.write_all(note.as_bytes());
    }
    let xs: Vec<f64> = xs.into_iter().map(|k| k.0).collect();
    let ys: Vec<f64> = ys.into_iter().map(|k| k.0).collect();
    // Per cell: the best feasible objective, whether any variant collided, how many ran.
    let mut cells = vec![(None::<f64>, false, 0usize); xs.len() * ys.len()];
    rows.for_each_row(&mut |r| {
        let (Some(xv), Some(yv)) = (r[x].number(), r[y].number()) else {
            return;
        };
        let (Ok(a), Ok(b)) = (
            xs.binary_search_by(|v| v.total_cmp(&xv)),
            ys.binary_search_by(|v| v.total_cmp(&yv)),
        ) else {
            return;
        };
        let c = &mut cells[b * xs.len() + a];
        c.2 += 1;
        c.1 |= collided(columns, r);
        if feasible(columns, r)
            && let Some(v) = r[o].number()
        {
            c.0 = Some(c.0.map_or(v, |m: f64| m.min(v)));
        }
    })?;
    let (lo, hi) = span(cells.iter().filter_map(|c| c.0));
    let cw = (W - L - 20.0) / xs.len() as f64;
    let ch = (H - B - 20.0) / ys.len() as f64;
    let mut s = format!(
        r##"<svg id="chart" xmlns="http://www.w3.org/2000/svg" viewBox="0 0 {W} {H}" width="{W}" role="img">"##
    );
    for (b, yv) in ys.iter().enumerate() {
        for (a, xv) in xs.iter().enumerate() {
            let (best, hit, n) = cells[b * xs.len() + a];
            let (fill, what) = match best {
                Some(v) => {
                    let t = (v - lo) / (hi - lo);
                    let (r, g, bl) = (40.0 + 200.0 * t, 90.0 + 150.0 * t, 200.0 + 40.0 * t);
                    (format!("rgb({r:.0},{g:.0},{bl:.0})"), format!("{v:.6}"))
                }
                None if hit => ("#d62728".to_string(), "collision".to_string()),
                None if n > 0 => ("#bbbbbb".to_string(), "did not complete".to_string()),
                None => ("#ffffff".to_string(), "no variant".to_string()),
            };
            let _ = write!(
                s,
                r##"<rect class="cell" x="{rx:.1}" y="{ry:.1}" width="{cw:.1}" height="{ch:.1}" fill="{fill}" stroke="#fff"><title>{xn} = {xv}, {yn} = {yv}: {what}</title></rect>"##,
                rx = L + a as f64 * cw,
                ry = 20.0 + (ys.len() - 1 - b) as f64 * ch,
                xn = esc(&columns[x]),
                yn = esc(&columns[y]),
            );
        }
    }
    let range = |name: &str, v: &[f64]| {
        let (a, b) = (
            v.first().copied().unwrap_or(0.0),
            v.last().copied().unwrap_or(0.0),
        );
        format!("{name} ({a} … {b})")
    };
    axis_titles(&mut s, &range(&columns[x], &xs), &range(&columns[y], &ys));
    s.push_str("</svg>\n");
    out.write_all(s.as_bytes())
}
