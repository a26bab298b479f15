//! Corners timed as one path (docs/engine.md, "Zones", "Timed corners"): a Cartesian
//! motion that flies out of the zone of a Cartesian motion timed within its axes' limits
//! takes the robot over where it is, and moves along the rest of the first path to the
//! zone, a curve inside it, and the rest of its own path, timed as one path from the
//! robot's speed to rest (`vworks_model::timing::Timing::from_speed`).
//!
//! The curve is the two paths *superposed* with fixed progressions: with `u` from 0 to 1
//! through the curve, the first path runs from where its zone begins to its point as
//! `1 − (1 − u)²` of that stretch and the second from its point to where its zone ends
//! as `u²`, and the pose is `p₁ + p₂ − P`, orientation `R₂·R_Pᵀ·R₁`. For two lines this is
//! the parabola from `P − r·u₁` to `P + r·u₂` (the quadratic Bézier curve with its control
//! point at the corner), within `r·((1 − u)² + u²) ≤ r` of the point: inside the zone; for
//! arcs, the same sum. The shares of the path's fraction `s` given to the three pieces
//! make the pose's derivative by `s` continuous at both joins (the joints' speeds are
//! continuous); its second derivative is not (the curve's curvature begins there), so the
//! joins are knots of the timing, with each side's derivatives on its side. These limits
//! hold through the corner: the axes' speeds and accelerations, the TCP's speed (from the
//! first motion's to the second's across the curve), its whole acceleration (along and
//! across the path, knot by knot) and each motion's own path speed (its orientation speed
//! on its own pieces; in the curve the two rotations compose).
//!
//! For an arm with jerk limits the progressions are `h(u) = 2u³ − u⁴` and its mirror
//! ([`run_out`]): the same shares of `s`, and no second derivative at the joins, so the
//! curvature and every axis's acceleration are continuous there; the path is timed within
//! every axis's jerk from the robot's path speed *and acceleration* as it takes over
//! (`smooth::time_smooth`, `Timing::jerk_limited_from`), its steps' `q‴` from their
//! quarter points (it jumps where the curve begins).
//!
//! With an orientation zone wider than the curve (RAPID's `pzone_ori`, [`Turn`]), the
//! tool turns over that wider stretch, centred on the curve, with progressions of the same
//! form of its own; the position's curve is unchanged (docs/engine.md, "Orientation
//! zones").

use vworks_model::RobotModel;
use vworks_model::math::{Iso, V3, add, axpy, dot, mat_mul, norm, sub, transpose};
use vworks_model::timing::{JointPath, KNOTS, KnotLimits, SEGMENTS, Timing};

use super::blend::{Fading, turn_angle};
use super::jerks::axis_jerks;
use super::path::{
    Memo, PathLimits, Untimed, axis_limits, knot_derivatives, knot_joints, sample_knots, seeds_of,
    timed_rates,
};
use super::plan::{Trajectory, to_ns};
use super::quarters::Inner;
use super::smooth::{smooth_look_ahead, time_smooth};
use crate::MAX_AXES;
use crate::motion::{NS, Path, cartesian_at, slerp};
use std::convert::Infallible;

/// How a trajectory that flies out of a zone follows the previous motion's path and its
/// own (module docs): the fractions of both at its own fraction `s`.
#[derive(Clone, Debug, PartialEq)]
pub(super) struct TimedCorner {
    /// The previous motion's path, its start pose and its point.
    pub(super) first: Path,
    pub(super) first_from: Iso,
    pub(super) first_to: Iso,
    /// The first path's fraction where the robot was when this motion took over, and
    /// where its zone begins.
    pub(super) f_now: f64,
    pub(super) f_in: f64,
    /// The fraction of this motion's own path where the zone ends.
    pub(super) f_out: f64,
    /// Where the curve begins and ends in `s`.
    pub(super) s_in: f64,
    pub(super) s_out: f64,
    /// Where the tool turns over a wider stretch than the curve (an orientation zone).
    pub(super) turn: Option<Turn>,
    /// Whether the progressions keep the curve's curvature continuous (an arm with jerk
    /// limits: [`run_out`]).
    pub(super) smooth: bool,
}

/// Where the tool turns from the first motion's orientation to the second's over more
/// than the curve (RAPID's orientation zone, module docs): from `s_in` to `s_out`, centred
/// on the curve, the first path's orientation running out from its fraction `f_in` and
/// the second's running in to its fraction `f_out`, as the curve's progressions do.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct Turn {
    pub(super) s_in: f64,
    pub(super) s_out: f64,
    pub(super) f_in: f64,
    pub(super) f_out: f64,
}

