//! The sweep's page: one self-contained HTML file (inline SVG, no script, nothing loaded)
//! with the objective over one variable (a scatter) or two (a heatmap), the best variants
//! and the whole table. The columns are named as the table file names them, with their
//! units (`robot.r2.base.xyz.0 [mm]`, `end_time [s]`): the axes' titles and the colour
//! bar's say them, and the ticks are the values in those units.
//!
//! - One numeric variable: the objective of each variant against it, with ticks on both
//!   axes; feasible variants (completed, no collision) as blue dots, collisions as red
//!   crosses, other outcomes (deadlock, error, timeout, `until`) grey; a legend says so.
//! - Two or more: a heatmap over the first two, a tick at each value; each cell the best
//!   feasible objective over the other variables, on a colour bar from dark blue
//!   (smallest: best) to light grey (largest); red where none completed without a
//!   collision and one collided, grey where none completed, white where no variant ran;
//!   a legend says so, with how many cells each.

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
#legend {{ list-style: none; padding: 0; margin: 8px 0 16px; display: flex; flex-wrap: wrap; gap: 6px 20px; }}
#legend li {{ display: flex; align-items: center; gap: 6px; }}
.swatch {{ display: inline-block; width: 14px; height: 14px; border: 1px solid #aaa; }}
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

const W: f64 = 760.0;
const H: f64 = 460.0;
/// The plot's left edge (room for the y ticks and title).
const L: f64 = 96.0;
/// Below the plot: the x ticks and title.
const B: f64 = 64.0;
/// Above the plot.
const T: f64 = 16.0;
/// Right of the plot: room for the heatmap's colour bar.
const R: f64 = 170.0;

const BLUE: &str = "#2f6fdf";
const RED: &str = "#d62728";
const GREY: &str = "#bbbbbb";

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

/// A value as a tick shows it: 12 significant digits at most (no conversion noise).
fn label(v: f64) -> String {
    let v: f64 = format!("{v:.11e}").parse().unwrap_or(v);
    format!("{}", v + 0.0)
}

/// Ticks at round numbers (1, 2 or 5 × 10ⁿ apart) from `lo` to `hi`, about `n` of them.
fn nice_ticks(lo: f64, hi: f64, n: usize) -> Vec<f64> {
    let raw = (hi - lo) / n.max(1) as f64;
    if !(raw.is_finite() && raw > 0.0) {
        return vec![lo];
    }
    let mag = 10f64.powf(raw.log10().floor());
    let step = [1.0, 2.0, 5.0, 10.0]
        .iter()
        .map(|m| m * mag)
        .find(|s| *s >= raw)
        .unwrap_or(10.0 * mag);
    let first = (lo / step).ceil() as i64;
    let last = (hi / step).floor() as i64;
    (first..=last).map(|k| k as f64 * step).collect()
}

/// The titles of the chart's axes: `x` under the plot, `y` turned along its left side.
fn axis_titles(s: &mut String, right: f64, x: &str, y: &str) {
    let _ = write!(
        s,
        r##"<text class="axis-title" id="x-title" x="{cx:.1}" y="{ty:.1}" font-size="13" text-anchor="middle">{x}</text><text class="axis-title" id="y-title" x="16" y="{cy:.1}" font-size="13" transform="rotate(-90 16 {cy:.1})" text-anchor="middle">{y}</text>"##,
        cx = (L + right) / 2.0,
        ty = H - 14.0,
        cy = (T + H - B) / 2.0,
        x = esc(x),
        y = esc(y),
    );
}

/// A tick under the plot at `at` (x) or left of it (y), with its label.
fn tick(s: &mut String, axis: char, at: f64, text: &str) {
    let text = esc(text);
    let _ = match axis {
        'x' => write!(
            s,
            r##"<g class="tick x-tick"><line x1="{at:.1}" y1="{y0:.1}" x2="{at:.1}" y2="{y1:.1}" stroke="#666"/><text x="{at:.1}" y="{ty:.1}" font-size="11" text-anchor="middle">{text}</text></g>"##,
            y0 = H - B,
            y1 = H - B + 5.0,
            ty = H - B + 18.0,
        ),
        _ => write!(
            s,
            r##"<g class="tick y-tick"><line x1="{x0:.1}" y1="{at:.1}" x2="{L:.1}" y2="{at:.1}" stroke="#666"/><text x="{tx:.1}" y="{ty:.1}" font-size="11" text-anchor="end">{text}</text></g>"##,
            x0 = L - 5.0,
            tx = L - 8.0,
            ty = at + 4.0,
        ),
    };
}

/// The legend under the chart: a swatch (or a mark) and what it means, per entry.
fn legend(out: &mut dyn Write, entries: &[(String, String)]) -> io::Result<()> {
    let mut s = String::from("<ul id=\"legend\">");
    for (mark, text) in entries {
        let _ = write!(s, "<li>{mark}<span>{}</span></li>", esc(text));
    }
    s.push_str("</ul>\n");
    out.write_all(s.as_bytes())
}

fn swatch(colour: &str, class: &str) -> String {
    format!("<span class=\"swatch {class}\" style=\"background:{colour}\"></span>")
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
    let mut counts = [0usize; 3];
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
    let right = W - 24.0;
    let px = |v: f64| L + 8.0 + (right - L - 16.0) * (v - x0) / (x1 - x0);
    let py = |v: f64| H - B - 8.0 - (H - B - T - 16.0) * (v - y0) / (y1 - y0);
    let mut s = format!(
        r##"<svg id="chart" xmlns="http://www.w3.org/2000/svg" viewBox="0 0 {W} {H}" width="{W}" role="img"><rect x="{L}" y="{T}" width="{w}" height="{h}" fill="none" stroke="#ccc"/>"##,
        w = right - L,
        h = H - B - T
    );
    for v in nice_ticks(x0, x1, 6) {
        tick(&mut s, 'x', px(v), &label(v));
    }
    for v in nice_ticks(y0, y1, 6) {
        let _ = write!(
            s,
            r##"<line x1="{L}" y1="{at:.1}" x2="{right}" y2="{at:.1}" stroke="#eee"/>"##,
            at = py(v)
        );
        tick(&mut s, 'y', py(v), &label(v));
    }
    axis_titles(&mut s, right, &columns[x], &columns[o]);
    out.write_all(s.as_bytes())?;
    let mut failed = Ok(());
    rows.for_each_row(&mut |r| {
        let (Some(xv), Some(yv), true) = (r[x].number(), r[o].number(), failed.is_ok()) else {
            return;
        };
        let (cx, cy) = (px(xv), py(yv));
        let i = num(&r[0]);
        let at = format!("{} = {}, {} = {}", columns[x], label(xv), columns[o], label(yv));
        let at = esc(&at);
        let dot = if feasible(columns, r) {
            counts[0] += 1;
            format!(
                r##"<circle class="feasible" cx="{cx:.1}" cy="{cy:.1}" r="4" fill="{BLUE}"><title>variant {i}: {at}</title></circle>"##
            )
        } else if collided(columns, r) {
            counts[1] += 1;
            format!(
                r##"<path class="collision" d="M{a:.1} {b:.1} l8 8 m0 -8 l-8 8" stroke="{RED}" stroke-width="2"><title>variant {i}: collision, {at}</title></path>"##,
                a = cx - 4.0,
                b = cy - 4.0
            )
        } else {
            counts[2] += 1;
            format!(
                r##"<circle class="other" cx="{cx:.1}" cy="{cy:.1}" r="3" fill="#999"><title>variant {i}: {at}</title></circle>"##
            )
        };
        failed = out.write_all(dot.as_bytes());
    })?;
    failed?;
    out.write_all(b"</svg>\n")?;
    legend(
        out,
        &[
            (
                format!(
                    r##"<svg width="14" height="14"><circle cx="7" cy="7" r="4" fill="{BLUE}"/></svg>"##
                ),
                format!("completed without a collision ({})", counts[0]),
            ),
            (
                format!(
                    r##"<svg width="14" height="14"><path d="M3 3 l8 8 m0 -8 l-8 8" stroke="{RED}" stroke-width="2"/></svg>"##
                ),
                format!("collision ({})", counts[1]),
            ),
            (
                r##"<svg width="14" height="14"><circle cx="7" cy="7" r="3" fill="#999"/></svg>"##
                    .to_string(),
                format!(
                    "did not complete: deadlock, error, timeout or stopped at `until` ({})",
                    counts[2]
                ),
            ),
        ],
    )
}

/// Cells of a heatmap at most: more distinct values than this are not charted.
const MAX_CELLS: usize = 250_000;

/// The heatmap's colour of `t` in 0..=1: dark blue (0, the smallest) to light grey (1).
fn colour(t: f64) -> (f64, f64, f64) {
    (40.0 + 200.0 * t, 90.0 + 150.0 * t, 200.0 + 40.0 * t)
}

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
    let right = W - R;
    let cw = (right - L) / xs.len() as f64;
    let ch = (H - B - T) / ys.len() as f64;
    let mut s = format!(
        r##"<svg id="chart" xmlns="http://www.w3.org/2000/svg" viewBox="0 0 {W} {H}" width="{W}" role="img">"##
    );
    let mut counts = [0usize; 4];
    for (b, yv) in ys.iter().enumerate() {
        for (a, xv) in xs.iter().enumerate() {
            let (best, hit, n) = cells[b * xs.len() + a];
            let (fill, what) = match best {
                Some(v) => {
                    counts[0] += 1;
                    let (r, g, bl) = colour((v - lo) / (hi - lo));
                    (
                        format!("rgb({r:.0},{g:.0},{bl:.0})"),
                        format!("{} = {}", columns[o], label(v)),
                    )
                }
                None if hit => {
                    counts[1] += 1;
                    (RED.to_string(), "collision".to_string())
                }
                None if n > 0 => {
                    counts[2] += 1;
                    (GREY.to_string(), "did not complete".to_string())
                }
                None => {
                    counts[3] += 1;
                    ("#ffffff".to_string(), "no variant".to_string())
                }
            };
            let _ = write!(
                s,
                r##"<rect class="cell" x="{rx:.1}" y="{ry:.1}" width="{cw:.1}" height="{ch:.1}" fill="{fill}" stroke="#fff"><title>{xn} = {xv}, {yn} = {yv}: {what}</title></rect>"##,
                rx = L + a as f64 * cw,
                ry = T + (ys.len() - 1 - b) as f64 * ch,
                xn = esc(&columns[x]),
                yn = esc(&columns[y]),
                xv = label(*xv),
                yv = label(*yv),
                what = esc(&what),
            );
        }
    }
    // A tick at each value (every k-th when there are many), centred on its column/row.
    let every = |n: usize, room: f64| (n as f64 / room).ceil().max(1.0) as usize;
    let kx = every(xs.len(), (right - L) / 40.0);
    for (a, v) in xs.iter().enumerate().filter(|(a, _)| a % kx == 0) {
        tick(&mut s, 'x', L + (a as f64 + 0.5) * cw, &label(*v));
    }
    let ky = every(ys.len(), (H - B - T) / 20.0);
    for (b, v) in ys.iter().enumerate().filter(|(b, _)| b % ky == 0) {
        tick(
            &mut s,
            'y',
            T + (ys.len() - 1 - b) as f64 * ch + ch / 2.0,
            &label(*v),
        );
    }
    axis_titles(&mut s, right, &columns[x], &columns[y]);
    colour_bar(&mut s, lo, hi, counts[0] > 0, &columns[o]);
    s.push_str("</svg>\n");
    out.write_all(s.as_bytes())?;
    legend(
        out,
        &[
            (
                r##"<span class="swatch scale" style="background:linear-gradient(90deg, rgb(40,90,200), rgb(240,240,240))"></span>"##.to_string(),
                format!(
                    "the best {} of the variants here that completed without a collision, on the colour bar: darker is smaller (better) ({} cells)",
                    columns[o], counts[0]
                ),
            ),
            (
                swatch(RED, "collision"),
                format!(
                    "none completed without a collision, and one or more collided ({} cells)",
                    counts[1]
                ),
            ),
            (
                swatch(GREY, "incomplete"),
                format!(
                    "none completed: deadlock, error, timeout, stopped at `until`, or invalid ({} cells)",
                    counts[2]
                ),
            ),
            (
                swatch("#ffffff", "empty"),
                format!("no variant ({} cells)", counts[3]),
            ),
        ],
    )
}

/// The heatmap's colour bar, right of the plot: the gradient from `lo` (bottom, dark) to
/// `hi` (top, light), ticks with the objective's values, and its name (with its unit).
fn colour_bar(s: &mut String, lo: f64, hi: f64, any: bool, name: &str) {
    let (x, w) = (W - R + 24.0, 16.0);
    let (top, bottom) = (T, H - B);
    let (r0, g0, b0) = colour(0.0);
    let (r1, g1, b1) = colour(1.0);
    let _ = write!(
        s,
        r##"<g id="colorbar"><defs><linearGradient id="scale" x1="0" y1="1" x2="0" y2="0"><stop offset="0" stop-color="rgb({r0:.0},{g0:.0},{b0:.0})"/><stop offset="1" stop-color="rgb({r1:.0},{g1:.0},{b1:.0})"/></linearGradient></defs><rect x="{x}" y="{top}" width="{w}" height="{h}" fill="url(#scale)" stroke="#999"/>"##,
        h = bottom - top,
    );
    if any {
        let at = |v: f64| bottom - (bottom - top) * (v - lo) / (hi - lo);
        let mut ticks = nice_ticks(lo, hi, 5);
        // The ends too, unless a round tick is about there.
        for end in [lo, hi] {
            if ticks.iter().all(|t| (at(*t) - at(end)).abs() > 12.0) {
                ticks.push(end);
            }
        }
        ticks.sort_by(f64::total_cmp);
        // The ends to a hundredth of the ticks' step (not every digit of 65.656295395).
        let step = nice_ticks(lo, hi, 5)
            .windows(2)
            .map(|w| w[1] - w[0])
            .next()
            .unwrap_or(hi - lo);
        let decimals = (2.0 - step.log10().floor()).clamp(0.0, 12.0) as usize;
        for v in ticks {
            let text = if v == lo || v == hi {
                label(format!("{v:.decimals$}").parse().unwrap_or(v))
            } else {
                label(v)
            };
            let _ = write!(
                s,
                r##"<g class="tick bar-tick"><line x1="{x1:.1}" y1="{y:.1}" x2="{x2:.1}" y2="{y:.1}" stroke="#666"/><text x="{tx:.1}" y="{ty:.1}" font-size="11">{t}</text></g>"##,
                x1 = x + w,
                x2 = x + w + 4.0,
                y = at(v),
                tx = x + w + 7.0,
                ty = at(v) + 4.0,
                t = esc(&text),
            );
        }
    }
    let cy = (top + bottom) / 2.0;
    let tx = W - 14.0;
    let _ = write!(
        s,
        r##"<text class="axis-title" id="colorbar-title" x="{tx}" y="{cy:.1}" font-size="13" transform="rotate(-90 {tx} {cy:.1})" text-anchor="middle">{n}</text></g>"##,
        n = esc(name),
    );
}
