//! The run in 3D, as the report plays it back: the frame tree of the log's `/tf`, the
//! frames' poses sampled at a fixed rate (and at every collision's start), encoded
//! compactly for the page.
//!
//! Only frames that move are sampled (a robot's links, held parts); the others keep the
//! pose they first had. Each sample is the latest transform at or before its time, as the
//! log's `/tf` carries them (at the logged cycle boundaries). A frame that turns about one
//! fixed axis of its first pose (a revolute joint's child link) is a [`Joint::Revolute`]
//! track: one angle per sample; one that slides along one fixed axis a
//! [`Joint::Prismatic`] track: one distance per sample. Any other moving frame (a held
//! part) is [`Joint::Free`]: translation x, y, z and rotation x, y, z, w in the parent
//! frame per sample. So the page does the forward kinematics, from the joint values and
//! the tree, and a 60 s run of four 6-axis arms is 24 numbers per sample, not 168.

use vworks_log::mcaplog::{FrameTransform, LogContents};
use vworks_log::trace::Kind;

/// Samples per simulated second the report plays back at (and more at collision starts).
pub const FRAMES_PER_SECOND: u64 = 30;

/// Regular samples at most: a run longer than 55 minutes is sampled less often, so that a
/// report (or a damaged log claiming a time in the year 2500) stays a few megabytes.
pub const MAX_SAMPLES: u64 = 100_000;

/// How a sampled frame moves in its parent.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Joint {
    /// Its pose is `base · rotation(axis, value)`: one angle (rad) per sample.
    Revolute {
        /// Unit axis in the frame's base pose.
        axis: [f64; 3],
    },
    /// Its pose is `base · translation(axis · value)`: one distance (m) per sample.
    Prismatic {
        /// Unit axis in the frame's base pose.
        axis: [f64; 3],
    },
    /// Any motion: the pose itself (7 numbers) per sample.
    Free,
}

impl Joint {
    /// Numbers per sample.
    pub fn width(&self) -> usize {
        match self {
            Joint::Free => 7,
            _ => 1,
        }
    }

    /// Its name in the page's data.
    pub fn name(&self) -> &'static str {
        match self {
            Joint::Revolute { .. } => "revolute",
            Joint::Prismatic { .. } => "prismatic",
            Joint::Free => "free",
        }
    }
}

/// A frame that moves, sampled.
#[derive(Clone, Debug, PartialEq)]
pub struct Track {
    /// The frame (an index into [`Playback::frames`]).
    pub frame: u32,
    /// How it moves.
    pub joint: Joint,
    /// Its pose in its parent at value 0 (its first sampled pose): translation, then
    /// rotation x, y, z, w.
    pub base: [f64; 7],
}

/// A log's run, ready to play back.
#[derive(Clone, Debug, PartialEq)]
pub struct Playback {
    /// Frame names, in the order the log first gave them.
    pub frames: Vec<String>,
    /// Each frame's parent (an index into `frames`), if it has one.
    pub parents: Vec<Option<u32>>,
    /// Each frame's first pose in its parent (7 numbers, see the module doc).
    pub first: Vec<[f32; 7]>,
    /// The frames that move, sampled below.
    pub tracks: Vec<Track>,
    /// Sample times (ns), increasing.
    pub times_ns: Vec<u64>,
    /// For each sample, for each track, its values ([`Joint::width`] of them):
    /// [`Playback::stride`] numbers per sample.
    pub values: Vec<f32>,
}

/// Rotations and translations that agree to this are the same (the log's values are
/// `f64`; the motions the simulation logs are exactly one-parameter).
const SAME: f64 = 1e-9;

