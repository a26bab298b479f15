//! The MCAP log of a run: every event, every cycle's state, and the cell's geometry, so
//! one file replays the whole run in Foxglove without plugins.
//!
//! Topics (chunked and zstd-compressed; see `docs/log.md`):
//! - `/events` (`vworks.Event`, JSON): one message per event — time, robot, kind,
//!   details, source position — the same content as a trace line.
//! - `/state` (`vworks.CycleState`, protobuf by default): per cycle boundary (every
//!   `every`-th), every robot's joints and TCP.
//! - `/tf` (`foxglove.FrameTransforms`, protobuf by default): per logged boundary, the
//!   link, device and part frames that moved (all of them once per simulated second).
//! - `/scene` (`foxglove.SceneUpdate`, JSON): the bodies' geometry attached to those frames
//!   (boxes as cubes, capsules as a cylinder and two spheres, meshes as their convex
//!   hull's triangles), at the start and whenever a body's collision colour changes (red
//!   while touching).
//! - `/log` (`foxglove.Log`, JSON): `log` output, warnings and errors.
//!
//! The workcell file, every program source, every URDF and every mesh are attachments;
//! `vworks` metadata holds the version, the cell name, the cycle and the seed.
//!
//! Messages are encoded on the simulation's thread straight into batches ([`writer`]); a
//! writer thread frames, compresses and writes them. The file is finished (summary, CRCs)
//! when [`McapLog::finish`] runs, which the engine does for every outcome, or when the
//! log is dropped.

mod cycles;
mod json;
mod proto;
mod writer;

use std::collections::BTreeMap;
use std::fs::File;
use std::io::BufWriter;
use std::path::Path;
use std::sync::OnceLock;

use foxglove::messages::FrameTransforms;
use vworks_model::math::Iso;
use vworks_model::model::Geometry;

use crate::engine::TraceEvent;
use crate::workcell::Cell;

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
}

