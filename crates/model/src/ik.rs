//! Inverse kinematics.
//!
//! - **Analytic**, all solutions, for 6-axis arms with a spherical wrist in the OPW family
//!   (ABB, KUKA, Fanuc, Stäubli geometry): axis 1 about ±z, axes 2 and 3 parallel about ±y,
//!   a wrist of ±x, ±y, ±x axes meeting in one point, all joint frames unrotated at zero.
//!   [`SphericalWrist::detect`] reads the lengths from the model itself, so the solver
//!   agrees with forward kinematics by construction; every candidate is also checked by
//!   FK. Up to 8 solutions (shoulder front/back × elbow up/down × wrist flip), each shifted
//!   by whole turns toward the current joints, filtered by the joint limits; the nearest to
//!   the current joints wins.
//! - **Numeric** damped least squares for any chain (UR-style, 7-axis, and as fallback),
//!   seeded from the current joints, with deterministic restarts.
//!
//! Neither allocates: solutions live in fixed arrays, so IK can run on every cycle of a
//! straight-line move.

use std::f64::consts::PI;

use crate::math::{Iso, M3, V3, cross, mat_mul, mat_vec, norm, rotation_vector, sub, transpose};
pub use crate::model::SphericalWrist;
use crate::model::{AxisDir, JointKind, RobotModel};

/// Levenberg–Marquardt iterations per start.
const ITERATIONS: usize = 500;

/// Starts of the numeric solver: the seed, then deterministic points across the ranges.
const RESTARTS: usize = 32;
/// Steps the numeric solver takes after converging to 1e-10 m and rad ([`RobotModel::ik_numeric`]).
const POLISH: usize = 2;

/// The most axes a numeric IK handles (the VM's `MAX_AXES`).
pub const MAX_AXES: usize = 12;

/// Why no joint solution was found.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum IkError {
    /// The position is beyond the arm's reach.
    #[error(
        "the pose (x {} m, y {} m, z {} m) is out of reach of {robot}: the wrist centre is {} what the arm can reach; bring the target closer or move the robot's base",
        m4(*.x), m4(*.y), m4(*.z), beyond(*.excess)
    )]
    OutOfReach {
        /// Robot name.
        robot: String,
        /// Target position.
        x: f64,
        /// Target position.
        y: f64,
        /// Target position.
        z: f64,
        /// How far out of reach (m).
        excess: f64,
    },
    /// Solutions exist, but none within the joint limits.
    #[error(
        "the pose (x {} m, y {} m, z {} m) is reachable by {robot} only outside its joint limits ({detail})",
        m4(*.x), m4(*.y), m4(*.z)
    )]
    JointLimits {
        /// Robot name.
        robot: String,
        /// Target position.
        x: f64,
        /// Target position.
        y: f64,
        /// Target position.
        z: f64,
        /// Which axis limits the nearest solution.
        detail: String,
    },
    /// The numeric solver did not converge (out of reach, a singularity, or the limits).
    #[error(
        "no joint solution found for the pose (x {} m, y {} m, z {} m) of {robot}: the nearest reached is {error_m:.2e} m / {error_rad:.2e} rad away (out of reach, at a singularity or blocked by joint limits)",
        m4(*.x), m4(*.y), m4(*.z)
    )]
    NoConvergence {
        /// Robot name.
        robot: String,
        /// Target position.
        x: f64,
        /// Target position.
        y: f64,
        /// Target position.
        z: f64,
        /// Remaining position error (m).
        error_m: f64,
        /// Remaining orientation error (rad).
        error_rad: f64,
    },
}

/// A length (m) in an error: 4 decimals, or scientific notation when huge.
fn m4(x: f64) -> String {
    crate::text::number(x, 4)
}

/// How far beyond the reach: in metres, or `far beyond` for a distance past any cell.
fn beyond(excess: f64) -> String {
    if excess.is_finite() && excess < 1e6 {
        format!("{excess:.4} m beyond")
    } else {
        "far beyond".to_string()
    }
}

