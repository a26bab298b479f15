//! Zones (fly-by points), as a controller makes them.
//!
//! - A zoned motion's `motion_end` happens when the TCP enters its zone (`zone_entry`) or,
//!   for a line with a trapezoid profile, earlier at its look-ahead point: the
//!   program runs ahead from there while the robot goes on toward the point (the motion
//!   becomes [`Fading`]).
//! - Two lines with trapezoid profiles fly by with *corner ramps* (`corner_ramps`,
//!   profiles in `crate::ramps`): the first holds its speed, brakes and ramps out to rest
//!   at its point while the next ramps in, both in the same time; their sum is a parabola
//!   inside the zone with a constant acceleration within both motions'.
//! - Any other next motion is planned from the corner as if from rest, and *superposed* on
//!   the rest of the previous one: `q(t) = q₁(t) + q₂(t − t_s) − corner` in joint space, or
//!   `p(t) = p₁(t) + p₂(t − t_s) − P` (orientation `R₂·R_Pᵀ·R₁`) when both are Cartesian.
//!   `blend_start` picks the earliest start `t_s` at which the corner stays within the zone
//!   and the axes within their limits (`docs/engine.md`, "Zones", gives the conditions).
//! - A statement that takes time without moving (or grips, or ends the program) makes the
//!   zoned point a stop point: its event waits until the robot is there (`stop_point`).
//!
//! Everything that samples the robot (`joints_at`, `tcp_at`, `axis_rate_bounds`,
//! `moving_at`, in `arm`) sees the blended path. The functions here are pure: the robot
//! model, the motions and the times in, a time or a radius out.

use vworks_model::RobotModel;
use vworks_model::math::{Iso, V3, axpy, mat_mul, norm, rotation_vector, sub, transpose};
use vworks_model::timing::KNOTS;

use super::plan::{JOINT_SPEED_TOLERANCE, Trajectory};
use super::quarters::chord_peak;
use crate::MAX_AXES;
use crate::bytecode::{Instr, SrcPos};
use crate::motion::{NS, Path, Profile};
use crate::ramps::Ramps;

/// The rest of a zoned motion after its `motion_end`: the robot goes on along it until
/// it reaches its point ([`Fading::end`]), and the next motion is superposed on it.
#[derive(Clone, Debug)]
pub(super) struct Fading {
    /// The motion (its zone: [`Planned::zone`]).
    pub(super) motion: Planned,
    /// The point, exactly: the joints and the TCP pose.
    pub(super) corner: [f64; MAX_AXES],
    pub(super) corner_pose: Iso,
    /// The statement of the motion.
    pub(super) pos: SrcPos,
}

impl Fading {
    /// When the robot reaches the point.
    pub(super) fn end(&self) -> i64 {
        self.motion.start + self.motion.point_ns
    }

    /// Seconds from the motion's start to `t` (ns).
    pub(super) fn dt(&self, t: i64) -> f64 {
        (t - self.motion.start) as f64 / NS
    }
}

/// A motion ready to start, then the current one: its trajectory, when it starts, when
/// its `motion_end` comes and when it reaches its point (both from its start).
#[derive(Clone, Debug)]
pub(super) struct Planned {
    pub(super) traj: Trajectory,
    pub(super) start: i64,
    pub(super) end_ns: i64,
    pub(super) point_ns: i64,
    /// When it enters its zone (from its start; `point_ns` without one): its
    /// `motion_end` is there or, with look-ahead, before.
    pub(super) entry_ns: i64,
    /// The zone radius its `motion_end` is placed with (0: a stop point).
    pub(super) zone: f64,
    /// The zone as programmed (or the workcell's default); `None`: `fine`.
    pub(super) programmed: Option<f64>,
    /// Its orientation zone (RAPID's extended zone), larger than its zone: radius (m) and
    /// angle (rad).
    pub(super) ori_zone: Option<(f64, f64)>,
    /// The radius within which it blends out of the previous zoned point, if it does.
    pub(super) blend: Option<f64>,
    /// Its TCP in the tool link's frame.
    pub(super) tool: Iso,
}

/// Samples of the corner checked for reachability, axis speeds and (joint-space corners)
/// the zone.
const CORNER_SAMPLES: usize = 64;

/// How far below its limit an axis's acceleration must stay at a superposed corner's
/// samples: second differences over 1/64 of the corner average the acceleration, so its
/// peaks between them are a little higher (at 1 kHz, up to 0.07 % above the samples on
/// random corners with jerk limits).
const SAMPLED_ACCEL_MARGIN: f64 = 0.01;

/// The joints at `t` of motion `next` starting at `ts` superposed on the rest of `f`
/// (in Cartesian space when both are Cartesian); `None` where IK fails.
pub(super) fn blend_joints(
    model: &RobotModel,
    f: &Fading,
    next: &Trajectory,
    ts: i64,
    t: i64,
) -> Option<[f64; MAX_AXES]> {
    let d1 = f.dt(t);
    let d2 = (t - ts) as f64 / NS;
    if f.motion.traj.is_cartesian() && next.is_cartesian() {
        if t <= ts {
            return f.motion.traj.joints_at(model, d1);
        }
        if t >= f.end() {
            return next.joints_at(model, d2);
        }
        return next.ik_on(
            model,
            &blend_pose(model, f, next, ts, t),
            next.fraction_at(d2),
        );
    }
    let q1 = f.motion.traj.joints_at(model, d1)?;
    let mut q = next.joints_at(model, d2)?;
    for ((qi, a), c) in q.iter_mut().zip(q1).zip(f.corner) {
        *qi += a - c;
    }
    Some(q)
}

