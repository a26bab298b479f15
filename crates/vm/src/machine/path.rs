//! Sampling a Cartesian path before it moves ([`sample_path`]): the joints at the
//! timing's knots by inverse kinematics on the motion's own branch, reachability, jumps
//! between configurations (a singularity on the way), every axis's speed and acceleration
//! under the planned profile, and where the profile would exceed one, the path's
//! time-optimal timing (`vworks_model::timing`); the bound on each axis's speed the
//! collider reads; and the VM's memo of sampled paths ([`PathMemo`]).

use vworks_model::RobotModel;
use vworks_model::math::Iso;
use vworks_model::timing::{JointPath, KNOTS, KnotLimits, Limits, SEGMENTS, Timing, TimingError};

use super::jerks::{KnotJerks, NEAR_JERK, axis_jerk_load, axis_jerks};
use super::plan::{JOINT_SPEED_TOLERANCE, PlanError, ik_tcp};
use super::quarters::{Inner, Kink};
use super::smooth::smooth_timing;
use crate::MAX_AXES;
use crate::motion::{Path, Profile, cartesian_at};

/// The most an axis may turn between two knots of a Cartesian path (1/256 of it) before
/// the path counts as passing a singularity (the joints jump to another configuration):
/// 45°.
pub(super) const MAX_KNOT_TURN: f64 = std::f64::consts::FRAC_PI_4;

/// How much of every axis limit a time-optimal path timing leaves unused: the timing keeps
/// the limits exactly at its knots and halfway between them, and the path's curvature
/// within one step (1/256 of the path) moves them by less than this.
pub(super) const TIMING_MARGIN: f64 = 5e-4;
/// Sampled paths a VM remembers (the oldest goes first).
pub(super) const PATH_MEMO: usize = 32;
/// A sampled path's key: the bits of the start joints, the start and goal poses (rotation,
/// translation), the via point (NaN for a line), the path's speed (minus the duration's
/// nanoseconds, with one), acceleration and jerk, the orientation speed asked (NaN: none),
/// the zone's share of the path (NaN: none), and the tool.
pub(super) const PATH_KEY: usize = MAX_AXES + 12 + 12 + 3 + 5 + 12;

/// What sampling a Cartesian path found: its time-optimal timing where the planned profile
/// would take an axis past its speed or acceleration limit (`None`: the profile keeps
/// them all), the axis whose limit binds most, each axis's largest speed, the joints at
/// the end.
#[derive(Clone, Debug)]
pub(super) struct PathSamples {
    /// The joints at every 16th knot: the seeds the executed path's IK starts from.
    pub(super) seeds: [[f64; MAX_AXES]; SEEDS],
    pub(super) timing: Option<Timing>,
    /// The profile the motion executes where it is not the programmed one: the same shape
    /// at a lower acceleration (`None` with a timing, or the programmed profile).
    pub(super) executed: Option<Profile>,
    /// Where the axes make the motion slower than its programmed speed and acceleration
    /// alone would (s): how long it would take without them; `None` if they do not.
    pub(super) unslowed: Option<f64>,
    pub(super) worst_axis: usize,
    pub(super) rates: [f64; MAX_AXES],
    /// Per axis, a bound on its speed under any profile no faster than the executed
    /// one's top speed anywhere (what a corner's ramps may do).
    pub(super) cruise_rates: [f64; MAX_AXES],
    pub(super) end: [f64; MAX_AXES],
    /// A timed path with a zone: when (s from its start) it can still stop where its zone
    /// begins, the last knot that can with a margin: its `motion_end`.
    pub(super) look_ahead: Option<f64>,
}

/// A cache of a pure function by exact keys (the bits of everything it depends on): at
/// most `capacity` results, the oldest going first, so a caller gives the same with an
/// empty memo as with a full one. Cartesian paths sampled ([`PathMemo`]) and corners timed
/// (`corner::CornerMemo`) are kept in one: a program repeating its moves plans each once.
#[derive(Debug)]
pub(super) struct Memo<const KEY: usize, V> {
    entries: Vec<([u64; KEY], V)>,
    capacity: usize,
}

impl<const KEY: usize, V: Clone> Memo<KEY, V> {
    /// An empty memo with its room reserved once (it never allocates after).
    pub(super) fn reserved(capacity: usize) -> Self {
        Memo {
            entries: Vec::with_capacity(capacity),
            capacity,
        }
    }

    /// An empty memo that grows as it is used, to `capacity` entries.
    pub(super) fn growing(capacity: usize) -> Self {
        Memo {
            entries: Vec::new(),
            capacity,
        }
    }

    /// The result under `key`, or the one `make` gives (then remembered; an error is
    /// not).
    pub(super) fn get_or_try<E>(
        &mut self,
        key: [u64; KEY],
        make: impl FnOnce() -> Result<V, E>,
    ) -> Result<V, E> {
        if let Some((_, v)) = self.entries.iter().find(|(k, _)| *k == key) {
            return Ok(v.clone());
        }
        let v = make()?;
        if self.entries.len() >= self.capacity {
            self.entries.remove(0);
        }
        self.entries.push((key, v.clone()));
        Ok(v)
    }
}

/// Cartesian paths sampled, by the bits of their joints, poses, speed and tool
/// ([`PATH_KEY`]).
pub(super) type PathMemo = Memo<PATH_KEY, PathSamples>;

