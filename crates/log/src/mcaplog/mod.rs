//! The MCAP log of a run: every event, every cycle's state, and the cell's geometry, so
//! one file replays the whole run in Foxglove without plugins.
//!
//! Topics (chunked and zstd-compressed; see `docs/log.md`):
//! - `/events` (`vworks.Event`, JSON): one message per event — time, robot, kind,
//!   details text, source position, and the typed details (`data`,
//!   [`crate::trace::Data`]) — written from and read back into [`crate::trace::Event`].
//! - `/state` (`vworks.CycleState`, protobuf by default): per cycle boundary (every
//!   `every`-th), every robot's joints and TCP.
//! - `/tf` (`foxglove.FrameTransforms`, protobuf by default): per logged boundary, the
//!   transforms of the frame tree (world → robot root links → links by joint; devices and
//!   parts under world) that changed, all of them once per simulated second.
//! - `/scene` (`foxglove.SceneUpdate`, JSON): the bodies' geometry attached to those frames
//!   (boxes as cubes, capsules as a cylinder and two spheres, meshes as their convex
//!   hull's triangles), at the start and whenever a body's collision colour changes (red
//!   while touching).
//! - `/log` (`foxglove.Log`, JSON): `log` output, warnings and errors.
//!
//! The workcell file, every program source, every URDF and every mesh are attachments;
//! `vworks` metadata holds the version, the cell name, the cycle and the seed, and
//! `vworks_result` metadata, written at the end, the outcome, the end time and how each
//! robot ended ([`RESULT_METADATA`]).
//!
//! The simulation's thread only appends records to batches: per logged boundary the
//! joints, TCPs and part poses, per event its JSON message. The log's writer thread
//! (`writer`) opens the file's MCAP structure, builds `/state`, `/tf` (`cycles`) and
//! `/scene`, frames, compresses and writes. The file is finished (summary, CRCs) when
//! [`McapLog::finish`] runs, which the engine does for every outcome, or when the log is
//! dropped.

mod cycles;
mod json;
mod poses;
mod proto;
mod read;
mod scene;
mod writer;

use std::collections::BTreeMap;
use std::fs::File;
use std::io::BufWriter;
use std::path::Path;
use std::sync::{Arc, OnceLock};

use foxglove::messages::FrameTransforms;
use vworks_model::math::Iso;

pub use cycles::tcp_frame;
pub use poses::FrameTransform;
pub use read::{
    LogContents, MAX_LOG_BYTES, ReadOptions, read_log, read_log_bytes, read_log_bytes_with,
    read_log_with,
};

use crate::cell::CellInfo;
use crate::sink::{RunEnd, RunSink, WorldView};
use crate::trace::{Data, Kind, TraceEvent};

/// An event as a log holds it: the run's typed event with names.
pub type LoggedEvent = crate::trace::Event;

/// The version of the log's layout and `/events` schema, in the `vworks` metadata as
/// `log_version`: 2 since events carry typed `data` and the log ends with
/// [`RESULT_METADATA`]; 3 since motions carry zones (`zone_m`, `blend_m` on
/// `motion_start`, data on a zoned `motion_end`). Logs without it are version 1 (read
/// too, without typed data); versions 2 and 3 read alike.
pub const LOG_VERSION: u32 = 3;

/// The name of the metadata record written at the end of a run: `outcome`,
/// `end_time_ns`, and `ended`, each robot's ending (`r1=ended,r2=waiting`).
pub const RESULT_METADATA: &str = "vworks_result";

/// Why the log could not be written.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum LogError {
    /// The file could not be created or written.
    #[error("cannot write the log `{file}`: {reason}")]
    Io {
        /// The file.
        file: String,
        /// Why.
        reason: String,
    },
    /// The file could not be read.
    #[error("cannot read `{file}`: {reason}")]
    Read {
        /// The file.
        file: String,
        /// Why.
        reason: String,
    },
    /// The file read is not an MCAP file.
    #[error(
        "{file}: not an MCAP file (it does not start with the MCAP magic bytes); give a log written by `vworks run --log FILE`"
    )]
    NotMcap {
        /// The file.
        file: String,
    },
    /// The file read is MCAP but not a vworks log, or broken before any message.
    #[error("{file}: not a valid vworks log: {reason}")]
    Invalid {
        /// The file.
        file: String,
        /// Why.
        reason: String,
    },
}

