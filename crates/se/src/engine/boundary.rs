//! Cycle boundaries and the time between them ([`Boundaries`]): the boundary clock, the
//! collision checks at each boundary and the sweeps between them (through the
//! [`Collider`]), and what they find recorded — collisions and their ends, near misses
//! with the motion statements of the robots involved.

use vworks_cell::Cell;
use vworks_vm::bytecode::SrcPos;
use vworks_vm::machine::Vm;

use crate::collide::{Collider, CollisionEvent};
use vworks_log::issue::IssueKind;
use vworks_log::place::Contact;
use vworks_log::place::RobotMotion;
use vworks_log::trace::{Detail, Kind};

use super::record::Recording;

/// The boundary clock and the collision world.
#[derive(Debug)]
pub(super) struct Boundaries {
    collider: Collider,
    /// The next cycle boundary still to be processed, and how many have been.
    next: i64,
    cycles: u64,
    /// Time up to which contacts between boundaries have been swept for.
    swept: i64,
    /// Whether to sweep between boundaries at all (see `Simulation::with_sweep`).
    sweep: bool,
    /// Whether each robot moves at the boundary being processed (reused).
    moving: Vec<bool>,
    /// Each robot's last `motion_start`: the statement a collision or near miss names.
    last_motion: Vec<Option<SrcPos>>,
}

impl Boundaries {
    /// The first boundary (time 0) of `cell`, none processed.
    pub(super) fn new(cell: &Cell) -> Boundaries {
        Boundaries {
            collider: Collider::new(cell),
            next: 0,
            cycles: 0,
            swept: 0,
            sweep: true,
            moving: Vec::with_capacity(cell.robots.len()),
            last_motion: vec![None; cell.robots.len()],
        }
    }

    /// Whether to sweep between boundaries.
    pub(super) fn set_sweep(&mut self, sweep: bool) {
        self.sweep = sweep;
    }

    /// The collision world.
    pub(super) fn collider(&self) -> &Collider {
        &self.collider
    }

    /// The collision world, to change (adaptive checking, grips and releases).
    pub(super) fn collider_mut(&mut self) -> &mut Collider {
        &mut self.collider
    }

    /// The time of the next cycle boundary still to be processed.
    pub(super) fn next(&self) -> i64 {
        self.next
    }

    /// How many boundaries have been processed (skipped ones included).
    pub(super) fn cycles(&self) -> u64 {
        self.cycles
    }

    /// Robot `r` starts the motion at `pos`.
    pub(super) fn motion_started(&mut self, r: usize, pos: SrcPos) {
        self.last_motion[r] = Some(pos);
        // Speed bounds behind skipped collision queries change with the motion.
        self.collider.motion_started(r);
    }

    /// Records a collision that started; true if the run stops on it.
    fn collision_started(
        &mut self,
        cell: &Cell,
        vms: &[Vm],
        rec: &mut Recording,
        mut contact: Contact,
    ) -> bool {
        contact.motions = self.motions_of(cell, vms, &contact.a, &contact.b, contact.time_ns);
        rec.collision(contact);
        cell.stop_on_collision
    }

    /// Sweeps the time since the last sweep up to (not including) `t` for contacts
    /// between boundaries (see [`Collider::sweep`]); runs before every boundary and
    /// before every event, so motions do not change within a swept stretch. The time of
    /// the contact the run stops on, if it does.
    #[inline]
    pub(super) fn sweep_until(
        &mut self,
        cell: &Cell,
        vms: &[Vm],
        rec: &mut Recording,
        t: i64,
    ) -> Option<i64> {
        if !self.sweep || t <= self.swept {
            return None;
        }
        // Nothing can touch before the collider's horizon: no sweep to do.
        if t <= self.collider.horizon() {
            self.swept = t;
            return None;
        }
        self.sweep_to(cell, vms, rec, t)
    }

    /// [`Boundaries::sweep_until`] once there is a stretch to sweep.
    fn sweep_to(&mut self, cell: &Cell, vms: &[Vm], rec: &mut Recording, t: i64) -> Option<i64> {
        let contacts = self.collider.sweep(cell, vms, self.swept, t);
        self.swept = t;
        for contact in contacts {
            let at = contact.time_ns;
            if self.collision_started(cell, vms, rec, contact) {
                return Some(at);
            }
        }
        None
    }

