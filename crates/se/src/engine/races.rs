//! Race detection ([`RaceDetector`]): a vector clock per robot records what each has seen
//! of the others (a robot sees another's actions when that robot's set, signal or remote
//! work releases it); two same-instant actions on one global, signal, remote robot or sync
//! point that neither has seen are a race — their order is only the queue's tie order.
//! The detector finds races; the simulation words them as warnings ([`Race`]).

use vworks_vm::bytecode::SrcPos;
use vworks_vm::machine::Vm;

use super::lists::WaitLists;

/// Whose vector clock a released robot takes in (see [`RaceDetector::merge`]).
#[derive(Clone, Copy, Debug)]
pub(super) enum Seen {
    /// A robot's, now.
    Robot(usize),
    /// The setter's, at the last set of this cell global.
    Set(usize),
}

/// What two robots raced on.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) enum Subject {
    /// A cell global.
    Global(usize),
    /// A signal.
    Signal,
    /// A robot's remote work.
    RemoteWork(usize),
    /// A sync point of the cell.
    SyncPoint(usize),
}

/// A race found at `time` between robot `first`'s statement and robot `second`'s (the one
/// acting now): `race SUBJECT at T: A (file:pos) and B (file:pos) WHAT`.
#[derive(Clone, Copy, Debug)]
pub(super) struct Race {
    pub(super) time: i64,
    pub(super) first: (usize, SrcPos),
    pub(super) second: (usize, SrcPos),
    pub(super) subject: Subject,
    /// What they did, after the two statements.
    pub(super) what: &'static str,
}

/// An action another robot may race with: (time, robot, position, the robot's own clock
/// entry at that action).
type Action = Option<(i64, usize, SrcPos, u64)>;

/// The vector clocks and the last actions of every kind that can race, and the races found
/// and not yet reported.
#[derive(Debug)]
pub(super) struct RaceDetector {
    /// How many robots.
    robots: usize,
    /// Happens-before: a vector clock per robot (`clock[r * n + q]`: how many of robot q's
    /// actions robot r has seen, directly or through others).
    clock: Vec<u64>,
    /// Per cell global: the setter's clock at the last set (what a robot it releases sees).
    set_clock: Vec<u64>,
    /// Per cell global: the last set and the last condition read at a wait start that
    /// passed at once.
    last_set: Vec<Action>,
    last_read: Vec<Action>,
    /// Per robot: the last remote request made to it.
    last_request: Vec<Action>,
    /// Per robot: the last signal sent to it, and the last time one of its signal waits
    /// timed out (time, position).
    last_signal: Vec<Action>,
    signal_timeout: Vec<Option<(i64, SrcPos)>>,
    /// Per cell global: the last wait on it that timed out (time, robot, position).
    last_timeout: Vec<Option<(i64, usize, SrcPos)>>,
    /// Per sync point: the last wait there that timed out (time, robot, position).
    sync_timeout: Vec<Option<(i64, usize, SrcPos)>>,
    /// Reads of globals a robot's segment made (reused; see [`Vm::take_reads`]).
    reads: Vec<(u32, SrcPos)>,
    /// Races found, in order, not yet reported (reused).
    found: Vec<Race>,
}

const TOUCH: &str = "touch it at the same instant; the outcome depends on their order";
const SYNC_TIED: &str =
    "time out there and arrive at the same instant; whether they meet depends on their order";

impl RaceDetector {
    /// A detector for `robots` robots, `globals` cell globals and `syncs` sync points, no
    /// robot having seen anything.
    pub(super) fn new(robots: usize, globals: usize, syncs: usize) -> RaceDetector {
        RaceDetector {
            robots,
            clock: vec![0; robots * robots],
            set_clock: vec![0; globals * robots],
            last_set: vec![None; globals],
            last_read: vec![None; globals],
            last_request: vec![None; robots],
            last_signal: vec![None; robots],
            signal_timeout: vec![None; robots],
            last_timeout: vec![None; globals],
            sync_timeout: vec![None; syncs],
            reads: Vec::new(),
            found: Vec::new(),
        }
    }

