//! The report's 3D view and timeline: the HTML around them, the run's playback data as
//! one JSON block, and the page's script (`viewer.js`) with three.js inlined.
//!
//! The data block (`<script type="application/json" id="vworks-playback">`) holds:
//! - `frames`, `parents` (index, or -1), `first` (each frame's first pose in its parent:
//!   base64 `f32`, 7 per frame);
//! - `tracks` (the frames that move: `frame`, `kind` revolute/prismatic/free, `base`,
//!   `axis`), `times` (sample times, ns) and `values` (base64 `f32`, `stride` per sample):
//!   see [`crate::playback`];
//! - `bodies`: each `/scene` entity of the first scene as `frame`, `label`, `colour` and
//!   `shapes` (`box`/`sphere`/`cylinder`/`capsule` with pose and size, `mesh` with pose, shared
//!   vertices as base64 `f32` and three indices per triangle as base64 `u32`);
//! - `colours`: every later `/scene` change as `[time ns, frame, r, g, b]` (red while two
//!   bodies touch, their own colour after);
//! - `tcps`: each robot's TCP frame (`robot:tcp`), for the trail.
//!
//! Without poses (an older log), the view is a note and only the timeline stays; without
//! WebGL, the script says so in one line and the timeline still moves the Gantt cursor.

use std::fmt::Write as _;

use serde_json::{Value, json};
use vworks_log::mcaplog::LogContents;

use crate::playback::{Playback, f32_base64};

/// three.js (with its `OrbitControls`), minified, inlined into every report with a 3D view.
const THREE: &str = include_str!("../vendor/three/three.iife.min.js");
/// The page's script: the 3D view, the timeline, the links from the Gantt chart and tables.
const SCRIPT: &str = include_str!("viewer.js");

/// The playback data of `log` as the page reads it, or why there is none.
pub fn data(log: &LogContents) -> Result<Value, &'static str> {
    if let Some(why) = missing(log) {
        return Err(why);
    }
    let (Some(first_scene), Some(p)) = (log.scene.first(), Playback::from_log(log)) else {
        return Err("this log has no /tf (the frames' poses)");
    };
    let parents: Vec<i64> = p.parents.iter().map(|q| q.map_or(-1, i64::from)).collect();
    let first: Vec<f32> = p.first.iter().flatten().copied().collect();
    let tracks: Vec<Value> = p
        .tracks
        .iter()
        .map(|t| {
            let axis = match t.joint {
                crate::playback::Joint::Revolute { axis }
                | crate::playback::Joint::Prismatic { axis } => axis,
                crate::playback::Joint::Free => [0.0; 3],
            };
            json!({"frame": t.frame, "kind": t.joint.name(), "base": t.base, "axis": axis})
        })
        .collect();
    let bodies: Vec<Value> = first_scene
        .1
        .get("entities")
        .and_then(Value::as_array)
        .map(|es| es.iter().filter_map(body).collect())
        .unwrap_or_default();
    let mut colours = Vec::new();
    for (t, update) in log.scene.iter().skip(1) {
        for e in update
            .get("entities")
            .and_then(Value::as_array)
            .into_iter()
            .flatten()
        {
            if let (Some(frame), Some(c)) = (e.get("frame_id").and_then(Value::as_str), colour(e)) {
                colours.push(json!([t, frame, c[0], c[1], c[2]]));
            }
        }
    }
    let tcps: Vec<&str> = p
        .frames
        .iter()
        .map(String::as_str)
        .filter(|f| f.ends_with(":tcp"))
        .collect();
    Ok(json!({
        "frames": p.frames, "parents": parents, "first": f32_base64(&first),
        "tracks": tracks, "times": p.times_ns, "stride": p.stride(),
        "values": f32_base64(&p.values), "bodies": bodies, "colours": colours, "tcps": tcps,
    }))
}

/// Why `log` gives no 3D view, if it does not: it lacks the shapes (`/scene`) or the
/// poses (`/tf`).
pub fn missing(log: &LogContents) -> Option<&'static str> {
    if log.scene.is_empty() {
        Some("this log has no /scene (the bodies' shapes)")
    } else if log.frames.is_empty() || log.transforms.is_empty() {
        Some("this log has no /tf (the frames' poses)")
    } else {
        None
    }
}