/// The fractions of both paths at `s` and their first and second derivatives by `s`.
#[derive(Clone, Copy, Debug)]
struct Progress {
    f1: f64,
    d1: f64,
    dd1: f64,
    f2: f64,
    d2: f64,
    dd2: f64,
}

impl TimedCorner {
    fn progress(&self, s: f64) -> Progress {
        self.progress_on(s, false)
    }

    /// [`TimedCorner::progress`], or at a join, with `curve`, the curve's side of it (its
    /// curvature begins there).
    fn progress_on(&self, s: f64, curve: bool) -> Progress {
        let join = s == self.s_in || s == self.s_out;
        if curve && join && self.s_out > self.s_in {
            return self.in_curve(s);
        }
        if s <= self.s_in && self.s_in > 0.0 {
            let d1 = (self.f_in - self.f_now) / self.s_in;
            return Progress {
                f1: self.f_now + d1 * s,
                d1,
                dd1: 0.0,
                f2: 0.0,
                d2: 0.0,
                dd2: 0.0,
            };
        }
        if s >= self.s_out {
            let d2 = (1.0 - self.f_out) / (1.0 - self.s_out);
            return Progress {
                f1: 1.0,
                d1: 0.0,
                dd1: 0.0,
                f2: (self.f_out + d2 * (s - self.s_out)).min(1.0),
                d2,
                dd2: 0.0,
            };
        }
        self.in_curve(s)
    }

    /// The progressions inside the curve at `s` (clamped to it).
    fn in_curve(&self, s: f64) -> Progress {
        let sigma = self.s_out - self.s_in;
        let u = ((s - self.s_in) / sigma).clamp(0.0, 1.0);
        let (r1, r2) = (1.0 - self.f_in, self.f_out);
        let (g1, g1d, g1dd) = run_out(u, self.smooth);
        let (g2, g2d, g2dd) = run_out(1.0 - u, self.smooth);
        Progress {
            f1: self.f_in + r1 * g1,
            d1: r1 * g1d / sigma,
            dd1: r1 * g1dd / (sigma * sigma),
            f2: r2 * (1.0 - g2),
            d2: r2 * g2d / sigma,
            dd2: -r2 * g2dd / (sigma * sigma),
        }
    }

    /// Inside the turn, the fractions of both paths the orientation follows at `s` and
    /// their rates by `s` (`o1, o1', o2, o2'`); `None` outside it (the orientation follows
    /// the position's progressions).
    fn turning(&self, s: f64) -> Option<[f64; 4]> {
        let w = self.turn.as_ref().filter(|w| s > w.s_in && s < w.s_out)?;
        let width = w.s_out - w.s_in;
        let u = (s - w.s_in) / width;
        let (g, gd, _) = run_out(u, self.smooth);
        let (g2, g2d, _) = run_out(1.0 - u, self.smooth);
        let (r1, r2) = (1.0 - w.f_in, w.f_out);
        Some([
            w.f_in + r1 * g,
            r1 * gd / width,
            r2 * (1.0 - g2),
            r2 * g2d / width,
        ])
    }

    /// Where the corner is over: the curve, or the turn if it ends later (the pose is
    /// the motion's own path's from there on).
    pub(super) fn end(&self) -> f64 {
        self.turn.map_or(self.s_out, |w| w.s_out.max(self.s_out))
    }

    /// The TCP pose at `s` of the motion whose own path is `path` from `from` to `to`.
    pub(super) fn pose(&self, path: &Path, from: &Iso, to: &Iso, s: f64) -> Iso {
        let p = self.progress(s);
        if let Some([o1, _, o2, _]) = self.turning(s) {
            let one = cartesian_at(&self.first, &self.first_from, &self.first_to, p.f1);
            let two = cartesian_at(path, from, to, p.f2);
            let r1 = slerp(&self.first_from.r, &self.first_to.r, o1);
            let r2 = slerp(&from.r, &to.r, o2);
            return Iso {
                r: mat_mul(&r2, &mat_mul(&transpose(&self.first_to.r), &r1)),
                t: sub(add(one.t, two.t), self.first_to.t),
            };
        }
        if p.f2 <= 0.0 {
            return cartesian_at(&self.first, &self.first_from, &self.first_to, p.f1);
        }
        if p.f1 >= 1.0 {
            return cartesian_at(path, from, to, p.f2);
        }
        let one = cartesian_at(&self.first, &self.first_from, &self.first_to, p.f1);
        let two = cartesian_at(path, from, to, p.f2);
        Iso {
            r: mat_mul(&two.r, &mat_mul(&transpose(&self.first_to.r), &one.r)),
            t: sub(add(one.t, two.t), self.first_to.t),
        }
    }

