//! The run in 3D, as the report plays it back: the frame tree of the log's `/tf`, the
//! frames' poses sampled at a fixed rate (and at every collision's start), and the
//! `/scene` updates (shapes, colours, collision red), encoded compactly for the page.
//!
//! Only frames that move are sampled (a robot's links, held parts); the others keep the
//! pose they first had. Each sample is the latest transform at or before its time, as the
//! log's `/tf` carries them (at the logged cycle boundaries), as `f32`: translation x, y,
//! z and rotation x, y, z, w in the parent frame.

use vworks_se::mcaplog::LogContents;
use vworks_se::trace::Kind;

/// Samples per simulated second the report plays back at (and more at collision starts).
pub const FRAMES_PER_SECOND: u64 = 30;

/// A log's run, ready to play back.
#[derive(Clone, Debug, PartialEq)]
pub struct Playback {
    /// Frame names, in the order the log first gave them.
    pub frames: Vec<String>,
    /// Each frame's parent (an index into `frames`), if it has one.
    pub parents: Vec<Option<u32>>,
    /// Each frame's first pose in its parent (7 numbers, see the module doc).
    pub first: Vec<[f32; 7]>,
    /// The frames that move, sampled below (indices into `frames`).
    pub moving: Vec<u32>,
    /// Sample times (ns), increasing.
    pub times_ns: Vec<u64>,
    /// For each sample, for each moving frame, its pose in its parent (7 numbers).
    pub poses: Vec<f32>,
}

impl Playback {
    /// The playback of a log read with `ReadOptions { poses: true }`; `None` if it has no
    /// `/tf` (an older or thinned log: the report says so instead of a 3D view).
    pub fn from_log(log: &LogContents) -> Option<Playback> {
        let n = log.frames.len();
        if n == 0 || log.transforms.is_empty() {
            return None;
        }
        let mut parents = vec![None; n];
        let mut first: Vec<Option<[f32; 7]>> = vec![None; n];
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
        let step = 1_000_000_000 / FRAMES_PER_SECOND;
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
        let mut current: Vec<[f32; 7]> = first.iter().map(|p| p.unwrap_or(IDENTITY)).collect();
        let mut poses = Vec::with_capacity(times.len() * moving.len() * 7);
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
            for &m in &moving {
                poses.extend_from_slice(&current[m as usize]);
            }
        }
        Some(Playback {
            frames: log.frames.clone(),
            parents,
            first: first.into_iter().map(|p| p.unwrap_or(IDENTITY)).collect(),
            moving,
            times_ns: times,
            poses,
        })
    }

    /// The pose of frame `frame` in its parent at sample `k`.
    pub fn pose(&self, k: usize, frame: u32) -> Option<[f32; 7]> {
        match self.moving.iter().position(|&m| m == frame) {
            Some(j) => {
                let at = (k * self.moving.len() + j) * 7;
                self.poses.get(at..at + 7)?.try_into().ok()
            }
            None => self.first.get(frame as usize).copied(),
        }
    }
}

const IDENTITY: [f32; 7] = [0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0];

fn pose_of(t: &vworks_se::mcaplog::FrameTransform) -> [f32; 7] {
    let (p, q) = (t.translation, t.rotation);
    [p[0], p[1], p[2], q[0], q[1], q[2], q[3]].map(|x| x as f32)
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
