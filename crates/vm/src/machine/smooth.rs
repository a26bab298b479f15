//! A Cartesian path timed within its axes' jerk limits ([`smooth_timing`]): the path
//! sampled again on knots finer towards its ends (where its jerk ramps from and to rest
//! lie), its jerk-limited timing (`vworks_model::timing::Timing::jerk_limited`), and that
//! timing checked between the knots: every axis's speed and acceleration at the steps'
//! quarter points (`quarters::Inner`), its jerk there with `q‴` from the steps' third
//! differences. Where a speed or an acceleration is over (by the path's curvature within a
//! step) those steps get less room and the path is timed again, once; what is still over
//! makes the whole timing run slower by just enough. A corner's path, timed from the
//! robot's state as it takes over ([`time_smooth`] from a start), cannot be slower as a
//! whole: its steps get less room a few times, else it has no timing.

use vworks_model::timing::{JerkStart, JointPath, KNOTS, SEGMENTS, Timing};

use super::path::{PathLimits, TIMING_MARGIN, check_turns, knot_derivatives};
use super::plan::PlanError;
use super::quarters::{Inner, Kink, worse};
use crate::MAX_AXES;
use crate::motion::Profile;

/// How much finer the steps are at the path's ends than at its middle: knots at
/// `g − E·sin(2πg)/2π` of the equal ones `g`, `E` this (steps `1 − E` of the mean at the ends).
const END_GRADING: f64 = 0.5;

/// How far over a speed or an acceleration between the knots must be for its steps to
/// be given less room and the path timed again (below, the whole timing slows by as
/// much, at most 0.1 %).
const RETIME_FROM: f64 = 1.001;

/// Every axis's speed, acceleration and jerk limits.
pub(super) type AxisLimits<'a> = (
    &'a [f64; MAX_AXES],
    &'a [f64; MAX_AXES],
    &'a [f64; MAX_AXES],
);

/// The path `joints` (sampled on equal knots by `joints_at`) timed within every axis's
/// speed, acceleration and jerk (`limits`: per axis) and its own speed and acceleration
/// (`path`): the path as sampled for it and the timing, or `None` where no jerk-limited
/// timing is found (the caller keeps its S-curve): also where a knot or quarter point of
/// its own fails (the path was checked on its equal knots; a point between them that is
/// out of reach is not this timing's to report).
pub(super) fn smooth_timing(
    joints: &JointPath,
    limits: AxisLimits<'_>,
    path: &PathLimits<'_>,
    joints_at: &impl Fn(f64, &[f64; MAX_AXES]) -> Result<[f64; MAX_AXES], PlanError>,
) -> Option<(JointPath, Timing)> {
    let mut timed = joints.clone();
    // Graded near a singularity (`JointPath::grade`), else finer towards the ends.
    let knots = joints.grade().unwrap_or_else(|| {
        let mut s = [0.0; KNOTS];
        let tau = 2.0 * std::f64::consts::PI;
        for (k, v) in s.iter_mut().enumerate() {
            let g = k as f64 / SEGMENTS as f64;
            *v = g - END_GRADING * (tau * g).sin() / tau;
        }
        s[SEGMENTS] = 1.0;
        s
    });
    timed.set_knots(&knots);
    for (k, s) in knots.iter().enumerate().skip(1) {
        let prev = timed.q[k - 1];
        timed.q[k] = joints_at(*s, &prev).ok()?;
    }
    check_turns(&timed).ok()?;
    time_smooth(timed, limits, path, joints_at, (0.0, 0.0))
}

/// Rounds of less room for a timing that starts moving (it cannot be slower as a whole).
const ROOM_ROUNDS_MOVING: usize = 3;

/// The share of every axis's jerk a timing that starts moving is timed within at first.
const MOVING_JERK_SHARE: f64 = 0.99;

