//! Protobuf encoding of the per-cycle topics, written by hand into the log's batch buffer
//! (no message structs, no allocation): `/tf` as Foxglove's `FrameTransforms` and `/state`
//! as `vworks.CycleState`, whose descriptor ([`cycle_state_descriptor`]) is built here.
//!
//! The bytes are exactly what prost would write for the same values (fields in tag order,
//! proto3 defaults omitted, repeated doubles packed); the unit tests compare the two.

use prost::Message as _;
use prost_types::field_descriptor_proto::{Label, Type};
use prost_types::{DescriptorProto, FieldDescriptorProto, FileDescriptorProto, FileDescriptorSet};
use vworks_model::math::Iso;

/// Wire type of varints.
const VARINT: u32 = 0;
/// Wire type of 64-bit values (doubles).
const FIXED64: u32 = 1;
/// Wire type of length-delimited values (strings, messages, packed repeats).
const LEN: u32 = 2;

#[inline]
pub(crate) fn varint(b: &mut Vec<u8>, mut v: u64) {
    while v >= 0x80 {
        b.push((v as u8) | 0x80);
        v >>= 7;
    }
    b.push(v as u8);
}

#[inline]
fn key(b: &mut Vec<u8>, field: u32, wire: u32) {
    varint(b, u64::from((field << 3) | wire));
}

/// A `double` field; 0 is the default and is not written.
#[inline]
fn double(b: &mut Vec<u8>, field: u32, v: f64) {
    if v != 0.0 {
        key(b, field, FIXED64);
        b.extend_from_slice(&v.to_le_bytes());
    }
}

/// An unsigned integer field; 0 is the default and is not written.
#[inline]
fn uint(b: &mut Vec<u8>, field: u32, v: u64) {
    if v != 0 {
        key(b, field, VARINT);
        varint(b, v);
    }
}

/// A `string`/`bytes` field; empty is the default and is not written.
#[inline]
pub(crate) fn bytes(b: &mut Vec<u8>, field: u32, data: &[u8]) {
    if !data.is_empty() {
        key(b, field, LEN);
        varint(b, data.len() as u64);
        b.extend_from_slice(data);
    }
}

/// The unit quaternion (x, y, z, w) of a rotation matrix (Shepperd's method: the largest
/// of w, x, y, z is found from the diagonal, the others from one reciprocal).
#[inline]
pub(crate) fn quat(r: &[[f64; 3]; 3]) -> [f64; 4] {
    let tr = r[0][0] + r[1][1] + r[2][2];
    if tr > 0.0 {
        let s = (tr + 1.0).sqrt() * 2.0;
        let k = 1.0 / s;
        [
            (r[2][1] - r[1][2]) * k,
            (r[0][2] - r[2][0]) * k,
            (r[1][0] - r[0][1]) * k,
            0.25 * s,
        ]
    } else if r[0][0] > r[1][1] && r[0][0] > r[2][2] {
        let s = (1.0 + r[0][0] - r[1][1] - r[2][2]).sqrt() * 2.0;
        let k = 1.0 / s;
        [
            0.25 * s,
            (r[0][1] + r[1][0]) * k,
            (r[0][2] + r[2][0]) * k,
            (r[2][1] - r[1][2]) * k,
        ]
    } else if r[1][1] > r[2][2] {
        let s = (1.0 + r[1][1] - r[0][0] - r[2][2]).sqrt() * 2.0;
        let k = 1.0 / s;
        [
            (r[0][1] + r[1][0]) * k,
            0.25 * s,
            (r[1][2] + r[2][1]) * k,
            (r[0][2] - r[2][0]) * k,
        ]
    } else {
        let s = (1.0 + r[2][2] - r[0][0] - r[1][1]).sqrt() * 2.0;
        let k = 1.0 / s;
        [
            (r[0][2] + r[2][0]) * k,
            (r[1][2] + r[2][1]) * k,
            0.25 * s,
            (r[1][0] - r[0][1]) * k,
        ]
    }
}

/// Bytes of a varint.
#[inline]
fn varint_len(v: u64) -> usize {
    // 1 byte per 7 bits, at least one.
    (64 - (v | 1).leading_zeros() as usize).div_ceil(7)
}

