//! Where a thread of the VM stands between events ([`State`]): running, stopped before an
//! event, moving, delaying, waiting (and for what), released, joining, idle or done; and
//! which context produced the event last returned ([`Source`]).

use super::Event;
use crate::bytecode::{Module, SrcPos};

/// Where the main program (or the running handler) stands.
#[derive(Clone, Debug, PartialEq)]
pub(super) enum State {
    /// Must run code to find the next event.
    Run,
    /// Stopped before this event.
    At(Event),
    /// Moving until `end`.
    Moving { end: i64, pos: SrcPos },
    /// Holding still until `end`.
    Delaying { end: i64, pos: SrcPos },
    /// Waiting for a condition or a signal.
    Waiting {
        cond: Option<u32>,
        signal: Option<u32>,
        /// A sync site: waiting at its sync point until the engine releases the meeting.
        sync: Option<u32>,
        deadline: Option<i64>,
        /// A polled wait's start and period (ns).
        poll: Option<(i64, i64)>,
        pos: SrcPos,
    },
    /// Released from a wait at `time`; `timed`: the wait had a timeout (only those set
    /// `timed_out()`).
    Released {
        time: i64,
        timed_out: bool,
        timed: bool,
        pos: SrcPos,
    },
    /// Waiting for the remote work of the `parallel` block at this depth.
    Joining { depth: u32, pos: SrcPos },
    /// The program ended; serving remote requests.
    Idle,
    /// Failed or stopped for good.
    Done,
}

impl State {
    /// Released at `time` (not by a timeout) from the wait at `pos`; `deadline`: the wait's,
    /// if it had a timeout.
    pub(super) fn released(time: i64, deadline: Option<i64>, pos: SrcPos) -> State {
        State::Released {
            time,
            timed_out: false,
            timed: deadline.is_some(),
            pos,
        }
    }

    /// What a blocked thread waits for, in words, and the wait's statement: for deadlock
    /// reports.
    pub(super) fn waiting_for(&self, m: &Module) -> Option<(String, SrcPos)> {
        match self {
            State::Waiting {
                cond: Some(c), pos, ..
            } => {
                let info = &m.conds[*c as usize];
                let names: Vec<&str> = info
                    .globals
                    .iter()
                    .map(|g| m.str(m.globals[*g as usize].name))
                    .collect();
                Some((format!("a condition on {}", names.join(", ")), *pos))
            }
            State::Waiting {
                signal: Some(s),
                pos,
                ..
            } => Some((format!("the signal `{}`", m.str(*s)), *pos)),
            State::Waiting {
                sync: Some(s), pos, ..
            } => {
                let site = &m.syncs[*s as usize];
                Some((format!("the sync point `{}`", m.str(site.name)), *pos))
            }
            State::Joining { pos, .. } => Some((
                "the remote work of its `parallel` block (join)".into(),
                *pos,
            )),
            _ => None,
        }
    }

    /// The signal (its name's string index) a waiting thread waits for, if one.
    pub(super) fn waited_signal(&self) -> Option<u32> {
        match self {
            State::Waiting { signal, .. } => *signal,
            _ => None,
        }
    }

    /// The deadline of the wait, if it has a timeout.
    pub(super) fn wait_deadline(&self) -> Option<i64> {
        match self {
            State::Waiting { deadline, .. } => *deadline,
            _ => None,
        }
    }

    /// The condition (index in the module's conditions) waited on, if one.
    pub(super) fn waiting_cond(&self) -> Option<u32> {
        match self {
            State::Waiting { cond, .. } => *cond,
            _ => None,
        }
    }

    /// The sync site waited at, if one.
    pub(super) fn waiting_sync(&self) -> Option<u32> {
        match self {
            State::Waiting { sync, .. } => *sync,
            _ => None,
        }
    }

    /// The end of the current motion, while moving.
    pub(super) fn moving_until(&self) -> Option<i64> {
        match self {
            State::Moving { end, .. } => Some(*end),
            _ => None,
        }
    }
}

/// Which context produced the event `next_event` returned last.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) enum Source {
    Main,
    Handler,
    Fire(usize),
    /// The end of a pulse (an index into the pulses under way).
    Pulse(usize),
    None,
}