    /// Processes every cycle boundary up to and including `t`; `next_event` is the time of
    /// the earliest queue entry (boundaries before it where nothing moves are skipped).
    /// The time of the contact the run stops on, if it does.
    #[inline]
    pub(super) fn advance(
        &mut self,
        cell: &Cell,
        vms: &[Vm],
        rec: &mut Recording,
        t: i64,
        next_event: Option<i64>,
    ) -> Option<i64> {
        if self.next > t {
            return None;
        }
        self.advance_to(cell, vms, rec, t, next_event)
    }

    /// [`Boundaries::advance`] once a boundary is due.
    fn advance_to(
        &mut self,
        cell: &Cell,
        vms: &[Vm],
        rec: &mut Recording,
        t: i64,
        next_event: Option<i64>,
    ) -> Option<i64> {
        let c = cell.cycle_ns;
        while self.next <= t {
            let b = self.next;
            // Before the collider's horizon no pair can come within the clearance: the
            // boundary has nothing to check (unless a log records every boundary's state).
            if b < self.collider.horizon() && !rec.has_sinks() {
                self.swept = self.swept.max(b);
                self.next += c;
                self.cycles += 1;
                continue;
            }
            // A contact before the boundary may end the run before it is reached.
            if let Some(at) = self.sweep_until(cell, vms, rec, b) {
                return Some(at);
            }
            self.next += c;
            self.cycles += 1;
            self.moving.clear();
            self.moving.extend(vms.iter().map(|v| v.moving_at(b)));
            let events = self.collider.check(cell, vms, b, &self.moving);
            // The state at the boundary, for the log: after the check, whose link frames
            // it reuses.
            rec.log_cycle(b, self.collider.world());
            for ev in events {
                match ev {
                    CollisionEvent::Start(contact) => {
                        if self.collision_started(cell, vms, rec, contact) {
                            return Some(b);
                        }
                    }
                    CollisionEvent::End(a, bname) => {
                        let detail = Detail::CollisionEnd(Box::new((a, bname)));
                        rec.record(b, None, Kind::CollisionEnd, detail, None)
                    }
                    CollisionEvent::NearMiss(a, bname, dist) => {
                        self.near_miss(cell, vms, rec, b, (a, bname), dist);
                    }
                }
            }
            // With nothing queued before the next boundary and nothing moving, skip ahead.
            // (Not when a sink records every boundary.)
            if !rec.records_cycles() && !self.moving.iter().any(|m| *m) {
                let next_event = next_event.unwrap_or(t).min(t);
                if next_event > self.next {
                    let skip = (next_event - self.next) / c;
                    self.next += skip * c;
                    self.cycles += skip as u64;
                }
            }
        }
        None
    }

    /// Records the near miss of bodies `a` and `b`, `dist` apart at boundary `at`.
    fn near_miss(
        &self,
        cell: &Cell,
        vms: &[Vm],
        rec: &mut Recording,
        at: i64,
        (a, b): (String, String),
        dist: f64,
    ) {
        // Hundredths of a millimetre in words; the exact distance in `Issue::distance_m`
        // (JSON, Python).
        let m = format!("near miss: {a} and {b} come within {:.2} mm", dist * 1e3);
        let mut issue = Recording::issue(cell, IssueKind::NearMiss, m, None, None);
        issue.distance_m = Some(dist);
        issue.motions = self.motions_of(cell, vms, &a, &b, at);
        // The warning's own place: the first robot moving (else the first robot's last
        // motion).
        let main = issue.motions.iter().find(|m| m.moving);
        if let Some(first) = main.or(issue.motions.first()) {
            issue.robot = Some(first.robot.clone());
            issue.file.clone_from(&first.file);
            (issue.line, issue.col) = (first.line, first.col);
        }
        rec.add_issue(at, None, None, Kind::Warning, issue);
    }

    /// The robots that move bodies `a` and `b` (each once, in that order), and the motion
    /// each was making at `t`, or last made.
    fn motions_of(&self, cell: &Cell, vms: &[Vm], a: &str, b: &str, t: i64) -> Vec<RobotMotion> {
        let ra = self.collider.robot_moving(a);
        let rb = self.collider.robot_moving(b).filter(|r| Some(*r) != ra);
        [ra, rb]
            .into_iter()
            .flatten()
            .map(|r| {
                let robot = cell.robots[r].name.clone();
                match self.last_motion[r] {
                    Some(pos) => RobotMotion {
                        robot,
                        moving: vms[r].moving_at(t),
                        file: Some(cell.robots[r].module.file_of(pos).to_string()),
                        line: pos.line,
                        col: pos.col,
                        statement: crate::describe::statement_at(cell, r, pos),
                    },
                    None => RobotMotion::not_moved(robot),
                }
            })
            .collect()
    }
}
