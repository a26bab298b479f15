//! The motion planner: a motion's operands ([`MotionOperands`]), and the pure function
//! [`plan`] from the robot model, where the robot is ([`PlanFrom`]) and those operands to a
//! trajectory with its exact duration ([`Plan`]) or a typed [`PlanError`]; and the joints
//! and TCP at any time inside a trajectory (the collider's sweep reads its speed bounds).
//!
//! Planning allocates nothing: operands are read into fixed-size arrays, and a Cartesian
//! path's samples are remembered in a [`PathMemo`](super::path::PathMemo) of fixed
//! capacity (module `path`).

use vworks_model::math::Iso;
use vworks_model::{IkError, RobotModel};

use super::{span_ns, to_iso};
use crate::MAX_AXES;
use crate::bytecode::{Instr, MoveFlags};
use crate::motion::{NS, Path, Profile};
use crate::types::{Dim, fmt_quantity};
use vworks_model::timing::{SEGMENTS, Timing};

use super::path::{PATH_KEY, PathMemo, PathSamples, SEEDS, sample_path};
use super::smooth::{profile_look_ahead, smooth_look_ahead};
pub(super) use super::trajectory::Trajectory;

/// How far (relative) an axis's speed found by sampling may exceed its limit and still
/// count as within it: `|Δq|/Δt > v_max · (1 + JOINT_SPEED_TOLERANCE)` is too fast. Both
/// sampled checks use it — a Cartesian path's axis speeds ([`plan`]) and a corner's
/// (`blend`). Sampled speeds are finite differences of joints that numeric IK solved to
/// about 1e-10, and a corner's sample times are whole nanoseconds: a span of ~1 ms between
/// samples rounds by up to 1e-6 of itself. Below that, an excess is rounding, not a
/// faster axis. (The exact, analytic bounds of `blend::corner_bounds` keep 1e-9.)
pub(super) const JOINT_SPEED_TOLERANCE: f64 = 1e-6;

/// Why a motion cannot be planned. The texts are the runtime errors the program sees.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum PlanError {
    /// The target (or, with `at_percent`, a point of the path) has no joint solution.
    #[error("unreachable pose: {error}{}", at_percent.map(|p| format!(" (at {p:.0}% of the path)")).unwrap_or_default())]
    Unreachable {
        /// Why inverse kinematics failed, at the TCP position the program wrote.
        error: IkError,
        /// Where on a Cartesian path (percent of its length), if not at the target.
        at_percent: Option<f64>,
    },
    /// The path passes a point where an axis would need unbounded speed (a singularity,
    /// or inverse kinematics changing configuration): the motion cannot move there.
    #[error(
        "the path passes a singularity at {at_percent:.0}% of its length: axis {} would need unbounded speed there; move the path away from it (change the target or the approach), or use move_j",
        axis + 1
    )]
    Singular {
        /// The axis (0-based).
        axis: usize,
        /// Where (percent of the path).
        at_percent: f64,
    },
    /// Along the path the joints jump to another configuration: an axis turns more than
    /// [`MAX_KNOT_TURN`] within one step of the path (a wrist or shoulder singularity on the
    /// way, or inverse kinematics changing branch).
    #[error(
        "the path passes a singularity at {at_percent:.0}% of its length: axis {} would turn {turn_deg:.0}° within 1/{} of the path (the arm changes configuration there); a controller stops here too: move the path away from it (another target, approach or wrist configuration), or use move_j",
        axis + 1,
        SEGMENTS
    )]
    ConfigurationJump {
        /// The axis (0-based).
        axis: usize,
        /// Where (percent of the path).
        at_percent: f64,
        /// How far it would turn (degrees, or mm for a prismatic axis).
        turn_deg: f64,
    },
    /// A `move_j` target outside an axis's range.
    #[error(
        "joint limit exceeded: axis {} `{name}` would go to {goal}, outside its range {lower} to {upper}; choose a target within the range{}",
        axis + 1,
        if *from_pose { " (this pose needs it: try another wrist configuration or approach)" } else { "" }
    )]
    JointLimit {
        /// The axis (0-based).
        axis: usize,
        /// Its name.
        name: String,
        /// The target, the lower and the upper limit, in the axis's display unit.
        goal: String,
        /// See `goal`.
        lower: String,
        /// See `goal`.
        upper: String,
        /// The target was a pose (its joints came from inverse kinematics).
        from_pose: bool,
    },
    /// `duration` of zero or less (s).
    #[error("the duration of a motion must be greater than zero (got {})", fmt_quantity(*.0, Dim::TIME))]
    Duration(f64),
    /// A time past the simulator's range (the text of `span_ns`).
    #[error("{0}")]
    TimeLimit(String),
    /// A TCP speed of zero or less, or not a number (m/s).
    #[error("the speed must be greater than zero (got {})", fmt_quantity(*.0, Dim::SPEED))]
    Speed(f64),
    /// An acceleration of zero or less (m/s²).
    #[error("the acceleration must be greater than zero (got {})", fmt_quantity(*.0, Dim::ACCEL))]
    Accel(f64),
    /// An orientation speed of zero or less (rad/s).
    #[error("the orientation speed must be greater than zero (got {})", fmt_quantity(*.0, Dim::ANGSPEED))]
    Orient(f64),
    /// `move_j` speed or acceleration ratios outside (0, 1].
    #[error(
        "speed and acceleration of move_j must be more than 0% and at most 100% (got {}%, {}%)",
        ratio * 100.0,
        aratio * 100.0
    )]
    Ratios {
        /// The speed ratio.
        ratio: f64,
        /// The acceleration ratio.
        aratio: f64,
    },
    /// A `move_c` via point on the line from start to target.
    #[error(
        "move_c: the via point lies on the line from start to target; give a point off that line"
    )]
    ViaOnLine,
    /// A negative zone radius (m).
    #[error(
        "the zone cannot be negative (got {}); write a radius such as `zone 10mm`, or `zone fine`",
        fmt_quantity(*.0, Dim::LENGTH)
    )]
    Zone(f64),
    /// A negative orientation zone: its radius (m) or angle (rad).
    #[error(
        "the orientation zone cannot be negative (got {} and {}); write a radius and an angle such as `ori 15mm 1.5deg`",
        fmt_quantity(*.0, Dim::LENGTH),
        fmt_quantity(*.1, Dim::ANGLE)
    )]
    OriZone(f64, f64),
}

