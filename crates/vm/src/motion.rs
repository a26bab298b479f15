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

/// A rest-to-rest velocity profile from 0 to `dist` (≥ 0) within a speed, an acceleration
/// and (optionally) a jerk limit: a trapezoid (or triangle) without a jerk limit, else the
/// time-optimal S-curve of up to 7 phases (jerk up, constant acceleration, jerk down,
/// cruise, and the mirror image). The acceleration phase is point-symmetric about its
/// middle, so the speed during it is `v − σ(t_acc − τ)`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Profile {
    /// Distance covered.
    pub dist: f64,
    /// Cruise (peak) speed actually reached.
    pub v: f64,
    /// Peak acceleration used.
    pub a: f64,
    /// Jerk (`f64::INFINITY`: a trapezoid).
    pub j: f64,
    /// Time of each jerk phase (s; 0 for a trapezoid).
    pub t_jerk: f64,
    /// Time of the whole acceleration phase (s): `2·t_jerk` + the constant-acceleration part.
    pub t_acc: f64,
    /// Total duration (s).
    pub t_total: f64,
}

impl Profile {
    /// The fastest trapezoidal profile over `dist` within `vmax` and `amax` (both > 0).
    pub fn new(dist: f64, vmax: f64, amax: f64) -> Profile {
        let dist = dist.abs();
        let trapezoid = |v: f64, a: f64, t_acc: f64, t_total: f64| Profile {
            dist,
            v,
            a,
            j: f64::INFINITY,
            t_jerk: 0.0,
            t_acc,
            t_total,
        };
        if dist == 0.0 {
            return trapezoid(0.0, amax, 0.0, 0.0);
        }
        // Reaching vmax takes vmax/amax and covers vmax²/amax (accelerate + decelerate).
        if dist * amax >= vmax * vmax {
            let t_acc = vmax / amax;
            trapezoid(vmax, amax, t_acc, dist / vmax + t_acc)
        } else {
            // Triangular: peak speed sqrt(dist·amax).
            let v = (dist * amax).sqrt();
            let t_acc = v / amax;
            trapezoid(v, amax, t_acc, 2.0 * t_acc)
        }
    }

    /// The time-optimal profile over `dist` within `vmax`, `amax` and `jmax` (all > 0;
    /// `jmax` infinite: the trapezoid of [`Profile::new`]).
    ///
    /// The acceleration phase to a speed `v` takes `t_j = a/j` of rising jerk, `v/a − a/j`
    /// of constant acceleration and `t_j` of falling jerk when `v·j ≥ a²`; otherwise the
    /// acceleration peaks at `√(v·j)` after `t_j = √(v/j)`. It covers `v·t_acc/2`. When the
    /// two phases would cover more than `dist`, the peak speed is lowered until they cover
    /// it exactly: `v = (a/2)(√(a²/j² + 4d/a) − a/j)` if that speed still reaches `a`,
    /// else `t_j = ∛(d/(2j))` and the profile is four jerk phases.
    pub fn with_jerk(dist: f64, vmax: f64, amax: f64, jmax: f64) -> Profile {
        if !jmax.is_finite() {
            return Profile::new(dist, vmax, amax);
        }
        let dist = dist.abs();
        if dist == 0.0 {
            return Profile {
                dist,
                v: 0.0,
                a: amax,
                j: jmax,
                t_jerk: 0.0,
                t_acc: 0.0,
                t_total: 0.0,
            };
        }
        let full = Self::ramp(vmax, amax, jmax);
        if vmax * full.t_acc <= dist {
            return Profile {
                dist,
                t_total: 2.0 * full.t_acc + (dist - vmax * full.t_acc) / vmax,
                ..full
            };
        }
        let (a, j) = (amax, jmax);
        let v = 0.5 * a * ((a * a / (j * j) + 4.0 * dist / a).sqrt() - a / j);
        let p = if v * j >= a * a {
            Self::ramp(v, a, j)
        } else {
            let t_jerk = (dist / (2.0 * j)).cbrt();
            Profile {
                dist: 0.0,
                v: j * t_jerk * t_jerk,
                a: j * t_jerk,
                j,
                t_jerk,
                t_acc: 2.0 * t_jerk,
                t_total: 0.0,
            }
        };
        Profile {
            dist,
            t_total: 2.0 * p.t_acc,
            ..p
        }
    }

    /// The acceleration phase from rest to `v` within `a` and `j` (`dist` and `t_total`
    /// left 0 for the caller).
    fn ramp(v: f64, a: f64, j: f64) -> Profile {
        let (t_jerk, a, t_acc) = if v * j >= a * a {
            (a / j, a, v / a + a / j)
        } else {
            let t = (v / j).sqrt();
            (t, j * t, 2.0 * t)
        };
        Profile {
            dist: 0.0,
            v,
            a,
            j,
            t_jerk,
            t_acc,
            t_total: 0.0,
        }
    }

