//! Routing a robot's event to the rest of the cell: a `set` updates every robot's copy of
//! the global and queues `check_wait`/`check_when` for exactly the robots on its WAIT and
//! WHEN lists; signals are delivered, remote requests queued and answered, parts gripped
//! and released; runtime errors stop the run.

use std::sync::Arc;

use vworks_vm::Dim;
use vworks_vm::bytecode::SrcPos;
use vworks_vm::machine::{Event, EventKind};
use vworks_vm::types::fmt_quantity;

use super::queue::Entry;
use super::races::Seen;
use vworks_log::issue::IssueKind;

use super::{Detail, Kind, Outcome, Simulation};

impl Simulation {
    pub(super) fn route(&mut self, r: usize, e: &Event, kind: Kind) {
        let t = e.time;
        // A set is recorded with the cell's global and the value it replaces.
        let set = match e.kind {
            EventKind::Set { global, value, .. } => {
                Some((self.cell.linked.robots[r].globals[global as usize], value))
            }
            _ => None,
        };
        let detail = match set {
            Some((cg, new)) => Detail::Set {
                global: cg,
                old: self.globals[cg as usize].0,
                new,
            },
            None => Detail::Vm(e.kind.clone()),
        };
        self.record(t, Some(r), kind, detail, Some(e.pos));
        if let Some((cg, value)) = set {
            self.on_set(r, cg as usize, value, t, e.pos);
            return;
        }
        match &e.kind {
            EventKind::WaitUntil { cond, .. } => {
                let cell = Arc::clone(&self.cell);
                // A later set at this instant races with this read only if the wait passed
                // at once: a wait that blocks is re-tested by that set's check_wait at the
                // same instant, so either order releases it at the same time.
                let passed = !self.vms[r].waits();
                let stamp = self.tick(r);
                if passed {
                    // A wait that passes on a value set earlier at this instant would, in
                    // the other order, have blocked and been released by that set's
                    // check_wait at the same instant: it follows the set either way.
                    self.seen_condition(r, *cond);
                }
                for g in &cell.robots[r].module.conds[*cond as usize].globals {
                    let cg = cell.linked.robots[r].globals[*g as usize] as usize;
                    self.check_race(cg, r, t, e.pos, false);
                    if passed {
                        self.last_read[cg] = Some((t, r, e.pos, stamp));
                    }
                    self.wait_list[cg].insert(r);
                }
            }
            EventKind::WaitEnd { timed_out } => {
                if *timed_out {
                    self.timed_out_race(r, t, e.pos);
                }
                self.clear_waits(r);
                // A wait at a sync point that timed out: the task leaves the meeting.
                if *timed_out && let Some(cs) = self.at_sync[r] {
                    self.sync_timeout[cs] = Some((t, r, e.pos));
                }
                self.leave_sync(r);
            }
            EventKind::WaitSync { site, .. } => self.arrive(r, *site as usize, t, e.pos),
            EventKind::EnableWhen { handler } => {
                let m = self.vms[r].module();
                let h = &m.handlers[*handler as usize];
                if let vworks_vm::bytecode::Trigger::Condition(c) = h.trigger {
                    let target = h.target;
                    let cell = Arc::clone(&self.cell);
                    for g in &cell.robots[r].module.conds[c as usize].globals {
                        let cg = cell.linked.robots[r].globals[*g as usize] as usize;
                        self.when_list[cg].insert((r, target));
                    }
                }
            }
            EventKind::DisableWhen { proc } => {
                for w in &mut self.when_list {
                    w.remove(&(r, *proc));
                }
            }
            EventKind::End => {
                for w in &mut self.when_list {
                    w.retain(|(q, _)| *q != r);
                }
                // (`stop` in a handler may end a wait, a wait at a sync point too.)
                self.clear_waits(r);
                self.leave_sync(r);
            }
            EventKind::Signal { site } => {
                let (target, idx) = self.signal_to[r][*site as usize];
                let stamp = self.tick(r);
                let timing_out = self.vms[target].wait_deadline() == Some(t)
                    && idx.is_some()
                    && self.vms[target].waited_signal() == idx;
                let timed_out = self.signal_timeout[target]
                    .filter(|(ot, _)| *ot == t)
                    .map(|(_, p)| p);
                let waiting = timing_out
                    .then(|| self.vms[target].waiting_for().map(|(_, p)| p))
                    .flatten();
                if let Some(wpos) = timed_out.or(waiting) {
                    self.race(t, (target, wpos), (r, e.pos), "on a signal", "time out a wait for it and send it at the same instant; whether the signal releases the wait depends on their order");
                }
                self.last_signal[target] = Some((t, r, e.pos, stamp));
                if let Some(idx) = idx
                    && self.vms[target].deliver_signal_index(idx, t)
                {
                    // The receiver, released, has seen what the sender had.
                    self.merge_clock(target, Seen::Robot(r));
                    self.requeue(target);
                }
            }
            EventKind::RemoteCall { site, req, args } => {
                let (target, proc) = self.cell.linked.robots[r].remotes[*site as usize];
                let target = target as usize;
                // Two requests to one robot at one instant: which it serves first is only
                // the queue's tie order (a request made after seeing the other's is not).
                let stamp = self.tick(r);
                let n = self.vms.len();
                if let Some((ot, or, opos, ostamp)) = self.last_request[target]
                    && ot == t
                    && or != r
                    && self.clock[r * n + or] < ostamp
                {
                    let subject = format!("for {}'s remote work", self.cell.robots[target].name);
                    self.race(t, (or, opos), (r, e.pos), &subject, "ask for it at the same instant; which request it serves first depends on their order");
                }
                self.last_request[target] = Some((t, r, e.pos, stamp));
                self.vms[target].request_remote(proc, args.clone(), t);
                self.serving[target].push_back((r, *req));
                if self.queued_at[target].is_none() {
                    self.requeue(target);
                }
            }
            EventKind::RemoteEnd { .. } => {
                // The handlers the remote work enabled ended with it.
                self.sync_when_list(r);
                self.clear_waits(r);
                self.leave_sync(r);
                if let Some((caller, req)) = self.serving[r].pop_front() {
                    self.tick(r);
                    self.merge_clock(caller, Seen::Robot(r));
                    self.vms[caller].remote_done(req, t);
                    self.requeue(caller);
                }
            }
            EventKind::Grip { site } => {
                let part = self.cell.linked.robots[r].parts[*site as usize] as usize;
                let name = &self.cell.parts[part].name;
                match self.collider.holder(part) {
                    None => {
                        let gap = self.collider.grip_gap(part, r, &self.vms, &self.cell, t);
                        let robot = &self.cell.robots[r];
                        if gap <= robot.grip_distance {
                            self.collider.grip(part, r, &self.vms, &self.cell, t);
                        } else {
                            let m = format!(
                                "cannot grip `{name}`: it is {:.2} mm from {}'s gripper (its TCP and its tool link's collision bodies), farther than grip_distance {}; move the tool to the part first, or set a larger `grip_distance` in the workcell",
                                gap * 1e3,
                                robot.name,
                                fmt_quantity(robot.grip_distance, Dim::LENGTH)
                            );
                            self.runtime_error(r, t, e.pos, m);
                        }
                    }
                    Some(h) if h == r => {
                        let m = format!(
                            "`{name}` is already in this robot's gripper; release it before gripping it again"
                        );
                        self.runtime_error(r, t, e.pos, m);
                    }
                    Some(h) => {
                        let m = format!(
                            "`{name}` is held by {}; it must release the part before this robot can grip it",
                            self.cell.robots[h].name
                        );
                        self.runtime_error(r, t, e.pos, m);
                    }
                }
            }
            EventKind::Release { site } => {
                let part = self.cell.linked.robots[r].parts[*site as usize] as usize;
                let name = &self.cell.parts[part].name;
                match self.collider.holder(part) {
                    Some(h) if h == r => self.collider.release(part, &self.vms, &self.cell, t),
                    Some(h) => {
                        let m = format!(
                            "this robot does not hold `{name}`: {} does; only the robot holding a part can release it",
                            self.cell.robots[h].name
                        );
                        self.runtime_error(r, t, e.pos, m);
                    }
                    None => {
                        let m = format!(
                            "this robot does not hold `{name}` (no robot does); grip it before releasing it"
                        );
                        self.runtime_error(r, t, e.pos, m);
                    }
                }
            }
            EventKind::Error { message } => {
                let issue = self.issue(IssueKind::Runtime, message.clone(), Some(r), Some(e.pos));
                self.errors.push(issue);
                self.outcome = Some(Outcome::Error);
            }
            _ => {}
        }
    }