impl IkError {
    /// The same error reporting the position `p` (m) instead of the flange's: IK solves
    /// for the flange, but the user wrote the TCP, which a tool offset moves.
    pub fn at_position(mut self, p: [f64; 3]) -> IkError {
        match &mut self {
            IkError::OutOfReach { x, y, z, .. }
            | IkError::JointLimits { x, y, z, .. }
            | IkError::NoConvergence { x, y, z, .. } => {
                (*x, *y, *z) = (p[0], p[1], p[2]);
            }
        }
        self
    }
}

fn is_identity(r: &M3) -> bool {
    (0..3).all(|i| (0..3).all(|j| (r[i][j] - if i == j { 1.0 } else { 0.0 }).abs() < 1e-12))
}

impl SphericalWrist {
    /// The wrist geometry, if the model is a 6-axis arm of the OPW family.
    pub fn detect(m: &RobotModel) -> Option<SphericalWrist> {
        if m.dof() != 6 {
            return None;
        }
        let chain = m.chain();
        let first = chain
            .iter()
            .position(|j| m.joints[*j].axis_index == Some(0))?;
        // The six axes must be consecutive joints of the chain.
        if chain
            .get(first..first + 6)?
            .iter()
            .enumerate()
            .any(|(i, j)| m.joints[*j].axis_index != Some(i))
        {
            return None;
        }
        let mut pre = Iso::IDENTITY;
        for &j in &chain[..first] {
            pre = pre.mul(&m.joints[j].origin);
        }
        pre = pre.mul(&m.joints[chain[first]].origin);
        let mut post = Iso::IDENTITY;
        for &j in &chain[first + 6..] {
            post = post.mul(&m.joints[j].origin);
        }
        let want = ['z', 'y', 'y', 'x', 'y', 'x'];
        let mut sign = [0.0; 6];
        for i in 0..6 {
            let j = m.axis(i);
            if j.kind != JointKind::Revolute && j.kind != JointKind::Continuous {
                return None;
            }
            sign[i] = match (j.dir, want[i]) {
                (AxisDir::X(s), 'x') | (AxisDir::Y(s), 'y') | (AxisDir::Z(s), 'z') => s,
                _ => return None,
            };
            if i > 0 && !is_identity(&j.origin.r) {
                return None;
            }
        }
        let o = |i: usize| m.axis(i).origin.t;
        let (j2, u, v1, v2, w) = (o(1), o(2), o(3), o(4), o(5));
        let planar = |v: V3| v[1].abs() < 1e-12;
        if !(planar(j2) && planar(u) && planar(v1) && planar(v2) && planar(w)) {
            return None;
        }
        // The wrist centre lies on axis 4 (x) and axis 6 passes through it.
        if v2[2].abs() > 1e-12 || w[2].abs() > 1e-12 {
            return None;
        }
        Some(SphericalWrist {
            pre,
            pre_inv: pre.inverse(),
            post_inv: post.inverse(),
            sign,
            shoulder: [j2[0], j2[2]],
            upper: [u[0], u[2]],
            fore: [v1[0] + v2[0], v1[2] + v2[2]],
            hand: w[0],
        })
    }

