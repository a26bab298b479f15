//! The collider's per-pair state, in memory linear in bodies: which pairs are never
//! checked (per-body sorted lists and per-body keys, not a table of every pair), and the
//! promises of adaptive checking (kept only for the pairs the broadphase has kept, in
//! per-body sorted lists). With 1,000 robots the dense tables of every pair took 0.54 GB;
//! with 10,000 robots, 49 GB.

use parry3d::bounding_volume::BoundingVolume;
use parry3d::math::Pose;
use vworks_cell::Cell;
use vworks_model::math::Iso;

use super::broadphase::SweepAndPrune;
use super::{BodyRef, Owner, matches};

/// Which pairs of bodies are never checked: two shapes of one link, links of one robot
/// joined by a joint or touching at the robot's zero configuration (touching by design,
/// like MoveIt's "default" pairs), and the pairs the workcell allows. (Two devices are
/// never checked either: see `Collider::static_pair`.)
pub(super) struct PairFilter {
    /// Per body: its link and its parent link, and which of its lists are not empty (the
    /// one place the hot loop reads for most pairs).
    keys: Vec<BodyKeys>,
    /// Per body `i`: the bodies `j > i` of its robot that touch it at the zero
    /// configuration (besides its own link and the links joined to it), sorted.
    touching_at_zero: Vec<Vec<usize>>,
    /// Per body: the workcell's allowed pairs it matches, sorted: (entry, bit 1 if it
    /// matches the entry's first name, bit 2 its second).
    allowed: Vec<Vec<(usize, u8)>>,
}

/// A body's link as `robot << 32 | link` and its parent link's likewise (`u64::MAX`:
/// none; bodies that are not links get keys no link has), and flags: [`TOUCHES_AT_ZERO`],
/// [`ALLOWED`].
#[derive(Clone, Copy, Debug, Default)]
pub(super) struct BodyKeys {
    link: u64,
    parent: u64,
    flags: u8,
}

/// The body touches others of its robot at the zero configuration.
const TOUCHES_AT_ZERO: u8 = 1;
/// The body matches an entry of the workcell's allowed pairs.
const ALLOWED: u8 = 2;

/// Bodies' boxes at the zero configuration are grown by this before they are compared,
/// so that two shapes touching exactly are still a candidate pair (m).
const ZERO_BOX_MARGIN: f64 = 1e-6;

impl PairFilter {
    /// The filter of `bodies` (the links of every robot first, robot by robot).
    pub(super) fn new(cell: &Cell, bodies: &[BodyRef]) -> PairFilter {
        let n = bodies.len();
        let key = |robot: usize, link: usize| ((robot as u64) << 32) | link as u64;
        let keys = bodies
            .iter()
            .enumerate()
            .map(|(i, b)| {
                let (link, parent) = match b.owner {
                    Owner::Link { robot, link } => {
                        let model = &cell.robots[robot].model;
                        let parent = model.links[link]
                            .parent_joint
                            .and_then(|j| model.joints.get(j))
                            .map_or(u64::MAX, |j| key(robot, j.parent));
                        (key(robot, link), parent)
                    }
                    // Above every link's key (robots and links are far fewer than 2^31).
                    _ => ((1 << 63) | i as u64, u64::MAX),
                };
                BodyKeys {
                    link,
                    parent,
                    flags: 0,
                }
            })
            .collect();
        let mut filter = PairFilter {
            keys,
            touching_at_zero: vec![Vec::new(); n],
            allowed: vec![Vec::new(); n],
        };
        filter.find_touching_at_zero(cell, bodies);
        for (i, b) in bodies.iter().enumerate() {
            for (k, (x, y)) in cell.allowed.iter().enumerate() {
                let sides = u8::from(matches(&b.name, b.owner, cell, x))
                    | (u8::from(matches(&b.name, b.owner, cell, y)) << 1);
                if sides != 0 {
                    filter.allowed[i].push((k, sides));
                }
            }
        }
        for (i, k) in filter.keys.iter_mut().enumerate() {
            if !filter.touching_at_zero[i].is_empty() {
                k.flags |= TOUCHES_AT_ZERO;
            }
            if !filter.allowed[i].is_empty() {
                k.flags |= ALLOWED;
            }
        }
        filter
    }