/// A body of the scene: its frame and primitives.
struct SceneBody {
    frame: String,
    geometry: Geometry,
    /// Shape pose in the frame (URDF convention: cylinders and capsules along z).
    local: Iso,
    /// For a hull: its triangles, three corners each (empty if the hull is degenerate).
    hull: Vec<[f64; 3]>,
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

/// The MCAP writer's options: chunks of 1 MiB, zstd level 1 (on handoff both faster and
/// smaller than the default level 3). Built once per process, because
/// `WriteOptions::new` asks the OS for the number of physical CPUs (it parses `/proc`,
/// about 0.7 ms here), which a sweep that writes many logs should pay once.
fn write_options() -> mcap::WriteOptions {
    static OPTIONS: OnceLock<mcap::WriteOptions> = OnceLock::new();
    OPTIONS
        .get_or_init(|| {
            mcap::WriteOptions::new()
                .compression(Some(mcap::Compression::Zstd))
                .compression_level(1)
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

/// The convex hull of `points` as a triangle list (three corners per triangle).
fn hull_triangles(geometry: &Geometry) -> Vec<[f64; 3]> {
    let Geometry::Hull { points, .. } = geometry else {
        return Vec::new();
    };
    let pts: Vec<parry3d::math::Vector3> = points
        .iter()
        .map(|p| parry3d::math::Vector3::new(p[0] as f32, p[1] as f32, p[2] as f32))
        .collect();
    let Ok((vertices, faces)) = parry3d::transformation::try_convex_hull(&pts) else {
        return Vec::new();
    };
    let mut out = Vec::with_capacity(faces.len() * 3);
    for face in faces {
        for k in face {
            if let Some(v) = vertices.get(k as usize) {
                out.push([f64::from(v.x), f64::from(v.y), f64::from(v.z)]);
            }
        }
    }
    out
}

/// The MCAP log being written.
pub struct McapLog {
    /// The writer thread's end: records are appended to its batch.
    sink: writer::Sink,
    file: String,
    events: u16,
    scene: u16,
    log: u16,
    every: u64,
    boundary: u64,
    bodies: Vec<SceneBody>,
    red: Vec<bool>,
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

fn ts(t: i64) -> serde_json::Value {
    serde_json::json!({"sec": t.max(0) / 1_000_000_000, "nsec": t.max(0) % 1_000_000_000})
}

fn pose_json(p: &Iso) -> serde_json::Value {
    let q = proto::quat(&p.r);
    serde_json::json!({"position": {"x": p.t[0], "y": p.t[1], "z": p.t[2]}, "orientation": {"x": q[0], "y": q[1], "z": q[2], "w": q[3]}})
}

impl McapLog {
    /// Creates the log for `cell`; `every` thins cycle states (1 = every boundary).
    pub fn create(path: &Path, cell: &Cell, every: u64) -> Result<McapLog, LogError> {
        McapLog::create_with(
            path,
            cell,
            LogOptions {
                every,
                ..LogOptions::default()
            },
        )
    }

    /// Creates the log for `cell` with these options.
    pub fn create_with(path: &Path, cell: &Cell, options: LogOptions) -> Result<McapLog, LogError> {
        let every = options.every;
        let file = path.display().to_string();
        let io = |e: &dyn std::error::Error| LogError::Io {
            file: file.clone(),
            reason: error_chain(e),
        };
        let f = File::create(path).map_err(|e| io(&e))?;
        let mut w = write_options()
            .create(BufWriter::new(f))
            .map_err(|e| io(&e))?;
        let none = BTreeMap::new();
        let channel = |w: &mut writer::Mcap,
                       name: &str,
                       encoding: Encoding,
                       schema: &[u8],
                       topic: &str|
         -> Result<u16, LogError> {
            let (schema_encoding, message_encoding) = match encoding {
                Encoding::Json => ("jsonschema", "json"),
                Encoding::Protobuf => ("protobuf", "protobuf"),
            };
            let s = w
                .add_schema(name, schema_encoding, schema)
                .map_err(|e| io(&e))?;
            w.add_channel(s, topic, message_encoding, &none)
                .map_err(|e| io(&e))
        };
        let json = Encoding::Json;
        let events = channel(
            &mut w,
            "vworks.Event",
            json,
            json::EVENT_SCHEMA.as_bytes(),
            TOPICS[EVENTS],
        )?;
        let (state_schema, tf_schema) = match options.encoding {
            Encoding::Json => (
                json::STATE_SCHEMA.as_bytes().to_vec(),
                json::tf_schema().into_bytes(),
            ),
            Encoding::Protobuf => {
                let tf = <FrameTransforms as foxglove::Encode>::get_schema().ok_or_else(|| {
                    LogError::Io {
                        file: file.clone(),
                        reason: "the foxglove crate has no FrameTransforms schema".into(),
                    }
                })?;
                (proto::cycle_state_descriptor(), tf.data.into_owned())
            }
        };
        let state = channel(
            &mut w,
            "vworks.CycleState",
            options.encoding,
            &state_schema,
            TOPICS[STATE],
        )?;
        let tf = channel(
            &mut w,
            "foxglove.FrameTransforms",
            options.encoding,
            &tf_schema,
            TOPICS[TF],
        )?;
        let scene = channel(
            &mut w,
            "foxglove.SceneUpdate",
            json,
            json::scene_schema().as_bytes(),
            TOPICS[SCENE],
        )?;
        let log = channel(
            &mut w,
            "foxglove.Log",
            json,
            json::log_schema().as_bytes(),
            TOPICS[LOG],
        )?;
        let mut meta = BTreeMap::new();
        meta.insert(
            "vworks_version".to_string(),
            env!("CARGO_PKG_VERSION").to_string(),
        );
        meta.insert("cell".to_string(), cell.name.clone());
        meta.insert("cycle_ns".to_string(), cell.cycle_ns.to_string());
        meta.insert("workcell_file".to_string(), cell.file.display().to_string());
        meta.insert("clearance_m".to_string(), cell.clearance.to_string());
        // The engine draws no random numbers: the same inputs give the same run.
        meta.insert("seed".to_string(), "none (deterministic)".to_string());
        meta.insert(
            "robots".to_string(),
            cell.robots
                .iter()
                .map(|r| r.name.as_str())
                .collect::<Vec<_>>()
                .join(","),
        );
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
        let mut bodies = Vec::new();
        for r in &cell.robots {
            for l in &r.model.links {
                for s in &l.shapes {
                    bodies.push(SceneBody {
                        frame: format!("{}.{}", r.name, l.name),
                        hull: hull_triangles(&s.geometry),
                        geometry: s.geometry.clone(),
                        local: s.origin,
                    });
                }
            }
        }
        for d in cell.devices.iter().chain(&cell.parts) {
            bodies.push(SceneBody {
                frame: d.name.clone(),
                hull: hull_triangles(&d.geometry),
                geometry: d.geometry.clone(),
                local: Iso::IDENTITY,
            });
        }
        let red = vec![false; bodies.len()];
        let setup = writer::WriterSetup {
            mcap: w,
            cycles: cycles::CycleEncoder::new(cell, options.encoding),
            channels: [events, state, tf, scene, log],
        };
        let sink = writer::Sink::spawn(setup).map_err(|e| io(&e))?;
        let mut log = McapLog {
            sink,
            file,
            events,
            scene,
            log,
            every: every.max(1),
            boundary: 0,
            bodies,
            red,
        };
        log.write_scene(0, None)?;
        Ok(log)
    }

    /// Starts a message on `channel` at time `t`: returns where it starts and the buffer
    /// to encode it into; [`McapLog::end`] completes it.
    fn begin(&mut self, channel: u16, t: i64) -> (writer::Started, &mut Vec<u8>) {
        self.sink.begin(channel, t.max(0) as u64)
    }

    /// Completes the message begun at `start`.
    fn end(&mut self, start: writer::Started) -> Result<(), LogError> {
        self.sink.end(start).map_err(|reason| self.failed(reason))
    }

    /// The error to report when the writer failed: the thread's own reason if it has one.
    fn failed(&mut self, reason: String) -> LogError {
        LogError::Io {
            file: self.file.clone(),
            reason: self.sink.finish().err().unwrap_or(reason),
        }
    }

    /// Writes one JSON message.
    fn write(&mut self, channel: u16, t: i64, value: &serde_json::Value) -> Result<(), LogError> {
        let (start, b) = self.begin(channel, t);
        if let Err(e) = serde_json::to_writer(b, value) {
            self.sink.cancel(start);
            return Err(self.failed(e.to_string()));
        }
        self.end(start)
    }

    /// Publishes the geometry; with `only`, just the bodies whose frame is one of those.
    fn write_scene(&mut self, t: i64, only: Option<&[&str]>) -> Result<(), LogError> {
        let mut entities = Vec::new();
        for (i, b) in self.bodies.iter().enumerate() {
            if only.is_some_and(|o| !o.contains(&b.frame.as_str())) {
                continue;
            }
            let color = if self.red[i] {
                serde_json::json!({"r": 0.9, "g": 0.1, "b": 0.1, "a": 1.0})
            } else {
                serde_json::json!({"r": 0.6, "g": 0.65, "b": 0.7, "a": 1.0})
            };
            let (mut cubes, mut spheres, mut cylinders) = (Vec::new(), Vec::new(), Vec::new());
            let mut triangles = Vec::new();
            let local = b.local;
            match &b.geometry {
                Geometry::Box { half } => cubes.push(serde_json::json!({"pose": pose_json(&local), "size": {"x": 2.0 * half[0], "y": 2.0 * half[1], "z": 2.0 * half[2]}, "color": color})),
                Geometry::Sphere { radius } => spheres.push(serde_json::json!({"pose": pose_json(&local), "size": {"x": 2.0 * radius, "y": 2.0 * radius, "z": 2.0 * radius}, "color": color})),
                Geometry::Cylinder { radius, length } => cylinders.push(serde_json::json!({"pose": pose_json(&local), "size": {"x": 2.0 * radius, "y": 2.0 * radius, "z": length}, "bottom_scale": 1.0, "top_scale": 1.0, "color": color})),
                Geometry::Capsule { radius, length } => {
                    cylinders.push(serde_json::json!({"pose": pose_json(&local), "size": {"x": 2.0 * radius, "y": 2.0 * radius, "z": length}, "bottom_scale": 1.0, "top_scale": 1.0, "color": color}));
                    for end in [-0.5, 0.5] {
                        let c = local.mul(&Iso { r: vworks_model::math::I3, t: [0.0, 0.0, end * length] });
                        spheres.push(serde_json::json!({"pose": pose_json(&c), "size": {"x": 2.0 * radius, "y": 2.0 * radius, "z": 2.0 * radius}, "color": color}));
                    }
                }
                Geometry::Hull { .. } if !b.hull.is_empty() => {
                    let points: Vec<serde_json::Value> = b
                        .hull
                        .iter()
                        .map(|p| serde_json::json!({"x": p[0], "y": p[1], "z": p[2]}))
                        .collect();
                    triangles.push(serde_json::json!({"pose": pose_json(&local), "points": points, "color": color, "colors": [], "indices": []}));
                }
                Geometry::Hull { points, .. } => {
                    // A degenerate hull (flat or a line): its bounding box stands in.
                    let mut lo = [f64::INFINITY; 3];
                    let mut hi = [f64::NEG_INFINITY; 3];
                    for p in points {
                        for k in 0..3 {
                            lo[k] = lo[k].min(p[k]);
                            hi[k] = hi[k].max(p[k]);
                        }
                    }
                    let c = local.mul(&Iso { r: vworks_model::math::I3, t: [(lo[0] + hi[0]) / 2.0, (lo[1] + hi[1]) / 2.0, (lo[2] + hi[2]) / 2.0] });
                    cubes.push(serde_json::json!({"pose": pose_json(&c), "size": {"x": hi[0] - lo[0], "y": hi[1] - lo[1], "z": hi[2] - lo[2]}, "color": color}));
                }
            }
            entities.push(serde_json::json!({
                "timestamp": ts(t), "frame_id": b.frame, "id": format!("{}#{i}", b.frame),
                "lifetime": {"sec": 0, "nsec": 0}, "frame_locked": true, "metadata": [],
                "arrows": [], "cubes": cubes, "spheres": spheres, "cylinders": cylinders,
                "lines": [], "triangles": triangles, "texts": [], "models": [],
            }));
        }
        self.write(
            self.scene,
            t,
            &serde_json::json!({"deletions": [], "entities": entities}),
        )
    }

    /// Logs an event (and, for `log`, `warning` and `error`, a Foxglove log message); on
    /// `collision_start`/`collision_end` the two bodies change colour.
    pub(crate) fn event(&mut self, cell: &Cell, e: &TraceEvent) -> Result<(), LogError> {
        let robot = e.robot.map(|r| cell.robots[r].name.clone());
        let (file, line, col) = e
            .pos
            .as_ref()
            .map_or((None, 0, 0), |(f, p)| (Some(f.to_string()), p.line, p.col));
        let v = serde_json::json!({"time_ns": e.time, "robot": robot, "kind": e.kind, "details": e.details, "file": file, "line": line, "col": col});
        self.write(self.events, e.time, &v)?;
        let level = match e.kind {
            "log" => Some(2),
            "warning" => Some(3),
            "error" => Some(4),
            _ => None,
        };
        if let Some(level) = level {
            let v = serde_json::json!({"timestamp": ts(e.time), "level": level, "message": e.details.trim_matches('"'), "name": robot.unwrap_or_else(|| "cell".into()), "file": file.unwrap_or_default(), "line": line});
            self.write(self.log, e.time, &v)?;
        }
        if matches!(e.kind, "collision_start" | "collision_end") {
            let mut names = e.details.split(' ');
            let (a, b) = (
                names.next().unwrap_or_default().to_string(),
                names.next().unwrap_or_default().to_string(),
            );
            let on = e.kind == "collision_start";
            for (i, body) in self.bodies.iter().enumerate() {
                if body.frame == a || body.frame == b {
                    self.red[i] = on;
                }
            }
            self.write_scene(e.time, Some(&[a.as_str(), b.as_str()]))?;
        }
        Ok(())
    }

    /// Whether the next boundary's state is logged (every `every`-th is).
    pub(crate) fn logs_next_boundary(&self) -> bool {
        self.boundary.is_multiple_of(self.every)
    }

    /// Counts a boundary that is not logged without computing its state.
    pub(crate) fn skip_boundary(&mut self) {
        self.boundary += 1;
    }

    /// Logs a cycle boundary (every `every`-th): `joints[r]` holds robot r's axis values,
    /// `frames[r]` its link frames in the cell, `parts` the parts' poses in the cell. The writer thread builds `/state` and `/tf`
    /// from them (see [`cycles`]).
    pub(crate) fn cycle(
        &mut self,
        cell: &Cell,
        t: i64,
        joints: &[[f64; vworks_vm::MAX_AXES]],
        frames: &[Vec<Iso>],
        parts: &[Iso],
    ) -> Result<(), LogError> {
        let k = self.boundary;
        self.boundary += 1;
        if !k.is_multiple_of(self.every) {
            return Ok(());
        }
        let payload = |b: &mut Vec<u8>| cycles::append_cycle(b, cell, joints, frames, parts);
        self.sink
            .cycle(t.max(0) as u64, k, payload)
            .map_err(|reason| self.failed(reason))
    }

    /// Finishes the file: summary, indexes, CRCs. Returns the counts per topic.
    pub fn finish(mut self) -> Result<BTreeMap<&'static str, u64>, LogError> {
        let counts = self.sink.finish().map_err(|reason| LogError::Io {
            file: self.file.clone(),
            reason,
        })?;
        Ok(TOPICS.iter().copied().zip(counts).collect())
    }
}
