//! A planned motion ([`Trajectory`]): a joint-space profile, or a TCP path with its
//! profile or time-optimal timing (and the corner it took over through, if any), and what
//! it is at any time: the joints, the TCP, the path's fraction and speed.

use vworks_model::RobotModel;
use vworks_model::math::Iso;
use vworks_model::timing::{SEGMENTS, Timing};

use super::corner::TimedCorner;
use super::path::SEEDS;
use crate::MAX_AXES;
use crate::motion::{Path, Profile, cartesian_at};
use crate::ramps::Ramps;

/// A planned motion.
// One per VM (its current motion), never in a collection: the variants' sizes do not
// matter, and boxing would add an allocation per motion.
#[allow(clippy::large_enum_variant)]
#[derive(Clone, Debug)]
pub(super) enum Trajectory {
    /// Joint-space: each axis from `from` by `delta` along a shared normalised profile.
    Joint {
        from: [f64; MAX_AXES],
        delta: [f64; MAX_AXES],
        profile: Profile,
    },
    /// Joint-space with a jerk limit on some axis: each axis from `from` by `delta` along
    /// its own profile over `|delta|` (trapezoid or S-curve), all lasting the same time
    /// (time synchronisation, as Ruckig's).
    JointSynced {
        from: [f64; MAX_AXES],
        delta: [f64; MAX_AXES],
        profiles: [Profile; MAX_AXES],
    },
    /// Cartesian: the TCP along `path`, orientation by slerp; joints by IK. The path
    /// fraction follows `profile`, or `timing` where the profile would take an axis past
    /// a limit (the time-optimal timing within them) or, with jerk limits, where the
    /// jerk-limited timing is faster than the profile.
    Cartesian {
        path: Path,
        from: Iso,
        to: Iso,
        profile: Profile,
        timing: Option<Timing>,
        /// The profile it follows instead of `profile` once it flies by a corner with
        /// look-ahead (`blend`): corner ramps at its start, its end or both.
        ramps: Option<Ramps>,
        /// It was given a `duration`: a corner never changes how long it takes.
        timed: bool,
        end_joints: [f64; MAX_AXES],
        /// The analytic IK branch the motion stays on (spherical-wrist arms).
        branch: Option<u8>,
        /// Per axis, the largest speed found at the samples the motion was checked at
        /// (rad/s or m/s).
        rates: [f64; MAX_AXES],
        /// Per axis, a bound on its speed at the profile's top speed anywhere on the path.
        cruise_rates: [f64; MAX_AXES],
        /// The joints at every 16th knot of the sampled path: a point's IK starts from the
        /// nearest (the path executed is the path checked).
        seeds: [[f64; MAX_AXES]; SEEDS],
        /// The TCP (in the tool link's frame) the path is for.
        tool: Iso,
        /// It took the robot over from the zone of the motion before, through a corner
        /// timed with it as one path (`corner`): the path's fraction then covers the rest
        /// of that motion's path, the corner and this one's.
        corner: Option<TimedCorner>,
        /// The largest speed and acceleration of its own path's fraction (1/s, 1/s²:
        /// the TCP's, or the orientation's speed, over the path), and the largest speed
        /// of its orientation's fraction (1/s: its orientation speed over the angle it
        /// turns the tool by; infinite if it does not).
        path_limits: [f64; 3],
    },
}

impl Trajectory {
    /// The joints at the end: exactly the target (not the profile's last float).
    pub(super) fn end_joints(&self) -> [f64; MAX_AXES] {
        match self {
            Trajectory::Joint { from, delta, .. } | Trajectory::JointSynced { from, delta, .. } => {
                let mut q = *from;
                for (qi, d) in q.iter_mut().zip(delta) {
                    *qi += d;
                }
                q
            }
            Trajectory::Cartesian { end_joints, .. } => *end_joints,
        }
    }

    /// True for `move_l`/`move_c` (the TCP follows a path).
    pub(super) fn is_cartesian(&self) -> bool {
        matches!(self, Trajectory::Cartesian { .. })
    }

