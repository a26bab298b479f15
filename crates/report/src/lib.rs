//! The run report: one self-contained HTML file (no network, no external files) made from
//! a run's MCAP log — what `vworks report run.mcap -o report.html` writes.
//!
//! - the cell in 3D at the top, played back from the log's `/tf` and `/scene` (three.js
//!   inlined; see [`viewer`]), under it a timeline (play, speed, slider) that also moves a
//!   cursor over the Gantt chart; clicking the chart or an event row jumps to its time,
//!   and `#t=SECONDS` in the URL opens the report there;
//! - a Gantt chart per robot over simulated time: moving, waiting, idle (the rest), with
//!   collisions (red lines across every row) and signals (ticks on the sender's row)
//!   marked, as an inline SVG;
//! - the cycle time of each robot and its time moving, waiting and idle — the same fold
//!   over the same typed events as `vworks run` ([`vworks_log::stats`]), so the numbers
//!   agree;
//! - the collisions and the warnings and errors;
//! - the event table, filterable by text, robot and kind (a few lines of inline
//!   JavaScript; without it the whole table shows).
//!
//! Everything but the 3D view is derived from the `/events` topic and the log's metadata,
//! so a log thinned with `--log-every` gives the same numbers. `docs/report.md` describes
//! the page.

use std::collections::BTreeMap;
use std::fmt::Write as _;

use vworks_log::mcaplog::{LogContents, LoggedEvent};
use vworks_log::place::RobotMotion;
use vworks_log::stats::{Ending, Fold, RobotStats};
use vworks_log::trace::{Data, Kind, Times, contact_text};

pub use vworks_log::stats::Activity;

pub mod playback;
pub mod viewer;
use viewer::esc;

/// The README's Rust example, compiled by `cargo test --doc` so that it stays true (this
/// crate sits at the end of the run's data flow, so it can see every crate the example
/// uses).
#[cfg(doctest)]
#[doc = include_str!("../../../README.md")]
pub struct ReadmeExamples;

/// Events in the table at most (the rest are counted; `vworks log events` lists them).
pub const TABLE_LIMIT: usize = 20_000;

fn colour(a: Activity) -> &'static str {
    match a {
        Activity::Moving => "#2f6fdf",
        Activity::Waiting => "#f0a030",
    }
}

/// One robot's timeline, derived from its events.
#[derive(Clone, Debug, PartialEq)]
pub struct Timeline {
    /// Time moving, waiting and idle, the cycle time and how the robot ended, exactly as
    /// the run reported them.
    pub stats: RobotStats,
    /// (activity, start ns, end ns), in order of start.
    pub intervals: Vec<(Activity, i64, i64)>,
    /// Signals it sent: (time ns, `receiver.name`).
    pub signals: Vec<(i64, String)>,
}

impl Timeline {
    /// The robot's name.
    pub fn robot(&self) -> &str {
        &self.stats.name
    }

    /// When its program ended (its cycle time), if it did.
    pub fn ended_ns(&self) -> Option<i64> {
        (self.stats.ended == Ending::Ended).then_some(self.stats.end_time_ns)
    }
}

/// A collision in the report.
#[derive(Clone, Debug, PartialEq)]
pub struct Collision {
    /// When it started (ns).
    pub start_ns: i64,
    /// When it ended, if it did (ns).
    pub end_ns: Option<i64>,
    /// The two bodies.
    pub a: String,
    /// The second body.
    pub b: String,
    /// How deep and where (`depth=0.4mm point=(0.5200, 0.1000, 0.4000)`).
    pub details: String,
    /// Each robot whose body is in the pair and the motion it was making.
    pub motions: Vec<RobotMotion>,
}

/// A warning or an error in the report.
#[derive(Clone, Debug, PartialEq)]
pub struct Issue {
    /// When (ns).
    pub time_ns: i64,
    /// [`Kind::Warning`] or [`Kind::Error`].
    pub kind: Kind,
    /// Its robot, if one.
    pub robot: Option<String>,
    /// The message.
    pub message: String,
    /// Where in the robot's program (`r1.wsl:7:9`), if known.
    pub position: Option<String>,
    /// For a near miss: each robot in the pair and the motion it was making.
    pub motions: Vec<RobotMotion>,
}