/// Samples a Cartesian path at the timing's [`KNOTS`] from joints `from` (each knot's IK
/// seeded from the one before, on the analytic `branch` the motion executes on, if the arm
/// has one): every point reachable (or the error, naming where), no axis jumping to
/// another configuration between two knots. Then checks `profile` (the path fraction
/// against time; top speed `vs`, jerk ramp `ramp` s) against every axis's speed and
/// acceleration; if an axis would exceed one, the faster of the same profile at a lower
/// acceleration and the path's time-optimal timing within the axis limits and the
/// profile's own speed and acceleration. With jerk limits (`ramp` > 0) and `jerk_timed`
/// (not a motion given a `duration`, which keeps its S-curve stretched), the path's
/// jerk-limited timing where it is faster than the S-curves (`smooth`).
pub(super) fn sample_path(
    model: &RobotModel,
    tool: &Iso,
    (path, start, goal, from): (&Path, &Iso, &Iso, &[f64; MAX_AXES]),
    branch: Option<u8>,
    (profile, vs, ramp, whole): (&Profile, f64, f64, f64),
    zone: Option<f64>,
    jerk_timed: bool,
) -> Result<PathSamples, PlanError> {
    let n = model.dof();
    let pose = |s: f64| cartesian_at(path, start, goal, s);
    let joints_at = knot_joints(model, tool, branch, &pose);
    let mut joints = JointPath::new(n);
    sample_knots(&mut joints, from, None, &joints_at)?;
    let (speed, accel) = axis_limits(model);
    let jerk = axis_jerks(model);
    let end = joints.q[SEGMENTS];
    let mut derivatives = knot_derivatives(&joints);
    let mut inner = Inner::new();
    let limits_of = (&speed[..n], &accel[..n], &jerk[..n]);
    // Without an acceleration of its own (no `accel`, no TCP limit in the model) the path
    // accelerates as fast as its axes let it: never the programmed profile as it is.
    let bounded = profile.a.is_finite();
    // An arc's TCP accelerates towards its centre too (v²/R, per ṡ² its swept angle): the
    // programmed profile fits only if its peak acceleration along the path and the
    // centripetal one at its peak speed stay within the whole acceleration (never for a
    // trapezoid at the TCP's acceleration; an S-curve too short to reach it can).
    let normal = match path {
        Path::Arc { sweep, .. } if whole.is_finite() => *sweep,
        _ => 0.0,
    };
    // With jerk limits: the path timed within every axis's jerk (the fastest found),
    // unless an S-curve below is faster (a short line whose ramps the steps cannot
    // resolve).
    let path_limits = PathLimits {
        speed: vs,
        accel: profile.a,
        normal,
        whole,
        along: None,
    };
    let mut smooth = if ramp > 0.0 && jerk_timed {
        smooth_timing(&joints, (&speed, &accel, &jerk), &path_limits, &joints_at)
    } else {
        None
    };
    let smooth_lasts = smooth.as_ref().map_or(f64::INFINITY, |(_, t)| t.duration());
    let smooth_samples = |(timed, timing): (JointPath, Timing)| {
        let derivatives = knot_derivatives(&timed);
        let (worst_axis, nearest) = fastest_axis(&derivatives, &timing, &speed[..n]);
        let unslowed = (nearest >= SPEED_BINDS && timing.duration() > profile.t_total)
            .then_some(profile.t_total)
            .filter(|t| t.is_finite());
        let end = timed.q[SEGMENTS];
        timed_samples(&timed, timing, (unslowed, worst_axis), end, None)
    };
    // (No S-curve, the programmed one nor slower ones, can beat a jerk-limited timing
    // faster than the programmed one: the checks and searches below are for none.)
    if let Some(found) = smooth.take_if(|_| smooth_lasts < profile.t_total) {
        return Ok(smooth_samples(found));
    }
    if bounded && within_whole(profile, normal, whole) {
        let check = check_profile(
            &joints,
            &derivatives,
            profile,
            limits_of,
            &mut inner,
            &joints_at,
        )?;
        if check.fits {
            return Ok(profile_samples(&joints, profile, &check, None, end));
        }
    }
    // The same trapezoid (S-curve) at the highest lower acceleration that keeps every
    // axis within its limits: where an axis binds only in the ramps (a short ramp at a
    // high acceleration), as fast as a timing can be — the time-optimal timing below
    // changes speed only at its knots, and loses up to a step's time at each end when the
    // whole ramp lies within one step. The faster of the two is the motion's.
    let mut lower = lower_profile(
        &joints,
        &derivatives,
        profile,
        (vs, ramp, normal, whole),
        limits_of,
        &mut inner,
        &joints_at,
    )?;
    // With jerk limits the motion keeps an S-curve: the faster of the programmed speed at
    // the highest acceleration that fits (above) and a lower speed at the highest
    // acceleration that fits there. Where an axis's speed binds, a lower acceleration
    // keeps the axis within it only by never reaching the speed (a slow triangle); a
    // lower speed reaches its cruise sooner. The best speed by golden-section search
    // between 1/64 of the programmed one and all of it; a slower speed than programmed
    // is a `slowdown` (against the programmed profile).
    if ramp > 0.0 {
        if let Some(found) = smooth
            && smooth_lasts < lower.as_ref().map_or(f64::INFINITY, |(p, _)| p.t_total)
        {
            return Ok(smooth_samples(found));
        }
        let mut at = |f: f64| {
            lower_profile(
                &joints,
                &derivatives,
                profile,
                (f * vs, ramp, normal, whole),
                limits_of,
                &mut inner,
                &joints_at,
            )
        };
        let lasts = |found: &Option<(Profile, ProfileCheck)>| {
            found.as_ref().map_or(f64::INFINITY, |(p, _)| p.t_total)
        };
        // (Taken: with none found here, there was none at the programmed speed either.)
        let mut best = (lasts(&lower), 1.0, lower.take());
        let ratio = 0.5 * (5f64.sqrt() - 1.0);
        let (mut lo, mut hi) = (SLOWEST_S_CURVE, 1.0);
        let (mut x1, mut x2) = (hi - ratio * (hi - lo), lo + ratio * (hi - lo));
        let (mut f1, mut f2) = (at(x1)?, at(x2)?);
        for _ in 0..SPEED_ROUNDS {
            if lasts(&f1) <= lasts(&f2) {
                hi = x2;
                (x2, f2) = (x1, f1);
                x1 = hi - ratio * (hi - lo);
                f1 = at(x1)?;
            } else {
                lo = x1;
                (x1, f1) = (x2, f2);
                x2 = lo + ratio * (hi - lo);
                f2 = at(x2)?;
            }
        }
        for (x, found) in [(x1, f1), (x2, f2)] {
            if lasts(&found) < best.0 {
                best = (lasts(&found), x, found);
            }
        }
        if let (_, f, Some((p, check))) = best {
            let mut samples = profile_samples(&joints, &p, &check, Some(p), end);
            if f < 1.0 {
                samples.unslowed = Some(profile.t_total).filter(|t| t.is_finite());
            }
            return Ok(samples);
        }
    } else if let Some((lower, check)) = &lower {
        // No timing beats the programmed profile (nor, without an acceleration, cruising
        // at the programmed speed all the way): a trapezoid this close to it is kept
        // without the time-optimal timing.
        let bound = if bounded { profile.t_total } else { 1.0 / vs };
        if lower.t_total <= bound * (1.0 + NEAR_OPTIMAL) {
            return Ok(profile_samples(&joints, lower, check, Some(*lower), end));
        }
    }
    let (timing, look_ahead) = time_path(
        &mut joints,
        &mut derivatives,
        &mut inner,
        (&speed, &accel),
        &path_limits,
        (0.0, zone.map(|z| 1.0 - z)),
        &joints_at,
    )
    .map_err(|e| match e {
        Untimed::Plan(e) => e,
        // (From rest, a path that can move at all can start.)
        Untimed::TooFast { .. } => PlanError::Singular {
            axis: 0,
            at_percent: 0.0,
        },
    })?;
    if let Some((lower, mut check)) = lower
        && lower.t_total <= timing.duration()
    {
        // (Checked on the equal knots: its path speeds at the graded ones, where graded.)
        for (k, sd) in check.sd.iter_mut().enumerate() {
            *sd = state_at_distance(&lower, joints.knot(k) * lower.dist).0;
        }
        return Ok(profile_samples(&joints, &lower, &check, Some(lower), end));
    }
    // Slowed: where an axis's speed keeps the TCP below its programmed speed (the axes'
    // accelerations are the path's own dynamics, as on a controller), against the same
    // timing without the axis speeds.
    let (worst_axis, nearest) = fastest_axis(&derivatives, &timing, &speed[..n]);
    let unslowed = if nearest < SPEED_BINDS {
        None
    } else {
        let no_speed = [f64::INFINITY; MAX_AXES];
        let accel_timed = accel.map(|a| a * (1.0 - TIMING_MARGIN));
        let unbound = Limits {
            axis_speed: &no_speed[..n],
            axis_accel: &accel_timed[..n],
            path_speed: vs,
            path_accel: profile.a,
            path_normal: normal,
            path_whole: whole,
            along: None,
        };
        // (Without a timing to compare with, no warning.)
        Timing::optimal(&joints, &unbound)
            .ok()
            .map(|t| t.duration())
            .filter(|would| timing.duration() > would * (1.0 + 1e-9))
    };
    Ok(timed_samples(
        &joints,
        timing,
        (unslowed, worst_axis),
        end,
        look_ahead,
    ))
}

