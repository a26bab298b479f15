//! The `/scene` topic: every collision body as Foxglove scene primitives attached to its
//! frame (boxes as cubes, capsules as a cylinder and two spheres, meshes as their convex
//! hull's triangles), in its kind's colour (robots amber, devices slate grey, parts green),
//! and red while it touches another body. Built on the log's
//! writer thread: the convex hulls and the JSON cost the simulation nothing.

use vworks_model::math::Iso;
use vworks_model::model::Geometry;

use super::proto;
use crate::cell::CellInfo;

/// A body of the scene: its frame and primitives.
pub(crate) struct SceneBody {
    frame: String,
    geometry: Geometry,
    /// Shape pose in the frame (URDF convention: cylinders and capsules along z).
    local: Iso,
    /// For a hull: its triangles, three corners each (empty if the hull is degenerate).
    hull: Vec<[f64; 3]>,
    /// Its colour when it touches nothing (r, g, b).
    colour: [f64; 3],
}

/// A robot link's colour.
const ROBOT: [f64; 3] = [0.95, 0.68, 0.22];
/// A device's colour.
const DEVICE: [f64; 3] = [0.55, 0.6, 0.68];
/// A part's colour.
const PART: [f64; 3] = [0.25, 0.65, 0.35];
/// Any body's colour while it touches another.
const TOUCHING: [f64; 3] = [0.9, 0.1, 0.1];

/// The bodies and their colours.
pub(crate) struct Scene {
    bodies: Vec<SceneBody>,
    red: Vec<bool>,
}

/// A mesh body's convex hull as a triangle list (empty for other shapes).
fn hull_triangles(geometry: &Geometry) -> Vec<[f64; 3]> {
    match geometry {
        Geometry::Hull { points, .. } => vworks_model::mesh::hull_triangles(points),
        _ => Vec::new(),
    }
}

/// A Foxglove time of `t` nanoseconds (negative: 0), as JSON.
pub(crate) fn ts(t: i64) -> serde_json::Value {
    serde_json::json!({"sec": t.max(0) / 1_000_000_000, "nsec": t.max(0) % 1_000_000_000})
}

fn pose_json(p: &Iso) -> serde_json::Value {
    let q = proto::quat(&p.r);
    serde_json::json!({"position": {"x": p.t[0], "y": p.t[1], "z": p.t[2]}, "orientation": {"x": q[0], "y": q[1], "z": q[2], "w": q[3]}})
}

impl Scene {
    /// Every body of `cell`: robots' link shapes, devices, parts.
    pub(crate) fn new(cell: &CellInfo) -> Scene {
        let mut bodies = Vec::new();
        for r in &cell.robots {
            for l in &r.model.links {
                for s in &l.shapes {
                    bodies.push(SceneBody {
                        frame: format!("{}.{}", r.name, l.name),
                        hull: hull_triangles(&s.geometry),
                        geometry: s.geometry.clone(),
                        local: s.origin,
                        colour: ROBOT,
                    });
                }
            }
        }
        let devices = cell.devices.iter().map(|d| (d, DEVICE));
        for (d, colour) in devices.chain(cell.parts.iter().map(|p| (p, PART))) {
            bodies.push(SceneBody {
                frame: d.name.clone(),
                hull: hull_triangles(&d.geometry),
                geometry: d.geometry.clone(),
                local: Iso::IDENTITY,
                colour,
            });
        }
        let red = vec![false; bodies.len()];
        Scene { bodies, red }
    }

    /// Bodies of frames `a` and `b` turn red (`on`) or back to grey.
    pub(crate) fn colour(&mut self, a: &str, b: &str, on: bool) {
        for (body, red) in self.bodies.iter().zip(&mut self.red) {
            if body.frame == a || body.frame == b {
                *red = on;
            }
        }
    }

    /// A `SceneUpdate` at `t` of every body, or with `only`, of the bodies whose frame is
    /// one of those.
    pub(crate) fn update(&self, t: i64, only: Option<&[&str]>) -> serde_json::Value {
        let mut entities = Vec::new();
        for (i, b) in self.bodies.iter().enumerate() {
            if only.is_some_and(|o| !o.contains(&b.frame.as_str())) {
                continue;
            }
            let [r, g, bl] = if self.red[i] { TOUCHING } else { b.colour };
            let color = serde_json::json!({"r": r, "g": g, "b": bl, "a": 1.0});
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
        serde_json::json!({"deletions": [], "entities": entities})
    }
}