/// Up to 12 slots of a pose (6) or joints (12) operand, without allocating.
#[derive(Clone, Copy, Debug)]
pub(super) struct Slots {
    v: [u64; MAX_AXES],
    len: usize,
}

impl Slots {
    fn read(stack: &[u64], from: usize, len: usize) -> Slots {
        let mut v = [0u64; MAX_AXES];
        v[..len].copy_from_slice(&stack[from..from + len]);
        Slots { v, len }
    }
    fn get(&self) -> &[u64] {
        &self.v[..self.len]
    }
}

/// The operands of a motion instruction.
#[derive(Clone, Copy, Debug)]
pub(super) struct MotionOperands {
    /// `move_j`, `move_l` or `move_c`.
    kind: MoveKind,
    /// Target slots (6 for a pose, 12 for joints).
    target: Slots,
    /// Via point slots of `move_c`.
    via: Option<Slots>,
    /// `speed`, if given.
    speed: Option<f64>,
    /// `accel`, if given.
    accel: Option<f64>,
    /// `zone` radius (m; 0 for `zone fine`), if given.
    pub(super) zone: Option<f64>,
    /// Its orientation zone, if given: radius (m) and angle (rad).
    pub(super) ori_zone: Option<(f64, f64)>,
    /// `tool` (the TCP in the tool link's frame), if given.
    pub(super) tool: Option<Iso>,
    /// The `speed` of a `move_j` is a TCP speed (m/s), not a ratio.
    tcp_speed: bool,
    /// `orient`: the largest orientation speed of a Cartesian motion (rad/s).
    orient: Option<f64>,
    /// `duration`: how long the motion takes (s), instead of a speed.
    duration: Option<f64>,
    /// Slots they take on the stack.
    pub(super) width: usize,
}

/// Which motion instruction.
#[derive(Clone, Copy, Debug, PartialEq)]
enum MoveKind {
    /// `move_j`: joint space.
    Joint,
    /// `move_l`, `move_c`: the TCP along a line or an arc.
    Cartesian,
}

impl MotionOperands {
    /// The operands of motion instruction `ins`, read (not popped) from the top of `s`.
    pub(super) fn read(s: &[u64], ins: Instr) -> MotionOperands {
        let f = match ins {
            Instr::MoveJ(f) | Instr::MoveL(f) | Instr::MoveC(f) => f,
            _ => MoveFlags(0),
        };
        let mut k = 0;
        let duration = f.has(MoveFlags::DURATION).then(|| {
            k += 1;
            f64::from_bits(s[s.len() - k])
        });
        let tool = f.has(MoveFlags::TOOL).then(|| {
            k += 6;
            to_iso(&s[s.len() - k..s.len() - k + 6])
        });
        let ori_zone = f.has(MoveFlags::ZONE | MoveFlags::ZONE_ORI).then(|| {
            k += 2;
            (
                f64::from_bits(s[s.len() - k]),
                f64::from_bits(s[s.len() - k + 1]),
            )
        });
        let zone = f.has(MoveFlags::ZONE).then(|| {
            k += 1;
            f64::from_bits(s[s.len() - k])
        });
        let orient = f.has(MoveFlags::ORIENT).then(|| {
            k += 1;
            f64::from_bits(s[s.len() - k])
        });
        let accel = f.has(MoveFlags::ACCEL).then(|| {
            k += 1;
            f64::from_bits(s[s.len() - k])
        });
        let speed = f.has(MoveFlags::SPEED).then(|| {
            k += 1;
            f64::from_bits(s[s.len() - k])
        });
        let tw = if f.has(MoveFlags::TARGET_JOINTS) {
            MAX_AXES
        } else {
            6
        };
        let target = Slots::read(s, s.len() - k - tw, tw);
        k += tw;
        let via = matches!(ins, Instr::MoveC(_)).then(|| {
            let vw = if f.has(MoveFlags::VIA_JOINTS) {
                MAX_AXES
            } else {
                6
            };
            let v = Slots::read(s, s.len() - k - vw, vw);
            k += vw;
            v
        });
        MotionOperands {
            kind: if matches!(ins, Instr::MoveJ(_)) {
                MoveKind::Joint
            } else {
                MoveKind::Cartesian
            },
            target,
            via,
            speed,
            accel,
            zone,
            ori_zone,
            tool,
            orient,
            duration,
            tcp_speed: f.has(MoveFlags::TCP_SPEED),
            width: k,
        }
    }