    /// The fraction of the motion's own path done at `s`.
    pub(super) fn own_fraction(&self, s: f64) -> f64 {
        self.progress(s).f2
    }

    /// The rate of the motion's own fraction per unit of `s` at `s`.
    pub(super) fn own_rate(&self, s: f64) -> f64 {
        self.progress(s).d2
    }

    /// The `s` at which the motion's own fraction is `f2` (the curve's start for 0).
    pub(super) fn s_of_own(&self, f2: f64) -> f64 {
        if f2 >= self.f_out {
            let share = (1.0 - self.s_out) / (1.0 - self.f_out);
            return (self.s_out + (f2 - self.f_out) * share).min(1.0);
        }
        if f2 <= 0.0 {
            return self.s_in;
        }
        // f2 = r₂·(1 − g(1 − u)): u², or with smooth progressions 2u³ − u⁴, increasing
        // (by bisection).
        let share = f2 / self.f_out;
        let u = if self.smooth {
            let (mut lo, mut hi) = (0.0f64, 1.0f64);
            for _ in 0..60 {
                let mid = 0.5 * (lo + hi);
                if 1.0 - run_out(1.0 - mid, true).0 < share {
                    lo = mid;
                } else {
                    hi = mid;
                }
            }
            hi
        } else {
            share.sqrt()
        };
        self.s_in + (self.s_out - self.s_in) * u
    }
}

/// Knots for a path of five pieces meeting at `joins` (fractions, increasing; a piece of
/// no length gets no steps): the turn's stretch before the curve, the curve (the middle
/// one) and the turn's stretch after it between the straight pieces at both ends. Each
/// piece in equal steps, as many as its share (at least two; the curve at least
/// [`CURVE_STEPS`]), and the knots where they meet.
fn piece_knots(joins: [f64; 4]) -> ([f64; KNOTS], [usize; 4]) {
    let ends = [0.0, joins[0], joins[1], joins[2], joins[3], 1.0];
    let mut steps = [0usize; 5];
    let mut least = [0usize; 5];
    for (j, st) in steps.iter_mut().enumerate() {
        let share = ends[j + 1] - ends[j];
        if share > 0.0 {
            least[j] = if j == 2 { CURVE_STEPS } else { 2 };
            *st = ((share * SEGMENTS as f64).round() as usize).max(least[j]);
        }
    }
    // The largest piece takes what the rounding leaves over or short, where it keeps its
    // least; else the pieces furthest above theirs give up a step each in turn (the
    // least of all five, CURVE_STEPS + 8, fit in SEGMENTS).
    let mut total: usize = steps.iter().sum();
    let big = (0..5).max_by_key(|&j| steps[j]).unwrap_or(4);
    if steps[big] + SEGMENTS >= total + least[big] {
        steps[big] = steps[big] + SEGMENTS - total;
    } else {
        while total > SEGMENTS {
            let j = (0..5).max_by_key(|&j| steps[j] - least[j]).unwrap_or(4);
            if steps[j] <= least[j] {
                break;
            }
            steps[j] -= 1;
            total -= 1;
        }
    }
    let mut knots = [0.0f64; KNOTS];
    let mut k = 0;
    for (j, st) in steps.iter().enumerate() {
        for m in 0..*st {
            // (The steps sum to SEGMENTS: CURVE_STEPS + 8 ≤ SEGMENTS.)
            if let Some(knot) = knots.get_mut(k) {
                *knot = ends[j] + (ends[j + 1] - ends[j]) * m as f64 / *st as f64;
            }
            k += 1;
        }
    }
    knots[SEGMENTS] = 1.0;
    let mut breaks = [0usize; 4];
    let mut at = 0;
    for (b, st) in breaks.iter_mut().zip(steps) {
        at += st;
        *b = at;
    }
    (knots, breaks)
}

/// The first path's progression through the curve, `g(u) = 2u − u² = 1 − (1 − u)²`, and
/// its first and second derivatives: from 0 at slope 2 to 1 at slope 0 (the second runs
/// in as `1 − g(1 − u) = u²`). With `smooth`, `g(u) = 1 − h(1 − u)` with `h(v) = 2v³ −
/// v⁴`: the same slopes at both ends, and no second derivative there (`h(0) = h′(0) =
/// h″(0) = 0`, `h(1) = 1`, `h′(1) = 2`, `h″(1) = 0`), so the curve's curvature begins at
/// 0 and the axes' accelerations are continuous at the joins (an arm with jerk limits
/// would jump there); its second runs in as `h(u)`. Both keep the curve within the zone:
/// for two lines the TCP is within `r·(e₁ + e₂) ≤ r` of the point.
fn run_out(u: f64, smooth: bool) -> (f64, f64, f64) {
    if smooth {
        let v = 1.0 - u;
        let (v2, v3) = (v * v, v * v * v);
        (
            1.0 - (2.0 * v3 - v2 * v2),
            6.0 * v2 - 4.0 * v3,
            -(12.0 * v - 12.0 * v2),
        )
    } else {
        (2.0 * u - u * u, 2.0 - 2.0 * u, -2.0)
    }
}