/// An error and its sources, `: `-separated (the MCAP writer's errors wrap the I/O error
/// that says what actually went wrong, such as a full disk).
pub(crate) fn error_chain(e: &dyn std::error::Error) -> String {
    let mut out = e.to_string();
    let mut source = e.source();
    while let Some(s) = source {
        let text = s.to_string();
        if !out.contains(&text) {
            out.push_str(": ");
            out.push_str(&text);
        }
        source = s.source();
    }
    out
}

/// The zstd level of the chunks: −3, one of zstd's fast levels (`zstd --fast=3`; any zstd
/// reader decompresses it). Compression is the largest part of the writer thread's work,
/// which runs beside the simulation; on handoff −3 against level 1 costs 8 % more bytes
/// (3.78 MB against 3.49 MB) and takes about a third off compression time (`docs/log.md`).
pub const ZSTD_LEVEL: i32 = -3;

/// The MCAP writer's options: chunks of 1 MiB, zstd at [`ZSTD_LEVEL`]. Built once per
/// process, because `WriteOptions::new` asks the OS for the number of physical CPUs (it
/// parses `/proc`, about 0.7 ms here), which a sweep that writes many logs should pay once.
fn write_options() -> mcap::WriteOptions {
    static OPTIONS: OnceLock<mcap::WriteOptions> = OnceLock::new();
    OPTIONS
        .get_or_init(|| {
            mcap::WriteOptions::new()
                .compression(Some(mcap::Compression::Zstd))
                // The mcap crate takes the level as a u32 and hands `level as i32` to zstd,
                // so a negative level travels as its two's complement (tested: the chunks'
                // compressed size shows the level took effect).
                .compression_level(ZSTD_LEVEL as u32)
                // Compression runs on the log's own writer thread (see `writer`); zstd's
                // worker threads would only add locking on top of it.
                .compression_threads(0)
                .chunk_size(Some(1 << 20))
                .profile("")
        })
        .clone()
}

/// The media type of an attached file, from its extension (`text`: a program or the
/// workcell, plain text whatever its name).
fn media_type(name: &str, text: bool) -> &'static str {
    let lower = name.to_ascii_lowercase();
    let ext = lower.rsplit_once('.').map_or("", |(_, e)| e);
    match ext {
        "toml" => "application/toml",
        "wsl" => "text/plain",
        "urdf" | "xml" => "application/xml",
        "stl" => "model/stl",
        "obj" => "model/obj",
        _ if text => "text/plain",
        _ => "application/octet-stream",
    }
}

/// The MCAP log being written.
pub struct McapLog {
    /// The cell logged: events are resolved with its names; boundaries read its models.
    cell: Arc<CellInfo>,
    /// The writer thread's end: records are appended to its batch.
    sink: writer::Sink,
    file: String,
    every: u64,
    boundary: u64,
    /// The parts' poses at a logged boundary (reused).
    parts: Vec<Iso>,
}

/// How the per-cycle topics `/state` and `/tf` are encoded. `docs/log.md` has the
/// measurements behind the default.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[non_exhaustive]
pub enum Encoding {
    /// Protobuf (the default: smaller and faster): `/tf` with Foxglove's
    /// `FrameTransforms` descriptor from the `foxglove` crate, `/state` with vworks' own.
    #[default]
    Protobuf,
    /// JSON with JSON Schemas written here (readable with any JSON tool).
    Json,
}

/// Options for [`McapLog::create_with`].
#[derive(Clone, Copy, Debug)]
#[non_exhaustive]
pub struct LogOptions {
    /// Log every `every`-th cycle boundary's state (1 = all; events are never thinned).
    pub every: u64,
    /// The encoding of `/state` and `/tf`.
    pub encoding: Encoding,
}

impl Default for LogOptions {
    fn default() -> LogOptions {
        LogOptions {
            every: 1,
            encoding: Encoding::Protobuf,
        }
    }
}

