//! Mesh files for collision geometry: STL (binary and ASCII) and Wavefront OBJ. Only the
//! vertices are kept — links collide as the convex hulls of their meshes.

use crate::math::V3;

/// The convex hull of `points` as a triangle list (three corners per triangle; empty if
/// the points span no volume): how the log draws a mesh body.
pub fn hull_triangles(points: &[V3]) -> Vec<V3> {
    let pts: Vec<parry3d::math::Vector3> = points
        .iter()
        .map(|p| parry3d::math::Vector3::new(p[0], p[1], p[2]))
        .collect();
    let Ok((vertices, faces)) = parry3d::transformation::try_convex_hull(&pts) else {
        return Vec::new();
    };
    let mut out = Vec::with_capacity(faces.len() * 3);
    for face in faces {
        for k in face {
            if let Some(v) = vertices.get(k as usize) {
                out.push([v.x, v.y, v.z]);
            }
        }
    }
    out
}

/// Reads the vertices of an STL or OBJ mesh, scaled. The error says what is wrong.
pub fn read_vertices(bytes: &[u8], name: &str, scale: V3) -> Result<Vec<V3>, String> {
    let lower = name.to_ascii_lowercase();
    let mut pts = if lower.ends_with(".obj") {
        obj(bytes)?
    } else if lower.ends_with(".stl") {
        stl(bytes)?
    } else {
        return Err("unsupported mesh format; use .stl (binary or ASCII) or .obj".into());
    };
    for p in &mut pts {
        for k in 0..3 {
            p[k] *= scale[k];
        }
    }
    if pts.len() < 4 {
        return Err(format!(
            "the mesh has {} vertices; a collision hull needs at least 4",
            pts.len()
        ));
    }
    if pts.iter().flatten().any(|x| !x.is_finite()) {
        return Err("the mesh has a vertex that is not a finite number".into());
    }
    Ok(pts)
}

fn stl(b: &[u8]) -> Result<Vec<V3>, String> {
    // Binary STL: 80-byte header, u32 triangle count, 50 bytes per triangle. Some binary
    // files start with "solid" too, so the size decides.
    if b.len() >= 84 {
        let n = u32::from_le_bytes([b[80], b[81], b[82], b[83]]) as usize;
        if n.checked_mul(50).and_then(|x| x.checked_add(84)) == Some(b.len()) {
            let mut pts = Vec::with_capacity(n * 3);
            for t in 0..n {
                let base = 84 + t * 50 + 12;
                for v in 0..3 {
                    let o = base + v * 12;
                    let f = |i: usize| {
                        f64::from(f32::from_le_bytes([
                            b[o + i],
                            b[o + i + 1],
                            b[o + i + 2],
                            b[o + i + 3],
                        ]))
                    };
                    pts.push([f(0), f(4), f(8)]);
                }
            }
            return Ok(pts);
        }
    }
    let text = std::str::from_utf8(b).map_err(|_| {
        "not a binary STL (its size does not match its triangle count) and not ASCII text"
            .to_string()
    })?;
    if !text.trim_start().starts_with("solid") {
        return Err("not an STL file: a binary STL's size must match its triangle count, an ASCII STL starts with `solid`".into());
    }
    vertex_lines(text, "vertex")
}

fn obj(b: &[u8]) -> Result<Vec<V3>, String> {
    vertex_lines(&String::from_utf8_lossy(b), "v")
}

/// The coordinates of every line `KEYWORD x y z` (OBJ may add a 4th, w, which is ignored).
fn vertex_lines(text: &str, keyword: &str) -> Result<Vec<V3>, String> {
    let mut pts = Vec::new();
    for (i, line) in text.lines().enumerate() {
        let mut w = line.split_whitespace();
        if w.next() == Some(keyword) {
            let v: Vec<f64> = w
                .take(3)
                .map(|x| x.parse::<f64>())
                .collect::<Result<_, _>>()
                .map_err(|e| format!("line {}: {e}", i + 1))?;
            if v.len() != 3 {
                return Err(format!("line {}: a vertex needs 3 coordinates", i + 1));
            }
            pts.push([v[0], v[1], v[2]]);
        }
    }
    Ok(pts)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn binary_stl(tris: &[[V3; 3]]) -> Vec<u8> {
        let mut b = vec![0u8; 80];
        b.extend_from_slice(&(tris.len() as u32).to_le_bytes());
        for t in tris {
            b.extend_from_slice(&[0u8; 12]);
            for v in t {
                for x in v {
                    b.extend_from_slice(&(*x as f32).to_le_bytes());
                }
            }
            b.extend_from_slice(&[0u8; 2]);
        }
        b
    }

    #[test]
    fn reads_binary_ascii_stl_and_obj_with_scale() {
        let tet = [
            [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]],
            [[0.0, 0.0, 0.0], [0.0, 0.0, 1.0], [1.0, 0.0, 0.0]],
        ];
        let p = read_vertices(&binary_stl(&tet), "a.STL", [2.0, 2.0, 2.0]).unwrap_or_default();
        assert_eq!(p.len(), 6);
        assert_eq!(p[1], [2.0, 0.0, 0.0]);
        let ascii = "solid t\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 1 0\nendloop\nendfacet\nfacet normal 0 0 1\nouter loop\nvertex 0 0 1\nvertex 1 0 0\nvertex 0 1 0\nendloop\nendfacet\nendsolid t\n";
        assert_eq!(
            read_vertices(ascii.as_bytes(), "a.stl", [1.0; 3]).map(|v| v.len()),
            Ok(6)
        );
        let obj = "# tetra\nv 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 2 3\n";
        assert_eq!(
            read_vertices(obj.as_bytes(), "a.obj", [0.001; 3]).map(|v| v[1]),
            Ok([0.001, 0.0, 0.0])
        );
        assert!(read_vertices(b"garbage", "a.stl", [1.0; 3]).is_err());
        assert!(read_vertices(b"v 1 2\n", "a.obj", [1.0; 3]).is_err());
        assert!(read_vertices(obj.as_bytes(), "a.dae", [1.0; 3]).is_err());
    }
}