/// The fewest steps of a corner's curve: it turns the TCP within the zone, often a small
/// share of the path, and its axes' accelerations change along it.
const CURVE_STEPS: usize = 64;
const _: () = assert!(CURVE_STEPS + 8 <= SEGMENTS);

/// How much wider (relative) than a corner's curve its orientation zone must be for the
/// tool to turn over it: below, it turns within the curve.
pub(super) const TURN_WIDER: f64 = 1e-3;

/// How much faster (in `ṡ²`) the robot may be than the fastest start a corner's timing
/// finds, for that start to be taken: half the timing's margin below the limits.
const START_TOLERANCE: f64 = 4e-4;

/// A corner timed as one path: the next motion's trajectory from now, how long it takes
/// (ns), its own look-ahead point (s from its start) and the radius of the corner.
#[derive(Clone, Debug)]
pub(super) struct Taken {
    pub(super) traj: Trajectory,
    pub(super) point_ns: i64,
    pub(super) look_ahead: Option<f64>,
    pub(super) radius: f64,
}

/// The next Cartesian motion `next` (planned from the point as if from rest) taking the
/// robot over at `time` from the rest of `f`, a Cartesian motion timed within its axes'
/// limits (module docs); `next_zone` its own zone. `None` where this corner does not
/// apply (a motion with a `duration`, corner ramps, a path of no length, the
/// robot already inside the zone or still in a corner of its own) or has no timing that
/// starts at the robot's speed (and, with jerk limits, its acceleration) and ends by
/// `stop_end` (where stopping at the point would):
/// the caller superposes them instead. With `plain` false, only a corner that turns the
/// tool over its orientation zone (where the caller has corner ramps to fall back on, as
/// without an orientation zone). With the corner, the instant it takes over:
/// `time`, or the few nanoseconds later at which the robot reaches its zone if it is
/// within a micrometre of it (or leaves its own corner).
pub(super) fn take_over(
    model: &RobotModel,
    tool: &Iso,
    (time, stop_end, plain): (i64, i64, bool),
    (f, next, next_zone): (&Fading, &Trajectory, Option<f64>),
    memo: &mut CornerMemo,
) -> Option<(i64, Taken)> {
    let first = &f.motion.traj;
    let Trajectory::Cartesian {
        path: p1,
        from: from1,
        to: to1,
        profile: prof1,
        ramps: None,
        timed: false,
        corner: corner1,
        path_limits: [vs1, as1, ws1],
        ..
    } = first
    else {
        return None;
    };
    let Trajectory::Cartesian {
        path: p2,
        from: from2,
        to: to2,
        profile: prof2,
        ramps: None,
        timed: false,
        corner: None,
        end_joints,
        branch,
        path_limits: [vs2, as2, ws2],
        ..
    } = next
    else {
        return None;
    };
    let (l1, l2) = (p1.length(), p2.length());
    if l1 <= 1e-7 || l2 <= 1e-7 {
        return None;
    }
    // An arm with jerk limits (its profiles ramp): the curve's curvature continuous, the
    // timing within every axis's jerk from the robot's acceleration too.
    let smooth = prof1.t_jerk > 0.0 || prof2.t_jerk > 0.0;
    let zone = f.motion.zone.min(0.5 * l2);
    // Within a micrometre before its zone (a look-ahead point is a knot, which may fall
    // just before it): from where the robot has reached it, the nanoseconds later that
    // takes. A shorter piece before the curve would be all rounding, and a robot moved on
    // by a micrometre in no time would jump.
    let before =
        |at: i64| (1.0 - first.own_fraction_at((at - f.motion.start) as f64 / NS)) * l1 - zone;
    let mut start = time;
    let gap = before(start);
    if gap > 0.0 && gap < 1e-6 {
        let speed = l1 * first.own_speed_at((start - f.motion.start) as f64 / NS);
        if speed <= 0.0 || gap / speed > 1e-3 {
            return None;
        }
        // The first nanosecond there, by bisection within its motion (the robot only
        // moves on along its path).
        start = first_ns((start, f.end()), |at| before(at) <= 0.0);
    }
    // Its motion_end is where its own corner ends, or later — but rounded down to the
    // nanosecond, a few nanometres before it: from the first nanosecond past it, where the
    // robot is on its own path again (within a microsecond; else it is in its corner).
    if let Some(c) = corner1 {
        let past = |at: i64| first.fraction_at((at - f.motion.start) as f64 / NS) >= c.end();
        if !past(start) {
            let left = first.time_at_fraction(c.end()) - (start - f.motion.start) as f64 / NS;
            if left > 1e-6 {
                return None;
            }
            let hi = start + (left.max(0.0) * NS).ceil() as i64 + 2;
            if !past(hi) {
                return None;
            }
            start = first_ns((start, hi), past);
        }
    }
    let dt = (start - f.motion.start) as f64 / NS;
    let s_now = first.fraction_at(dt);
    if corner1.as_ref().is_some_and(|c| s_now < c.end()) {
        return None;
    }
    let f_now = first.own_fraction_at(dt);
    // Already past where the zone begins (short moves whose corners meet: the last one
    // ended there): the corner from where the robot is, as far on.
    let r = zone.min((1.0 - f_now) * l1);
    if r <= 1e-6 {
        return None;
    }
    let (f_in, f_out) = (1.0 - r / l1, r / l2);
    // (From where the robot is, `f_in` is `f_now` but for rounding: no piece before the
    // curve, rather than one of 1e-16 with two steps of its own.)
    let f_now = if (f_in - f_now).abs() * l1 < 1e-12 {
        f_in
    } else {
        f_now
    };
    // Shares of s: the derivative by s continuous at both joins.
    let (rho1, c1, c2, rho2) = (f_in - f_now, 2.0 * (1.0 - f_in), 2.0 * f_out, 1.0 - f_out);
    let sigma = 1.0 / (1.0 + rho1 / c1 + rho2 / c2);
    let s_in = sigma * rho1 / c1;
    let mut corner = TimedCorner {
        first: p1.clone(),
        first_from: *from1,
        first_to: *to1,
        f_now,
        f_in,
        f_out,
        s_in,
        s_out: s_in + sigma,
        turn: None,
        smooth,
    };
    // The orientation zone: the TCP covers 2r/σ of either path per unit of s on the
    // straight pieces, so a turn of radius ρ is ρσ/r wide in s, centred on the curve,
    // and its progressions meet the straight pieces' with the same rates.
    // (Only a turn wider than the curve by more than TURN_WIDER: a sliver of a turn on
    // either side would get steps of its own, its differences rounding noise.)
    let rho = turn_radius(f, next, f_now).filter(|rho| *rho > r * (1.0 + TURN_WIDER));
    if rho.is_none() && !plain {
        return None;
    }
    if let Some(rho) = rho {
        let (mid, half) = (s_in + 0.5 * sigma, 0.5 * rho * sigma / r);
        // (Within a nanometre of where the robot is or of the path's end, there: a piece
        // of rounding would get steps of its own, and its differences would be noise.)
        let nm = 1e-9 * sigma / (2.0 * r);
        let w_in = if mid - half < nm { 0.0 } else { mid - half };
        let w_out = if mid + half > 1.0 - nm {
            1.0
        } else {
            mid + half
        };
        corner.turn = Some(Turn {
            s_in: w_in,
            s_out: w_out,
            f_in: corner.progress(w_in).f1,
            f_out: corner.progress(w_out).f2,
        });
    }
    let q_now = first.joints_at(model, dt)?;
    let own_speed = first.own_speed_at(dt);
    let own_accel = if smooth { first.own_accel_at(dt) } else { 0.0 };
    // The same corner from the same state (a program repeating its moves) is timed once.
    let mut key = [0u64; CORNER_KEY];
    let mid1 = p1.at(0.5);
    let mid2 = p2.at(0.5);
    let zone_key = next_zone.unwrap_or(f64::NAN);
    for (k, x) in q_now
        .iter()
        .chain(end_joints)
        .chain([&f_now, &own_speed, &r, &zone_key, vs1, as1, vs2, as2])
        .chain([&rho.unwrap_or(f64::NAN), ws1, ws2])
        .chain(from1.r.iter().flatten().chain(&from1.t))
        .chain(to1.r.iter().flatten().chain(&to1.t))
        .chain(from2.r.iter().flatten().chain(&from2.t))
        .chain(to2.r.iter().flatten().chain(&to2.t))
        .chain(tool.r.iter().flatten().chain(&tool.t))
        .chain(mid1.iter().chain(&mid2))
        .chain([
            &prof2.dist,
            &prof2.v,
            &prof2.a,
            &prof2.j,
            &prof2.t_jerk,
            &prof2.t_acc,
            &prof2.t_total,
            &own_accel,
        ])
        .enumerate()
    {
        key[k] = x.to_bits();
    }
    key[CORNER_KEY - 1] = branch.map_or(u64::MAX, u64::from);
    let mut time = |corner: TimedCorner, key| {
        let timed = memo.get_or_try(key, || {
            Ok::<_, Infallible>(time_corner(
                model,
                tool,
                (corner, r, [*vs1, *as1, *ws1]),
                (q_now, own_speed, own_accel),
                (next, next_zone),
            ))
        });
        // (Never slower than stopping at the point and starting again, at `stop_end`: two
        // timings on their own steps may differ by a little the other way — 117 ns found
        // on a 1 mm zone; then as if it did not apply.)
        timed
            .ok()
            .flatten()
            .filter(|t| start + t.point_ns <= stop_end)
    };
    // A turn over the orientation zone that no timing keeps from the robot's speed (or
    // slower than stopping): the tool turns within the curve, as without one (never a
    // corner lost to it).
    let plain_corner = rho.is_some().then(|| TimedCorner {
        turn: None,
        ..corner.clone()
    });
    if let Some(taken) = time(corner, key) {
        return Some((start, taken));
    }
    let plain = plain_corner.filter(|_| plain)?;
    // (Keyed as a corner without an orientation zone.)
    key[2 * MAX_AXES + 8] = f64::NAN.to_bits();
    time(plain, key).map(|taken| (start, taken))
}