impl LogOptions {
    /// Every `every`-th state, `/state` and `/tf` encoded as `encoding`.
    pub fn new(every: u64, encoding: Encoding) -> LogOptions {
        LogOptions { every, encoding }
    }
}

/// Every frame is republished at least this often (simulated time), so a player that
/// seeks into the middle of a run finds every frame within one second before.
pub const KEYFRAME_NS: i64 = 1_000_000_000;

/// The topics, in the order of [`McapLog`]'s counters.
pub const TOPICS: [&str; 5] = ["/events", "/state", "/tf", "/scene", "/log"];
const EVENTS: usize = 0;
const STATE: usize = 1;
const TF: usize = 2;
const SCENE: usize = 3;
const LOG: usize = 4;

impl std::fmt::Debug for McapLog {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("McapLog")
            .field("file", &self.file)
            .field("every", &self.every)
            .finish()
    }
}

/// Registers the schemas and channels (returns their ids, indexed like [`TOPICS`]) and
/// writes the metadata and the attachments. Runs on the writer thread.
fn open(
    w: &mut writer::Mcap,
    cell: &CellInfo,
    encoding: Encoding,
) -> Result<[u16; TOPICS.len()], String> {
    let io = |e: &dyn std::error::Error| error_chain(e);
    let none = BTreeMap::new();
    let (state_schema, tf_schema) = match encoding {
        Encoding::Json => (
            json::STATE_SCHEMA.as_bytes().to_vec(),
            json::tf_schema().into_bytes(),
        ),
        Encoding::Protobuf => {
            let tf = <FrameTransforms as foxglove::Encode>::get_schema()
                .ok_or("the foxglove crate has no FrameTransforms schema")?;
            (proto::cycle_state_descriptor(), tf.data.into_owned())
        }
    };
    let json = Encoding::Json;
    let (scene_schema, log_schema) = (json::scene_schema(), json::log_schema());
    let topics: [(&str, Encoding, &[u8]); TOPICS.len()] = [
        ("vworks.Event", json, json::EVENT_SCHEMA.as_bytes()),
        ("vworks.CycleState", encoding, &state_schema),
        ("foxglove.FrameTransforms", encoding, &tf_schema),
        ("foxglove.SceneUpdate", json, scene_schema.as_bytes()),
        ("foxglove.Log", json, log_schema.as_bytes()),
    ];
    let mut channels = [0; TOPICS.len()];
    for ((channel, (name, encoding, schema)), topic) in channels.iter_mut().zip(topics).zip(TOPICS)
    {
        let (schema_encoding, message_encoding) = match encoding {
            Encoding::Json => ("jsonschema", "json"),
            Encoding::Protobuf => ("protobuf", "protobuf"),
        };
        let s = w
            .add_schema(name, schema_encoding, schema)
            .map_err(|e| io(&e))?;
        *channel = w
            .add_channel(s, topic, message_encoding, &none)
            .map_err(|e| io(&e))?;
    }
    let mut meta = BTreeMap::new();
    meta.insert(
        "vworks_version".to_string(),
        env!("CARGO_PKG_VERSION").to_string(),
    );
    meta.insert("log_version".to_string(), LOG_VERSION.to_string());
    meta.insert("cell".to_string(), cell.name.clone());
    meta.insert("cycle_ns".to_string(), cell.cycle_ns.to_string());
    meta.insert("workcell_file".to_string(), cell.file.clone());
    meta.insert("clearance_m".to_string(), cell.clearance.to_string());
    // The engine draws no random numbers: the same inputs give the same run.
    meta.insert("seed".to_string(), "none (deterministic)".to_string());
    let robots: Vec<&str> = cell.robots.iter().map(|r| r.name.as_str()).collect();
    meta.insert("robots".to_string(), robots.join(","));
    // A sweep's variant: the values changed from the attached workcell file, one
    // `path = value` per line (TOML values).
    if !cell.overrides.is_empty() {
        let lines: Vec<String> = cell
            .overrides
            .iter()
            .map(|(p, v)| format!("{p} = {v}"))
            .collect();
        meta.insert("overrides".to_string(), lines.join("\n"));
    }
    w.write_metadata(&mcap::records::Metadata {
        name: "vworks".into(),
        metadata: meta,
    })
    .map_err(|e| io(&e))?;
    let texts = cell.sources.iter().map(|(n, t)| (n, t.as_bytes(), true));
    let files = cell.files.iter().map(|(n, b)| (n, b.as_slice(), false));
    for (name, data, text) in texts.chain(files) {
        w.attach(&mcap::Attachment {
            log_time: 0,
            create_time: 0,
            name: name.clone(),
            media_type: media_type(name, text).into(),
            data: std::borrow::Cow::Borrowed(data),
        })
        .map_err(|e| io(&e))?;
    }
    Ok(channels)
}

