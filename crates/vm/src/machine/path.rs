//! Sampling a Cartesian path before it moves ([`sample_path`]): the joints at the
//! timing's knots by inverse kinematics on the motion's own branch, reachability, jumps
//! between configurations (a singularity on the way), every axis's speed and acceleration
//! under the planned profile, and where the profile would exceed one, the path's
//! time-optimal timing (`vworks_model::timing`); the bound on each axis's speed the
//! collider reads; and the VM's memo of sampled paths ([`PathMemo`]).

use vworks_model::RobotModel;
use vworks_model::math::Iso;
use vworks_model::timing::{JointPath, KNOTS, Limits, SEGMENTS, Timing, TimingError};

use super::plan::{JOINT_SPEED_TOLERANCE, PlanError, ik_tcp};
use crate::MAX_AXES;
use crate::motion::{Path, Profile, cartesian_at};

/// The most an axis may turn between two knots of a Cartesian path (1/256 of it) before
/// the path counts as passing a singularity (the joints jump to another configuration):
/// 45°.
pub(super) const MAX_KNOT_TURN: f64 = std::f64::consts::FRAC_PI_4;

/// How much of every axis limit a time-optimal path timing leaves unused: the timing keeps
/// the limits exactly at its knots and halfway between them, and the path's curvature
/// within one step (1/256 of the path) moves them by less than this.
const TIMING_MARGIN: f64 = 5e-4;
/// Sampled paths a VM remembers (the oldest goes first).
pub(super) const PATH_MEMO: usize = 32;
/// A sampled path's key: the bits of the start joints, the start and goal poses (rotation,
/// translation), the via point (NaN for a line), the path's speed, acceleration and jerk,
/// and the tool.
pub(super) const PATH_KEY: usize = MAX_AXES + 12 + 12 + 3 + 3 + 12;

/// What sampling a Cartesian path found: its time-optimal timing where the planned profile
/// would take an axis past its speed or acceleration limit (`None`: the profile keeps
/// them all), the axis whose limit binds most, each axis's largest speed, the joints at
/// the end.
#[derive(Clone, Debug)]
pub(super) struct PathSamples {
    pub(super) timing: Option<Timing>,
    pub(super) worst_axis: usize,
    pub(super) rates: [f64; MAX_AXES],
    pub(super) end: [f64; MAX_AXES],
}

/// Cartesian paths sampled, by the bits of their joints, poses, speed and tool: a program
/// repeating its moves samples each once. A cache of a pure function (exact keys): [`plan`]
/// gives the same with an empty memo as with a full one.
#[derive(Debug)]
pub(super) struct PathMemo {
    entries: Vec<([u64; PATH_KEY], PathSamples)>,
}

impl PathMemo {
    /// An empty memo, its room reserved once.
    pub(super) fn new() -> PathMemo {
        PathMemo {
            entries: Vec::with_capacity(PATH_MEMO),
        }
    }

