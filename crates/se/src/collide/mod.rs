//! Collision checks at cycle boundaries, with parry3d.
//!
//! Bodies: every collision shape of every robot link (placed by forward kinematics of the
//! robot's joints at the boundary), devices (static), parts (static, or carried by the tool
//! of the robot that gripped them). A sort-and-sweep broadphase over the bodies' AABBs
//! (grown by the clearance) finds the nearby pairs; parry's `contact` with the clearance
//! as prediction distance decides touching (depth) and near misses. Skipped pairs: two
//! static bodies, links of one robot that are jointed or already touch at the robot's zero
//! configuration (touching by design, like MoveIt's "default" pairs), a held part and the
//! link holding it, and the pairs the workcell allows. Boundaries where nothing moved and
//! nothing was gripped or released make no query.
//!
//! Between boundaries ([`Collider::sweep`]): a link can pass through a thin body between
//! two boundaries. Every stretch of time in which no event changes any motion is swept by
//! conservative advancement: each body's speed is bounded from its robot's joint speeds
//! and its reach from each joint (precomputed), so two bodies at distance `d` cannot
//! touch for `d / (v_a + v_b)` seconds. Stepping by that (at least [`SWEEP_MIN_STEP_NS`])
//! until they intersect, no contact is stepped over and the first contact is reported at
//! most one minimum step late. Capsules and balls are measured exactly here (`gap`);
//! other shapes by parry's f64 build (f32 GJK was mm off, see `gap`).

use std::collections::BTreeSet;

use parry3d::bounding_volume::{Aabb, BoundingVolume};
use parry3d::math::Pose;
use parry3d::shape::SharedShape;
use vworks_model::math::Iso;

use vworks_cell::Cell;
use vworks_log::place::Contact;

use crate::world::World;

mod broadphase;
mod horizon;
mod narrow;
mod pairs;
mod robots;
mod sweep;

pub use robots::RobotPoses;

use broadphase::SweepAndPrune;
use horizon::Lookahead;
use narrow::*;
use pairs::{BodyKeys, PairFilter, Promises};
use sweep::SweepScratch;

/// A contact's depth from the signed gap between two bodies (m): how far they overlap, 0 for
/// bodies just touching (never `-0`, which would print as `-0.0 mm`).
pub(crate) fn depth_of(gap: f64) -> f64 {
    if gap < 0.0 { -gap } else { 0.0 }
}

/// What a boundary check found.
#[derive(Clone, Debug, PartialEq)]
pub enum CollisionEvent {
    /// A pair started touching.
    Start(Contact),
    /// A pair stopped touching.
    End(String, String),
    /// A pair came within the clearance (not touching): names and distance.
    NearMiss(String, String, f64),
}

#[derive(Clone, Copy, Debug, PartialEq)]
enum Owner {
    Link { robot: usize, link: usize },
    Device,
    Part(usize),
}

#[derive(Clone)]
struct BodyRef {
    owner: Owner,
    name: String,
    shape: SharedShape,
    /// Shape pose in the owner's frame (link frame, or body frame).
    local: Pose,
    /// Bounding sphere radius about the shape's local origin (for the broadphase).
    radius: f64,
    /// A device's pose in the cell (devices never move).
    fixed: Pose,
    /// Its link and parent link, for the pair filter ([`PairFilter::never`]).
    keys: BodyKeys,
    /// For a link's body: per moving joint upstream (robot joint index), how far any point
    /// of the body can be from that joint's axis (m; 1 for a prismatic joint, whose
    /// displacement moves every point by as much). Speed bound = Σ joint speed × reach.
    reach: Vec<(usize, f64)>,
}

impl BodyRef {
    /// The body's box at `pose`: exact where parry computes it in closed form (capsules,
    /// balls, boxes), else the bounding sphere's (cylinders, hulls: their exact boxes need
    /// support-map searches).
    fn bounding_box(&self, pose: &Pose) -> Aabb {
        let shape = self.shape.as_ref();
        if let Some(c) = shape.as_capsule() {
            // The two end centres, grown by the radius (parry's own goes through a
            // transformed copy and its support function: 3x the time).
            let (a, b) = (
                pose.transform_point(c.segment.a),
                pose.transform_point(c.segment.b),
            );
            let r = parry3d::math::Vector::splat(c.radius);
            Aabb::new(a.min(b) - r, a.max(b) + r)
        } else if shape.as_ball().is_some() || shape.as_cuboid().is_some() {
            shape.compute_aabb(pose)
        } else {
            let c = pose.translation;
            let r = parry3d::math::Vector::splat(self.radius);
            Aabb::new(c - r, c + r)
        }
    }
}

