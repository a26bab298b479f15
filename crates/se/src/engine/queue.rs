//! The event queue ([`EventQueue`]): 24-byte entries ordered by (time, turn, tie rank,
//! sequence), a robot's entry made stale by a generation number when its next event
//! changes.
//!
//! **Turns.** The zero-time work robots do at one instant runs as one serial order of the
//! robots, never interleaved (docs/engine.md, "One instant, one serial order"): the robot
//! whose entry the engine took last has the *turn*, and whatever it queues for itself at
//! that instant (its next event, its own `check_wait`/`check_when`) goes before every other
//! entry of the instant. A robot that must run code before it knows its next event (at the
//! start; see `Vm::needs_turn`) and is queued by another robot's turn gets a `Resume`
//! entry instead: its code runs when that entry comes up, in its own turn.

use std::cmp::Reverse;
use std::collections::BinaryHeap;

use vworks_vm::machine::Event;

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Entry {
    /// The robot's next event (robot, generation).
    Vm(usize, u64),
    /// Re-test the robot's wait condition after a set of a global (cell index).
    CheckWait(usize, u32),
    /// Re-test the robot's condition handlers after a set of a global (cell index).
    CheckWhen(usize, u32),
    /// Run the robot's zero-time code in its own turn, then queue the event it stops
    /// before (robot, generation).
    Resume(usize, u64),
}

impl Entry {
    /// The entry in 64 bits: kind (2 bits), robot (22 bits), generation or global (40
    /// bits), so that a queued entry is 24 bytes.
    #[inline]
    pub(super) fn pack(self) -> u64 {
        let (kind, r, payload) = match self {
            Entry::Vm(r, g) => (0, r, g),
            Entry::CheckWait(r, g) => (1, r, u64::from(g)),
            Entry::CheckWhen(r, g) => (2, r, u64::from(g)),
            Entry::Resume(r, g) => (3, r, g),
        };
        (payload << 24) | ((r as u64 & 0x3f_ffff) << 2) | kind
    }

    #[inline]
    pub(super) fn unpack(x: u64) -> Entry {
        let (r, payload) = (((x >> 2) & 0x3f_ffff) as usize, x >> 24);
        match x & 3 {
            0 => Entry::Vm(r, payload),
            1 => Entry::CheckWait(r, payload as u32),
            2 => Entry::CheckWhen(r, payload as u32),
            _ => Entry::Resume(r, payload),
        }
    }

    /// The robot the entry is for.
    #[inline]
    pub(super) fn robot(self) -> usize {
        match self {
            Entry::Vm(r, _) | Entry::CheckWait(r, _) | Entry::CheckWhen(r, _) => r,
            Entry::Resume(r, _) => r,
        }
    }
}

/// An event-queue entry: the earliest time first, then by `key` (the turn's own entries
/// first, then the robot's tie rank, then the order queued), 24 bytes.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub(super) struct Queued {
    pub(super) time: i64,
    /// Not the turn's (top bit: 0 for an entry the robot whose turn it is queued for itself
    /// at the current instant), tie rank (19 bits) and sequence number (low 44 bits).
    pub(super) key: u64,
    pub(super) entry: u64,
}

/// The event queue: the entries in order, and per robot what its queue entry stands for.
/// A robot's entry becomes stale when its next event changes: it carries the robot's
/// generation at the time it was queued, and a requeue starts a new generation.
#[derive(Debug)]
pub(super) struct EventQueue {
    heap: BinaryHeap<Reverse<Queued>>,
    /// Sequence number of the last entry queued.
    seq: u64,
    /// Tie-break rank per robot for same-time entries of different robots (all 0 normally:
    /// first queued, first served). Tests permute it to prove the results do not depend on it.
    rank: Vec<u64>,
    generation: Vec<u64>,
    /// Per robot: the time of its `Vm` or `Resume` entry, while one is queued.
    queued_at: Vec<Option<i64>>,
    /// Per robot: the event its queue entry stands for, as its VM gave it at the requeue
    /// (so performing it does not ask the VM again).
    pending: Vec<Option<Event>>,
    /// The robot whose turn it is at the current instant: the entries it queues for itself
    /// at that instant go before every other (see the module docs).
    turn: Option<usize>,
}

