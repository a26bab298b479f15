//! The run's warnings and errors ([`Issue`]) and what kind each is ([`IssueKind`]): the
//! engine's own (`race`, `near_miss`, `runtime`, `deadlock`), the VM's motion warnings
//! (`slowdown`, `duration`, `stop-point`, `corner`) and the programs' compile and link warnings (their
//! code, `W0001`). Consumers match the enum; the name is only what JSON, trace lines and
//! Python show.

use serde::{Deserialize, Deserializer, Serialize, Serializer};
use serde_json::{Value as Json, json};
use vworks_vm::machine::WarningKind;

use crate::place::RobotMotion;

/// What kind of warning or error an [`Issue`] is.
#[derive(Clone, Debug, PartialEq, Eq, Hash)]
#[non_exhaustive]
pub enum IssueKind {
    /// Two robots touch a global, a signal or a remote request at one instant in an order
    /// no rule fixes (`race`).
    Race,
    /// Two bodies came within the cell's clearance (`near_miss`).
    NearMiss,
    /// A motion slowed to keep an axis within its speed (`slowdown`).
    Slowdown,
    /// A motion takes longer than the time it was asked to take (`duration`).
    Duration,
    /// A zoned point the robot must reach before the next statement (`stop-point`).
    StopPoint,
    /// A motion that cannot start inside the previous zone (`corner`).
    Corner,
    /// A runtime error, `fail`, a livelock or the event limit (`runtime`).
    Runtime,
    /// Every unfinished robot waits and nothing is pending (`deadlock`).
    Deadlock,
    /// A compile or link warning of the programs: its code (`W0001`).
    Compiler(String),
}

impl IssueKind {
    /// Every kind but [`IssueKind::Compiler`], with its name: the one table of names.
    const NAMED: [(IssueKind, &'static str); 8] = [
        (IssueKind::Race, "race"),
        (IssueKind::NearMiss, "near_miss"),
        (IssueKind::Slowdown, "slowdown"),
        (IssueKind::Duration, "duration"),
        (IssueKind::StopPoint, "stop-point"),
        (IssueKind::Corner, "corner"),
        (IssueKind::Runtime, "runtime"),
        (IssueKind::Deadlock, "deadlock"),
    ];

    /// The kind's name in JSON, logs, trace lines and Python (`race`, `near_miss`, …, or
    /// the compiler's code).
    pub fn name(&self) -> &str {
        match self {
            IssueKind::Compiler(code) => code,
            named => Self::NAMED
                .iter()
                .find(|(k, _)| k == named)
                .map_or("", |(_, n)| n),
        }
    }

    /// The kind named `name` ([`IssueKind::name`]): a named kind, or a compiler code (a
    /// capital letter and four digits); `None` for anything else.
    pub fn from_name(name: &str) -> Option<IssueKind> {
        if let Some((k, _)) = Self::NAMED.iter().find(|(_, n)| *n == name) {
            return Some(k.clone());
        }
        let b = name.as_bytes();
        let is_code =
            b.len() == 5 && b[0].is_ascii_uppercase() && b[1..].iter().all(u8::is_ascii_digit);
        is_code.then(|| IssueKind::Compiler(name.to_string()))
    }
}

impl From<WarningKind> for IssueKind {
    fn from(kind: WarningKind) -> IssueKind {
        match kind {
            WarningKind::Slowdown => IssueKind::Slowdown,
            WarningKind::Duration => IssueKind::Duration,
            WarningKind::StopPoint => IssueKind::StopPoint,
            WarningKind::Corner => IssueKind::Corner,
        }
    }
}

impl std::fmt::Display for IssueKind {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

impl Serialize for IssueKind {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        s.serialize_str(self.name())
    }
}

impl<'de> Deserialize<'de> for IssueKind {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<IssueKind, D::Error> {
        let name = <std::borrow::Cow<'de, str>>::deserialize(d)?;
        IssueKind::from_name(&name)
            .ok_or_else(|| serde::de::Error::custom(format!("unknown issue kind `{name}`")))
    }
}

/// A warning or error of the run.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Issue {
    /// What kind it is.
    pub kind: IssueKind,
    /// The message.
    pub message: String,
    /// The robot, if one.
    pub robot: Option<String>,
    /// Source position, if known.
    pub file: Option<String>,
    /// Line (0 if unknown).
    pub line: u32,
    /// Column (0 if unknown).
    pub col: u32,
    /// For a near miss, how close the bodies came (m), exactly; the message rounds it.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub distance_m: Option<f64>,
    /// For a near miss, each robot whose body is in the pair and the motion it was
    /// making (the first moving one's, else the first one's, is also `robot`, `file`,
    /// `line`, `col`).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub motions: Vec<RobotMotion>,
}

impl Issue {
    /// As JSON: `kind`, `message`, `robot`, `file`, `line`, `col`, and for a near miss
    /// `distance_m` and `motions` (each robot in the pair and its motion).
    pub fn to_json(&self) -> Json {
        serde_json::to_value(self).unwrap_or(Json::Null)
    }
}

/// An issue as JSON from its parts (load and compile errors use it too).
pub fn issue_json(
    kind: &str,
    message: &str,
    robot: Option<&str>,
    file: Option<&str>,
    line: u32,
    col: u32,
) -> Json {
    json!({"kind": kind, "message": message, "robot": robot, "file": file, "line": line, "col": col})
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_kind_reads_back_from_its_name() {
        let mut kinds: Vec<IssueKind> = IssueKind::NAMED.iter().map(|(k, _)| k.clone()).collect();
        kinds.push(IssueKind::Compiler("W0001".into()));
        for k in kinds {
            assert_eq!(IssueKind::from_name(k.name()), Some(k.clone()), "{k}");
        }
        assert_eq!(IssueKind::from_name("near miss"), None);
        assert_eq!(IssueKind::from_name("w0001"), None);
        assert_eq!(IssueKind::from_name("W00012"), None);
    }

    #[test]
    fn the_vm_warnings_have_their_names() {
        for (vm, name) in [
            (WarningKind::Slowdown, "slowdown"),
            (WarningKind::Duration, "duration"),
            (WarningKind::StopPoint, "stop-point"),
            (WarningKind::Corner, "corner"),
        ] {
            assert_eq!(IssueKind::from(vm).name(), name);
        }
    }

    #[test]
    fn derived_json_is_the_hand_written_form() {
        let issue = Issue {
            kind: IssueKind::Compiler("W0003".into()),
            message: "m".into(),
            robot: Some("r1".into()),
            file: None,
            line: 3,
            col: 4,
            distance_m: None,
            motions: Vec::new(),
        };
        assert_eq!(
            issue.to_json(),
            issue_json("W0003", "m", Some("r1"), None, 3, 4)
        );
        let near = Issue {
            kind: IssueKind::NearMiss,
            distance_m: Some(0.002),
            motions: vec![RobotMotion::not_moved("r1".into())],
            ..issue
        };
        let mut want = issue_json("near_miss", "m", Some("r1"), None, 3, 4);
        want["distance_m"] = 0.002.into();
        want["motions"] = json!([{"robot": "r1", "moving": false, "file": null, "line": 0,
                                   "col": 0, "statement": ""}]);
        assert_eq!(near.to_json(), want);
        assert_eq!(
            serde_json::to_string(&near.to_json()).ok(),
            serde_json::to_string(&want).ok()
        );
    }
}