/// The samples of a path that follows `timing`.
fn timed_samples(
    joints: &JointPath,
    timing: Timing,
    (unslowed, worst_axis): (Option<f64>, usize),
    end: [f64; MAX_AXES],
    look_ahead: Option<f64>,
) -> PathSamples {
    // (A timed path never flies with corner ramps: its cruise bound is its bound.)
    let rates = timed_rates(joints, &timing);
    PathSamples {
        seeds: seeds_of(joints),
        rates,
        cruise_rates: rates,
        timing: Some(timing),
        executed: None,
        unslowed,
        worst_axis,
        end,
        look_ahead,
    }
}

/// The joints at path fraction `s` of the TCP poses `pose`, seeded from `prev`: on the
/// motion's own analytic `branch` where it is within the joint limits (the executed
/// path); else the nearest solution, which then shows as a jump.
pub(super) fn knot_joints<'a>(
    model: &'a RobotModel,
    tool: &'a Iso,
    branch: Option<u8>,
    pose: &'a dyn Fn(f64) -> Iso,
) -> impl Fn(f64, &[f64; MAX_AXES]) -> Result<[f64; MAX_AXES], PlanError> + 'a {
    let n = model.dof();
    let tool_inv = tool.inverse();
    move |s: f64, prev: &[f64; MAX_AXES]| {
        let pose = pose(s);
        let mut q = [0.0; MAX_AXES];
        let on_branch = branch.is_some_and(|b| {
            let flange = pose.mul(&tool_inv);
            model
                .ik_in_branch(&flange, &prev[..n], b, &mut q[..n])
                .is_ok()
                && model.within_limits(&q[..n])
        });
        if on_branch {
            return Ok(q);
        }
        ik_tcp(model, tool, &pose, prev).map_err(|error| PlanError::Unreachable {
            error,
            at_percent: Some(s * 100.0),
        })
    }
}

/// The joints of a path at the timing's [`KNOTS`] (equal steps, or `knots`) from joints
/// `from` (each knot's IK seeded from the one before), into `joints`: every point reachable, no axis jumping to another
/// configuration between two knots, and the steepest slopes close to each end.
pub(super) fn sample_knots(
    joints: &mut JointPath,
    from: &[f64; MAX_AXES],
    knots: Option<&[f64; KNOTS]>,
    joints_at: &impl Fn(f64, &[f64; MAX_AXES]) -> Result<[f64; MAX_AXES], PlanError>,
) -> Result<(), PlanError> {
    let n = joints.axes;
    if let Some(knots) = knots {
        joints.set_knots(knots);
    }
    joints.q[0] = *from;
    for k in 1..KNOTS {
        let prev = joints.q[k - 1];
        joints.q[k] = joints_at(joints.knot(k), &prev)?;
    }
    check_turns(joints)?;
    // Close to each end, the steepest slope of points 1/4 to 1/4096 of a step in: a
    // path that starts or ends near a singularity is steeper there than the knots show.
    for (end, (s0, sign)) in [(0.0, 1.0), (1.0, -1.0)].into_iter().enumerate() {
        let delta = joints.step(end * (SEGMENTS - 1));
        let q0 = joints.q[end * SEGMENTS];
        for frac in [
            0.25,
            0.0625,
            0.015625,
            0.00390625,
            0.0009765625,
            0.000244140625,
        ] {
            let ds = frac * delta;
            let q = joints_at(s0 + sign * ds, &q0)?;
            for i in 0..n {
                let slope = sign * (q[i] - q0[i]) / ds;
                if slope.abs() > joints.end_slopes[end][i].abs() {
                    joints.end_slopes[end][i] = slope;
                }
            }
        }
    }
    Ok(())
}

/// Every axis's speed and acceleration limits in `model`.
pub(super) fn axis_limits(model: &RobotModel) -> ([f64; MAX_AXES], [f64; MAX_AXES]) {
    let mut speed = [0.0f64; MAX_AXES];
    let mut accel = [0.0f64; MAX_AXES];
    for i in 0..model.dof() {
        let j = model.axis(i);
        speed[i] = j.max_velocity;
        accel[i] = j.max_accel;
    }
    (speed, accel)
}