    /// True for `move_l`/`move_c`: the motion starts from the TCP ([`PlanFrom::tcp`]).
    pub(super) fn is_cartesian(&self) -> bool {
        self.kind == MoveKind::Cartesian
    }
}

/// Where a motion starts, and the settings it is planned with.
#[derive(Clone, Copy, Debug)]
pub(super) struct PlanFrom {
    /// The joints it starts from (the corner's, inside a zone).
    pub(super) joints: [f64; MAX_AXES],
    /// The TCP it starts from (a Cartesian motion's start; unused by `move_j`).
    pub(super) tcp: Iso,
    /// The TCP in the tool link's frame the motion is for.
    pub(super) tool: Iso,
    /// When it is planned (ns): a `duration` must end within the time limit.
    pub(super) time: i64,
    /// The TCP speed of a Cartesian motion without `speed` (m/s).
    pub(super) default_speed: f64,
    /// Its zone as programmed (or the workcell's default): a path timed within its axes'
    /// limits finds its look-ahead point for it.
    pub(super) zone: Option<f64>,
}

/// A planned trajectory and its duration, with what the program should be told of it.
#[derive(Clone, Debug)]
pub(super) struct Plan {
    /// The trajectory.
    pub(super) traj: Trajectory,
    /// Its exact duration (ns).
    pub(super) duration_ns: i64,
    /// It lasts longer than its `duration` asked.
    pub(super) longer: Option<Longer>,
    /// It was slowed to keep an axis within its speed limit.
    pub(super) slowed: Option<Slowed>,
    /// Its programmed TCP speed or acceleration was above the model's.
    pub(super) capped: Option<Capped>,
    /// A zoned path timed within its axes' limits: its look-ahead point (s from its
    /// start), where it can still stop before its zone.
    pub(super) look_ahead: Option<f64>,
}

/// A Cartesian motion asked to move faster than the model's TCP limits allow: the TCP
/// speed (asked, the model's) and the acceleration (asked, the model's), where above.
#[derive(Clone, Copy, Debug, Default)]
pub(super) struct Capped {
    pub(super) speed: Option<(f64, f64)>,
    pub(super) accel: Option<(f64, f64)>,
}

/// A motion that takes `lasts` ns where `want` were asked, the fastest it can (`how`).
#[derive(Clone, Copy, Debug)]
pub(super) struct Longer {
    pub(super) lasts: i64,
    pub(super) want: i64,
    pub(super) how: &'static str,
}

/// A Cartesian motion slowed below its programmed speed where axis `axis` (0-based) would
/// exceed its speed or acceleration limit: it lasts `lasts` ns where the programmed speed
/// and acceleration alone would take `would` ns.
#[derive(Clone, Copy, Debug)]
pub(super) struct Slowed {
    pub(super) axis: usize,
    pub(super) lasts: i64,
    pub(super) would: i64,
}
/// Plans a motion from `from` with `ops` on `model`: its trajectory (joint space, or the
/// TCP along a line or an arc) and exact duration, or why it cannot be. Pure: the result
/// depends on the arguments only (`memo` caches a pure function's samples).
pub(super) fn plan(
    model: &RobotModel,
    from: &PlanFrom,
    ops: &MotionOperands,
    memo: &mut PathMemo,
) -> Result<Plan, PlanError> {
    let duration_ns = match ops.duration {
        None => None,
        Some(t) if t > 0.0 => {
            Some(span_ns(t, from.time, "the motion's duration").map_err(PlanError::TimeLimit)?)
        }
        Some(t) => return Err(PlanError::Duration(t)),
    };
    match ops.kind {
        MoveKind::Joint => plan_move_j(model, from, ops, duration_ns),
        MoveKind::Cartesian => plan_cartesian(model, from, ops, duration_ns, memo),
    }
}

