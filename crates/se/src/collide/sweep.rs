//! The sweep between boundaries ([`Collider::sweep`]): conservative advancement with
//! per-body speed bounds, so that no contact between two boundaries is stepped over.

use super::*;

/// Buffers a sweep reuses (no allocation per boundary once sized).
#[derive(Default)]
pub(super) struct SweepScratch {
    /// Per robot and joint: how far the joint can move in the interval.
    pub(super) disp: Vec<Vec<f64>>,
    /// Per robot: whether it moves in the interval.
    pub(super) moving: Vec<bool>,
    /// Per robot: its joints at the end of the last sweep, and when that was.
    pub(super) q_to: Vec<[f64; vworks_vm::MAX_AXES]>,
    pub(super) q_at: Option<i64>,
    /// Per part: the robot holding it as of the last sweep, and its reach from that
    /// robot's joints.
    pub(super) held_by: Vec<Option<(usize, Iso)>>,
    pub(super) held_reach: Vec<Vec<(usize, f64)>>,
    /// Per body: its displacement bound in the interval.
    pub(super) bound: Vec<f64>,
    /// Per robot: link frames (and the time they are for), and per body its pose at the
    /// interval's start.
    pub(super) frames: Vec<Vec<Iso>>,
    pub(super) frames_at: Vec<i64>,
    /// Whether `frames` holds this sweep's frames (else they are still the last check's).
    pub(super) frames_ready: bool,
    pub(super) start: Vec<Pose>,
    /// The broadphase: per body its box grown by its bound, and the overlapping pairs.
    pub(super) reach_box: Vec<Aabb>,
    pub(super) broadphase: SweepAndPrune,
    pub(super) pairs: Vec<(usize, usize)>,
}

impl Collider {
    /// Sweeps the time `[from, to)`, in which no event changes any motion: for every pair
    /// of bodies not touching at `from` of which at least one moves, finds by conservative
    /// advancement the first time they touch, if they do. Pairs found are added to the
    /// touching set, so the next boundary check reports when they part. Returns the
    /// contacts found, in time order.
    pub fn sweep<R: RobotPoses>(
        &mut self,
        cell: &Cell,
        vms: &[R],
        from: i64,
        to: i64,
    ) -> Vec<Contact> {
        let h = (to - from) as f64 / 1e9;
        if h <= 0.0 {
            return Vec::new();
        }
        let mut sw = std::mem::take(&mut self.sweep_scratch);
        let found = self.sweep_with(cell, vms, from, to, h, &mut sw);
        self.sweep_scratch = sw;
        found
    }