    /// Robot `r` sets cell global `cg` to `value` at `t`.
    pub(super) fn on_set(&mut self, r: usize, cg: usize, value: u64, t: i64, pos: SrcPos) {
        self.check_race(cg, r, t, pos, true);
        if let Some((ot, q, qpos)) = self.last_timeout[cg]
            && ot == t
            && q != r
        {
            let name = &self.cell.linked.globals[cg].name;
            let subject = format!("on `{name}`");
            self.race(t, (q, qpos), (r, pos), &subject, "time out a wait and set it at the same instant; whether the set releases the wait depends on their order");
        }
        let stamp = self.tick(r);
        self.last_set[cg] = Some((t, r, pos, stamp));
        let n = self.vms.len();
        self.set_clock[cg * n..(cg + 1) * n].copy_from_slice(&self.clock[r * n..(r + 1) * n]);
        self.globals[cg].0 = value;
        for q in 0..self.vms.len() {
            if let Some(mg) = self.to_module[q][cg] {
                self.vms[q].set_global(mg, value);
            }
        }
        // check_wait / check_when for exactly the robots on this global's wait and when
        // lists, queued behind what is already due (in robot order, for determinism).
        // A robot whose check of this instant is still queued gets no second one: that
        // check comes after this set and tests the values it leaves (without this, checks
        // of robots taking turns piled up: 1,000 queued in a ring of 32).
        for i in 0..self.wait_list[cg].len() {
            let q = self.wait_list[cg].0[i];
            if self.check_pending[q].0 != Some(t) {
                self.check_pending[q].0 = Some(t);
                self.push(t, Entry::CheckWait(q, cg as u32));
            }
        }
        let mut last = None;
        for i in 0..self.when_list[cg].len() {
            let q = self.when_list[cg].0[i].0;
            if last != Some(q) {
                last = Some(q);
                if self.check_pending[q].1 != Some(t) {
                    self.check_pending[q].1 = Some(t);
                    self.push(t, Entry::CheckWhen(q, cg as u32));
                }
            }
        }
    }

