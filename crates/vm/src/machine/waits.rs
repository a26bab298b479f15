//! What waits need besides the thread's state ([`Waits`]): signals that came before a
//! wait consumed them, the check a polled wait asks for at its next poll, and whether the
//! last timed wait timed out; and reading a wait's timeout.

use super::span_ns;
use crate::types::{Dim, fmt_quantity};

/// The robot's pending signals, polls and timeout flag.
#[derive(Debug, Default)]
pub(super) struct Waits {
    /// Pending signals: (name string index, count).
    signals: Vec<(u32, u32)>,
    /// A polled wait's next poll the SE should check at (taken once), and the last one
    /// asked for (not asked twice).
    poll_check: Option<i64>,
    poll_requested: Option<i64>,
    /// The most recent timed wait timed out (`timed_out()`).
    timed_out: bool,
}

impl Waits {
    /// Whether the most recent timed wait timed out.
    pub(super) fn timed_out(&self) -> bool {
        self.timed_out
    }

    /// Records how the most recent timed wait ended.
    pub(super) fn set_timed_out(&mut self, timed_out: bool) {
        self.timed_out = timed_out;
    }

    /// Consumes a pending signal `name` (string index), if one came.
    pub(super) fn consume_signal(&mut self, name: u32) -> bool {
        match self.signals.iter_mut().find(|(n, c)| *n == name && *c > 0) {
            Some((_, c)) => {
                *c -= 1;
                true
            }
            None => false,
        }
    }

    /// Counts signal `name` (string index) until a wait consumes it.
    pub(super) fn count_signal(&mut self, name: u32) {
        match self.signals.iter_mut().find(|(n, _)| *n == name) {
            Some((_, c)) => *c += 1,
            None => self.signals.push((name, 1)),
        }
    }

    /// A new polled wait starts: no poll asked for yet.
    pub(super) fn start_polling(&mut self) {
        self.poll_requested = None;
    }

    /// The condition of a polled wait held between polls: asks for a check at the next
    /// poll `next` (once), unless the timeout `deadline` ends the wait first.
    pub(super) fn ask_poll(&mut self, next: i64, deadline: Option<i64>) {
        if self.poll_requested != Some(next) && deadline.is_none_or(|d| next < d) {
            self.poll_requested = Some(next);
            self.poll_check = Some(next);
        }
    }

    /// The check asked for, once.
    pub(super) fn take_poll_check(&mut self) -> Option<i64> {
        self.poll_check.take()
    }
}

/// The deadline of a wait reached at `t` whose timeout (s, slot bits) is `timeout`, if
/// it has one; else what is wrong with it.
pub(super) fn deadline(timeout: Option<u64>, t: i64) -> Result<Option<i64>, String> {
    let Some(bits) = timeout else {
        return Ok(None);
    };
    let d = f64::from_bits(bits);
    if d.is_nan() || d < 0.0 {
        return Err(format!(
            "a timeout cannot be negative ({})",
            fmt_quantity(d, Dim::TIME)
        ));
    }
    Ok(Some(t + span_ns(d, t, "the timeout")?))
}