/// Everything the report shows, derived from a log.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Report {
    /// The cell's name (from the log's metadata; `?` if it has none).
    pub cell: String,
    /// The run's outcome, if the log recorded it (`completed`, `deadlock`, …).
    pub outcome: Option<String>,
    /// The simulated span: the run's end time as recorded, else the last event's time (ns).
    pub end_ns: i64,
    /// Per robot, in the workcell's order (the metadata's), else in order of appearance.
    pub timelines: Vec<Timeline>,
    /// Collisions, in order of start.
    pub collisions: Vec<Collision>,
    /// Warnings and errors, in order.
    pub issues: Vec<Issue>,
}

impl Report {
    /// Derives the report from a log's events and metadata.
    pub fn from_log(log: &LogContents) -> Report {
        let mut order: Vec<String> = log
            .metadata
            .get("robots")
            .map(|r| {
                r.split(',')
                    .filter(|s| !s.is_empty())
                    .map(str::to_string)
                    .collect()
            })
            .unwrap_or_default();
        for e in &log.events {
            if let Some(r) = &e.robot
                && !order.contains(r)
            {
                order.push(r.clone());
            }
        }
        let index: BTreeMap<&str, usize> = order
            .iter()
            .enumerate()
            .map(|(i, r)| (r.as_str(), i))
            .collect();
        let last_event = log.events.iter().map(|e| e.time_ns).max().unwrap_or(0);
        let end_ns = log
            .result
            .get("end_time_ns")
            .and_then(|t| t.parse().ok())
            .unwrap_or(last_event);
        // Each robot's ending as the run recorded it (a log of version 1 has none: the
        // events decide).
        let recorded: BTreeMap<&str, Ending> = log
            .result
            .get("ended")
            .map(|list| {
                list.split(',')
                    .filter_map(|kv| kv.split_once('='))
                    .filter_map(|(r, e)| Some((r, Ending::from_name(e)?)))
                    .collect()
            })
            .unwrap_or_default();
        let mut fold = Fold::new(order.clone(), true);
        let mut signals = vec![Vec::new(); order.len()];
        let mut collisions: Vec<Collision> = Vec::new();
        let mut open_collisions: BTreeMap<(String, String), usize> = BTreeMap::new();
        let mut issues = Vec::new();
        for e in &log.events {
            let r = e.robot.as_deref().and_then(|r| index.get(r)).copied();
            // (Not a zoned motion's `motion_end`: the robot moves on; see `Fold::event`.)
            if !matches!(e.data, Data::MotionEnd { .. }) {
                fold.event(e.time_ns, r, e.kind);
            }
            match (e.kind, r, &e.data) {
                (Kind::Signal, Some(r), _) => signals[r].push((e.time_ns, e.details.clone())),
                (
                    Kind::CollisionStart,
                    _,
                    Data::Collision {
                        a,
                        b,
                        contact,
                        motions,
                    },
                ) => {
                    open_collisions.insert((a.clone(), b.clone()), collisions.len());
                    // Depth and point (the motions have a column of their own).
                    let details = contact
                        .as_ref()
                        .map_or(String::new(), |(depth, point)| contact_text(*depth, point));
                    collisions.push(Collision {
                        start_ns: e.time_ns,
                        end_ns: None,
                        a: a.clone(),
                        b: b.clone(),
                        details,
                        motions: motions.clone(),
                    });
                }
                (Kind::CollisionEnd, _, Data::Collision { a, b, .. }) => {
                    if let Some(i) = open_collisions.remove(&(a.clone(), b.clone())) {
                        collisions[i].end_ns = Some(e.time_ns);
                    }
                }
                (Kind::Warning | Kind::Error, _, data) => {
                    let (message, motions) = match data {
                        Data::Issue {
                            message, motions, ..
                        } => (message.clone(), motions.clone()),
                        _ => (e.details.clone(), Vec::new()),
                    };
                    issues.push(Issue {
                        time_ns: e.time_ns,
                        kind: e.kind,
                        robot: e.robot.clone(),
                        message,
                        position: e.position(),
                        motions,
                    });
                }
                _ => {}
            }
        }
        let (stats, intervals) = fold.finish(end_ns, &|r| {
            order.get(r).and_then(|n| recorded.get(n.as_str())).copied()
        });
        let timelines = stats
            .into_iter()
            .zip(intervals)
            .zip(signals)
            .map(|((stats, intervals), signals)| Timeline {
                stats,
                intervals,
                signals,
            })
            .collect();
        Report {
            cell: log
                .metadata
                .get("cell")
                .cloned()
                .unwrap_or_else(|| "?".into()),
            outcome: log.result.get("outcome").cloned(),
            end_ns,
            timelines,
            collisions,
            issues,
        }
    }
}