    /// All solutions (internal angles, before limits) for a tool-link pose; returns how
    /// many were written, or the excess distance when the position is out of reach.
    /// `q4_now` is axis 4's current (internal) angle, kept at a wrist singularity.
    ///
    /// Each solution's branch is written to `branches`: bit 2 shoulder (front/back), bit 1
    /// elbow, bit 0 wrist flip. With `only`, just that branch is computed.
    fn solve(
        &self,
        target: &Iso,
        q4_now: f64,
        only: Option<u8>,
        out: &mut [[f64; 6]; 8],
        branches: &mut [u8; 8],
    ) -> Result<usize, f64> {
        let t = self.pre_inv.mul(target).mul(&self.post_inv);
        let wc = sub(t.t, mat_vec(&t.r, [self.hand, 0.0, 0.0]));
        let rho = (wc[0] * wc[0] + wc[1] * wc[1]).sqrt();
        let base = wc[1].atan2(wc[0]);
        let [ux, uz] = self.upper;
        let [fx, fz] = self.fore;
        let a = ux * fx + uz * fz;
        let b = ux * fz - uz * fx;
        let ab = (a * a + b * b).sqrt();
        let phi = b.atan2(a);
        let mut n = 0;
        let mut worst_excess = f64::INFINITY;
        for (i1, (t1, r)) in [(base, rho), (base + PI, -rho)].into_iter().enumerate() {
            if only.is_some_and(|b| usize::from(b >> 2) != i1) {
                continue;
            }
            let dx = r - self.shoulder[0];
            let dz = wc[2] - self.shoulder[1];
            let d2 = dx * dx + dz * dz;
            let k = (d2 - ux * ux - uz * uz - fx * fx - fz * fz) / 2.0;
            if k.abs() > ab * (1.0 + 1e-12) {
                // |d| is outside [| |u| - |f| |, |u| + |f|].
                let reach = ((ux * ux + uz * uz).sqrt() + (fx * fx + fz * fz).sqrt()).max(0.0);
                worst_excess = worst_excess.min(d2.sqrt() - reach);
                continue;
            }
            let c = (k / ab).clamp(-1.0, 1.0).acos();
            for (i3, t3) in [phi + c, phi - c].into_iter().enumerate() {
                if only.is_some_and(|b| usize::from((b >> 1) & 1) != i3) {
                    continue;
                }
                let (s3, c3) = t3.sin_cos();
                let g = [ux + fx * c3 + fz * s3, uz - fx * s3 + fz * c3];
                let t2 = dx.atan2(dz) - g[0].atan2(g[1]);
                // Wrist: R36 = (Rz(t1)·Ry(t2+t3))ᵀ · R.
                let r03 = mat_mul(&rot_z(t1), &rot_y(t2 + t3));
                let m = mat_mul(&transpose(&r03), &t.r);
                let c5 = m[0][0].clamp(-1.0, 1.0);
                let t5a = c5.acos();
                for (i5, t5) in [t5a, -t5a].into_iter().enumerate() {
                    if only.is_some_and(|b| usize::from(b & 1) != i5) {
                        continue;
                    }
                    let s5 = t5.sin();
                    let (t4, t6) = if s5.abs() > 1e-9 {
                        (
                            (m[1][0] / s5).atan2(-m[2][0] / s5),
                            (m[0][1] / s5).atan2(m[0][2] / s5),
                        )
                    } else {
                        // Wrist singularity: only t4 ± t6 matters; keep axis 4 where it is
                        // and give axis 6 the rest, so a move through it does not jump.
                        let rest = mat_mul(
                            &mat_mul(&transpose(&rot_x(q4_now)), &m),
                            &transpose(&rot_y(t5)),
                        );
                        (q4_now, rest[2][1].atan2(rest[1][1]))
                    };
                    if n < 8 {
                        out[n] = [t1, t2, t3, t4, t5, t6];
                        branches[n] = (i1 * 4 + i3 * 2 + i5) as u8;
                        n += 1;
                    }
                }
            }
        }
        if n == 0 {
            return Err(worst_excess.max(0.0));
        }
        for s in out.iter_mut().take(n) {
            for (i, v) in s.iter_mut().enumerate() {
                *v *= self.sign[i];
            }
        }
        Ok(n)
    }
}

fn rot_z(a: f64) -> M3 {
    let (s, c) = a.sin_cos();
    [[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]]
}

fn rot_x(a: f64) -> M3 {
    let (s, c) = a.sin_cos();
    [[1.0, 0.0, 0.0], [0.0, c, -s], [0.0, s, c]]
}

fn rot_y(a: f64) -> M3 {
    let (s, c) = a.sin_cos();
    [[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]]
}

/// Position and orientation distance between two poses.
pub fn pose_error(a: &Iso, b: &Iso) -> (f64, f64) {
    let dp = norm(sub(a.t, b.t));
    let dr = norm(rotation_vector(&mat_mul(&a.r, &transpose(&b.r))));
    (dp, dr)
}