impl Playback {
    /// The playback of a log read with `ReadOptions { poses: true }`; `None` if it has no
    /// `/tf` (an older or thinned log: the report says so instead of a 3D view).
    pub fn from_log(log: &LogContents) -> Option<Playback> {
        let n = log.frames.len();
        if n == 0 || log.transforms.is_empty() {
            return None;
        }
        let mut parents = vec![None; n];
        let mut first: Vec<Option<[f64; 7]>> = vec![None; n];
        let mut changes = vec![0u32; n];
        for (_, ts) in &log.transforms {
            for t in ts {
                let (Some(slot), Some(parent)) = (
                    first.get_mut(t.child as usize),
                    parents.get_mut(t.child as usize),
                ) else {
                    continue;
                };
                let pose = pose_of(t);
                match slot {
                    None => *slot = Some(pose),
                    Some(p) if *p != pose => changes[t.child as usize] += 1,
                    Some(_) => {}
                }
                *parent = Some(t.parent);
            }
        }
        let moving: Vec<u32> = (0..n as u32).filter(|&i| changes[i as usize] > 0).collect();
        let end = log
            .transforms
            .last()
            .map_or(0, |(t, _)| *t)
            .max(log.span.map_or(0, |s| s.1));
        let step = (1_000_000_000 / FRAMES_PER_SECOND).max(end.div_ceil(MAX_SAMPLES));
        let mut times: Vec<u64> = (0..=end / step).map(|k| k * step).collect();
        times.extend(
            log.events
                .iter()
                .filter(|e| e.kind == Kind::CollisionStart)
                .filter_map(|e| u64::try_from(e.time_ns).ok()),
        );
        times.push(end);
        times.sort_unstable();
        times.dedup();
        // Each moving frame's pose at each sample (f64, as logged).
        let mut current: Vec<[f64; 7]> = first.iter().map(|p| p.unwrap_or(IDENTITY)).collect();
        let mut sampled: Vec<Vec<[f64; 7]>> = vec![Vec::with_capacity(times.len()); moving.len()];
        let mut next = 0;
        for &t in &times {
            while let Some((at, ts)) = log.transforms.get(next)
                && *at <= t
            {
                for tr in ts {
                    if let Some(c) = current.get_mut(tr.child as usize) {
                        *c = pose_of(tr);
                    }
                }
                next += 1;
            }
            for (s, &m) in sampled.iter_mut().zip(&moving) {
                s.push(current[m as usize]);
            }
        }
        let tracks: Vec<Track> = moving
            .iter()
            .zip(&sampled)
            .map(|(&frame, poses)| Track {
                frame,
                joint: classify(poses),
                base: poses.first().copied().unwrap_or(IDENTITY),
            })
            .collect();
        let stride: usize = tracks.iter().map(|t| t.joint.width()).sum();
        let mut values = Vec::with_capacity(times.len() * stride);
        for k in 0..times.len() {
            for (track, poses) in tracks.iter().zip(&sampled) {
                let pose = &poses[k];
                match track.joint {
                    Joint::Revolute { axis } => {
                        values.push(angle_about(&track.base, pose, &axis) as f32);
                    }
                    Joint::Prismatic { axis } => {
                        values.push(shift_along(&track.base, pose, &axis) as f32);
                    }
                    Joint::Free => values.extend(pose.iter().map(|&x| x as f32)),
                }
            }
        }
        Some(Playback {
            frames: log.frames.clone(),
            parents,
            first: first
                .into_iter()
                .map(|p| p.unwrap_or(IDENTITY).map(|x| x as f32))
                .collect(),
            tracks,
            times_ns: times,
            values,
        })
    }

    /// Numbers per sample in [`Playback::values`].
    pub fn stride(&self) -> usize {
        self.tracks.iter().map(|t| t.joint.width()).sum()
    }

    /// The pose of frame `frame` in its parent at sample `k`, as the page computes it
    /// from the encoded values (translation, then rotation x, y, z, w).
    pub fn pose(&self, k: usize, frame: u32) -> Option<[f64; 7]> {
        let mut at = k * self.stride();
        for track in &self.tracks {
            let width = track.joint.width();
            if track.frame == frame {
                let v = self.values.get(at..at + width)?;
                return Some(match track.joint {
                    Joint::Free => {
                        let mut p = [0.0; 7];
                        for (p, v) in p.iter_mut().zip(v) {
                            *p = f64::from(*v);
                        }
                        p
                    }
                    _ => track.at(f64::from(v[0])),
                });
            }
            at += width;
        }
        self.first.get(frame as usize).map(|p| p.map(f64::from))
    }
}

const IDENTITY: [f64; 7] = [0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0];

fn pose_of(t: &FrameTransform) -> [f64; 7] {
    let (p, q) = (t.translation, t.rotation);
    [p[0], p[1], p[2], q[0], q[1], q[2], q[3]]
}

/// Hamilton product `a · b` of quaternions (x, y, z, w).
fn quat_mul(a: &[f64; 4], b: &[f64; 4]) -> [f64; 4] {
    [
        a[3] * b[0] + a[0] * b[3] + a[1] * b[2] - a[2] * b[1],
        a[3] * b[1] - a[0] * b[2] + a[1] * b[3] + a[2] * b[0],
        a[3] * b[2] + a[0] * b[1] - a[1] * b[0] + a[2] * b[3],
        a[3] * b[3] - a[0] * b[0] - a[1] * b[1] - a[2] * b[2],
    ]
}

fn conj(q: &[f64; 4]) -> [f64; 4] {
    [-q[0], -q[1], -q[2], q[3]]
}

/// `v` rotated by the unit quaternion `q`.
fn rotate(q: &[f64; 4], v: &[f64; 3]) -> [f64; 3] {
    let p = quat_mul(&quat_mul(q, &[v[0], v[1], v[2], 0.0]), &conj(q));
    [p[0], p[1], p[2]]
}

fn rot(p: &[f64; 7]) -> [f64; 4] {
    [p[3], p[4], p[5], p[6]]
}

/// The rotation from `base` to `pose`, in `base`'s frame.
fn relative_rotation(base: &[f64; 7], pose: &[f64; 7]) -> [f64; 4] {
    quat_mul(&conj(&rot(base)), &rot(pose))
}

/// The translation from `base` to `pose`, in `base`'s frame.
fn relative_shift(base: &[f64; 7], pose: &[f64; 7]) -> [f64; 3] {
    let d = [pose[0] - base[0], pose[1] - base[1], pose[2] - base[2]];
    rotate(&conj(&rot(base)), &d)
}