/// Bytes of a message of `double` fields 1.. holding `v` (zeros are not written).
#[inline]
fn doubles_len(v: &[f64]) -> usize {
    v.iter().filter(|x| **x != 0.0).count() * 9
}

/// A message field of `double` fields 1.. holding `v` (Foxglove's and our `Vector3` and
/// `Quaternion`), its length computed first.
#[inline]
fn doubles_message(b: &mut Vec<u8>, field: u32, v: &[f64]) {
    key(b, field, LEN);
    b.push(doubles_len(v) as u8); // at most 4 × 9 bytes: one length byte
    for (x, tag) in v.iter().zip(1..) {
        double(b, tag, *x);
    }
}

/// The parent and child frame ids of a `FrameTransform` (fields 2 and 3), encoded once per
/// frame when the log is created.
pub(crate) fn frame_ids(parent: &str, child: &str) -> Vec<u8> {
    let mut b = Vec::with_capacity(parent.len() + child.len() + 6);
    bytes(&mut b, 2, parent.as_bytes());
    bytes(&mut b, 3, child.as_bytes());
    b
}

/// A `FrameTransform`'s `timestamp` field (field 1), encoded once for all the transforms
/// of a message.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Stamp {
    bytes: [u8; 16],
    len: usize,
}

impl Stamp {
    /// The timestamp of `time` ns (≥ 0): seconds (saturating at `u32::MAX`) and nanoseconds.
    pub(crate) fn new(time: u64) -> Stamp {
        let (sec, nsec) = (
            (time / 1_000_000_000).min(u64::from(u32::MAX)),
            time % 1_000_000_000,
        );
        let mut b = Vec::with_capacity(16);
        let body = usize::from(sec != 0) * (1 + varint_len(sec))
            + usize::from(nsec != 0) * (1 + varint_len(nsec));
        key(&mut b, 1, LEN);
        b.push(body as u8); // at most 2 × (1 + 5) bytes
        uint(&mut b, 1, sec);
        uint(&mut b, 2, nsec);
        let mut bytes = [0; 16];
        let len = b.len().min(16);
        bytes[..len].copy_from_slice(&b[..len]);
        Stamp { bytes, len }
    }

    fn as_slice(&self) -> &[u8] {
        &self.bytes[..self.len]
    }
}

/// Appends one `FrameTransform` as a `transforms` entry (field 1) of `FrameTransforms`:
/// `stamp` as its timestamp, `ids` from [`frame_ids`], `pose` in the parent.
pub(crate) fn frame_transform(b: &mut Vec<u8>, stamp: &Stamp, ids: &[u8], pose: &Iso) {
    let q = quat(&pose.r);
    let len = stamp.len + ids.len() + 2 + doubles_len(&pose.t) + 2 + doubles_len(&q);
    key(b, 1, LEN);
    varint(b, len as u64);
    b.extend_from_slice(stamp.as_slice());
    b.extend_from_slice(ids);
    doubles_message(b, 4, &pose.t);
    doubles_message(b, 5, &q);
}

/// The head of a `vworks.CycleState`: `time_ns` (field 1) and `cycle` (field 2). Robots
/// follow, one [`robot_state`] each.
pub(crate) fn cycle_state_head(b: &mut Vec<u8>, time: u64, cycle: u64) {
    uint(b, 1, time);
    uint(b, 2, cycle);
}

/// Appends one `vworks.RobotState` as a `robots` entry (field 3) of `vworks.CycleState`.
pub(crate) fn robot_state(b: &mut Vec<u8>, name: &[u8], joints: &[f64], tcp: &Iso) {
    let q = quat(&tcp.r);
    let name_len = if name.is_empty() {
        0
    } else {
        1 + varint_len(name.len() as u64) + name.len()
    };
    let joints_len = if joints.is_empty() {
        0
    } else {
        1 + varint_len(8 * joints.len() as u64) + 8 * joints.len()
    };
    let pose_len = 2 + doubles_len(&tcp.t) + 2 + doubles_len(&q);
    let len = name_len + joints_len + 2 + pose_len;
    key(b, 3, LEN);
    varint(b, len as u64);
    bytes(b, 1, name);
    if !joints.is_empty() {
        key(b, 2, LEN);
        varint(b, 8 * joints.len() as u64);
        for v in joints {
            b.extend_from_slice(&v.to_le_bytes());
        }
    }
    key(b, 3, LEN);
    b.push(pose_len as u8); // at most 2 + 27 + 2 + 36 bytes
    doubles_message(b, 1, &tcp.t);
    doubles_message(b, 2, &q);
}

