//! Motion planning and sampling: a motion's operands, inverse kinematics of its target,
//! its trajectory and exact duration (`plan_path`), and the joints and TCP at any time
//! inside a trajectory (`eval_joints`, `eval_pose`, the speed bounds the collider's
//! sweep uses).

use super::*;

/// Points a Cartesian path is checked at (reachability and axis speeds).
pub(super) const PATH_SAMPLES: usize = 64;
/// Sampled paths a VM remembers (the oldest goes first).
pub(super) const PATH_MEMO: usize = 32;
/// A sampled path's key: the bits of the start joints, the start and goal poses (rotation,
/// translation), the via point (NaN for a line) and the path speed.
pub(super) const PATH_KEY: usize = MAX_AXES + 12 + 12 + 3 + 1 + 12;

/// What sampling a Cartesian path found: the slowest ratio of an axis's speed limit to its
/// speed (1 if none is exceeded) and that axis, each axis's largest speed, the joints at
/// the end.
#[derive(Clone, Copy, Debug)]
pub(super) struct PathSamples {
    pub(super) worst: f64,
    pub(super) worst_axis: usize,
    pub(super) rates: [f64; MAX_AXES],
    pub(super) end: [f64; MAX_AXES],
}

/// Up to 12 slots of a pose (6) or joints (12) operand, without allocating.
#[derive(Clone, Copy)]
pub(super) struct Slots {
    v: [u64; MAX_AXES],
    len: usize,
}

impl Slots {
    pub(super) fn read(stack: &[u64], from: usize, len: usize) -> Slots {
        let mut v = [0u64; MAX_AXES];
        v[..len].copy_from_slice(&stack[from..from + len]);
        Slots { v, len }
    }
    pub(super) fn get(&self) -> &[u64] {
        &self.v[..self.len]
    }
}

/// The operands of a motion instruction.
pub(super) struct MotionOperands {
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
    /// Cartesian: the TCP along `path`, orientation by slerp; joints by IK.
    Cartesian {
        path: Path,
        from: Iso,
        to: Iso,
        profile: Profile,
        end_joints: [f64; MAX_AXES],
        /// The analytic IK branch the motion stays on (spherical-wrist arms).
        branch: Option<u8>,
        /// Per axis, the largest speed found at the samples the motion was checked at
        /// (rad/s or m/s).
        rates: [f64; MAX_AXES],
        /// The joints it starts from (the seed of numeric IK).
        seed: [f64; MAX_AXES],
        /// The TCP (in the tool link's frame) the path is for.
        tool: Iso,
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
}

impl Vm {
    /// The joints `dt` seconds into `traj` (its start before, its end after); `None` if
    /// the inverse kinematics of a Cartesian motion's pose fails there.
    pub(super) fn eval_joints(&self, traj: &Trajectory, dt: f64) -> Option<[f64; MAX_AXES]> {
        match traj {
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
            Trajectory::Cartesian {
                profile,
                end_joints,
                ..
            } => {
                if dt >= profile.t_total {
                    return Some(*end_joints);
                }
                self.ik_on(traj, &self.eval_pose(traj, dt))
            }
        }
    }

    /// The joints of a TCP pose on the configuration of Cartesian motion `traj`: on its
    /// analytic branch, or seeded from its start joints (numeric IK).
    pub(super) fn ik_on(&self, traj: &Trajectory, tcp: &Iso) -> Option<[f64; MAX_AXES]> {
        let Trajectory::Cartesian {
            branch, seed, tool, ..
        } = traj
        else {
            return None;
        };
        let flange = tcp.mul(&tool.inverse());
        let mut q = [0.0; MAX_AXES];
        let n = self.model.dof();
        let solved = match branch {
            Some(b) => self
                .model
                .ik_in_branch(&flange, &seed[..n], *b, &mut q[..n]),
            None => self.model.ik(&flange, &seed[..n], &mut q[..n]),
        };
        solved.is_ok().then_some(q)
    }