/// The joints of TCP pose `tcp` with tool `tool`, nearest `near`.
pub(super) fn ik_tcp(
    model: &RobotModel,
    tool: &Iso,
    tcp: &Iso,
    near: &[f64],
) -> Result<[f64; MAX_AXES], IkError> {
    let n = model.dof();
    let mut q = [0.0; MAX_AXES];
    let flange = tcp.mul(&tool.inverse());
    model
        .ik(&flange, &near[..n], &mut q[..n])
        // In the TCP's terms, as the program wrote the target.
        .map_err(|e| e.at_position(tcp.t))?;
    Ok(q)
}

/// A pose operand (6 slots) or a joints operand (12 slots) as a TCP pose.
fn operand_pose(model: &RobotModel, tool: &Iso, slots: &[u64]) -> Iso {
    if slots.len() == 6 {
        return to_iso(slots);
    }
    let mut q = [0.0; MAX_AXES];
    let n = model.dof().min(slots.len());
    for (qi, x) in q.iter_mut().zip(&slots[..n]) {
        *qi = f64::from_bits(*x);
    }
    model.tcp(&q[..n], tool)
}

/// A `move_j`: the target's joints within every axis's range, the speed ratio (from a
/// ratio, a TCP speed or a duration), one profile over every axis.
fn plan_move_j(
    model: &RobotModel,
    from: &PlanFrom,
    ops: &MotionOperands,
    duration_ns: Option<i64>,
) -> Result<Plan, PlanError> {
    let target = ops.target.get();
    let n = model.dof();
    let start = from.joints;
    let goal = if target.len() == MAX_AXES {
        let mut q = [0.0; MAX_AXES];
        for (i, v) in q.iter_mut().enumerate().take(n) {
            *v = f64::from_bits(target[i]);
        }
        q
    } else {
        ik_tcp(model, &from.tool, &to_iso(target), &start).map_err(|error| {
            PlanError::Unreachable {
                error,
                at_percent: None,
            }
        })?
    };
    for (i, g) in goal.iter().enumerate().take(n) {
        let j = model.axis(i);
        if *g < j.lower - 1e-9 || *g > j.upper + 1e-9 {
            return Err(PlanError::JointLimit {
                axis: i,
                name: j.name.clone(),
                goal: j.display(*g),
                lower: j.display(j.lower),
                upper: j.display(j.upper),
                from_pose: target.len() != MAX_AXES,
            });
        }
    }
    let aratio = ops.accel.unwrap_or(1.0);
    let mut longer = None;
    let ratio = match ops.speed {
        // A TCP speed: the axes' ratio at which the motion lasts about the TCP's
        // straight-line distance over that speed (docs/language.md, Motion).
        Some(v) if ops.tcp_speed => {
            if v.is_nan() || v <= 0.0 {
                return Err(PlanError::Speed(v));
            }
            let d = vworks_model::math::norm(vworks_model::math::sub(
                model.tcp(&goal[..n], &from.tool).t,
                model.tcp(&start[..n], &from.tool).t,
            ));
            let full = plan_joint(model, start, goal, 1.0, aratio).1 as f64 / NS;
            if d > 0.0 && full > 0.0 {
                (v * full / d).clamp(1e-6, 1.0)
            } else {
                1.0
            }
        }
        _ => match duration_ns {
            // The slowest ratio at which the motion takes at most the duration.
            Some(t) => {
                let lasts = |r: f64| plan_joint(model, start, goal, r, aratio).1;
                let ratio = slowest_within(t, 1e-9, 1.0, lasts);
                longer = longer_than(lasts(ratio), t, "with its slowest axis at full speed");
                ratio
            }
            None => ops.speed.unwrap_or(1.0),
        },
    };
    if !(ratio > 0.0 && ratio <= 1.0 && aratio > 0.0 && aratio <= 1.0) {
        return Err(PlanError::Ratios { ratio, aratio });
    }
    let (traj, duration_ns) = plan_joint(model, start, goal, ratio, aratio);
    Ok(Plan {
        traj,
        duration_ns,
        longer,
        slowed: None,
        capped: None,
        look_ahead: None,
    })
}

/// A motion that lasts `lasts` ns where `want` were asked, if longer.
fn longer_than(lasts: i64, want: i64, how: &'static str) -> Option<Longer> {
    (lasts > want).then_some(Longer { lasts, want, how })
}