/// The smallest step of conservative advancement (ns): near contact, where the safe step
/// `d / v` shrinks towards 0, the sweep steps by this. A contact is reported at most this
/// late; a body would have to be thinner than its speed × 1 µs (3 µm at 3 m/s) to be
/// passed through within one step.
pub const SWEEP_MIN_STEP_NS: i64 = 1_000;

/// Axis speeds may exceed the largest sampled one by this factor between the 64 samples at
/// which the VM checks a Cartesian motion's axis speeds; the sweep's speed bounds include it.
const SPEED_MARGIN: f64 = 1.25;

/// How far ahead a boundary check proves that no two bodies come within the clearance
/// ([`Collider::horizon`]): 0.1 s, 25 cycles of 4 ms. Longer proves more cycles at once
/// but grows the boxes of the look-ahead broadphase (more pairs to bound).
pub const HORIZON_NS: i64 = 100_000_000;

/// How far ahead one boundary query of a pair proves it apart (1 s): the query looks as far
/// as the pair could close in that time.
const PROMISE_NS: i64 = 1_000_000_000;

/// Per moving joint on the path from the root to `link`: (joint index, the farthest any
/// point within `extent` of the link's origin can be from the joint's axis).
fn reach_of(
    model: &vworks_model::model::RobotModel,
    link: usize,
    extent: f64,
) -> Vec<(usize, f64)> {
    use vworks_model::model::JointKind;
    let mut out = Vec::new();
    // Walking from the link towards the root (each link's parent joint), the distance from
    // a joint to the body grows by each joint origin's offset below it.
    let mut below = extent;
    let mut at = link;
    let mut steps = 0;
    while let Some((j, joint)) = model.links.get(at).and_then(|l| {
        let j = l.parent_joint?;
        Some((j, model.joints.get(j)?))
    }) {
        match joint.kind {
            JointKind::Revolute | JointKind::Continuous => out.push((j, below)),
            JointKind::Prismatic => out.push((j, 1.0)),
            JointKind::Fixed => {}
        }
        let t = joint.origin.t;
        below += (t[0] * t[0] + t[1] * t[1] + t[2] * t[2]).sqrt();
        if joint.kind == JointKind::Prismatic {
            // The joint's own travel adds to the lever arm of the joints above it.
            below += (joint.upper - joint.lower).abs().min(1e3);
        }
        at = joint.parent;
        steps += 1;
        if steps > model.joints.len() {
            break; // a cycle: the loader rejects those; never loop
        }
    }
    out
}

fn bounding_radius(shape: &SharedShape) -> f64 {
    let a = shape.compute_local_aabb();
    a.mins.abs().max(a.maxs.abs()).length()
}

/// The collision world of a cell.
pub struct Collider {
    bodies: Vec<BodyRef>,
    poses: Vec<Pose>,
    aabbs: Vec<Aabb>,
    /// The boundary check's broadphase and the pairs it keeps (reused).
    broadphase: SweepAndPrune,
    pairs: Vec<(usize, usize)>,
    /// Pairs never checked.
    filter: PairFilter,
    touching: BTreeSet<(usize, usize)>,
    near: BTreeSet<(usize, usize)>,
    /// Pairs touching when a part was gripped or released (a part resting on a table, a
    /// gripper closed on its part): not a collision until they are farther apart than
    /// the clearance, as MoveIt's touch links of an attached object.
    exempt: BTreeSet<(usize, usize)>,
    /// The robots' joints and link frames and the parts' poses, as of the last check.
    world: World,
    dirty: bool,
    /// Narrow-phase queries made so far.
    pub queries: u64,
    sweep_scratch: SweepScratch,
    /// The time `frames` and `poses` are for (the last check's), once there was one.
    checked_at: Option<i64>,
    /// Adaptive checking: per pair, the time before which the current motions cannot
    /// bring it within the clearance, so its query can be skipped. Withdrawn whenever a
    /// motion starts (its robot's pairs) or a part is gripped or released (all).
    promises: Promises,
    /// The horizon and the scratch that proves it (see [`Collider::horizon`]).
    lookahead: Lookahead,
    /// Whether to skip queries by their promises (see [`Collider::set_adaptive`]).
    adaptive: bool,
    /// Each robot's link bodies (the links of every robot come first, robot by robot),
    /// and where they end.
    robot_bodies: Vec<std::ops::Range<usize>>,
    links_end: usize,
}

impl std::fmt::Debug for Collider {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Collider")
            .field("bodies", &self.bodies.len())
            .field("queries", &self.queries)
            .finish()
    }
}

fn matches(name: &str, owner: Owner, cell: &Cell, pattern: &str) -> bool {
    if name == pattern {
        return true;
    }
    match owner {
        Owner::Link { robot, link } => {
            let r = &cell.robots[robot];
            match pattern.split_once('.') {
                None => r.name == pattern,
                Some((rn, ln)) => {
                    rn == r.name && vworks_cell::same_link(&r.model.links[link].name, ln)
                }
            }
        }
        _ => false,
    }
}