    /// Each robot's links touching at its zero configuration: a sort and sweep of their
    /// boxes there, and the exact test for the pairs whose boxes overlap.
    fn find_touching_at_zero(&mut self, cell: &Cell, bodies: &[BodyRef]) {
        let mut broadphase = SweepAndPrune::default();
        let (mut boxes, mut poses, mut pairs) = (Vec::new(), Vec::new(), Vec::new());
        let mut start = 0;
        for (r, robot) in cell.robots.iter().enumerate() {
            let end = start
                + bodies[start..]
                    .iter()
                    .take_while(|b| matches!(b.owner, Owner::Link { robot: rb, .. } if rb == r))
                    .count();
            let frames: Vec<Iso> = robot.model.fk(&vec![0.0; robot.model.dof()]);
            poses.clear();
            boxes.clear();
            for b in &bodies[start..end] {
                let link = match b.owner {
                    Owner::Link { link, .. } => link,
                    _ => 0,
                };
                let pose: Pose = frames[link].to_pose() * b.local;
                boxes.push(b.shape.compute_aabb(&pose).loosened(ZERO_BOX_MARGIN));
                poses.push(pose);
            }
            broadphase.overlapping(&boxes, &mut pairs);
            for &(a, b) in &pairs {
                let (i, j) = (start + a, start + b);
                if same_or_joined(&self.keys[i], &self.keys[j]) {
                    continue;
                }
                let touching = parry3d::query::intersection_test(
                    &poses[a],
                    bodies[i].shape.as_ref(),
                    &poses[b],
                    bodies[j].shape.as_ref(),
                )
                .is_ok_and(|x| x.intersecting);
                if touching {
                    self.touching_at_zero[i].push(j);
                }
            }
            start = end;
        }
        for list in &mut self.touching_at_zero {
            list.sort_unstable();
        }
    }

    /// Each body's keys (the collider keeps a copy in each body, beside what the hot loop
    /// reads of it anyway).
    pub(super) fn keys(&self) -> &[BodyKeys] {
        &self.keys
    }

    /// Whether the pair `i < j`, of keys `a` and `b`, is never checked (inlined: the
    /// boundary check asks it of every pair its broadphase keeps).
    #[inline(always)]
    pub(super) fn never(&self, (i, j): (usize, usize), a: &BodyKeys, b: &BodyKeys) -> bool {
        same_or_joined(a, b)
            || (a.flags & TOUCHES_AT_ZERO != 0
                && self.touching_at_zero[i].binary_search(&j).is_ok())
            || (a.flags & b.flags & ALLOWED != 0 && self.allowed(i, j))
    }

    /// The workcell allows the pair: one entry names one body first and the other second.
    fn allowed(&self, i: usize, j: usize) -> bool {
        let (a, b) = (&self.allowed[i], &self.allowed[j]);
        a.iter().any(|&(k, sa)| {
            b.binary_search_by_key(&k, |e| e.0).is_ok_and(|at| {
                (sa & 1 != 0 && b[at].1 & 2 != 0) || (sa & 2 != 0 && b[at].1 & 1 != 0)
            })
        })
    }

    /// How many pairs the filter lists (the touching-at-zero pairs; the allowed entries
    /// each body matches).
    pub(super) fn entries(&self) -> usize {
        self.touching_at_zero.iter().map(Vec::len).sum::<usize>()
            + self.allowed.iter().map(Vec::len).sum::<usize>()
    }
}

