//! Ctrl-C while Rust runs: Python runs its signal handlers only on the main thread and
//! only when that thread comes back to Python, so long work (a run, `run_until`, a sweep)
//! runs on a thread of its own while the calling thread, GIL released, wakes every
//! [`POLL`] to check for signals (`Python::check_signals`). A handler that raises
//! (Ctrl-C: `KeyboardInterrupt`) sets the work's stop flag — the engine ends its run
//! between two events (outcome `interrupted`, its log finished), a sweep starts no more
//! variants — and the exception is raised once the work has returned.

use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Condvar, Mutex};
use std::time::Duration;

use pyo3::prelude::*;

/// How often the waiting thread checks for signals.
const POLL: Duration = Duration::from_millis(50);

/// Runs `work` on a thread of its own with the GIL released, checking for signals every
/// [`POLL`] meanwhile. Returns its result, and the exception a signal handler raised (then
/// `stop` was set and `work` is expected to have ended early). A panic in `work` goes on
/// in the caller (pyo3 makes it a `PanicException`).
pub(crate) fn interruptible<T: Send>(
    py: Python<'_>,
    stop: &AtomicBool,
    work: impl FnOnce() -> T + Send,
) -> (T, Option<PyErr>) {
    let done = Done::default();
    std::thread::scope(|s| {
        let worker = s.spawn(|| {
            // Marks the work done when it returns or unwinds.
            let _done = DoneOnDrop(&done);
            work()
        });
        let mut raised = None;
        while !py.detach(|| done.wait(POLL)) {
            if raised.is_none()
                && let Err(e) = py.check_signals()
            {
                stop.store(true, Ordering::Relaxed);
                raised = Some(e);
            }
        }
        match worker.join() {
            Ok(out) => (out, raised),
            Err(panic) => std::panic::resume_unwind(panic),
        }
    })
}

/// Whether the work has returned, and its wake-up.
#[derive(Default)]
struct Done {
    flag: Mutex<bool>,
    wake: Condvar,
}

impl Done {
    /// Waits at most `timeout` for the work to end; whether it has.
    fn wait(&self, timeout: Duration) -> bool {
        let Ok(flag) = self.flag.lock() else {
            return true; // a poisoned lock: the worker panicked, and join says so
        };
        match self.wake.wait_timeout_while(flag, timeout, |done| !*done) {
            Ok((flag, _)) => *flag,
            Err(_) => true,
        }
    }
}

/// Sets [`Done`] when dropped: after the work, or while it unwinds.
struct DoneOnDrop<'a>(&'a Done);

impl Drop for DoneOnDrop<'_> {
    fn drop(&mut self) {
        if let Ok(mut flag) = self.0.flag.lock() {
            *flag = true;
        }
        self.0.wake.notify_all();
    }
}
