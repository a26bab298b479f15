//! Pure pose arithmetic shared by the compiler's constant folder and the interpreter.
//!
//! Poses are `[x, y, z, rx, ry, rz]` in the robot's base frame (m, rad) with the orientation
//! R = Rz(rz)·Ry(ry)·Rx(rx), URDF's fixed-axis roll-pitch-yaw.

/// A pose as stored in six slots: x, y, z (m), rx, ry, rz (rad).
pub type Pose6 = [f64; 6];

/// The rotation matrix (row-major) of fixed-axis roll-pitch-yaw angles: the robot
/// models' own ([`vworks_model::math::rpy_matrix`]), so poses mean the same in both.
pub fn rpy_to_matrix(rx: f64, ry: f64, rz: f64) -> [[f64; 3]; 3] {
    vworks_model::math::rpy_matrix([rx, ry, rz])
}

/// `offset(p, dx, dy, dz)`: translates the pose along the base frame's axes.
pub fn offset(p: Pose6, dx: f64, dy: f64, dz: f64) -> Pose6 {
    [p[0] + dx, p[1] + dy, p[2] + dz, p[3], p[4], p[5]]
}

/// `tool_offset(p, dx, dy, dz)`: translates the pose along its own (tool) axes.
pub fn tool_offset(p: Pose6, dx: f64, dy: f64, dz: f64) -> Pose6 {
    let r = rpy_to_matrix(p[3], p[4], p[5]);
    [
        p[0] + r[0][0] * dx + r[0][1] * dy + r[0][2] * dz,
        p[1] + r[1][0] * dx + r[1][1] * dy + r[1][2] * dz,
        p[2] + r[2][0] * dx + r[2][1] * dy + r[2][2] * dz,
        p[3],
        p[4],
        p[5],
    ]
}

/// The rotation matrix and translation of a pose.
fn frame(p: Pose6) -> ([[f64; 3]; 3], [f64; 3]) {
    (rpy_to_matrix(p[3], p[4], p[5]), [p[0], p[1], p[2]])
}

/// A pose from a rotation matrix and a translation (angles as the robot models read them).
pub(crate) fn pose_of(r: [[f64; 3]; 3], t: [f64; 3]) -> Pose6 {
    let rpy = vworks_model::math::Iso { r, t }.rpy();
    [t[0], t[1], t[2], rpy[0], rpy[1], rpy[2]]
}

/// Roll, pitch and yaw (a pose's angles) of a quaternion `[w, x, y, z]`, normalised;
/// `None` for a zero (or not finite) quaternion.
pub fn quat_rpy(q: [f64; 4]) -> Option<[f64; 3]> {
    let n = q.iter().map(|x| x * x).sum::<f64>().sqrt();
    if n.is_nan() || n <= 1e-9 || !n.is_finite() {
        return None;
    }
    let [w, x, y, z] = q.map(|v| v / n);
    let r = [
        [
            1.0 - 2.0 * (y * y + z * z),
            2.0 * (x * y - w * z),
            2.0 * (x * z + w * y),
        ],
        [
            2.0 * (x * y + w * z),
            1.0 - 2.0 * (x * x + z * z),
            2.0 * (y * z - w * x),
        ],
        [
            2.0 * (x * z - w * y),
            2.0 * (y * z + w * x),
            1.0 - 2.0 * (x * x + y * y),
        ],
    ];
    let p = pose_of(r, [0.0; 3]);
    Some([p[3], p[4], p[5]])
}

/// `pose_mul(a, b)`: the pose `b` given in the frame `a`, in `a`'s frame (a · b).
pub fn pose_mul(a: Pose6, b: Pose6) -> Pose6 {
    let (ra, ta) = frame(a);
    let (rb, tb) = frame(b);
    let mut r = [[0.0; 3]; 3];
    let mut t = ta;
    for i in 0..3 {
        for j in 0..3 {
            r[i][j] = (0..3).map(|k| ra[i][k] * rb[k][j]).sum();
            t[i] += ra[i][j] * tb[j];
        }
    }
    pose_of(r, t)
}

/// `pose_inv(p)`: the inverse transform.
pub fn pose_inv(p: Pose6) -> Pose6 {
    let (r, t) = frame(p);
    let mut rt = [[0.0; 3]; 3];
    let mut ti = [0.0; 3];
    for i in 0..3 {
        for j in 0..3 {
            rt[i][j] = r[j][i];
            ti[i] -= r[j][i] * t[j];
        }
    }
    pose_of(rt, ti)
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::PI;

    #[test]
    fn tool_offset_follows_the_tool_z_axis() {
        // Tool pointing down (rx = 180°): +z in the tool frame is -z in the base frame.
        let p = [0.45, -0.2, 0.3, PI, 0.0, 0.0];
        let q = tool_offset(p, 0.0, 0.0, 0.1);
        assert!((q[2] - 0.2).abs() < 1e-12);
        assert!((q[0] - 0.45).abs() < 1e-12 && (q[1] + 0.2).abs() < 1e-12);
    }

    #[test]
    fn pose_mul_and_inverse() {
        let a = [0.1, 0.2, 0.3, 0.4, -0.5, 0.6];
        let b = [-0.3, 0.05, 0.7, -1.0, 0.2, 2.5];
        let back = pose_mul(pose_inv(a), pose_mul(a, b));
        for k in 0..6 {
            assert!((back[k] - b[k]).abs() < 1e-12, "{back:?}");
        }
        // A frame turned 90° about z maps x to y.
        let f = [1.0, 0.0, 0.0, 0.0, 0.0, PI / 2.0];
        let p = pose_mul(f, [0.5, 0.0, 0.0, 0.0, 0.0, 0.0]);
        assert!((p[0] - 1.0).abs() < 1e-12 && (p[1] - 0.5).abs() < 1e-12);
    }

    #[test]
    fn rpy_matches_rz_ry_rx() {
        let r = rpy_to_matrix(0.0, 0.0, PI / 2.0);
        // Rz(90°) maps x to y.
        assert!((r[1][0] - 1.0).abs() < 1e-12 && r[0][0].abs() < 1e-12);
    }
}
