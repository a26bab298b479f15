//! Trajectories: the robot's joints as a pure function of time inside a motion.
//!
//! - [`Profile`]: a trapezoidal (or triangular) velocity profile over a distance, with
//!   the exact duration known in advance, so `motion_end` is an exact event.
//! - `move_j`: every axis follows the same normalised profile, scaled to its own travel;
//!   the slowest axis (at speed % of its maximum) sets the duration, so all axes start and
//!   stop together.
//! - `move_l`/`move_c`: the TCP follows a line or an arc, orientation by slerp, with a
//!   trapezoid in path length; the joints come from IK at each sampled instant.
//!
//! Times are integer nanoseconds; the durations are rounded up to a whole nanosecond and
//! the profile is evaluated on the rounded duration, so the end pose is exact.

use vworks_model::math::{Iso, M3, V3, add, mat_mul, norm, rotation_vector, sub, transpose};

/// Nanoseconds per second.
pub const NS: f64 = 1e9;

/// A trapezoidal velocity profile from 0 to `dist` (≥ 0) within `vmax` and `amax`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Profile {
    /// Distance covered.
    pub dist: f64,
    /// Cruise speed actually reached.
    pub v: f64,
    /// Acceleration used.
    pub a: f64,
    /// Time of the acceleration phase (s).
    pub t_acc: f64,
    /// Total duration (s).
    pub t_total: f64,
}

impl Profile {
    /// The fastest profile over `dist` within `vmax` and `amax` (both > 0).
    pub fn new(dist: f64, vmax: f64, amax: f64) -> Profile {
        let dist = dist.abs();
        if dist == 0.0 {
            return Profile {
                dist,
                v: 0.0,
                a: amax,
                t_acc: 0.0,
                t_total: 0.0,
            };
        }
        // Reaching vmax takes vmax/amax and covers vmax²/amax (accelerate + decelerate).
        if dist * amax >= vmax * vmax {
            let t_acc = vmax / amax;
            Profile {
                dist,
                v: vmax,
                a: amax,
                t_acc,
                t_total: dist / vmax + t_acc,
            }
        } else {
            // Triangular: peak speed sqrt(dist·amax).
            let v = (dist * amax).sqrt();
            let t_acc = v / amax;
            Profile {
                dist,
                v,
                a: amax,
                t_acc,
                t_total: 2.0 * t_acc,
            }
        }
    }

    /// The same shape stretched to last `t_total` (≥ the profile's own): used to make
    /// every axis of a `move_j` finish with the slowest one. Keeps the ratio of
    /// acceleration time to total time.
    pub fn stretched(&self, t_total: f64) -> Profile {
        if self.t_total <= 0.0 || t_total <= 0.0 {
            return Profile { t_total, ..*self };
        }
        let k = t_total / self.t_total;
        let t_acc = self.t_acc * k;
        // dist = v·(t_total − t_acc)
        let v = self.dist / (t_total - t_acc);
        Profile {
            dist: self.dist,
            v,
            a: v / t_acc.max(f64::MIN_POSITIVE),
            t_acc,
            t_total,
        }
    }

    /// Distance covered at time `t` (s), clamped to [0, dist].
    pub fn at(&self, t: f64) -> f64 {
        if t <= 0.0 {
            return 0.0;
        }
        if t >= self.t_total {
            return self.dist;
        }
        let (ta, tt) = (self.t_acc, self.t_total);
        if t < ta {
            0.5 * self.a * t * t
        } else if t <= tt - ta {
            0.5 * self.a * ta * ta + self.v * (t - ta)
        } else {
            let r = tt - t;
            self.dist - 0.5 * self.a * r * r
        }
    }

    /// Duration rounded up to whole nanoseconds.
    pub fn duration_ns(&self) -> i64 {
        (self.t_total * NS).ceil() as i64
    }
}

/// Spherical linear interpolation between two rotations: `from · exp(s · log(fromᵀ·to))`.
pub fn slerp(from: &M3, to: &M3, s: f64) -> M3 {
    let rel = mat_mul(&transpose(from), to);
    let w = rotation_vector(&rel);
    let angle = norm(w);
    if angle < 1e-15 {
        return *from;
    }
    let axis = [w[0] / angle, w[1] / angle, w[2] / angle];
    mat_mul(from, &vworks_model::math::axis_angle(axis, angle * s))
}

/// A Cartesian path from one TCP pose to another: a line or a circular arc.
#[derive(Clone, Debug, PartialEq)]
pub enum Path {
    /// Straight line.
    Line {
        /// Start position.
        from: V3,
        /// End position.
        to: V3,
    },
    /// Circular arc through a via point.
    Arc {
        /// Centre.
        center: V3,
        /// Start direction from the centre (radius length).
        u: V3,
        /// In-plane unit vector ⟂ u, toward the direction of travel (radius length).
        v: V3,
        /// Radius.
        radius: f64,
        /// Swept angle (rad, > 0).
        sweep: f64,
    },
}

