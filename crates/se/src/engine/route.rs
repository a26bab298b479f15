//! Routing a robot's event to the rest of the cell (the `Simulation`'s dispatcher, no
//! state of its own): a `set` updates every robot's copy of the global and queues
//! `check_wait`/`check_when` for exactly the robots on its WAIT and WHEN lists
//! ([`super::lists`]); signals are delivered, remote requests queued and answered
//! ([`super::remote`]), sync points met ([`super::sync`]), parts gripped and released
//! ([`crate::collide`]); runtime errors stop the run. What the events tell the race
//! detector ([`super::races`]) becomes race warnings here.

use vworks_log::issue::IssueKind;
use vworks_vm::Dim;
use vworks_vm::bytecode::{SrcPos, Trigger};
use vworks_vm::machine::{Event, EventKind};
use vworks_vm::types::fmt_quantity;

use super::races::{Seen, Subject};
use super::record::Recording;
use super::{Detail, Kind, Outcome, Simulation};

impl Simulation {
    /// Records robot `r`'s event `e` (performed) and routes it. A remote call's argument
    /// slots move to the serving robot's request: the recorded `remote_call` keeps its
    /// site and request number, its `args` empty (no consumer of the trace reads them).
    pub(super) fn route(&mut self, r: usize, e: &mut Event, kind: Kind) {
        let t = e.time;
        let args = match &mut e.kind {
            EventKind::RemoteCall { args, .. } => std::mem::take(args),
            _ => Vec::new(),
        };
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
                old: self.globals.value(cg as usize),
                new,
            },
            None => Detail::Vm(e.kind.clone()),
        };
        self.recording.record(t, Some(r), kind, detail, Some(e.pos));
        if let Some((cg, value)) = set {
            self.on_set(r, cg as usize, value, t, e.pos);
            return;
        }
        let cell = &*self.cell;
        match &e.kind {
            EventKind::WaitUntil { cond, .. } => {
                // A later set at this instant races with this read only if the wait passed
                // at once: a wait that blocks is re-tested by that set's check_wait at the
                // same instant, so either order releases it at the same time.
                let passed = !self.vms[r].waits();
                let stamp = self.races.tick(r);
                let to_cell = &cell.linked.robots[r].globals;
                let globals = &cell.robots[r].module.conds[*cond as usize].globals;
                if passed {
                    // A wait that passes on a value set earlier at this instant would, in
                    // the other order, have blocked and been released by that set's
                    // check_wait at the same instant: it follows the set either way.
                    for g in globals {
                        self.races
                            .merge(r, Seen::Set(to_cell[*g as usize] as usize));
                    }
                }
                for g in globals {
                    let cg = to_cell[*g as usize] as usize;
                    self.races.check(cg, r, t, e.pos, false);
                    if passed {
                        self.races.passed_read(cg, r, t, e.pos, stamp);
                    }
                    self.lists.add_wait(cg, r);
                }
            }
            EventKind::WaitEnd { timed_out } => {
                if *timed_out {
                    self.races.timed_out(r, t, e.pos, &self.lists);
                }
                self.lists.clear_waits(r);
                // A wait at a sync point that timed out: the task leaves the meeting.
                if *timed_out && let Some(cs) = self.syncs.waiting_at(r) {
                    self.races.sync_timed_out(cs, r, t, e.pos);
                }
                self.syncs.leave(cell, r);
            }
            EventKind::WaitSync { site, .. } => self.arrive(r, *site as usize, t, e.pos),
            EventKind::EnableWhen { handler } => {
                let h = &cell.robots[r].module.handlers[*handler as usize];
                if let Trigger::Condition(c) = h.trigger {
                    for g in &cell.robots[r].module.conds[c as usize].globals {
                        let cg = cell.linked.robots[r].globals[*g as usize] as usize;
                        self.lists.add_when(cg, r, h.target);
                    }
                }
            }
            EventKind::DisableWhen { proc } => self.lists.remove_when(r, *proc),
            EventKind::End => {
                self.lists.clear_whens(r);
                // (`stop` in a handler may end a wait, a wait at a sync point too.)
                self.lists.clear_waits(r);
                self.syncs.leave(cell, r);
            }
            EventKind::Signal { site } => {
                let (target, idx) = self.signal_to[r][*site as usize];
                let to = &self.vms[target];
                let timing_out =
                    to.wait_deadline() == Some(t) && idx.is_some() && to.waited_signal() == idx;
                let waiting = timing_out
                    .then(|| to.waiting_for().map(|(_, p)| p))
                    .flatten();
                self.races.signal(r, target, t, e.pos, waiting);
                if let Some(idx) = idx
                    && self.vms[target].deliver_signal_index(idx, t)
                {
                    // The receiver, released, has seen what the sender had.
                    self.races.merge(target, Seen::Robot(r));
                    self.requeue(target);
                }
            }
            EventKind::RemoteCall { site, req, .. } => {
                let (target, proc) = cell.linked.robots[r].remotes[*site as usize];
                let target = target as usize;
                self.races.request(r, target, t, e.pos);
                self.vms[target].request_remote(proc, args, t);
                self.remotes.request(target, r, *req);
                if self.queue.queued_at(target).is_none() {
                    self.requeue(target);
                }
            }
            EventKind::RemoteEnd { .. } => {
                // The handlers the remote work enabled ended with it.
                self.lists.clear_whens(r);
                let to_cell = &cell.linked.robots[r].globals;
                for (target, globals) in self.vms[r].condition_handlers() {
                    for g in globals {
                        self.lists
                            .add_when(to_cell[*g as usize] as usize, r, target);
                    }
                }
                self.lists.clear_waits(r);
                self.syncs.leave(cell, r);
                if let Some((caller, req)) = self.remotes.served(r) {
                    self.races.tick(r);
                    self.races.merge(caller, Seen::Robot(r));
                    self.vms[caller].remote_done(req, t);
                    self.requeue(caller);
                }
            }
            EventKind::Grip { site } => self.grip(r, *site as usize, t, e.pos),
            EventKind::Release { site } => self.release(r, *site as usize, t, e.pos),
            EventKind::Error { message } => {
                let issue = Recording::issue(
                    cell,
                    IssueKind::Runtime,
                    message.clone(),
                    Some(r),
                    Some(e.pos),
                );
                self.recording.vm_error(issue);
                self.outcome = Some(Outcome::Error);
            }
            _ => {}
        }
        self.report_races();
    }

    /// The races the detector found since, as warnings (in the order found).
    #[inline]
    pub(super) fn report_races(&mut self) {
        if self.races.has_races() {
            self.word_races();
        }
    }

    /// [`Simulation::report_races`] once there are some (kept out of the hot path).
    fn word_races(&mut self) {
        let cell = &*self.cell;
        for race in self.races.take_races() {
            let subject = match race.subject {
                Subject::Global(cg) => format!("on `{}`", cell.linked.globals[cg].name),
                Subject::Signal => "on a signal".to_string(),
                Subject::RemoteWork(target) => {
                    format!("for {}'s remote work", cell.robots[target].name)
                }
                Subject::SyncPoint(cs) => format!("at sync point `{}`", cell.linked.syncs[cs].name),
            };
            let ((or, opos), (r, pos)) = (race.first, race.second);
            let short = |r: usize, pos: SrcPos| cell.robots[r].module.file_name_of(pos);
            let m = format!(
                "race {subject} at {}: {} ({}:{}) and {} ({}:{}) {}",
                fmt_quantity(race.time as f64 / 1e9, Dim::TIME),
                cell.robots[or].name,
                short(or, opos),
                opos,
                cell.robots[r].name,
                short(r, pos),
                pos,
                race.what
            );
            self.recording
                .warning(cell, race.time, Some(r), Some(pos), IssueKind::Race, m);
        }
    }

    /// Robot `r` sets cell global `cg` to `value` at `t`.
    pub(super) fn on_set(&mut self, r: usize, cg: usize, value: u64, t: i64, pos: SrcPos) {
        self.races.set(cg, r, t, pos);
        self.report_races();
        self.globals.set(cg, value, &mut self.vms);
        self.lists.queue_checks(cg, t, self.time, &mut self.queue);
    }

    /// Robot `r` arrives at the sync point of its sync site `site`: when every task of the
    /// list has arrived, the meeting is complete and all of them go on at `t` (each has
    /// seen every other's arrival).
    fn arrive(&mut self, r: usize, site: usize, t: i64, pos: SrcPos) {
        let cell = &*self.cell;
        let cs = cell.linked.robots[r].syncs[site] as usize;
        let members = &cell.linked.syncs[cs].members;
        let complete = self.syncs.arrive(cell, cs, r);
        self.races.arrive(cs, r, t, pos);
        if !complete {
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
                self.races.met_at_deadline(cs, (q, qpos), (r, pos), t);
            }
        }
        self.report_races();
        let cell = &*self.cell;
        let members = &cell.linked.syncs[cs].members;
        self.syncs.release(cell, cs);
        // Every member has seen every arrival: the first gathers them all, the others
        // take its clock.
        let (first, rest) = members
            .split_first()
            .map_or((0, &[][..]), |(f, rest)| (*f as usize, rest));
        for p in rest {
            self.races.merge(first, Seen::Robot(*p as usize));
        }
        for q in rest {
            self.races.merge(*q as usize, Seen::Robot(first));
        }
        for k in 0..members.len() {
            let q = self.cell.linked.syncs[cs].members[k] as usize;
            if self.vms[q].release_sync(t) {
                self.requeue(q);
            }
        }
    }

    /// Robot `r` grips the part of its grip site `site` at `t` (the statement at `pos`).
    fn grip(&mut self, r: usize, site: usize, t: i64, pos: SrcPos) {
        let cell = &*self.cell;
        let part = cell.linked.robots[r].parts[site] as usize;
        let name = &cell.parts[part].name;
        let collider = self.boundaries.collider_mut();
        let m = match collider.holder(part) {
            None => {
                let gap = collider.grip_gap(part, r, &self.vms, cell, t);
                let robot = &cell.robots[r];
                if gap <= robot.grip_distance {
                    collider.grip(part, r, &self.vms, cell, t);
                    return;
                }
                format!(
                    "cannot grip `{name}`: it is {:.2} mm from {}'s gripper (its TCP and its tool link's collision bodies), farther than grip_distance {}; move the tool to the part first, or set a larger `grip_distance` in the workcell",
                    gap * 1e3,
                    robot.name,
                    fmt_quantity(robot.grip_distance, Dim::LENGTH)
                )
            }
            Some(h) if h == r => format!(
                "`{name}` is already in this robot's gripper; release it before gripping it again"
            ),
            Some(h) => format!(
                "`{name}` is held by {}; it must release the part before this robot can grip it",
                cell.robots[h].name
            ),
        };
        self.runtime_error(r, t, pos, m);
    }

    /// Robot `r` releases the part of its release site `site` at `t` (the statement at
    /// `pos`).
    fn release(&mut self, r: usize, site: usize, t: i64, pos: SrcPos) {
        let cell = &*self.cell;
        let part = cell.linked.robots[r].parts[site] as usize;
        let name = &cell.parts[part].name;
        let collider = self.boundaries.collider_mut();
        let m = match collider.holder(part) {
            Some(h) if h == r => {
                collider.release(part, &self.vms, cell, t);
                return;
            }
            Some(h) => format!(
                "this robot does not hold `{name}`: {} does; only the robot holding a part can release it",
                cell.robots[h].name
            ),
            None => format!(
                "this robot does not hold `{name}` (no robot does); grip it before releasing it"
            ),
        };
        self.runtime_error(r, t, pos, m);
    }

    /// A runtime error the SE finds in robot `r`'s event at `t` (a part gripped twice):
    /// an `error` event at the statement, and the run stops.
    fn runtime_error(&mut self, r: usize, t: i64, pos: SrcPos, message: String) {
        self.recording.error(
            &self.cell,
            t,
            Some(r),
            Some(pos),
            IssueKind::Runtime,
            message,
        );
        self.vms[r].halt();
        self.outcome = Some(Outcome::Error);
    }
}
