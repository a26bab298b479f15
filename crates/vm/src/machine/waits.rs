//! Waits and what releases them: `wait_until` conditions (re-tested on `check_wait`),
//! signals, joins, remote requests and their answers, timeouts.

use super::*;

impl Vm {
    /// What the robot waits for, when it is blocked: for deadlock reports.
    pub fn waiting_for(&self) -> Option<(String, SrcPos)> {
        match &self.state {
            State::Waiting {
                cond: Some(c), pos, ..
            } => {
                let info = &self.m.conds[*c as usize];
                let names: Vec<&str> = info
                    .globals
                    .iter()
                    .map(|g| self.m.str(self.m.globals[*g as usize].name))
                    .collect();
                Some((format!("a condition on {}", names.join(", ")), *pos))
            }
            State::Waiting {
                signal: Some(s),
                pos,
                ..
            } => Some((format!("the signal `{}`", self.m.str(*s)), *pos)),
            State::Waiting {
                sync: Some(s), pos, ..
            } => {
                let site = &self.m.syncs[*s as usize];
                Some((format!("the sync point `{}`", self.m.str(site.name)), *pos))
            }
            State::Joining { pos, .. } => Some((
                "the remote work of its `parallel` block (join)".into(),
                *pos,
            )),
            _ => None,
        }
    }

    /// The signal (its name's string index) the robot is blocked waiting for, if one.
    pub fn waited_signal(&self) -> Option<u32> {
        match self.state {
            State::Waiting { signal, .. } => signal,
            _ => None,
        }
    }

    /// The deadline of the wait the robot is blocked in, if it has a timeout.
    pub fn wait_deadline(&self) -> Option<i64> {
        match self.state {
            State::Waiting { deadline, .. } => deadline,
            _ => None,
        }
    }

    /// The globals (module indices) the robot's current wait condition reads.
    pub fn wait_globals(&self) -> &[u32] {
        match &self.state {
            State::Waiting { cond: Some(c), .. } => &self.m.conds[*c as usize].globals,
            _ => &[],
        }
    }

    pub(super) fn deadline(&self, timeout: bool, t: i64) -> Result<Option<i64>, String> {
        self.deadline_at(timeout, t, 0)
    }

    /// The deadline of a timeout `depth` slots below the top of the stack.
    pub(super) fn deadline_at(
        &self,
        timeout: bool,
        t: i64,
        depth: usize,
    ) -> Result<Option<i64>, String> {
        if !timeout {
            return Ok(None);
        }
        let d = f64::from_bits(self.top(false, depth));
        if d.is_nan() || d < 0.0 {
            return Err(format!(
                "a timeout cannot be negative ({})",
                fmt_quantity(d, Dim::TIME)
            ));
        }
        Ok(Some(t + span_ns(d, t, "the timeout")?))
    }

    /// Evaluates condition `c` with the locals it captures from the main thread's frame.
    pub(super) fn eval_cond(&mut self, c: u32, t: i64) -> bool {
        let cond = &self.m.conds[c as usize];
        let base = self.main.frames.last().map_or(0, |f| f.base as usize);
        let mut args = [0u64; 64];
        let mut n = 0;
        for cap in &cond.captures {
            for k in 0..cap.width as usize {
                if n < args.len() {
                    args[n] = self
                        .main
                        .locals
                        .get(base + cap.slot as usize + k)
                        .copied()
                        .unwrap_or(0);
                    n += 1;
                }
            }
        }
        let func = cond.func;
        self.eval_cond_with(func, &args[..n], t)
    }

    /// Runs condition function `func` with `args`; false if it fails.
    pub(super) fn eval_cond_with(&mut self, func: u32, args: &[u64], t: i64) -> bool {
        let mut th = std::mem::take(&mut self.cond_thread);
        th.start(&self.m, func, args);
        let r = self.run_thread(&mut th, t, false);
        let value = matches!(r, Ok(Stop::Finished)) && th.stack.last().copied().unwrap_or(0) != 0;
        self.cond_thread = th;
        value
    }

    /// The sync site this VM waits at, if it waits at a sync point.
    pub fn waiting_sync(&self) -> Option<u32> {
        match self.state {
            State::Waiting { sync, .. } => sync,
            _ => None,
        }
    }

    /// The engine's release of a meeting at a sync point: every task of its list has
    /// arrived. Returns true if this VM waited there (its next event becomes `wait_end`
    /// at `t`).
    pub fn release_sync(&mut self, t: i64) -> bool {
        if let State::Waiting {
            sync: Some(_),
            pos,
            deadline,
            ..
        } = self.state
        {
            self.state = State::released(t, deadline, pos);
            return true;
        }
        false
    }

