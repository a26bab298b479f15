//! Rigid transforms in f64: a rotation matrix and a translation, composed by hand so that
//! forward kinematics stays a few hundred floating-point operations with no allocation.

/// A 3-vector.
pub type V3 = [f64; 3];
/// A row-major 3×3 rotation matrix.
pub type M3 = [[f64; 3]; 3];

/// A rigid transform: `p' = r · p + t`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Iso {
    /// Rotation (row-major).
    pub r: M3,
    /// Translation (m).
    pub t: V3,
}

impl Default for Iso {
    fn default() -> Iso {
        Iso::IDENTITY
    }
}

/// The identity rotation.
pub const I3: M3 = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];

impl Iso {
    /// No motion.
    pub const IDENTITY: Iso = Iso { r: I3, t: [0.0; 3] };

    /// A transform from a translation and fixed-axis roll-pitch-yaw (R = Rz·Ry·Rx).
    pub fn from_xyz_rpy(t: V3, rpy: V3) -> Iso {
        Iso {
            r: rpy_matrix(rpy),
            t,
        }
    }

    /// `self · o`.
    #[inline]
    pub fn mul(&self, o: &Iso) -> Iso {
        Iso {
            r: mat_mul(&self.r, &o.r),
            t: add(mat_vec(&self.r, o.t), self.t),
        }
    }

    /// The inverse transform.
    pub fn inverse(&self) -> Iso {
        let rt = transpose(&self.r);
        let t = mat_vec(&rt, self.t);
        Iso {
            r: rt,
            t: [-t[0], -t[1], -t[2]],
        }
    }

    /// Applies the transform to a point.
    #[inline]
    pub fn apply(&self, p: V3) -> V3 {
        add(mat_vec(&self.r, p), self.t)
    }

    /// Fixed-axis roll, pitch, yaw of the rotation (the inverse of [`Iso::from_xyz_rpy`]).
    pub fn rpy(&self) -> V3 {
        let r = &self.r;
        let pitch = (-r[2][0]).clamp(-1.0, 1.0).asin();
        if r[2][0].abs() < 1.0 - 1e-12 {
            [r[2][1].atan2(r[2][2]), pitch, r[1][0].atan2(r[0][0])]
        } else {
            // Gimbal lock: roll and yaw share one axis; put it all in yaw.
            [0.0, pitch, (-r[0][1]).atan2(r[1][1])]
        }
    }
}

/// R = Rz(yaw)·Ry(pitch)·Rx(roll).
pub fn rpy_matrix(rpy: V3) -> M3 {
    let (sr, cr) = rpy[0].sin_cos();
    let (sp, cp) = rpy[1].sin_cos();
    let (sy, cy) = rpy[2].sin_cos();
    [
        [cy * cp, cy * sp * sr - sy * cr, cy * sp * cr + sy * sr],
        [sy * cp, sy * sp * sr + cy * cr, sy * sp * cr - cy * sr],
        [-sp, cp * sr, cp * cr],
    ]
}

/// Rotation by `angle` about the unit vector `a` (Rodrigues).
pub fn axis_angle(a: V3, angle: f64) -> M3 {
    let (s, c) = angle.sin_cos();
    let v = 1.0 - c;
    let [x, y, z] = a;
    [
        [c + x * x * v, x * y * v - z * s, x * z * v + y * s],
        [y * x * v + z * s, c + y * y * v, y * z * v - x * s],
        [z * x * v - y * s, z * y * v + x * s, c + z * z * v],
    ]
}

/// `a · b`.
#[inline]
pub fn mat_mul(a: &M3, b: &M3) -> M3 {
    let mut m = [[0.0; 3]; 3];
    for i in 0..3 {
        for j in 0..3 {
            m[i][j] = a[i][0] * b[0][j] + a[i][1] * b[1][j] + a[i][2] * b[2][j];
        }
    }
    m
}