/// The limits along a path made for its knots ([`KnotLimits`]).
pub(super) type AlongKnots<'a> = dyn Fn(&[f64; KNOTS]) -> KnotLimits + 'a;

/// The path's own limits for a timing: its speed and acceleration (fractions per second),
/// an arc's normal acceleration per `ṡ²` and its whole acceleration, and those that
/// change along it (a corner's, made for the knots given).
pub(super) struct PathLimits<'a> {
    pub(super) speed: f64,
    pub(super) accel: f64,
    pub(super) normal: f64,
    pub(super) whole: f64,
    pub(super) along: Option<&'a AlongKnots<'a>>,
}

impl PathLimits<'_> {
    /// The timing's limits: these and the axes' `speed` and `accel`, and the path's own
    /// limits knot by knot `along`.
    pub(super) fn with_axes<'a>(
        &self,
        speed: &'a [f64],
        accel: &'a [f64],
        along: Option<&'a KnotLimits>,
    ) -> Limits<'a> {
        Limits {
            axis_speed: speed,
            axis_accel: accel,
            path_speed: self.speed,
            path_accel: self.accel,
            path_normal: self.normal,
            path_whole: self.whole,
            along,
        }
    }
}

/// Why [`time_path`] found no timing.
#[derive(Debug)]
pub(super) enum Untimed {
    /// The path cannot be timed (a singularity, a point out of reach).
    Plan(PlanError),
    /// It cannot start as fast as asked: the fastest `ṡ²` it can start with.
    TooFast { largest: f64 },
}

impl From<PlanError> for Untimed {
    fn from(e: PlanError) -> Untimed {
        Untimed::Plan(e)
    }
}

/// The time-optimal timing of a sampled path from `ṡ² = x0` to rest within every axis's
/// `speed` and `accel` and the path's limits: sampled again at graded knots where the
/// axes' slopes change fast (near a singularity), a margin below the limits, and where
/// the quarter points between knots find an axis past a limit, less room for that step
/// (a few rounds; then the whole timing slower).
pub(super) fn time_path(
    joints: &mut JointPath,
    derivatives: &mut KnotDerivatives,
    inner: &mut Inner,
    (speed, accel): (&[f64; MAX_AXES], &[f64; MAX_AXES]),
    path: &PathLimits<'_>,
    (x0, stop_at): (f64, Option<f64>),
    joints_at: &impl Fn(f64, &[f64; MAX_AXES]) -> Result<[f64; MAX_AXES], PlanError>,
) -> Result<(Timing, Option<f64>), Untimed> {
    let n = joints.axes;
    // Where the axes' slopes change fast (near a singularity), the timing takes finer
    // steps there: the path is sampled again at graded knots (only paths that are timed:
    // a profile that fits needs no steps).
    if let Some(knots) = joints.grade() {
        joints.set_knots(&knots);
        for (k, s) in knots.iter().enumerate().skip(1) {
            let prev = joints.q[k - 1];
            joints.q[k] = joints_at(*s, &prev)?;
        }
        check_turns(joints)?;
        *derivatives = knot_derivatives(joints);
        *inner = Inner::new();
    }
    let along = path.along.map(|f| f(joints.knots()));
    // The timing keeps a margin below the limits the checks measure against.
    let speed_timed = speed.map(|v| v * (1.0 - TIMING_MARGIN));
    let accel_timed = accel.map(|a| a * (1.0 - TIMING_MARGIN));
    let limits = path.with_axes(&speed_timed[..n], &accel_timed[..n], along.as_ref());
    let optimal = |joints: &JointPath| {
        Timing::from_speed(joints, &limits, x0).map_err(|e| match e {
            TimingError::Stuck { knot, axis } | TimingError::NotFinite { knot, axis } => {
                Untimed::Plan(PlanError::Singular {
                    axis,
                    at_percent: joints.knot(knot) * 100.0,
                })
            }
            TimingError::TooFast { largest } => Untimed::TooFast { largest },
            // (The limits come from a checked model and a checked profile.)
            _ => Untimed::Plan(PlanError::Singular {
                axis: 0,
                at_percent: 0.0,
            }),
        })
    };
    // The timing keeps the limits at the knots and halfway; between them, where the
    // quarter points find an axis past a limit, that step gets less room and the timing
    // is made again (a few rounds; then, if still needed, the whole timing slower).
    let mut timing = optimal(joints)?;
    let mut ratios = [0.0f64; SEGMENTS];
    for round in 0..=ROOM_ROUNDS_AT_SPEED {
        // The steps where an axis comes near a limit at a knot under the timing.
        let mut near = [false; SEGMENTS];
        for (k, flag) in near.iter_mut().enumerate() {
            let (x, u) = timing.step_state(k);
            let x1 = x + 2.0 * u * joints.step(k);
            *flag = [(k, x), (k + 1, x1)].iter().any(|&(knot, x)| {
                (0..n).any(|i| {
                    let (d1, d2) = derivatives[knot][i];
                    let v = (d1 * x.max(0.0).sqrt()).abs() / speed[i];
                    let a = (d1 * u + d2 * x).abs() / accel[i];
                    v.max(a) > NEAR_LIMIT
                })
            });
        }
        inner
            .fill(joints, &near, joints_at)
            .map_err(Untimed::Plan)?;
        let state = |k: usize, s: f64| {
            let (x, u) = timing.step_state(k);
            (x + 2.0 * u * (s - joints.knot(k)), u)
        };
        let (rv, ra) = inner.ratios(
            joints,
            (&speed[..n], &accel[..n]),
            state,
            &[Kink::None; SEGMENTS],
            &mut ratios,
        );
        if rv.max(ra) <= 1.0 {
            break;
        }
        // A timing that starts at speed cannot be made slower as a whole: it gets more
        // rounds, else there is none.
        if x0 > 0.0 {
            if round + 1 < ROOM_ROUNDS_AT_SPEED && ratios[0] <= 1.0 {
                // (Twice the step: the rounds converge from above. The first step keeps
                // its room: less would leave no start at the robot's speed.)
                for (room, r) in joints.room.iter_mut().zip(&ratios).skip(1) {
                    if *r > 1.0 - TIMING_MARGIN {
                        *room *= ((1.0 - TIMING_MARGIN) / r).powi(2);
                    }
                }
                timing = optimal(joints)?;
                continue;
            }
            return Err(Untimed::TooFast { largest: 0.0 });
        }
        if round == ROOM_ROUNDS {
            timing = timing.slower(rv.max(ra.sqrt()).max(1.0));
            break;
        }
        for (room, r) in joints.room.iter_mut().zip(&ratios) {
            if *r > 1.0 - TIMING_MARGIN {
                *room *= (1.0 - TIMING_MARGIN) / r;
            }
        }
        timing = optimal(joints)?;
    }
    // The look-ahead point for a zone beginning at `stop_at`: the last knot before the
    // first where stopping there binds (the path could go faster if it did not have to)
    // and the timing is above a share of what it allows.
    let look_ahead = stop_at.and_then(|s_in| {
        let k_in = joints
            .knots()
            .partition_point(|s| *s <= s_in)
            .saturating_sub(1);
        if k_in == 0 {
            return None;
        }
        let stop = Timing::stopping_at(joints, &limits, k_in).ok()?;
        let full = Timing::stopping_at(joints, &limits, SEGMENTS).ok()?;
        let over = (1..=k_in).find(|&k| {
            stop[k] < full[k] * (1.0 - 1e-9) && timing.state_at_knot(k) > LOOK_AHEAD_SHARE * stop[k]
        })?;
        Some(timing.time_at_knot(over - 1))
    });
    Ok((timing, look_ahead))
}

