//! Race warnings: a vector clock per robot records what each has seen of the others
//! (a robot sees another's actions when that robot's set, signal or remote work releases
//! it); two same-instant actions on one global, signal or remote robot that neither has
//! seen are a race — their order is only the queue's tie order.

use std::sync::Arc;

use vworks_vm::bytecode::SrcPos;
use vworks_vm::types::fmt_quantity;

use vworks_log::issue::IssueKind;

use super::Simulation;

/// Whose vector clock a released robot takes in (see [`Simulation::merge_clock`]).
#[derive(Clone, Copy, Debug)]
pub(super) enum Seen {
    /// A robot's, now.
    Robot(usize),
    /// The setter's, at the last set of this cell global.
    Set(usize),
}

impl Simulation {
    /// Robot `r`'s wait timed out at `t`: a race with a set (of a global its condition
    /// reads) or a signal (that it waits for) at the same instant, which would have
    /// released it had it come first. Remembers the timeout for a set or signal that
    /// comes after it at this instant.
    pub(super) fn timed_out_race(&mut self, r: usize, t: i64, pos: SrcPos) {
        // A condition reads at least one global (E0040), so a wait on none was for a signal.
        if !self.wait_list.iter().any(|w| w.0.contains(&r)) {
            if let Some((st, sender, spos, _)) = self.last_signal[r]
                && st == t
            {
                self.race(t, (sender, spos), (r, pos), "on a signal", "send it and time out a wait for it at the same instant; whether the signal releases the wait depends on their order");
            }
            self.signal_timeout[r] = Some((t, pos));
            return;
        }
        let n = self.vms.len();
        for cg in 0..self.wait_list.len() {
            if !self.wait_list[cg].0.contains(&r) {
                continue;
            }
            if let Some((st, setter, spos, stamp)) = self.last_set[cg]
                && st == t
                && setter != r
                && self.clock[r * n + setter] < stamp
            {
                let name = &self.cell.linked.globals[cg].name;
                let subject = format!("on `{name}`");
                self.race(t, (setter, spos), (r, pos), &subject, "set it and time out a wait on it at the same instant; whether the set releases the wait depends on their order");
            }
            self.last_timeout[cg] = Some((t, r, pos));
        }
    }

    /// Robot `r` acts: its own clock entry advances; returns it (the action's stamp).
    pub(super) fn tick(&mut self, r: usize) -> u64 {
        let n = self.vms.len();
        self.clock[r * n + r] += 1;
        self.clock[r * n + r]
    }

    /// Robot `r` has now seen what `from` records: what a robot had seen (its own actions
    /// included), or what the setter of a global had seen at its last set.
    pub(super) fn merge_clock(&mut self, r: usize, from: Seen) {
        let n = self.vms.len();
        for k in 0..n {
            let seen = match from {
                Seen::Robot(q) => self.clock[q * n + k],
                Seen::Set(cg) => self.set_clock[cg * n + k],
            };
            let mine = &mut self.clock[r * n + k];
            *mine = (*mine).max(seen);
        }
    }

    /// Robot `r` tested condition `c` of its module: it has seen the last set of every
    /// global the condition reads.
    pub(super) fn seen_condition(&mut self, r: usize, c: u32) {
        let cell = Arc::clone(&self.cell);
        for g in &cell.robots[r].module.conds[c as usize].globals {
            let cg = cell.linked.robots[r].globals[*g as usize] as usize;
            self.merge_clock(r, Seen::Set(cg));
        }
    }

    /// Warns of a race when another robot set (or, for a set, read in a wait that passed)
    /// global `cg` at this same instant and robot `r` has not seen that action: their order
    /// is only the queue's tie order. An action `r` has seen (it was released, directly or
    /// through others, by what followed it) comes first in every order: a handshake.
    pub(super) fn check_race(&mut self, cg: usize, r: usize, t: i64, pos: SrcPos, is_set: bool) {
        let n = self.vms.len();
        let others = [
            self.last_set[cg],
            if is_set { self.last_read[cg] } else { None },
        ];
        for (ot, or, opos, stamp) in others.into_iter().flatten() {
            if ot == t && or != r && self.clock[r * n + or] < stamp {
                let name = &self.cell.linked.globals[cg].name;
                let subject = format!("on `{name}`");
                self.race(
                    t,
                    (or, opos),
                    (r, pos),
                    &subject,
                    "touch it at the same instant; the outcome depends on their order",
                );
            }
        }
    }

    /// Reports a race at `t` between robot `first`'s statement and robot `second`'s (the
    /// one acting now): `race SUBJECT at T: A (file:pos) and B (file:pos) WHAT`.
    pub(super) fn race(
        &mut self,
        t: i64,
        first: (usize, SrcPos),
        second: (usize, SrcPos),
        subject: &str,
        what: &str,
    ) {
        let ((or, opos), (r, pos)) = (first, second);
        let m = format!(
            "race {subject} at {}: {} ({}:{}) and {} ({}:{}) {what}",
            fmt_quantity(t as f64 / 1e9, vworks_vm::Dim::TIME),
            self.cell.robots[or].name,
            self.short(or, opos),
            opos,
            self.cell.robots[r].name,
            self.short(r, pos),
            pos
        );
        self.warning(t, Some(r), Some(pos), IssueKind::Race, m);
    }

    /// The globals robot `r`'s last segment read at this instant: a race with a set of
    /// another robot at the same instant that `r` has not seen (either order), as for
    /// `wait_until` conditions.
    pub(super) fn note_reads(&mut self, r: usize) {
        if !self.vms[r].has_reads() {
            return;
        }
        let mut reads = std::mem::take(&mut self.reads);
        self.vms[r].take_reads(&mut reads);
        let (t, n) = (self.time, self.vms.len());
        for (mg, pos) in reads.drain(..) {
            let cg = self.cell.linked.robots[r].globals[mg as usize] as usize;
            self.check_race(cg, r, t, pos, false);
            // Seen by whoever has seen r's next action.
            let stamp = self.clock[r * n + r] + 1;
            self.last_read[cg] = Some((t, r, pos, stamp));
        }
        self.reads = reads;
    }
}
