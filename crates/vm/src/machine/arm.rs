//! The robot's motion state ([`Arm`]): where it rests, the motion under way, the one
//! planned to start, the rest of a zoned motion it is finishing, its tool; planning the
//! next motion from there (the pure planner of `plan`, placed in the corner by `blend`),
//! and sampling the robot at any time through all of them (`joints_at`, `tcp_at`,
//! `tool_at`, `axis_rate_bounds`).

use std::sync::Arc;

use vworks_model::RobotModel;
use vworks_model::math::Iso;

use super::blend::{self, Fading, Planned};
use super::corner::{self, CornerMemo};
use super::path::{PATH_MEMO, PathMemo};
use super::plan::{self, Capped, Longer, MotionOperands, PlanError, PlanFrom, Slowed, Trajectory};
use crate::MAX_AXES;
use crate::bytecode::SrcPos;
use crate::motion::NS;

/// One robot's motions and what it holds.
#[derive(Debug)]
pub(super) struct Arm {
    model: Arc<RobotModel>,
    /// Joints when not moving (at the VM's time, or at the start of the current motion).
    rest: [f64; MAX_AXES],
    /// The current motion (its start time is its `start`).
    current: Option<Planned>,
    /// The motion planned by `next_event`, started by `perform`.
    pending: Option<Planned>,
    /// The rest of a zoned motion after its `motion_end`, while the robot finishes it.
    fading: Option<Fading>,
    /// The TCP in the tool link's frame: the workcell's tool, then the last motion's
    /// `tool`.
    tool: Iso,
    /// Cartesian paths already sampled.
    memo: PathMemo,
    /// Corners already timed as one path.
    corners: CornerMemo,
}

/// What planning a motion found that the program should be told.
#[derive(Clone, Copy, Debug, Default)]
pub(super) struct PlanNotes {
    /// The motion lasts longer than its `duration` asked.
    pub(super) longer: Option<Longer>,
    /// It was slowed to keep an axis within its speed limit.
    pub(super) slowed: Option<Slowed>,
    /// Its programmed TCP speed or acceleration was above the model's.
    pub(super) capped: Option<Capped>,
    /// It cannot start inside the zone of the motion at this statement: the robot stops at
    /// that point (at this time) first.
    pub(super) corner_failure: Option<(i64, SrcPos)>,
}

impl Arm {
    /// The robot at rest at `start_joints` (missing axes at 0) with TCP `tool`.
    pub(super) fn new(model: Arc<RobotModel>, start_joints: &[f64], tool: Iso) -> Arm {
        let mut rest = [0.0; MAX_AXES];
        for (r, q) in rest.iter_mut().zip(start_joints) {
            *r = *q;
        }
        Arm {
            model,
            rest,
            current: None,
            pending: None,
            fading: None,
            tool,
            memo: PathMemo::reserved(PATH_MEMO),
            corners: CornerMemo::growing(corner::CORNER_MEMO),
        }
    }

    /// The robot model.
    pub(super) fn model(&self) -> &RobotModel {
        &self.model
    }

    /// The previous motion's rest, while it goes on at `t`.
    fn fading_at(&self, t: i64) -> Option<&Fading> {
        self.fading.as_ref().filter(|f| t < f.end())
    }

    /// While the robot finishes a zoned motion after its `motion_end` (the next motion,
    /// if any, superposed on it): the time it reaches that point and the point's TCP
    /// position.
    pub(super) fn zoned_point(&self) -> Option<(i64, [f64; 3])> {
        self.fading.as_ref().map(|f| (f.end(), f.corner_pose.t))
    }

    /// The joints at time `t` (inside or after the current motion, through a corner).
    pub(super) fn joints_at(&self, t: i64) -> [f64; MAX_AXES] {
        let model = &*self.model;
        let Some(f) = self.fading_at(t) else {
            return match &self.current {
                Some(m) => m
                    .traj
                    .joints_at(model, (t - m.start) as f64 / NS)
                    .unwrap_or(self.rest),
                None => self.rest,
            };
        };
        match &self.current {
            Some(m) => blend::blend_joints(model, f, &m.traj, m.start, t).unwrap_or(self.rest),
            None => f.motion.traj.joints_at(model, f.dt(t)).unwrap_or(self.rest),
        }
    }