    /// The profile over the same distance with the same acceleration and jerk limits
    /// that lasts exactly `t_total` (≥ the time-optimal one's): the cruise speed is
    /// lowered until it does — what time synchronisation of several axes needs (each axis
    /// keeps its own limits and all end together). From `t_total = t_acc(v) + d/v`:
    /// `v = (a/2)(T' − √(T'² − 4d/a))` with `T' = T − a/j` while `v·j ≥ a²`, else solved
    /// by bisection.
    pub fn lasting(&self, t_total: f64, amax: f64) -> Profile {
        let d = self.dist;
        if d == 0.0 || t_total <= self.t_total {
            return *self;
        }
        let (a, j) = (amax, self.j);
        let jt = if j.is_finite() { a / j } else { 0.0 };
        let tp = t_total - jt;
        let v = 0.5 * a * (tp - (tp * tp - 4.0 * d / a).max(0.0).sqrt());
        let v = if !j.is_finite() || v * j >= a * a {
            v
        } else {
            // t_acc = 2√(v/j): t_total = 2√(v/j) + d/v, decreasing in v below a²/j.
            let (mut lo, mut hi) = (0.0f64, (a * a / j).min(self.v.max(f64::MIN_POSITIVE)));
            for _ in 0..200 {
                let mid = 0.5 * (lo + hi);
                if mid <= lo || mid >= hi {
                    break;
                }
                if 2.0 * (mid / j).sqrt() + d / mid > t_total {
                    lo = mid;
                } else {
                    hi = mid;
                }
            }
            hi
        };
        let ramp = if j.is_finite() {
            Self::ramp(v, a, j)
        } else {
            Profile {
                dist: 0.0,
                v,
                a,
                j,
                t_jerk: 0.0,
                t_acc: v / a,
                t_total: 0.0,
            }
        };
        Profile {
            dist: d,
            t_total,
            // The cruise absorbs the rounding: it lasts t_total − 2·t_acc.
            t_acc: ramp.t_acc.min(0.5 * t_total),
            ..ramp
        }
    }