impl McapLog {
    /// Creates the log for `cell`; `every` thins cycle states (1 = every boundary).
    pub fn create(path: &Path, cell: &Arc<CellInfo>, every: u64) -> Result<McapLog, LogError> {
        McapLog::create_with(
            path,
            cell,
            LogOptions {
                every,
                ..LogOptions::default()
            },
        )
    }

    /// Creates the log for `cell` with these options. The file is created here (an error
    /// if it cannot be); its contents are written by the log's writer thread, whose errors
    /// (a full disk, say) come out of [`McapLog::finish`] or the run's `log_error`.
    pub fn create_with(
        path: &Path,
        cell: &Arc<CellInfo>,
        options: LogOptions,
    ) -> Result<McapLog, LogError> {
        let file = path.display().to_string();
        let io = |e: &dyn std::error::Error| LogError::Io {
            file: file.clone(),
            reason: error_chain(e),
        };
        let f = BufWriter::new(File::create(path).map_err(|e| {
            let hint = match e.kind() {
                std::io::ErrorKind::NotFound => match path.parent() {
                    Some(dir) if !dir.as_os_str().is_empty() => format!(
                        "; the folder `{}` does not exist: create it, or write the log elsewhere",
                        dir.display()
                    ),
                    _ => String::new(),
                },
                std::io::ErrorKind::PermissionDenied => {
                    "; this folder is not writable: write the log elsewhere".into()
                }
                _ => String::new(),
            };
            LogError::Io {
                file: file.clone(),
                reason: format!("{}{hint}", error_chain(&e)),
            }
        })?);
        let names = Arc::clone(cell);
        let cell = Arc::clone(cell);
        let encoding = options.encoding;
        let open = move || {
            let mut mcap = write_options().create(f).map_err(|e| error_chain(&e))?;
            let channels = open(&mut mcap, &cell, encoding)?;
            Ok(writer::WriterSetup {
                mcap,
                cycles: cycles::CycleEncoder::new(&cell, encoding),
                channels,
                scene: scene::Scene::new(&cell),
            })
        };
        let sink = writer::Sink::spawn(open).map_err(|e| io(&e))?;
        Ok(McapLog {
            cell: names,
            sink,
            file,
            every: options.every.max(1),
            boundary: 0,
            parts: Vec::new(),
        })
    }

    /// The error to report when the writer failed: the thread's own reason if it has one.
    fn failed(&mut self, reason: String) -> LogError {
        LogError::Io {
            file: self.file.clone(),
            reason: self.sink.finish().err().unwrap_or(reason),
        }
    }

    /// Writes one JSON message on topic `topic` (index in [`TOPICS`]).
    fn write(&mut self, topic: usize, t: i64, value: &serde_json::Value) -> Result<(), LogError> {
        let (start, b) = self.sink.begin(topic, t.max(0) as u64);
        if let Err(e) = serde_json::to_writer(b, value) {
            self.sink.cancel(start);
            return Err(self.failed(e.to_string()));
        }
        self.sink.end(start).map_err(|reason| self.failed(reason))
    }