/// Numbers of `v` (a JSON object) under `keys`, in order (`None` if one is missing).
fn numbers(v: &Value, keys: &[&str]) -> Option<Vec<f64>> {
    keys.iter().map(|k| v.get(*k)?.as_f64()).collect()
}

/// A Foxglove pose as 7 numbers (translation, rotation x, y, z, w).
fn pose(v: &Value) -> Option<Vec<f64>> {
    let mut p = numbers(v.get("position")?, &["x", "y", "z"])?;
    p.extend(numbers(v.get("orientation")?, &["x", "y", "z", "w"])?);
    Some(p)
}

/// The colour (r, g, b) of an entity's first primitive.
fn colour(entity: &Value) -> Option<Vec<f64>> {
    ["cubes", "spheres", "cylinders", "triangles"]
        .iter()
        .find_map(|k| entity.get(*k)?.as_array()?.first())
        .and_then(|p| numbers(p.get("color")?, &["r", "g", "b"]))
}

/// A `/scene` entity as the page draws it (`None` if it is not one vworks writes).
fn body(entity: &Value) -> Option<Value> {
    let frame = entity.get("frame_id")?.as_str()?;
    let mut shapes = Vec::new();
    let prims = |k: &str| {
        entity
            .get(k)
            .and_then(Value::as_array)
            .into_iter()
            .flatten()
    };
    for (key, kind) in [
        ("cubes", "box"),
        ("spheres", "sphere"),
        ("cylinders", "cylinder"),
    ] {
        for c in prims(key) {
            let (Some(p), Some(s)) = (pose(c.get("pose")?), c.get("size")) else {
                continue;
            };
            if let Some(size) = numbers(s, &["x", "y", "z"]) {
                shapes.push(json!({"kind": kind, "pose": p, "size": size}));
            }
        }
    }
    for t in prims("triangles") {
        let (Some(p), Some(points)) = (pose(t.get("pose")?), t.get("points")) else {
            continue;
        };
        let corners: Option<Vec<[f32; 3]>> = points
            .as_array()?
            .iter()
            .map(|q| numbers(q, &["x", "y", "z"]).map(|v| [v[0] as f32, v[1] as f32, v[2] as f32]))
            .collect();
        if let Some(corners) = corners.filter(|c| !c.is_empty() && c.len() % 3 == 0) {
            let (vertices, indices) = indexed(&corners);
            let (cv, ci) = coarse(&vertices, &indices, COARSE_CELLS);
            shapes.push(json!({
                "kind": "mesh", "pose": p, "vertices": f32_base64(&vertices),
                "indices": u32_base64(&indices), "coarse_vertices": f32_base64(&cv),
                "coarse_indices": u32_base64(&ci),
            }));
        }
    }
    capsules(&mut shapes);
    let label = match frame.split_once('.') {
        Some((robot, link)) => format!("{robot} · {link}"),
        None => frame.to_string(),
    };
    Some(json!({"frame": frame, "label": label, "colour": colour(entity)?, "shapes": shapes}))
}

/// The log writes a capsule as a cylinder and a sphere at each end of it (Foxglove has no
/// capsule); the page draws one capsule instead, which needs a third of the triangles.
fn capsules(shapes: &mut Vec<Value>) {
    let num = |v: &Value, k: usize| v.as_array().and_then(|a| a.get(k)?.as_f64());
    let mut k = 0;
    while k < shapes.len() {
        let c = &shapes[k];
        if c["kind"] != "cylinder" {
            k += 1;
            continue;
        }
        let (Some(d), Some(d2), Some(length)) =
            (num(&c["size"], 0), num(&c["size"], 1), num(&c["size"], 2))
        else {
            k += 1;
            continue;
        };
        let pose: Vec<f64> = (0..7).filter_map(|i| num(&c["pose"], i)).collect();
        if pose.len() != 7 || d != d2 {
            k += 1;
            continue;
        }
        // The cylinder's axis (its pose's z) and the two ends.
        let q = [pose[3], pose[4], pose[5], pose[6]];
        let z = [
            2.0 * (q[0] * q[2] + q[3] * q[1]),
            2.0 * (q[1] * q[2] - q[3] * q[0]),
            1.0 - 2.0 * (q[0] * q[0] + q[1] * q[1]),
        ];
        let end = |sign: f64| [0, 1, 2].map(|i| pose[i] + sign * length / 2.0 * z[i]);
        let is_cap = |s: &Value, at: [f64; 3]| {
            s["kind"] == "sphere"
                && num(&s["size"], 0).is_some_and(|x| (x - d).abs() <= 1e-9)
                && (0..3).all(|i| num(&s["pose"], i).is_some_and(|x| (x - at[i]).abs() <= 1e-9))
        };
        let lower = shapes.iter().position(|s| is_cap(s, end(-1.0)));
        let upper = shapes.iter().position(|s| is_cap(s, end(1.0)));
        if let (Some(a), Some(b)) = (lower, upper) {
            let capsule = json!({"kind": "capsule", "pose": pose, "size": [d, d, length]});
            shapes[k] = capsule;
            let (first, second) = (a.max(b), a.min(b));
            shapes.remove(first);
            shapes.remove(second);
            k = 0; // indices moved: look again from the start
        } else {
            k += 1;
        }
    }
}