impl Path {
    /// Path length (m).
    pub fn length(&self) -> f64 {
        match self {
            Path::Line { from, to } => norm(sub(*to, *from)),
            Path::Arc { radius, sweep, .. } => radius * sweep,
        }
    }

    /// Position at fraction `s` ∈ [0, 1] of the path.
    pub fn at(&self, s: f64) -> V3 {
        match self {
            Path::Line { from, to } => {
                let d = sub(*to, *from);
                add(*from, [d[0] * s, d[1] * s, d[2] * s])
            }
            Path::Arc {
                center,
                u,
                v,
                sweep,
                ..
            } => {
                let (sn, c) = (sweep * s).sin_cos();
                [
                    center[0] + u[0] * c + v[0] * sn,
                    center[1] + u[1] * c + v[1] * sn,
                    center[2] + u[2] * c + v[2] * sn,
                ]
            }
        }
    }

    /// The circle through three points, or `None` if they are (nearly) collinear.
    pub fn arc(p0: V3, via: V3, p1: V3) -> Option<Path> {
        use vworks_model::math::cross;
        let a = sub(via, p0);
        let b = sub(p1, p0);
        let n = cross(a, b);
        let n2 = n[0] * n[0] + n[1] * n[1] + n[2] * n[2];
        if n2 < 1e-18 {
            return None;
        }
        // Circumcentre of p0, via, p1.
        let aa = a[0] * a[0] + a[1] * a[1] + a[2] * a[2];
        let bb = b[0] * b[0] + b[1] * b[1] + b[2] * b[2];
        let t1 = cross(n, a);
        let t2 = cross(b, n);
        let off = [
            (bb * t1[0] + aa * t2[0]) / (2.0 * n2),
            (bb * t1[1] + aa * t2[1]) / (2.0 * n2),
            (bb * t1[2] + aa * t2[2]) / (2.0 * n2),
        ];
        let center = add(p0, off);
        let u = sub(p0, center);
        let radius = norm(u);
        let nn = n2.sqrt();
        let axis = [n[0] / nn, n[1] / nn, n[2] / nn];
        let v = cross(axis, u);
        // Sweep from p0 to p1 in the direction that passes the via point (right-hand about n).
        let angle_of = |p: V3| {
            let d = sub(p, center);
            let x = d[0] * u[0] + d[1] * u[1] + d[2] * u[2];
            let y = d[0] * v[0] + d[1] * v[1] + d[2] * v[2];
            let a = y.atan2(x);
            if a < 0.0 {
                a + 2.0 * std::f64::consts::PI
            } else {
                a
            }
        };
        let sweep = angle_of(p1);
        Some(Path::Arc {
            center,
            u,
            v,
            radius,
            sweep,
        })
    }
}

/// The TCP pose at fraction `s` of a Cartesian move.
pub fn cartesian_at(path: &Path, from: &Iso, to: &Iso, s: f64) -> Iso {
    Iso {
        r: slerp(&from.r, &to.r, s),
        t: path.at(s),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn trapezoid_and_triangle_times_are_closed_form() {
        // 90° at 250°/s with 250/0.3 °/s²: t = d/v + v/a.
        let (d, v, a) = (
            90f64.to_radians(),
            250f64.to_radians(),
            250f64.to_radians() / 0.3,
        );
        let p = Profile::new(d, v, a);
        assert!((p.t_total - (d / v + v / a)).abs() < 1e-15);
        assert!((p.at(p.t_total) - d).abs() < 1e-15 && p.at(p.t_total / 2.0) > 0.0);
        // Short move: triangular, t = 2·sqrt(d/a).
        let p = Profile::new(0.01, 1.0, 2.0);
        assert!((p.t_total - 2.0 * (0.01f64 / 2.0).sqrt()).abs() < 1e-15);
        assert!((p.at(p.t_total / 2.0) - 0.005).abs() < 1e-12);
    }

    #[test]
    fn stretched_profiles_end_together() {
        let fast = Profile::new(0.5, 2.0, 4.0);
        let s = fast.stretched(2.0);
        assert!((s.at(2.0) - 0.5).abs() < 1e-12 && (s.at(1.0) - 0.25).abs() < 1e-12);
    }

    #[test]
    fn arc_passes_through_its_via_point() {
        let p =
            Path::arc([1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [-1.0, 0.0, 0.0]).unwrap_or(Path::Line {
                from: [0.0; 3],
                to: [0.0; 3],
            });
        assert!((p.length() - std::f64::consts::PI).abs() < 1e-12);
        assert!(norm(sub(p.at(0.5), [0.0, 1.0, 0.0])) < 1e-12);
        assert!(norm(sub(p.at(1.0), [-1.0, 0.0, 0.0])) < 1e-12);
        assert!(Path::arc([0.0; 3], [1.0, 0.0, 0.0], [2.0, 0.0, 0.0]).is_none());
    }
}