/// The first nanosecond in `(lo, hi]` at which `reached` holds, by bisection: it holds at
/// `hi` and, once it does, ever after (the robot only moves on along its path).
fn first_ns((mut lo, mut hi): (i64, i64), reached: impl Fn(i64) -> bool) -> i64 {
    while hi - lo > 1 {
        let mid = lo + (hi - lo) / 2;
        if reached(mid) {
            hi = mid;
        } else {
            lo = mid;
        }
    }
    hi
}

/// Corners timed already ([`Memo`]), by the bits of what they depend on: the robot's
/// joints and place and speed on the first path, both paths (ends, midpoints), their
/// limits, the zones, the next motion's profile, the tool and the IK branch ([`CORNER_KEY`];
/// `None`: no timed corner there). It grows as corners are timed (10 KB each: a robot
/// without corners keeps none).
pub(super) type CornerMemo = Memo<CORNER_KEY, Option<Taken>>;

/// Corners a VM remembers.
pub(super) const CORNER_MEMO: usize = 16;
/// A corner's key: joints now and at the end, 11 numbers, 5 poses, 2 midpoints, the next
/// motion's profile, the robot's acceleration on its own path, the branch.
pub(super) const CORNER_KEY: usize = 2 * MAX_AXES + 11 + 5 * 12 + 6 + 7 + 1 + 1;

