//! The per-cycle topics `/state` and `/tf`, built on the log's writer thread.
//!
//! At each logged boundary the simulation hands over what it already has: every robot's
//! joints, its tool link's frame (from the collision check's link frames) and active tool,
//! and every part's pose ([`append_cycle`], a few hundred bytes). The writer thread's
//! [`CycleEncoder`] turns that into the two messages: it computes each TCP (tool link ×
//! tool), the transforms of the joints that moved
//! ([`RobotModel::joint_transform`]: no forward kinematics needed) and encodes `/state`
//! and the `/tf` tree. So the simulation's thread pays a copy per boundary, and the
//! rotations, quaternions and encoding run beside it.
//!
//! The `/tf` tree: `world` → each robot's root link (its base pose) → each link through
//! its joint (parent link → child link, the joint's own transform) → the robot's TCP
//! (`robot:tcp`, under its tool link: the tool the robot moves with — the workcell's
//! `tool`, or a motion's `tool`, a RAPID tooldata); devices and parts under
//! `world`. Between keyframes a joint's transform is sent only when its axis value
//! changed, a TCP when its tool changed, a device or part only when its pose changed; at
//! a keyframe (t = 0, then at least every [`KEYFRAME_NS`]) every frame is sent.

use std::sync::Arc;

use vworks_model::math::Iso;
use vworks_model::model::RobotModel;
use vworks_vm::MAX_AXES;

use super::{Encoding, KEYFRAME_NS, json, proto};
use crate::cell::CellInfo;

/// Bytes of one pose in a cycle record: rotation (9) and translation (3), f64 each.
const POSE_BYTES: usize = 12 * 8;

fn append_pose(b: &mut Vec<u8>, p: &Iso) {
    for v in p.r.iter().flatten().chain(&p.t) {
        b.extend_from_slice(&v.to_le_bytes());
    }
}

/// Appends the payload of one cycle record: for each robot its axis values (its `dof` of
/// them), its tool link's frame in the cell (from `frames[r]`, its link frames) and its
/// active tool (`tools[r]`; the encoder makes the TCP of the two), then each part's pose.
/// [`CycleEncoder::payload_len`] bytes.
pub(crate) fn append_cycle(
    b: &mut Vec<u8>,
    cell: &CellInfo,
    joints: &[[f64; MAX_AXES]],
    frames: &[Vec<Iso>],
    tools: &[Iso],
    parts: &[Iso],
) {
    for (((robot, q), f), tool) in cell.robots.iter().zip(joints).zip(frames).zip(tools) {
        for v in &q[..robot.model.dof()] {
            b.extend_from_slice(&v.to_le_bytes());
        }
        let flange = f
            .get(robot.model.tool_link)
            .copied()
            .unwrap_or(Iso::IDENTITY);
        append_pose(b, &flange);
        append_pose(b, tool);
    }
    for p in parts {
        append_pose(b, p);
    }
}

fn take_pose(payload: &mut &[u8]) -> Iso {
    let mut v = [0.0; 12];
    for x in &mut v {
        *x = take_f64(payload);
    }
    Iso {
        r: [[v[0], v[1], v[2]], [v[3], v[4], v[5]], [v[6], v[7], v[8]]],
        t: [v[9], v[10], v[11]],
    }
}

/// Reads the next f64 of a payload (0 past its end, which [`CycleEncoder::encode`]'s
/// length check rules out).
fn take_f64(payload: &mut &[u8]) -> f64 {
    match payload.split_first_chunk::<8>() {
        Some((bytes, rest)) => {
            *payload = rest;
            f64::from_le_bytes(*bytes)
        }
        None => 0.0,
    }
}

/// The `/tf` frame of robot `robot`'s TCP: `robot:tcp` (a link's frame is `robot.link`,
/// so no link can take its name).
pub fn tcp_frame(robot: &str) -> String {
    format!("{robot}:tcp")
}

/// One robot as the encoder sees it.
struct RobotFrames {
    model: Arc<RobotModel>,
    base: Iso,
    /// The TCP in the tool link last published (NaN before the first keyframe).
    tool: Iso,
    /// Its name as `/state` writes it (JSON: quoted).
    name: String,
    /// The joints the last published link transforms are for.
    published: [f64; MAX_AXES],
}

/// Builds `/state` and `/tf` from cycle records (see the module docs).
pub(crate) struct CycleEncoder {
    encoding: Encoding,
    robots: Vec<RobotFrames>,
    devices: Vec<Iso>,
    parts: usize,
    /// Per frame of the tree, in publishing order (per robot its root link and each
    /// joint's child link; devices; parts): its parent and child ids, encoded.
    frame_ids: Vec<Vec<u8>>,
    /// The last published pose of every device and part.
    published_world: Vec<Iso>,
    /// When the next `/tf` carries every frame.
    next_keyframe: u64,
    /// The part poses of the record being encoded (reused).
    part_poses: Vec<Iso>,
}