    /// The samples under `key`, or those `sample` makes (then remembered; the oldest goes
    /// when the memo is full, so it never grows past its capacity).
    pub(super) fn get_or_sample(
        &mut self,
        key: [u64; PATH_KEY],
        sample: impl FnOnce() -> Result<PathSamples, PlanError>,
    ) -> Result<PathSamples, PlanError> {
        if let Some((_, s)) = self.entries.iter().find(|(k, _)| *k == key) {
            return Ok(s.clone());
        }
        let s = sample()?;
        if self.entries.len() >= PATH_MEMO {
            self.entries.remove(0);
        }
        self.entries.push((key, s.clone()));
        Ok(s)
    }
}
/// Samples a Cartesian path at the timing's [`KNOTS`] from joints `from` (each knot's IK
/// seeded from the one before, on the analytic `branch` the motion executes on, if the arm
/// has one): every point reachable (or the error, naming where), no axis jumping to
/// another configuration between two knots. Then
/// checks `profile` (the path fraction against time) against every axis's speed and
/// acceleration at the knots; if an axis would exceed one, the path's time-optimal
/// timing within the axis limits and the profile's own speed and acceleration.
pub(super) fn sample_path(
    model: &RobotModel,
    tool: &Iso,
    (path, start, goal, from): (&Path, &Iso, &Iso, &[f64; MAX_AXES]),
    branch: Option<u8>,
    profile: &Profile,
) -> Result<PathSamples, PlanError> {
    let n = model.dof();
    let mut joints = JointPath::new(n);
    joints.q[0] = *from;
    let tool_inv = tool.inverse();
    for k in 1..KNOTS {
        let s = k as f64 / SEGMENTS as f64;
        let pose = cartesian_at(path, start, goal, s);
        let prev = joints.q[k - 1];
        // The motion's own branch where it is within the joint limits (the executed
        // path); else the nearest solution, which then shows as a jump below.
        let mut q = [0.0; MAX_AXES];
        let on_branch = branch.is_some_and(|b| {
            let flange = pose.mul(&tool_inv);
            model
                .ik_in_branch(&flange, &prev[..n], b, &mut q[..n])
                .is_ok()
                && model.within_limits(&q[..n])
        });
        joints.q[k] = if on_branch {
            q
        } else {
            ik_tcp(model, tool, &pose, &prev).map_err(|error| PlanError::Unreachable {
                error,
                at_percent: Some(s * 100.0),
            })?
        };
    }
    for k in 1..KNOTS {
        for i in 0..n {
            let turn = (joints.q[k][i] - joints.q[k - 1][i]).abs();
            if turn > MAX_KNOT_TURN {
                return Err(PlanError::ConfigurationJump {
                    axis: i,
                    at_percent: k as f64 * 100.0 / SEGMENTS as f64,
                    turn_deg: turn.to_degrees(),
                });
            }
        }
    }
    let mut speed = [0.0f64; MAX_AXES];
    let mut accel = [0.0f64; MAX_AXES];
    for i in 0..n {
        let j = model.axis(i);
        speed[i] = j.max_velocity;
        accel[i] = j.max_accel;
    }
    // The profile at each knot: path speed and acceleration where it passes.
    let mut worst = 1.0f64;
    let mut worst_axis = 0;
    let mut sd = [0.0f64; KNOTS];
    for (k, sd_k) in sd.iter_mut().enumerate() {
        let s = k as f64 / SEGMENTS as f64;
        let (v_path, a_path) = state_at_distance(profile, s * profile.dist);
        *sd_k = v_path;
        for i in 0..n {
            let (d1, d2) = joints.derivatives(k, i);
            let v = (d1 * v_path).abs();
            let a = (d1 * a_path + d2 * v_path * v_path).abs();
            let ratio = (speed[i] / v).min(accel[i] / a);
            if ratio < worst {
                worst = ratio;
                worst_axis = i;
            }
        }
    }
    // The profile's top speed is halfway through its time: the step it falls in moves
    // at most that fast.
    let peak_s = profile.at(0.5 * profile.t_total) / profile.dist.max(f64::MIN_POSITIVE);
    let peak = profile.speed_at(0.5 * profile.t_total);
    let peak_step = ((peak_s * SEGMENTS as f64) as usize).min(SEGMENTS - 1);
    let end = joints.q[SEGMENTS];
    if worst >= 1.0 - JOINT_SPEED_TOLERANCE {
        let mut step_speed = [0.0f64; SEGMENTS];
        for (k, v) in step_speed.iter_mut().enumerate() {
            *v = if k == peak_step {
                peak
            } else {
                sd[k].max(sd[k + 1])
            };
        }
        return Ok(PathSamples {
            timing: None,
            worst_axis,
            rates: rate_bounds(&joints, &step_speed),
            end,
        });
    }
    for i in 0..n {
        speed[i] *= 1.0 - TIMING_MARGIN;
        accel[i] *= 1.0 - TIMING_MARGIN;
    }
    let limits = Limits {
        axis_speed: &speed[..n],
        axis_accel: &accel[..n],
        path_speed: profile.v,
        path_accel: profile.a,
    };
    let timing = Timing::optimal(&joints, &limits).map_err(|e| match e {
        TimingError::Stuck { knot, axis } | TimingError::NotFinite { knot, axis } => {
            PlanError::Singular {
                axis,
                at_percent: knot as f64 * 100.0 / SEGMENTS as f64,
            }
        }
        // (The limits come from a checked model and a checked profile.)
        _ => PlanError::Singular {
            axis: 0,
            at_percent: 0.0,
        },
    })?;
    // ṡ² is linear in s within a step: ṡ is largest at one of its ends.
    let mut step_speed = [0.0f64; SEGMENTS];
    for (k, v) in step_speed.iter_mut().enumerate() {
        *v = timing.speed_at_knot(k).max(timing.speed_at_knot(k + 1));
    }
    Ok(PathSamples {
        rates: rate_bounds(&joints, &step_speed),
        timing: Some(timing),
        worst_axis,
        end,
    })
}

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

/// Per axis, a bound on its speed along a sampled path whose fraction moves at most
/// `step_speed[k]` through step `k`: the largest of the axis's rate of change over the
/// step (the chord) and at its two knots, times that speed, with 1 % for the path's
/// curvature within a step (the collider's horizon relies on it as a bound).
fn rate_bounds(joints: &JointPath, step_speed: &[f64; SEGMENTS]) -> [f64; MAX_AXES] {
    let mut rates = [0.0f64; MAX_AXES];
    for (k, v) in step_speed.iter().enumerate() {
        for (i, r) in rates.iter_mut().enumerate().take(joints.axes) {
            let chord = (joints.q[k + 1][i] - joints.q[k][i]).abs() * SEGMENTS as f64;
            let d = chord
                .max(joints.derivatives(k, i).0.abs())
                .max(joints.derivatives(k + 1, i).0.abs());
            *r = r.max(1.01 * d * v);
        }
    }
    rates
}