    /// The TCP pose at time `t`.
    pub(super) fn tcp_at(&self, t: i64) -> Iso {
        let model = &*self.model;
        match (self.fading_at(t), &self.current) {
            (None, Some(m)) if m.traj.is_cartesian() => {
                m.traj.pose_at(model, &self.tool, (t - m.start) as f64 / NS)
            }
            (Some(f), Some(m))
                if f.motion.traj.is_cartesian() && m.traj.is_cartesian() && t > m.start =>
            {
                blend::blend_pose(model, f, &m.traj, m.start, t)
            }
            _ => {
                let q = self.joints_at(t);
                model.tcp(&q[..model.dof()], &self.tool_at(t))
            }
        }
    }

    /// The TCP in the tool link's frame at `t`: the tool of the motion the robot is in
    /// (a tool change never blends: the next motion starts at the point), else the last
    /// motion's (or the workcell's, before any).
    pub(super) fn tool_at(&self, t: i64) -> Iso {
        match (self.fading_at(t), &self.current) {
            (Some(f), _) => f.motion.tool,
            (None, Some(m)) if t >= m.start => m.tool,
            (None, Some(m)) => self.fading.as_ref().map_or(m.tool, |f| f.motion.tool),
            (None, None) => self.tool,
        }
    }

    /// Per axis, a bound on its speed during the current motion (see
    /// `Vm::axis_rate_bounds`). Through a corner, the two motions' bounds add.
    pub(super) fn axis_rate_bounds(&self) -> [f64; MAX_AXES] {
        let mut out = match &self.current {
            Some(m) => m.traj.rates(),
            None => [0.0; MAX_AXES],
        };
        if let Some(f) = &self.fading {
            for (o, r) in out.iter_mut().zip(f.motion.traj.rates()) {
                *o += r;
            }
        }
        out
    }

    /// True while a motion is in progress at `t`: the current one (which ends at
    /// `moving_until`, while the VM is in it), or the rest of a zoned one.
    pub(super) fn moving_at(&self, t: i64, moving_until: Option<i64>) -> bool {
        moving_until.is_some_and(|end| t < end)
            && self.current.as_ref().is_some_and(|m| t > m.start)
            || self
                .fading
                .as_ref()
                .is_some_and(|f| t > f.motion.start && t < f.end())
    }

    /// The current motion's zone radius at its `motion_end` (a zoned one's) and the
    /// radius programmed.
    pub(super) fn current_zone(&self) -> (Option<f64>, Option<f64>) {
        (
            self.current.as_ref().map(|m| m.zone).filter(|z| *z > 0.0),
            self.current.as_ref().and_then(|m| m.programmed),
        )
    }

    /// When the motion planned by [`Arm::plan`] starts, if one is.
    pub(super) fn pending_start(&self) -> Option<i64> {
        self.pending.as_ref().map(|p| p.start)
    }