/// Two bodies are shapes of one link, or of two links joined by a joint.
#[inline(always)]
fn same_or_joined(a: &BodyKeys, b: &BodyKeys) -> bool {
    // (Parents come before children: of two joined links, the second is the child.)
    b.parent == a.link || a.link == b.link || a.parent == b.link
}

/// One pair's promise: no query needed before `until` (see `Collider::check`).
#[derive(Clone, Copy, Debug)]
struct Promise {
    other: usize,
    until: i64,
    /// When it was made (in withdrawals: see [`Promises`]).
    stamp: u64,
}

/// The promises of adaptive checking: per pair, the time before which the current motions
/// cannot bring it within the clearance. Kept per body `i` for the bodies `j > i` it has a
/// promise with, sorted; a pair without one has `i64::MIN`. A robot's motion start
/// withdraws the promises of its bodies: each body remembers the withdrawal's stamp, and a
/// promise made before it no longer counts (no pass over the other bodies' lists).
#[derive(Debug, Default)]
pub(super) struct Promises {
    by_body: Vec<Vec<Promise>>,
    withdrawn: Vec<u64>,
    stamp: u64,
}

impl Promises {
    /// No promises between `n` bodies.
    pub(super) fn new(n: usize) -> Promises {
        Promises {
            by_body: vec![Vec::new(); n],
            withdrawn: vec![0; n],
            stamp: 0,
        }
    }

    /// The promise of the pair `i < j` (`i64::MIN`: none).
    #[inline]
    pub(super) fn get(&self, i: usize, j: usize) -> i64 {
        let list = &self.by_body[i];
        match list.binary_search_by_key(&j, |p| p.other) {
            Ok(at) => {
                let p = list[at];
                if p.stamp >= self.withdrawn[i] && p.stamp >= self.withdrawn[j] {
                    p.until
                } else {
                    i64::MIN
                }
            }
            Err(_) => i64::MIN,
        }
    }

    /// The pair `i < j` promises `until`.
    pub(super) fn set(&mut self, i: usize, j: usize, until: i64) {
        let promise = Promise {
            other: j,
            until,
            stamp: self.stamp,
        };
        let list = &mut self.by_body[i];
        match list.binary_search_by_key(&j, |p| p.other) {
            Ok(at) => list[at] = promise,
            Err(at) => list.insert(at, promise),
        }
    }

    /// Every promise is withdrawn.
    pub(super) fn withdraw_all(&mut self) {
        for list in &mut self.by_body {
            list.clear();
        }
    }

    /// The next withdrawal begins: the promises made so far of the bodies it names
    /// ([`Promises::withdraw`]) no longer count.
    pub(super) fn begin_withdrawal(&mut self) {
        self.stamp += 1;
    }

    /// Body `i`'s promises are withdrawn.
    pub(super) fn withdraw(&mut self, i: usize) {
        self.withdrawn[i] = self.stamp;
        self.by_body[i].clear();
    }

    /// How many promises are held (withdrawn ones included until they are replaced).
    pub(super) fn entries(&self) -> usize {
        self.by_body.iter().map(Vec::len).sum()
    }
}

/// For two link bodies of one robot, with reaches `a` and `b` (the moving joints from each
/// one's link up to the root): how many leading entries of each are joints the other does
/// not have. The paths share the joints above their common ancestor, a common suffix,
/// found by bisection (a joint on both paths has every joint above it on both).
pub(super) fn unshared(a: &[(usize, f64)], b: &[(usize, f64)]) -> (usize, usize) {
    let (la, lb) = (a.len(), b.len());
    // The longest shared suffix: the predicate "the k-th from the end agrees" holds for
    // k = 1..=s and fails after.
    let (mut lo, mut hi) = (0, la.min(lb));
    while lo < hi {
        let k = (lo + hi).div_ceil(2);
        if a[la - k].0 == b[lb - k].0 {
            lo = k;
        } else {
            hi = k - 1;
        }
    }
    (la - lo, lb - lo)
}