/// The share of the speed squared from which a path could still stop where its zone
/// begins that its look-ahead point may have: a corner planned there is timed again on
/// other knots, and must find its start within its own limits.
const LOOK_AHEAD_SHARE: f64 = 0.95;

/// No axis turns more than [`MAX_KNOT_TURN`] between two knots (else the arm changes
/// configuration there).
pub(super) fn check_turns(joints: &JointPath) -> Result<(), PlanError> {
    for k in 1..KNOTS {
        for i in 0..joints.axes {
            let turn = (joints.q[k][i] - joints.q[k - 1][i]).abs();
            if turn > MAX_KNOT_TURN {
                return Err(PlanError::ConfigurationJump {
                    axis: i,
                    at_percent: joints.knot(k) * 100.0,
                    turn_deg: turn.to_degrees(),
                });
            }
        }
    }
    Ok(())
}

/// How near its speed limit (its fraction) an axis must come under a timing for the
/// timing to be compared with one without the axis speeds (a `slowdown` warning).
const SPEED_BINDS: f64 = 0.99;

/// The axis that comes nearest its speed limit at a knot under `timing`, and how near
/// (its fraction of the limit).
fn fastest_axis(derivatives: &KnotDerivatives, timing: &Timing, speed: &[f64]) -> (usize, f64) {
    let (mut best, mut axis) = (0.0f64, 0);
    for (k, row) in derivatives.iter().enumerate() {
        let sd = timing.speed_at_knot(k);
        for (i, v) in speed.iter().enumerate() {
            let r = (row[i].0 * sd).abs() / v;
            if r > best {
                (best, axis) = (r, i);
            }
        }
    }
    (axis, best)
}

/// How far over a limit an axis may be measured (relative) where it runs exactly at it:
/// the joints' finite differences from numeric IK round by about 5e-9 (a slide joint whose
/// speed is its TCP's, exactly at its limit). A profile measured further over is
/// stretched in time ([`profile_samples`]).
const MEASURED_OVER: f64 = 1e-8;

/// How far to each side of a profile's breakpoint (a share of its time) its acceleration
/// is taken on that side: a step of a trapezoid's acceleration is exactly at it.
pub(super) const PHASE_SIDE: f64 = 1e-12;

/// How much more jerk the quarter points' q‴ must show than the knots' to count.
const FINER_JERK: f64 = 1e-5;

/// How a profile keeps the axis limits along a sampled path.
#[derive(Clone)]
struct ProfileCheck {
    /// Every axis within its speed and acceleration at the knots, and between them where
    /// one comes near a limit.
    fits: bool,
    /// The axis nearest its limit (its largest fraction) at a knot or a phase's end.
    worst_axis: usize,
    /// The path speed at each knot.
    sd: [f64; KNOTS],
    /// How much slower (in time) the profile must run for every axis the check found
    /// within its tolerance over a limit to be within it: 1 if none.
    over: f64,
}