/// The corner `corner` from the robot's joints and own-path speed and acceleration `now`
/// on the first path into `next`, timed (`take_over`'s work once the corner is known):
/// within every axis's jerk too for an arm with jerk limits (a smooth corner).
fn time_corner(
    model: &RobotModel,
    tool: &Iso,
    (corner, r, [vs1, as1, ws1]): (TimedCorner, f64, [f64; 3]),
    (q_now, own_speed, own_accel): ([f64; MAX_AXES], f64, f64),
    (next, next_zone): (&Trajectory, Option<f64>),
) -> Option<Taken> {
    let Trajectory::Cartesian {
        path: p2,
        from: from2,
        to: to2,
        branch,
        path_limits: [vs2, as2, ws2],
        ..
    } = next
    else {
        return None;
    };
    let p1 = &corner.first;
    let (l1, l2) = (p1.length(), p2.length());
    let n = model.dof();
    let pose = |s: f64| corner.pose(p2, from2, to2, s);
    let joints_at = knot_joints(model, tool, *branch, &pose);
    // Knots on both joins, each piece in equal steps by its share of s (at least two).
    let (w_in, w_out) = corner
        .turn
        .map_or((corner.s_in, corner.s_out), |w| (w.s_in, w.s_out));
    let (knots, breaks) = piece_knots([w_in, corner.s_in, corner.s_out, w_out]);
    let mut joints = JointPath::new(n);
    sample_knots(&mut joints, &q_now, Some(&knots), &joints_at).ok()?;
    // (A smooth corner's curvature is continuous at its joins: its third derivative,
    // which its jerk depends on, jumps there, and one-sided second differences there
    // would lose it over the step after; central ones keep it.)
    joints.set_breaks(if corner.smooth { [0; 4] } else { breaks });
    let mut derivatives = knot_derivatives(&joints);
    let mut inner = Inner::new();
    let limits = axis_limits(model);
    // How far each motion turns the tool (rad).
    let (turn1, turn2) = (
        turn_angle(&corner.first_from, &corner.first_to),
        turn_angle(from2, to2),
    );
    // The TCP's speed and acceleration along each motion (m/s, m/s²) and each motion's
    // own fraction speed (which holds its orientation speed too).
    let (v1, v2) = (vs1 * l1, vs2 * l2);
    let (a1, a2) = (as1 * l1, as2 * l2);
    let along = |knots: &[f64; KNOTS]| {
        let mut out = KnotLimits::none();
        for (k, s) in knots.iter().enumerate() {
            // (At a join, the curve's side: the stricter, its curvature begins there.)
            let p = corner.progress_on(*s, true);
            let (t1, c1) = p1.derivatives(p.f1);
            let (t2, c2) = p2.derivatives(p.f2);
            let d = add(t1.map(|x| x * p.d1), t2.map(|x| x * p.d2));
            let dd = add(
                axpy(p.dd1, t1, c1.map(|x| x * p.d1 * p.d1)),
                axpy(p.dd2, t2, c2.map(|x| x * p.d2 * p.d2)),
            );
            let (v, a) = if *s < corner.s_in {
                (v1, a1)
            } else if *s > corner.s_out {
                (v2, a2)
            } else {
                let u = ((*s - corner.s_in) / (corner.s_out - corner.s_in)).clamp(0.0, 1.0);
                ((1.0 - u) * v1 + u * v2, a1.min(a2))
            };
            let mut x_max = f64::INFINITY;
            // (In the turn the orientation follows progressions of its own: each within
            // its motion's orientation speed, not its TCP's.)
            let [_, od1, _, od2] = corner.turning(*s).unwrap_or([0.0, p.d1, 0.0, p.d2]);
            for (rate, vs) in [(p.d1, vs1), (p.d2, *vs2), (od1, ws1), (od2, *ws2)] {
                if rate > 0.0 {
                    x_max = x_max.min((vs / rate).powi(2));
                }
            }
            // Where both motions turn the tool, their rotations compose: the orientation's
            // speed is at most the sum of their rates, held within the faster of the two
            // motions' orientation speeds (each its `orient`).
            let turning = turn1 * od1 + turn2 * od2;
            if turn1 > 0.0 && turn2 > 0.0 && turning > 0.0 {
                x_max = x_max.min(((turn1 * ws1).max(turn2 * *ws2) / turning).powi(2));
            }
            let len = norm(d);
            if len > 1e-12 {
                x_max = x_max.min((v / len).powi(2));
                let along_t = dot(dd, d) / (len * len);
                let across: V3 = axpy(-along_t, d, dd);
                out.tangent[k] = along_t;
                out.normal[k] = norm(across) / len;
                out.whole[k] = a / len;
            }
            out.x_max[k] = x_max;
        }
        out
    };
    let path_limits = PathLimits {
        speed: f64::INFINITY,
        accel: f64::INFINITY,
        normal: 0.0,
        whole: f64::INFINITY,
        along: Some(&along),
    };
    // The robot's speed now, in this path's fraction.
    let rate_now = corner.progress(0.0).d1;
    let x0 = if rate_now > 0.0 {
        (own_speed / rate_now).powi(2)
    } else {
        0.0
    };
    let stop_at = next_zone
        .filter(|z| *z > 0.0)
        .map(|z| corner.s_of_own(1.0 - z.min(0.5 * l2) / l2));
    // With jerk limits: from the robot's speed and acceleration (in this path's fraction:
    // the first path's is linear in it where the robot is), no faster start.
    if corner.smooth {
        let start = if x0 > 0.0 {
            (x0, own_accel / rate_now)
        } else {
            (0.0, 0.0)
        };
        let jerk = axis_jerks(model);
        let (timed, timing) = time_smooth(
            joints,
            (&limits.0, &limits.1, &jerk),
            &path_limits,
            &joints_at,
            start,
        )?;
        let look_ahead = stop_at.and_then(|s| smooth_look_ahead(&timing, s));
        return taken((next, tool), &corner, (&timed, timing, look_ahead), r);
    }
    let mut time = |x0: f64| {
        super::path::time_path(
            &mut joints,
            &mut derivatives,
            &mut inner,
            (&limits.0, &limits.1),
            &path_limits,
            (x0, stop_at),
            &joints_at,
        )
    };
    let (timing, look_ahead) = match time(x0) {
        Ok(found) => found,
        // The same state on other knots: its finite differences may put the fastest start
        // a little below the robot's speed. Within the timing's margin below the limits,
        // the corner starts at that speed (a jump of at most 2e-4 of it); else it is not
        // taken.
        Err(Untimed::TooFast { largest }) if x0 <= largest * (1.0 + START_TOLERANCE) => {
            time(largest).ok()?
        }
        Err(_) => return None,
    };
    taken((next, tool), &corner, (&joints, timing, look_ahead), r)
}

