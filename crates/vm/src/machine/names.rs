//! The names the run gives the VM's events and warnings: [`EVENT_NAMES`], the one table of
//! the event kinds' names (`vworks_log`'s `Kind` takes them from it), and [`WarningKind`].

use super::EventKind;

/// The names of the VM's event kinds in traces and logs, by [`EventKind::index`]: the one
/// table of these names (the run's vocabulary, `vworks_log`'s `Kind`, takes its first
/// kinds and their names from it).
pub const EVENT_NAMES: [&str; 21] = [
    "motion_start",
    "motion_end",
    "delay",
    "delay_end",
    "set",
    "wait_until",
    "wait_end",
    "signal",
    "grip",
    "release",
    "log",
    "error",
    "enable_when",
    "disable_when",
    "when_fire",
    "when_end",
    "remote_call",
    "join",
    "remote_start",
    "remote_end",
    "end",
];

impl EventKind {
    /// The kind's index in [`EVENT_NAMES`] (a wait on a signal or at a sync point is a
    /// `wait_until`).
    pub fn index(&self) -> usize {
        match self {
            EventKind::MotionStart { .. } => 0,
            EventKind::MotionEnd { .. } => 1,
            EventKind::Delay { .. } => 2,
            EventKind::DelayEnd => 3,
            EventKind::Set { .. } => 4,
            EventKind::WaitUntil { .. }
            | EventKind::WaitSignal { .. }
            | EventKind::WaitSync { .. } => 5,
            EventKind::WaitEnd { .. } => 6,
            EventKind::Signal { .. } => 7,
            EventKind::Grip { .. } => 8,
            EventKind::Release { .. } => 9,
            EventKind::Log { .. } => 10,
            EventKind::Error { .. } => 11,
            EventKind::EnableWhen { .. } => 12,
            EventKind::DisableWhen { .. } => 13,
            EventKind::WhenFire { .. } => 14,
            EventKind::WhenEnd { .. } => 15,
            EventKind::RemoteCall { .. } => 16,
            EventKind::Join => 17,
            EventKind::RemoteStart { .. } => 18,
            EventKind::RemoteEnd { .. } => 19,
            EventKind::End => 20,
        }
    }

    /// The kind's name in event traces.
    pub fn name(&self) -> &'static str {
        EVENT_NAMES[self.index()]
    }
}

/// What a [`Warning`](super::Warning) is about (its name in the run's warnings: `vworks_log`'s `IssueKind`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum WarningKind {
    /// A motion slowed to keep an axis within its speed (`slowdown`).
    Slowdown,
    /// A motion takes longer than the time it was asked to take (`duration`).
    Duration,
    /// A zoned point the robot must reach before the next statement (`stop-point`).
    StopPoint,
    /// A motion that cannot start inside the previous zone: the robot stops at that point
    /// (`corner`).
    Corner,
}
