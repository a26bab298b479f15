//! Reading a log back: its topics, message counts and simulated span, and its events as
//! trace lines. A log cut short (the run was killed) is read up to the damage, and the
//! damage is reported beside what was read.

use std::collections::BTreeMap;
use std::path::Path;

use super::LogError;

/// An event as logged on `/events`.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct LoggedEvent {
    /// Simulated time (ns).
    pub time_ns: i64,
    /// The robot, if the event belongs to one.
    pub robot: Option<String>,
    /// Kind, e.g. `motion_start`.
    pub kind: String,
    /// Details (may be empty).
    pub details: String,
    /// The WSL source file, if known.
    pub file: Option<String>,
    /// Line and column (0 if unknown).
    pub line: u32,
    /// Column (0 if unknown).
    pub col: u32,
}

impl LoggedEvent {
    /// `file:line:col` with the file's name only, if the event has a source position.
    pub fn position(&self) -> Option<String> {
        let f = self.file.as_ref()?;
        let name = Path::new(f)
            .file_name()
            .map_or(f.clone(), |n| n.to_string_lossy().into_owned());
        Some(format!("{name}:{}:{}", self.line, self.col))
    }

    /// The event as a trace line, `time_ns robot kind details file:line:col` with `-` for
    /// an empty field and the file's name only: the golden traces' format.
    pub fn line(&self) -> String {
        let details = if self.details.is_empty() {
            "-"
        } else {
            &self.details
        };
        let pos = self.position().unwrap_or_else(|| "-".into());
        format!(
            "{} {} {} {details} {pos}",
            self.time_ns,
            self.robot.as_deref().unwrap_or("-"),
            self.kind
        )
    }
}

/// What a log holds.
#[derive(Clone, Debug, Default)]
pub struct LogContents {
    /// Messages per topic (topics with at least one message).
    pub counts: BTreeMap<String, u64>,
    /// The first and last message time (ns), if there are messages.
    pub span: Option<(u64, u64)>,
    /// The `/events` messages, in order.
    pub events: Vec<LoggedEvent>,
    /// If the file is unfinished or damaged: how many messages were read before the
    /// damage, and what the damage is. Everything before it is above.
    pub damage: Option<(u64, String)>,
    /// The `vworks` metadata record: the version, the cell's name, its robots (comma
    /// separated), the cycle, the workcell file (empty if the record was not found).
    pub metadata: BTreeMap<String, String>,
}

/// Reads the log at `path`.
pub fn read_log(path: &Path) -> Result<LogContents, LogError> {
    let file = path.display().to_string();
    let bytes = std::fs::read(path).map_err(|e| LogError::Read {
        file: file.clone(),
        reason: match e.kind() {
            std::io::ErrorKind::NotFound => format!(
                "{e}; check the path, or write the log first: `vworks run CELL --log {file}`"
            ),
            _ => e.to_string(),
        },
    })?;
    read_log_bytes(&file, &bytes)
}

/// Reads a log from its bytes; `file` names it in errors.
pub fn read_log_bytes(file: &str, bytes: &[u8]) -> Result<LogContents, LogError> {
    if !bytes.starts_with(mcap::MAGIC) {
        return Err(LogError::NotMcap { file: file.into() });
    }
    let invalid = |reason: String| LogError::Invalid {
        file: file.into(),
        reason,
    };
    let stream = mcap::MessageStream::new(bytes).map_err(|e| invalid(e.to_string()))?;
    let mut out = LogContents::default();
    // The metadata record sits before the first chunk; a damaged tail does not hide it.
    if let Ok(records) = mcap::read::LinearReader::new(bytes) {
        for record in records {
            match record {
                Ok(mcap::records::Record::Metadata(m)) if m.name == "vworks" => {
                    out.metadata = m.metadata;
                    break;
                }
                Ok(_) => {}
                Err(_) => break,
            }
        }
    }
    for (read, m) in (0u64..).zip(stream) {
        let m = match m {
            Ok(m) => m,
            Err(e) => {
                out.damage = Some((read, e.to_string()));
                break;
            }
        };
        *out.counts.entry(m.channel.topic.clone()).or_default() += 1;
        let (first, last) = out.span.unwrap_or((m.log_time, m.log_time));
        out.span = Some((first.min(m.log_time), last.max(m.log_time)));
        if m.channel.topic == "/events" {
            let v: serde_json::Value = serde_json::from_slice(&m.data)
                .map_err(|e| invalid(format!("an event is not JSON: {e}")))?;
            let text = |k: &str| v[k].as_str().map(str::to_string);
            let int = |k: &str| u32::try_from(v[k].as_u64().unwrap_or(0)).unwrap_or(u32::MAX);
            out.events.push(LoggedEvent {
                time_ns: v["time_ns"].as_i64().unwrap_or(0),
                robot: text("robot"),
                kind: text("kind").unwrap_or_else(|| "?".into()),
                details: text("details").unwrap_or_default(),
                file: text("file"),
                line: int("line"),
                col: int("col"),
            });
        }
    }
    Ok(out)
}