/// A `move_l`/`move_c`: the TCP along a line or an arc, orientation by slerp, within the
/// speeds asked (or a duration) and every axis's speed limit along the path.
fn plan_cartesian(
    model: &RobotModel,
    from: &PlanFrom,
    ops: &MotionOperands,
    duration_ns: Option<i64>,
    memo: &mut PathMemo,
) -> Result<Plan, PlanError> {
    let n = model.dof();
    let (start_joints, start, tool) = (from.joints, from.tcp, from.tool);
    let goal = operand_pose(model, &tool, ops.target.get());
    let via_t = ops
        .via
        .as_ref()
        .map(|v| operand_pose(model, &tool, v.get()).t);
    let path = match via_t {
        None => Path::Line {
            from: start.t,
            to: goal.t,
        },
        Some(via_t) => Path::arc(start.t, via_t, goal.t).ok_or(PlanError::ViaOnLine)?,
    };
    let (accel, orient) = (ops.accel, ops.orient);
    let mut v = ops.speed.unwrap_or(from.default_speed);
    if v.is_nan() || v <= 0.0 {
        return Err(PlanError::Speed(v));
    }
    if let Some(a) = accel
        && (a.is_nan() || a <= 0.0)
    {
        // (A param, `--set` or a sweep can make it so at run time; 0 would make the
        // motion take no time at all.)
        return Err(PlanError::Accel(a));
    }
    // The model's TCP limits bound what a program asks; without an `accel` (or a TCP
    // acceleration in the model) the path accelerates as fast as its axes allow.
    let tcp = model.tcp;
    let tcp_speed = tcp.speed.unwrap_or(f64::INFINITY);
    let tcp_accel = tcp.accel.unwrap_or(f64::INFINITY);
    // (Said once per statement: a `slowdown` warning.)
    let mut capped = None;
    // (With a duration the speed is not asked.)
    let speed_above = duration_ns.is_none() && v > tcp_speed;
    if speed_above || accel.is_some_and(|a| a > tcp_accel) {
        capped = Some(Capped {
            speed: speed_above.then_some((v, tcp_speed)),
            accel: accel.filter(|a| *a > tcp_accel).map(|a| (a, tcp_accel)),
        });
    }
    v = v.min(tcp_speed);
    let a = accel.unwrap_or(f64::INFINITY).min(tcp_accel);
    let len = path.length();
    let angle = vworks_model::math::norm(vworks_model::math::rotation_vector(
        &vworks_model::math::mat_mul(&vworks_model::math::transpose(&start.r), &goal.r),
    ));
    // Orientation moves at most `orient` (180°/s without it), as fast as the axes let it
    // accelerate.
    let w = orient.unwrap_or(std::f64::consts::PI);
    if w.is_nan() || w <= 0.0 {
        return Err(PlanError::Orient(w));
    }
    // With jerk limits, the path's jerk ramps as long as the slowest axis's does.
    let ramp = jerk_ramp_time(model);
    // The profile's limits along the path (per unit of its fraction) at TCP speed `v`
    // and orientation speed `w`, the TCP's acceleration `a`. The orientation has no
    // acceleration of its own: the wrist axes bound it, as they do the TCP's without one.
    let limits = |v: f64, w: f64| {
        let (mut vs, mut as_, mut js) = (f64::INFINITY, f64::INFINITY, f64::INFINITY);
        // Below 0.1 µm and 0.1 µrad a move is a rounding error, not a motion.
        if len > 1e-7 {
            vs = vs.min(v / len);
            as_ = as_.min(a / len);
            js = js.min(a / ramp / len);
        }
        if angle > 1e-7 {
            vs = vs.min(w / angle);
        }
        (vs, as_, js)
    };
    let mut longer = None;
    // (`as_` is also the TCP's whole acceleration: on an arc, along it and towards its
    // centre together, within `accel` or the model's.)
    let (vs, as_, js) = limits(v, w);
    if !vs.is_finite() {
        let traj = Trajectory::Cartesian {
            path,
            from: start,
            to: goal,
            profile: Profile::new(0.0, 1.0, 1.0),
            timing: None,
            ramps: None,
            timed: duration_ns.is_some(),
            end_joints: start_joints,
            branch: None,
            rates: [0.0; MAX_AXES],
            cruise_rates: [0.0; MAX_AXES],
            seeds: [start_joints; SEEDS],
            tool,
            corner: None,
            path_limits: [vs, as_, f64::INFINITY],
        };
        return Ok(Plan {
            traj,
            duration_ns: 0,
            longer,
            slowed: None,
            capped,
            look_ahead: None,
        });
    }
    // Joints along the path: reachable, and within every axis's speed and acceleration
    // under the profile; where they are not, the time-optimal timing along the path.
    // The same path from the same joints with the same limits samples the same: a
    // program repeating its moves samples each once (`memo`, exact: keyed by the bits).
    // (A motion with a duration is keyed by it, as minus its nanoseconds: never a speed.)
    let vs_key = duration_ns.map_or(vs, |t| -(t as f64));
    let orient_key = orient.unwrap_or(f64::NAN);
    // A zone's share of the path (at most half), where the look-ahead point is found for.
    let zone_share = from.zone.filter(|z| *z > 0.0).map(|z| (z / len).min(0.5));
    let zone_key = zone_share.unwrap_or(f64::NAN);
    let mut key = [0u64; PATH_KEY];
    let via_or_none = via_t.unwrap_or([f64::NAN; 3]);
    for (k, x) in start_joints
        .iter()
        .chain(start.r.iter().flatten())
        .chain(&start.t)
        .chain(goal.r.iter().flatten())
        .chain(&goal.t)
        .chain(&via_or_none)
        .chain([&vs_key, &as_, &js, &orient_key, &zone_key])
        .chain(tool.r.iter().flatten())
        .chain(&tool.t)
        .enumerate()
    {
        key[k] = x.to_bits();
    }
    let branch = model.ik_branch(&start.mul(&tool.inverse()), &start_joints[..n]);
    let ends = (&path, &start, &goal, &start_joints);
    // The path sampled at TCP speed `v` and orientation speed `w` (its limits there), and
    // how long it then lasts (ns).
    let sample_at = |v: f64, w: f64| -> Result<(PathSamples, Profile, f64), PlanError> {
        let (vs, as_, js) = limits(v, w);
        let profile = Profile::with_jerk(1.0, vs, as_, js);
        let mut s = sample_path(
            model,
            &tool,
            ends,
            branch,
            (&profile, vs, ramp, as_),
            zone_share,
            duration_ns.is_none(),
        )?;
        // (With a zone, a jerk-limited timing or an S-curve looks ahead from where its
        // last braking, moved back by the zone, begins; a timing within the axes' limits
        // has its own look-ahead point.)
        if let (None, Some(z)) = (s.look_ahead, zone_share) {
            s.look_ahead = match &s.timing {
                Some(t) if t.is_smooth() => smooth_look_ahead(t, 1.0 - z),
                Some(_) => None,
                None => profile_look_ahead(s.executed.as_ref().unwrap_or(&profile), z),
            };
        }
        let lasts = sampled_seconds(&s.timing, &s.executed, &profile);
        Ok((s, profile, lasts * NS))
    };
    let profile = Profile::with_jerk(1.0, vs, as_, js);
    // (A path that goes nowhere has returned above: a duration's path moves.)
    let sampled = memo.get_or_try(key, || match duration_ns {
        Some(want) => {
            // The fastest TCP and orientation speeds (`orient`, if given, stays the
            // orientation's bound), scaled together by k.
            let (v_top, w_top) = (MAX_TCP_SPEED.min(tcp_speed), MAX_ORIENT_SPEED);
            let at = |k: f64| sample_at(k * v_top, orient.unwrap_or(k * w_top));
            let cruise = (len / v_top).max(if orient.is_some() { 0.0 } else { angle / w_top });
            let (mut samples, profile, _) = duration_search(want, cruise, at)?;
            // (Its profile with it: not the programmed one of this motion's speed.)
            if samples.timing.is_none() && samples.executed.is_none() {
                samples.executed = Some(profile);
            }
            Ok(samples)
        }
        None => sample_at(v, w).map(|(s, ..)| s),
    })?;
    if let Some(want) = duration_ns {
        longer = longer_than(
            to_ns(sampled_seconds(
                &sampled.timing,
                &sampled.executed,
                &profile,
            )),
            want,
            "at the fastest TCP speed (7 m/s, or the model's TCP speed) and orientation speed (500°/s, or its `orient`)",
        );
    }
    Ok(cartesian_plan(
        (path, start, goal, tool, branch),
        [
            vs,
            as_,
            if angle > 1e-7 {
                w / angle
            } else {
                f64::INFINITY
            },
        ],
        sampled,
        profile,
        duration_ns.is_some(),
        (longer, capped),
    ))
}