impl RobotModel {
    /// The joints from the root to the tool link, in order (computed; see `chain_cache`).
    pub fn chain(&self) -> Vec<usize> {
        let mut chain = Vec::with_capacity(8);
        let mut link = self.tool_link;
        while let Some(j) = self.links[link].parent_joint {
            chain.push(j);
            link = self.joints[j].parent;
        }
        chain.reverse();
        chain
    }

    /// Every analytic solution within the joint limits for a tool-link pose, each as close
    /// to `current` as whole turns allow. `None` if the model has no analytic solver.
    pub fn ik_analytic_all(
        &self,
        target: &Iso,
        current: &[f64],
        out: &mut [[f64; 6]; 8],
    ) -> Option<Result<usize, IkError>> {
        self.analytic_candidates(target, current, out, true)
    }

    /// The candidates within limits; with `verify`, only those FK confirms.
    fn analytic_candidates(
        &self,
        target: &Iso,
        current: &[f64],
        out: &mut [[f64; 6]; 8],
        verify: bool,
    ) -> Option<Result<usize, IkError>> {
        let w = self.wrist.as_ref()?;
        let mut raw = [[0.0; 6]; 8];
        let q4_now = w.sign[3] * current.get(3).copied().unwrap_or(0.0);
        let mut branches = [0u8; 8];
        let n = match w.solve(target, q4_now, None, &mut raw, &mut branches) {
            Ok(n) => n,
            Err(excess) => return Some(Err(self.out_of_reach(target, excess))),
        };
        let mut kept = 0;
        // The first limit violation (axis, value), formatted only if nothing is left.
        let mut limit_hit: Option<(usize, f64)> = None;
        'cand: for s in raw.iter().take(n) {
            let mut q = *s;
            for (i, qi) in q.iter_mut().enumerate() {
                let j = self.axis(i);
                let cur = current.get(i).copied().unwrap_or(0.0);
                // Whole turns toward the current value, then into the limits if possible.
                let mut v = *qi + (2.0 * PI) * ((cur - *qi) / (2.0 * PI)).round();
                // In closed form, not a loop of single turns: with joints far out of range
                // (`v - 2π == v` past 1e16) such a loop never ends.
                let tau = 2.0 * PI;
                if v > j.upper + 1e-9 {
                    let w = v - tau * ((v - j.upper - 1e-9) / tau).ceil();
                    if w >= j.lower - 1e-9 {
                        v = w;
                    }
                }
                if v < j.lower - 1e-9 {
                    let w = v + tau * ((j.lower - 1e-9 - v) / tau).ceil();
                    if w <= j.upper + 1e-9 {
                        v = w;
                    }
                }
                if v < j.lower - 1e-9 || v > j.upper + 1e-9 {
                    limit_hit.get_or_insert((i, v));
                    continue 'cand;
                }
                *qi = v;
            }
            // Guard: the solution must reproduce the pose.
            if verify && !self.reproduces(&q, target) {
                continue;
            }
            out[kept] = q;
            kept += 1;
        }
        if kept == 0 {
            return Some(Err(IkError::JointLimits {
                robot: self.name.clone(),
                x: target.t[0],
                y: target.t[1],
                z: target.t[2],
                detail: match limit_hit {
                    None => "no candidate reproduced the pose".into(),
                    Some((i, v)) => {
                        let j = self.axis(i);
                        format!(
                            "axis {} `{}` would be {:.1}°, limits {:.1}°..{:.1}°",
                            i + 1,
                            j.name,
                            v.to_degrees(),
                            j.lower.to_degrees(),
                            j.upper.to_degrees()
                        )
                    }
                },
            }));
        }
        Some(Ok(kept))
    }

    /// The analytic branch (shoulder, elbow, wrist) of the solution nearest `current` for a
    /// tool-link pose: fixed for the length of a straight or circular move.
    pub fn ik_branch(&self, target: &Iso, current: &[f64]) -> Option<u8> {
        let w = self.wrist.as_ref()?;
        let mut raw = [[0.0; 6]; 8];
        let mut branches = [0u8; 8];
        let q4 = w.sign[3] * current.get(3).copied().unwrap_or(0.0);
        let n = w.solve(target, q4, None, &mut raw, &mut branches).ok()?;
        let wrapped = |a: f64, b: f64| {
            let d = (a - b).rem_euclid(2.0 * PI);
            d.min(2.0 * PI - d)
        };
        let dist = |s: &[f64; 6]| {
            s.iter()
                .zip(current)
                .map(|(a, b)| wrapped(*a, *b))
                .fold(0.0, f64::max)
        };
        (0..n)
            .min_by(|a, b| dist(&raw[*a]).total_cmp(&dist(&raw[*b])))
            .map(|i| branches[i])
    }

    /// Analytic IK restricted to one branch (see [`RobotModel::ik_branch`]), each joint
    /// shifted by whole turns toward `current`: one solution, no search. For sampling a
    /// Cartesian motion.
    pub fn ik_in_branch(
        &self,
        target: &Iso,
        current: &[f64],
        branch: u8,
        q: &mut [f64],
    ) -> Result<(), IkError> {
        let Some(w) = self.wrist.as_ref() else {
            return self.ik(target, current, q);
        };
        let mut raw = [[0.0; 6]; 8];
        let mut branches = [0u8; 8];
        let q4 = w.sign[3] * current.get(3).copied().unwrap_or(0.0);
        let n = w
            .solve(target, q4, Some(branch), &mut raw, &mut branches)
            .map_err(|excess| self.out_of_reach(target, excess))?;
        if n == 0 {
            return Err(self.out_of_reach(target, 0.0));
        }
        for (i, v) in raw[0].iter().enumerate() {
            let cur = current.get(i).copied().unwrap_or(0.0);
            q[i] = *v + (2.0 * PI) * ((cur - v) / (2.0 * PI)).round();
        }
        Ok(())
    }

    fn reproduces(&self, q: &[f64; 6], target: &Iso) -> bool {
        let (dp, dr) = pose_error(&self.flange(q), target);
        dp <= 1e-7 && dr <= 1e-7
    }

    fn out_of_reach(&self, target: &Iso, excess: f64) -> IkError {
        IkError::OutOfReach {
            robot: self.name.clone(),
            x: target.t[0],
            y: target.t[1],
            z: target.t[2],
            excess,
        }
    }

    /// IK for a tool-link pose, nearest to `current`: analytic when the model has a
    /// spherical wrist, else numeric seeded from `current`. Writes the solution to `q`.
    pub fn ik(&self, target: &Iso, current: &[f64], q: &mut [f64]) -> Result<(), IkError> {
        let mut sols = [[0.0; 6]; 8];
        if let Some(r) = self.analytic_candidates(target, current, &mut sols, false) {
            let n = r?;
            let dist = |s: &[f64; 6]| {
                s.iter()
                    .zip(current)
                    .map(|(a, b)| (a - b).abs())
                    .fold(0.0, f64::max)
            };
            let cands = &mut sols[..n];
            cands.sort_by(|a, b| dist(a).total_cmp(&dist(b)));
            // Verify by FK, nearest first (normally the first passes).
            if let Some(best) = cands.iter().find(|c| self.reproduces(c, target)) {
                q[..6].copy_from_slice(best);
                return Ok(());
            }
            return Err(IkError::JointLimits {
                robot: self.name.clone(),
                x: target.t[0],
                y: target.t[1],
                z: target.t[2],
                detail: "no candidate reproduced the pose".into(),
            });
        }
        self.ik_numeric(target, current, q)
    }

    /// Damped least squares from `seed`, then from deterministic restarts across the
    /// joint ranges. Converges to 1e-10 m and rad, then takes up to two more steps
    /// towards the pose's rounding.
    pub fn ik_numeric(&self, target: &Iso, seed: &[f64], q: &mut [f64]) -> Result<(), IkError> {
        let n = self.dof();
        let mut best = (f64::INFINITY, f64::INFINITY);
        let mut rng = 0x9e37_79b9_7f4a_7c15u64;
        for attempt in 0..RESTARTS {
            let mut x = [0.0; MAX_AXES];
            for (i, xi) in x.iter_mut().enumerate().take(n) {
                let j = self.axis(i);
                *xi = if attempt == 0 {
                    seed.get(i).copied().unwrap_or(0.0)
                } else {
                    rng ^= rng << 13;
                    rng ^= rng >> 7;
                    rng ^= rng << 17;
                    let u = (rng >> 11) as f64 / (1u64 << 53) as f64;
                    let (lo, hi) = (j.lower.max(-PI), j.upper.min(PI));
                    lo + u * (hi - lo)
                };
                *xi = xi.clamp(j.lower, j.upper);
            }
            let (ep, er) = self.dls(target, &mut x[..n]);
            if ep < 1e-10 && er < 1e-10 {
                q[..n].copy_from_slice(&x[..n]);
                return Ok(());
            }
            if ep + er < best.0 + best.1 {
                best = (ep, er);
            }
        }
        Err(IkError::NoConvergence {
            robot: self.name.clone(),
            x: target.t[0],
            y: target.t[1],
            z: target.t[2],
            error_m: best.0,
            error_rad: best.1,
        })
    }

    /// The pose error at `x` (target − current: position, rotation vector) and the
    /// geometric Jacobian (6 × dof, in `jac`).
    fn residual(&self, target: &Iso, x: &[f64], jac: &mut [[f64; MAX_AXES]; 6]) -> [f64; 6] {
        let mut f = Iso::IDENTITY;
        let mut axis_frames = [(Iso::IDENTITY, 0usize); MAX_AXES];
        for &j in &self.chain_cache {
            let before = f.mul(&self.joints[j].origin);
            f = self.joint_step(&f, j, x);
            if let Some(i) = self.joints[j].axis_index {
                axis_frames[i] = (before, j);
            }
        }
        for (i, (fr, j)) in axis_frames.iter().enumerate().take(x.len()) {
            let joint = &self.joints[*j];
            let z = mat_vec(&fr.r, joint.dir.vector());
            let (lin, ang) = match joint.kind {
                JointKind::Prismatic => (z, [0.0; 3]),
                _ => (cross(z, sub(f.t, fr.t)), z),
            };
            for r in 0..3 {
                jac[r][i] = lin[r];
                jac[r + 3][i] = ang[r];
            }
        }
        let e_p = sub(target.t, f.t);
        let e_r = rotation_vector(&mat_mul(&target.r, &transpose(&f.r)));
        [e_p[0], e_p[1], e_p[2], e_r[0], e_r[1], e_r[2]]
    }

    /// Levenberg–Marquardt in place: a step that does not reduce the error is rejected and
    /// the damping raised. Returns the final position and orientation errors.
    fn dls(&self, target: &Iso, x: &mut [f64]) -> (f64, f64) {
        let n = x.len();
        let split = |e: &[f64; 6]| (norm([e[0], e[1], e[2]]), norm([e[3], e[4], e[5]]));
        let sq = |e: &[f64; 6]| e.iter().map(|v| v * v).sum::<f64>();
        let mut jac = [[0.0f64; MAX_AXES]; 6];
        let mut e = self.residual(target, x, &mut jac);
        // Sugihara's damping: λ = ½|e|² + w̄ keeps steps well conditioned at singularities
        // and at the edge of the workspace; `bias` grows when a step fails to help.
        let mut bias: f64 = 1e-6;
        let mut trial = [0.0f64; MAX_AXES];
        let mut trial_jac = [[0.0f64; MAX_AXES]; 6];
        // Steps taken after converging to 1e-10: Gauss–Newton's are quadratic there, so one
        // or two reach the rounding of the pose (1e-16), where a motion's joints sampled a
        // millisecond apart differ smoothly: a joint 1e-10 off, by an amount that drifts
        // along the path, reads as 1e-4 rad/s² in a second difference at 1 kHz.
        let mut polish = 0;
        for _ in 0..ITERATIONS {
            let (ep, er) = split(&e);
            if ep < 1e-10 && er < 1e-10 {
                if polish == POLISH || (ep < 1e-15 && er < 1e-15) {
                    break;
                }
                polish += 1;
            }
            let lambda = sq(&e) / 2.0 + bias;
            // dq = Jᵀ (J Jᵀ + λ I)⁻¹ e
            let mut a = nalgebra::Matrix6::<f64>::zeros();
            for r in 0..6 {
                for c in 0..6 {
                    a[(r, c)] = (0..n).map(|k| jac[r][k] * jac[c][k]).sum::<f64>()
                        + if r == c { lambda } else { 0.0 };
                }
            }
            let Some(chol) = a.cholesky() else { break };
            let y = chol.solve(&nalgebra::Vector6::from_row_slice(&e));
            for i in 0..n {
                let dq: f64 = (0..6).map(|r| jac[r][i] * y[r]).sum();
                let j = self.axis(i);
                trial[i] = (x[i] + dq).clamp(j.lower, j.upper);
            }
            let e_new = self.residual(target, &trial[..n], &mut trial_jac);
            if sq(&e_new) < sq(&e) {
                x.copy_from_slice(&trial[..n]);
                e = e_new;
                jac = trial_jac;
                bias = (bias / 2.0).max(1e-12);
            } else {
                bias *= 4.0;
                if bias > 1e3 {
                    break;
                }
            }
        }
        split(&e)
    }
}