/// The path `timed` (sampled on its knots) timed within every axis's speed, acceleration
/// and jerk and its own limits (`path`, also those along it) from `start` (`ṡ²`, `s̈`;
/// `(0, 0)`: rest) to rest, checked between its knots ([`smooth_timing`]); `None` where
/// none is found.
pub(super) fn time_smooth(
    mut timed: JointPath,
    (speed, accel, jerk): AxisLimits<'_>,
    path: &PathLimits<'_>,
    joints_at: &impl Fn(f64, &[f64; MAX_AXES]) -> Result<[f64; MAX_AXES], PlanError>,
    start: (f64, f64),
) -> Option<(JointPath, Timing)> {
    let n = timed.axes;
    let moving = start.0 > 0.0;
    let derivatives = knot_derivatives(&timed);
    let margin = 1.0 - TIMING_MARGIN;
    // (From a robot moving the jerks are timed a little lower still: the checks between
    // the knots find a corner's jerks up to 0.7 % over its programs' rows, and a timing
    // that starts moving can only be made again.)
    let jerk_share = if moving {
        margin * MOVING_JERK_SHARE
    } else {
        margin
    };
    let (speed_timed, accel_timed, mut jerk_timed) = (
        speed.map(|v| v * margin),
        accel.map(|a| a * margin),
        jerk.map(|j| j * jerk_share),
    );
    let along = path.along.map(|f| f(timed.knots()));
    // Between the knots: the quarter points of every step.
    let mut inner = Inner::new();
    inner.fill(&timed, &[true; SEGMENTS], joints_at).ok()?;
    // Each step's q‴ from its quarter points, for the programs' jerk rows as for the
    // checks (knots' differences would smear a jump in it: where a corner's curve begins).
    let mut thirds = vec![[(0.0, 0.0); MAX_AXES]; SEGMENTS];
    for (k, d3) in thirds.iter_mut().enumerate() {
        for (i, d) in d3.iter_mut().enumerate().take(n) {
            let (t0, t1) = step_thirds(&timed, &derivatives, &inner, k, i);
            *d = (t0 - 1.5 * (t1 - t0), t0 + 2.5 * (t1 - t0));
        }
    }
    let mut ratios = [0.0f64; SEGMENTS];
    // Where an axis's speed or acceleration goes over between the knots, its steps get
    // less room and the path is timed again (once); what is still over, the jerk's too,
    // slows the whole timing.
    let rounds = if moving { ROOM_ROUNDS_MOVING } else { 2 };
    let mut previous: Option<[f64; KNOTS]> = None;
    for round in 0..rounds {
        let limits = path.with_axes(&speed_timed[..n], &accel_timed[..n], along.as_ref());
        let from = JerkStart {
            state: start,
            third: Some(&thirds),
            guess: previous.as_ref(),
        };
        let timing = Timing::jerk_limited_from(&timed, &limits, &jerk_timed[..n], &from).ok()?;
        // (The next round, if any, starts its tangents at this timing: it is close.)
        previous = Some(timing_knots(&timing));
        let state = |_: usize, s: f64| {
            let (x, u, _) = timing.state_at_place(s);
            (x, u)
        };
        let (rv, ra) = inner.ratios(
            &timed,
            (&speed[..n], &accel[..n]),
            state,
            &[Kink::None; SEGMENTS],
            &mut ratios,
        );
        let rj = jerk_ratio(&timed, &derivatives, &inner, &timing, &jerk[..n]);
        let over = rv.max(ra.sqrt()).max(rj.cbrt());
        // (A ratio that is not a number counts as infinitely over: no timing.)
        if !over.is_finite() {
            return None;
        }
        if over <= 1.0 {
            return Some((timed, timing));
        }
        // (From a robot moving: less room for the steps over, and the jerks timed lower by
        // as much as the checks find them over, a few times; else none. Over by less
        // than RETIME_FROM: not worth the programs again.)
        if moving {
            if round + 1 == rounds {
                return None;
            }
            if rj > 1.0 {
                for j in &mut jerk_timed {
                    *j *= margin / rj;
                }
            }
        } else if round == 1 || rv.max(ra) <= RETIME_FROM {
            return Some((timed, timing.slower(over)));
        }
        // (From a robot moving, the first step keeps its room: less would leave no start
        // at the robot's speed.)
        for (room, r) in timed.room.iter_mut().zip(&ratios).skip(usize::from(moving)) {
            if *r > margin {
                *room *= margin / r;
            }
        }
    }
    None
}

/// A smooth timing's look-ahead point for a zone beginning at `stop_at` (`s`): when (s
/// from its start) the next motion may take the robot over, early enough for it to stop
/// before the zone as the timing itself stops at its end. The timing's last braking
/// begins at the last knot where `s̈ ≥ 0`; moved back by the zone's length, a robot
/// cruising there has as long to brake before the zone as the timing had to its end.
/// Where the robot there is still accelerating (a motion too short to cruise: it would
/// have to ease its acceleration first, and often could not turn into the curve in time)
/// or that place is before the first knot, its start: the next motion takes it over from
/// rest, the two timed as one path.
pub(super) fn smooth_look_ahead(timing: &Timing, stop_at: f64) -> Option<f64> {
    // (s̈ at knot k: the step after it starts there.)
    let accel = |k: usize| timing.state_at_place(timing.knot(k)).1;
    let braking = (1..SEGMENTS).rev().find(|&k| accel(k) >= 0.0)?;
    let place = timing.knot(braking) - (1.0 - stop_at);
    let top_accel = (0..SEGMENTS).map(|k| accel(k).abs()).fold(0.0f64, f64::max);
    let cruising = |k: usize| accel(k) <= CRUISING * top_accel;
    match (1..=braking).rev().find(|&k| timing.knot(k) <= place) {
        Some(k) if cruising(k) => Some(timing.time_at_knot(k)),
        _ => Some(0.0),
    }
}