/// The corner `corner` into `next` (with `tool`) as taken: the path `joints` and its
/// `timing`, its own look-ahead point (never before its curve and its turn have ended:
/// its own motion_end, and so the next corner, comes after them).
fn taken(
    (next, tool): (&Trajectory, &Iso),
    corner: &TimedCorner,
    (joints, timing, look_ahead): (&JointPath, Timing, Option<f64>),
    r: f64,
) -> Option<Taken> {
    let Trajectory::Cartesian {
        path: p2,
        from: from2,
        to: to2,
        profile: prof2,
        end_joints,
        branch,
        path_limits: [vs2, as2, ws2],
        ..
    } = next
    else {
        return None;
    };
    let look_ahead = look_ahead.map(|t| t.max(timing.time_at(corner.end())));
    let rates = timed_rates(joints, &timing);
    let point_ns = to_ns(timing.duration());
    Some(Taken {
        traj: Trajectory::Cartesian {
            path: p2.clone(),
            from: *from2,
            to: *to2,
            profile: *prof2,
            timing: Some(timing),
            ramps: None,
            timed: false,
            end_joints: *end_joints,
            branch: *branch,
            rates,
            cruise_rates: rates,
            seeds: seeds_of(joints),
            tool: *tool,
            corner: Some(corner.clone()),
            path_limits: [*vs2, *as2, *ws2],
        },
        point_ns,
        look_ahead,
        radius: r,
    })
}