/// A triangle list (three corners per triangle) as shared vertices (x, y, z each) and
/// three indices per triangle: a convex hull's corners are each in about six triangles, so
/// the page transforms a sixth of the vertices (its faces are shaded flat, from the
/// triangles themselves).
fn indexed(corners: &[[f32; 3]]) -> (Vec<f32>, Vec<u32>) {
    let mut index: std::collections::BTreeMap<[u32; 3], u32> = std::collections::BTreeMap::new();
    let mut vertices = Vec::new();
    let indices = corners
        .iter()
        .map(|c| {
            *index.entry(c.map(f32::to_bits)).or_insert_with(|| {
                vertices.extend_from_slice(c);
                (vertices.len() / 3 - 1) as u32
            })
        })
        .collect();
    (vertices, indices)
}

/// Cells across a mesh's largest extent for its coarse version.
pub const COARSE_CELLS: f32 = 8.0;

/// A coarse version of an indexed mesh, by vertex clustering: the vertices in each cell of
/// a grid (`cells` across the largest extent) merge into their mean, and triangles that
/// lose a corner that way go. A software renderer plays back with these (a few hundred
/// triangles per arm instead of thousands) and draws the exact shapes when paused.
pub fn coarse(vertices: &[f32], indices: &[u32], cells: f32) -> (Vec<f32>, Vec<u32>) {
    let mut lo = [f32::INFINITY; 3];
    let mut hi = [f32::NEG_INFINITY; 3];
    for v in vertices.chunks_exact(3) {
        for k in 0..3 {
            lo[k] = lo[k].min(v[k]);
            hi[k] = hi[k].max(v[k]);
        }
    }
    let extent = (0..3).map(|k| hi[k] - lo[k]).fold(0.0f32, f32::max);
    let cell = (extent / cells).max(1e-6);
    let mut cluster: std::collections::BTreeMap<[i32; 3], u32> = std::collections::BTreeMap::new();
    let mut sums: Vec<[f32; 4]> = Vec::new();
    let remap: Vec<u32> = vertices
        .chunks_exact(3)
        .map(|v| {
            let key = [0, 1, 2].map(|k| ((v[k] - lo[k]) / cell).floor() as i32);
            let c = *cluster.entry(key).or_insert_with(|| {
                sums.push([0.0; 4]);
                (sums.len() - 1) as u32
            });
            let s = &mut sums[c as usize];
            for k in 0..3 {
                s[k] += v[k];
            }
            s[3] += 1.0;
            c
        })
        .collect();
    let out_vertices = sums
        .iter()
        .flat_map(|s| [s[0] / s[3], s[1] / s[3], s[2] / s[3]])
        .collect();
    let mut out_indices = Vec::new();
    for t in indices.chunks_exact(3) {
        let Some(m) = t
            .iter()
            .map(|&i| remap.get(i as usize).copied())
            .collect::<Option<Vec<u32>>>()
        else {
            continue;
        };
        if m[0] != m[1] && m[1] != m[2] && m[0] != m[2] {
            out_indices.extend_from_slice(&m);
        }
    }
    (out_vertices, out_indices)
}

/// `values` as little-endian `u32` bytes in base64 (a `Uint32Array` in the page).
fn u32_base64(values: &[u32]) -> String {
    let bytes: Vec<u8> = values.iter().flat_map(|v| v.to_le_bytes()).collect();
    crate::playback::base64(&bytes)
}