/// The share of its largest `s̈` below which a timing counts as cruising, not accelerating
/// ([`smooth_look_ahead`]).
const CRUISING: f64 = 0.01;

/// An S-curve's look-ahead point for a zone of `zone` (a share of its distance), as
/// [`smooth_look_ahead`]'s: its braking begins `t_acc` before its end; moved back by the
/// zone, the first time it is there, if it cruises there; else its start. `None`
/// for a trapezoid: an arm without jerk limits flies by with corner ramps.
pub(super) fn profile_look_ahead(profile: &Profile, zone: f64) -> Option<f64> {
    if profile.t_jerk <= 0.0 || profile.dist.is_nan() || profile.dist <= 0.0 {
        return None;
    }
    let braking = (profile.t_total - profile.t_acc).max(0.0);
    let place = profile.at(braking) - zone * profile.dist;
    if place <= profile.at(profile.t_acc) {
        return Some(0.0);
    }
    Some(profile.time_at(place))
}

/// Axis `i`'s third differences in step `k` at its 1.5 and 2.5 quarters (from its knots
/// and quarter points; without them, the knots' `q″` difference, both the same).
fn step_thirds(
    joints: &JointPath,
    derivatives: &super::path::KnotDerivatives,
    inner: &Inner,
    k: usize,
    i: usize,
) -> (f64, f64) {
    let h = 0.25 * joints.step(k);
    let Some(points) = inner.points(joints, k) else {
        let d3 = (derivatives[k + 1][i].1 - derivatives[k][i].1) / joints.step(k);
        return (d3, d3);
    };
    let q = points.map(|p| p[i]);
    let third = |a: usize| (q[a + 3] - 3.0 * q[a + 2] + 3.0 * q[a + 1] - q[a]) / (h * h * h);
    (third(0), third(1))
}

/// The largest ratio of an axis's jerk to its limit at the knots and quarter points of
/// every step under `timing`: `q′·s⃛ + 3q″·ṡ·s̈ + q‴·ṡ³` there, slopes and curvatures by
/// differences over the quarter grid (at a knot, the knot's own), `q‴` from the step's two
/// third differences (at 1.5 and 2.5 quarters: linear between and beyond them) and half
/// their difference added as `|·|·ṡ³` (how much `q‴` may change across the step beyond
/// that line).
fn jerk_ratio(
    joints: &JointPath,
    derivatives: &super::path::KnotDerivatives,
    inner: &Inner,
    timing: &Timing,
    jerk: &[f64],
) -> f64 {
    let mut worst = 0.0f64;
    for k in 0..SEGMENTS {
        let h = 0.25 * joints.step(k);
        let Some(points) = inner.points(joints, k) else {
            continue;
        };
        for (i, j) in jerk.iter().enumerate() {
            if !j.is_finite() {
                continue;
            }
            let q = points.map(|p| p[i]);
            let (t0, t1) = step_thirds(joints, derivatives, inner, k, i);
            for p in 0..=4 {
                let s = joints.knot(k) + p as f64 * h;
                // (Just inside the step at its knots: the step's own jerk.)
                let at = match p {
                    0 => s + 1e-9 * h,
                    4 => joints.knot(k + 1) - 1e-9 * h,
                    _ => s,
                };
                let (x, u, sddd) = timing.state_at_place(at);
                let (d1, d2) = match p {
                    0 => derivatives[k][i],
                    4 => derivatives[k + 1][i],
                    _ => (
                        (q[p + 1] - q[p - 1]) / (2.0 * h),
                        (q[p + 1] - 2.0 * q[p] + q[p - 1]) / (h * h),
                    ),
                };
                let d3 = t0 + (t1 - t0) * (p as f64 - 1.5);
                let sd = x.max(0.0).sqrt();
                let cube = sd * sd * sd;
                let load = (d1 * sddd + 3.0 * d2 * sd * u + d3 * cube).abs()
                    + 0.5 * (t1 - t0).abs() * cube;
                worst = worse(worst, load / j);
            }
        }
    }
    worst
}

/// `ṡ²` at every knot of `timing`.
fn timing_knots(timing: &Timing) -> [f64; KNOTS] {
    std::array::from_fn(|k| timing.state_at_knot(k))
}