/// The plan of a Cartesian motion from its sampled path (`profile`: the programmed one;
/// `timed`: it was given a duration, so a slower speed than the fastest is no slowdown).
fn cartesian_plan(
    (path, start, goal, tool, branch): (Path, Iso, Iso, Iso, Option<u8>),
    path_limits: [f64; 3],
    sampled: PathSamples,
    profile: Profile,
    timed: bool,
    (longer, capped): (Option<Longer>, Option<Capped>),
) -> Plan {
    let PathSamples {
        seeds,
        timing,
        executed,
        unslowed,
        worst_axis,
        rates,
        cruise_rates,
        end: prev,
        look_ahead,
    } = sampled;
    let duration_ns = to_ns(sampled_seconds(&timing, &executed, &profile));
    let profile = executed.unwrap_or(profile);
    let slowed = unslowed.filter(|_| !timed).map(|would| Slowed {
        axis: worst_axis,
        lasts: duration_ns,
        would: (would * NS).ceil() as i64,
    });
    Plan {
        traj: Trajectory::Cartesian {
            path,
            from: start,
            to: goal,
            profile,
            timing,
            ramps: None,
            timed,
            end_joints: prev,
            branch,
            rates,
            cruise_rates,
            seeds,
            tool,
            corner: None,
            path_limits,
        },
        duration_ns,
        longer,
        slowed,
        capped,
        look_ahead: look_ahead.filter(|_| !timed),
    }
}