    /// The TCP pose `dt` seconds into `traj`.
    pub(super) fn eval_pose(&self, traj: &Trajectory, dt: f64) -> Iso {
        match traj {
            Trajectory::Cartesian {
                path,
                from,
                to,
                profile,
                ..
            } => {
                let s = if profile.dist > 0.0 {
                    (profile.at(dt) / profile.dist).min(1.0)
                } else {
                    1.0
                };
                cartesian_at(path, from, to, s)
            }
            _ => {
                let q = self.eval_joints(traj, dt).unwrap_or(self.rest);
                self.model.tcp(&q[..self.model.dof()], &self.tool)
            }
        }
    }

    /// The time a jerk-limited axis takes to ramp its acceleration up (`a/j`), the
    /// longest over the axes with a jerk limit; 0 (no ramp: trapezoids) if none has one.
    /// Cartesian motions give their path the same ramp time.
    fn jerk_ramp_time(&self) -> f64 {
        (0..self.model.dof())
            .filter_map(|i| {
                let j = self.model.axis(i);
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
        &self,
        from: [f64; MAX_AXES],
        goal: [f64; MAX_AXES],
        ratio: f64,
        aratio: f64,
    ) -> (Trajectory, i64) {
        let n = self.model.dof();
        let mut delta = [0.0; MAX_AXES];
        let mut profiles = [Profile::new(0.0, 1.0, 1.0); MAX_AXES];
        let mut t_total = 0.0f64;
        for i in 0..n {
            delta[i] = goal[i] - from[i];
            let j = self.model.axis(i);
            profiles[i] = Profile::with_jerk(
                delta[i],
                ratio * j.max_velocity,
                aratio * j.max_accel,
                j.max_jerk.unwrap_or(f64::INFINITY),
            );
            t_total = t_total.max(profiles[i].t_total);
        }
        for (i, p) in profiles.iter_mut().enumerate().take(n) {
            *p = p.lasting(t_total, aratio * self.model.axis(i).max_accel);
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

    /// The operands of a motion instruction, read (not popped) from the stack.
    pub(super) fn motion_operands(&self, ins: Instr) -> MotionOperands {
        let f = match ins {
            Instr::MoveJ(f) | Instr::MoveL(f) | Instr::MoveC(f) => f,
            _ => MoveFlags(0),
        };
        let s = &self.main.stack;
        let mut k = 0;
        let duration = f.has(MoveFlags::DURATION).then(|| {
            k += 1;
            f64::from_bits(s[s.len() - k])
        });
        let tool = f.has(MoveFlags::TOOL).then(|| {
            k += 6;
            to_iso(&s[s.len() - k..s.len() - k + 6])
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
            target,
            via,
            speed,
            accel,
            zone,
            tool,
            orient,
            duration,
            tcp_speed: f.has(MoveFlags::TCP_SPEED),
            width: k,
        }
    }

    /// A pose operand (6 slots) or a joints operand (12 slots) as a TCP pose.
    pub(super) fn operand_pose(&self, slots: &[u64]) -> Iso {
        if slots.len() == 6 {
            return to_iso(slots);
        }
        let q: Vec<f64> = slots
            .iter()
            .take(self.model.dof())
            .map(|x| f64::from_bits(*x))
            .collect();
        self.model.tcp(&q, &self.tool)
    }

    /// Samples a Cartesian path at [`PATH_SAMPLES`] points from joints `from`: every point
    /// reachable (or the error, naming where), each axis's largest speed at path speed `vs`
    /// (1/s), and the slowest ratio of an axis's limit to its speed, if one is exceeded.
    fn sample_path(
        &self,
        path: &Path,
        start: &Iso,
        goal: &Iso,
        from: &[f64; MAX_AXES],
        vs: f64,
    ) -> Result<PathSamples, String> {
        let n = self.model.dof();
        let mut prev = *from;
        let mut worst = 1.0f64;
        let mut worst_axis = 0;
        let mut rates = [0.0f64; MAX_AXES];
        for k in 1..=PATH_SAMPLES {
            let s = k as f64 / PATH_SAMPLES as f64;
            let pose = cartesian_at(path, start, goal, s);
            let q = self
                .ik_tcp(&pose, &prev)
                .map_err(|e| format!("{e} (at {:.0}% of the path)", s * 100.0))?;
            for i in 0..n {
                // ds/dt at most vs: axis speed ≈ |Δq/Δs|·vs.
                let rate = (q[i] - prev[i]).abs() * PATH_SAMPLES as f64 * vs;
                rates[i] = rates[i].max(rate);
                let j = self.model.axis(i);
                // (A relative 1e-9 over the limit is rounding, not a faster axis.)
                if rate > j.max_velocity * (1.0 + 1e-9) && j.max_velocity / rate < worst {
                    worst = j.max_velocity / rate;
                    worst_axis = i;
                }
            }
            prev = q;
        }
        Ok(PathSamples {
            worst,
            worst_axis,
            rates,
            end: prev,
        })
    }

    pub(super) fn ik_tcp(&self, tcp: &Iso, near: &[f64]) -> Result<[f64; MAX_AXES], String> {
        let n = self.model.dof();
        let mut q = [0.0; MAX_AXES];
        let flange = tcp.mul(&self.tool.inverse());
        self.model
            .ik(&flange, &near[..n], &mut q[..n])
            // In the TCP's terms, as the program wrote the target.
            .map_err(|e: IkError| format!("unreachable pose: {}", e.at_position(tcp.t)))?;
        Ok(q)
    }

    /// A joint motion from `from` to `goal` at speed and acceleration ratios `ratio` and
    /// `aratio`, and its duration: one normalised profile s(t) ∈ [0, 1] within every axis's
    /// limits, or the axes' own time-synchronised profiles where one has a jerk limit.
    fn plan_joint(
        &self,
        from: [f64; MAX_AXES],
        goal: [f64; MAX_AXES],
        ratio: f64,
        aratio: f64,
    ) -> (Trajectory, i64) {
        let n = self.model.dof();
        if (0..n).any(|i| goal[i] != from[i] && self.model.axis(i).max_jerk.is_some()) {
            return self.plan_synced(from, goal, ratio, aratio);
        }
        let (mut vs, mut as_) = (f64::INFINITY, f64::INFINITY);
        let mut delta = [0.0; MAX_AXES];
        for i in 0..n {
            delta[i] = goal[i] - from[i];
            let d = delta[i].abs();
            if d > 0.0 {
                let j = self.model.axis(i);
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

    /// A warning that a motion asked to take `want` ns takes `lasts` ns, the fastest it
    /// can (`how`).
    fn warn_if_longer(&mut self, lasts: i64, want: i64, how: &str) {
        if lasts > want {
            let pos = self.m.pos_of(self.main.pc);
            self.warnings.push(Warning {
                time: self.time,
                pos,
                kind: WarningKind::Duration,
                message: format!(
                    "the motion takes {}, longer than the {} asked: it cannot be faster {how}",
                    fmt_quantity(lasts as f64 / NS, Dim::TIME),
                    fmt_quantity(want as f64 / NS, Dim::TIME)
                ),
            });
        }
    }

    /// Plans the path and profile of `ins` from the robot's state now (from the corner
    /// of a zoned motion still finishing: see `blend`); returns it and its duration.
    pub(super) fn plan_path(&mut self, ins: Instr) -> Result<(Trajectory, i64), String> {
        let MotionOperands {
            target: target_slots,
            via,
            speed,
            accel,
            tcp_speed,
            orient,
            duration,
            ..
        } = self.motion_operands(ins);
        let duration_ns = match duration {
            None => None,
            Some(t) if t > 0.0 => Some(span_ns(t, self.time, "the motion's duration")?),
            Some(t) => {
                return Err(format!(
                    "the duration of a motion must be greater than zero (got {})",
                    fmt_quantity(t, Dim::TIME)
                ));
            }
        };
        let from = self.rest;
        let target = target_slots.get();
        let n = self.model.dof();
        if let Instr::MoveJ(_) = ins {
            let goal = if target.len() == MAX_AXES {
                let mut q = [0.0; MAX_AXES];
                for (i, v) in q.iter_mut().enumerate().take(n) {
                    *v = f64::from_bits(target[i]);
                }
                q
            } else {
                self.ik_tcp(&to_iso(target), &from)?
            };
            for (i, g) in goal.iter().enumerate().take(n) {
                let j = self.model.axis(i);
                if *g < j.lower - 1e-9 || *g > j.upper + 1e-9 {
                    return Err(format!(
                        "joint limit exceeded: axis {} `{}` would go to {}, outside its range {} to {}; choose a target within the range{}",
                        i + 1,
                        j.name,
                        j.display(*g),
                        j.display(j.lower),
                        j.display(j.upper),
                        if target.len() == MAX_AXES {
                            ""
                        } else {
                            " (this pose needs it: try another wrist configuration or approach)"
                        }
                    ));
                }
            }
            let aratio = accel.unwrap_or(1.0);
            let ratio = match speed {
                // A TCP speed: the axes' ratio at which the motion lasts about the TCP's
                // straight-line distance over that speed (docs/language.md, Motion).
                Some(v) if tcp_speed => {
                    if v.is_nan() || v <= 0.0 {
                        return Err(format!(
                            "the speed must be greater than zero (got {})",
                            fmt_quantity(v, Dim::SPEED)
                        ));
                    }
                    let d = vworks_model::math::norm(vworks_model::math::sub(
                        self.model.tcp(&goal[..n], &self.tool).t,
                        self.model.tcp(&from[..n], &self.tool).t,
                    ));
                    let full = self.plan_joint(from, goal, 1.0, aratio).1 as f64 / NS;
                    if d > 0.0 && full > 0.0 {
                        (v * full / d).clamp(1e-6, 1.0)
                    } else {
                        1.0
                    }
                }
                _ => match duration_ns {
                    // The slowest ratio at which the motion takes at most the duration.
                    Some(t) => {
                        let lasts = |r: f64| self.plan_joint(from, goal, r, aratio).1;
                        let ratio = slowest_within(t, 1e-9, 1.0, lasts);
                        self.warn_if_longer(lasts(ratio), t, "with its slowest axis at full speed");
                        ratio
                    }
                    None => speed.unwrap_or(1.0),
                },
            };
            if !(ratio > 0.0 && ratio <= 1.0 && aratio > 0.0 && aratio <= 1.0) {
                return Err(format!(
                    "speed and acceleration of move_j must be more than 0% and at most 100% (got {}%, {}%)",
                    ratio * 100.0,
                    aratio * 100.0
                ));
            }
            return Ok(self.plan_joint(from, goal, ratio, aratio));
        }
        // Cartesian: line or arc, orientation by slerp.
        let start = match &self.fading {
            Some(f) => f.corner_pose,
            None => self.tcp_at(self.time),
        };
        let goal = self.operand_pose(target);
        let via_t = via.as_ref().map(|v| self.operand_pose(v.get()).t);
        let path = match via_t {
            None => Path::Line {
                from: start.t,
                to: goal.t,
            },
            Some(via_t) => {
                Path::arc(start.t, via_t, goal.t).ok_or_else(|| "move_c: the via point lies on the line from start to target; give a point off that line".to_string())?
            }
        };
        let mut v = speed.unwrap_or(self.cfg.default_speed);
        if v.is_nan() || v <= 0.0 {
            return Err(format!(
                "the speed must be greater than zero (got {})",
                fmt_quantity(v, Dim::SPEED)
            ));
        }
        if let Some(a) = accel
            && (a.is_nan() || a <= 0.0)
        {
            // (A param, `--set` or a sweep can make it so at run time; 0 would make the
            // motion take no time at all.)
            return Err(format!(
                "the acceleration must be greater than zero (got {})",
                fmt_quantity(a, Dim::ACCEL)
            ));
        }
        let mut a = accel.unwrap_or(v / vworks_model::model::DEFAULT_ACCEL_TIME);
        let len = path.length();
        let angle = vworks_model::math::norm(vworks_model::math::rotation_vector(
            &vworks_model::math::mat_mul(&vworks_model::math::transpose(&start.r), &goal.r),
        ));
        // Orientation moves at most `orient` (180°/s without it), with the same ramp time.
        let mut w = orient.unwrap_or(std::f64::consts::PI);
        if w.is_nan() || w <= 0.0 {
            return Err(format!(
                "the orientation speed must be greater than zero (got {})",
                fmt_quantity(w, Dim::ANGSPEED)
            ));
        }
        // With jerk limits, the path's jerk ramps as long as the slowest axis's does.
        let ramp = self.jerk_ramp_time();
        // The profile's limits along the path (per unit of its fraction) at TCP speed `v`
        // and acceleration `a`, orientation speed `w`.
        let limits = |v: f64, a: f64, w: f64| {
            let wa = w / vworks_model::model::DEFAULT_ACCEL_TIME;
            let (mut vs, mut as_, mut js) = (f64::INFINITY, f64::INFINITY, f64::INFINITY);
            // Below 0.1 µm and 0.1 µrad a move is a rounding error, not a motion.
            if len > 1e-7 {
                vs = vs.min(v / len);
                as_ = as_.min(a / len);
                js = js.min(a / ramp / len);
            }
            if angle > 1e-7 {
                vs = vs.min(w / angle);
                as_ = as_.min(wa / angle);
                js = js.min(wa / ramp / angle);
            }
            (vs, as_, js)
        };
        if let Some(t) = duration_ns
            && (len > 1e-7 || angle > 1e-7)
        {
            // The slowest fraction of the fastest TCP and orientation speeds (the TCP's
            // acceleration with them, unless given; `orient`, if given, stays the
            // orientation's bound) at which the motion takes at most the duration.
            let at = |k: f64| {
                let v = k * MAX_TCP_SPEED;
                let a = accel.unwrap_or(v / vworks_model::model::DEFAULT_ACCEL_TIME);
                (v, a, orient.unwrap_or(k * MAX_ORIENT_SPEED))
            };
            let lasts = |k: f64| {
                let (v, a, w) = at(k);
                let (vs, as_, js) = limits(v, a, w);
                Profile::with_jerk(1.0, vs, as_, js).duration_ns()
            };
            let k = slowest_within(t, 1e-12, 1.0, lasts);
            (v, a, w) = at(k);
            self.warn_if_longer(
                lasts(k),
                t,
                "at 7 m/s and 500°/s, the fastest TCP and orientation speeds",
            );
        }
        let (mut vs, mut as_, mut js) = limits(v, a, w);
        if !vs.is_finite() {
            let traj = Trajectory::Cartesian {
                path,
                from: start,
                to: goal,
                profile: Profile::new(0.0, 1.0, 1.0),
                end_joints: from,
                branch: None,
                rates: [0.0; MAX_AXES],
                seed: from,
                tool: self.tool,
            };
            return Ok((traj, 0));
        }
        // Joints along the path: reachable, and within every axis's speed at this speed.
        // The same path from the same joints at the same speed samples the same: a program
        // repeating its moves samples each once (`path_memo`, exact: keyed by the bits).
        let mut key = [0u64; PATH_KEY];
        let via_or_none = via_t.unwrap_or([f64::NAN; 3]);
        for (k, x) in from
            .iter()
            .chain(start.r.iter().flatten())
            .chain(&start.t)
            .chain(goal.r.iter().flatten())
            .chain(&goal.t)
            .chain(&via_or_none)
            .chain([&vs])
            .chain(self.tool.r.iter().flatten())
            .chain(&self.tool.t)
            .enumerate()
        {
            key[k] = x.to_bits();
        }
        let sampled = match self.path_memo.iter().find(|(k, _)| *k == key) {
            Some((_, s)) => *s,
            None => {
                let s = self.sample_path(&path, &start, &goal, &from, vs)?;
                if self.path_memo.len() >= PATH_MEMO {
                    self.path_memo.remove(0);
                }
                self.path_memo.push((key, s));
                s
            }
        };
        let PathSamples {
            worst,
            worst_axis,
            mut rates,
            end: prev,
        } = sampled;
        if worst < 1.0 {
            vs *= worst;
            as_ *= worst;
            js *= worst;
            for r in &mut rates {
                *r *= worst;
            }
            let pos = self.m.pos_of(self.main.pc);
            let j = self.model.axis(worst_axis);
            self.warnings.push(Warning {
                time: self.time,
                pos,
                kind: WarningKind::Slowdown,
                message: format!("the motion is slowed to {:.0}% of its speed: axis {} `{}` would exceed its speed limit", worst * 100.0, worst_axis + 1, j.name),
            });
        }
        let profile = Profile::with_jerk(1.0, vs, as_, js);
        let dur = profile.duration_ns();
        let branch = self
            .model
            .ik_branch(&start.mul(&self.tool.inverse()), &from[..n]);
        Ok((
            Trajectory::Cartesian {
                path,
                from: start,
                to: goal,
                profile,
                end_joints: prev,
                branch,
                rates,
                seed: from,
                tool: self.tool,
            },
            dur,
        ))
    }
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