impl Collider {
    /// The bodies of `cell`, with the pairs never to check.
    pub fn new(cell: &Cell) -> Collider {
        let mut bodies = Vec::new();
        let mut robot_bodies = Vec::with_capacity(cell.robots.len());
        for (r, robot) in cell.robots.iter().enumerate() {
            let first = bodies.len();
            for (l, link) in robot.model.links.iter().enumerate() {
                for s in &link.shapes {
                    let radius = bounding_radius(&s.shape);
                    let extent = s.local_pose.translation.length() + radius;
                    bodies.push(BodyRef {
                        owner: Owner::Link { robot: r, link: l },
                        name: format!("{}.{}", robot.name, link.name),
                        shape: s.shape.clone(),
                        local: s.local_pose,
                        radius,
                        fixed: Pose::IDENTITY,
                        reach: reach_of(&robot.model, l, extent),
                        keys: BodyKeys::default(),
                    });
                }
            }
            robot_bodies.push(first..bodies.len());
        }
        let links_end = bodies.len();
        for d in &cell.devices {
            bodies.push(BodyRef {
                owner: Owner::Device,
                name: d.name.clone(),
                shape: d.shape.clone(),
                local: d.local.to_pose(),
                radius: bounding_radius(&d.shape),
                fixed: d.pose.to_pose() * d.local.to_pose(),
                reach: Vec::new(),
                keys: BodyKeys::default(),
            });
        }
        for (i, p) in cell.parts.iter().enumerate() {
            bodies.push(BodyRef {
                owner: Owner::Part(i),
                name: p.name.clone(),
                shape: p.shape.clone(),
                local: p.local.to_pose(),
                radius: bounding_radius(&p.shape),
                fixed: Pose::IDENTITY,
                reach: Vec::new(),
                keys: BodyKeys::default(),
            });
        }
        let n = bodies.len();
        let filter = PairFilter::new(cell, &bodies);
        for (b, k) in bodies.iter_mut().zip(filter.keys()) {
            b.keys = *k;
        }
        Collider {
            filter,
            poses: vec![Pose::IDENTITY; n],
            aabbs: vec![Aabb::new_invalid(); n],
            broadphase: SweepAndPrune::default(),
            pairs: Vec::new(),
            touching: BTreeSet::new(),
            near: BTreeSet::new(),
            exempt: BTreeSet::new(),
            world: World::new(cell),
            dirty: true,
            queries: 0,
            sweep_scratch: SweepScratch::default(),
            checked_at: None,
            promises: Promises::new(n),
            lookahead: Lookahead::default(),
            adaptive: true,
            robot_bodies,
            links_end,
            bodies,
        }
    }

    /// With `false`, every pair the broadphase keeps is queried at every boundary (the
    /// exhaustive check adaptive checking is tested against).
    pub fn set_adaptive(&mut self, adaptive: bool) {
        self.adaptive = adaptive;
    }

    /// A motion started, or a part was gripped or released: the speed bounds behind the
    /// skipped queries no longer hold.
    pub fn motions_changed(&mut self) {
        self.promises.withdraw_all();
        self.lookahead.horizon = i64::MIN;
    }

    /// Until when no two bodies can come within the clearance, as the last boundary check
    /// proved it under the motions of that time (`i64::MIN` if it could not, or a motion,
    /// grip or release has changed them since). Before it, a sweep finds no contact and a
    /// boundary check no contact, near miss or parting: the engine skips them (and so the
    /// joints, FK and boxes they need), which is what makes a cell whose robots work near
    /// each other and near shared devices cheap between its close calls.
    ///
    /// The proof, at a check at `t` (adaptive checking on, no pair touching, near,
    /// exempt, and no part held): every body's speed is at most `v_i` (its joints' speed
    /// bounds × their lever arms); the pairs the check's broadphase kept have their
    /// promises (`safe_until`); a pair whose boxes are apart but within the look-ahead's
    /// reach closes at most at `v_i + v_j` from its boxes' distance; a pair farther apart
    /// than that cannot close before the look-ahead (`HORIZON_NS`) ends.
    pub fn horizon(&self) -> i64 {
        self.lookahead.horizon
    }

    /// Robot `r` starts a motion: the promises of the pairs with one of its bodies (its
    /// links, a part it holds) no longer hold; the others' still do (see `Promises`).
    pub fn motion_started(&mut self, r: usize) {
        self.lookahead.horizon = i64::MIN;
        self.promises.begin_withdrawal();
        if let Some(links) = self.robot_bodies.get(r) {
            for i in links.clone() {
                self.promises.withdraw(i);
            }
        }
        for (i, b) in self.bodies.iter().enumerate().skip(self.links_end) {
            if matches!(b.owner, Owner::Part(p) if self.world.held[p].is_some_and(|(h, _)| h == r))
            {
                self.promises.withdraw(i);
            }
        }
    }