    pub(super) fn sweep_with<R: RobotPoses>(
        &mut self,
        cell: &Cell,
        vms: &[R],
        from: i64,
        to: i64,
        h: f64,
        sw: &mut SweepScratch,
    ) -> Vec<Contact> {
        let n = cell.robots.len();
        sw.disp.resize_with(n, Vec::new);
        sw.moving.resize(n, false);
        sw.q_to.resize(n, [0.0; vworks_vm::MAX_AXES]);
        // Per robot: does it move, and how far can each of its joints turn or slide. The
        // joints at `from` are those of the previous sweep's end when it ended there.
        let mut any = false;
        for (r, (robot, vm)) in cell.robots.iter().zip(vms).enumerate() {
            let q0 = match sw.q_at {
                Some(t) if t == from => sw.q_to[r],
                _ => vm.joints_at(from),
            };
            let q1 = vm.joints_at(to);
            sw.q_to[r] = q1;
            let moves = q0 != q1 || vm.moving_at(from) || vm.moving_at(to);
            sw.moving[r] = moves;
            let d = &mut sw.disp[r];
            d.clear();
            d.resize(robot.model.joints.len(), 0.0);
            if moves {
                any = true;
                // The motion's own axis speeds (a motion that ended in the interval has
                // none left: its axes moved by their endpoint difference at most).
                let rates = vm.axis_rate_bounds();
                for (i, &j) in robot.model.axes.iter().enumerate() {
                    let limit = SPEED_MARGIN * rates[i].min(robot.model.joints[j].max_velocity) * h;
                    d[j] = (q1[i] - q0[i]).abs().max(limit);
                }
            }
        }
        sw.q_at = Some(to);
        if !any {
            return Vec::new();
        }
        // A held part moves with its robot's tool link: its reach from each joint
        // (recomputed only when what is held changes).
        sw.held_reach.resize_with(self.world.held.len(), Vec::new);
        for (p, held) in self.world.held.iter().enumerate() {
            let holder = *held;
            if sw.held_by.get(p) == Some(&holder) {
                continue;
            }
            if sw.held_by.len() <= p {
                sw.held_by.resize(p + 1, None);
            }
            sw.held_by[p] = holder;
            sw.held_reach[p] = match held {
                Some((r, offset)) => {
                    let model = &cell.robots[*r].model;
                    let part = self.bodies.iter().find(|b| b.owner == Owner::Part(p));
                    let extent = offset.t.iter().map(|x| x * x).sum::<f64>().sqrt()
                        + part.map_or(0.0, |b| b.radius + b.local.translation.length());
                    reach_of(model, model.tool_link, extent)
                }
                None => Vec::new(),
            };
        }
        // Each body's displacement bound over the interval (m).
        sw.bound.clear();
        for b in &self.bodies {
            let bound = match self.owner_reach(b, &sw.held_reach) {
                Some((robot, reach)) => reach.iter().map(|(j, arm)| sw.disp[robot][*j] * arm).sum(),
                None => 0.0,
            };
            sw.bound.push(bound);
        }
        // Poses at `from`: the last check's when it was at `from` (the usual case, from
        // one boundary to the next; its frames are copied only if a pair needs frames at
        // another time), else its frames with the moving robots' recomputed.
        sw.frames_at.clear();
        sw.frames_at.resize(n, from);
        if self.checked_at == Some(from) {
            sw.start.clone_from(&self.poses);
            sw.frames_ready = false;
        } else {
            sw.frames.clone_from(&self.world.frames);
            sw.frames_ready = true;
            for r in 0..n {
                // Moving now, or moved since the last check's frames (boundaries skipped
                // before the collider's horizon leave them behind a robot that has
                // stopped since).
                if sw.moving[r] || vms[r].joints_at(from) != self.world.joints[r] {
                    self.robot_frame_at(cell, vms, r, from, &mut sw.frames[r]);
                }
            }
            sw.start.clear();
            for i in 0..self.bodies.len() {
                sw.start.push(self.body_pose(cell, i, &sw.frames));
            }
        }
        let mut found = Vec::new();
        // Broadphase: each body's bounding box grown by how far it can move, swept along
        // x; only overlapping pairs go further.
        sw.reach_box.clear();
        for (i, b) in self.bodies.iter().enumerate() {
            sw.reach_box
                .push(b.bounding_box(&sw.start[i]).loosened(sw.bound[i]));
        }
        sw.broadphase.overlapping(&sw.reach_box, &mut sw.pairs);
        // (Pairs are advanced independently; the contacts found are sorted below.)
        let pairs = std::mem::take(&mut sw.pairs);
        for &(i, j) in &pairs {
            {
                if sw.bound[i] + sw.bound[j] <= 0.0
                    || self.never((i, j))
                    || (self.adaptive && to <= self.promises.get(i, j))
                {
                    continue;
                }
                let (a, b) = (&self.bodies[i], &self.bodies[j]);
                let centres = (sw.start[i].translation - sw.start[j].translation).length();
                let gap = centres - a.radius - b.radius;
                if gap > sw.bound[i] + sw.bound[j]
                    || self.touching.contains(&(i, j))
                    || self.exempt.contains(&(i, j))
                    || self.held_by((i, j), cell)
                {
                    continue;
                }
                let reach = self.pair_bound(i, j, &sw.disp, &sw.held_reach);
                if gap > reach {
                    continue; // too far apart to meet in this interval
                }
                if let Some(c) = self.advance(cell, vms, (i, j), (from, to), reach / h, sw) {
                    found.push(((i, j), c));
                }
            }
        }
        sw.pairs = pairs;
        found.sort_by_key(|(pair, c)| (c.time_ns, *pair));
        for (pair, _) in &found {
            self.touching.insert(*pair);
        }
        found.into_iter().map(|(_, c)| c).collect()
    }