/// Checks `profile` against every axis's speed and acceleration at the knots (axis speed
/// q′(s)·ṡ, acceleration q′(s)·s̈ + q″(s)·ṡ²), at its phases' ends (below) and, where an
/// axis comes within [`NEAR_LIMIT`] of a limit there, at the quarter points of the steps
/// around and between them ([`Inner::ratios`]).
fn check_profile(
    joints: &JointPath,
    derivatives: &KnotDerivatives,
    profile: &Profile,
    (speed, accel, jerk): (&[f64], &[f64], &[f64]),
    inner: &mut Inner,
    joints_at: &impl Fn(f64, &[f64; MAX_AXES]) -> Result<[f64; MAX_AXES], PlanError>,
) -> Result<ProfileCheck, PlanError> {
    let mut worst = 1.0f64;
    let mut worst_axis = 0;
    let mut sd = [0.0f64; KNOTS];
    let mut near = [false; SEGMENTS];
    // (An S-curve on an arm with jerk limits: each axis's jerk at the knots too, as a
    // ratio whose cube root stretches the time enough: jerk goes as the time cubed.)
    let knot_jerks = KnotJerks::of(joints, profile).filter(|_| jerk.iter().any(|j| j.is_finite()));
    // (The steps where an axis's jerk comes near its limit at the knots: checked again with
    // its q‴ from the quarter points, below.)
    let mut jerk_near = [false; SEGMENTS];
    for (k, sd_k) in sd.iter_mut().enumerate() {
        let s = joints.knot(k);
        let (v_path, a_path) = knot_state(knot_jerks.as_ref(), profile, s, k);
        *sd_k = v_path;
        for i in 0..joints.axes {
            let (v, a) = axis_load(derivatives[k][i], v_path, a_path);
            let mut ratio = (speed[i] / v).min(accel[i] / a);
            if let Some(kj) = knot_jerks.as_ref().filter(|_| jerk[i].is_finite()) {
                let load = axis_jerk_load(joints, derivatives, (k, i), kj.near[k], 0.0);
                ratio = ratio.min((jerk[i] / load).cbrt());
                if load > NEAR_JERK * jerk[i] {
                    jerk_near[k.min(SEGMENTS - 1)] = true;
                    jerk_near[k.saturating_sub(1)] = true;
                }
            }
            if ratio < worst {
                worst = ratio;
                worst_axis = i;
            }
            if ratio < 1.0 / NEAR_LIMIT {
                near[k.min(SEGMENTS - 1)] = true;
                near[k.saturating_sub(1)] = true;
            }
        }
    }
    // Where the profile's acceleration peaks (its phases' ends) the steps are checked
    // between the knots too, and every axis at the peak itself, on both sides of it: an
    // S-curve's braking peaks within the last step or two, and between its quarter points
    // the acceleration's triangle can rise by 2 % (always checked); a trapezoid's braking
    // begins at its top speed, where the term q″·ṡ² is largest, between two knots (0.07 %
    // over on a line whose braking takes two steps: checked where an axis comes near a
    // limit there).
    let mut peaks = false;
    // (The steps around a phase's end: the state's derivative steps there.)
    let mut kinks = [Kink::None; SEGMENTS];
    if profile.dist > 0.0 {
        let s_curve = profile.t_jerk > 0.0;
        let mut last = f64::NAN;
        for t in profile.breakpoints() {
            // (A trapezoid's are pairs: no jerk phases.)
            if t == last {
                continue;
            }
            last = t;
            let s = (profile.at(t) / profile.dist).clamp(0.0, 1.0);
            let k = joints.step_at(s);
            let steps = [k.saturating_sub(1), k, (k + 1).min(SEGMENTS - 1)];
            for step in steps {
                kinks[step] = if s_curve { Kink::Accel } else { Kink::Speed };
            }
            let w = ((s - joints.knot(k)) / joints.step(k)).clamp(0.0, 1.0);
            let v_path = profile.speed_at(t) / profile.dist;
            // (A trapezoid's acceleration steps at its breakpoints: both sides.)
            let sides = [
                t - PHASE_SIDE * profile.t_total,
                t + PHASE_SIDE * profile.t_total,
            ]
            .map(|t| profile.accel_at(t) / profile.dist);
            // The worst axis there, its slopes and curvatures given per axis.
            let worst_at = |slopes: &dyn Fn(usize) -> (f64, f64)| {
                let mut out = (f64::INFINITY, 0);
                for a_path in sides {
                    for i in 0..joints.axes {
                        let (v, a) = axis_load(slopes(i), v_path, a_path);
                        let ratio = (speed[i] / v).min(accel[i] / a);
                        if ratio < out.0 {
                            out = (ratio, i);
                        }
                    }
                }
                out
            };
            // First the knots' slopes, interpolated.
            let mut here = worst_at(&|i| {
                let (a0, a1) = (derivatives[k][i], derivatives[k + 1][i]);
                (a0.0 + w * (a1.0 - a0.0), a0.1 + w * (a1.1 - a0.1))
            });
            if !s_curve && here.0 >= 1.0 / NEAR_LIMIT {
                continue;
            }
            // Near a limit (or an S-curve's), the slopes and curvatures from the joints an
            // eighth of a step to each side (the knots' are a step's finite differences:
            // 3e-5 of a limit off, where a braking phase ends at its peak), inside the path.
            let h = 0.125 * joints.step(k);
            if here.0 < 1.0 / NEAR_LIMIT && s - h > 0.0 && s + h < 1.0 {
                let before = joints_at(s - h, &joints.q[k])?;
                let at = joints_at(s, &before)?;
                let after = joints_at(s + h, &at)?;
                here = worst_at(&|i| {
                    let d1 = (after[i] - before[i]) / (2.0 * h);
                    (d1, (after[i] - 2.0 * at[i] + before[i]) / (h * h))
                });
            }
            if here.0 < worst {
                (worst, worst_axis) = here;
            }
            for step in steps {
                near[step] = true;
            }
            peaks = true;
        }
    }
    // The jerk where it came near a limit, with each step's q‴ from its quarter points: a
    // sharp peak of q‴ (a path close to a singularity, at speed) falls between the knots'
    // differences.
    if let Some(kj) = &knot_jerks
        && jerk_near.iter().any(|n| *n)
    {
        inner.fill(joints, &jerk_near, joints_at)?;
        for k in 0..KNOTS {
            for i in (0..joints.axes).filter(|i| jerk[*i].is_finite()) {
                let finer = [k.saturating_sub(1), k.min(SEGMENTS - 1)]
                    .iter()
                    .filter_map(|step| inner.third_slope(joints, *step, i))
                    .fold(0.0f64, f64::max);
                // (No step solved next to this knot: its bound is the knots' own, above.)
                if finer <= 0.0 {
                    continue;
                }
                let load = axis_jerk_load(joints, derivatives, (k, i), kj.near[k], finer);
                // (Only a q‴ sharper than the knots' counts: third differences a quarter
                // step apart carry the joints' rounding, ~1e-7 of a limit, even on a line.)
                let knots = axis_jerk_load(joints, derivatives, (k, i), kj.near[k], 0.0);
                if load > knots * (1.0 + FINER_JERK) {
                    let ratio = (jerk[i] / load).cbrt();
                    if ratio < worst {
                        (worst, worst_axis) = (ratio, i);
                    }
                }
            }
        }
    }
    let mut fits = worst >= 1.0 - JOINT_SPEED_TOLERANCE;
    // (A ratio below 1 is a speed's or an acceleration's: stretching the profile's time by
    // its inverse keeps both.)
    let mut over = 1.0 / worst.min(1.0);
    if fits && (worst < 1.0 / NEAR_LIMIT || peaks) {
        inner.fill(joints, &near, joints_at)?;
        let state = |_: usize, s: f64| {
            let (v, a) = state_at_distance(profile, s * profile.dist);
            (v * v, a)
        };
        let mut ratios = [0.0f64; SEGMENTS];
        let (rv, ra) = inner.ratios(joints, (speed, accel), state, &kinks, &mut ratios);
        fits = rv.max(ra) <= 1.0 + JOINT_SPEED_TOLERANCE;
        over = over.max(rv).max(ra.sqrt());
    }
    Ok(ProfileCheck {
        fits,
        worst_axis,
        sd,
        over,
    })
}