    /// The races found since the last call, in the order found.
    pub(super) fn take_races(&mut self) -> std::vec::Drain<'_, Race> {
        self.found.drain(..)
    }

    /// Whether races were found and not yet taken.
    #[inline]
    pub(super) fn has_races(&self) -> bool {
        !self.found.is_empty()
    }

    /// Reports a race found outside the detector.
    fn report(
        &mut self,
        time: i64,
        first: (usize, SrcPos),
        second: (usize, SrcPos),
        subject: Subject,
        what: &'static str,
    ) {
        self.found.push(Race {
            time,
            first,
            second,
            subject,
            what,
        });
    }

    /// Robot `r` acts: its own clock entry advances; returns it (the action's stamp).
    #[inline]
    pub(super) fn tick(&mut self, r: usize) -> u64 {
        let n = self.robots;
        self.clock[r * n + r] += 1;
        self.clock[r * n + r]
    }

    /// Whether robot `r` has seen the action of robot `q` stamped `stamp`.
    #[inline]
    fn has_seen(&self, r: usize, q: usize, stamp: u64) -> bool {
        self.clock[r * self.robots + q] >= stamp
    }

    /// Robot `r` has now seen what `from` records: what a robot had seen (its own actions
    /// included), or what the setter of a global had seen at its last set.
    #[inline]
    pub(super) fn merge(&mut self, r: usize, from: Seen) {
        let n = self.robots;
        for k in 0..n {
            let seen = match from {
                Seen::Robot(q) => self.clock[q * n + k],
                Seen::Set(cg) => self.set_clock[cg * n + k],
            };
            let mine = &mut self.clock[r * n + k];
            *mine = (*mine).max(seen);
        }
    }

    /// Warns of a race when another robot set (or, for a set, read in a wait that passed)
    /// global `cg` at this same instant and robot `r` has not seen that action: their order
    /// is only the queue's tie order. An action `r` has seen (it was released, directly or
    /// through others, by what followed it) comes first in every order: a handshake.
    pub(super) fn check(&mut self, cg: usize, r: usize, t: i64, pos: SrcPos, is_set: bool) {
        let others = [
            self.last_set[cg],
            if is_set { self.last_read[cg] } else { None },
        ];
        for (ot, or, opos, stamp) in others.into_iter().flatten() {
            if ot == t && or != r && !self.has_seen(r, or, stamp) {
                self.report(t, (or, opos), (r, pos), Subject::Global(cg), TOUCH);
            }
        }
    }

    /// Robot `r`'s wait condition read cell global `cg` at `t` and passed at once (its
    /// action stamped `stamp`): a later set at this instant races with it.
    pub(super) fn passed_read(&mut self, cg: usize, r: usize, t: i64, pos: SrcPos, stamp: u64) {
        self.last_read[cg] = Some((t, r, pos, stamp));
    }

    /// Robot `r` sets cell global `cg` at `t`: races with the same instant's sets, reads
    /// and wait timeouts on it; the setter's clock goes with the value.
    pub(super) fn set(&mut self, cg: usize, r: usize, t: i64, pos: SrcPos) {
        self.check(cg, r, t, pos, true);
        if let Some((ot, q, qpos)) = self.last_timeout[cg]
            && ot == t
            && q != r
        {
            self.report(t, (q, qpos), (r, pos), Subject::Global(cg), "time out a wait and set it at the same instant; whether the set releases the wait depends on their order");
        }
        let stamp = self.tick(r);
        self.last_set[cg] = Some((t, r, pos, stamp));
        let n = self.robots;
        self.set_clock[cg * n..(cg + 1) * n].copy_from_slice(&self.clock[r * n..(r + 1) * n]);
    }

    /// Robot `r`'s wait timed out at `t`: a race with a set (of a global its condition
    /// reads, by the WAIT list `lists`) or a signal (that it waits for) at the same
    /// instant, which would have released it had it come first. Remembers the timeout for
    /// a set or signal that comes after it at this instant.
    pub(super) fn timed_out(&mut self, r: usize, t: i64, pos: SrcPos, lists: &WaitLists) {
        // A condition reads at least one global (E0040), so a wait on none was for a signal.
        if !lists.waits_on_any(r) {
            if let Some((st, sender, spos, _)) = self.last_signal[r]
                && st == t
            {
                self.report(t, (sender, spos), (r, pos), Subject::Signal, "send it and time out a wait for it at the same instant; whether the signal releases the wait depends on their order");
            }
            self.signal_timeout[r] = Some((t, pos));
            return;
        }
        for cg in 0..lists.globals() {
            if !lists.waits_on(cg, r) {
                continue;
            }
            if let Some((st, setter, spos, stamp)) = self.last_set[cg]
                && st == t
                && setter != r
                && !self.has_seen(r, setter, stamp)
            {
                self.report(t, (setter, spos), (r, pos), Subject::Global(cg), "set it and time out a wait on it at the same instant; whether the set releases the wait depends on their order");
            }
            self.last_timeout[cg] = Some((t, r, pos));
        }
    }

    /// Robot `r` signals robot `target` at `t`. `waiting`: where `target` waits for the
    /// signal with a wait timing out at this instant, if it does: that timeout (or one
    /// already passed at this instant) races with the signal.
    #[inline]
    pub(super) fn signal(
        &mut self,
        r: usize,
        target: usize,
        t: i64,
        pos: SrcPos,
        waiting: Option<SrcPos>,
    ) {
        let stamp = self.tick(r);
        let timed_out = self.signal_timeout[target]
            .filter(|(ot, _)| *ot == t)
            .map(|(_, p)| p);
        if let Some(wpos) = timed_out.or(waiting) {
            self.report(t, (target, wpos), (r, pos), Subject::Signal, "time out a wait for it and send it at the same instant; whether the signal releases the wait depends on their order");
        }
        self.last_signal[target] = Some((t, r, pos, stamp));
    }

    /// Robot `r` asks robot `target` for remote work at `t`. Two requests to one robot at
    /// one instant: which it serves first is only the queue's tie order (a request made
    /// after seeing the other's is not).
    pub(super) fn request(&mut self, r: usize, target: usize, t: i64, pos: SrcPos) {
        let stamp = self.tick(r);
        if let Some((ot, or, opos, ostamp)) = self.last_request[target]
            && ot == t
            && or != r
            && !self.has_seen(r, or, ostamp)
        {
            self.report(t, (or, opos), (r, pos), Subject::RemoteWork(target), "ask for it at the same instant; which request it serves first depends on their order");
        }
        self.last_request[target] = Some((t, r, pos, stamp));
    }

    /// Robot `r`'s wait at sync point `cs` timed out at `t`.
    pub(super) fn sync_timed_out(&mut self, cs: usize, r: usize, t: i64, pos: SrcPos) {
        self.sync_timeout[cs] = Some((t, r, pos));
    }

    /// Robot `r` arrives at sync point `cs` at `t`: a race with a wait there that timed out
    /// at this instant.
    pub(super) fn arrive(&mut self, cs: usize, r: usize, t: i64, pos: SrcPos) {
        self.tick(r);
        if let Some((ot, q, qpos)) = self.sync_timeout[cs]
            && ot == t
            && q != r
        {
            self.report(t, (q, qpos), (r, pos), Subject::SyncPoint(cs), SYNC_TIED);
        }
    }

    /// Robot `r`'s arrival completes the meeting at sync point `cs` at `t`, while robot
    /// `q`'s wait there (at `qpos`) would time out at this very instant: it meets the
    /// others only because this arrival came first.
    pub(super) fn met_at_deadline(
        &mut self,
        cs: usize,
        q: (usize, SrcPos),
        r: (usize, SrcPos),
        t: i64,
    ) {
        self.report(t, q, r, Subject::SyncPoint(cs), SYNC_TIED);
    }

    /// The globals robot `r`'s last segment read at this instant `t` (its VM `vm`; module
    /// global → cell global `to_cell`): a race with a set of another robot at the same
    /// instant that `r` has not seen (either order), as for `wait_until` conditions.
    #[inline]
    pub(super) fn note_reads(&mut self, r: usize, t: i64, vm: &mut Vm, to_cell: &[u32]) {
        if vm.has_reads() {
            self.note_taken_reads(r, t, vm, to_cell);
        }
    }

    /// [`RaceDetector::note_reads`] once the VM has reads (kept out of the hot path).
    fn note_taken_reads(&mut self, r: usize, t: i64, vm: &mut Vm, to_cell: &[u32]) {
        let mut reads = std::mem::take(&mut self.reads);
        vm.take_reads(&mut reads);
        let n = self.robots;
        for (mg, pos) in reads.drain(..) {
            let cg = to_cell[mg as usize] as usize;
            self.check(cg, r, t, pos, false);
            // Seen by whoever has seen r's next action.
            let stamp = self.clock[r * n + r] + 1;
            self.last_read[cg] = Some((t, r, pos, stamp));
        }
        self.reads = reads;
    }
}