    /// Per axis, a bound on its speed (rad/s or m/s): exact for joint motions; for a
    /// Cartesian one the largest speed at the samples its axis speeds were checked at.
    pub(super) fn rates(&self) -> [f64; MAX_AXES] {
        let mut out = [0.0; MAX_AXES];
        match self {
            Trajectory::Joint { delta, profile, .. } if profile.dist > 0.0 => {
                for (o, d) in out.iter_mut().zip(delta) {
                    *o = d.abs() * profile.v / profile.dist;
                }
            }
            Trajectory::JointSynced { profiles, .. } => {
                for (o, p) in out.iter_mut().zip(profiles) {
                    *o = p.v;
                }
            }
            Trajectory::Cartesian { rates, .. } => out = *rates,
            _ => {}
        }
        out
    }

    /// Axis `i`'s profile and the factor from the profile's distance to the axis's
    /// (signed) motion, for joint motions: the axis moves `k·p.at(t)`.
    pub(super) fn axis_profile(&self, i: usize) -> Option<(&Profile, f64)> {
        match self {
            Trajectory::Joint { delta, profile, .. } => {
                let k = if profile.dist > 0.0 {
                    delta[i] / profile.dist
                } else {
                    0.0
                };
                Some((profile, k))
            }
            Trajectory::JointSynced {
                delta, profiles, ..
            } => Some((&profiles[i], if delta[i] < 0.0 { -1.0 } else { 1.0 })),
            Trajectory::Cartesian { .. } => None,
        }
    }

    /// The instants (s from its start) where its profile changes phase, where an axis's
    /// speed may turn at a kink: every axis's profile's of a joint motion, the path's
    /// profile's of a Cartesian one moved by it. Not yet those of a timed path (its path
    /// acceleration steps at every knot) nor of corner ramps: a corner with one of them
    /// is checked at its samples only.
    pub(super) fn phase_ends(&self, mut visit: impl FnMut(f64)) {
        let mut each = |p: &Profile| p.breakpoints().into_iter().for_each(&mut visit);
        match self {
            Trajectory::Joint { profile, .. } => each(profile),
            Trajectory::JointSynced { profiles, .. } => profiles.iter().for_each(each),
            Trajectory::Cartesian {
                profile,
                timing: None,
                ramps: None,
                ..
            } => each(profile),
            Trajectory::Cartesian { .. } => {}
        }
    }

    /// Every time (s from its start) the motion's path jerk may jump: its profiles' phase
    /// ends ([`Trajectory::phase_ends`]) and a smooth timing's knots (its jerk `c_k·ṡ`
    /// changes with each step's `c_k`).
    pub(super) fn jerk_breaks(&self, mut visit: impl FnMut(f64)) {
        self.phase_ends(&mut visit);
        if let Trajectory::Cartesian {
            timing: Some(t), ..
        } = self
            && t.is_smooth()
        {
            (1..SEGMENTS).for_each(|k| visit(t.time_at_knot(k)));
        }
    }
}

impl Trajectory {
    /// The joints `dt` seconds into the trajectory (its start before, its end after);
    /// `None` if the inverse kinematics of a Cartesian motion's pose fails there.
    pub(super) fn joints_at(&self, model: &RobotModel, dt: f64) -> Option<[f64; MAX_AXES]> {
        match self {
            Trajectory::Joint {
                from,
                delta,
                profile,
            } => {
                let s = if profile.dist > 0.0 {
                    profile.at(dt) / profile.dist
                } else {
                    1.0
                };
                let mut q = *from;
                for (qi, d) in q.iter_mut().zip(delta) {
                    *qi += d * s;
                }
                Some(q)
            }
            Trajectory::JointSynced {
                from,
                delta,
                profiles,
            } => {
                let mut q = *from;
                for ((qi, d), p) in q.iter_mut().zip(delta).zip(profiles) {
                    *qi += p.at(dt).copysign(*d);
                }
                Some(q)
            }
            Trajectory::Cartesian { end_joints, .. } => {
                if dt >= self.path_duration() {
                    return Some(*end_joints);
                }
                let s = self.fraction_at(dt);
                self.ik_on(model, &self.pose_at(model, &Iso::IDENTITY, dt), s)
            }
        }
    }