#[cfg(test)]
mod tests {
    use crate::builtin;

    #[test]
    fn every_opw_model_gets_the_analytic_solver() {
        for name in ["irb120", "kr6r900", "lrmate200id"] {
            let m = builtin::load(name).unwrap_or_else(|e| panic!("{e}"));
            assert!(m.wrist.is_some(), "{name}");
        }
        let ur5 = builtin::load("ur5").unwrap_or_else(|e| panic!("{e}"));
        assert!(ur5.wrist.is_none());
    }

    #[test]
    fn analytic_ik_reproduces_fk() {
        let m = builtin::load("irb120").unwrap_or_else(|e| panic!("{e}"));
        let q0 = [0.3, -0.4, 0.5, 0.6, -0.7, 0.8];
        let target = m.flange(&q0);
        let mut q = [0.0; 6];
        m.ik(&target, &[0.0; 6], &mut q)
            .unwrap_or_else(|e| panic!("{e}"));
        let (dp, dr) = super::pose_error(&m.flange(&q), &target);
        assert!(dp < 1e-9 && dr < 1e-9, "{dp} {dr}");
        // Nearest to the current joints: from q0 itself, IK returns q0.
        m.ik(&target, &q0, &mut q).unwrap_or_else(|e| panic!("{e}"));
        assert!(q.iter().zip(q0).all(|(a, b)| (a - b).abs() < 1e-9), "{q:?}");
    }