/// The `vworks.CycleState` schema: a serialized `FileDescriptorSet` of
/// `vworks/cycle_state.proto`, as MCAP wants for protobuf channels. In proto syntax:
///
/// ```proto
/// syntax = "proto3";
/// package vworks;
/// message Vector3 { double x = 1; double y = 2; double z = 3; }
/// message Quaternion { double x = 1; double y = 2; double z = 3; double w = 4; }
/// message Pose { Vector3 position = 1; Quaternion orientation = 2; }
/// message RobotState { string name = 1; repeated double joints = 2; Pose tcp = 3; }
/// message CycleState { uint64 time_ns = 1; uint64 cycle = 2; repeated RobotState robots = 3; }
/// ```
pub(crate) fn cycle_state_descriptor() -> Vec<u8> {
    fn field(name: &str, number: i32, ty: Type, repeated: bool) -> FieldDescriptorProto {
        FieldDescriptorProto {
            name: Some(name.into()),
            number: Some(number),
            label: Some(if repeated {
                Label::Repeated
            } else {
                Label::Optional
            } as i32),
            r#type: Some(ty as i32),
            json_name: Some(camel(name)),
            ..FieldDescriptorProto::default()
        }
    }
    fn message_field(name: &str, number: i32, of: &str, repeated: bool) -> FieldDescriptorProto {
        FieldDescriptorProto {
            type_name: Some(format!(".vworks.{of}")),
            ..field(name, number, Type::Message, repeated)
        }
    }
    fn message(name: &str, fields: Vec<FieldDescriptorProto>) -> DescriptorProto {
        DescriptorProto {
            name: Some(name.into()),
            field: fields,
            ..DescriptorProto::default()
        }
    }
    let doubles = |names: &[&str]| {
        names
            .iter()
            .zip(1..)
            .map(|(n, i)| field(n, i, Type::Double, false))
            .collect()
    };
    let file = FileDescriptorProto {
        name: Some("vworks/cycle_state.proto".into()),
        package: Some("vworks".into()),
        syntax: Some("proto3".into()),
        message_type: vec![
            message("Vector3", doubles(&["x", "y", "z"])),
            message("Quaternion", doubles(&["x", "y", "z", "w"])),
            message(
                "Pose",
                vec![
                    message_field("position", 1, "Vector3", false),
                    message_field("orientation", 2, "Quaternion", false),
                ],
            ),
            message(
                "RobotState",
                vec![
                    field("name", 1, Type::String, false),
                    field("joints", 2, Type::Double, true),
                    message_field("tcp", 3, "Pose", false),
                ],
            ),
            message(
                "CycleState",
                vec![
                    field("time_ns", 1, Type::Uint64, false),
                    field("cycle", 2, Type::Uint64, false),
                    message_field("robots", 3, "RobotState", true),
                ],
            ),
        ],
        ..FileDescriptorProto::default()
    };
    FileDescriptorSet { file: vec![file] }.encode_to_vec()
}

