//! Decoding `/tf` messages (`foxglove.FrameTransforms`, protobuf or JSON) back into frame
//! transforms, for what plays a log back (the report's 3D view). A hand-written protobuf
//! reader for the one message the log writes: every length and tag is checked, so a
//! damaged message is `None`, never a panic.

/// One transform of a `/tf` message: `child`'s pose in `parent` (frame indices into the
/// log's frame names), translation (m) and rotation quaternion (x, y, z, w).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FrameTransform {
    /// The parent frame.
    pub parent: u32,
    /// The child frame.
    pub child: u32,
    /// Translation (m).
    pub translation: [f64; 3],
    /// Rotation (x, y, z, w).
    pub rotation: [f64; 4],
}

/// A transform as the message names it.
pub(crate) type NamedTransform = (String, String, [f64; 3], [f64; 4]);

/// Reads a protobuf varint at `*at`.
fn varint(b: &[u8], at: &mut usize) -> Option<u64> {
    let mut v = 0u64;
    for shift in (0..64).step_by(7) {
        let byte = *b.get(*at)?;
        *at += 1;
        v |= u64::from(byte & 0x7f) << shift;
        if byte & 0x80 == 0 {
            return Some(v);
        }
    }
    None
}

/// The fields of a protobuf message: (field number, value) where the value is a varint
/// (its value unused here), a 64-bit word or a length-delimited slice.
enum Field<'a> {
    Varint,
    Fixed64(u64),
    Bytes(&'a [u8]),
}

fn fields(b: &[u8]) -> Option<Vec<(u64, Field<'_>)>> {
    let mut at = 0;
    let mut out = Vec::new();
    while at < b.len() {
        let key = varint(b, &mut at)?;
        let (field, wire) = (key >> 3, key & 7);
        let value = match wire {
            0 => {
                varint(b, &mut at)?;
                Field::Varint
            }
            1 => {
                let w = b.get(at..at.checked_add(8)?)?;
                at += 8;
                Field::Fixed64(u64::from_le_bytes(w.try_into().ok()?))
            }
            2 => {
                let len = usize::try_from(varint(b, &mut at)?).ok()?;
                let s = b.get(at..at.checked_add(len)?)?;
                at += len;
                Field::Bytes(s)
            }
            5 => {
                at = at.checked_add(4)?;
                if at > b.len() {
                    return None;
                }
                continue;
            }
            _ => return None,
        };
        out.push((field, value));
    }
    Some(out)
}

/// The doubles of a `Vector3` (x, y, z: fields 1–3) or `Quaternion` (x, y, z, w: 1–4);
/// absent fields are 0, as protobuf defaults are.
fn doubles<const N: usize>(b: &[u8]) -> Option<[f64; N]> {
    let mut out = [0.0; N];
    for (f, v) in fields(b)? {
        if let (Field::Fixed64(w), Some(slot)) =
            (v, (f as usize).checked_sub(1).and_then(|i| out.get_mut(i)))
        {
            *slot = f64::from_bits(w);
        }
    }
    Some(out)
}

/// The transforms of a protobuf `foxglove.FrameTransforms`; `None` if it is damaged.
pub(crate) fn decode_protobuf(b: &[u8]) -> Option<Vec<NamedTransform>> {
    let mut out = Vec::new();
    for (f, v) in fields(b)? {
        let (1, Field::Bytes(t)) = (f, v) else {
            continue;
        };
        let (mut parent, mut child) = (String::new(), String::new());
        let (mut translation, mut rotation) = ([0.0; 3], [0.0, 0.0, 0.0, 1.0]);
        for (g, w) in fields(t)? {
            match (g, w) {
                (2, Field::Bytes(s)) => parent = String::from_utf8_lossy(s).into_owned(),
                (3, Field::Bytes(s)) => child = String::from_utf8_lossy(s).into_owned(),
                (4, Field::Bytes(s)) => translation = doubles(s)?,
                (5, Field::Bytes(s)) => rotation = doubles(s)?,
                (_, Field::Varint | Field::Fixed64(_) | Field::Bytes(_)) => {}
            }
        }
        out.push((parent, child, translation, rotation));
    }
    Some(out)
}

/// The transforms of a JSON `foxglove.FrameTransforms`; `None` if it does not fit.
pub(crate) fn decode_json(v: &serde_json::Value) -> Option<Vec<NamedTransform>> {
    let xyz = |v: &serde_json::Value, keys: &[&str]| -> Option<Vec<f64>> {
        keys.iter().map(|k| v.get(*k)?.as_f64()).collect()
    };
    v.get("transforms")?
        .as_array()?
        .iter()
        .map(|t| {
            let tr = xyz(t.get("translation")?, &["x", "y", "z"])?;
            let q = xyz(t.get("rotation")?, &["x", "y", "z", "w"])?;
            Some((
                t.get("parent_frame_id")?.as_str()?.to_string(),
                t.get("child_frame_id")?.as_str()?.to_string(),
                [tr[0], tr[1], tr[2]],
                [q[0], q[1], q[2], q[3]],
            ))
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn damaged_messages_are_none_not_panics() {
        // A length that runs past the end, a varint that never ends, an unknown wire type.
        assert!(decode_protobuf(&[0x0a, 0x50, 0x01]).is_none());
        assert!(decode_protobuf(&[0x08, 0xff, 0xff, 0xff]).is_none());
        assert!(decode_protobuf(&[0x0b]).is_none());
        assert_eq!(decode_protobuf(&[]), Some(Vec::new()));
        assert!(
            decode_json(&serde_json::json!({"transforms": [{"parent_frame_id": "a"}]})).is_none()
        );
    }
}