/// The samples of a path that moves by `profile` (`executed`: the profile, when it is
/// not the programmed one).
fn profile_samples(
    joints: &JointPath,
    profile: &Profile,
    check: &ProfileCheck,
    executed: Option<Profile>,
    end: [f64; MAX_AXES],
) -> PathSamples {
    // A profile accepted within the check's tolerance over a limit (up to 1e-6, for the
    // rounding of the joints' differences) runs that much slower where the check
    // measured more than [`MEASURED_OVER`]: every axis within its limits as measured.
    if check.over > 1.0 + MEASURED_OVER {
        let stretched = executed.unwrap_or(*profile).stretched(check.over);
        let mut within = check.clone();
        within.over = 1.0;
        for sd in within.sd.iter_mut() {
            *sd /= check.over;
        }
        return profile_samples(joints, &stretched, &within, Some(stretched), end);
    }
    // The profile's top speed is halfway through its time: the step it falls in moves
    // at most that fast.
    let peak_s = profile.at(0.5 * profile.t_total) / profile.dist.max(f64::MIN_POSITIVE);
    let peak = profile.speed_at(0.5 * profile.t_total);
    let peak_step = joints.step_at(peak_s);
    let mut step_speed = [0.0f64; SEGMENTS];
    for (k, v) in step_speed.iter_mut().enumerate() {
        *v = if k == peak_step {
            peak
        } else {
            check.sd[k].max(check.sd[k + 1])
        };
    }
    PathSamples {
        seeds: seeds_of(joints),
        timing: None,
        executed,
        unslowed: None,
        worst_axis: check.worst_axis,
        rates: rate_bounds(joints, &step_speed),
        cruise_rates: rate_bounds(joints, &[peak; SEGMENTS]),
        end,
        look_ahead: None,
    }
}

/// How much slower than the fastest any timing could be (the programmed profile, or
/// cruising at the programmed speed from end to end) a trapezoid at a lower acceleration
/// may be for the time-optimal timing to be left out: 0.05 %.
const NEAR_OPTIMAL: f64 = 5e-4;

/// Halvings of the acceleration interval in [`lower_profile`]: to 2⁻²⁴ of the largest.
const LOWER_ROUNDS: usize = 24;

/// The programmed profile's shape (speed `vs`, jerk ramp kept) at the highest path
/// acceleration below the programmed one (and below what the axes allow at the path's
/// ends, where it starts from rest) at which every axis keeps its limits, found by
/// bisection; `None` if even a tiny one does not (an axis's speed binds at cruise). On
/// an arc (`normal`: its swept angle) the tangential acceleration `a` leaves room for the
/// centripetal one at cruise: √(a² + (normal·vs²)²) within `whole`.
fn lower_profile(
    joints: &JointPath,
    derivatives: &KnotDerivatives,
    profile: &Profile,
    (vs, ramp, normal, whole): (f64, f64, f64, f64),
    limits: (&[f64], &[f64], &[f64]),
    inner: &mut Inner,
    joints_at: &impl Fn(f64, &[f64; MAX_AXES]) -> Result<[f64; MAX_AXES], PlanError>,
) -> Result<Option<(Profile, ProfileCheck)>, PlanError> {
    // At rest at either end the axis accelerations are q′·s̈: a bound in closed form.
    let mut hi = profile.a;
    for slopes in &joints.end_slopes {
        for (slope, a) in slopes.iter().zip(limits.1) {
            if *slope != 0.0 {
                hi = hi.min(a / slope.abs());
            }
        }
    }
    if !hi.is_finite() || hi <= 0.0 {
        return Ok(None);
    }
    // With jerk limits, the jerk ramps as long as the slowest axis's does (a / j = ramp).
    let shaped = |a: f64| {
        let j = if ramp > 0.0 { a / ramp } else { f64::INFINITY };
        Profile::with_jerk(1.0, vs, a, j)
    };
    // Bisection on the knots alone (cheap: no IK), then the full check between them; where
    // that finds an axis past a limit, a little lower.
    // (On an arc, the whole acceleration too: a lower acceleration never reaches a higher
    // peak speed, so this too holds below where it holds.)
    let fits = |a: f64| {
        let p = shaped(a);
        within_whole(&p, normal, whole) && fits_at_knots(joints, derivatives, &p, limits)
    };
    let mut a = hi;
    if !fits(hi) {
        let mut lo = 0.0;
        for _ in 0..LOWER_ROUNDS {
            let mid = 0.5 * (lo + a);
            if fits(mid) {
                lo = mid;
            } else {
                a = mid;
            }
        }
        a = lo;
    }
    let mut failed = None;
    for _ in 0..LOWER_RETRIES {
        if a <= 0.0 {
            break;
        }
        let p = shaped(a);
        let check = check_profile(joints, derivatives, &p, limits, inner, joints_at)?;
        if check.fits {
            // Between this one and the last that failed, the highest that passes.
            let mut best = (p, check);
            if let Some(mut hi) = failed {
                let mut lo = a;
                for _ in 0..LOWER_REFINE {
                    let mid = 0.5 * (lo + hi);
                    let p = shaped(mid);
                    let check = check_profile(joints, derivatives, &p, limits, inner, joints_at)?;
                    if check.fits {
                        lo = mid;
                        best = (p, check);
                    } else {
                        hi = mid;
                    }
                }
            }
            return Ok(Some(best));
        }
        failed = Some(a);
        a *= LOWER_STEP;
    }
    Ok(None)
}

/// Whether a profile's peak acceleration along a path and the centripetal one at its peak
/// speed (`normal`·v², `normal` an arc's swept angle, 0 on a line) stay together within
/// the path's whole acceleration (per unit of its fraction; they peak at different times,
/// so this is on the safe side).
fn within_whole(p: &Profile, normal: f64, whole: f64) -> bool {
    if normal == 0.0 {
        return true;
    }
    let centripetal = normal * p.v * p.v;
    p.a * p.a + centripetal * centripetal <= whole * whole
}

/// Every axis's (q′, q″) at every knot ([`JointPath::derivatives`]), computed once per
/// sampled path.
pub(super) type KnotDerivatives = [[(f64, f64); MAX_AXES]; KNOTS];

pub(super) fn knot_derivatives(joints: &JointPath) -> KnotDerivatives {
    let mut out = [[(0.0, 0.0); MAX_AXES]; KNOTS];
    for (k, row) in out.iter_mut().enumerate() {
        for (i, d) in row.iter_mut().enumerate().take(joints.axes) {
            *d = joints.derivatives(k, i);
        }
    }
    out
}