    /// Distance covered during the acceleration phase by time `tau` ∈ [0, t_acc].
    fn ramp_at(&self, tau: f64) -> f64 {
        let (tj, ta) = (self.t_jerk, self.t_acc);
        if tj == 0.0 {
            return 0.5 * self.a * tau * tau;
        }
        let rising = |t: f64| self.j * t * t * t / 6.0;
        if tau <= tj {
            rising(tau)
        } else if tau <= ta - tj {
            let u = tau - tj;
            rising(tj) + 0.5 * self.j * tj * tj * u + 0.5 * self.a * u * u
        } else {
            // Point symmetry of the phase: f(τ) = v·τ − f(t_acc) + f(t_acc − τ).
            self.v * tau - 0.5 * self.v * ta + rising(ta - tau)
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
        if self.t_jerk == 0.0 {
            // The trapezoid, as it always was (bit for bit).
            return if t < ta {
                0.5 * self.a * t * t
            } else if t <= tt - ta {
                0.5 * self.a * ta * ta + self.v * (t - ta)
            } else {
                let r = tt - t;
                self.dist - 0.5 * self.a * r * r
            };
        }
        if t < ta {
            self.ramp_at(t)
        } else if t <= tt - ta {
            0.5 * self.v * ta + self.v * (t - ta)
        } else {
            self.dist - self.ramp_at(tt - t)
        }
    }

    /// Speed at time `t` (s).
    pub fn speed_at(&self, t: f64) -> f64 {
        if t <= 0.0 || t >= self.t_total {
            return 0.0;
        }
        let (ta, tt) = (self.t_acc, self.t_total);
        let ramp = |tau: f64| {
            let tj = self.t_jerk;
            if tj == 0.0 {
                self.a * tau
            } else if tau <= tj {
                0.5 * self.j * tau * tau
            } else if tau <= ta - tj {
                0.5 * self.j * tj * tj + self.a * (tau - tj)
            } else {
                let r = ta - tau;
                self.v - 0.5 * self.j * r * r
            }
        };
        if t < ta {
            ramp(t)
        } else if t <= tt - ta {
            self.v
        } else {
            ramp(tt - t)
        }
    }

    /// Acceleration at time `t` (s); at a phase boundary, the value of the phase that
    /// starts there.
    pub fn accel_at(&self, t: f64) -> f64 {
        if t < 0.0 || t >= self.t_total {
            return 0.0;
        }
        let (ta, tt, tj) = (self.t_acc, self.t_total, self.t_jerk);
        let ramp = |tau: f64| {
            if tj == 0.0 || (tau >= tj && tau < ta - tj) {
                self.a
            } else if tau < tj {
                self.j * tau
            } else {
                self.j * (ta - tau)
            }
        };
        if t < ta {
            ramp(t)
        } else if t < tt - ta {
            0.0
        } else {
            -ramp(tt - t)
        }
    }

    /// Jerk at time `t` (s): ±j in the jerk phases, 0 elsewhere (and 0 for a trapezoid,
    /// whose acceleration steps instead); at a phase boundary, the value of the phase
    /// that starts there.
    pub fn jerk_at(&self, t: f64) -> f64 {
        if t < 0.0 || t >= self.t_total || self.t_jerk == 0.0 || !self.j.is_finite() {
            return 0.0;
        }
        let (ta, tt, tj) = (self.t_acc, self.t_total, self.t_jerk);
        // The acceleration phase: up, hold, down; the braking mirrors it.
        let ramp = |tau: f64| {
            if tau < tj {
                self.j
            } else if tau >= ta - tj {
                -self.j
            } else {
                0.0
            }
        };
        if t < ta {
            ramp(t)
        } else if t < tt - ta {
            0.0
        } else {
            -ramp(t - (tt - ta))
        }
    }

    /// The times where a phase begins or ends (acceleration or jerk changes): within
    /// each stretch between two of them the acceleration is linear in time.
    pub fn breakpoints(&self) -> [f64; 8] {
        let (ta, tt, tj) = (self.t_acc, self.t_total, self.t_jerk);
        [0.0, tj, ta - tj, ta, tt - ta, tt - ta + tj, tt - tj, tt]
    }

    /// The first time the profile has covered `d` (clamped to [0, t_total]), by bisection
    /// (the distance never decreases).
    pub fn time_at(&self, d: f64) -> f64 {
        if d <= 0.0 {
            return 0.0;
        }
        if d >= self.dist {
            return self.t_total;
        }
        let (mut lo, mut hi) = (0.0, self.t_total);
        for _ in 0..200 {
            let mid = 0.5 * (lo + hi);
            if mid <= lo || mid >= hi {
                break;
            }
            if self.at(mid) < d {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        hi
    }

    /// The same profile `f` (≥ 1) times slower: the same shape stretched in time (speed
    /// over f, acceleration over f², jerk over f³).
    pub fn stretched(&self, f: f64) -> Profile {
        Profile {
            v: self.v / f,
            a: self.a / (f * f),
            j: self.j / (f * f * f),
            t_jerk: self.t_jerk * f,
            t_acc: self.t_acc * f,
            t_total: self.t_total * f,
            ..*self
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

    /// The first and second derivatives of the position by the fraction `s` of the path.
    pub fn derivatives(&self, s: f64) -> (V3, V3) {
        match self {
            Path::Line { from, to } => (sub(*to, *from), [0.0; 3]),
            Path::Arc { u, v, sweep, .. } => {
                let (sn, c) = (sweep * s).sin_cos();
                let w = *sweep;
                (
                    [
                        w * (v[0] * c - u[0] * sn),
                        w * (v[1] * c - u[1] * sn),
                        w * (v[2] * c - u[2] * sn),
                    ],
                    [
                        -w * w * (u[0] * c + v[0] * sn),
                        -w * w * (u[1] * c + v[1] * sn),
                        -w * w * (u[2] * c + v[2] * sn),
                    ],
                )
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

    /// Samples a profile at 100 kHz: position and speed continuous and consistent, speed
    /// within `v`, acceleration within `a`, jerk within `j` (finite differences).
    fn check_limits(p: &Profile, v: f64, a: f64, j: f64) {
        let dt = 1e-5;
        let n = (p.t_total / dt).ceil() as usize + 2;
        let mut prev_speed = 0.0;
        let mut prev_acc = 0.0;
        for k in 1..n {
            let t = k as f64 * dt;
            let speed = p.speed_at(t);
            let fd = (p.at(t) - p.at(t - dt)) / dt;
            let mid = p.speed_at(t - 0.5 * dt);
            assert!((fd - mid).abs() <= a * dt, "{p:?} at {t}: {fd} vs {mid}");
            assert!(
                speed <= v * (1.0 + 1e-12) && speed >= 0.0,
                "{p:?} at {t}: {speed}"
            );
            let acc = (speed - prev_speed) / dt;
            assert!(
                acc.abs() <= a * (1.0 + 1e-6) + 1e-9,
                "{p:?} at {t}: acc {acc}"
            );
            if j.is_finite() && k > 1 {
                assert!(((acc - prev_acc) / dt).abs() <= j * (1.0 + 1e-3) + 1e-6);
            }
            prev_speed = speed;
            prev_acc = acc;
        }
        assert_eq!(p.at(p.t_total), p.dist);
    }

    #[test]
    fn s_curves_are_time_optimal_in_closed_form() {
        // All seven phases: v·j ≥ a², and the two ramps (0.7 s, 0.35 m each) leave a
        // 0.3 m cruise at 1 m/s: 1.7 s (Ruckig gives 1.7 s too).
        let p = Profile::with_jerk(1.0, 1.0, 2.0, 10.0);
        assert!((p.t_total - 1.7).abs() < 1e-15, "{p:?}");
        check_limits(&p, 1.0, 2.0, 10.0);
        // No cruise, still reaching a: v = (a/2)(√(a²/j² + 4d/a) − a/j) = √1.04 − 0.2.
        let p = Profile::with_jerk(0.5, 1.0, 2.0, 10.0);
        let v: f64 = (0.04f64 + 1.0).sqrt() - 0.2;
        assert!((p.v - v).abs() < 1e-15 && (p.t_total - 2.0 * (v / 2.0 + 0.2)).abs() < 1e-15);
        check_limits(&p, 1.0, 2.0, 10.0);
        // Four jerk phases: t_j = ∛(d/2j), T = 4·t_j.
        let p = Profile::with_jerk(0.002, 1.0, 2.0, 10.0);
        assert!((p.t_total - 4.0 * 0.0001f64.cbrt()).abs() < 1e-15);
        check_limits(&p, 1.0, 2.0, 10.0);
        // Speed limit below a²/j: the acceleration peaks at √(v·j) = 1 < 2.
        let p = Profile::with_jerk(1.0, 0.1, 2.0, 10.0);
        // t_j = √(v/j) = 0.1 s, t_acc = 0.2 s covering 0.02 m: 0.4 s + 0.98 m at 0.1 m/s.
        assert!((p.t_total - 10.2).abs() < 1e-12, "{p:?}");
        check_limits(&p, 0.1, 2.0, 10.0);
        // An infinite jerk is the trapezoid, bit for bit.
        assert_eq!(
            Profile::with_jerk(0.5, 1.0, 2.0, f64::INFINITY),
            Profile::new(0.5, 1.0, 2.0)
        );
    }

    #[test]
    fn acceleration_and_jerk_are_the_derivatives_of_speed_and_time_at_inverts_at() {
        for p in [
            Profile::with_jerk(1.0, 1.0, 2.0, 10.0),
            Profile::with_jerk(0.002, 1.0, 2.0, 10.0),
            Profile::new(0.5, 1.0, 2.0),
            Profile::with_jerk(1.0, 1.0, 2.0, 10.0).lasting(3.0, 2.0),
        ] {
            let dt = 1e-7;
            let bps = p.breakpoints();
            for k in 1..1000 {
                let t = p.t_total * k as f64 / 1000.0;
                if bps.iter().any(|b| (t - b).abs() < 2.0 * dt) {
                    continue;
                }
                let fd = (p.speed_at(t + dt) - p.speed_at(t - dt)) / (2.0 * dt);
                assert!(
                    (fd - p.accel_at(t)).abs() < 1e-5 * p.a.max(1.0),
                    "{p:?} at {t}"
                );
                // And the jerk its derivative (0 on a trapezoid's ramps).
                let fd = (p.accel_at(t + dt) - p.accel_at(t - dt)) / (2.0 * dt);
                let jerk = if p.j.is_finite() { p.j } else { 1.0 };
                assert!(
                    (fd - p.jerk_at(t)).abs() < 1e-6 * jerk,
                    "{p:?} at {t}: {fd} against {}",
                    p.jerk_at(t)
                );
                let d = p.at(t);
                assert!((p.at(p.time_at(d)) - d).abs() < 1e-12);
            }
        }
    }

    #[test]
    fn lasting_profiles_end_exactly_when_asked_within_their_limits() {
        for (d, v, a, j) in [
            (1.0, 1.0, 2.0, 10.0),
            (0.05, 1.0, 2.0, 10.0),
            (0.002, 1.0, 2.0, 10.0),
            (1.0, 1.0, 2.0, f64::INFINITY),
            (0.01, 1.0, 2.0, f64::INFINITY),
        ] {
            let p = Profile::with_jerk(d, v, a, j);
            for k in [1.0, 1.0001, 1.3, 2.0, 10.0] {
                let t = p.t_total * k;
                let q = p.lasting(t, a);
                assert_eq!(q.t_total, t);
                assert!((q.at(t * (1.0 - 1e-12)) - d).abs() < 1e-9, "{q:?}");
                check_limits(&q, v, a, j);
            }
        }
    }

    #[test]
    fn profiles_made_to_last_longer_end_together() {
        let fast = Profile::new(0.5, 2.0, 4.0);
        let s = fast.lasting(2.0, 4.0);
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