    /// Plans the motion of `ops` at `time` from where the robot is (from the corner of a
    /// zoned motion still finishing: see `blend`): its trajectory, when it starts (at
    /// once, or later within that corner), and where its own zone begins. It becomes the
    /// pending motion, started by [`Arm::start_pending`].
    pub(super) fn plan(
        &mut self,
        ops: &MotionOperands,
        time: i64,
        default_zone: Option<f64>,
        default_speed: f64,
    ) -> Result<(&Planned, PlanNotes), PlanError> {
        let programmed = match ops.zone.or(default_zone) {
            Some(z) if z.is_nan() || z < 0.0 => return Err(PlanError::Zone(z)),
            Some(z) if z > 0.0 => Some(z),
            _ => None,
        };
        // RAPID's rule: an orientation zone smaller than the zone is the zone.
        let ori_zone = match ops.ori_zone {
            Some((rho, alpha)) if rho.is_nan() || rho < 0.0 || alpha.is_nan() || alpha < 0.0 => {
                return Err(PlanError::OriZone(rho, alpha));
            }
            Some((rho, alpha)) => programmed.filter(|r| rho > *r).map(|_| (rho, alpha)),
            None => None,
        };
        if let Some(tool) = ops.tool {
            self.tool = tool;
        }
        // (A motion with another tool than the zoned one starts at the point with its own
        // TCP there: it does not blend.)
        let tcp = match (&self.fading, ops.is_cartesian()) {
            (_, false) => Iso::IDENTITY,
            (Some(f), true) if f.motion.tool == self.tool => f.corner_pose,
            (Some(f), true) => self.model.tcp(&f.corner[..self.model.dof()], &self.tool),
            (None, true) => self.tcp_at(time),
        };
        let from = PlanFrom {
            joints: self.rest,
            tcp,
            tool: self.tool,
            time,
            default_speed,
            zone: programmed,
        };
        let plan::Plan {
            mut traj,
            duration_ns: mut point_ns,
            longer,
            slowed,
            capped,
            mut look_ahead,
        } = plan::plan(&self.model, &from, ops, &mut self.memo)?;
        let mut notes = PlanNotes {
            longer,
            slowed,
            capped,
            corner_failure: None,
        };
        let model = &*self.model;
        // Inside a zoned motion's corner: when this one can start, the radius it blends
        // within, and when the robot would reach that corner's point. **Choice:** a motion
        // with another tool than the zoned one does not blend: it starts at the point.
        let tool = self.tool;
        let fading = self.fading.as_mut().filter(|f| time < f.end());
        let tool_changed = fading.as_ref().is_some_and(|f| f.motion.tool != tool);
        // (when it starts, the radius, when the first motion is over, its statement, and
        // whether it stops at its point: a corner failure)
        let corner = fading.map(|f| {
            if tool_changed {
                return (f.end(), 0.0, f.end(), f.pos, false);
            }
            // Two lines fly by with ramps and look-ahead where they can (where that cannot
            // beat stopping and superposing them would break their TCP acceleration, they
            // are timed as one path, or stop).
            // (A tool turning over an orientation zone wider than the curve: the corner
            // timed as one path turns it so; corner ramps would turn it within the curve.)
            let turns = corner::turn_radius(f, &traj, 0.0)
                .is_some_and(|rho| rho > f.motion.zone * (1.0 + corner::TURN_WIDER));
            let ramps = blend::corner_ramps(model, time, f, &traj);
            let stops = matches!(ramps, Some(blend::RampCorner::Stops));
            let flies = match ramps {
                Some(blend::RampCorner::Flies(c)) => Some(c),
                _ => None,
            };
            let with_ramps = |f: &mut Fading, c: &blend::Corner, traj: &mut Trajectory| {
                let (first, next) = blend::with_corner(f, traj, c);
                *f = first;
                *traj = next;
                let point_ns = (traj.path_duration() * NS).ceil() as i64;
                ((c.start, c.radius, f.end(), f.pos, false), point_ns)
            };
            if let Some(c) = flies.as_ref().filter(|_| !turns) {
                let (out, ns) = with_ramps(f, c, &mut traj);
                point_ns = ns;
                return out;
            }
            // Else the next takes the robot over now, through a corner timed with the rest of
            // the first as one path, where it can.
            let corners = &mut self.corners;
            // (Never slower than stopping at the point and starting again.)
            let stop_end = f.end() + point_ns;
            // (Where two lines fly with ramps, a timed corner only to turn the tool over its
            // orientation zone: else the ramps, as without one.)
            if let Some((start, taken)) = corner::take_over(
                model,
                &tool,
                (time, stop_end, flies.is_none()),
                (f, &traj, programmed),
                corners,
            ) {
                traj = taken.traj;
                point_ns = taken.point_ns;
                look_ahead = taken.look_ahead;
                return (start, taken.radius, start, f.pos, false);
            }
            // (With ramps after all where no timing turned the tool over its zone.)
            if let Some(c) = &flies {
                let (out, ns) = with_ramps(f, c, &mut traj);
                point_ns = ns;
                return out;
            }
            if stops {
                return (f.end(), 0.0, f.end(), f.pos, true);
            }
            // Else it is superposed on the first as it was planned.
            let (ts, radius) = blend::blend_start(model, &tool, time, f, &traj, point_ns);
            (ts, radius, f.end(), f.pos, ts >= f.end())
        });
        if let Some((_, _, point, at, true)) = corner {
            notes.corner_failure = Some((point, at));
            // It starts from rest at the point, planned as after a `fine` point there (from
            // the TCP of the point's joints, not the programmed pose: the two differ by
            // rounding, and a path timed within its axes' limits would by a little more).
            if ops.is_cartesian() {
                let from = PlanFrom {
                    tcp: model.tcp(&self.rest[..model.dof()], &tool),
                    ..from
                };
                let again = plan::plan(model, &from, ops, &mut self.memo)?;
                traj = again.traj;
                point_ns = again.duration_ns;
                look_ahead = again.look_ahead;
                notes.longer = again.longer;
                notes.slowed = again.slowed;
                notes.capped = again.capped;
            }
        }
        let (start, blend) = match corner {
            Some((ts, ..)) if tool_changed => (ts, None),
            Some((ts, r, ..)) => (ts, Some(r)),
            None => (time, None),
        };
        let (mut end_ns, zone, entry_ns) = match programmed {
            // A TCP that does not move (a turntable's, on its axis) enters no zone.
            Some(r) => match blend::zone_entry(
                model,
                &self.tool,
                &self.rest,
                &traj,
                point_ns,
                (r, ori_zone),
            ) {
                (_, z, _) if z <= 1e-9 => (point_ns, 0.0, point_ns),
                entry => entry,
            },
            None => (point_ns, 0.0, point_ns),
        };
        // A path timed within its axes' limits looks ahead from where it can still stop
        // before its zone.
        if let Some(t) = look_ahead
            && zone > 0.0
        {
            end_ns = end_ns.min(((t * NS).floor() as i64).clamp(0, point_ns));
        }
        // The next corner begins after this one has ended.
        if let Some((_, _, point, ..)) = corner {
            end_ns = end_ns.max((point - start).min(point_ns));
        }
        let planned = self.pending.insert(Planned {
            traj,
            start,
            end_ns,
            point_ns,
            entry_ns,
            zone: if end_ns < point_ns { zone } else { 0.0 },
            programmed,
            ori_zone,
            blend,
            tool: self.tool,
        });
        Ok((planned, notes))
    }

