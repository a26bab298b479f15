//! Sync points ([`SyncPoints`], RAPID's `WaitSyncTask`): per sync point of the cell, which
//! of its tasks have arrived at the meeting under way, and per robot the sync point it
//! waits at.

use vworks_cell::Cell;

/// The meetings under way at the cell's sync points.
#[derive(Debug)]
pub(super) struct SyncPoints {
    /// Per sync point of the cell (`Linked::syncs`), per member: whether it has arrived at
    /// the meeting under way.
    arrived: Vec<Vec<bool>>,
    /// Per robot: the sync point it waits at.
    at: Vec<Option<usize>>,
}

impl SyncPoints {
    /// No meeting under way at any sync point of `cell`.
    pub(super) fn new(cell: &Cell) -> SyncPoints {
        SyncPoints {
            arrived: cell
                .linked
                .syncs
                .iter()
                .map(|s| vec![false; s.members.len()])
                .collect(),
            at: vec![None; cell.robots.len()],
        }
    }

    /// The sync point robot `r` waits at, if any.
    pub(super) fn waiting_at(&self, r: usize) -> Option<usize> {
        self.at[r]
    }

    /// Whether member `r` of sync point `cs` has arrived at the meeting under way.
    fn mark_arrived(&mut self, cell: &Cell, cs: usize, r: usize, arrived: bool) {
        let members = &cell.linked.syncs[cs].members;
        if let Ok(k) = members.binary_search(&(r as u32)) {
            self.arrived[cs][k] = arrived;
        }
    }

    /// Robot `r` leaves the meeting it waits at, if any (its wait timed out, or its
    /// program or remote work ended while it waited): its arrival no longer counts.
    pub(super) fn leave(&mut self, cell: &Cell, r: usize) {
        if let Some(cs) = self.at[r].take() {
            self.mark_arrived(cell, cs, r, false);
        }
    }

    /// Robot `r` arrives at sync point `cs`; true when every task of its list has arrived
    /// (the meeting is complete: see [`SyncPoints::release`]).
    pub(super) fn arrive(&mut self, cell: &Cell, cs: usize, r: usize) -> bool {
        self.mark_arrived(cell, cs, r, true);
        self.at[r] = Some(cs);
        self.arrived[cs].iter().all(|a| *a)
    }

    /// The meeting at sync point `cs` is complete: its members no longer wait there, and
    /// the next meeting starts with no one arrived.
    pub(super) fn release(&mut self, cell: &Cell, cs: usize) {
        self.arrived[cs].iter_mut().for_each(|a| *a = false);
        for q in &cell.linked.syncs[cs].members {
            self.at[*q as usize] = None;
        }
    }

    /// A sync point and the tasks of its list that have not arrived at its meeting.
    pub(super) fn missing(&self, cell: &Cell, cs: usize) -> String {
        let sync = &cell.linked.syncs[cs];
        let missing: Vec<String> = sync
            .members
            .iter()
            .zip(&self.arrived[cs])
            .filter(|(_, arrived)| !**arrived)
            .map(|(q, _)| {
                let robot = &cell.robots[*q as usize];
                if robot.task == robot.name {
                    format!("`{}`", robot.name)
                } else {
                    format!("`{}` (robot {})", robot.task, robot.name)
                }
            })
            .collect();
        format!(
            "the other tasks at sync point `{}`; never arrived: {}",
            sync.name,
            missing.join(", ")
        )
    }
}