    /// How long a Cartesian trajectory takes (s; 0 for a joint one).
    pub(super) fn path_duration(&self) -> f64 {
        match self {
            Trajectory::Cartesian {
                timing: Some(t), ..
            } => t.duration(),
            Trajectory::Cartesian { ramps: Some(r), .. } => r.duration(),
            Trajectory::Cartesian { profile, .. } => profile.t_total,
            _ => 0.0,
        }
    }

    /// The fraction of a Cartesian trajectory's path done `dt` seconds in (1 for a joint
    /// one).
    pub(super) fn fraction_at(&self, dt: f64) -> f64 {
        match self {
            Trajectory::Cartesian {
                timing: Some(t), ..
            } => t.at(dt).s,
            Trajectory::Cartesian { ramps: Some(r), .. } => r.at(dt).min(1.0),
            Trajectory::Cartesian { profile, .. } if profile.dist > 0.0 => {
                (profile.at(dt) / profile.dist).min(1.0)
            }
            _ => 1.0,
        }
    }

    /// The path speed `ds/dt` (fractions of the path per second) of a Cartesian trajectory
    /// `dt` seconds in (0 for a joint one).
    pub(super) fn path_speed_at(&self, dt: f64) -> f64 {
        match self {
            Trajectory::Cartesian {
                timing: Some(t), ..
            } => t.at(dt).speed,
            Trajectory::Cartesian { ramps: Some(r), .. } => r.speed_at(dt),
            Trajectory::Cartesian { profile, .. } if profile.dist > 0.0 => {
                profile.speed_at(dt) / profile.dist
            }
            _ => 0.0,
        }
    }

    /// The largest path speed of a Cartesian trajectory (fractions of the path per
    /// second; 0 for a joint one).
    pub(super) fn top_path_speed(&self) -> f64 {
        match self {
            Trajectory::Cartesian {
                timing: Some(t), ..
            } => t.top_speed(),
            Trajectory::Cartesian { ramps: Some(r), .. } => r.top,
            Trajectory::Cartesian { profile, .. } if profile.dist > 0.0 => {
                profile.speed_at(0.5 * profile.t_total) / profile.dist
            }
            _ => 0.0,
        }
    }

    /// The fraction of a Cartesian motion's own path (from its point, not through the
    /// corner it took over: [`TimedCorner`]) done `dt` seconds in.
    pub(super) fn own_fraction_at(&self, dt: f64) -> f64 {
        match self {
            Trajectory::Cartesian {
                corner: Some(c), ..
            } => c.own_fraction(self.fraction_at(dt)),
            _ => self.fraction_at(dt),
        }
    }

    /// The speed of a Cartesian motion's own path fraction `dt` seconds in (1/s).
    pub(super) fn own_speed_at(&self, dt: f64) -> f64 {
        match self {
            Trajectory::Cartesian {
                corner: Some(c), ..
            } => c.own_rate(self.fraction_at(dt)) * self.path_speed_at(dt),
            _ => self.path_speed_at(dt),
        }
    }

    /// The path acceleration `d²s/dt²` (fractions of the path per second²) of a Cartesian
    /// trajectory `dt` seconds in (0 for a joint one, and on corner ramps: timed corners,
    /// which read it, never take over from them).
    pub(super) fn path_accel_at(&self, dt: f64) -> f64 {
        match self {
            Trajectory::Cartesian { ramps: Some(_), .. } => 0.0,
            Trajectory::Cartesian {
                timing: Some(t), ..
            } => t.at(dt).accel,
            Trajectory::Cartesian { profile, .. } if profile.dist > 0.0 => {
                profile.accel_at(dt) / profile.dist
            }
            _ => 0.0,
        }
    }