/// The radius (m, a TCP distance from the point) over which the tool turns from the rest
/// of `f` into `next` (two Cartesian motions) with the robot at fraction `f_now` of the
/// first path: `f`'s orientation zone, at most half of either path and where the robot
/// is, and no wider than turns either motion's tool by its angle (`zone_ori`); `None`
/// where neither motion turns the tool or there is no orientation zone.
pub(super) fn turn_radius(f: &Fading, next: &Trajectory, f_now: f64) -> Option<f64> {
    let (rho, alpha) = f.motion.ori_zone?;
    let (
        Trajectory::Cartesian {
            path: p1,
            from: from1,
            to: to1,
            ..
        },
        Trajectory::Cartesian {
            path: p2,
            from: from2,
            to: to2,
            ..
        },
    ) = (&f.motion.traj, next)
    else {
        return None;
    };
    let (l1, l2) = (p1.length(), p2.length());
    let (a1, a2) = (turn_angle(from1, to1), turn_angle(from2, to2));
    if (a1 <= 1e-9 && a2 <= 1e-9) || l1 <= 1e-7 || l2 <= 1e-7 {
        return None;
    }
    let mut radius = rho.min(0.5 * l1).min(0.5 * l2).min((1.0 - f_now) * l1);
    for (len, angle) in [(l1, a1), (l2, a2)] {
        if angle > 1e-9 {
            radius = radius.min(alpha * len / angle);
        }
    }
    Some(radius)
}

#[cfg(test)]
mod tests {
    use super::{CURVE_STEPS, piece_knots};
    use vworks_model::timing::SEGMENTS;

    /// Every piece of some length keeps at least its least steps (the curve
    /// [`CURVE_STEPS`], the others two) and the steps sum to the path's: a long turn on a
    /// short path, whose curve is a sliver, once left its last piece no step at all (its
    /// first knot off the robot).
    #[test]
    fn every_piece_keeps_its_least_steps() {
        for joins in [
            [0.252, 0.499, 0.501, 0.748],
            [0.0, 0.4999, 0.5001, 1.0],
            [0.01, 0.02, 0.03, 0.99],
            [0.3, 0.3, 0.6, 0.6],
            [0.45, 0.499, 0.501, 0.999],
        ] {
            let (knots, breaks) = piece_knots(joins);
            let ends = [0.0, joins[0], joins[1], joins[2], joins[3], 1.0];
            let mut at = 0;
            for (j, b) in breaks.iter().chain([&SEGMENTS]).enumerate() {
                let steps = b - at;
                if ends[j + 1] > ends[j] {
                    let least = if j == 2 { CURVE_STEPS } else { 2 };
                    assert!(steps >= least, "{joins:?}: piece {j} has {steps} steps");
                    assert_eq!(knots[at], ends[j], "{joins:?}: piece {j}");
                } else {
                    assert_eq!(steps, 0, "{joins:?}: piece {j}");
                }
                at = *b;
            }
            assert_eq!(knots[SEGMENTS], 1.0);
        }
    }
}