    /// The condition (index in the module's conditions) this VM waits on, if it waits
    /// for one.
    pub fn waiting_cond(&self) -> Option<u32> {
        match self.state {
            State::Waiting { cond, .. } => cond,
            _ => None,
        }
    }

    /// Whether the next `next_event` would run zero-time code (the main program's or a
    /// running handler's) before it knows the event: that code reads the cell's globals,
    /// so the engine calls it only in the robot's own turn at the instant.
    pub fn needs_turn(&self) -> bool {
        matches!(self.state, State::Run) || (self.hrun.is_some() && self.hstate == State::Run)
    }

    /// Whether the VM is blocked in a `wait_until` or `wait_signal` (not released yet).
    pub fn waits(&self) -> bool {
        matches!(self.state, State::Waiting { .. })
    }

    /// The SE's `check_wait` at time `t`: re-tests the condition this VM waits on.
    /// Returns true if the VM is released (its next event becomes `wait_end` at `t`).
    /// A polled wait (`wait_until … poll p`) is released only on its grid (its start plus
    /// a whole number of periods): when the condition holds between two polls, the VM asks
    /// for a check at the next one ([`Vm::take_poll_check`]), where it is tested again.
    pub fn check_wait(&mut self, t: i64) -> bool {
        let State::Waiting {
            cond: Some(c),
            pos,
            deadline,
            poll,
            ..
        } = self.state
        else {
            return false;
        };
        if !self.eval_cond(c, t) {
            return false;
        }
        match poll {
            Some((start, period)) if (t - start) % period != 0 => {
                let next = start + ((t - start) / period + 1) * period;
                // A timeout at or before the next poll ends the wait first.
                if self.poll_requested != Some(next) && deadline.is_none_or(|d| next < d) {
                    self.poll_requested = Some(next);
                    self.poll_check = Some(next);
                }
                false
            }
            _ => {
                self.state = State::released(t, deadline, pos);
                true
            }
        }
    }

    /// The time of the next poll of a polled wait whose condition held between polls, once:
    /// the SE queues a `check_wait` then.
    pub fn take_poll_check(&mut self) -> Option<i64> {
        self.poll_check.take()
    }

    /// Delivers a signal named `name` at time `t`: releases a matching wait, or is counted
    /// until one consumes it. Returns true if it released a wait.
    pub fn deliver_signal(&mut self, name: &str, t: i64) -> bool {
        match self.signal_index(name) {
            Some(idx) => self.deliver_signal_index(idx, t),
            None => false,
        }
    }

    /// The index under which this VM knows the signal `name` (its string index), for
    /// [`Vm::deliver_signal_index`]; `None` if its program never mentions it (a signal it
    /// can never wait for).
    pub fn signal_index(&self, name: &str) -> Option<u32> {
        self.m
            .strings
            .iter()
            .position(|s| s == name)
            .map(|i| i as u32)
    }

    /// [`Vm::deliver_signal`] with the name already looked up by [`Vm::signal_index`].
    pub fn deliver_signal_index(&mut self, idx: u32, t: i64) -> bool {
        if let State::Waiting {
            signal: Some(s),
            pos,
            deadline,
            ..
        } = self.state
            && s == idx
        {
            self.state = State::released(t, deadline, pos);
            return true;
        }
        match self.signals.iter_mut().find(|(n, _)| *n == idx) {
            Some((_, c)) => *c += 1,
            None => self.signals.push((idx, 1)),
        }
        false
    }
    /// Queues a remote request to run procedure `proc` with `args` (arriving at `t`).
    /// It starts when the robot is idle, in arrival order.
    pub fn request_remote(&mut self, proc: u32, args: Vec<u64>, t: i64) {
        self.queue.push_back(Request {
            proc,
            args,
            time: t,
        });
    }

    /// Tells the caller that its remote request `req` ended at `t`; releases its join when
    /// it was the last of its `parallel` block.
    pub fn remote_done(&mut self, req: u64, t: i64) {
        self.join.retain(|(_, r)| *r != req);
        if let State::Joining { depth, pos } = self.state
            && !self.join.iter().any(|(d, _)| *d == depth)
        {
            self.par_depth = self.par_depth.saturating_sub(1);
            self.state = State::released(t, None, pos);
        }
    }
}