/// How long a sampled path lasts (s): its timing's, else the profile it executes, else
/// the programmed one.
fn sampled_seconds(
    timing: &Option<Timing>,
    executed: &Option<Profile>,
    programmed: &Profile,
) -> f64 {
    match (timing, executed) {
        (Some(t), _) => t.duration(),
        (None, Some(p)) => p.t_total,
        (None, None) => programmed.t_total,
    }
}

/// Seconds rounded up to whole nanoseconds (as [`Profile::duration_ns`]).
pub(super) fn to_ns(seconds: f64) -> i64 {
    (seconds * NS).ceil() as i64
}

/// Rounds of the search for a `duration` motion's speed (regula falsi, Illinois): it
/// usually settles to the nanosecond in a few.
const DURATION_ROUNDS: usize = 40;

/// A `duration` motion: the path sampled at the lowest fraction k of the fastest speeds
/// (`at(k)`: its samples, programmed profile and duration in ns) at which it lasts at most
/// `want` ns, then stretched in time to last exactly that (every speed over f ≥ 1, every
/// acceleration over f²: within the limits); at full speed if it cannot be that fast.
/// `cruise`: how long the path takes cruising at full speed all the way (s), so at k it
/// takes at least cruise/k: no k below cruise/want can do.
fn duration_search(
    want: i64,
    cruise: f64,
    at: impl Fn(f64) -> Result<(PathSamples, Profile, f64), PlanError>,
) -> Result<(PathSamples, Profile, f64), PlanError> {
    let goal = want as f64;
    let full = at(1.0)?;
    if full.2 > goal {
        // (Not always fastest at full speed: an arc's centripetal acceleration, a jerk
        // ramp. A few slower speeds, then the fastest found.)
        let mut fastest = (1.0, full);
        for k in [0.5, 0.25, 0.125] {
            let found = at(k)?;
            if found.2 < fastest.1.2 {
                fastest = (k, found);
            }
        }
        if fastest.1.2 > goal {
            return Ok(fastest.1);
        }
        // Fast enough at k: the bracket below ends there.
        return duration_between(want, cruise, fastest, at);
    }
    duration_between(want, cruise, (1.0, full), at)
}

/// [`duration_search`] in the bracket from the slowest fraction that can do (cruise at
/// full speed all the way over `want`) to `fast`, a fraction fast enough.
fn duration_between(
    want: i64,
    cruise: f64,
    (k_fast, full): (f64, (PathSamples, Profile, f64)),
    at: impl Fn(f64) -> Result<(PathSamples, Profile, f64), PlanError>,
) -> Result<(PathSamples, Profile, f64), PlanError> {
    let goal = want as f64;
    let k0 = (cruise * NS / goal).min(k_fast);
    let low = at(k0)?;
    if low.2 <= goal {
        return Ok(stretch(low, want));
    }
    // A bracket [ka, kb]: too slow at ka, fast enough at kb.
    let (mut ka, mut fa) = (k0, low.2 - goal);
    let (mut kb, mut fb, mut best) = (k_fast, full.2 - goal, full);
    let mut kept = 0i8;
    for _ in 0..DURATION_ROUNDS {
        if fb > -1.0 || kb - ka <= 1e-14 * kb {
            break;
        }
        let mut k = kb - fb * (kb - ka) / (fb - fa);
        if !(k > ka && k < kb) {
            k = 0.5 * (ka + kb);
        }
        let found = at(k)?;
        let f = found.2 - goal;
        if f <= 0.0 {
            (kb, fb, best) = (k, f, found);
            // (The same end kept twice: its weight halved, the Illinois step.)
            if kept == -1 {
                fa *= 0.5;
            }
            kept = -1;
        } else {
            (ka, fa) = (k, f);
            if kept == 1 {
                fb *= 0.5;
            }
            kept = 1;
        }
    }
    Ok(stretch(best, want))
}

/// A sampled path that lasts at most `want` ns, stretched in time to last exactly that
/// (to the nanosecond: a hair less where rounding would go past).
fn stretch(
    (mut samples, profile, lasts): (PathSamples, Profile, f64),
    want: i64,
) -> (PathSamples, Profile, f64) {
    if lasts <= 0.0 || lasts >= want as f64 {
        return (samples, profile, lasts);
    }
    let mut f = want as f64 / lasts;
    for _ in 0..8 {
        let stretched = match (&samples.timing, &samples.executed) {
            (Some(t), _) => (Some(t.slower(f)), samples.executed),
            (None, Some(p)) => (None, Some(p.stretched(f))),
            (None, None) => (None, Some(profile.stretched(f))),
        };
        let ns = to_ns(sampled_seconds(&stretched.0, &stretched.1, &profile));
        if ns <= want {
            (samples.timing, samples.executed) = stretched;
            return (samples, profile, ns as f64);
        }
        f *= 1.0 - 1e-15;
    }
    (samples, profile, lasts)
}