/// protoc's JSON name of a field: `time_ns` → `timeNs`.
fn camel(name: &str) -> String {
    let mut out = String::with_capacity(name.len());
    let mut upper = false;
    for c in name.chars() {
        if c == '_' {
            upper = true;
        } else if upper {
            out.extend(c.to_uppercase());
            upper = false;
        } else {
            out.push(c);
        }
    }
    out
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

    use foxglove::messages::{FrameTransform, FrameTransforms, Quaternion, Timestamp, Vector3};
    use prost::Message as _;
    use vworks_model::math::{Iso, axis_angle, rpy_matrix};

    use super::*;

    /// Poses with zero components, negative zeros, near-180° turns (every quaternion
    /// branch) and ordinary ones.
    fn poses() -> Vec<Iso> {
        let mut out = vec![Iso::IDENTITY];
        for (i, (rpy, t)) in [
            ([0.0, 0.0, 0.3], [0.0, 0.0, 0.29]),
            ([0.0, -1.2, 0.0], [0.1, 0.0, 0.0]),
            ([3.1, 0.01, -0.02], [-0.0, 1.5, -2.0]),
            ([0.02, 3.1, 0.01], [0.25, -0.5, 0.75]),
            ([0.01, 0.02, 3.13], [1e-300, 0.0, 3.0]),
            ([1.0, 2.0, 3.0], [4.0, 5.0, 6.0]),
        ]
        .into_iter()
        .enumerate()
        {
            let r = rpy_matrix(rpy);
            let r = if i == 5 {
                axis_angle(
                    [
                        std::f64::consts::FRAC_1_SQRT_2,
                        std::f64::consts::FRAC_1_SQRT_2,
                        0.0,
                    ],
                    3.1,
                )
            } else {
                r
            };
            out.push(Iso { r, t });
        }
        out
    }

    #[test]
    fn quaternions_rebuild_their_matrices() {
        for p in poses() {
            let [x, y, z, w] = quat(&p.r);
            assert!((x * x + y * y + z * z + w * w - 1.0).abs() < 1e-12);
            let m = [
                [
                    1.0 - 2.0 * (y * y + z * z),
                    2.0 * (x * y - z * w),
                    2.0 * (x * z + y * w),
                ],
                [
                    2.0 * (x * y + z * w),
                    1.0 - 2.0 * (x * x + z * z),
                    2.0 * (y * z - x * w),
                ],
                [
                    2.0 * (x * z - y * w),
                    2.0 * (y * z + x * w),
                    1.0 - 2.0 * (x * x + y * y),
                ],
            ];
            for (a, b) in m.iter().flatten().zip(p.r.iter().flatten()) {
                assert!((a - b).abs() < 1e-12, "{:?}", p.r);
            }
        }
    }

    #[test]
    fn frame_transforms_are_byte_identical_to_prost() {
        let long = "r1.".to_string() + &"x".repeat(150); // a transform longer than 127 bytes
        for child in ["r1.link_3", long.as_str()] {
            for time in [
                0,
                7,
                999_999_999,
                1_000_000_000,
                63_418_000_000,
                5_000_000_000_000,
            ] {
                let mut ours = Vec::new();
                let mut theirs = FrameTransforms::default();
                for p in poses() {
                    frame_transform(&mut ours, &Stamp::new(time), &frame_ids("world", child), &p);
                    let q = quat(&p.r);
                    theirs.transforms.push(FrameTransform {
                        timestamp: Some(Timestamp::new(
                            (time / 1_000_000_000) as u32,
                            (time % 1_000_000_000) as u32,
                        )),
                        parent_frame_id: "world".into(),
                        child_frame_id: child.into(),
                        translation: Some(Vector3 {
                            x: p.t[0],
                            y: p.t[1],
                            z: p.t[2],
                        }),
                        rotation: Some(Quaternion {
                            x: q[0],
                            y: q[1],
                            z: q[2],
                            w: q[3],
                        }),
                    });
                }
                assert_eq!(ours, theirs.encode_to_vec(), "{child} at {time}");
            }
        }
    }

    // The same messages as the descriptor, for prost to encode.
    #[derive(Clone, PartialEq, prost::Message)]
    struct V3 {
        #[prost(double, tag = "1")]
        x: f64,
        #[prost(double, tag = "2")]
        y: f64,
        #[prost(double, tag = "3")]
        z: f64,
    }
    #[derive(Clone, PartialEq, prost::Message)]
    struct Q4 {
        #[prost(double, tag = "1")]
        x: f64,
        #[prost(double, tag = "2")]
        y: f64,
        #[prost(double, tag = "3")]
        z: f64,
        #[prost(double, tag = "4")]
        w: f64,
    }
    #[derive(Clone, PartialEq, prost::Message)]
    struct PoseMsg {
        #[prost(message, optional, tag = "1")]
        position: Option<V3>,
        #[prost(message, optional, tag = "2")]
        orientation: Option<Q4>,
    }
    #[derive(Clone, PartialEq, prost::Message)]
    struct RobotStateMsg {
        #[prost(string, tag = "1")]
        name: String,
        #[prost(double, repeated, tag = "2")]
        joints: Vec<f64>,
        #[prost(message, optional, tag = "3")]
        tcp: Option<PoseMsg>,
    }
    #[derive(Clone, PartialEq, prost::Message)]
    struct CycleStateMsg {
        #[prost(uint64, tag = "1")]
        time_ns: u64,
        #[prost(uint64, tag = "2")]
        cycle: u64,
        #[prost(message, repeated, tag = "3")]
        robots: Vec<RobotStateMsg>,
    }

    #[test]
    fn cycle_states_are_byte_identical_to_prost() {
        let joint_sets: [&[f64]; 4] = [&[], &[0.5], &[0.0, -1.0, 2.0, 0.0, 1e-9, 3.0], &[1.0; 20]];
        for (k, p) in poses().into_iter().enumerate() {
            for name in ["", "r1", &"long".repeat(40)] {
                let (time, cycle) = (4_000_000 * k as u64, k as u64);
                let mut ours = Vec::new();
                cycle_state_head(&mut ours, time, cycle);
                let mut theirs = CycleStateMsg {
                    time_ns: time,
                    cycle,
                    robots: Vec::new(),
                };
                for joints in joint_sets {
                    robot_state(&mut ours, name.as_bytes(), joints, &p);
                    let q = quat(&p.r);
                    theirs.robots.push(RobotStateMsg {
                        name: name.into(),
                        joints: joints.to_vec(),
                        tcp: Some(PoseMsg {
                            position: Some(V3 {
                                x: p.t[0],
                                y: p.t[1],
                                z: p.t[2],
                            }),
                            orientation: Some(Q4 {
                                x: q[0],
                                y: q[1],
                                z: q[2],
                                w: q[3],
                            }),
                        }),
                    });
                }
                assert_eq!(ours, theirs.encode_to_vec(), "pose {k}, name {name:?}");
            }
        }
    }

    #[test]
    fn the_descriptor_describes_the_encoded_messages() {
        let set = FileDescriptorSet::decode(&cycle_state_descriptor()[..]).unwrap();
        let [file] = &set.file[..] else {
            panic!("one file")
        };
        assert_eq!((file.package(), file.syntax()), ("vworks", "proto3"));
        let fields = |m: &str| -> Vec<(String, i32, Type, Label, String)> {
            let d = file.message_type.iter().find(|d| d.name() == m).unwrap();
            d.field
                .iter()
                .map(|f| {
                    (
                        f.name().into(),
                        f.number(),
                        f.r#type(),
                        f.label(),
                        f.type_name().into(),
                    )
                })
                .collect()
        };
        let f = |n: &str, i, t, l, tn: &str| (n.to_string(), i, t, l, tn.to_string());
        let (opt, rep) = (Label::Optional, Label::Repeated);
        assert_eq!(
            fields("CycleState"),
            [
                f("time_ns", 1, Type::Uint64, opt, ""),
                f("cycle", 2, Type::Uint64, opt, ""),
                f("robots", 3, Type::Message, rep, ".vworks.RobotState"),
            ]
        );
        assert_eq!(
            fields("RobotState"),
            [
                f("name", 1, Type::String, opt, ""),
                f("joints", 2, Type::Double, rep, ""),
                f("tcp", 3, Type::Message, opt, ".vworks.Pose"),
            ]
        );
        assert_eq!(
            fields("Pose"),
            [
                f("position", 1, Type::Message, opt, ".vworks.Vector3"),
                f("orientation", 2, Type::Message, opt, ".vworks.Quaternion"),
            ]
        );
        let d = Type::Double;
        assert_eq!(
            fields("Vector3"),
            [
                f("x", 1, d, opt, ""),
                f("y", 2, d, opt, ""),
                f("z", 3, d, opt, "")
            ]
        );
        assert_eq!(
            fields("Quaternion"),
            [
                f("x", 1, d, opt, ""),
                f("y", 2, d, opt, ""),
                f("z", 3, d, opt, ""),
                f("w", 4, d, opt, "")
            ]
        );
    }
}