/// The TCP of a Cartesian corner at `t`: `p₁ + p₂ − P`, orientation `R₂·R_Pᵀ·R₁`.
pub(super) fn blend_pose(
    model: &RobotModel,
    f: &Fading,
    next: &Trajectory,
    ts: i64,
    t: i64,
) -> Iso {
    use vworks_model::math::{mat_mul, transpose};
    let a = f.motion.traj.pose_at(model, &Iso::IDENTITY, f.dt(t));
    let b = next.pose_at(model, &Iso::IDENTITY, (t - ts) as f64 / NS);
    let p = f.corner_pose;
    Iso {
        r: mat_mul(&mat_mul(&b.r, &transpose(&p.r)), &a.r),
        t: [
            a.t[0] + b.t[0] - p.t[0],
            a.t[1] + b.t[1] - p.t[1],
            a.t[2] + b.t[2] - p.t[2],
        ],
    }
}

/// Where a motion of `point_ns` enters the zone of radius `r` around its point: its
/// look-ahead point (where its `motion_end` happens), the radius used, and the time it
/// reaches the zone's boundary, all from its start. A Cartesian motion's zone is at most
/// half its path (`s = 1 − r/L` along it); one that can fly by with corner ramps
/// ([`ramp_profile`]) looks ahead from where it would have to begin braking for the
/// sharpest corner (a reversal: `1 − s = ṡ²/2a + r/2`), if that is before the zone. A
/// joint motion's zone begins where the TCP comes within `r` of the point, and not
/// before half its duration. With an orientation zone `ori` (radius, angle: RAPID's
/// extended zone, where the tool begins to turn towards the next motion), the
/// `motion_end` is no later than where the robot enters it ([`extended_share`]).
pub(super) fn zone_entry(
    model: &RobotModel,
    tool: &Iso,
    rest: &[f64; MAX_AXES],
    traj: &Trajectory,
    point_ns: i64,
    (r, ori): (f64, Option<(f64, f64)>),
) -> (i64, f64, i64) {
    let total = point_ns as f64 / NS;
    let to_ns = |t: f64| ((t * NS).ceil() as i64).clamp(0, point_ns);
    if let Trajectory::Cartesian {
        path,
        profile,
        from,
        to,
        ..
    } = traj
    {
        let len = path.length();
        if len <= 1e-7 || profile.dist <= 0.0 {
            return (point_ns, 0.0, point_ns);
        }
        let r1 = r.min(0.5 * len);
        let boundary = traj.time_at_own_fraction(1.0 - r1 / len);
        // (Where the tool begins to turn towards the next motion: the extended zone.)
        let share = extended_share(r1 / len, ori, len, turn_angle(from, to));
        let extended = if share > r1 / len {
            traj.time_at_own_fraction(1.0 - share)
        } else {
            boundary
        };
        let Some(ramps) = ramp_profile(traj) else {
            return (to_ns(extended), r1, to_ns(boundary));
        };
        let (a, rf) = (ramps.accel, r1 / len);
        let must_brake = |t: f64| {
            let v = ramps.speed_at(t);
            // (A millionth of the radius early: braking for a reversal stays feasible
            // after the decision is rounded up to a whole nanosecond.)
            1.0 - ramps.at(t) <= v * v / (2.0 * a) + 0.5 * rf * (1.0 + 1e-6)
        };
        let (mut lo, mut hi) = (0.0, boundary);
        if must_brake(hi) {
            for _ in 0..100 {
                let mid = 0.5 * (lo + hi);
                if mid <= lo || mid >= hi {
                    break;
                }
                if must_brake(mid) {
                    hi = mid;
                } else {
                    lo = mid;
                }
            }
        }
        // (Rounded down: the decision is never past the braking point or the zone.)
        let decision = ((hi.min(extended) * NS).floor() as i64).clamp(0, point_ns);
        return (decision, r1, to_ns(boundary));
    }
    let n = model.dof();
    let point = model.tcp(&traj.end_joints()[..n], tool).t;
    let dist = |t: f64| {
        let q = traj.joints_at(model, t).unwrap_or(*rest);
        norm(sub(model.tcp(&q[..n], tool).t, point))
    };
    const STEPS: usize = 32;
    let at = |k: usize| 0.5 * total + 0.5 * total * k as f64 / STEPS as f64;
    // The last sample still outside the zone, from the end back to the middle.
    let Some(k) = (0..STEPS).rev().find(|&k| dist(at(k)) > r) else {
        // The TCP is within `r` all through the second half, but its distance from
        // the point need not fall all the way: the zone is the farthest it gets.
        let farthest = (0..=STEPS).map(|k| dist(at(k))).fold(0.0, f64::max);
        let t = to_ns(0.5 * total);
        return (t, farthest, t);
    };
    let within = |r: f64, k: usize| {
        let (mut lo, mut hi) = (at(k), at(k + 1));
        for _ in 0..60 {
            let mid = 0.5 * (lo + hi);
            if dist(mid) > r {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        hi
    };
    let entry = within(r, k);
    // (An extended zone: where the TCP comes within its radius, from the middle on.)
    let decision = match ori {
        Some((rho, _)) if rho > r => match (0..STEPS).rev().find(|&k| dist(at(k)) > rho) {
            Some(k) => within(rho, k),
            None => 0.5 * total,
        },
        _ => entry,
    };
    (to_ns(decision.min(entry)), r, to_ns(entry))
}

/// The angle (rad) a Cartesian motion turns its tool by, from `from` to `to`.
pub(super) fn turn_angle(from: &Iso, to: &Iso) -> f64 {
    norm(rotation_vector(&mat_mul(&transpose(&from.r), &to.r)))
}

/// The share of a Cartesian motion's path (of length `len`, turning its tool by `angle`)
/// that its extended zone covers, from its point back: RAPID's `pzone_ori` as a share
/// (at most half the path) and no more than turns the tool by `zone_ori`, and never less
/// than the TCP zone's share `tcp`.
pub(super) fn extended_share(tcp: f64, ori: Option<(f64, f64)>, len: f64, angle: f64) -> f64 {
    let Some((rho, alpha)) = ori else {
        return tcp;
    };
    let mut share = (rho / len).min(0.5);
    if angle > 1e-9 {
        share = share.min(alpha / angle);
    }
    share.max(tcp)
}

/// The profile of a straight line that can fly by a corner with ramps (a trapezoid in
/// path fraction, or one already changed by a corner), as [`Ramps`]; `None` for an arc, a
/// joint motion, a time-optimal timing, an S-curve, a motion given a `duration` (a corner
/// would change it) or a motion without a path length.
pub(super) fn ramp_profile(traj: &Trajectory) -> Option<Ramps> {
    let Trajectory::Cartesian {
        path,
        profile,
        timing: None,
        ramps,
        timed: false,
        ..
    } = traj
    else {
        return None;
    };
    // (Lines only: on an arc the direction turns inside the ramps, which the corner's
    // acceleration bound does not see.)
    if path.length() <= 1e-7 || !matches!(path, Path::Line { .. }) {
        return None;
    }
    if let Some(r) = ramps {
        return Some(*r);
    }
    let usable = profile.dist > 0.0
        && profile.t_jerk == 0.0
        && profile.a.is_finite()
        && profile.a > 0.0
        && profile.v > 0.0;
    usable.then(|| Ramps::trapezoid(profile.dist, profile.v, profile.a))
}

/// A corner flown with ramps: the first motion's profile from now on, the next motion's,
/// when the next starts (the first enters the corner there) and the corner's radius.
#[derive(Clone, Copy, Debug)]
pub(super) struct Corner {
    pub(super) first: Ramps,
    pub(super) next: Ramps,
    pub(super) start: i64,
    pub(super) radius: f64,
}

/// What a corner between two lines with [`ramp_profile`]s comes to.
// One per corner planned, never stored: boxing would add an allocation per corner.
#[allow(clippy::large_enum_variant)]
pub(super) enum RampCorner {
    /// It flies by with ramps.
    Flies(Corner),
    /// No corner with ramps beats stopping, and the lines turn by more than 60°
    /// (`|u₂ − u₁| > 1`): superposed as planned, their braking and accelerating would add
    /// up to more than their TCP acceleration, so the robot stops at the point.
    Stops,
}

/// The corner between the rest of `f` and `next` (two lines with [`ramp_profile`]s),
/// decided at `time`, with look-ahead (docs/engine.md, "Zones"): at radius
/// `r ≤ min(zone, L₁/2, L₂/2)`, ramps lasting w over `rᵢ = min(r, vᵢ·w/2)` (vᵢ each
/// motion's top speed), w the shortest at which the TCP's acceleration in the corner,
/// `(2r₂·u₂ − 2r₁·u₁)/w²`, is within both motions'. Of the radii and durations tried
/// ([`RADII`], [`SPEEDS`]) the one whose next motion ends first, if no later than stopping
/// at the point would, and whose samples keep every axis within its limits
/// ([`ramps_fit`]). `None`: not two such lines, or no such corner and a turn of at most
/// 60° (the superposition of [`blend_start`] then).
pub(super) fn corner_ramps(
    model: &RobotModel,
    time: i64,
    f: &Fading,
    next: &Trajectory,
) -> Option<RampCorner> {
    let (p1, p2) = (ramp_profile(&f.motion.traj)?, ramp_profile(next)?);
    let (
        Trajectory::Cartesian {
            path: path1,
            cruise_rates: c1,
            ..
        },
        Trajectory::Cartesian {
            path: path2,
            cruise_rates: c2,
            ..
        },
    ) = (&f.motion.traj, next)
    else {
        return None;
    };
    let (u1, u2) = (line_direction(path1), line_direction(path2));
    let turn = norm(sub(u2, u1));
    let fallback = (turn > 1.0).then_some(RampCorner::Stops);
    // Each motion's axes within their speeds at its top speed anywhere on its path.
    for i in 0..model.dof() {
        if c1[i].max(c2[i]) > model.axis(i).max_velocity * (1.0 + JOINT_SPEED_TOLERANCE) {
            return fallback;
        }
    }
    let (l1, l2) = (path1.length(), path2.length());
    let zone = f.motion.zone.min(0.5 * l1).min(0.5 * l2);
    if zone <= 1e-9 {
        return fallback;
    }
    let a_lim = (p1.accel * l1).min(p2.accel * l2);
    let (v1, v2) = (p1.top * l1, p2.top * l2);
    // Ramps lasting w at radius r: each as long as its motion's top speed allows, at most
    // r; the TCP's acceleration in the corner is (2r₂·u₂ − 2r₁·u₁)/w².
    let lengths = |w: f64, r: f64| (r.min(0.5 * v1 * w), r.min(0.5 * v2 * w));
    let accel_at = |w: f64, r: f64| {
        let (r1, r2) = lengths(w, r);
        2.0 * norm(axpy(r2, u2, axpy(-r1, u1, [0.0; 3]))) / (w * w)
    };
    let now = (time - f.motion.start) as f64 / NS;
    // Stopping at the point: the bound no corner may be slower than.
    let stop_end = f.end() + (next.path_duration() * NS).ceil() as i64;
    let mut candidates: [Option<(i64, Corner)>; RADII * SPEEDS] = [None; RADII * SPEEDS];
    let mut found = 0;
    for k in 0..RADII {
        let r = zone / f64::from(1u32 << k);
        // The shortest ramps: the faster motion's over the whole radius, longer while the
        // TCP's acceleration would be above both motions' (it falls as w grows).
        let mut w = 2.0 * r / v1.max(v2);
        // Both ramps over the whole radius: w = √(2r·|u₂ − u₁| / a), in closed form.
        let whole = (2.0 * r * turn / a_lim).sqrt();
        if whole >= 2.0 * r / v1.min(v2) {
            w = w.max(whole);
        } else if accel_at(w, r) > a_lim {
            let mut hi = w;
            for _ in 0..64 {
                hi *= 2.0;
                if accel_at(hi, r) <= a_lim {
                    break;
                }
            }
            let mut lo = w;
            for _ in 0..64 {
                let mid = 0.5 * (lo + hi);
                if mid <= lo || mid >= hi {
                    break;
                }
                if accel_at(mid, r) > a_lim {
                    lo = mid;
                } else {
                    hi = mid;
                }
            }
            w = hi;
        }
        for _ in 0..SPEEDS {
            let (r1, r2) = lengths(w, r);
            let ends = ((r1, 2.0 * r1 / w), (r2, 2.0 * r2 / w));
            if let Some(c) = corner_at(&p1, &p2, f, time, now, (l1, l2), ends) {
                let end = c.start + (c.next.duration() * NS).ceil() as i64;
                if end <= stop_end {
                    candidates[found] = Some((end, c));
                    found += 1;
                }
            }
            w *= 1.25;
        }
    }
    // The fastest corner whose samples keep every axis within its limits (of two that end
    // together, the larger radius).
    let candidates = &mut candidates[..found];
    candidates.sort_by(|x, y| match (x, y) {
        (Some((ex, cx)), Some((ey, cy))) => ex.cmp(ey).then(cy.radius.total_cmp(&cx.radius)),
        _ => std::cmp::Ordering::Equal,
    });
    candidates
        .iter()
        .flatten()
        .find(|(_, c)| ramps_fit(model, time, f, next, c))
        .map(|(_, c)| RampCorner::Flies(*c))
        .or(fallback)
}

/// The unit direction of a line (zero for one of no length, or an arc).
fn line_direction(path: &Path) -> V3 {
    let Path::Line { from, to } = path else {
        return [0.0; 3];
    };
    let d = sub(*to, *from);
    let n = norm(d);
    if n > 0.0 {
        axpy(1.0 / n, d, [0.0; 3])
    } else {
        [0.0; 3]
    }
}

/// Corner radii tried (the zone, then halved) and ramp durations at each (from the
/// shortest the TCP's acceleration allows, 25 % longer at a time).
const RADII: usize = 4;
const SPEEDS: usize = 5;

/// The corner between `f` (profile `p1`, decided at `time`, `now` seconds into it) and a
/// motion of profile `p2`: the first runs out over `r₁` from `v₁ₑ`, the next ramps up over
/// `r₂` to `v₂ₑ` (m, m/s; both ramps lasting `2r₁/v₁ₑ = 2r₂/v₂ₑ`), if the first can brake
/// to it and the next can still stop.
fn corner_at(
    p1: &Ramps,
    p2: &Ramps,
    f: &Fading,
    time: i64,
    now: f64,
    (l1, l2): (f64, f64),
    ((r1, v1e), (r2, v2e)): ((f64, f64), (f64, f64)),
) -> Option<Corner> {
    let first = p1.with_tail(now, r1 / l1, v1e / l1).ok()?;
    let next = Ramps::with_head(1.0, p2.top, p2.accel, r2 / l2, v2e / l2).ok()?;
    let t_z = first.time_at(1.0 - r1 / l1);
    let start = f.motion.start + (t_z * NS).ceil() as i64;
    (start >= time).then_some(Corner {
        first,
        next,
        start,
        radius: r1.max(r2),
    })
}

/// The two motions with a corner's ramps: `f` from the corner's decision on, and `next`.
pub(super) fn with_corner(f: &Fading, next: &Trajectory, c: &Corner) -> (Fading, Trajectory) {
    let mut f = f.clone();
    set_ramps(&mut f.motion.traj, c.first);
    f.motion.point_ns = (c.first.duration() * NS).ceil() as i64;
    let mut next = next.clone();
    set_ramps(&mut next, c.next);
    (f, next)
}

/// A Cartesian trajectory follows `ramps` (its axis speed bound: at its top speed
/// anywhere, which the ramps never pass).
fn set_ramps(traj: &mut Trajectory, r: Ramps) {
    if let Trajectory::Cartesian {
        ramps,
        rates,
        cruise_rates,
        ..
    } = traj
    {
        *ramps = Some(r);
        *rates = *cruise_rates;
    }
}

/// Samples of a corner flown with ramps, and of the next motion's acceleration after it.
const RAMP_SAMPLES: usize = 64;

/// The corner `c` decided at `time` sampled at [`RAMP_SAMPLES`] instants through the
/// first motion's changed approach (from `time`), as many through the overlap and as many
/// through the next motion until it has reached its top speed: every pose reachable,
/// every axis within its speed (chords) and acceleration (second differences).
fn ramps_fit(model: &RobotModel, time: i64, f: &Fading, next: &Trajectory, c: &Corner) -> bool {
    let (f, next) = with_corner(f, next, c);
    let ts = c.start;
    // The next motion at its top speed: after its ramp and acceleration phases.
    let top = c
        .next
        .phases()
        .find(|&(_, _, a)| a <= 0.0)
        .map_or(c.next.duration(), |(t0, ..)| t0);
    let spans = [
        (time, ts),
        (ts, f.end()),
        (f.end(), ts + (top * NS).ceil() as i64),
    ];
    for (from, to) in spans {
        if to <= from {
            continue;
        }
        let dt = (to - from) as f64 / NS / RAMP_SAMPLES as f64;
        let mut q = [[0.0; MAX_AXES]; 4];
        for k in 0..=RAMP_SAMPLES {
            let t = from + ((to - from) as f64 * k as f64 / RAMP_SAMPLES as f64) as i64;
            let Some(qk) = blend_joints(model, &f, &next, ts, t) else {
                return false;
            };
            q = [q[1], q[2], q[3], qk];
            if !axes_within(model, &q, k, dt, Some(1.0 + JOINT_SPEED_TOLERANCE), true) {
                return false;
            }
        }
    }
    true
}

/// The earliest start of `next` (lasting `next_ns`, planned from the corner) within
/// the rest of `f` at which the corner is feasible, and the radius around the point
/// the corner stays within. Feasibility only gets easier as the start moves later
/// (less overlap), so a bisection over whole nanoseconds finds it; at `f.end()` there
/// is no overlap (a stop point).
pub(super) fn blend_start(
    model: &RobotModel,
    tool: &Iso,
    time: i64,
    f: &Fading,
    next: &Trajectory,
    next_ns: i64,
) -> (i64, f64) {
    // (From the zone's boundary: a look-ahead point before it only serves corner ramps.)
    let lo = time.max(f.motion.start + f.motion.entry_ns);
    let hi = f.end();
    if lo >= hi {
        return (hi, 0.0);
    }
    let search = |ok: &dyn Fn(i64) -> Option<f64>, mut lo: i64| -> (i64, f64) {
        if let Some(r) = ok(lo) {
            return (lo, r);
        }
        let mut hi = hi;
        let mut best = 0.0;
        while hi - lo > 1 {
            let mid = lo + (hi - lo) / 2;
            match ok(mid) {
                Some(r) => {
                    hi = mid;
                    best = r;
                }
                None => lo = mid,
            }
        }
        (hi, if hi >= f.end() { 0.0 } else { best })
    };
    let (ts, radius) = search(&|ts| corner_bounds(model, f, next, next_ns, ts), lo);
    if ts >= f.end() {
        return (f.end(), 0.0);
    }
    // The sampled checks (inverse kinematics, axis speeds and accelerations, the zone of
    // a joint-space corner) cost more: at the start found, and only if they fail, searched
    // again.
    if let Some(r) = corner_samples(model, tool, f, next, ts) {
        return (ts, radius.max(r));
    }
    let checked = || {
        search(
            &|t| {
                let a = corner_bounds(model, f, next, next_ns, t)?;
                Some(a.max(corner_samples(model, tool, f, next, t)?))
            },
            ts,
        )
    };
    // Where no start keeps them (two motions that both brake and accelerate at an axis's
    // limit at the point cannot overlap there at all), the robot stops at the point (a
    // corner failure), as a controller does, rather than break a limit.
    checked()
}

/// The exact conditions of a corner starting at `ts`; the radius it stays within (a
/// bound) if they hold.
///
/// - Cartesian corners: the TCP is at most `A` from the point on the way in and `B`
///   on the way out (`A` the path left of the first motion at `ts`, `B` the path the
///   second has covered when the first ends); for two lines it stays within
///   `max(A, B, |B·u₂ − A·u₁|)` (a norm is convex: its maximum over the box is at a
///   corner), else within `A + B`. That must be at most the zone, itself at most half
///   the second path. The path speed (the two speeds' sum bounds it) stays within the
///   faster motion's cruise speed.
/// - Joint-space corners: every axis's summed speed and acceleration within its limits
///   (exact: checked at every phase boundary of both profiles and where the summed
///   acceleration crosses zero), and at most half the second motion's time overlaps.
fn corner_bounds(
    model: &RobotModel,
    f: &Fading,
    next: &Trajectory,
    next_ns: i64,
    ts: i64,
) -> Option<f64> {
    let window = (f.end() - ts) as f64 / NS;
    if window <= 0.0 {
        return Some(0.0);
    }
    let off1 = (ts - f.motion.start) as f64 / NS;
    match (&f.motion.traj, next) {
        (
            Trajectory::Cartesian {
                path: p1,
                profile: s1,
                timing: t1,
                ..
            },
            Trajectory::Cartesian {
                path: p2,
                profile: s2,
                timing: t2,
                ..
            },
        ) => {
            let (l1, l2) = (p1.length(), p2.length());
            let first = &f.motion.traj;
            let a = l1 * (1.0 - first.own_fraction_at(off1));
            let b = l2 * next.fraction_at(window);
            let radius = match (p1, p2) {
                (Path::Line { from, to }, Path::Line { to: to2, .. }) if l1 > 0.0 && l2 > 0.0 => {
                    let u1 = sub(*to, *from);
                    let u2 = sub(*to2, *to);
                    let v = [
                        b * u2[0] / l2 - a * u1[0] / l1,
                        b * u2[1] / l2 - a * u1[1] / l1,
                        b * u2[2] / l2 - a * u1[2] / l1,
                    ];
                    a.max(b).max(norm(v))
                }
                _ => a + b,
            };
            if radius > f.motion.zone.min(0.5 * l2) + 1e-12 {
                return None;
            }
            // (Exact on the trapezoids; a motion following corner ramps is sampled.)
            let ramped = |t: &Trajectory| matches!(t, Trajectory::Cartesian { ramps: Some(_), .. });
            if t1.is_none() && t2.is_none() && !ramped(first) && !ramped(next) {
                let k1 = if s1.dist > 0.0 { l1 / s1.dist } else { 0.0 };
                let k2 = if s2.dist > 0.0 { l2 / s2.dist } else { 0.0 };
                let vmax = (k1 * s1.v).max(k2 * s2.v);
                let (speed, _) = window_extremes(window, [(s1, off1, k1), (s2, 0.0, k2)]);
                return (speed <= vmax * (1.0 + 1e-9)).then_some(radius);
            }
            // A path timed within its axes' limits: the summed path speed at 65 points of
            // the window within the faster motion's top speed (the sampled checks of the
            // axes follow).
            let vmax = (l1 * first.top_own_speed()).max(l2 * next.top_path_speed());
            let within = (0..=64).all(|j| {
                let tau = window * f64::from(j) / 64.0;
                let v = l1 * first.own_speed_at(off1 + tau) + l2 * next.path_speed_at(tau);
                v <= vmax * (1.0 + 1e-9)
            });
            within.then_some(radius)
        }
        _ => {
            if 2.0 * window > next_ns as f64 / NS {
                return None;
            }
            // Between two joint motions (a mixed corner is checked by samples).
            for i in 0..model.dof() {
                let (Some((p1, k1)), Some((p2, k2))) =
                    (f.motion.traj.axis_profile(i), next.axis_profile(i))
                else {
                    break;
                };
                let j = model.axis(i);
                let parts = [(p1, off1, k1), (p2, 0.0, k2)];
                let (speed, acc) = window_extremes(window, parts);
                if speed > j.max_velocity * (1.0 + 1e-9) || acc > j.max_accel * (1.0 + 1e-9) {
                    return None;
                }
                // (Two S-curves' jerk phases overlapping add up too.)
                if j.max_jerk
                    .is_some_and(|jerk| window_jerk(window, parts) > jerk * (1.0 + 1e-9))
                {
                    return None;
                }
            }
            Some(0.0)
        }
    }
}

/// The corner starting at `ts`, sampled at [`CORNER_SAMPLES`] even steps (and one step
/// before and after it): every pose reachable (Cartesian corners), no axis faster than
/// its limit between samples nor accelerating harder (second differences), and for
/// joint-space corners every axis within its range and the TCP within the zone. The
/// largest distance from the point seen, if all hold.
fn corner_samples(
    model: &RobotModel,
    tool: &Iso,
    f: &Fading,
    next: &Trajectory,
    ts: i64,
) -> Option<f64> {
    let n = model.dof();
    let span = f.end() - ts;
    if span <= 0 {
        return Some(0.0);
    }
    let joint_space = !(f.motion.traj.is_cartesian() && next.is_cartesian());
    // (Between two joint motions the accelerations are bounded exactly by
    // `corner_bounds`: second differences would only add rounding.)
    let both_joint = !f.motion.traj.is_cartesian() && !next.is_cartesian();
    // Evenly spaced from a step before the corner to a step after it: the accelerations
    // of its start and end are where the two motions' add up or stop adding up.
    let step = (span / CORNER_SAMPLES as i64).max(1);
    let dt = step as f64 / NS;
    let mut q = [[0.0; MAX_AXES]; 4];
    let mut farthest = 0.0f64;
    for k in 0..=CORNER_SAMPLES as i64 + 2 {
        let t = ts + (k - 1) * step;
        q = [q[1], q[2], q[3], blend_joints(model, f, next, ts, t)?];
        let inside = t > ts && t <= f.end();
        if inside && joint_space && !model.within_limits(&q[3][..n]) {
            return None;
        }
        let accel = (!both_joint).then_some(1.0 - SAMPLED_ACCEL_MARGIN);
        if !axes_within(model, &q, k as usize, dt, accel, !both_joint) {
            return None;
        }
        if inside && joint_space {
            let p = model.tcp(&q[3][..n], tool).t;
            let d = norm(sub(p, f.corner_pose.t));
            if d > f.motion.zone {
                return None;
            }
            farthest = farthest.max(d);
        }
    }
    // (Where a profile changes phase the speed may turn at a kink, which the curves
    // through the samples round off.)
    if !both_joint && !phase_ends_within(model, f, next, ts) {
        return None;
    }
    if !both_joint && !jerks_within(model, f, next, ts) {
        return None;
    }
    Some(farthest)
}

/// How long the differences at a phase's end are (ns): long enough that the joints'
/// rounding (numeric IK converges to 1e-10 rad) stays below 1e-6 of a speed and 0.3 % of
/// an acceleration, short enough to stay within one phase of each motion.
const PHASE_END_STEP: i64 = 100_000;

/// Every axis within its speed (within [`JOINT_SPEED_TOLERANCE`], as at the samples) on
/// both sides of each instant inside the corner starting at `ts` where either motion's
/// profile changes phase ([`Trajectory::phase_ends`]), and within its acceleration there
/// as at the samples ([`SAMPLED_ACCEL_MARGIN`] below): a motion reaching its cruise at an
/// axis's limit while the other still moves that axis the same way goes over at that
/// kink, between two samples (4.8e-6 of a limit found), and two S-curves' accelerations
/// add up to a triangle whose peak is there (0.8 % over the limit, 1.8 % over the samples
/// around). By second-order differences [`PHASE_END_STEP`] long (one-sided for the
/// speeds).
fn phase_ends_within(model: &RobotModel, f: &Fading, next: &Trajectory, ts: i64) -> bool {
    let end = f.end();
    let h = PHASE_END_STEP as f64 / NS;
    let mut ok = true;
    let mut last = i64::MIN;
    let mut check = |t: i64| {
        if !ok || t <= ts || t > end || t == last {
            return;
        }
        last = t;
        // The joints 2, 1 and 0 steps before `t` and 1 and 2 after, where they lie within
        // the corner (a phase may end next to its ends).
        let mut q = [None; 5];
        for (k, q) in q.iter_mut().enumerate() {
            let at = t + (k as i64 - 2) * PHASE_END_STEP;
            if at < ts || at > end {
                continue;
            }
            match blend_joints(model, f, next, ts, at) {
                Some(joints) => *q = Some(joints),
                None => {
                    ok = false;
                    return;
                }
            }
        }
        for i in 0..model.dof() {
            let at = |k: usize| q[k].map(|q| q[i]);
            let (speed, accel) = (model.axis(i).max_velocity, model.axis(i).max_accel);
            // Each side's speed, one-sided.
            for (a, b, c) in [(at(2), at(1), at(0)), (at(2), at(3), at(4))] {
                if let (Some(a), Some(b), Some(c)) = (a, b, c)
                    && ((-3.0 * a + 4.0 * b - c) / (2.0 * h)).abs()
                        > speed * (1.0 + JOINT_SPEED_TOLERANCE)
                {
                    ok = false;
                }
            }
            // The acceleration there (its peak, where two S-curves' add up to a
            // triangle), as at the samples.
            if let (Some(a), Some(b), Some(c)) = (at(1), at(2), at(3))
                && ((a - 2.0 * b + c) / (h * h)).abs() > accel * (1.0 - SAMPLED_ACCEL_MARGIN)
            {
                ok = false;
            }
        }
    };
    let to_ns = |origin: i64, b: f64| origin + (b * NS).round() as i64;
    f.motion
        .traj
        .phase_ends(|b| check(to_ns(f.motion.start, b)));
    next.phase_ends(|b| check(to_ns(ts, b)));
    // (Where the first motion ends: where a corner's sum of speeds drops to the second's.)
    check(end);
    ok
}

/// The longest step of the third differences [`jerks_within`] takes (ns): a mean over three
/// of them stays close to the jerk of a phase of either motion.
const JERK_STEP: i64 = 500_000;
/// A quarter of the shortest corner [`jerks_within`] lets an axis with a jerk limit take (ns).
const JERK_MIN_CORNER: i64 = 250_000;

/// Every axis with a jerk limit within it through the corner starting at `ts` (a corner
/// with a Cartesian motion: its joints come from the blended poses). Between two instants
/// where either motion's profile changes phase, each motion's path jerk holds (S-curves)
/// or is none (trapezoids), and the axes' jerks change only with their slopes and the
/// speeds, so each such stretch is checked by third differences inside it, a quarter of it
/// and at most [`JERK_STEP`] apart, end to end (each a mean of the jerk over three steps;
/// a stretch shorter than 4 µs is left out). Two S-curves' jerk phases overlapping — the
/// next motion jerking up as the first jerks into its braking — add up, as their
/// accelerations do. A corner shorter than four [`JERK_MIN_CORNER`]s is not taken: it
/// would save less than a millisecond, and its own stretches would be too short to
/// measure.
fn jerks_within(model: &RobotModel, f: &Fading, next: &Trajectory, ts: i64) -> bool {
    let n = model.dof();
    if (0..n).all(|i| model.axis(i).max_jerk.is_none()) {
        return true;
    }
    let end = f.end();
    if end <= ts {
        return true;
    }
    if end - ts < 4 * JERK_MIN_CORNER {
        return false;
    }
    // (Each motion has up to 8 phase ends per profile, a joint motion one profile per
    // axis, a smooth timing its knots.)
    let mut cuts = [0i64; 2 + 2 * (8 * MAX_AXES + KNOTS)];
    let mut count = 0;
    let mut push = |t: i64| {
        if t >= ts && t <= end && count < cuts.len() {
            cuts[count] = t;
            count += 1;
        }
    };
    push(ts);
    push(end);
    let to_ns = |origin: i64, b: f64| origin + (b * NS).round() as i64;
    f.motion
        .traj
        .jerk_breaks(|b| push(to_ns(f.motion.start, b)));
    next.jerk_breaks(|b| push(to_ns(ts, b)));
    let cuts = &mut cuts[..count];
    cuts.sort_unstable();
    for w in cuts.windows(2) {
        let (a, b) = (w[0], w[1]);
        let h = ((b - a) / 4).min(JERK_STEP);
        if h < 1_000 {
            continue;
        }
        let dt = h as f64 / NS;
        // Windows of three steps end to end from its start, the last one ending at its end.
        let mut first = a;
        loop {
            let last = first + 3 * h >= b;
            if last {
                first = b - 3 * h;
            }
            let mut q = [[0.0; MAX_AXES]; 4];
            for (k, q) in q.iter_mut().enumerate() {
                match blend_joints(model, f, next, ts, first + k as i64 * h) {
                    Some(joints) => *q = joints,
                    None => return false,
                }
            }
            let over = (0..n).any(|i| {
                model.axis(i).max_jerk.is_some_and(|jerk| {
                    let d3 = q[3][i] - 3.0 * q[2][i] + 3.0 * q[1][i] - q[0][i];
                    d3.abs() / (dt * dt * dt) > jerk * (1.0 + JOINT_SPEED_TOLERANCE)
                })
            });
            if over {
                return false;
            }
            if last {
                break;
            }
            first += 3 * h;
        }
    }
    true
}

/// Every axis within its speed and acceleration at the last of four samples `dt` apart
/// (`q[3]` is sample `k`):
///
/// - its speed between the last two (when there are two: `k` ≥ 1) within
///   [`JOINT_SPEED_TOLERANCE`] of its limit, and, with `peaks` (`k` ≥ 3), its peak speed
///   between the middle two: a chord averages the speed, and a smooth peak between two
///   samples rises above it (at 1/64 of a corner, 1.8e-4 above a chord at the limit). The
///   peak is that of the derivative of the cubic through the four samples, a quadratic
///   whose means over the three intervals are their chords;
/// - with a share `accel` of its acceleration, within that by the second difference of
///   the last three (`k` ≥ 2): corner ramps `1 + JOINT_SPEED_TOLERANCE`, superposed
///   corners [`SAMPLED_ACCEL_MARGIN`] below.
fn axes_within(
    model: &RobotModel,
    q: &[[f64; MAX_AXES]; 4],
    k: usize,
    dt: f64,
    accel: Option<f64>,
    peaks: bool,
) -> bool {
    (0..model.dof()).all(|i| {
        let axis = model.axis(i);
        let top = axis.max_velocity * (1.0 + JOINT_SPEED_TOLERANCE);
        let [d1, d2, d3] = [1, 2, 3].map(|j| (q[j][i] - q[j - 1][i]) / dt);
        let speed = k < 1 || d3.abs() <= top;
        let peak = !peaks || k < 3 || chord_peak([d1, d2, d3], 0.0) <= top;
        let within = k < 2
            || accel.is_none_or(|share| {
                (q[3][i] - 2.0 * q[2][i] + q[1][i]).abs() / (dt * dt) <= axis.max_accel * share
            });
        speed && peak && within
    })
}

/// What makes a zoned point still ahead a stop point, named for the warning: the main
/// program's statement at instruction `ins` (`None`: its end; `remote`: the program is
/// remote work), if it takes time without moving, grips or releases, or ends the program.
pub(super) fn stop_point_reason(ins: Option<Instr>, remote: bool) -> Option<&'static str> {
    Some(match ins {
        None | Some(Instr::Stop) if remote => "the end of the remote procedure",
        None | Some(Instr::Stop) => "the end of the program",
        Some(Instr::Delay) => "`delay`",
        Some(Instr::WaitUntil(..) | Instr::WaitPoll(..)) => "`wait_until`",
        Some(Instr::WaitSignal(..)) => "`wait_signal`",
        Some(Instr::WaitSync(..)) => "`sync`",
        Some(Instr::ParJoin) => "the end of a `parallel` block",
        Some(Instr::Grip(_)) => "`grip`",
        Some(Instr::Release(_)) => "`release`",
        _ => return None,
    })
}

/// Instants to evaluate two motions `k·p(t + offset)` at over `[0, window]`, in order: an
/// even grid, and every phase boundary of either inside the window with a point just
/// before it (how many there are: the rest of the array is unused).
fn window_instants(
    window: f64,
    parts: [(&Profile, f64, f64); 2],
) -> ([f64; WINDOW_INSTANTS], usize) {
    const GRID: usize = 8;
    let mut ts = [0.0f64; WINDOW_INSTANTS];
    let mut n = 0;
    for k in 0..=GRID {
        ts[n] = window * k as f64 / GRID as f64;
        n += 1;
    }
    for (p, off, _) in parts {
        for b in p.breakpoints() {
            let t = b - off;
            if t > 0.0 && t < window {
                ts[n] = t;
                ts[n + 1] = (t - 1e-9).max(0.0);
                n += 2;
            }
        }
    }
    ts[..n].sort_unstable_by(f64::total_cmp);
    (ts, n)
}

/// The grid's 9 instants and two for each of the two profiles' 8 phase boundaries.
const WINDOW_INSTANTS: usize = 9 + 2 * 2 * 8;

/// The largest summed jerk of two profiles (each shifted by `off` and scaled by `k`) over
/// `[0, window]`: both are piecewise constant, so it is taken halfway between each two of
/// the instants of [`window_instants`], which hold every phase boundary.
fn window_jerk(window: f64, parts: [(&Profile, f64, f64); 2]) -> f64 {
    let (ts, n) = window_instants(window, parts);
    let jerk = |t: f64| {
        parts
            .iter()
            .map(|(p, off, k)| k * p.jerk_at(t + off))
            .sum::<f64>()
    };
    ts[..n]
        .windows(2)
        .map(|w| jerk(0.5 * (w[0] + w[1])).abs())
        .fold(0.0, f64::max)
}

/// The largest |summed speed| and |summed acceleration| over `[0, window]` of motions
/// `k·p(t + offset)`: exact for these piecewise-polynomial profiles (acceleration linear
/// between phase boundaries), as every boundary (and a point just before it) is
/// evaluated, and the speed also where the summed acceleration crosses zero.
fn window_extremes(window: f64, parts: [(&Profile, f64, f64); 2]) -> (f64, f64) {
    let (ts, n) = window_instants(window, parts);
    let ts = &ts[..n];
    let speed = |t: f64| {
        parts
            .iter()
            .map(|(p, off, k)| k * p.speed_at(t + off))
            .sum::<f64>()
    };
    let acc = |t: f64| {
        parts
            .iter()
            .map(|(p, off, k)| k * p.accel_at(t + off))
            .sum::<f64>()
    };
    let (mut vmax, mut amax) = (0.0f64, 0.0f64);
    for w in 0..ts.len() {
        let t = ts[w];
        let a = acc(t);
        vmax = vmax.max(speed(t).abs());
        amax = amax.max(a.abs());
        if let Some(&t2) = ts.get(w + 1) {
            let a2 = acc((t2 - 1e-12).max(t));
            if a * a2 < 0.0 {
                let z = t + (t2 - t) * a / (a - a2);
                vmax = vmax.max(speed(z).abs());
            }
        }
    }
    (vmax, amax)
}