/// Whether every axis keeps its speed and acceleration under `profile` at every knot.
fn fits_at_knots(
    joints: &JointPath,
    derivatives: &KnotDerivatives,
    profile: &Profile,
    (speed, accel, jerk): (&[f64], &[f64], &[f64]),
) -> bool {
    let knot_jerks = KnotJerks::of(joints, profile).filter(|_| jerk.iter().any(|j| j.is_finite()));
    derivatives.iter().enumerate().all(|(k, row)| {
        let s = joints.knot(k);
        let (v_path, a_path) = knot_state(knot_jerks.as_ref(), profile, s, k);
        row[..joints.axes].iter().enumerate().all(|(i, &d)| {
            let (v, a) = axis_load(d, v_path, a_path);
            let jerk_within = match &knot_jerks {
                Some(kj) if jerk[i].is_finite() => {
                    axis_jerk_load(joints, derivatives, (k, i), kj.near[k], 0.0)
                        <= jerk[i] * (1.0 + JOINT_SPEED_TOLERANCE)
                }
                _ => true,
            };
            v <= speed[i] * (1.0 + JOINT_SPEED_TOLERANCE)
                && a <= accel[i] * (1.0 + JOINT_SPEED_TOLERANCE)
                && jerk_within
        })
    })
}

/// The path's speed and acceleration at knot `k` (at `s`): from the knot's time where
/// [`KnotJerks`] has it, else by distance.
fn knot_state(knot_jerks: Option<&KnotJerks>, profile: &Profile, s: f64, k: usize) -> (f64, f64) {
    match knot_jerks {
        Some(kj) => kj.state(profile, k),
        None => state_at_distance(profile, s * profile.dist),
    }
}

/// An axis's speed and acceleration (magnitudes) where its path derivatives are `(q′, q″)`
/// and the path moves at `ṡ`, accelerating at `s̈`: q′·ṡ and q′·s̈ + q″·ṡ².
fn axis_load((d1, d2): (f64, f64), sd: f64, sdd: f64) -> (f64, f64) {
    ((d1 * sd).abs(), (d1 * sdd + d2 * sd * sd).abs())
}

/// The slowest fraction of the programmed speed a jerk-limited path tries (below, the
/// time-optimal timing without its jerk ramps, if no S-curve fits at all).
const SLOWEST_S_CURVE: f64 = 1.0 / 64.0;
/// Rounds of the golden-section search for a jerk-limited path's speed: to 0.618²⁴ of
/// the interval (about 1e-5).
const SPEED_ROUNDS: usize = 24;

/// Tries of [`lower_profile`] when the check between the knots fails, each
/// [`LOWER_STEP`] of the last.
const LOWER_RETRIES: usize = 6;
const LOWER_STEP: f64 = 0.97;
/// Halvings between the last step that failed and the first that passed: to 2⁻⁸ of a step.
const LOWER_REFINE: usize = 8;

/// Knots kept as IK seeds for the executed path: every 16th (0, 16, …, 256).
pub(super) const SEEDS: usize = SEGMENTS / 16 + 1;

/// The seeds of a sampled path: its joints at every 16th knot (at the knots nearest
/// every 16th of the path where they are graded).
pub(super) fn seeds_of(joints: &JointPath) -> [[f64; MAX_AXES]; SEEDS] {
    let mut out = [[0.0; MAX_AXES]; SEEDS];
    for (j, seed) in out.iter_mut().enumerate() {
        let k = if joints.graded() {
            let s = j as f64 / (SEEDS - 1) as f64;
            let knots = joints.knots();
            let after = knots.partition_point(|v| *v < s).min(SEGMENTS);
            if after > 0 && s - knots[after - 1] < knots[after] - s {
                after - 1
            } else {
                after
            }
        } else {
            j * 16
        };
        *seed = joints.q[k];
    }
    out
}

/// How near a limit (its fraction) an axis may come at the knots under the programmed
/// profile before the path is also checked between them.
const NEAR_LIMIT: f64 = 0.95;

/// Rounds of giving steps less room before the timing is slowed as a whole.
const ROOM_ROUNDS: usize = 4;

/// Rounds of giving steps less room to a timing that starts at speed (a corner's).
const ROOM_ROUNDS_AT_SPEED: usize = 10;

/// A profile's speed and acceleration where it has covered `d`: in closed form for a
/// trapezoid (the speed squared is linear in the distance on each ramp; at a ramp's end
/// the ramp's acceleration), else through its time.
fn state_at_distance(p: &Profile, d: f64) -> (f64, f64) {
    if p.t_jerk == 0.0 && p.t_acc > 0.0 {
        let ramp = 0.5 * p.v * p.t_acc;
        if d <= ramp {
            return ((2.0 * p.a * d).max(0.0).sqrt(), p.a);
        }
        if d >= p.dist - ramp {
            return ((2.0 * p.a * (p.dist - d)).max(0.0).sqrt(), -p.a);
        }
        return (p.v, 0.0);
    }
    let t = p.time_at(d);
    (p.speed_at(t), p.accel_at(t))
}

/// Per axis, a bound on its speed along a sampled path under `timing` (its largest path
/// speed on each step: `Timing::step_top_speed`).
pub(super) fn timed_rates(joints: &JointPath, timing: &Timing) -> [f64; MAX_AXES] {
    let mut step_speed = [0.0f64; SEGMENTS];
    for (k, v) in step_speed.iter_mut().enumerate() {
        *v = timing.step_top_speed(k);
    }
    rate_bounds(joints, &step_speed)
}

/// Per axis, a bound on its speed along a sampled path whose fraction moves at most
/// `step_speed[k]` through step `k`: the largest of the axis's rate of change over the
/// step (the chord) and at its two knots, times that speed, with 1 % for the path's
/// curvature within a step (the collider's horizon relies on it as a bound).
fn rate_bounds(joints: &JointPath, step_speed: &[f64; SEGMENTS]) -> [f64; MAX_AXES] {
    let mut rates = [0.0f64; MAX_AXES];
    for (k, v) in step_speed.iter().enumerate() {
        for (i, r) in rates.iter_mut().enumerate().take(joints.axes) {
            let chord = (joints.q[k + 1][i] - joints.q[k][i]).abs() / joints.step(k);
            let d = chord
                .max(joints.derivatives(k, i).0.abs())
                .max(joints.derivatives(k + 1, i).0.abs());
            *r = r.max(1.01 * d * v);
        }
    }
    rates
}
