//! Remote work ([`Remote`]): the requests this robot made in `parallel` blocks and has not
//! seen end (its joins), and the requests other robots made of it, queued until it is
//! idle, and the one it serves.

use std::collections::VecDeque;

/// A remote request waiting to be served.
#[derive(Clone, Debug)]
pub(super) struct Request {
    pub(super) proc: u32,
    pub(super) args: Vec<u64>,
    pub(super) time: i64,
}

/// The robot's remote calls and the requests it serves.
#[derive(Debug, Default)]
pub(super) struct Remote {
    /// Outstanding remote requests: (parallel depth, request number).
    join: Vec<(u32, u64)>,
    /// How deep the `parallel` blocks are nested now.
    par_depth: u32,
    /// The number of the next request this robot makes.
    next_req: u64,
    /// Remote requests waiting for this robot, and the one being served.
    queue: VecDeque<Request>,
    serving: Option<u32>,
}

impl Remote {
    /// The number the next request will have.
    pub(super) fn next_req(&self) -> u64 {
        self.next_req
    }

    /// A `parallel` block begins.
    pub(super) fn begin_parallel(&mut self) {
        self.par_depth += 1;
    }

    /// Request `req` was made in the current `parallel` block.
    pub(super) fn called(&mut self, req: u64) {
        self.join.push((self.par_depth, req));
        self.next_req += 1;
    }

    /// The end of the current `parallel` block: the depth to wait at if some of its
    /// requests are still outstanding; else the block is over.
    pub(super) fn join(&mut self) -> Option<u32> {
        let d = self.par_depth;
        if self.join.iter().any(|(depth, _)| *depth == d) {
            Some(d)
        } else {
            self.par_depth = self.par_depth.saturating_sub(1);
            None
        }
    }

    /// Request `req` ended; true if that releases the join at `joining` (the depth a
    /// join waits at, if one does).
    pub(super) fn done(&mut self, req: u64, joining: Option<u32>) -> bool {
        self.join.retain(|(_, r)| *r != req);
        match joining {
            Some(depth) if !self.join.iter().any(|(d, _)| *d == depth) => {
                self.par_depth = self.par_depth.saturating_sub(1);
                true
            }
            _ => false,
        }
    }

    /// Queues a request of another robot.
    pub(super) fn push(&mut self, r: Request) {
        self.queue.push_back(r);
    }

    /// The first request waiting.
    pub(super) fn front(&self) -> Option<&Request> {
        self.queue.front()
    }

    /// Starts serving the first request waiting (procedure `proc`).
    pub(super) fn serve(&mut self, proc: u32) -> Option<Request> {
        let r = self.queue.pop_front()?;
        self.serving = Some(proc);
        Some(r)
    }

    /// The procedure being served, if remote work is under way.
    pub(super) fn serving(&self) -> Option<u32> {
        self.serving
    }

    /// The remote work (or the program) ended.
    pub(super) fn end_serving(&mut self) {
        self.serving = None;
    }
}
