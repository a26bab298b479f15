//! Where in the programs something happened, for people to find it: the motion statement
//! each robot in a collision or near miss was making ([`RobotMotion`]), the lines the
//! programs logged ([`LogLine`]), and a statement's text as written ([`statement_at`]).

use std::path::Path;

use serde_json::{Value as Json, json};
use vworks_cell::Cell;
use vworks_vm::bytecode::SrcPos;

/// `path`'s file name (the whole text if it has none).
pub(crate) fn file_name(path: &str) -> String {
    Path::new(path)
        .file_name()
        .map_or(path.to_string(), |n| n.to_string_lossy().into_owned())
}

/// A robot whose body (a link, or a part it holds) is in a collision or a near miss, and
/// the motion statement it was making then — or, standing, the last one it made.
#[derive(Clone, Debug, PartialEq)]
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
    /// [`statement_at`].
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
        json!({"robot": self.robot, "moving": self.moving, "file": self.file,
               "line": self.line, "col": self.col, "statement": self.statement})
    }

    /// From the JSON [`RobotMotion::to_json`] writes.
    pub fn from_json(v: &Json) -> Option<RobotMotion> {
        let file = match v.get("file") {
            None | Some(Json::Null) => None,
            Some(f) => Some(f.as_str()?.to_string()),
        };
        Some(RobotMotion {
            robot: v.get("robot")?.as_str()?.to_string(),
            moving: v.get("moving")?.as_bool()?,
            file,
            line: u32::try_from(v.get("line")?.as_u64()?).ok()?,
            col: u32::try_from(v.get("col")?.as_u64()?).ok()?,
            statement: v.get("statement")?.as_str()?.to_string(),
        })
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
#[derive(Clone, Debug, PartialEq)]
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
        json!({"time_ns": self.time_ns, "robot": self.robot, "text": self.text,
               "file": self.file, "line": self.line, "col": self.col})
    }
}

/// The statement at `pos` of robot `r`'s program as written: from its column to its `;`,
/// over as many lines as it takes (each line trimmed, joined by one space), at most
/// [`STATEMENT_LINES`] lines (then it ends with ` …`); the first line alone if the file
/// ends before a `;`. Empty if the source is not in the cell.
pub fn statement_at(cell: &Cell, r: usize, pos: SrcPos) -> String {
    let Some(robot) = cell.robots.get(r) else {
        return String::new();
    };
    let file = robot.module.file_of(pos);
    let Some((_, text)) = cell.sources.iter().find(|(p, _)| p == file) else {
        return String::new();
    };
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

/// How many lines [`statement_at`] follows a statement over before it stops.
pub const STATEMENT_LINES: usize = 8;