/// `m · v`.
#[inline]
pub fn mat_vec(m: &M3, v: V3) -> V3 {
    [
        m[0][0] * v[0] + m[0][1] * v[1] + m[0][2] * v[2],
        m[1][0] * v[0] + m[1][1] * v[1] + m[1][2] * v[2],
        m[2][0] * v[0] + m[2][1] * v[1] + m[2][2] * v[2],
    ]
}

/// The transpose (the inverse of a rotation).
pub fn transpose(m: &M3) -> M3 {
    [
        [m[0][0], m[1][0], m[2][0]],
        [m[0][1], m[1][1], m[2][1]],
        [m[0][2], m[1][2], m[2][2]],
    ]
}

/// `a + b`.
#[inline]
pub fn add(a: V3, b: V3) -> V3 {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}

/// `a - b`.
#[inline]
pub fn sub(a: V3, b: V3) -> V3 {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

/// `a · b`.
#[inline]
pub fn dot(a: V3, b: V3) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// `s·x + y`.
#[inline]
pub fn axpy(s: f64, x: V3, y: V3) -> V3 {
    [s * x[0] + y[0], s * x[1] + y[1], s * x[2] + y[2]]
}

/// `a × b`.
#[inline]
pub fn cross(a: V3, b: V3) -> V3 {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

/// `|a|`.
pub fn norm(a: V3) -> f64 {
    (a[0] * a[0] + a[1] * a[1] + a[2] * a[2]).sqrt()
}

/// The rotation vector (axis × angle) of `m`, the "log" of a rotation.
pub fn rotation_vector(m: &M3) -> V3 {
    let tr = m[0][0] + m[1][1] + m[2][2];
    let c = ((tr - 1.0) / 2.0).clamp(-1.0, 1.0);
    let angle = c.acos();
    let w = [m[2][1] - m[1][2], m[0][2] - m[2][0], m[1][0] - m[0][1]];
    if angle < 1e-9 {
        return [w[0] / 2.0, w[1] / 2.0, w[2] / 2.0];
    }
    if std::f64::consts::PI - angle < 1e-6 {
        // Near 180°: the axis from the diagonal.
        let mut axis = [
            ((m[0][0] + 1.0) / 2.0).max(0.0).sqrt(),
            ((m[1][1] + 1.0) / 2.0).max(0.0).sqrt(),
            ((m[2][2] + 1.0) / 2.0).max(0.0).sqrt(),
        ];
        if m[0][1] + m[1][0] < 0.0 {
            axis[1] = -axis[1];
        }
        if m[0][2] + m[2][0] < 0.0 {
            axis[2] = -axis[2];
        }
        let n = norm(axis).max(1e-300);
        return [
            axis[0] / n * angle,
            axis[1] / n * angle,
            axis[2] / n * angle,
        ];
    }
    let k = angle / (2.0 * angle.sin());
    [w[0] * k, w[1] * k, w[2] * k]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rpy_round_trips() {
        for rpy in [[0.1, -0.4, 2.0], [3.0, 0.2, -1.0], [0.0, 0.0, 0.0]] {
            let back = Iso::from_xyz_rpy([0.0; 3], rpy).rpy();
            let again = rpy_matrix(back);
            let orig = rpy_matrix(rpy);
            for i in 0..3 {
                for j in 0..3 {
                    assert!((again[i][j] - orig[i][j]).abs() < 1e-12);
                }
            }
        }
    }

    #[test]
    fn inverse_undoes() {
        let a = Iso::from_xyz_rpy([0.1, 0.2, 0.3], [0.4, -0.5, 0.6]);
        let p = a.mul(&a.inverse()).apply([1.0, 2.0, 3.0]);
        assert!(norm(sub(p, [1.0, 2.0, 3.0])) < 1e-12);
    }

    #[test]
    fn rotation_vector_of_axis_angle() {
        let m = axis_angle([0.0, 0.6, 0.8], 1.2);
        let v = rotation_vector(&m);
        assert!(norm(sub(v, [0.0, 0.72, 0.96])) < 1e-12);
        let m = axis_angle([0.0, 0.0, 1.0], std::f64::consts::PI);
        assert!((norm(rotation_vector(&m)) - std::f64::consts::PI).abs() < 1e-9);
    }
}
