//! The event queue: 24-byte entries ordered by (time, turn, tie rank, sequence), a robot's
//! entry made stale by a generation number when its next event changes, and the small
//! sorted sets behind the WAIT and WHEN lists.
//!
//! **Turns.** The zero-time work robots do at one instant runs as one serial order of the
//! robots, never interleaved (docs/engine.md, "One instant, one serial order"): the robot
//! whose entry the engine took last has the *turn*, and whatever it queues for itself at
//! that instant (its next event, its own `check_wait`/`check_when`) goes before every other
//! entry of the instant. A robot that must run code before it knows its next event (at the
//! start; see [`Vm::needs_turn`]) and is queued by another robot's turn gets a `Resume`
//! entry instead: its code runs when that entry comes up, in its own turn.

use std::cmp::Reverse;

use vworks_vm::machine::Next;

use super::Simulation;

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
    pub(super) fn pack(self) -> u64 {
        let (kind, r, payload) = match self {
            Entry::Vm(r, g) => (0, r, g),
            Entry::CheckWait(r, g) => (1, r, u64::from(g)),
            Entry::CheckWhen(r, g) => (2, r, u64::from(g)),
            Entry::Resume(r, g) => (3, r, g),
        };
        (payload << 24) | ((r as u64 & 0x3f_ffff) << 2) | kind
    }

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

/// A small ordered set kept as a sorted `Vec`: iterated by index while the simulation
/// queues entries, in the same (ascending) order a `BTreeSet` would give.
#[derive(Clone, Debug)]
pub(super) struct SortedSet<T>(pub(super) Vec<T>);

impl<T> Default for SortedSet<T> {
    fn default() -> Self {
        SortedSet(Vec::new())
    }
}

impl<T: Ord + Copy> SortedSet<T> {
    pub(super) fn insert(&mut self, x: T) {
        if let Err(i) = self.0.binary_search(&x) {
            self.0.insert(i, x);
        }
    }

    pub(super) fn remove(&mut self, x: &T) {
        if let Ok(i) = self.0.binary_search(x) {
            self.0.remove(i);
        }
    }

    pub(super) fn retain(&mut self, keep: impl FnMut(&T) -> bool) {
        self.0.retain(keep);
    }

    pub(super) fn len(&self) -> usize {
        self.0.len()
    }
}

impl Simulation {
    pub(super) fn push(&mut self, time: i64, entry: Entry) {
        self.seq += 1;
        let robot = entry.robot();
        let others = u64::from(!(self.turn == Some(robot) && time == self.time));
        self.queue.push(Reverse(Queued {
            time,
            key: (others << 63) | (self.rank[robot] << 44) | (self.seq & ((1 << 44) - 1)),
            entry: entry.pack(),
        }));
    }

    /// Breaks ties between robots' same-time entries by `rank` (a permutation) instead of
    /// queueing order. Each robot's own entries keep their order. For testing that no
    /// result depends on tie order.
    pub fn set_tie_ranks(&mut self, rank: Vec<u64>) {
        if rank.len() == self.rank.len() && rank.iter().all(|r| *r < 1 << 19) {
            self.rank = rank;
        }
    }

    /// (Re)queues robot `r`'s next event; the previous entry becomes stale.
    pub(super) fn requeue(&mut self, r: usize) {
        self.generation[r] += 1;
        self.queued_at[r] = None;
        if self.turn != Some(r) && self.vms[r].needs_turn() {
            // Its code reads the cell's globals: it runs in the robot's own turn.
            let g = self.generation[r];
            self.queued_at[r] = Some(self.time);
            self.pending[r] = None;
            self.push(self.time, Entry::Resume(r, g));
            return;
        }
        let next = self.vms[r].next_event();
        self.note_reads(r);
        if let Next::Event(e) = next {
            self.queued_at[r] = Some(e.time);
            let g = self.generation[r];
            self.push(e.time, Entry::Vm(r, g));
            // Kept for `perform`: the VM's next event cannot change without a requeue.
            self.pending[r] = Some(e);
        } else {
            self.pending[r] = None;
        }
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