/// The 3D view (or the note that stands in for it) and the timeline, for the top of the
/// page; `end_ns` is the run's span.
pub fn section(log: &LogContents, end_ns: i64) -> String {
    let mut s = String::new();
    s.push_str("<section id=\"view\">\n");
    let data = data(log);
    match &data {
        Ok(_) => s.push_str(
            "<div id=\"stage\"><canvas id=\"canvas3d\" aria-label=\"the cell in 3D at the timeline's time\"></canvas>\
<div id=\"view-tools\"><button id=\"reset-view\" type=\"button\">Reset view</button>\
<label><input id=\"trail\" type=\"checkbox\"> TCP trail</label></div>\
<div id=\"tip\" hidden></div><p id=\"view-note\" class=\"note\" hidden></p></div>\n",
        ),
        Err(why) => {
            let _ = writeln!(
                s,
                "<div id=\"stage\" class=\"empty\"><p id=\"view-note\" class=\"note\">No 3D view: {}. Logs that `vworks run CELL --log run.mcap` writes today carry both.</p></div>",
                esc(why)
            );
        }
    }
    let _ = writeln!(
        s,
        "<div id=\"timeline\" data-end-ns=\"{end}\"><button id=\"play\" type=\"button\">Play</button>\
<label>speed <select id=\"speed\" aria-label=\"playback speed\"><option value=\"0.25\">0.25×</option><option value=\"0.5\">0.5×</option><option value=\"1\" selected>1×</option><option value=\"2\">2×</option><option value=\"4\">4×</option><option value=\"8\">8×</option></select></label>\
<input id=\"slider\" type=\"range\" min=\"0\" max=\"{end_s}\" step=\"0.001\" value=\"0\" aria-label=\"simulated time\">\
<span id=\"clock\">0.000 s</span></div>",
        end = end_ns.max(0),
        end_s = end_ns.max(0) as f64 / 1e9,
    );
    if let Ok(d) = data {
        // `<` escaped so that no string in the data can close the script element.
        let json = d.to_string().replace('<', "\\u003c");
        let _ = writeln!(
            s,
            "<script type=\"application/json\" id=\"vworks-playback\">{json}</script>\n<script>{THREE}</script>"
        );
    }
    s.push_str("</section>\n");
    s
}

/// The page's script (after the Gantt chart and the tables it links to).
pub fn script() -> String {
    format!("<script>\n{SCRIPT}</script>\n")
}

/// The CSS of the view and the timeline.
pub const STYLE: &str = r#"
[hidden] { display: none !important; }
#stage { position: relative; height: 460px; border: 1px solid #d8dde3; border-radius: 4px; background: linear-gradient(#fbfcfd, #e4e9ee); overflow: hidden; }
#stage.empty { height: auto; min-height: 60px; display: flex; align-items: center; padding: 0 16px; }
#canvas3d { display: block; width: 100%; height: 100%; }
#view-tools { position: absolute; top: 8px; right: 8px; display: flex; gap: 10px; align-items: center; background: rgba(255,255,255,0.8); padding: 4px 8px; border-radius: 4px; }
#tip { position: absolute; pointer-events: none; background: rgba(20,20,20,0.85); color: #fff; padding: 2px 7px; border-radius: 3px; font-size: 12px; white-space: nowrap; }
.note { color: #666; margin: 8px 0; } #stage .note { position: absolute; left: 12px; bottom: 4px; } #stage.empty .note { position: static; }
#timeline { display: flex; align-items: center; gap: 12px; margin: 8px 0 4px; }
#timeline #slider { flex: 1; } #clock { font-variant-numeric: tabular-nums; min-width: 80px; text-align: right; }
#play { min-width: 70px; }
#gantt { cursor: pointer; } tr[data-t] { cursor: pointer; } tr[data-t]:hover { background: #f2f6fc; }
"#;

/// Escapes text for HTML.
pub(crate) fn esc(s: &str) -> String {
    let mut out = String::with_capacity(s.len());
    for c in s.chars() {
        match c {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' => out.push_str("&quot;"),
            '\'' => out.push_str("&#39;"),
            c => out.push(c),
        }
    }
    out
}
