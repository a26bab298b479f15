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

use std::collections::BTreeSet;

use parry3d::bounding_volume::{Aabb, BoundingVolume};
use parry3d::math::Pose;
use parry3d::shape::SharedShape;
use vworks_model::math::Iso;
use vworks_vm::machine::Vm;

use crate::workcell::Cell;

/// A collision that started.
#[derive(Clone, Debug, PartialEq)]
pub struct Contact {
    /// When (ns).
    pub time_ns: i64,
    /// First body (`r1.link_4`, `table`, `part1`).
    pub a: String,
    /// Second body.
    pub b: String,
    /// Penetration depth (m).
    pub depth: f64,
    /// A contact point in the cell frame (m).
    pub point: [f64; 3],
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
    radius: f32,
}

fn bounding_radius(shape: &SharedShape) -> f32 {
    let a = shape.compute_local_aabb();
    a.mins.abs().max(a.maxs.abs()).length()
}

/// The collision world of a cell.
pub struct Collider {
    bodies: Vec<BodyRef>,
    poses: Vec<Pose>,
    aabbs: Vec<Aabb>,
    order: Vec<usize>,
    skip: BTreeSet<(usize, usize)>,
    touching: BTreeSet<(usize, usize)>,
    near: BTreeSet<(usize, usize)>,
    /// Per part: the robot holding it and the part's pose in that robot's tool-link frame.
    held: Vec<Option<(usize, Iso)>>,
    /// Per part: pose in the cell when not held.
    part_pose: Vec<Iso>,
    frames: Vec<Vec<Iso>>,
    /// Per robot: the joints `frames` were computed for (NaN before the first check).
    frames_q: Vec<[f64; vworks_vm::MAX_AXES]>,
    dirty: bool,
    /// Narrow-phase queries made so far.
    pub queries: u64,
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
                    rn == r.name && crate::workcell::same_link(&r.model.links[link].name, ln)
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
        for (r, robot) in cell.robots.iter().enumerate() {
            for (l, link) in robot.model.links.iter().enumerate() {
                for s in &link.shapes {
                    bodies.push(BodyRef {
                        owner: Owner::Link { robot: r, link: l },
                        name: format!("{}.{}", robot.name, link.name),
                        shape: s.shape.clone(),
                        local: s.local_pose,
                        radius: bounding_radius(&s.shape),
                    });
                }
            }
        }
        for d in &cell.devices {
            bodies.push(BodyRef {
                owner: Owner::Device,
                name: d.name.clone(),
                shape: d.shape.clone(),
                local: d.local.to_pose(),
                radius: bounding_radius(&d.shape),
            });
        }
        for (i, p) in cell.parts.iter().enumerate() {
            bodies.push(BodyRef {
                owner: Owner::Part(i),
                name: p.name.clone(),
                shape: p.shape.clone(),
                local: p.local.to_pose(),
                radius: bounding_radius(&p.shape),
            });
        }
        // Links of one robot that touch at its zero configuration touch by design (the
        // enveloping shapes overlap around the joints): like MoveIt's "default" pairs.
        let zero_frames: Vec<Vec<Iso>> = cell
            .robots
            .iter()
            .map(|r| r.model.fk(&vec![0.0; r.model.dof()]))
            .collect();
        let pose_at_zero = |b: &BodyRef| match b.owner {
            Owner::Link { robot, link } => zero_frames[robot][link].to_pose() * b.local,
            _ => Pose::IDENTITY,
        };
        let mut skip = BTreeSet::new();
        for i in 0..bodies.len() {
            for j in i + 1..bodies.len() {
                let (a, b) = (&bodies[i], &bodies[j]);
                let same_robot = match (a.owner, b.owner) {
                    (
                        Owner::Link {
                            robot: ra,
                            link: la,
                        },
                        Owner::Link {
                            robot: rb,
                            link: lb,
                        },
                    ) if ra == rb => {
                        la == lb
                            || cell.robots[ra]
                                .model
                                .adjacent_pairs()
                                .contains(&(la.min(lb), la.max(lb)))
                            || parry3d::query::intersection_test(
                                &pose_at_zero(a),
                                a.shape.as_ref(),
                                &pose_at_zero(b),
                                b.shape.as_ref(),
                            )
                            .is_ok_and(|x| x.intersecting)
                    }
                    _ => false,
                };
                let allowed = cell.allowed.iter().any(|(x, y)| {
                    (matches(&a.name, a.owner, cell, x) && matches(&b.name, b.owner, cell, y))
                        || (matches(&a.name, a.owner, cell, y)
                            && matches(&b.name, b.owner, cell, x))
                });
                let static_pair =
                    matches!(a.owner, Owner::Device) && matches!(b.owner, Owner::Device);
                if same_robot || allowed || static_pair {
                    skip.insert((i, j));
                }
            }
        }
        let n = bodies.len();
        Collider {
            poses: vec![Pose::IDENTITY; n],
            aabbs: vec![Aabb::new_invalid(); n],
            order: (0..n).collect(),
            skip,
            touching: BTreeSet::new(),
            near: BTreeSet::new(),
            held: vec![None; cell.parts.len()],
            part_pose: cell.parts.iter().map(|p| p.pose).collect(),
            frames: cell
                .robots
                .iter()
                .map(|r| r.model.frames_buffer())
                .collect(),
            frames_q: vec![[f64::NAN; vworks_vm::MAX_AXES]; cell.robots.len()],
            dirty: true,
            queries: 0,
            bodies,
        }
    }

    /// Robot `r`'s tool link in the cell at time `t` (the frames of the last check stay).
    fn tool_world(cell: &Cell, vm: &Vm, r: usize, t: i64) -> Iso {
        let robot = &cell.robots[r];
        let q = vm.joints_at(t);
        robot.base.mul(&robot.model.flange(&q[..robot.model.dof()]))
    }

    /// Robot `r` grips part `p` at time `t`: from now on the part moves with its tool link.
    pub fn grip(&mut self, p: usize, r: usize, vm: &Vm, cell: &Cell, t: i64) {
        let tool = Collider::tool_world(cell, vm, r, t);
        let pose = self.current_part_pose(p, cell, t, None);
        self.held[p] = Some((r, tool.inverse().mul(&pose)));
        self.dirty = true;
    }

    /// Part `p` is released at time `t` and stays where it is.
    pub fn release(&mut self, p: usize, vms: &[Vm], cell: &Cell, t: i64) {
        if let Some((r, offset)) = self.held[p] {
            let tool = Collider::tool_world(cell, &vms[r], r, t);
            self.part_pose[p] = tool.mul(&offset);
        }
        self.held[p] = None;
        self.dirty = true;
    }

    /// Every robot's link frames in the cell as of the last [`Collider::check`] (which
    /// brings all of them up to date: robots it skipped have not moved).
    pub fn frames(&self) -> &[Vec<Iso>] {
        &self.frames
    }

    /// Every robot's joints as of the last [`Collider::check`] (the joints its frames are
    /// the forward kinematics of; `MAX_AXES` slots, the robot's axes first).
    pub fn joints(&self) -> &[[f64; vworks_vm::MAX_AXES]] {
        &self.frames_q
    }

    /// The pose of every part as of the last [`Collider::check`], into `out` (reused).
    pub fn part_poses_into(&self, cell: &Cell, out: &mut Vec<Iso>) {
        out.clear();
        out.extend((0..cell.parts.len()).map(|p| match self.held[p] {
            Some((r, offset)) => self.frames[r][cell.robots[r].model.tool_link].mul(&offset),
            None => self.part_pose[p],
        }));
    }

    fn current_part_pose(&self, p: usize, _cell: &Cell, _t: i64, _vm: Option<&Vm>) -> Iso {
        self.part_pose[p]
    }

    /// Checks the cell at boundary time `t`; `moving[r]` says whether robot r moves.
    pub fn check(
        &mut self,
        cell: &Cell,
        vms: &[Vm],
        t: i64,
        moving: &[bool],
    ) -> Vec<CollisionEvent> {
        // A robot needs new link frames when its joints differ from those its frames were
        // computed for: moving now, or moved since the last check (even a motion that
        // began and ended between two boundaries).
        let mut update = [false; 64];
        let mut any = false;
        for (r, vm) in vms.iter().enumerate() {
            let q = vm.joints_at(t); // once per robot and boundary: may be an IK solve
            let changed = moving[r] || q != self.frames_q[r];
            if changed {
                self.frames_q[r] = q;
            }
            any |= changed;
            if r < update.len() {
                update[r] = changed;
            }
        }
        if !self.dirty && !any {
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
            let q = &self.frames_q[r][..robot.model.dof()];
            robot.model.fk_into(q, &mut self.frames[r]);
            for f in self.frames[r].iter_mut() {
                *f = robot.base.mul(f);
            }
        }
        let updated = |r: usize| r >= update.len() || update[r];
        let margin = cell.clearance as f32;
        for (i, b) in self.bodies.iter().enumerate() {
            let owner_pose = match b.owner {
                Owner::Link { robot, link } if updated(robot) => self.frames[robot][link].to_pose(),
                Owner::Device if all => cell
                    .devices
                    .iter()
                    .find(|d| d.name == b.name)
                    .map_or(Pose::IDENTITY, |d| d.pose.to_pose()),
                Owner::Part(p) => match self.held[p] {
                    Some((r, offset)) if updated(r) || all => self.frames[r]
                        [cell.robots[r].model.tool_link]
                        .mul(&offset)
                        .to_pose(),
                    None if all => self.part_pose[p].to_pose(),
                    _ => continue,
                },
                _ => continue,
            };
            self.poses[i] = owner_pose * b.local;
            // The broadphase box: exact where parry computes it in closed form (capsules,
            // balls, boxes), else the bounding sphere (cylinders, hulls: their exact boxes
            // need support-map searches).
            self.aabbs[i] = if b.shape.as_capsule().is_some()
                || b.shape.as_ball().is_some()
                || b.shape.as_cuboid().is_some()
            {
                b.shape.compute_aabb(&self.poses[i]).loosened(margin)
            } else {
                let c = self.poses[i].translation;
                let r = parry3d::math::Vector::splat(b.radius + margin);
                Aabb::new(c - r, c + r)
            };
        }
        // Sort and sweep along x.
        let aabbs = &self.aabbs;
        self.order
            .sort_by(|a, b| aabbs[*a].mins.x.total_cmp(&aabbs[*b].mins.x).then(a.cmp(b)));
        let mut touching = BTreeSet::new();
        let mut near: Vec<((usize, usize), f64)> = Vec::new();
        let mut starts = Vec::new();
        for (k, &i) in self.order.iter().enumerate() {
            for &j in &self.order[k + 1..] {
                if self.aabbs[j].mins.x > self.aabbs[i].maxs.x {
                    break;
                }
                if !self.aabbs[i].intersects(&self.aabbs[j]) {
                    continue;
                }
                let pair = (i.min(j), i.max(j));
                if self.skip.contains(&pair) || self.held_by(pair, cell) {
                    continue;
                }
                let (a, b) = (&self.bodies[pair.0], &self.bodies[pair.1]);
                let static_pair = !matches!(a.owner, Owner::Link { .. })
                    && !matches!(b.owner, Owner::Link { .. })
                    && !self.is_held(a.owner)
                    && !self.is_held(b.owner);
                if static_pair {
                    continue;
                }
                self.queries += 1;
                let Ok(Some(c)) = parry3d::query::contact(
                    &self.poses[pair.0],
                    a.shape.as_ref(),
                    &self.poses[pair.1],
                    b.shape.as_ref(),
                    margin,
                ) else {
                    continue;
                };
                let dist = f64::from(c.dist);
                if dist <= 0.0 {
                    touching.insert(pair);
                    if !self.touching.contains(&pair) {
                        let p = c.point1;
                        starts.push(Contact {
                            time_ns: t,
                            a: a.name.clone(),
                            b: b.name.clone(),
                            depth: -dist,
                            point: [f64::from(p.x), f64::from(p.y), f64::from(p.z)],
                        });
                    }
                } else if dist < cell.clearance {
                    near.push((pair, dist));
                }
            }
        }
        let mut events: Vec<CollisionEvent> =
            starts.into_iter().map(CollisionEvent::Start).collect();
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
        events
    }

    fn is_held(&self, o: Owner) -> bool {
        matches!(o, Owner::Part(p) if self.held[p].is_some())
    }

    /// A held part and the tool link of the robot holding it.
    fn held_by(&self, (i, j): (usize, usize), cell: &Cell) -> bool {
        let (a, b) = (self.bodies[i].owner, self.bodies[j].owner);
        let check = |part: Owner, link: Owner| match (part, link) {
            (Owner::Part(p), Owner::Link { robot, link }) => self.held[p]
                .is_some_and(|(r, _)| r == robot && link == cell.robots[r].model.tool_link),
            _ => false,
        };
        check(a, b) || check(b, a)
    }
}