impl EventQueue {
    /// An empty queue for `robots` robots.
    pub(super) fn new(robots: usize) -> EventQueue {
        EventQueue {
            heap: BinaryHeap::new(),
            seq: 0,
            rank: vec![0; robots],
            generation: vec![0; robots],
            queued_at: vec![None; robots],
            pending: vec![None; robots],
            turn: None,
        }
    }

    /// Queues `entry` at `time`; `now` is the simulated time (an entry of the robot whose
    /// turn it is, at `now`, goes first).
    #[inline]
    pub(super) fn push(&mut self, time: i64, entry: Entry, now: i64) {
        self.seq += 1;
        let robot = entry.robot();
        let others = u64::from(!(self.turn == Some(robot) && time == now));
        self.heap.push(Reverse(Queued {
            time,
            key: (others << 63) | (self.rank[robot] << 44) | (self.seq & ((1 << 44) - 1)),
            entry: entry.pack(),
        }));
    }

    /// The time of the earliest entry, stale or not.
    #[inline]
    pub(super) fn next_time(&self) -> Option<i64> {
        self.heap.peek().map(|Reverse(q)| q.time)
    }

    /// Takes the earliest entry: its time and the entry.
    #[inline]
    pub(super) fn pop(&mut self) -> Option<(i64, Entry)> {
        self.heap
            .pop()
            .map(|Reverse(q)| (q.time, Entry::unpack(q.entry)))
    }

    /// Whether `entry` stands for an event its robot no longer has next.
    #[inline]
    pub(super) fn is_stale(&self, entry: Entry) -> bool {
        matches!(entry, Entry::Vm(r, g) | Entry::Resume(r, g) if g != self.generation[r])
    }

    /// Breaks ties between robots' same-time entries by `rank` (a permutation, each below
    /// 2^19) instead of queueing order; anything else is ignored.
    pub(super) fn set_tie_ranks(&mut self, rank: Vec<u64>) {
        if rank.len() == self.rank.len() && rank.iter().all(|r| *r < 1 << 19) {
            self.rank = rank;
        }
    }

    /// The robot whose turn it is.
    #[inline]
    pub(super) fn turn(&self) -> Option<usize> {
        self.turn
    }

    /// Gives the turn to `robot` (`None`: to no robot).
    #[inline]
    pub(super) fn set_turn(&mut self, robot: Option<usize>) {
        self.turn = robot;
    }

    /// When robot `r`'s entry is due, while one is queued.
    #[inline]
    pub(super) fn queued_at(&self, r: usize) -> Option<i64> {
        self.queued_at[r]
    }

    /// Robot `r`'s entry came up (or was dropped): none is queued.
    #[inline]
    pub(super) fn taken(&mut self, r: usize) {
        self.queued_at[r] = None;
    }

    /// Starts robot `r`'s new generation: its queued entry, if any, becomes stale.
    /// Returns the generation.
    #[inline]
    pub(super) fn renew(&mut self, r: usize) -> u64 {
        self.generation[r] += 1;
        self.queued_at[r] = None;
        self.pending[r] = None;
        self.generation[r]
    }

    /// Queues robot `r`'s entry of generation `g` for `event` (kept for `take_pending`), or,
    /// without an event, a `Resume` at `now`.
    #[inline]
    pub(super) fn queue_robot(&mut self, r: usize, g: u64, event: Option<Event>, now: i64) {
        match event {
            Some(e) => {
                self.queued_at[r] = Some(e.time);
                self.push(e.time, Entry::Vm(r, g), now);
                self.pending[r] = Some(e);
            }
            None => {
                self.queued_at[r] = Some(now);
                self.push(now, Entry::Resume(r, g), now);
            }
        }
    }

    /// The event robot `r`'s entry stands for (taken: performed once).
    #[inline]
    pub(super) fn take_pending(&mut self, r: usize) -> Option<Event> {
        self.pending[r].take()
    }
}

#[cfg(test)]
mod tests {
    use super::Entry;

    #[test]
    fn queue_entries_pack_into_64_bits_and_back() {
        for e in [
            Entry::Vm(0, 0),
            Entry::Vm(3, 1 << 39),
            Entry::Vm((1 << 22) - 1, 12_345),
            Entry::CheckWait(7, u32::MAX),
            Entry::CheckWhen(63, 5),
            Entry::CheckWait(0, 0),
            Entry::Resume(9, 1 << 39),
        ] {
            assert_eq!(Entry::unpack(e.pack()), e);
        }
    }
}
