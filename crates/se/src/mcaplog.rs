//! The MCAP log of a run: every event, every cycle's state, and the cell's geometry, so
//! one file replays the whole run in Foxglove without plugins.
//!
//! Topics (all JSON-encoded, chunked and zstd-compressed; see `docs/log.md`):
//! - `/events` (`vworks.Event`): one message per event — time, robot, kind, details,
//!   source position — the same content as a trace line.
//! - `/state` (`vworks.CycleState`): per cycle boundary (every `every`-th), every robot's
//!   joints and TCP.
//! - `/tf` (`foxglove.FrameTransforms`): per logged boundary, every link, device and part
//!   frame in the `world` frame.
//! - `/scene` (`foxglove.SceneUpdate`): the bodies' geometry attached to those frames
//!   (boxes as cubes, capsules as a cylinder and two spheres, meshes as their convex
//!   hull's triangles), at the start and whenever a body's collision colour changes (red
//!   while touching).
//! - `/log` (`foxglove.Log`): `log` output, warnings and errors.
//!
//! The workcell file, every program source, every URDF and every mesh are attachments;
//! `vworks` metadata holds the version, the cell name, the cycle and the seed. The file is finished (summary, CRCs) when
//! [`McapLog::finish`] runs, which the engine does for every outcome.

use std::collections::BTreeMap;
use std::fs::File;
use std::io::BufWriter;
use std::path::Path;

use foxglove::messages::{FrameTransform, FrameTransforms, Quaternion, Timestamp, Vector3};
use prost::Message as _;
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

const EVENT_SCHEMA: &str = r#"{"title":"vworks.Event","type":"object","properties":{"time_ns":{"type":"integer"},"robot":{"type":["string","null"]},"kind":{"type":"string"},"details":{"type":"string"},"file":{"type":["string","null"]},"line":{"type":"integer"},"col":{"type":"integer"}}}"#;
const STATE_SCHEMA: &str = r#"{"title":"vworks.CycleState","type":"object","properties":{"time_ns":{"type":"integer"},"cycle":{"type":"integer"},"robots":{"type":"array","items":{"type":"object","properties":{"name":{"type":"string"},"joints":{"type":"array","items":{"type":"number"}},"tcp":{"type":"object","properties":{"position":{"type":"object"},"orientation":{"type":"object"}}}}}}}}"#;
const TIME: &str = r#"{"type":"object","properties":{"sec":{"type":"integer","minimum":0},"nsec":{"type":"integer","minimum":0}}}"#;
const VEC3: &str = r#"{"type":"object","properties":{"x":{"type":"number"},"y":{"type":"number"},"z":{"type":"number"}}}"#;
const QUAT: &str = r#"{"type":"object","properties":{"x":{"type":"number"},"y":{"type":"number"},"z":{"type":"number"},"w":{"type":"number"}}}"#;
const COLOR: &str = r#"{"type":"object","properties":{"r":{"type":"number"},"g":{"type":"number"},"b":{"type":"number"},"a":{"type":"number"}}}"#;

fn tf_schema() -> String {
    format!(
        r#"{{"title":"foxglove.FrameTransforms","type":"object","properties":{{"transforms":{{"type":"array","items":{{"type":"object","properties":{{"timestamp":{TIME},"parent_frame_id":{{"type":"string"}},"child_frame_id":{{"type":"string"}},"translation":{VEC3},"rotation":{QUAT}}}}}}}}}}}"#
    )
}