    /// How many pair entries the collider holds: the pairs its filter lists, its
    /// promises, and the pairs touching, near or exempt. Linear in the bodies (the
    /// broadphase's neighbours of each), not quadratic (tested).
    pub fn pair_entries(&self) -> usize {
        self.filter.entries()
            + self.promises.entries()
            + self.touching.len()
            + self.near.len()
            + self.exempt.len()
    }

    /// Robot `r`'s tool link in the cell at time `t` (the frames of the last check stay).
    fn tool_world<R: RobotPoses>(cell: &Cell, vm: &R, r: usize, t: i64) -> Iso {
        let robot = &cell.robots[r];
        let q = vm.joints_at(t);
        robot.base.mul(&robot.model.flange(&q[..robot.model.dof()]))
    }

    /// The robot holding part `p`, if one does.
    pub fn holder(&self, p: usize) -> Option<usize> {
        self.world.holder(p)
    }

    /// How far part `p`, which no robot holds, is from robot `r`'s gripper at time `t` (m;
    /// 0 when they touch or overlap): the least distance from the part's bodies to the
    /// robot's TCP (with the tool it moves with) or to a collision body of its tool link.
    /// The TCP counts because a gripper is often not modelled (a tool link without
    /// bodies, the `tool` offset standing for its fingers); the tool link's bodies count
    /// because a modelled gripper closes on the part with them. Allocates nothing.
    pub fn grip_gap<R: RobotPoses>(
        &self,
        p: usize,
        r: usize,
        vms: &[R],
        cell: &Cell,
        t: i64,
    ) -> f64 {
        let (robot, vm) = (&cell.robots[r], &vms[r]);
        let link = Collider::tool_world(cell, vm, r, t);
        let tcp = link.mul(&vm.tool_at(t)).to_pose().translation;
        let (link, part) = (link.to_pose(), self.world.part_pose(p).to_pose());
        let gripper = Owner::Link {
            robot: r,
            link: robot.model.tool_link,
        };
        let mut least = f64::INFINITY;
        for b in self.bodies.iter().filter(|b| b.owner == Owner::Part(p)) {
            let pb = part * b.local;
            least = least.min(b.shape.distance_to_point(&pb, tcp, true));
            for g in self.bodies.iter().filter(|g| g.owner == gripper) {
                let d = distance(&pb, b.shape.as_ref(), &(link * g.local), g.shape.as_ref());
                least = least.min(d);
            }
        }
        least.max(0.0)
    }

    /// Robot `r` grips part `p` at time `t`: from now on the part moves with its tool link.
    /// Pairs of the part touching at that instant are exempt until they separate.
    pub fn grip<R: RobotPoses>(&mut self, p: usize, r: usize, vms: &[R], cell: &Cell, t: i64) {
        let tool = Collider::tool_world(cell, &vms[r], r, t);
        let pose = self.world.part_pose[p];
        self.world.held[p] = Some((r, tool.inverse().mul(&pose)));
        self.dirty = true;
        self.motions_changed();
        self.exempt_touching(p, cell, vms, t);
    }

    /// Part `p` is released at time `t` and stays where it is. Pairs of the part touching
    /// at that instant are exempt until they separate.
    pub fn release<R: RobotPoses>(&mut self, p: usize, vms: &[R], cell: &Cell, t: i64) {
        if let Some((r, offset)) = self.world.held[p] {
            let tool = Collider::tool_world(cell, &vms[r], r, t);
            self.world.part_pose[p] = tool.mul(&offset);
        }
        self.world.held[p] = None;
        self.dirty = true;
        self.motions_changed();
        self.exempt_touching(p, cell, vms, t);
    }

    /// Exempts every checked pair of part `p`'s bodies that touches at time `t`.
    fn exempt_touching<R: RobotPoses>(&mut self, p: usize, cell: &Cell, vms: &[R], t: i64) {
        let mut frames = self.world.frames.clone();
        for (r, f) in frames.iter_mut().enumerate() {
            self.robot_frame_at(cell, vms, r, t, f);
        }
        let n = self.bodies.len();
        for i in 0..n {
            if !matches!(self.bodies[i].owner, Owner::Part(q) if q == p) {
                continue;
            }
            let pi = self.body_pose(cell, i, &frames);
            for j in 0..n {
                let pair = (i.min(j), i.max(j));
                if j == i || self.static_pair(pair) || self.never(pair) || self.held_by(pair, cell)
                {
                    continue;
                }
                let pj = self.body_pose(cell, j, &frames);
                let touching = gap(
                    &pi,
                    self.bodies[i].shape.as_ref(),
                    &pj,
                    self.bodies[j].shape.as_ref(),
                    0.0,
                )
                .is_some_and(|(d, _, _)| d <= 0.0);
                // (A pair already reported as a collision stays one.)
                if touching && !self.touching.contains(&pair) {
                    self.exempt.insert(pair);
                }
            }
        }
    }

