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

use std::fmt::Write as _;

use crate::table::{Table, Value};

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

/// The page. `title` names the sweep; `variables` are the variable columns; `objective` a
/// numeric column; `feasible` per row; `best` indices into the rows.
pub fn page(
    title: &str,
    table: &Table,
    variables: &[String],
    objective: &str,
    feasible: &[bool],
    best: &[usize],
) -> String {
    let mut s = String::new();
    let _ = write!(
        s,
        r#"<!DOCTYPE html>
<html lang="en"><head><meta charset="utf-8"><title>vworks sweep: {t}</title>
<style>
body {{ font: 14px/1.4 system-ui, sans-serif; margin: 24px; color: #222; }}
table {{ border-collapse: collapse; }} th, td {{ padding: 2px 8px; border-bottom: 1px solid #eee; text-align: right; font-variant-numeric: tabular-nums; }}
th {{ background: #f6f6f6; }} .none {{ color: #888; }}
</style></head><body>
<h1>vworks sweep: {t}</h1>
<p>{n} variants · objective: {o} (smaller is better) · {f} completed without collision</p>
"#,
        t = esc(title),
        n = table.rows.len(),
        o = esc(objective),
        f = feasible.iter().filter(|f| **f).count()
    );
    let obj = table.column(objective);
    let numeric: Vec<usize> = variables
        .iter()
        .filter_map(|v| table.column(v))
        .filter(|k| table.rows.iter().all(|r| r[*k].number().is_some()))
        .collect();
    if let Some(o) = obj {
        match numeric.as_slice() {
            [x] => s.push_str(&scatter(table, *x, o, feasible)),
            [x, y, ..] => s.push_str(&heatmap(table, *x, *y, o, feasible)),
            [] => s.push_str("<p class=\"none\">No numeric variable to chart.</p>\n"),
        }
    }
    s.push_str("<h2>Best variants</h2>\n");
    if best.is_empty() {
        s.push_str("<p class=\"none\" id=\"best\">No variant completed without a collision.</p>\n");
    } else {
        rows(&mut s, "best", table, best.iter().copied());
    }
    s.push_str("<h2>Every variant</h2>\n");
    rows(&mut s, "all", table, 0..table.rows.len());
    s.push_str("</body></html>\n");
    s
}

fn rows(s: &mut String, id: &str, table: &Table, which: impl Iterator<Item = usize>) {
    let _ = write!(s, "<table id=\"{id}\"><tr>");
    for c in &table.columns {
        let _ = write!(s, "<th>{}</th>", esc(c));
    }
    s.push_str("</tr>\n");
    for i in which {
        s.push_str("<tr>");
        for v in &table.rows[i] {
            let _ = write!(s, "<td>{}</td>", num(v));
        }
        s.push_str("</tr>\n");
    }
    s.push_str("</table>\n");
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

fn scatter(table: &Table, x: usize, o: usize, feasible: &[bool]) -> String {
    let pts: Vec<(f64, Option<f64>, usize)> = table
        .rows
        .iter()
        .enumerate()
        .filter_map(|(i, r)| Some((r[x].number()?, r[o].number(), i)))
        .collect();
    let (x0, x1) = span(pts.iter().map(|p| p.0));
    let (y0, y1) = span(pts.iter().filter_map(|p| p.1));
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
    axis_titles(&mut s, &table.columns[x], &table.columns[o]);
    let collided = table.column("collisions");
    for (xv, yv, i) in pts {
        let Some(yv) = yv else { continue };
        let (cx, cy) = (px(xv), py(yv));
        let hit = collided.is_some_and(|c| table.rows[i][c].number().unwrap_or(0.0) > 0.0);
        if feasible.get(i).copied().unwrap_or(false) {
            let _ = write!(
                s,
                r##"<circle class="feasible" cx="{cx:.1}" cy="{cy:.1}" r="4" fill="#2f6fdf"><title>variant {i}</title></circle>"##
            );
        } else if hit {
            let _ = write!(
                s,
                r##"<path class="collision" d="M{a:.1} {b:.1} l8 8 m0 -8 l-8 8" stroke="#d62728" stroke-width="2"><title>variant {i}: collision</title></path>"##,
                a = cx - 4.0,
                b = cy - 4.0
            );
        } else {
            let _ = write!(
                s,
                r##"<circle class="other" cx="{cx:.1}" cy="{cy:.1}" r="3" fill="#999"><title>variant {i}</title></circle>"##
            );
        }
    }
    s.push_str("</svg>\n");
    s
}

fn heatmap(table: &Table, x: usize, y: usize, o: usize, feasible: &[bool]) -> String {
    let distinct = |k: usize| {
        let mut v: Vec<f64> = table.rows.iter().filter_map(|r| r[k].number()).collect();
        v.sort_by(f64::total_cmp);
        v.dedup();
        v
    };
    let (xs, ys) = (distinct(x), distinct(y));
    // Per cell: the best feasible objective, whether any variant collided, how many ran.
    let mut cells = vec![(None::<f64>, false, 0usize); xs.len() * ys.len()];
    let collided = table.column("collisions");
    for (i, r) in table.rows.iter().enumerate() {
        let (Some(xv), Some(yv)) = (r[x].number(), r[y].number()) else {
            continue;
        };
        let (Some(a), Some(b)) = (
            xs.iter().position(|v| *v == xv),
            ys.iter().position(|v| *v == yv),
        ) else {
            continue;
        };
        let c = &mut cells[b * xs.len() + a];
        c.2 += 1;
        if collided.is_some_and(|k| r[k].number().unwrap_or(0.0) > 0.0) {
            c.1 = true;
        }
        if feasible.get(i).copied().unwrap_or(false)
            && let Some(v) = r[o].number()
        {
            c.0 = Some(c.0.map_or(v, |m: f64| m.min(v)));
        }
    }
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
                xn = esc(&table.columns[x]),
                yn = esc(&table.columns[y]),
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
    axis_titles(
        &mut s,
        &range(&table.columns[x], &xs),
        &range(&table.columns[y], &ys),
    );
    s.push_str("</svg>\n");
    s
}
