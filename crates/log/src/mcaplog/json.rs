//! JSON encoding of the log's messages: the JSON Schemas of every JSON topic, and the
//! hand-written writers for the per-cycle topics when they are logged as JSON (numbers
//! printed straight into the batch buffer, no allocation).

use vworks_model::math::Iso;

use super::proto::quat;

pub(crate) const EVENT_SCHEMA: &str = r#"{"title":"vworks.Event","type":"object","properties":{"time_ns":{"type":"integer"},"robot":{"type":["string","null"]},"kind":{"type":"string"},"details":{"type":"string"},"file":{"type":["string","null"]},"line":{"type":"integer"},"col":{"type":"integer"},"data":{"type":["object","null"],"description":"the details, typed by kind (docs/log.md)"}}}"#;
pub(crate) const STATE_SCHEMA: &str = r#"{"title":"vworks.CycleState","type":"object","properties":{"time_ns":{"type":"integer"},"cycle":{"type":"integer"},"robots":{"type":"array","items":{"type":"object","properties":{"name":{"type":"string"},"joints":{"type":"array","items":{"type":"number"}},"tcp":{"type":"object","properties":{"position":{"type":"object"},"orientation":{"type":"object"}}}}}}}}"#;
const TIME: &str = r#"{"type":"object","properties":{"sec":{"type":"integer","minimum":0},"nsec":{"type":"integer","minimum":0}}}"#;
const VEC3: &str = r#"{"type":"object","properties":{"x":{"type":"number"},"y":{"type":"number"},"z":{"type":"number"}}}"#;
const QUAT: &str = r#"{"type":"object","properties":{"x":{"type":"number"},"y":{"type":"number"},"z":{"type":"number"},"w":{"type":"number"}}}"#;
const COLOR: &str = r#"{"type":"object","properties":{"r":{"type":"number"},"g":{"type":"number"},"b":{"type":"number"},"a":{"type":"number"}}}"#;

pub(crate) fn tf_schema() -> String {
    format!(
        r#"{{"title":"foxglove.FrameTransforms","type":"object","properties":{{"transforms":{{"type":"array","items":{{"type":"object","properties":{{"timestamp":{TIME},"parent_frame_id":{{"type":"string"}},"child_frame_id":{{"type":"string"}},"translation":{VEC3},"rotation":{QUAT}}}}}}}}}}}"#
    )
}

pub(crate) fn scene_schema() -> String {
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

pub(crate) fn log_schema() -> String {
    format!(
        r#"{{"title":"foxglove.Log","type":"object","properties":{{"timestamp":{TIME},"level":{{"type":"integer"}},"message":{{"type":"string"}},"name":{{"type":"string"}},"file":{{"type":"string"}},"line":{{"type":"integer","minimum":0}}}}}}"#
    )
}

/// `s` as a JSON string literal, quotes included.
pub(crate) fn quoted(s: &str) -> String {
    serde_json::Value::from(s).to_string()
}

fn int(b: &mut Vec<u8>, v: u64) {
    b.extend_from_slice(itoa::Buffer::new().format(v).as_bytes());
}

/// A JSON number; NaN and infinities (never expected) become `null`.
fn num(b: &mut Vec<u8>, v: f64) {
    if v.is_finite() {
        b.extend_from_slice(zmij::Buffer::new().format_finite(v).as_bytes());
    } else {
        b.extend_from_slice(b"null");
    }
}

/// A Foxglove time `{"sec":..,"nsec":..}` of `t` nanoseconds.
fn time(b: &mut Vec<u8>, t: u64) {
    b.extend_from_slice(b"{\"sec\":");
    int(b, t / 1_000_000_000);
    b.extend_from_slice(b",\"nsec\":");
    int(b, t % 1_000_000_000);
    b.push(b'}');
}

/// `"pos":{"x":..,"y":..,"z":..},"rot":{"x":..,"y":..,"z":..,"w":..}` (no braces around).
fn pose_fields(b: &mut Vec<u8>, p: &Iso, pos: &[u8], rot: &[u8]) {
    let q = quat(&p.r);
    b.push(b'"');
    b.extend_from_slice(pos);
    b.extend_from_slice(b"\":{\"x\":");
    num(b, p.t[0]);
    b.extend_from_slice(b",\"y\":");
    num(b, p.t[1]);
    b.extend_from_slice(b",\"z\":");
    num(b, p.t[2]);
    b.extend_from_slice(b"},\"");
    b.extend_from_slice(rot);
    b.extend_from_slice(b"\":{\"x\":");
    num(b, q[0]);
    b.extend_from_slice(b",\"y\":");
    num(b, q[1]);
    b.extend_from_slice(b",\"z\":");
    num(b, q[2]);
    b.extend_from_slice(b",\"w\":");
    num(b, q[3]);
    b.push(b'}');
}

/// The head of a `vworks.CycleState` up to the robots' array, opened.
pub(crate) fn cycle_state_head(b: &mut Vec<u8>, t: u64, cycle: u64) {
    b.extend_from_slice(b"{\"time_ns\":");
    int(b, t);
    b.extend_from_slice(b",\"cycle\":");
    int(b, cycle);
    b.extend_from_slice(b",\"robots\":[");
}

/// One robot of a `vworks.CycleState` (`name` already quoted), after a comma unless first.
pub(crate) fn robot_state(b: &mut Vec<u8>, first: bool, name: &str, joints: &[f64], tcp: &Iso) {
    if !first {
        b.push(b',');
    }
    b.extend_from_slice(b"{\"name\":");
    b.extend_from_slice(name.as_bytes());
    b.extend_from_slice(b",\"joints\":[");
    for (j, q) in joints.iter().enumerate() {
        if j > 0 {
            b.push(b',');
        }
        num(b, *q);
    }
    b.extend_from_slice(b"],\"tcp\":{");
    pose_fields(b, tcp, b"position", b"orientation");
    b.extend_from_slice(b"}}");
}

/// Closes a `vworks.CycleState`.
pub(crate) fn cycle_state_tail(b: &mut Vec<u8>) {
    b.extend_from_slice(b"]}");
}

/// Opens a `FrameTransforms`.
pub(crate) fn transforms_head(b: &mut Vec<u8>) {
    b.extend_from_slice(b"{\"transforms\":[");
}

/// The parent and child frame fields of a `FrameTransform`, written once per frame.
pub(crate) fn frame_ids(parent: &str, child: &str) -> Vec<u8> {
    format!(
        "\"parent_frame_id\":{},\"child_frame_id\":{}",
        quoted(parent),
        quoted(child)
    )
    .into_bytes()
}

/// One `FrameTransform` (`ids` from [`frame_ids`]), after a comma unless first.
pub(crate) fn frame_transform(b: &mut Vec<u8>, first: bool, t: u64, ids: &[u8], pose: &Iso) {
    if !first {
        b.push(b',');
    }
    b.extend_from_slice(b"{\"timestamp\":");
    time(b, t);
    b.push(b',');
    b.extend_from_slice(ids);
    b.push(b',');
    pose_fields(b, pose, b"translation", b"rotation");
    b.push(b'}');
}

/// Closes a `FrameTransforms`.
pub(crate) fn transforms_tail(b: &mut Vec<u8>) {
    b.extend_from_slice(b"]}");
}