    #[test]
    fn a_wrist_singularity_keeps_axis_4() {
        let m = builtin::load("irb120").unwrap_or_else(|e| panic!("{e}"));
        // Axis 5 at 0: axes 4 and 6 are aligned; only their sum is determined.
        let truth = [0.2, -0.3, 0.4, 0.7, 0.0, -0.2];
        let target = m.flange(&truth);
        let current = [0.2, -0.3, 0.4, 0.5, 0.0, 0.0];
        let mut q = [0.0; 6];
        m.ik(&target, &current, &mut q)
            .unwrap_or_else(|e| panic!("{e}"));
        let (dp, dr) = super::pose_error(&m.flange(&q), &target);
        assert!(dp < 1e-9 && dr < 1e-9, "{dp} {dr}");
        assert!(
            (q[3] - 0.5).abs() < 1e-9,
            "axis 4 should stay at 0.5, got {}",
            q[3]
        );
        assert!(
            (q[3] + q[5] - 0.5).abs() < 1e-9,
            "axes 4 + 6 carry the wrist angle: {q:?}"
        );
    }

    #[test]
    fn out_of_reach_says_so() {
        let m = builtin::load("irb120").unwrap_or_else(|e| panic!("{e}"));
        let mut target = m.flange(&[0.0; 6]);
        target.t = [3.0, 0.0, 0.5];
        let mut q = [0.0; 6];
        let e = m
            .ik(&target, &[0.0; 6], &mut q)
            .err()
            .map(|e| e.to_string())
            .unwrap_or_default();
        assert!(e.contains("out of reach"), "{e}");
    }
}