/// The time a jerk-limited axis takes to ramp its acceleration up (`a/j`), the longest
/// over the axes with a jerk limit; 0 (no ramp: trapezoids) if none has one. Cartesian
/// motions give their path the same ramp time.
fn jerk_ramp_time(model: &RobotModel) -> f64 {
    (0..model.dof())
        .filter_map(|i| {
            let j = model.axis(i);
            j.max_jerk.map(|jerk| j.max_accel / jerk)
        })
        .fold(0.0, f64::max)
}

/// A `move_j` on a robot with jerk limits: every axis its own time-optimal profile
/// (S-curve where the axis has a jerk limit, trapezoid elsewhere) within its speed ×
/// `ratio` and acceleration × `aratio`; the slowest sets the duration, and every other
/// axis is slowed (lower cruise speed, same acceleration and jerk) to last exactly as
/// long — Ruckig's time synchronisation.
fn plan_synced(
    model: &RobotModel,
    from: [f64; MAX_AXES],
    goal: [f64; MAX_AXES],
    ratio: f64,
    aratio: f64,
) -> (Trajectory, i64) {
    let n = model.dof();
    let mut delta = [0.0; MAX_AXES];
    let mut profiles = [Profile::new(0.0, 1.0, 1.0); MAX_AXES];
    let mut t_total = 0.0f64;
    for i in 0..n {
        delta[i] = goal[i] - from[i];
        let j = model.axis(i);
        profiles[i] = Profile::with_jerk(
            delta[i],
            ratio * j.max_velocity,
            aratio * j.max_accel,
            j.max_jerk.unwrap_or(f64::INFINITY),
        );
        t_total = t_total.max(profiles[i].t_total);
    }
    for (i, p) in profiles.iter_mut().enumerate().take(n) {
        *p = p.lasting(t_total, aratio * model.axis(i).max_accel);
    }
    let dur = profiles.iter().map(Profile::duration_ns).max().unwrap_or(0);
    (
        Trajectory::JointSynced {
            from,
            delta,
            profiles,
        },
        dur,
    )
}

/// A joint motion from `from` to `goal` at speed and acceleration ratios `ratio` and
/// `aratio`, and its duration: one normalised profile s(t) ∈ [0, 1] within every axis's
/// limits, or the axes' own time-synchronised profiles where one has a jerk limit.
fn plan_joint(
    model: &RobotModel,
    from: [f64; MAX_AXES],
    goal: [f64; MAX_AXES],
    ratio: f64,
    aratio: f64,
) -> (Trajectory, i64) {
    let n = model.dof();
    if (0..n).any(|i| goal[i] != from[i] && model.axis(i).max_jerk.is_some()) {
        return plan_synced(model, from, goal, ratio, aratio);
    }
    let (mut vs, mut as_) = (f64::INFINITY, f64::INFINITY);
    let mut delta = [0.0; MAX_AXES];
    for i in 0..n {
        delta[i] = goal[i] - from[i];
        let d = delta[i].abs();
        if d > 0.0 {
            let j = model.axis(i);
            vs = vs.min(ratio * j.max_velocity / d);
            as_ = as_.min(aratio * j.max_accel / d);
        }
    }
    let profile = if vs.is_finite() {
        Profile::new(1.0, vs, as_)
    } else {
        Profile::new(0.0, 1.0, 1.0)
    };
    let dur = profile.duration_ns();
    (
        Trajectory::Joint {
            from,
            delta,
            profile,
        },
        dur,
    )
}

/// The fastest TCP speed a motion given a `duration` may use (m/s): RAPID's `v7000`.
const MAX_TCP_SPEED: f64 = 7.0;

/// The fastest orientation speed a motion given a `duration` may use (rad/s): 500°/s, the
/// `v_ori` of RAPID's speeds.
const MAX_ORIENT_SPEED: f64 = 500.0 * std::f64::consts::PI / 180.0;

/// The smallest rate in `lo..=hi` at which a motion lasts at most `want` ns (`lasts`:
/// its duration at a rate, not increasing with it), found by bisection; `hi` if even it
/// lasts longer.
fn slowest_within(want: i64, lo: f64, hi: f64, lasts: impl Fn(f64) -> i64) -> f64 {
    if lasts(hi) > want {
        return hi;
    }
    let (mut lo, mut hi) = (lo, hi);
    if lasts(lo) <= want {
        return lo;
    }
    // 80 halvings take the interval below f64's resolution around the answer.
    for _ in 0..80 {
        let mid = 0.5 * (lo + hi);
        if lasts(mid) <= want {
            hi = mid;
        } else {
            lo = mid;
        }
    }
    hi
}
