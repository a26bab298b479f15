//! The collider's horizon ([`Collider::horizon`]): the time before which no two bodies can
//! come within the clearance under the current motions, proved at each boundary check from
//! the bodies' speed bounds, the pairs' promises and a look-ahead broadphase.

use parry3d::bounding_volume::{Aabb, BoundingVolume};
use vworks_cell::Cell;

use super::broadphase::SweepAndPrune;
use super::{Collider, HORIZON_NS, Owner};

/// The horizon and the scratch its proof reuses.
#[derive(Debug)]
pub(super) struct Lookahead {
    /// No two bodies can come within the clearance before this time under the current
    /// motions (`i64::MIN`: no such promise): the engine skips the sweeps and boundary
    /// checks before it.
    pub(super) horizon: i64,
    /// Each body's speed bound, the boxes grown by the look-ahead, their overlapping pairs.
    body_speed: Vec<f64>,
    ahead_boxes: Vec<Aabb>,
    ahead: SweepAndPrune,
    ahead_pairs: Vec<(usize, usize)>,
}

impl Default for Lookahead {
    fn default() -> Self {
        Lookahead {
            horizon: i64::MIN,
            body_speed: Vec::new(),
            ahead_boxes: Vec::new(),
            ahead: SweepAndPrune::default(),
            ahead_pairs: Vec::new(),
        }
    }
}

impl Collider {
    /// The horizon at a check at `t` (see [`Collider::horizon`]).
    pub(super) fn prove_horizon(&mut self, cell: &Cell, t: i64, joint_speed: &[Vec<f64>]) -> i64 {
        if !self.touching.is_empty()
            || !self.near.is_empty()
            || !self.exempt.is_empty()
            || self.world.held.iter().any(Option::is_some)
        {
            return i64::MIN;
        }
        self.lookahead.body_speed.clear();
        let mut fastest = 0.0f64;
        for b in &self.bodies {
            let v = match b.owner {
                Owner::Link { robot, .. } => b
                    .reach
                    .iter()
                    .map(|(j, arm)| joint_speed[robot][*j] * arm)
                    .sum(),
                _ => 0.0,
            };
            fastest = fastest.max(v);
            self.lookahead.body_speed.push(v);
        }
        if !fastest.is_finite() {
            return i64::MIN;
        }
        let mut h = t.saturating_add(HORIZON_NS);
        // The pairs the check's broadphase kept: their promises.
        for &(i, j) in &self.pairs {
            if self.never((i, j)) || self.static_pair((i, j)) {
                continue;
            }
            h = h.min(self.promises.get(i, j));
        }
        if h <= t {
            return i64::MIN;
        }
        if fastest <= 0.0 {
            return h;
        }
        // Pairs apart but within reach of each other in the look-ahead: from their boxes.
        let reach = fastest * HORIZON_NS as f64 / 1e9;
        let margin = cell.clearance;
        self.lookahead.ahead_boxes.clear();
        self.lookahead
            .ahead_boxes
            .extend(self.aabbs.iter().map(|b| b.loosened(reach)));
        let mut pairs = std::mem::take(&mut self.lookahead.ahead_pairs);
        self.lookahead
            .ahead
            .overlapping(&self.lookahead.ahead_boxes, &mut pairs);
        for &(i, j) in &pairs {
            let (a, b) = (&self.aabbs[i], &self.aabbs[j]);
            if self.never((i, j)) || self.static_pair((i, j)) || a.intersects(b) {
                continue; // (boxes within the clearance: a pair the check kept, above)
            }
            let v = self.lookahead.body_speed[i] + self.lookahead.body_speed[j];
            if v <= 0.0 {
                continue;
            }
            // The distance of the boxes themselves (not grown by the clearance).
            let mut d2 = 0.0;
            for k in 0..3 {
                let g = (b.mins[k] - a.maxs[k]).max(a.mins[k] - b.maxs[k]) + 2.0 * margin;
                if g > 0.0 {
                    d2 += g * g;
                }
            }
            let gap = d2.sqrt() - cell.clearance;
            if gap <= 0.0 {
                h = i64::MIN;
                break;
            }
            h = h.min(t.saturating_add((gap / v * 1e9) as i64));
        }
        self.lookahead.ahead_pairs = pairs;
        h
    }
}
