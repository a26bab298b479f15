//! The paper's WAIT and WHEN lists ([`WaitLists`]): per cell global, the robots whose wait
//! condition reads it and the enabled condition handlers reading it, so that a `set`
//! queues `check_wait`/`check_when` for exactly those robots.

use super::queue::{Entry, EventQueue};

/// A small ordered set kept as a sorted `Vec`: iterated by index while the simulation
/// queues entries, in the same (ascending) order a `BTreeSet` would give.
#[derive(Clone, Debug)]
struct SortedSet<T>(Vec<T>);

impl<T> Default for SortedSet<T> {
    fn default() -> Self {
        SortedSet(Vec::new())
    }
}

impl<T: Ord + Copy> SortedSet<T> {
    fn insert(&mut self, x: T) {
        if let Err(i) = self.0.binary_search(&x) {
            self.0.insert(i, x);
        }
    }

    fn remove(&mut self, x: &T) {
        if let Ok(i) = self.0.binary_search(x) {
            self.0.remove(i);
        }
    }

    fn contains(&self, x: &T) -> bool {
        self.0.binary_search(x).is_ok()
    }
}

/// The WAIT and WHEN lists, and per robot the checks of the current instant still queued.
#[derive(Debug)]
pub(super) struct WaitLists {
    /// Per cell global: the robots whose wait condition reads it.
    wait: Vec<SortedSet<usize>>,
    /// Per cell global: the (robot, handler procedure) of each enabled condition handler
    /// reading it.
    when: Vec<SortedSet<(usize, u32)>>,
    /// Per robot: the instant of its `check_wait` and of its `check_when` still queued, if
    /// any (a set at that instant needs no second one: the queued check comes after it and
    /// tests the values it leaves).
    check_pending: Vec<(Option<i64>, Option<i64>)>,
}

impl WaitLists {
    /// Empty lists for `globals` cell globals and `robots` robots.
    pub(super) fn new(globals: usize, robots: usize) -> WaitLists {
        WaitLists {
            wait: vec![SortedSet::default(); globals],
            when: vec![SortedSet::default(); globals],
            check_pending: vec![(None, None); robots],
        }
    }

    /// Robot `r` waits on a condition reading cell global `cg`.
    pub(super) fn add_wait(&mut self, cg: usize, r: usize) {
        self.wait[cg].insert(r);
    }

    /// Robot `r` no longer waits: off the WAIT list.
    pub(super) fn clear_waits(&mut self, r: usize) {
        for w in &mut self.wait {
            w.remove(&r);
        }
    }

    /// Whether robot `r`'s wait is on cell global `cg`.
    pub(super) fn waits_on(&self, cg: usize, r: usize) -> bool {
        self.wait[cg].contains(&r)
    }

    /// Whether robot `r` waits on a condition (on any global).
    pub(super) fn waits_on_any(&self, r: usize) -> bool {
        self.wait.iter().any(|w| w.contains(&r))
    }

    /// How many cell globals the lists cover.
    pub(super) fn globals(&self) -> usize {
        self.wait.len()
    }

    /// Robot `r`'s condition handler `target` reads cell global `cg`.
    pub(super) fn add_when(&mut self, cg: usize, r: usize, target: u32) {
        self.when[cg].insert((r, target));
    }

    /// Robot `r`'s handler procedure `proc` was disabled.
    pub(super) fn remove_when(&mut self, r: usize, proc: u32) {
        for w in &mut self.when {
            w.remove(&(r, proc));
        }
    }

    /// Robot `r` has no enabled condition handlers.
    pub(super) fn clear_whens(&mut self, r: usize) {
        for w in &mut self.when {
            w.0.retain(|(q, _)| *q != r);
        }
    }

    /// Whether one of robot `r`'s enabled condition handlers reads cell global `cg`.
    pub(super) fn when_reads(&self, cg: usize, r: usize) -> bool {
        self.when[cg].0.iter().any(|(q, _)| *q == r)
    }

    /// Robot `r`'s `check_wait` came up.
    pub(super) fn wait_checked(&mut self, r: usize) {
        self.check_pending[r].0 = None;
    }

    /// Robot `r`'s `check_when` came up.
    pub(super) fn when_checked(&mut self, r: usize) {
        self.check_pending[r].1 = None;
    }

    /// Cell global `cg` was set at `t` (the simulated time being `now`): `check_wait` / `check_when` for exactly the robots
    /// on its wait and when lists, queued behind what is already due (in robot order, for
    /// determinism). A robot whose check of this instant is still queued gets no second
    /// one: that check comes after this set and tests the values it leaves (without this,
    /// checks of robots taking turns piled up: 1,000 queued in a ring of 32).
    pub(super) fn queue_checks(&mut self, cg: usize, t: i64, now: i64, queue: &mut EventQueue) {
        for &q in &self.wait[cg].0 {
            if self.check_pending[q].0 != Some(t) {
                self.check_pending[q].0 = Some(t);
                queue.push(t, Entry::CheckWait(q, cg as u32), now);
            }
        }
        let mut last = None;
        for &(q, _) in &self.when[cg].0 {
            if last != Some(q) {
                last = Some(q);
                if self.check_pending[q].1 != Some(t) {
                    self.check_pending[q].1 = Some(t);
                    queue.push(t, Entry::CheckWhen(q, cg as u32), now);
                }
            }
        }
    }
}