    /// The acceleration of a Cartesian motion's own path fraction `dt` seconds in (1/s²),
    /// as [`Trajectory::own_speed_at`]: past a corner it took over its own fraction is
    /// linear in the path's.
    pub(super) fn own_accel_at(&self, dt: f64) -> f64 {
        match self {
            Trajectory::Cartesian {
                corner: Some(c), ..
            } => c.own_rate(self.fraction_at(dt)) * self.path_accel_at(dt),
            _ => self.path_accel_at(dt),
        }
    }

    /// The largest speed of a Cartesian motion's own path fraction (1/s): through a corner
    /// it took over, at most the largest over the timing's steps of the path's top speed
    /// on the step times its own fraction's larger rate at the step's ends (that rate is
    /// constant or rises monotonically between knots: `u²` and `2u³ − u⁴` alike).
    pub(super) fn top_own_speed(&self) -> f64 {
        match self {
            Trajectory::Cartesian {
                corner: Some(c),
                timing: Some(t),
                ..
            } => (0..SEGMENTS)
                .map(|k| c.own_rate(t.knot(k)).max(c.own_rate(t.knot(k + 1))) * t.step_top_speed(k))
                .fold(0.0, f64::max),
            _ => self.top_path_speed(),
        }
    }

    /// The time (s) a Cartesian trajectory reaches fraction `f` of its own path.
    pub(super) fn time_at_own_fraction(&self, f: f64) -> f64 {
        match self {
            Trajectory::Cartesian {
                corner: Some(c), ..
            } => self.time_at_fraction(c.s_of_own(f)),
            _ => self.time_at_fraction(f),
        }
    }

    /// The time (s) a Cartesian trajectory reaches path fraction `s`.
    pub(super) fn time_at_fraction(&self, s: f64) -> f64 {
        match self {
            Trajectory::Cartesian {
                timing: Some(t), ..
            } => t.time_at(s),
            Trajectory::Cartesian { ramps: Some(r), .. } => r.time_at(s),
            Trajectory::Cartesian { profile, .. } => profile.time_at(s * profile.dist),
            _ => 0.0,
        }
    }

    /// The joints of a TCP pose at path fraction `s` of a Cartesian trajectory: on its
    /// analytic branch, each from the sampled path's joints nearest `s` (the seed).
    pub(super) fn ik_on(&self, model: &RobotModel, tcp: &Iso, s: f64) -> Option<[f64; MAX_AXES]> {
        let Trajectory::Cartesian {
            branch,
            seeds,
            tool,
            ..
        } = self
        else {
            return None;
        };
        let nearest = (s.clamp(0.0, 1.0) * (SEEDS - 1) as f64).round() as usize;
        let seed = &seeds[nearest.min(SEEDS - 1)];
        let flange = tcp.mul(&tool.inverse());
        let mut q = [0.0; MAX_AXES];
        let n = model.dof();
        let solved = match branch {
            Some(b) => model.ik_in_branch(&flange, &seed[..n], *b, &mut q[..n]),
            None => model.ik(&flange, &seed[..n], &mut q[..n]),
        };
        solved.is_ok().then_some(q)
    }

    /// The TCP pose `dt` seconds into the trajectory; for a joint motion with TCP `tool`
    /// (a Cartesian one has its own).
    pub(super) fn pose_at(&self, model: &RobotModel, tool: &Iso, dt: f64) -> Iso {
        match self {
            Trajectory::Cartesian {
                path,
                from,
                to,
                corner: Some(c),
                ..
            } => c.pose(path, from, to, self.fraction_at(dt)),
            Trajectory::Cartesian { path, from, to, .. } => {
                cartesian_at(path, from, to, self.fraction_at(dt))
            }
            _ => {
                // (A joint trajectory always has joints.)
                let q = self
                    .joints_at(model, dt)
                    .unwrap_or_else(|| self.end_joints());
                model.tcp(&q[..model.dof()], tool)
            }
        }
    }
}