fn scene_schema() -> String {
    let pose =
        format!(r#"{{"type":"object","properties":{{"position":{VEC3},"orientation":{QUAT}}}}}"#);
    let prim = |extra: &str| {
        format!(
            r#"{{"type":"array","items":{{"type":"object","properties":{{"pose":{pose},"size":{VEC3},"color":{COLOR}{extra}}}}}}}"#
        )
    };
    format!(
        r#"{{"title":"foxglove.SceneUpdate","type":"object","properties":{{"deletions":{{"type":"array"}},"entities":{{"type":"array","items":{{"type":"object","properties":{{"timestamp":{TIME},"frame_id":{{"type":"string"}},"id":{{"type":"string"}},"lifetime":{TIME},"frame_locked":{{"type":"boolean"}},"metadata":{{"type":"array"}},"arrows":{{"type":"array"}},"cubes":{},"spheres":{},"cylinders":{},"lines":{{"type":"array"}},"triangles":{{"type":"array"}},"texts":{{"type":"array"}},"models":{{"type":"array"}}}}}}}}}}}}"#,
        prim(""),
        prim(""),
        prim(r#","bottom_scale":{"type":"number"},"top_scale":{"type":"number"}"#)
    )
}

fn log_schema() -> String {
    format!(
        r#"{{"title":"foxglove.Log","type":"object","properties":{{"timestamp":{TIME},"level":{{"type":"integer"}},"message":{{"type":"string"}},"name":{{"type":"string"}},"file":{{"type":"string"}},"line":{{"type":"integer","minimum":0}}}}}}"#
    )
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

/// Whether frame `i` (in publishing order) goes into this `/tf` message: at a keyframe,
/// or when it moved since it was last published; records it as published if so.
fn publish_frame(last: &mut Vec<Iso>, i: usize, pose: &Iso, keyframe: bool) -> bool {
    if !keyframe && last.get(i) == Some(pose) {
        return false;
    }
    match last.get_mut(i) {
        Some(l) => *l = *pose,
        None => last.push(*pose),
    }
    true
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
    w: mcap::Writer<BufWriter<File>>,
    file: String,
    events: u16,
    state: u16,
    tf: u16,
    scene: u16,
    log: u16,
    seq: u32,
    every: u64,
    boundary: u64,
    bodies: Vec<SceneBody>,
    red: Vec<bool>,
    buf: Vec<u8>,
    /// Messages written per topic, indexed like [`TOPICS`].
    counts: [u64; 5],
    /// Frame and robot names, JSON-quoted once.
    names: Names,
    /// Every frame's last published pose, in publishing order (robots' links, devices, parts).
    last_frames: Vec<Iso>,
    /// When the next `/tf` message carries every frame, not only the moved ones.
    next_keyframe: i64,
    tf_encoding: TfEncoding,
    /// One protobuf transform per frame (names filled once), updated in place.
    tf_frames: Vec<FrameTransform>,
}

/// How `/tf` is encoded. Both are Foxglove's `FrameTransforms`; `docs/log.md` has the
/// measurements behind the default.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[non_exhaustive]
pub enum TfEncoding {
    /// Protobuf, with the schema from the `foxglove` crate (the default: smaller, faster).
    #[default]
    Protobuf,
    /// JSON with a JSON schema written here.
    Json,
}

/// Options for [`McapLog::create_with`].
#[derive(Clone, Copy, Debug)]
#[non_exhaustive]
pub struct LogOptions {
    /// Log every `every`-th cycle boundary's state (1 = all; events are never thinned).
    pub every: u64,
    /// The `/tf` encoding.
    pub tf_encoding: TfEncoding,
}

impl Default for LogOptions {
    fn default() -> LogOptions {
        LogOptions {
            every: 1,
            tf_encoding: TfEncoding::Protobuf,
        }
    }
}

impl LogOptions {
    /// Every `every`-th state, `/tf` encoded as `tf_encoding`.
    pub fn new(every: u64, tf_encoding: TfEncoding) -> LogOptions {
        LogOptions { every, tf_encoding }
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

/// Names as JSON string literals (with quotes), built once when the log is created.
struct Names {
    robots: Vec<String>,
    links: Vec<Vec<String>>,
    devices: Vec<String>,
    parts: Vec<String>,
}

fn quoted(s: &str) -> String {
    serde_json::Value::from(s).to_string()
}

fn json_int(b: &mut Vec<u8>, v: i64) {
    b.extend_from_slice(itoa::Buffer::new().format(v).as_bytes());
}

/// A JSON number; NaN and infinities (never expected) become `null`.
fn json_num(b: &mut Vec<u8>, v: f64) {
    if v.is_finite() {
        b.extend_from_slice(zmij::Buffer::new().format_finite(v).as_bytes());
    } else {
        b.extend_from_slice(b"null");
    }
}

fn json_time(b: &mut Vec<u8>, t: i64) {
    let t = t.max(0);
    b.extend_from_slice(b"{\"sec\":");
    json_int(b, t / 1_000_000_000);
    b.extend_from_slice(b",\"nsec\":");
    json_int(b, t % 1_000_000_000);
    b.push(b'}');
}

/// `"pos":{"x":..,"y":..,"z":..},"rot":{"x":..,"y":..,"z":..,"w":..}` (no braces around).
fn json_pose_fields(b: &mut Vec<u8>, p: &Iso, pos: &[u8], rot: &[u8]) {
    let q = quat(&p.r);
    b.push(b'"');
    b.extend_from_slice(pos);
    b.extend_from_slice(b"\":{\"x\":");
    json_num(b, p.t[0]);
    b.extend_from_slice(b",\"y\":");
    json_num(b, p.t[1]);
    b.extend_from_slice(b",\"z\":");
    json_num(b, p.t[2]);
    b.extend_from_slice(b"},\"");
    b.extend_from_slice(rot);
    b.extend_from_slice(b"\":{\"x\":");
    json_num(b, q[0]);
    b.extend_from_slice(b",\"y\":");
    json_num(b, q[1]);
    b.extend_from_slice(b",\"z\":");
    json_num(b, q[2]);
    b.extend_from_slice(b",\"w\":");
    json_num(b, q[3]);
    b.push(b'}');
}

fn json_pose(b: &mut Vec<u8>, p: &Iso, pos: &[u8], rot: &[u8]) {
    b.push(b'{');
    json_pose_fields(b, p, pos, rot);
    b.push(b'}');
}

impl std::fmt::Debug for McapLog {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("McapLog")
            .field("file", &self.file)
            .field("counts", &self.counts)
            .finish()
    }
}

fn ts(t: i64) -> serde_json::Value {
    serde_json::json!({"sec": t.max(0) / 1_000_000_000, "nsec": t.max(0) % 1_000_000_000})
}

fn quat(r: &[[f64; 3]; 3]) -> [f64; 4] {
    // Shepperd's method.
    let tr = r[0][0] + r[1][1] + r[2][2];
    let (x, y, z, w);
    if tr > 0.0 {
        let s = (tr + 1.0).sqrt() * 2.0;
        w = 0.25 * s;
        x = (r[2][1] - r[1][2]) / s;
        y = (r[0][2] - r[2][0]) / s;
        z = (r[1][0] - r[0][1]) / s;
    } else if r[0][0] > r[1][1] && r[0][0] > r[2][2] {
        let s = (1.0 + r[0][0] - r[1][1] - r[2][2]).sqrt() * 2.0;
        w = (r[2][1] - r[1][2]) / s;
        x = 0.25 * s;
        y = (r[0][1] + r[1][0]) / s;
        z = (r[0][2] + r[2][0]) / s;
    } else if r[1][1] > r[2][2] {
        let s = (1.0 + r[1][1] - r[0][0] - r[2][2]).sqrt() * 2.0;
        w = (r[0][2] - r[2][0]) / s;
        x = (r[0][1] + r[1][0]) / s;
        y = 0.25 * s;
        z = (r[1][2] + r[2][1]) / s;
    } else {
        let s = (1.0 + r[2][2] - r[0][0] - r[1][1]).sqrt() * 2.0;
        w = (r[1][0] - r[0][1]) / s;
        x = (r[0][2] + r[2][0]) / s;
        y = (r[1][2] + r[2][1]) / s;
        z = 0.25 * s;
    }
    [x, y, z, w]
}

fn pose_json(p: &Iso) -> serde_json::Value {
    let q = quat(&p.r);
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
        let io = |e: &dyn std::fmt::Display| LogError::Io {
            file: file.clone(),
            reason: e.to_string(),
        };
        let f = File::create(path).map_err(|e| io(&e))?;
        let mut w = mcap::WriteOptions::new()
            .compression(Some(mcap::Compression::Zstd))
            .compression_level(1)
            .chunk_size(Some(1 << 20))
            .profile("")
            .create(BufWriter::new(f))
            .map_err(|e| io(&e))?;
        let none = BTreeMap::new();
        let channel = |w: &mut mcap::Writer<BufWriter<File>>,
                       name: &str,
                       schema: &str,
                       topic: &str|
         -> Result<u16, LogError> {
            let s = w
                .add_schema(name, "jsonschema", schema.as_bytes())
                .map_err(|e| io(&e))?;
            w.add_channel(s, topic, "json", &none).map_err(|e| io(&e))
        };
        let events = channel(&mut w, "vworks.Event", EVENT_SCHEMA, TOPICS[EVENTS])?;
        let state = channel(&mut w, "vworks.CycleState", STATE_SCHEMA, TOPICS[STATE])?;
        let tf = match options.tf_encoding {
            TfEncoding::Json => {
                channel(&mut w, "foxglove.FrameTransforms", &tf_schema(), TOPICS[TF])?
            }
            TfEncoding::Protobuf => {
                let schema =
                    <FrameTransforms as foxglove::Encode>::get_schema().ok_or_else(|| {
                        LogError::Io {
                            file: file.clone(),
                            reason: "the foxglove crate has no FrameTransforms schema".into(),
                        }
                    })?;
                let s = w
                    .add_schema(&schema.name, &schema.encoding, &schema.data)
                    .map_err(|e| io(&e))?;
                w.add_channel(s, TOPICS[TF], "protobuf", &none)
                    .map_err(|e| io(&e))?
            }
        };
        let scene = channel(
            &mut w,
            "foxglove.SceneUpdate",
            &scene_schema(),
            TOPICS[SCENE],
        )?;
        let log = channel(&mut w, "foxglove.Log", &log_schema(), TOPICS[LOG])?;
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
        let mut log = McapLog {
            w,
            file,
            events,
            state,
            tf,
            scene,
            log,
            seq: 0,
            every: every.max(1),
            boundary: 0,
            bodies,
            red,
            buf: Vec::with_capacity(4096),
            counts: [0; 5],
            last_frames: Vec::new(),
            tf_encoding: options.tf_encoding,
            tf_frames: cell
                .robots
                .iter()
                .flat_map(|r| {
                    r.model
                        .links
                        .iter()
                        .map(|l| format!("{}.{}", r.name, l.name))
                })
                .chain(cell.devices.iter().map(|d| d.name.clone()))
                .chain(cell.parts.iter().map(|p| p.name.clone()))
                .map(|child| FrameTransform {
                    timestamp: None,
                    parent_frame_id: "world".into(),
                    child_frame_id: child,
                    translation: None,
                    rotation: None,
                })
                .collect(),
            next_keyframe: 0,
            names: Names {
                robots: cell.robots.iter().map(|r| quoted(&r.name)).collect(),
                links: cell
                    .robots
                    .iter()
                    .map(|r| {
                        r.model
                            .links
                            .iter()
                            .map(|l| quoted(&format!("{}.{}", r.name, l.name)))
                            .collect()
                    })
                    .collect(),
                devices: cell.devices.iter().map(|d| quoted(&d.name)).collect(),
                parts: cell.parts.iter().map(|p| quoted(&p.name)).collect(),
            },
        };
        log.write_scene(0, None)?;
        Ok(log)
    }

    fn write(
        &mut self,
        channel: u16,
        topic: usize,
        t: i64,
        value: &serde_json::Value,
    ) -> Result<(), LogError> {
        let mut b = std::mem::take(&mut self.buf);
        b.clear();
        let r = serde_json::to_writer(&mut b, value)
            .map_err(|e| LogError::Io {
                file: self.file.clone(),
                reason: e.to_string(),
            })
            .and_then(|()| self.write_buf(channel, topic, t, &b));
        self.buf = b;
        r
    }

    /// Writes one encoded message and counts it.
    fn write_buf(
        &mut self,
        channel: u16,
        topic: usize,
        t: i64,
        data: &[u8],
    ) -> Result<(), LogError> {
        self.seq = self.seq.wrapping_add(1);
        let header = mcap::records::MessageHeader {
            channel_id: channel,
            sequence: self.seq,
            log_time: t.max(0) as u64,
            publish_time: t.max(0) as u64,
        };
        self.w
            .write_to_known_channel(&header, data)
            .map_err(|e| LogError::Io {
                file: self.file.clone(),
                reason: e.to_string(),
            })?;
        self.counts[topic] += 1;
        Ok(())
    }

    /// `/tf` as protobuf `FrameTransforms`: each moved frame (every frame at a keyframe)
    /// as one length-delimited `transforms` entry (field 1), appended to `b`.
    fn tf_protobuf(
        &mut self,
        b: &mut Vec<u8>,
        t: i64,
        keyframe: bool,
        frames: &[Vec<Iso>],
        devices: &[crate::workcell::Body],
        parts: &[Iso],
    ) -> Result<(), LogError> {
        b.clear();
        let tt = t.max(0);
        let stamp = Timestamp::new(
            u32::try_from(tt / 1_000_000_000).unwrap_or(u32::MAX),
            (tt % 1_000_000_000) as u32,
        );
        let poses = frames
            .iter()
            .flatten()
            .chain(devices.iter().map(|d| &d.pose))
            .chain(parts);
        for (i, pose) in poses.enumerate() {
            if !publish_frame(&mut self.last_frames, i, pose, keyframe) {
                continue;
            }
            let Some(msg) = self.tf_frames.get_mut(i) else {
                continue;
            };
            let q = quat(&pose.r);
            msg.timestamp = Some(stamp);
            msg.translation = Some(Vector3 {
                x: pose.t[0],
                y: pose.t[1],
                z: pose.t[2],
            });
            msg.rotation = Some(Quaternion {
                x: q[0],
                y: q[1],
                z: q[2],
                w: q[3],
            });
            b.push(0x0a); // field 1, length-delimited
            msg.encode_length_delimited(b).map_err(|e| LogError::Io {
                file: self.file.clone(),
                reason: e.to_string(),
            })?;
        }
        if b.is_empty() {
            return Ok(()); // nothing moved
        }
        self.write_buf(self.tf, TF, t, b)
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
            SCENE,
            t,
            &serde_json::json!({"deletions": [], "entities": entities}),
        )
    }

    /// Logs an event (and, for `log`, `warning` and `error`, a Foxglove log message); on
    /// `collision_start`/`collision_end` the two bodies change colour.
    pub fn event(&mut self, cell: &Cell, e: &TraceEvent) -> Result<(), LogError> {
        let robot = e.robot.map(|r| cell.robots[r].name.clone());
        let (file, line, col) = e
            .pos
            .as_ref()
            .map_or((None, 0, 0), |(f, p)| (Some(f.to_string()), p.line, p.col));
        let v = serde_json::json!({"time_ns": e.time, "robot": robot, "kind": e.kind, "details": e.details, "file": file, "line": line, "col": col});
        self.write(self.events, EVENTS, e.time, &v)?;
        let level = match e.kind {
            "log" => Some(2),
            "warning" => Some(3),
            "error" => Some(4),
            _ => None,
        };
        if let Some(level) = level {
            let v = serde_json::json!({"timestamp": ts(e.time), "level": level, "message": e.details.trim_matches('"'), "name": robot.unwrap_or_else(|| "cell".into()), "file": file.unwrap_or_default(), "line": line});
            self.write(self.log, LOG, e.time, &v)?;
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
    pub fn logs_next_boundary(&self) -> bool {
        self.boundary.is_multiple_of(self.every)
    }

    /// Counts a boundary that is not logged without computing its state.
    pub fn skip_boundary(&mut self) {
        self.boundary += 1;
    }

    /// Logs a cycle boundary (every `every`-th): state and frames. `frames[r]` holds robot
    /// r's link frames in the cell, `parts` the parts' poses.
    pub fn cycle(
        &mut self,
        cell: &Cell,
        t: i64,
        joints: &[Vec<f64>],
        frames: &[Vec<Iso>],
        parts: &[Iso],
    ) -> Result<(), LogError> {
        let k = self.boundary;
        self.boundary += 1;
        if !k.is_multiple_of(self.every) {
            return Ok(());
        }
        // Written straight into the reused buffer: no allocation per cycle.
        let mut b = std::mem::take(&mut self.buf);
        b.clear();
        b.extend_from_slice(b"{\"time_ns\":");
        json_int(&mut b, t);
        b.extend_from_slice(b",\"cycle\":");
        json_int(&mut b, k as i64);
        b.extend_from_slice(b",\"robots\":[");
        for (r, robot) in cell.robots.iter().enumerate() {
            if r > 0 {
                b.push(b',');
            }
            b.extend_from_slice(b"{\"name\":");
            b.extend_from_slice(self.names.robots[r].as_bytes());
            b.extend_from_slice(b",\"joints\":[");
            for (j, q) in joints[r].iter().enumerate() {
                if j > 0 {
                    b.push(b',');
                }
                json_num(&mut b, *q);
            }
            b.extend_from_slice(b"],\"tcp\":");
            let tcp = frames[r][robot.model.tool_link].mul(&robot.tool);
            json_pose(&mut b, &tcp, b"position", b"orientation");
            b.push(b'}');
        }
        b.extend_from_slice(b"]}");
        let r = self.write_buf(self.state, STATE, t, &b);
        b.clear();
        // Frame transforms: every frame at a keyframe, in between only the frames that moved.
        let keyframe = t >= self.next_keyframe;
        if keyframe {
            self.next_keyframe = t + KEYFRAME_NS;
        }
        if self.tf_encoding == TfEncoding::Protobuf {
            let r2 = self.tf_protobuf(&mut b, t, keyframe, frames, &cell.devices, parts);
            self.buf = b;
            return r.and(r2);
        }
        b.extend_from_slice(b"{\"transforms\":[");
        let mut first = true;
        let mut slot = 0;
        let last = &mut self.last_frames;
        let mut transform = |b: &mut Vec<u8>, name: &str, pose: &Iso| {
            let i = slot;
            slot += 1;
            if !publish_frame(last, i, pose, keyframe) {
                return;
            }
            if !first {
                b.push(b',');
            }
            first = false;
            b.extend_from_slice(b"{\"timestamp\":");
            json_time(b, t);
            b.extend_from_slice(b",\"parent_frame_id\":\"world\",\"child_frame_id\":");
            b.extend_from_slice(name.as_bytes());
            b.push(b',');
            json_pose_fields(b, pose, b"translation", b"rotation");
            b.push(b'}');
        };
        for (r, names) in self.names.links.iter().enumerate() {
            for (l, name) in names.iter().enumerate() {
                transform(&mut b, name, &frames[r][l]);
            }
        }
        for (d, name) in cell.devices.iter().zip(&self.names.devices) {
            transform(&mut b, name, &d.pose);
        }
        for (p, name) in parts.iter().zip(&self.names.parts) {
            transform(&mut b, name, p);
        }
        b.extend_from_slice(b"]}");
        let r2 = if first {
            Ok(()) // nothing moved
        } else {
            self.write_buf(self.tf, TF, t, &b)
        };
        self.buf = b;
        r.and(r2)
    }

    /// Finishes the file: summary, indexes, CRCs. Returns the counts per topic.
    pub fn finish(mut self) -> Result<BTreeMap<&'static str, u64>, LogError> {
        self.w.finish().map_err(|e| LogError::Io {
            file: self.file.clone(),
            reason: e.to_string(),
        })?;
        Ok(TOPICS.iter().copied().zip(self.counts).collect())
    }
}