    /// Robot `r` leaves the meeting it waits at, if any (its wait timed out, or its
    /// program or remote work ended while it waited): its arrival no longer counts.
    fn leave_sync(&mut self, r: usize) {
        if let Some(cs) = self.at_sync[r].take() {
            self.mark_arrived(cs, r, false);
        }
    }

    /// Whether member `r` of sync point `cs` has arrived at the meeting under way.
    fn mark_arrived(&mut self, cs: usize, r: usize, arrived: bool) {
        let members = &self.cell.linked.syncs[cs].members;
        if let Ok(k) = members.binary_search(&(r as u32)) {
            self.sync_arrived[cs][k] = arrived;
        }
    }

    /// Robot `r` arrives at the sync point of its sync site `site`: when every task of the
    /// list has arrived, the meeting is complete and all of them go on at `t` (each has
    /// seen every other's arrival).
    fn arrive(&mut self, r: usize, site: usize, t: i64, pos: SrcPos) {
        let cs = self.cell.linked.robots[r].syncs[site] as usize;
        let cell = Arc::clone(&self.cell);
        let members = &cell.linked.syncs[cs].members;
        self.mark_arrived(cs, r, true);
        self.at_sync[r] = Some(cs);
        self.tick(r);
        let name = || format!("at sync point `{}`", cell.linked.syncs[cs].name);
        const TIED: &str = "time out there and arrive at the same instant; whether they meet depends on their order";
        if let Some((ot, q, qpos)) = self.sync_timeout[cs]
            && ot == t
            && q != r
        {
            self.race(t, (q, qpos), (r, pos), &name(), TIED);
        }
        if !self.sync_arrived[cs].iter().all(|a| *a) {
            return;
        }
        // A task whose wait would time out at this very instant meets the others only
        // because this arrival came first.
        for q in members {
            let q = *q as usize;
            if q != r
                && self.vms[q].wait_deadline() == Some(t)
                && let Some((_, qpos)) = self.vms[q].waiting_for()
            {
                self.race(t, (q, qpos), (r, pos), &name(), TIED);
            }
        }
        self.sync_arrived[cs].iter_mut().for_each(|a| *a = false);
        // Every member has seen every arrival: the first gathers them all, the others
        // take its clock.
        let (first, rest) = members
            .split_first()
            .map_or((0, &[][..]), |(f, rest)| (*f as usize, rest));
        for p in rest {
            self.merge_clock(first, Seen::Robot(*p as usize));
        }
        for q in rest {
            self.merge_clock(*q as usize, Seen::Robot(first));
        }
        for q in members {
            let q = *q as usize;
            self.at_sync[q] = None;
            if self.vms[q].release_sync(t) {
                self.requeue(q);
            }
        }
    }

    /// Robot `r`'s entries in the WHEN list, made anew from its VM's enabled handlers.
    pub(super) fn sync_when_list(&mut self, r: usize) {
        for w in &mut self.when_list {
            w.retain(|(q, _)| *q != r);
        }
        let cell = Arc::clone(&self.cell);
        for (target, globals) in self.vms[r].condition_handlers() {
            for g in globals {
                let cg = cell.linked.robots[r].globals[*g as usize] as usize;
                self.when_list[cg].insert((r, target));
            }
        }
    }

    /// Robot `r` no longer waits: off the WAIT list.
    pub(super) fn clear_waits(&mut self, r: usize) {
        for w in &mut self.wait_list {
            w.remove(&r);
        }
    }

    /// A runtime error the SE finds in robot `r`'s event at `t` (a part gripped twice):
    /// an `error` event at the statement, and the run stops.
    pub(super) fn runtime_error(&mut self, r: usize, t: i64, pos: SrcPos, message: String) {
        self.error(t, Some(r), Some(pos), IssueKind::Runtime, message);
        self.vms[r].halt();
        self.outcome = Some(Outcome::Error);
    }
}