    /// The pending motion starts: it becomes the current one.
    pub(super) fn start_pending(&mut self) {
        self.current = self.pending.take();
        // A motion that takes the robot over through a timed corner: the rest of the
        // zoned motion is now its own.
        if let (Some(m), Some(f)) = (&self.current, &mut self.fading)
            && matches!(
                m.traj,
                Trajectory::Cartesian {
                    corner: Some(_),
                    ..
                }
            )
            && m.start < f.end()
        {
            f.motion.point_ns = m.start - f.motion.start;
        }
    }

    /// The current motion's `motion_end` (of the statement at `pos`): the robot rests at
    /// its target — or, for a zoned one, goes on toward its point (it fades).
    pub(super) fn end_current(&mut self, pos: SrcPos) {
        let Some(motion) = self.current.take() else {
            return;
        };
        // Exactly the target, not the profile's last float.
        self.rest = motion.traj.end_joints();
        if motion.zone > 0.0 && motion.end_ns < motion.point_ns {
            let n = self.model.dof();
            let corner_pose = match &motion.traj {
                Trajectory::Cartesian { to, .. } => *to,
                _ => self.model.tcp(&self.rest[..n], &motion.tool),
            };
            self.fading = Some(Fading {
                motion,
                corner: self.rest,
                corner_pose,
                pos,
            });
        }
    }

    /// The robot stops where it is at `t` (`stop` in a handler): whatever motion it was
    /// in is abandoned, and the one planned never starts.
    pub(super) fn halt_at(&mut self, t: i64) {
        if self.current.is_some() || self.fading.is_some() {
            self.rest = self.joints_at(t);
            self.current = None;
            self.fading = None;
        }
        self.pending = None;
    }

    /// The rest of a zoned motion is over by `t`: it goes.
    pub(super) fn forget_faded(&mut self, t: i64) {
        if self.fading.as_ref().is_some_and(|f| t >= f.end()) {
            self.fading = None;
        }
    }

    /// The rest of a zoned motion the robot is still in at `t`: when it reaches the point
    /// and the statement of that motion.
    pub(super) fn zoned_point_ahead(&self, t: i64) -> Option<(i64, SrcPos)> {
        self.fading_at(t).map(|f| (f.end(), f.pos))
    }
}
