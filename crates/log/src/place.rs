//! Where in the cell and the programs something happened, for people to find it: a
//! collision's bodies and contact ([`Contact`]), the motion statement each robot in a
//! collision or near miss was making ([`RobotMotion`]), the lines the programs logged
//! ([`LogLine`]), and a statement's text as written ([`statement_in`]).
//!
//! Their JSON is derived (serde); serialized into a `serde_json::Value`, whose objects
//! keep their keys sorted, it is byte for byte the form written by hand before.

use std::path::Path;

use serde::{Deserialize, Serialize};
use serde_json::Value as Json;
use vworks_vm::bytecode::SrcPos;

/// `path`'s file name (the whole text if it has none).
pub(crate) fn file_name(path: &str) -> String {
    Path::new(path)
        .file_name()
        .map_or(path.to_string(), |n| n.to_string_lossy().into_owned())
}

/// Two bodies that started touching: what the collider finds and the run reports.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Contact {
    /// When (ns).
    pub time_ns: i64,
    /// First body (`r1.link_4`, `table`, `part1`).
    pub a: String,
    /// Second body.
    pub b: String,
    /// Penetration depth (m).
    #[serde(rename = "depth_m")]
    pub depth: f64,
    /// A contact point in the cell frame (m).
    #[serde(rename = "point_m")]
    pub point: [f64; 3],
    /// Each robot whose body is in the pair and the motion it was making (filled in by
    /// the engine, which knows the programs; the collider leaves it empty).
    pub motions: Vec<RobotMotion>,
}

impl Contact {
    /// As in `run --json`: `time_ns`, `a`, `b`, `depth_m`, `point_m`, `motions`.
    pub fn to_json(&self) -> Json {
        serde_json::to_value(self).unwrap_or(Json::Null)
    }
}

/// A robot whose body (a link, or a part it holds) is in a collision or a near miss, and
/// the motion statement it was making then — or, standing, the last one it made.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct RobotMotion {
    /// The robot's name.
    pub robot: String,
    /// Whether it was moving at that instant (false: standing after `file:line`, or, with
    /// no file, before its first motion).
    pub moving: bool,
    /// The motion statement's program file (`None`: the robot has not moved yet).
    pub file: Option<String>,
    /// Its line (0 if none).
    pub line: u32,
    /// Its column (0 if none).
    pub col: u32,
    /// The statement's text as written (`move_l above speed 250mm/s;`): see
    /// [`statement_in`].
    pub statement: String,
}

impl RobotMotion {
    /// A robot that has not moved yet (no motion to name).
    pub fn not_moved(robot: String) -> RobotMotion {
        RobotMotion {
            robot,
            moving: false,
            file: None,
            line: 0,
            col: 0,
            statement: String::new(),
        }
    }

    /// What the robot was doing, for people: `r1 moving: r1.wsl:7:9 move_l above speed
    /// 250mm/s;`, `r1 standing after: …`, `r1 standing (not moved yet)`.
    pub fn describe(&self) -> String {
        match &self.file {
            None => format!("{} standing (not moved yet)", self.robot),
            Some(f) => format!(
                "{} {}: {}:{}:{} {}",
                self.robot,
                if self.moving {
                    "moving"
                } else {
                    "standing after"
                },
                file_name(f),
                self.line,
                self.col,
                self.statement
            ),
        }
    }

    /// The motion as trace details show it: `r1 at r1.wsl:7:9 "move_l above speed
    /// 250mm/s;"`, `r1 standing after r1.wsl:7:9 "…"`, `r1 not moved yet`.
    fn brief(&self) -> String {
        match &self.file {
            None => format!("{} not moved yet", self.robot),
            Some(f) => format!(
                "{} {} {}:{}:{} {:?}",
                self.robot,
                if self.moving { "at" } else { "standing after" },
                file_name(f),
                self.line,
                self.col,
                self.statement
            ),
        }
    }

    /// As JSON: `robot`, `moving`, `file`, `line`, `col`, `statement`.
    pub fn to_json(&self) -> Json {
        serde_json::to_value(self).unwrap_or(Json::Null)
    }

    /// From the JSON [`RobotMotion::to_json`] writes (`file` may be absent).
    pub fn from_json(v: &Json) -> Option<RobotMotion> {
        RobotMotion::deserialize(v).ok()
    }

    /// Sets `object`'s `motions` to the list, if it is not empty (a JSON object of a
    /// collision or a near miss).
    pub(crate) fn put_list(object: &mut Json, motions: &[RobotMotion]) {
        if !motions.is_empty() {
            object["motions"] = motions.iter().map(RobotMotion::to_json).collect();
        }
    }

    /// The list of a `motions` field (absent, in a log written before they were: empty).
    pub(crate) fn list_from_json(v: Option<&Json>) -> Option<Vec<RobotMotion>> {
        match v {
            None | Some(Json::Null) => Some(Vec::new()),
            Some(v) => v.as_array()?.iter().map(RobotMotion::from_json).collect(),
        }
    }

    /// ` during r1 at r1.wsl:7:9 "…", r2 standing after r2.wsl:3:5 "…"` (empty for no
    /// motions): the end of a collision's or near miss's trace details.
    pub(crate) fn trace_suffix(motions: &[RobotMotion]) -> String {
        if motions.is_empty() {
            return String::new();
        }
        let list: Vec<String> = motions.iter().map(RobotMotion::brief).collect();
        format!(" during {}", list.join(", "))
    }
}

/// A line a program logged (`log "…";`, RAPID's `TPWrite`): what a run prints as it
/// happens and lists in its result.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct LogLine {
    /// When (ns).
    pub time_ns: i64,
    /// The robot whose program logged it.
    pub robot: String,
    /// The text.
    pub text: String,
    /// The `log` statement's program file.
    pub file: Option<String>,
    /// Its line (0 if unknown).
    pub line: u32,
    /// Its column (0 if unknown).
    pub col: u32,
}

impl LogLine {
    /// As JSON: `time_ns`, `robot`, `text`, `file`, `line`, `col`.
    pub fn to_json(&self) -> Json {
        serde_json::to_value(self).unwrap_or(Json::Null)
    }
}

/// The statement at `pos` of a program file whose text is `text`, as written: from its
/// column to its `;`, over as many lines as it takes (each line trimmed, joined by one
/// space), at most [`STATEMENT_LINES`] lines (then it ends with ` …`); the first line alone
/// if the file ends before a `;`.
pub fn statement_in(text: &str, pos: SrcPos) -> String {
    let line_start: usize = text
        .split_inclusive('\n')
        .take((pos.line as usize).saturating_sub(1))
        .map(str::len)
        .sum();
    let line = &text[line_start..];
    let rest = line
        .char_indices()
        .nth((pos.col as usize).saturating_sub(1))
        .map_or("", |(i, _)| &line[i..]);
    let window_end = rest
        .match_indices('\n')
        .nth(STATEMENT_LINES - 1)
        .map_or(rest.len(), |(i, _)| i);
    let window = &rest[..window_end];
    let joined = |s: &str| {
        s.lines()
            .map(str::trim)
            .filter(|l| !l.is_empty())
            .collect::<Vec<_>>()
            .join(" ")
    };
    match window.find(';') {
        Some(end) => joined(&window[..=end]),
        None if window_end < rest.len() => joined(window) + " …",
        None => rest.lines().next().unwrap_or_default().trim().to_string(),
    }
}

/// How many lines [`statement_in`] follows a statement over before it stops.
pub const STATEMENT_LINES: usize = 8;