    /// The cell's state as of the last [`Collider::check`] (which brings every robot's
    /// frames up to date: robots it skipped have not moved).
    pub fn world(&self) -> &World {
        &self.world
    }

    /// Checks the cell at boundary time `t`, its robots being `vms` (the VMs in a run);
    /// `moving[r]` says whether robot r moves.
    pub fn check<R: RobotPoses>(
        &mut self,
        cell: &Cell,
        vms: &[R],
        t: i64,
        moving: &[bool],
    ) -> Vec<CollisionEvent> {
        // A robot needs new link frames when its joints differ from those its frames were
        // computed for: moving now, or moved since the last check (even a motion that
        // began and ended between two boundaries).
        let mut update = [false; 64];
        let mut any = false;
        let swept = self.sweep_scratch.q_at == Some(t);
        for (r, vm) in vms.iter().enumerate() {
            // Once per robot and boundary (it may be an IK solve): the sweep up to this
            // boundary has them already.
            let q = match self.sweep_scratch.q_to.get(r) {
                Some(q) if swept => *q,
                _ => vm.joints_at(t),
            };
            let changed = moving[r] || q != self.world.joints[r];
            if changed {
                self.world.joints[r] = q;
                // The tool changes only with a motion, so only while the robot moves.
                if let Some(tool) = self.world.tools.get_mut(r) {
                    *tool = vm.tool_at(t);
                }
            }
            any |= changed;
            if r < update.len() {
                update[r] = changed;
            }
        }
        if !self.dirty && !any {
            self.checked_at = Some(t);
            return Vec::new();
        }
        let all = std::mem::replace(&mut self.dirty, false);
        for (r, robot) in cell.robots.iter().enumerate() {
            let u = all || r >= update.len() || update[r];
            if r < update.len() {
                update[r] = u;
            }
            if !u {
                continue;
            }
            let q = &self.world.joints[r][..robot.model.dof()];
            robot
                .model
                .fk_into_from(&robot.base, q, &mut self.world.frames[r]);
        }
        let updated = |r: usize| r >= update.len() || update[r];
        let margin = cell.clearance;
        for (i, b) in self.bodies.iter().enumerate() {
            let owner_pose = match b.owner {
                Owner::Link { robot, link } if updated(robot) => {
                    self.world.frames[robot][link].to_pose()
                }
                Owner::Device if all => cell
                    .devices
                    .iter()
                    .find(|d| d.name == b.name)
                    .map_or(Pose::IDENTITY, |d| d.pose.to_pose()),
                Owner::Part(p) => match self.world.held[p] {
                    Some((r, offset)) if updated(r) || all => self.world.frames[r]
                        [cell.robots[r].model.tool_link]
                        .mul(&offset)
                        .to_pose(),
                    None if all => self.world.part_pose[p].to_pose(),
                    _ => continue,
                },
                _ => continue,
            };
            self.poses[i] = owner_pose * b.local;
            self.aabbs[i] = b.bounding_box(&self.poses[i]).loosened(margin);
        }
        self.checked_at = Some(t);
        // Adaptive checking: each joint's speed bound under the current motions.
        let mut joint_speed = std::mem::take(&mut self.sweep_scratch.disp);
        joint_speed.resize_with(cell.robots.len(), Vec::new);
        for ((robot, vm), js) in cell.robots.iter().zip(vms).zip(joint_speed.iter_mut()) {
            let rates = vm.axis_rate_bounds();
            js.clear();
            js.resize(robot.model.joints.len(), 0.0);
            for (i, &j) in robot.model.axes.iter().enumerate() {
                js[j] = SPEED_MARGIN * rates[i];
            }
        }
        // Sort and sweep along x.
        let aabbs = &self.aabbs;
        let mut pairs = std::mem::take(&mut self.pairs);
        self.broadphase.overlapping(aabbs, &mut pairs);
        let mut touching = BTreeSet::new();
        let mut near: Vec<((usize, usize), f64)> = Vec::new();
        let mut starts = Vec::new();
        for &pair in &pairs {
            {
                if self.never(pair) || self.held_by(pair, cell) {
                    continue;
                }
                if self.static_pair(pair) {
                    continue;
                }
                let (a, b) = (&self.bodies[pair.0], &self.bodies[pair.1]);
                if self.adaptive && t < self.promises.get(pair.0, pair.1) {
                    continue; // provably farther than the clearance until then
                }
                // Held parts' speeds are not bounded here: always queried.
                let v = if self.is_held(a.owner) || self.is_held(b.owner) {
                    f64::INFINITY
                } else {
                    self.pair_bound(pair.0, pair.1, &joint_speed, &[])
                };
                self.queries += 1;
                let (pa, pb) = (&self.poses[pair.0], &self.poses[pair.1]);
                // One bounded query per pair and boundary: with adaptive checking it looks
                // as far as the pair could close in `PROMISE_NS`, so the same query gives
                // the gap behind the promise (at least that far when it finds nothing) —
                // adaptive checking never makes more queries than checking every boundary.
                let within = if self.adaptive && v.is_finite() && v > 0.0 {
                    margin + v * PROMISE_NS as f64 / 1e9
                } else {
                    margin
                };
                let wide = gap(pa, a.shape.as_ref(), pb, b.shape.as_ref(), within);
                let found = wide.filter(|(d, _, _)| *d <= margin);
                if self.adaptive && v.is_finite() {
                    let d = wide.map_or(within, |(d, _, _)| d);
                    let gap = d.max(0.0) * trust(a.shape.as_ref(), b.shape.as_ref());
                    let until = if v <= 0.0 {
                        i64::MAX
                    } else if gap > cell.clearance {
                        t.saturating_add(((gap - cell.clearance) / v * 1e9) as i64)
                    } else {
                        i64::MIN
                    };
                    self.promises.set(pair.0, pair.1, until);
                }
                if self.exempt.contains(&pair) {
                    // Touching since a grip or release: exempt until they separate.
                    if found.is_none_or(|(d, _, _)| d > cell.clearance) {
                        self.exempt.remove(&pair);
                    }
                    continue;
                }
                let Some((dist, point, _)) = found else {
                    continue;
                };
                if dist <= 0.0 {
                    touching.insert(pair);
                    if !self.touching.contains(&pair) {
                        starts.push((
                            pair,
                            Contact {
                                time_ns: t,
                                a: a.name.clone(),
                                b: b.name.clone(),
                                depth: depth_of(dist),
                                point,
                                motions: Vec::new(),
                            },
                        ));
                    }
                } else if dist < cell.clearance {
                    near.push((pair, dist));
                }
            }
        }
        self.pairs = pairs;
        // In body order, whatever order the broadphase found them in.
        starts.sort_by_key(|(pair, _)| *pair);
        let mut events: Vec<CollisionEvent> = starts
            .into_iter()
            .map(|(_, c)| CollisionEvent::Start(c))
            .collect();
        for pair in self.touching.difference(&touching) {
            events.push(CollisionEvent::End(
                self.bodies[pair.0].name.clone(),
                self.bodies[pair.1].name.clone(),
            ));
        }
        let near_now: BTreeSet<(usize, usize)> = near.iter().map(|(p, _)| *p).collect();
        near.sort_by_key(|(p, _)| *p);
        for (pair, d) in &near {
            if !self.near.contains(pair) {
                events.push(CollisionEvent::NearMiss(
                    self.bodies[pair.0].name.clone(),
                    self.bodies[pair.1].name.clone(),
                    *d,
                ));
            }
        }
        self.touching = touching;
        self.near = near_now;
        self.lookahead.horizon = if self.adaptive {
            self.prove_horizon(cell, t, &joint_speed)
        } else {
            i64::MIN
        };
        self.sweep_scratch.disp = joint_speed;
        events
    }