impl CycleEncoder {
    pub(crate) fn new(cell: &CellInfo, encoding: Encoding) -> CycleEncoder {
        let mut edges: Vec<(String, String)> = Vec::new();
        for r in &cell.robots {
            let link = |l: usize| format!("{}.{}", r.name, r.model.links[l].name);
            edges.push(("world".into(), link(0)));
            edges.extend(
                r.model
                    .joints
                    .iter()
                    .map(|j| (link(j.parent), link(j.child))),
            );
            edges.push((link(r.model.tool_link), tcp_frame(&r.name)));
        }
        let in_world = cell.devices.iter().chain(&cell.parts);
        edges.extend(in_world.map(|b| ("world".to_string(), b.name.clone())));
        let frame_ids = edges
            .iter()
            .map(|(p, c)| match encoding {
                Encoding::Json => json::frame_ids(p, c),
                Encoding::Protobuf => proto::frame_ids(p, c),
            })
            .collect();
        let robots = cell
            .robots
            .iter()
            .map(|r| RobotFrames {
                model: Arc::clone(&r.model),
                base: r.base,
                tool: Iso {
                    r: [[f64::NAN; 3]; 3],
                    t: [f64::NAN; 3],
                },
                name: match encoding {
                    Encoding::Json => json::quoted(&r.name),
                    Encoding::Protobuf => r.name.clone(),
                },
                published: [f64::NAN; MAX_AXES],
            })
            .collect();
        CycleEncoder {
            encoding,
            robots,
            devices: cell.devices.iter().map(|d| d.pose).collect(),
            parts: cell.parts.len(),
            frame_ids,
            published_world: Vec::new(),
            next_keyframe: 0,
            part_poses: Vec::with_capacity(cell.parts.len()),
        }
    }

    /// Bytes of a cycle record's payload ([`append_cycle`]).
    pub(crate) fn payload_len(&self) -> usize {
        let axes: usize = self.robots.iter().map(|r| r.model.dof()).sum();
        axes * 8 + (2 * self.robots.len() + self.parts) * POSE_BYTES
    }

    /// Encodes the boundary at `time` (the `cycle`-th) from its record `payload`: `/state`
    /// into `state`, `/tf` into `tf` (left empty when no frame is due).
    pub(crate) fn encode(
        &mut self,
        time: u64,
        cycle: u64,
        mut payload: &[u8],
        state: &mut Vec<u8>,
        tf: &mut Vec<u8>,
    ) {
        state.clear();
        tf.clear();
        let json = self.encoding == Encoding::Json;
        let keyframe = time >= self.next_keyframe;
        if keyframe {
            self.next_keyframe = time.saturating_add(KEYFRAME_NS as u64);
        }
        if json {
            json::cycle_state_head(state, time, cycle);
            json::transforms_head(tf);
        } else {
            proto::cycle_state_head(state, time, cycle);
        }
        let mut sent = 0;
        let stamp = proto::Stamp::new(time);
        let mut emit = |b: &mut Vec<u8>, ids: &[u8], pose: &Iso| {
            if json {
                json::frame_transform(b, sent == 0, time, ids, pose);
            } else {
                proto::frame_transform(b, &stamp, ids, pose);
            }
            sent += 1;
        };
        let mut ids = self.frame_ids.iter().map(Vec::as_slice);
        for (i, robot) in self.robots.iter_mut().enumerate() {
            let dof = robot.model.dof();
            let mut q = [0.0; MAX_AXES];
            for v in q.iter_mut().take(dof) {
                *v = take_f64(&mut payload);
            }
            let flange = take_pose(&mut payload);
            let tool = take_pose(&mut payload);
            let tcp = flange.mul(&tool);
            if json {
                json::robot_state(state, i == 0, &robot.name, &q[..dof], &tcp);
            } else {
                proto::robot_state(state, robot.name.as_bytes(), &q[..dof], &tcp);
            }
            // The root link's pose in the world is the robot's base: it never changes.
            let root = ids.next().unwrap_or_default();
            if keyframe {
                emit(tf, root, &robot.base);
            }
            let joint_ids = ids.by_ref().take(robot.model.joints.len());
            let published = &mut robot.published;
            if keyframe || q != *published {
                // A joint's transform changes with its axis value only.
                let moved = |a: Option<usize>| a.is_some_and(|a| q[a] != published[a]);
                for ((j, joint), id) in robot.model.joints.iter().enumerate().zip(joint_ids) {
                    if keyframe || moved(joint.axis_index) {
                        emit(tf, id, &robot.model.joint_transform(j, &q[..dof]));
                    }
                }
                *published = q;
            } else {
                joint_ids.for_each(drop);
            }
            // The TCP in its tool link changes only with the tool a motion moves with.
            let tcp_id = ids.next().unwrap_or_default();
            if keyframe || tool != robot.tool {
                emit(tf, tcp_id, &tool);
                robot.tool = tool;
            }
        }
        self.part_poses.clear();
        for _ in 0..self.parts {
            self.part_poses.push(take_pose(&mut payload));
        }
        let in_world = self.devices.iter().chain(&self.part_poses);
        for ((k, pose), id) in in_world.enumerate().zip(ids) {
            let last = &mut self.published_world;
            let due = keyframe || last.get(k) != Some(pose);
            if due {
                match last.get_mut(k) {
                    Some(l) => *l = *pose,
                    None => last.push(*pose),
                }
                emit(tf, id, pose);
            }
        }
        if json {
            json::cycle_state_tail(state);
            if sent == 0 {
                tf.clear();
            } else {
                json::transforms_tail(tf);
            }
        }
    }
}