    /// The robot moving body `b` and its reach from each of that robot's joints, if any.
    pub(super) fn owner_reach<'a>(
        &'a self,
        b: &'a BodyRef,
        held_reach: &'a [Vec<(usize, f64)>],
    ) -> Option<(usize, &'a [(usize, f64)])> {
        match b.owner {
            Owner::Link { robot, .. } => Some((robot, &b.reach)),
            Owner::Part(p) => match (self.world.held[p], held_reach.get(p)) {
                (Some((r, _)), Some(reach)) => Some((r, reach.as_slice())),
                _ => None,
            },
            Owner::Device => None,
        }
    }

    /// How far (or how fast) bodies `i` and `j` can move towards each other, given per
    /// robot and joint how far (how fast) each joint can move: Σ per moving joint × the
    /// body's reach from it. Bodies of one robot move together under the joints they
    /// share: only the joints on one's path and not the other's count.
    pub(super) fn pair_bound(
        &self,
        i: usize,
        j: usize,
        per_joint: &[Vec<f64>],
        held_reach: &[Vec<(usize, f64)>],
    ) -> f64 {
        let (a, b) = (&self.bodies[i], &self.bodies[j]);
        let sum = |r: usize, reach: &[(usize, f64)], take: usize, skip: &[(usize, f64)]| {
            reach
                .iter()
                .take(take)
                .filter(|(jt, _)| !skip.iter().any(|(k, _)| k == jt))
                .map(|(jt, arm)| per_joint[r][*jt] * arm)
                .sum::<f64>()
        };
        match (
            self.owner_reach(a, held_reach),
            self.owner_reach(b, held_reach),
        ) {
            (Some((ra, reach_a)), Some((rb, reach_b))) if ra == rb => {
                if matches!((a.owner, b.owner), (Owner::Link { .. }, Owner::Link { .. })) {
                    // The unshared joints are a prefix of each reach.
                    let (na, nb) = pairs::unshared(reach_a, reach_b);
                    sum(ra, reach_a, na, &[]) + sum(ra, reach_b, nb, &[])
                } else {
                    // A held part and a link of the robot holding it.
                    sum(ra, reach_a, usize::MAX, reach_b) + sum(ra, reach_b, usize::MAX, reach_a)
                }
            }
            (ea, eb) => {
                let whole = |e: Option<(usize, &[(usize, f64)])>| {
                    e.map_or(0.0, |(r, reach)| sum(r, reach, usize::MAX, &[]))
                };
                whole(ea) + whole(eb)
            }
        }
    }

    /// Conservative advancement of one pair over `[from, to)` with closing speed bound
    /// `speed` (m/s): the first time at which they intersect, if any (at most
    /// [`SWEEP_MIN_STEP_NS`] after the true first contact, up to rounding).
    pub(super) fn advance<R: RobotPoses>(
        &mut self,
        cell: &Cell,
        vms: &[R],
        (i, j): (usize, usize),
        (from, to): (i64, i64),
        speed: f64,
        sw: &mut SweepScratch,
    ) -> Option<Contact> {
        if speed <= 0.0 {
            return None;
        }
        // Query the pair in name order, so that rounding — and so the time found — does
        // not depend on the order of the bodies (that is, of the robots in the workcell).
        let (first, second) = (i, j);
        let swapped = self.bodies[i].name > self.bodies[j].name;
        let (i, j) = if swapped { (j, i) } else { (i, j) };
        let robot_of = |c: &Collider, body: usize| match c.bodies[body].owner {
            Owner::Link { robot, .. } => Some(robot),
            Owner::Part(p) => c.world.held[p].map(|(r, _)| r),
            Owner::Device => None,
        };
        let (ri, rj) = (robot_of(self, i), robot_of(self, j));
        let trust = trust(self.bodies[i].shape.as_ref(), self.bodies[j].shape.as_ref());
        let mut now = from;
        for _ in 0..100_000 {
            let (pa, pb) = if now == from {
                (sw.start[i], sw.start[j])
            } else {
                if !sw.frames_ready {
                    sw.frames.clone_from(&self.world.frames); // the frames at `from`
                    sw.frames_ready = true;
                }
                for r in [ri, rj].into_iter().flatten() {
                    if sw.moving[r] && sw.frames_at[r] != now {
                        self.robot_frame_at(cell, vms, r, now, &mut sw.frames[r]);
                        sw.frames_at[r] = now;
                    }
                }
                (
                    self.body_pose(cell, i, &sw.frames),
                    self.body_pose(cell, j, &sw.frames),
                )
            };
            let (a, b) = (&self.bodies[i], &self.bodies[j]);
            self.queries += 1;
            // How far they can close in the rest of the interval: farther apart than that,
            // they cannot touch in it (the bounded query stops early).
            let rest = speed * (to - now) as f64 / 1e9;
            // Reported in body order, as the boundary check reports: the point is on the
            // first body.
            // The part of a gap relied on is `trust` of it: farther apart than `rest /
            // trust`, they cannot touch in the rest of the interval.
            let (d, p1, p2) = gap(&pa, a.shape.as_ref(), &pb, b.shape.as_ref(), rest / trust)?;
            let safe = d * trust;
            if d <= 0.0 {
                let p = if swapped { p2 } else { p1 };
                return Some(Contact {
                    time_ns: now,
                    a: self.bodies[first].name.clone(),
                    b: self.bodies[second].name.clone(),
                    depth: depth_of(d),
                    point: p,
                    motions: Vec::new(),
                });
            }
            // Safe for `safe / speed` seconds; at least the minimum step.
            let step = (safe / speed * 1e9).min(1e18) as i64;
            now = now.saturating_add(step.max(SWEEP_MIN_STEP_NS));
            if now >= to {
                return None;
            }
        }
        None
    }
}