    /// Robot `r`'s link frames in the cell at time `t`, into `out`.
    fn robot_frame_at<R: RobotPoses>(
        &self,
        cell: &Cell,
        vms: &[R],
        r: usize,
        t: i64,
        out: &mut [Iso],
    ) {
        let robot = &cell.robots[r];
        let q = vms[r].joints_at(t);
        robot
            .model
            .fk_into_from(&robot.base, &q[..robot.model.dof()], out);
    }

    /// Body `i`'s pose in the cell, its robot's link frames being `frames`.
    fn body_pose(&self, cell: &Cell, i: usize, frames: &[Vec<Iso>]) -> Pose {
        let b = &self.bodies[i];
        let owner = match b.owner {
            Owner::Link { robot, link } => frames[robot][link],
            Owner::Device => return b.fixed,
            Owner::Part(p) => match self.world.held[p] {
                Some((r, offset)) => frames[r][cell.robots[r].model.tool_link].mul(&offset),
                None => self.world.part_pose[p],
            },
        };
        owner.to_pose() * b.local
    }

    /// The pair `i < j` is never checked (see [`PairFilter`]).
    #[inline(always)]
    fn never(&self, (i, j): (usize, usize)) -> bool {
        self.filter
            .never((i, j), &self.bodies[i].keys, &self.bodies[j].keys)
    }