/// Why a report could not be written.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum ReportError {
    /// The log cannot be read at all (missing, not MCAP, damaged before anything).
    #[error(transparent)]
    Log(#[from] vworks_log::mcaplog::LogError),
    /// The page cannot be written.
    #[error("{0}")]
    Write(#[from] vworks_model::output::OutputError),
}

/// What [`write_report`] wrote.
#[derive(Clone, Debug)]
pub struct Written {
    /// The report's numbers.
    pub report: Report,
    /// Events read from the log.
    pub events: usize,
    /// Whether the page has the 3D view (the log has poses and shapes).
    pub has_view: bool,
    /// If the log is unfinished or damaged: messages read before the damage, and what it
    /// is (the report shows what was read).
    pub damage: Option<(u64, String)>,
}

/// Reads the log at `log` (with its poses) and writes its report to `out`: what
/// `vworks report` and Python's `write_report` do.
pub fn write_report(log: &std::path::Path, out: &std::path::Path) -> Result<Written, ReportError> {
    let options = vworks_log::mcaplog::ReadOptions { poses: true };
    let contents = vworks_log::mcaplog::read_log_with(log, options)?;
    let (report, html) = page(&contents, &log.display().to_string());
    // Never over the log it reads; through a temporary file, so a failure keeps the old page.
    vworks_model::output::write_output(out, &[log], html.as_bytes())?;
    Ok(Written {
        report,
        events: contents.events.len(),
        has_view: viewer::missing(&contents).is_none(),
        damage: contents.damage,
    })
}

fn secs(ns: i64) -> String {
    format!("{:.3} s", ns as f64 / 1e9)
}

/// A tick step (s) giving about 8–12 ticks over `span` seconds: 1, 2 or 5 × 10^k.
fn tick_step(span: f64) -> f64 {
    let raw = (span / 10.0).max(1e-9);
    let mag = 10f64.powf(raw.log10().floor());
    [1.0, 2.0, 5.0, 10.0]
        .into_iter()
        .map(|m| m * mag)
        .find(|s| *s >= raw)
        .unwrap_or(10.0 * mag)
}

/// The Gantt chart as an SVG element.
fn gantt(report: &Report) -> String {
    const LEFT: f64 = 140.0;
    const WIDTH: f64 = 1000.0;
    const ROW: f64 = 34.0;
    const TOP: f64 = 24.0;
    let span = report.end_ns.max(1) as f64;
    let x = |ns: i64| LEFT + WIDTH * (ns as f64 / span);
    let rows = report.timelines.len().max(1) as f64;
    let height = TOP + rows * ROW + 30.0;
    let mut s = String::new();
    let _ = write!(
        s,
        r#"<svg id="gantt" xmlns="http://www.w3.org/2000/svg" viewBox="0 0 {w} {height}" width="100%" role="img" aria-label="Gantt chart of every robot over simulated time (click: show that time)" data-left="{LEFT}" data-width="{WIDTH}">"#,
        w = LEFT + WIDTH + 20.0
    );
    // Time axis and grid.
    let step = tick_step(span / 1e9);
    let mut t = 0.0;
    while t <= span / 1e9 + 1e-9 {
        let xt = x((t * 1e9) as i64);
        let _ = write!(
            s,
            r##"<line x1="{xt:.1}" y1="{TOP}" x2="{xt:.1}" y2="{y2:.1}" stroke="#ddd"/><text x="{xt:.1}" y="{ty:.1}" font-size="11" text-anchor="middle" fill="#555">{t}</text>"##,
            y2 = TOP + rows * ROW,
            ty = TOP + rows * ROW + 16.0,
            t = format_tick(t, step)
        );
        t += step;
    }
    let _ = write!(
        s,
        r##"<text x="{xl:.1}" y="{ty:.1}" font-size="11" fill="#555">s</text>"##,
        xl = LEFT + WIDTH + 6.0,
        ty = TOP + rows * ROW + 16.0
    );
    for (i, tl) in report.timelines.iter().enumerate() {
        let y = TOP + i as f64 * ROW;
        let _ = write!(
            s,
            r##"<g class="row" data-robot="{name}"><text x="{tx}" y="{ty:.1}" font-size="13" text-anchor="end" fill="#222">{name}</text><rect class="idle" x="{LEFT}" y="{yb:.1}" width="{wi:.1}" height="22" fill="#e8e8e8"><title>{name}: idle</title></rect>"##,
            name = esc(tl.robot()),
            tx = LEFT - 8.0,
            ty = y + 20.0,
            yb = y + 4.0,
            wi = x(tl.ended_ns().unwrap_or(report.end_ns)) - LEFT,
        );
        for (activity, start, end) in &tl.intervals {
            let _ = write!(
                s,
                r#"<rect class="{cls}" x="{x0:.2}" y="{yb:.1}" width="{w:.2}" height="22" fill="{fill}"><title>{name}: {what} {a} – {b}</title></rect>"#,
                cls = activity.name(),
                x0 = x(*start),
                yb = y + 4.0,
                w = (x(*end) - x(*start)).max(0.5),
                fill = colour(*activity),
                name = esc(tl.robot()),
                what = activity.name(),
                a = secs(*start),
                b = secs(*end),
            );
        }
        for (t, to) in &tl.signals {
            let xs = x(*t);
            let _ = write!(
                s,
                r##"<path class="signal" d="M{xs:.1} {y0:.1} l-4 -6 h8 z" fill="#1a9e55"><title>{name} signals {to} at {at}</title></path>"##,
                y0 = y + 4.0,
                name = esc(tl.robot()),
                to = esc(to),
                at = secs(*t),
            );
        }
        if let Some(end) = tl.ended_ns() {
            let _ = write!(
                s,
                r##"<line class="end" x1="{xe:.1}" y1="{y0:.1}" x2="{xe:.1}" y2="{y1:.1}" stroke="#222" stroke-width="2"><title>{name} ends at {at}</title></line>"##,
                xe = x(end),
                y0 = y + 2.0,
                y1 = y + 28.0,
                name = esc(tl.robot()),
                at = secs(end),
            );
        }
        s.push_str("</g>");
    }
    for c in &report.collisions {
        let xc = x(c.start_ns);
        let _ = write!(
            s,
            r##"<line class="collision" x1="{xc:.1}" y1="{TOP}" x2="{xc:.1}" y2="{y1:.1}" stroke="#d62728" stroke-width="2"><title>collision at {at}: {d}</title></line>"##,
            y1 = TOP + rows * ROW,
            at = secs(c.start_ns),
            d = esc(&if c.details.is_empty() {
                format!("{} {}", c.a, c.b)
            } else {
                c.details.clone()
            }),
        );
    }
    // The timeline's cursor (moved by the page's script).
    let _ = write!(
        s,
        r##"<line id="gantt-cursor" x1="{LEFT}" y1="{y0}" x2="{LEFT}" y2="{y1:.1}" stroke="#111" stroke-width="1.5" stroke-dasharray="4 3" pointer-events="none"/>"##,
        y0 = TOP - 6.0,
        y1 = TOP + rows * ROW + 4.0,
    );
    s.push_str("</svg>");
    s
}

fn format_tick(t: f64, step: f64) -> String {
    if step >= 1.0 {
        format!("{t:.0}")
    } else {
        let digits = (-step.log10()).ceil() as usize;
        format!("{t:.digits$}")
    }
}

/// A titled table (`id`) of `rows` (each its time in ns, which a click shows, and its
/// cells, already escaped) under `columns` (name, whether numeric), or the `none` line
/// when there are no rows.
/// The motions of a collision or near miss as one table cell: one line per robot, `r1
/// moving: r1.wsl:7:9 move_l above speed 250mm/s;` (escaped).
fn motions_cell(motions: &[RobotMotion]) -> String {
    if motions.is_empty() {
        return "–".into();
    }
    motions
        .iter()
        .map(|m| esc(&m.describe()))
        .collect::<Vec<_>>()
        .join("<br>")
}

fn list(
    s: &mut String,
    (title, id, none): (&str, &str, &str),
    columns: &[(&str, bool)],
    rows: impl Iterator<Item = (i64, Vec<String>)>,
) {
    let _ = writeln!(s, "<h2>{title}</h2>");
    let num = |numeric: bool| if numeric { " class=\"num\"" } else { "" };
    let mut rows = rows.peekable();
    if rows.peek().is_none() {
        let _ = writeln!(s, "<p class=\"none\" id=\"{id}\">{none}</p>");
        return;
    }
    let _ = write!(s, "<table id=\"{id}\"><tr>");
    for (name, numeric) in columns {
        let _ = write!(s, "<th{}>{name}</th>", num(*numeric));
    }
    s.push_str("</tr>\n");
    for (t, row) in rows {
        let _ = write!(s, "<tr data-t=\"{t}\">");
        for (cell, (_, numeric)) in row.iter().zip(columns) {
            let _ = write!(s, "<td{}>{cell}</td>", num(*numeric));
        }
        s.push_str("</tr>\n");
    }
    s.push_str("</table>\n");
}

/// The report of a log read with `ReadOptions { poses: true }`, as one HTML document,
/// with the 3D view (or the note saying why there is none). `source` names the log.
pub fn page(log: &LogContents, source: &str) -> (Report, String) {
    let report = Report::from_log(log);
    let page = render(&report, &log.events, source, Some(log));
    (report, page)
}

/// The report as one HTML document, without the 3D view (a report of events alone).
/// `source` names the log in the heading.
pub fn html(report: &Report, events: &[LoggedEvent], source: &str) -> String {
    render(report, events, source, None)
}

fn render(
    report: &Report,
    events: &[LoggedEvent],
    source: &str,
    log: Option<&LogContents>,
) -> String {
    let mut s = String::new();
    let title = format!("vworks report: {}", report.cell);
    let _ = write!(
        s,
        r#"<!DOCTYPE html>
<html lang="en"><head><meta charset="utf-8"><meta name="viewport" content="width=device-width, initial-scale=1">
<title>{t}</title>
<style>
body {{ font: 14px/1.4 system-ui, -apple-system, "Segoe UI", sans-serif; margin: 24px; color: #222; }}
h1 {{ font-size: 22px; margin: 0 0 4px; }} h2 {{ font-size: 17px; margin: 28px 0 8px; }}
.sub {{ color: #666; margin-bottom: 16px; }}
table {{ border-collapse: collapse; }} th, td {{ padding: 3px 10px; border-bottom: 1px solid #eee; text-align: left; }}
th {{ background: #f6f6f6; position: sticky; top: 0; }} td.num, th.num {{ text-align: right; font-variant-numeric: tabular-nums; }}
.legend span {{ display: inline-block; margin-right: 16px; }} .legend i {{ display: inline-block; width: 14px; height: 10px; margin-right: 5px; vertical-align: middle; }}
#filters input, #filters select {{ margin-right: 8px; padding: 3px 6px; }}
#events {{ font-family: ui-monospace, monospace; font-size: 12px; }} .none {{ color: #888; }}
.damage {{ color: #a33; }}{view_style}
</style></head><body>
<h1>{t}</h1>
<div class="sub">{src} · {outcome}simulated span {span} · {n} events</div>
"#,
        view_style = if log.is_some() { viewer::STYLE } else { "" },
        t = esc(&title),
        src = esc(source),
        span = secs(report.end_ns),
        outcome = report
            .outcome
            .as_ref()
            .map_or(String::new(), |o| format!("{} · ", esc(o))),
        n = events.len()
    );
    if let Some((read, why)) = log.and_then(|l| l.damage.as_ref()) {
        let _ = writeln!(
            s,
            "<p class=\"damage\">The log is unfinished or damaged after {read} messages ({}): this report shows what was read.</p>",
            esc(why)
        );
    }
    if let Some(log) = log {
        s.push_str(&viewer::section(log, report.end_ns));
    }
    // Cycle times.
    s.push_str("<h2>Cycle time per robot</h2>\n<table id=\"cycle-times\"><tr><th>robot</th><th class=\"num\">cycle time</th><th class=\"num\">moving</th><th class=\"num\">waiting</th><th class=\"num\">idle</th><th class=\"num\">motions</th></tr>\n");
    for tl in &report.timelines {
        let st = &tl.stats;
        let _ = writeln!(
            s,
            "<tr><td>{}</td><td class=\"num\">{}</td><td class=\"num\">{}</td><td class=\"num\">{}</td><td class=\"num\">{}</td><td class=\"num\">{}</td></tr>",
            esc(&st.name),
            match st.ended {
                Ending::Ended => secs(st.end_time_ns),
                other => format!("did not end: {} ({})", other.name(), secs(st.end_time_ns)),
            },
            secs(st.moving_ns),
            secs(st.waiting_ns),
            secs(st.idle_ns),
            st.motions
        );
    }
    s.push_str("</table>\n");
    // Gantt.
    s.push_str("<h2>Timeline</h2>\n<div class=\"legend\">");
    for a in [Activity::Moving, Activity::Waiting] {
        let _ = write!(
            s,
            "<span><i style=\"background:{}\"></i>{}</span>",
            colour(a),
            a.name()
        );
    }
    s.push_str("<span><i style=\"background:#e8e8e8\"></i>idle</span><span><i style=\"background:#d62728\"></i>collision</span><span><i style=\"background:#1a9e55\"></i>signal sent</span><span><i style=\"background:#222\"></i>program end</span></div>\n");
    s.push_str(&gantt(report));
    s.push('\n');
    // Collisions and issues.
    let collisions = report.collisions.iter().map(|c| {
        (
            c.start_ns,
            vec![
                secs(c.start_ns),
                c.end_ns.map_or("–".into(), secs),
                esc(&format!("{} {}", c.a, c.b)),
                motions_cell(&c.motions),
                esc(&c.details),
            ],
        )
    });
    list(
        &mut s,
        ("Collisions", "collisions", "No collision."),
        &[
            ("start", true),
            ("end", true),
            ("bodies", false),
            ("motions", false),
            ("details", false),
        ],
        collisions,
    );
    let issues = report.issues.iter().map(|i| {
        let mut message = esc(&i.message);
        if !i.motions.is_empty() {
            message.push_str("<br>");
            message.push_str(&motions_cell(&i.motions));
        } else if let Some(p) = &i.position {
            let _ = write!(message, " <span class=\"src\">({})</span>", esc(p));
        }
        (
            i.time_ns,
            vec![
                secs(i.time_ns),
                esc(i.kind.name()),
                esc(i.robot.as_deref().unwrap_or("–")),
                message,
            ],
        )
    });
    list(
        &mut s,
        ("Warnings and errors", "issues", "None."),
        &[
            ("time", true),
            ("kind", false),
            ("robot", false),
            ("message", false),
        ],
        issues,
    );
    // Events.
    let robots: Vec<&str> = report.timelines.iter().map(|t| t.robot()).collect();
    let mut kinds: Vec<&str> = events.iter().map(|e| e.kind.name()).collect();
    kinds.sort_unstable();
    kinds.dedup();
    s.push_str("<h2>Events</h2>\n<div id=\"filters\"><input id=\"text\" type=\"search\" placeholder=\"filter: any text\" aria-label=\"filter events by text\">");
    s.push_str("<select id=\"robot\" aria-label=\"robot\"><option value=\"\">every robot</option>");
    for r in &robots {
        let _ = write!(s, "<option>{}</option>", esc(r));
    }
    s.push_str("<option value=\"-\">(cell)</option></select><select id=\"kind\" aria-label=\"kind\"><option value=\"\">every kind</option>");
    for k in &kinds {
        let _ = write!(s, "<option>{}</option>", esc(k));
    }
    let shown = events.len().min(TABLE_LIMIT);
    let _ = writeln!(
        s,
        "</select><span id=\"count\">{shown} of {} events</span></div>",
        events.len()
    );
    s.push_str("<table id=\"events\"><thead><tr><th class=\"num\">time (s)</th><th>robot</th><th>kind</th><th>details</th><th>source</th></tr></thead><tbody>\n");
    for e in &events[..shown] {
        let pos = e.position().unwrap_or_default();
        let robot = e.robot.as_deref().unwrap_or("-");
        let _ = writeln!(
            s,
            "<tr data-robot=\"{r}\" data-kind=\"{k}\" data-t=\"{ns}\"><td class=\"num\">{t:.6}</td><td>{r}</td><td>{k}</td><td>{d}</td><td>{p}</td></tr>",
            r = esc(robot),
            k = e.kind.name(),
            ns = e.time_ns,
            t = e.time_ns as f64 / 1e9,
            // Durations and deadlines in seconds, as the time column (not nanoseconds).
            d = esc(&e.details_as(Times::Seconds)),
            p = esc(&pos)
        );
    }
    s.push_str("</tbody></table>\n");
    if events.len() > shown {
        let _ = writeln!(
            s,
            "<p class=\"none\">The first {shown} of {} events; `vworks log events` lists them all.</p>",
            events.len()
        );
    }
    s.push_str(
        r##"<script>
(function () {
  var text = document.getElementById("text"), robot = document.getElementById("robot"),
      kind = document.getElementById("kind"), count = document.getElementById("count");
  var rows = Array.prototype.slice.call(document.querySelectorAll("#events tbody tr"));
  function apply() {
    var t = text.value.toLowerCase(), r = robot.value, k = kind.value, n = 0;
    rows.forEach(function (row) {
      var show = (!r || row.dataset.robot === r) && (!k || row.dataset.kind === k) &&
                 (!t || row.textContent.toLowerCase().indexOf(t) >= 0);
      row.style.display = show ? "" : "none";
      if (show) n++;
    });
    count.textContent = n + " of " + rows.length + " events shown";
  }
  [text, robot, kind].forEach(function (el) { el.addEventListener("input", apply); });
  apply();
})();
</script>
"##,
    );
    if log.is_some() {
        s.push_str(&viewer::script());
    }
    s.push_str("</body></html>\n");
    s
}

#[cfg(test)]
mod tests {
    use super::*;
    use vworks_log::issue::IssueKind;

    fn ev(t: i64, robot: Option<&str>, kind: Kind, data: Data) -> LoggedEvent {
        LoggedEvent {
            time_ns: t,
            robot: robot.map(str::to_string),
            kind,
            details: String::new(),
            data,
            file: None,
            line: 0,
            col: 0,
        }
    }

    /// A collision row names each robot's motion (statement and place), a near miss's row
    /// too, and the event table writes durations in seconds like its time column.
    #[test]
    fn collision_rows_name_the_motions_and_events_show_seconds() {
        let motion = |robot: &str, moving: bool| RobotMotion {
            robot: robot.into(),
            moving,
            file: Some(format!("/cell/{robot}.wsl")),
            line: 3,
            col: 5,
            statement: "move_l p1 speed 1m/s;".into(),
        };
        let motions = vec![motion("r1", true), motion("r2", false)];
        let mut start = ev(
            1_500_000_000,
            None,
            Kind::CollisionStart,
            Data::Collision {
                a: "r1.link_6".into(),
                b: "r2.link_6".into(),
                contact: Some((0.0004, [0.5, 0.0, 0.25])),
                motions: motions.clone(),
            },
        );
        start.details = start.data.text();
        let mut near = ev(
            1_400_000_000,
            None,
            Kind::Warning,
            Data::Issue {
                kind: IssueKind::NearMiss,
                message: "near miss: r1.link_6 and r2.link_6 come within 2.00 mm".into(),
                distance_m: Some(0.002),
                motions: motions.clone(),
            },
        );
        near.details = near.data.text();
        let mut moving = ev(
            0,
            Some("r1"),
            Kind::MotionStart,
            Data::Motion {
                command: "move_l".into(),
                duration_ns: 1_300_000_000,
                zone_m: None,
                blend_m: None,
            },
        );
        moving.details = moving.data.text();
        let log = LogContents {
            events: vec![moving, near, start],
            ..LogContents::default()
        };
        let r = Report::from_log(&log);
        assert_eq!(r.collisions[0].motions, motions);
        assert_eq!(
            r.collisions[0].details,
            "depth=0.4mm point=(0.5000, 0.0000, 0.2500)"
        );
        assert_eq!(r.issues[0].motions, motions);
        let page = html(&r, &log.events, "t.mcap");
        let moving_row = "r1 moving: r1.wsl:3:5 move_l p1 speed 1m/s;";
        let standing_row = "r2 standing after: r2.wsl:3:5 move_l p1 speed 1m/s;";
        let collisions = &page[page.find("id=\"collisions\"").unwrap()..];
        assert!(collisions.contains(&format!("{moving_row}<br>{standing_row}")));
        let issues = &page[page.find("id=\"issues\"").unwrap()..];
        assert!(issues.contains(&format!("2.00 mm<br>{moving_row}")));
        assert!(page.contains("<td>move_l duration=1.3 s</td>"), "{page}");
        assert!(!page.contains("1300000000"));
    }

    /// Times by hand from docs/engine.md: a moves 0–5, waits 5–8, fires a handler at 9
    /// (no time) and ends at 10; b sends a signal at 7 and waits from 7 to the end at 12;
    /// idle is the rest of the 12 ns run.
    #[test]
    fn intervals_and_totals_come_from_the_shared_fold() {
        let pair = |contact| Data::Collision {
            a: "a.link_1".into(),
            b: "b.link_2".into(),
            contact,
            motions: Vec::new(),
        };
        let mut signal = ev(7, Some("b"), Kind::Signal, Data::None);
        signal.details = "a.go".into();
        let log = LogContents {
            events: vec![
                ev(0, Some("a"), Kind::MotionStart, Data::None),
                ev(5, Some("a"), Kind::MotionEnd, Data::None),
                ev(5, Some("a"), Kind::WaitUntil, Data::None),
                signal,
                ev(7, Some("b"), Kind::WaitUntil, Data::None),
                ev(8, Some("a"), Kind::WaitEnd, Data::None),
                ev(8, None, Kind::CollisionStart, pair(Some((0.0, [0.0; 3])))),
                ev(9, None, Kind::CollisionEnd, pair(None)),
                ev(9, Some("a"), Kind::WhenFire, Data::None),
                ev(9, Some("a"), Kind::WhenEnd, Data::None),
                ev(10, Some("a"), Kind::End, Data::None),
                ev(
                    12,
                    None,
                    Kind::Warning,
                    Data::Issue {
                        kind: IssueKind::NearMiss,
                        message: "near miss: x and y come within 1mm".into(),
                        distance_m: Some(1e-3),
                        motions: Vec::new(),
                    },
                ),
            ],
            ..LogContents::default()
        };
        let r = Report::from_log(&log);
        assert_eq!(r.end_ns, 12);
        let a = &r.timelines[0];
        assert_eq!(
            a.intervals,
            vec![(Activity::Moving, 0, 5), (Activity::Waiting, 5, 8)]
        );
        assert_eq!((a.ended_ns(), a.stats.motions), (Some(10), 1));
        assert_eq!(
            (a.stats.moving_ns, a.stats.waiting_ns, a.stats.idle_ns),
            (5, 3, 4)
        );
        let b = &r.timelines[1];
        assert_eq!(b.signals, vec![(7, "a.go".to_string())]);
        assert_eq!((b.stats.waiting_ns, b.stats.idle_ns), (5, 7));
        assert_eq!((b.stats.ended, b.stats.end_time_ns), (Ending::Waiting, 12));
        assert_eq!(
            r.collisions[0].start_ns..r.collisions[0].end_ns.unwrap(),
            8..9
        );
        assert_eq!(r.issues[0].message, "near miss: x and y come within 1mm");
        let page = html(&r, &log.events, "x.mcap");
        assert!(page.contains("<svg id=\"gantt\""));
        assert!(page.contains("class=\"collision\""));
        assert!(!page.contains("handler"));
        // Self-contained: nothing loaded from elsewhere.
        assert!(!page.contains(" src=") && !page.contains("<link"));
    }

    /// The run's own end time and endings, when the log records them, win over what the
    /// events alone suggest.
    #[test]
    fn the_recorded_result_sets_the_span_and_endings() {
        let log = LogContents {
            events: vec![ev(0, Some("a"), Kind::WaitUntil, Data::None)],
            result: BTreeMap::from([
                ("end_time_ns".to_string(), "20".to_string()),
                ("ended".to_string(), "a=running".to_string()),
                ("outcome".to_string(), "until".to_string()),
            ]),
            ..LogContents::default()
        };
        let r = Report::from_log(&log);
        assert_eq!((r.end_ns, r.outcome.as_deref()), (20, Some("until")));
        let a = &r.timelines[0].stats;
        assert_eq!((a.waiting_ns, a.ended), (20, Ending::Running));
    }

    #[test]
    fn text_is_escaped() {
        assert_eq!(
            esc("<a href=\"x\">&'"),
            "&lt;a href=&quot;x&quot;&gt;&amp;&#39;"
        );
    }

    #[test]
    fn ticks_are_round_numbers() {
        assert_eq!(tick_step(63.4), 10.0);
        assert_eq!(tick_step(17.8), 2.0);
        assert_eq!(tick_step(0.4), 0.05);
        assert_eq!(format_tick(0.15, 0.05), "0.15");
    }
}