/// The angle of `pose` about `axis` from `base` (its rotation is `base`'s turned about it).
fn angle_about(base: &[f64; 7], pose: &[f64; 7], axis: &[f64; 3]) -> f64 {
    let r = relative_rotation(base, pose);
    2.0 * (r[0] * axis[0] + r[1] * axis[1] + r[2] * axis[2]).atan2(r[3])
}

/// The distance of `pose` along `axis` from `base`.
fn shift_along(base: &[f64; 7], pose: &[f64; 7], axis: &[f64; 3]) -> f64 {
    let d = relative_shift(base, pose);
    d[0] * axis[0] + d[1] * axis[1] + d[2] * axis[2]
}

fn norm(v: &[f64]) -> f64 {
    v.iter().map(|x| x * x).sum::<f64>().sqrt()
}

/// How a frame with these sampled poses moves: about one fixed axis, along one, or
/// otherwise. A one-parameter guess is kept only if it gives back every sample to
/// [`SAME`] (rotation up to sign).
fn classify(poses: &[[f64; 7]]) -> Joint {
    let Some(base) = poses.first() else {
        return Joint::Free;
    };
    let fits = |joint: Joint| {
        let track = Track {
            frame: 0,
            joint,
            base: *base,
        };
        poses.iter().all(|p| {
            let value = match joint {
                Joint::Revolute { axis } => angle_about(base, p, &axis),
                Joint::Prismatic { axis } => shift_along(base, p, &axis),
                Joint::Free => return true,
            };
            let got = track.at(value);
            let same_t = (0..3).all(|i| (got[i] - p[i]).abs() <= SAME);
            let same_q = |sign: f64| (3..7).all(|i| (got[i] - sign * p[i]).abs() <= SAME);
            same_t && (same_q(1.0) || same_q(-1.0))
        })
    };
    // About an axis: the first sample that turned gives it.
    let turned = poses.iter().find_map(|p| {
        let r = relative_rotation(base, p);
        let v = [r[0], r[1], r[2]];
        let s = norm(&v);
        (s > 1e-6).then(|| v.map(|x| x / s))
    });
    if let Some(axis) = turned {
        let joint = Joint::Revolute { axis };
        return if fits(joint) { joint } else { Joint::Free };
    }
    let moved = poses.iter().find_map(|p| {
        let d = relative_shift(base, p);
        let s = norm(&d);
        (s > 1e-9).then(|| d.map(|x| x / s))
    });
    match moved {
        Some(axis) if fits(Joint::Prismatic { axis }) => Joint::Prismatic { axis },
        _ => Joint::Free,
    }
}

impl Track {
    /// Its pose at `value` (f64; [`Playback::pose`] gives the encoded `f32` one).
    fn at(&self, value: f64) -> [f64; 7] {
        let b = &self.base;
        match self.joint {
            Joint::Revolute { axis } => {
                let (s, c) = (value / 2.0).sin_cos();
                let q = quat_mul(&rot(b), &[axis[0] * s, axis[1] * s, axis[2] * s, c]);
                [b[0], b[1], b[2], q[0], q[1], q[2], q[3]]
            }
            Joint::Prismatic { axis } => {
                let r = rotate(&rot(b), &axis.map(|a| a * value));
                [
                    b[0] + r[0],
                    b[1] + r[1],
                    b[2] + r[2],
                    b[3],
                    b[4],
                    b[5],
                    b[6],
                ]
            }
            Joint::Free => *b,
        }
    }
}

/// Standard base64 (RFC 4648, with padding) of `bytes`.
pub fn base64(bytes: &[u8]) -> String {
    const A: &[u8; 64] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    let mut out = String::with_capacity(bytes.len().div_ceil(3) * 4);
    for c in bytes.chunks(3) {
        let b = [c[0], *c.get(1).unwrap_or(&0), *c.get(2).unwrap_or(&0)];
        let v = (u32::from(b[0]) << 16) | (u32::from(b[1]) << 8) | u32::from(b[2]);
        for (k, shift) in [18, 12, 6, 0].into_iter().enumerate() {
            out.push(if k <= c.len() {
                A[(v >> shift) as usize & 63] as char
            } else {
                '='
            });
        }
    }
    out
}

/// `values` as little-endian `f32` bytes in base64 (a `Float32Array` in the page).
pub fn f32_base64(values: &[f32]) -> String {
    let bytes: Vec<u8> = values.iter().flat_map(|v| v.to_le_bytes()).collect();
    base64(&bytes)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn base64_is_rfc_4648() {
        assert_eq!(base64(b""), "");
        assert_eq!(base64(b"f"), "Zg==");
        assert_eq!(base64(b"fo"), "Zm8=");
        assert_eq!(base64(b"foo"), "Zm9v");
        assert_eq!(base64(b"foobar"), "Zm9vYmFy");
        assert_eq!(f32_base64(&[1.0]), "AACAPw==");
    }
}