    /// Two bodies neither of which can move (devices and parts nobody holds): never
    /// checked.
    fn static_pair(&self, (i, j): (usize, usize)) -> bool {
        let moves = |o: Owner| matches!(o, Owner::Link { .. }) || self.is_held(o);
        !moves(self.bodies[i].owner) && !moves(self.bodies[j].owner)
    }

    /// The robot that moves the body named `name`: a link's robot, or the robot holding a
    /// part; `None` for a device or a part lying still. (A scan of the bodies: for
    /// collisions and near misses as they start, not per cycle.)
    pub fn robot_moving(&self, name: &str) -> Option<usize> {
        let body = self.bodies.iter().find(|b| b.name == name)?;
        match body.owner {
            Owner::Link { robot, .. } => Some(robot),
            Owner::Part(p) => self.world.held[p].map(|(r, _)| r),
            Owner::Device => None,
        }
    }

    fn is_held(&self, o: Owner) -> bool {
        matches!(o, Owner::Part(p) if self.world.held[p].is_some())
    }

    /// A held part and the tool link of the robot holding it.
    fn held_by(&self, (i, j): (usize, usize), cell: &Cell) -> bool {
        let (a, b) = (self.bodies[i].owner, self.bodies[j].owner);
        let check = |part: Owner, link: Owner| match (part, link) {
            (Owner::Part(p), Owner::Link { robot, link }) => self.world.held[p]
                .is_some_and(|(r, _)| r == robot && link == cell.robots[r].model.tool_link),
            _ => false,
        };
        check(a, b) || check(b, a)
    }
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]
    use super::*;
    use parry3d::math::Vector;

    /// Bodies just touching have depth 0, never -0 (it printed as `depth -0.0 mm`).
    #[test]
    fn depth_is_the_overlap_and_never_negative_zero() {
        assert_eq!(depth_of(-0.002), 0.002);
        let touching = depth_of(-0.0);
        assert!(touching == 0.0 && touching.is_sign_positive());
        assert!(depth_of(0.0).is_sign_positive());
        assert_eq!(format!("{:.1}", depth_of(-0.0) * 1e3), "0.0");
    }

    /// A small deterministic generator (no test depends on a random seed).
    struct Lcg(u64);
    impl Lcg {
        fn next(&mut self) -> f64 {
            self.0 = self
                .0
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            ((self.0 >> 11) as f64) / ((1u64 << 53) as f64) * 2.0 - 1.0
        }
        fn pose(&mut self) -> Pose {
            let axis = Vector::new(self.next(), self.next(), self.next()).normalize_or_zero();
            let rot = parry3d::math::Rotation::from_axis_angle(
                if axis == Vector::ZERO {
                    Vector::X
                } else {
                    axis
                },
                self.next() * 3.1,
            );
            Pose::from_parts(
                Vector::new(self.next(), self.next(), self.next()) * 0.3,
                rot,
            )
        }
    }

    /// An independent oracle: the distance from a point of segment A to segment B is
    /// convex along A, so a ternary search over A with the closed-form point–segment
    /// distance finds the segments' distance.
    fn segments_distance(a0: V3, a1: V3, b0: V3, b1: V3) -> f64 {
        let point_segment = |p: V3| {
            let d = sub(b1, b0);
            let len2 = dot(d, d);
            let t = if len2 > 0.0 {
                (dot(sub(p, b0), d) / len2).clamp(0.0, 1.0)
            } else {
                0.0
            };
            let q = axpy(t, d, b0);
            dot(sub(p, q), sub(p, q)).sqrt()
        };
        let at = |s: f64| point_segment(axpy(s, sub(a1, a0), a0));
        let (mut lo, mut hi) = (0.0f64, 1.0f64);
        for _ in 0..200 {
            let (m1, m2) = (lo + (hi - lo) / 3.0, hi - (hi - lo) / 3.0);
            if at(m1) <= at(m2) {
                hi = m2;
            } else {
                lo = m1;
            }
        }
        at((lo + hi) / 2.0).min(at(0.0)).min(at(1.0))
    }

    #[test]
    fn capsule_and_ball_gaps_agree_with_an_independent_oracle() {
        // Capsules and balls of random sizes and poses, overlapping or apart.
        let mut g = Lcg(7);
        let (mut apart, mut overlapping) = (0, 0);
        let mut parry_error = 0.0f64;
        for k in 0..2000 {
            let shape = |g: &mut Lcg, ball: bool| -> SharedShape {
                let r = 0.02 + 0.05 * g.next().abs();
                if ball {
                    SharedShape::ball(r)
                } else {
                    SharedShape::capsule_z(0.01 + 0.2 * g.next().abs(), r)
                }
            };
            let (a, b) = (shape(&mut g, k % 7 == 0), shape(&mut g, k % 5 == 0));
            let (pa, pb) = (g.pose(), g.pose());
            let (ca, cb) = (
                Capsule::of(a.as_ref()).unwrap(),
                Capsule::of(b.as_ref()).unwrap(),
            );
            let axes = segments_distance(
                place(&pa, ca.a),
                place(&pa, ca.b),
                place(&pb, cb.a),
                place(&pb, cb.b),
            );
            let oracle = axes - ca.radius - cb.radius;
            let (ours, p1, p2) = gap(&pa, a.as_ref(), &pb, b.as_ref(), 10.0).unwrap();
            assert_eq!(distance(&pa, a.as_ref(), &pb, b.as_ref()), ours.max(0.0));
            assert!((ours - oracle).abs() < 1e-9, "{k}: {ours} vs {oracle}");
            if ours > 0.0 {
                apart += 1;
                // The two points lie on the surfaces, `ours` apart.
                let between = dot(sub(p2, p1), sub(p2, p1)).sqrt();
                assert!((between - ours).abs() < 1e-9, "{k}: {between} vs {ours}");
                let parry = parry3d::query::distance(&pa, a.as_ref(), &pb, b.as_ref()).unwrap();
                parry_error = parry_error.max((parry.distance - ours).abs());
            } else {
                overlapping += 1;
            }
        }
        assert!(
            apart > 500 && overlapping > 100,
            "{apart} apart, {overlapping} overlapping"
        );
        eprintln!("parry's GJK distance is off by up to {parry_error} m");
    }

    #[test]
    fn the_broadphase_finds_every_overlapping_pair_once() {
        let mut g = Lcg(9);
        let mut broadphase = SweepAndPrune::default();
        let mut out = Vec::new();
        for round in 0..60 {
            let n = 1 + round * 5;
            let boxes: Vec<Aabb> = (0..n)
                .map(|k| {
                    let c = Vector::new(g.next() * 5.0, g.next() * 5.0, g.next());
                    // Mostly small boxes, some long ones, a few covering everything.
                    let h = if k % 17 == 3 {
                        8.0
                    } else if k % 5 == 0 {
                        1.5
                    } else {
                        0.2
                    };
                    let e = Vector::new(h * g.next().abs(), h * g.next().abs(), 0.3);
                    Aabb::new(c - e, c + e)
                })
                .collect();
            broadphase.overlapping(&boxes, &mut out);
            out.sort_unstable();
            let mut all = Vec::new();
            for i in 0..n {
                for j in i + 1..n {
                    if boxes[i].intersects(&boxes[j]) {
                        all.push((i, j));
                    }
                }
            }
            assert_eq!(out, all, "{n} boxes");
        }
    }

    #[test]
    fn capsule_boxes_equal_parrys() {
        let mut g = Lcg(4);
        for _ in 0..200 {
            let shape =
                SharedShape::capsule_z(0.01 + 0.2 * g.next().abs(), 0.02 + 0.05 * g.next().abs());
            let body = BodyRef {
                owner: Owner::Device,
                name: String::new(),
                radius: 1.0,
                shape: shape.clone(),
                local: Pose::IDENTITY,
                fixed: Pose::IDENTITY,
                reach: Vec::new(),
                keys: BodyKeys::default(),
            };
            let pose = g.pose();
            let (ours, parry) = (body.bounding_box(&pose), shape.compute_aabb(&pose));
            assert!((ours.mins - parry.mins).abs().max_element() < 1e-12);
            assert!((ours.maxs - parry.maxs).abs().max_element() < 1e-12);
        }
    }

    #[test]
    fn nearly_parallel_capsules_just_touching_are_measured_exactly() {
        // Two capsules of radius 5 cm side by side, axes 0.001° apart, surfaces
        // `gap` apart at their closest ends: parry's f64 query misreads gaps below some µm.
        for apart in [1e-6f64, 1e-7, 0.0, -1e-6, -1e-4] {
            let c = SharedShape::capsule_z(0.15, 0.05);
            let pa = Pose::IDENTITY;
            let pb = Pose::from_parts(
                Vector::new(0.1 + apart, 0.0, 0.0),
                parry3d::math::Rotation::from_rotation_y(1e-5f64.to_radians()),
            );
            let (d, _, _) = gap(&pa, c.as_ref(), &pb, c.as_ref(), 1.0).unwrap();
            // The tilt moves the closer end of b by 0.15 m × 1e-5° in x.
            let tilt = 0.15 * (1e-5f64).to_radians().sin();
            let expected = apart - tilt;
            assert!((d - expected).abs() < 2e-8, "{apart}: {d} vs {expected}");
        }
    }
}