    /// Logs an event (and, for `log`, `warning` and `error`, a Foxglove log message); on
    /// `collision_start`/`collision_end` the two bodies change colour.
    pub(crate) fn event(&mut self, e: &TraceEvent) -> Result<(), LogError> {
        let ev = e.resolve(&*self.cell);
        self.write(EVENTS, e.time, &ev.to_json())?;
        let level = match e.kind {
            Kind::Log => Some(2),
            Kind::Warning => Some(3),
            Kind::Error => Some(4),
            _ => None,
        };
        if let Some(level) = level {
            let message: std::borrow::Cow<'_, str> = match &ev.data {
                Data::Text { text } => text.into(),
                Data::Issue {
                    message, motions, ..
                } if motions.is_empty() => message.into(),
                // A near miss names each robot's motion, a line each.
                Data::Issue {
                    message, motions, ..
                } => std::iter::once(message.clone())
                    .chain(motions.iter().map(|m| m.describe()))
                    .collect::<Vec<_>>()
                    .join("\n")
                    .into(),
                _ => ev.details.as_str().into(),
            };
            let v = serde_json::json!({"timestamp": scene::ts(e.time), "level": level, "message": message, "name": ev.robot.as_deref().unwrap_or("cell"), "file": ev.file.as_deref().unwrap_or_default(), "line": ev.line});
            self.write(LOG, e.time, &v)?;
        }
        if let Data::Collision { a, b, .. } = &ev.data {
            let on = e.kind == Kind::CollisionStart;
            self.sink
                .colour(e.time.max(0) as u64, on, a, b)
                .map_err(|reason| self.failed(reason))?;
        }
        Ok(())
    }

    /// Records how the run ended ([`RESULT_METADATA`]).
    fn result(&mut self, end: &RunEnd<'_>) -> Result<(), LogError> {
        let ended: Vec<String> = end
            .robots
            .iter()
            .map(|r| format!("{}={}", r.name, r.ended.name()))
            .collect();
        let map = BTreeMap::from([
            ("outcome".to_string(), end.outcome.name().to_string()),
            ("end_time_ns".to_string(), end.end_time_ns.to_string()),
            ("ended".to_string(), ended.join(",")),
        ]);
        self.sink
            .metadata(RESULT_METADATA, &map)
            .map_err(|reason| self.failed(reason))
    }

    /// Finishes the file: summary, indexes, CRCs. Returns the counts per topic.
    pub fn finish(mut self) -> Result<BTreeMap<&'static str, u64>, LogError> {
        self.close()
    }

    /// Writes what is left and closes the file; the messages written per topic.
    fn close(&mut self) -> Result<BTreeMap<&'static str, u64>, LogError> {
        let counts = self.sink.finish().map_err(|reason| LogError::Io {
            file: self.file.clone(),
            reason,
        })?;
        Ok(TOPICS.iter().copied().zip(counts).collect())
    }
}

impl RunSink for McapLog {
    fn event(&mut self, e: &TraceEvent) -> Result<(), String> {
        McapLog::event(self, e).map_err(|e| e.to_string())
    }

    /// Logs every `every`-th boundary: the robots' joints and link frames and the parts'
    /// poses, from which the writer thread builds `/state` and `/tf` (in the module `cycles`).
    /// Other boundaries are only counted.
    fn cycle(&mut self, t: i64, world: &dyn WorldView) -> Result<(), String> {
        let k = self.boundary;
        self.boundary += 1;
        if !k.is_multiple_of(self.every) {
            return Ok(());
        }
        world.part_poses_into(&mut self.parts);
        let (joints, frames, tools) = (world.joints(), world.frames(), world.tools());
        let (cell, parts) = (&*self.cell, &self.parts);
        let payload = |b: &mut Vec<u8>| cycles::append_cycle(b, cell, joints, frames, tools, parts);
        let done = self.sink.cycle(t.max(0) as u64, k, payload);
        done.map_err(|reason| self.failed(reason).to_string())
    }

    fn records_cycles(&self) -> bool {
        true
    }

    fn finish(&mut self, end: &RunEnd<'_>) -> Result<BTreeMap<&'static str, u64>, String> {
        let recorded = self.result(end);
        let counts = self.close().map_err(|e| e.to_string())?;
        recorded.map_err(|e| e.to_string())?;
        Ok(counts)
    }
}
