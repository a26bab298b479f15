//! The run's limits. The event limit: the trace is kept in memory (`RunResult::trace`,
//! Python's events, the golden traces), so a run records at most [`EVENT_LIMIT`] events.
//! One that would record more — a handler firing every nanosecond, a loop of 1 ns delays —
//! stops with an error naming what records them and what to do, instead of growing until
//! the process aborts ([`too_many_events`]). The instant limit ([`InstantLimit`]): how
//! many queue entries the cell may handle at one simulated instant.

use vworks_cell::Cell;
use vworks_vm::bytecode::SrcPos;
use vworks_vm::machine::{EventKind, Vm};

use vworks_log::trace::{Detail, Kind, TraceEvent};

/// How many queue entries the cell may handle at one simulated instant by default: far
/// more than any program needs, few enough to stop a zero-time livelock of several
/// robots in well under a second.
pub const INSTANT_LIMIT: u64 = 1_000_000;

/// The queue entries handled at the instant being simulated, against the limit.
#[derive(Debug)]
pub(super) struct InstantLimit {
    /// The instant being simulated, and the queue entries handled at it.
    instant: i64,
    entries: u64,
    /// How many the cell may handle at one instant.
    limit: u64,
}

impl InstantLimit {
    /// No entry handled yet, the limit [`INSTANT_LIMIT`].
    pub(super) fn new() -> InstantLimit {
        InstantLimit {
            instant: -1,
            entries: 0,
            limit: INSTANT_LIMIT,
        }
    }

    /// How many entries the cell may handle at one instant (at least 1).
    pub(super) fn set_limit(&mut self, limit: u64) {
        self.limit = limit.max(1);
    }

    /// How many entries the cell may handle at one instant.
    pub(super) fn limit(&self) -> u64 {
        self.limit
    }

    /// An entry is handled at `t`: false if that is one more than the limit.
    pub(super) fn handle(&mut self, t: i64) -> bool {
        if t != self.instant {
            self.instant = t;
            self.entries = 0;
        }
        self.entries += 1;
        self.entries <= self.limit
    }
}

/// How many events a run records at most by default (see
/// [`super::Simulation::with_event_limit`]): far more than real cells record (the handoff
/// example, 3 a second: 38 days; 64 robots with an event every 100 ms each: 4 hours),
/// few enough to bound the trace's memory (an event is 104 bytes: about 1 GB).
pub const EVENT_LIMIT: u64 = 10_000_000;

/// A time in the largest of s, ms and ns that gives it exactly (`1 ns`, `4 ms`, `2 s`).
fn exact_time(ns: i64) -> String {
    match ns {
        _ if ns % 1_000_000_000 == 0 => format!("{} s", ns / 1_000_000_000),
        _ if ns % 1_000_000 == 0 => format!("{} ms", ns / 1_000_000),
        _ => format!("{ns} ns"),
    }
}

/// How many of the last events are looked at to find what records them.
const TAIL: usize = 10_000;

/// The error of a run whose `trace` holds `event_limit` events, the most it may (cell
/// `cell`, robots `vms`): (robot, position, message), naming the robot that recorded most
/// of the last ones and, when a handler's firings are most of those, the handler and its
/// period.
pub(super) fn too_many_events(
    trace: &[TraceEvent],
    event_limit: u64,
    cell: &Cell,
    vms: &[Vm],
) -> (Option<usize>, Option<SrcPos>, String) {
    let tail = &trace[trace.len().saturating_sub(TAIL)..];
    let mut per_robot = vec![0usize; vms.len()];
    for e in tail {
        if let Some(r) = e.robot.filter(|r| *r < per_robot.len()) {
            per_robot[r] += 1;
        }
    }
    // The busiest robot (the first of equals).
    let Some((r, _)) = per_robot.iter().enumerate().fold(
        None,
        |best: Option<(usize, usize)>, (r, &k)| match best {
            Some((_, b)) if b >= k => best,
            _ if k > 0 => Some((r, k)),
            _ => best,
        },
    ) else {
        let m = format!(
            "the run has recorded {event_limit} events, the most a run keeps; simulate less time (`--until`)",
        );
        return (None, None, m);
    };
    // Its handler that fired most among the last events, if firings are most of them.
    let fired = |h: u32, events: &[TraceEvent]| {
        events
                .iter()
                .filter(|e| {
                    e.robot == Some(r)
                        && e.kind == Kind::WhenFire
                        && matches!(e.detail, Detail::Vm(EventKind::WhenFire { handler }) if handler == h)
                })
                .count()
    };
    let handlers = cell.robots[r].module.handlers.len() as u32;
    let busiest = (0..handlers)
        .map(|h| (fired(h, tail), h))
        .filter(|(k, _)| *k > 0)
        .max_by(|a, b| a.0.cmp(&b.0).then(b.1.cmp(&a.1)));
    let robot = cell.robots[r].name.clone();
    let (message, pos) = match busiest {
        // A firing records two events (`when_fire`, `when_end`).
        Some((k, h)) if 4 * k >= per_robot[r] => {
            let m = &cell.robots[r].module;
            let info = &m.handlers[h as usize];
            let name = m.str(m.procs[info.target as usize].name).to_string();
            let every = vms[r]
                .handler_period_ns(h)
                .map(|p| format!(" every {}", exact_time(p)))
                .unwrap_or_default();
            let total = fired(h, trace);
            (
                format!(
                    "the run has recorded {} events, the most a run keeps: the handler `{name}` of {robot}, firing{every}, fired {total} times; give it a longer period, disable it when it is not needed, or simulate less time (`--until`)",
                    event_limit
                ),
                info.pos,
            )
        }
        _ => {
            let pos = tail
                .iter()
                .rev()
                .find(|e| e.robot == Some(r))
                .and_then(|e| e.pos)
                .unwrap_or_default();
            (
                format!(
                    "the run has recorded {} events, the most a run keeps: {robot} recorded {} of the last {}, the last at {}:{pos}; let more time pass between its events, or simulate less time (`--until`)",
                    event_limit,
                    per_robot[r],
                    tail.len(),
                    cell.robots[r].module.file_name_of(pos),
                ),
                pos,
            )
        }
    };
    (Some(r), Some(pos), message)
}

#[cfg(test)]
mod tests {
    /// The memory bound [`super::EVENT_LIMIT`] documents: events of fixed size.
    #[test]
    fn a_trace_event_takes_at_most_104_bytes() {
        assert!(size_of::<vworks_log::trace::TraceEvent>() <= 104);
    }
}
