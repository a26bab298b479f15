//! The remote queues ([`RemoteQueues`]): per robot, the remote requests it serves, in the
//! order they arrived, so that the end of its remote work answers the right caller.

use std::collections::VecDeque;

/// Per robot, the remote requests it serves: (caller, request number).
#[derive(Debug)]
pub(super) struct RemoteQueues {
    serving: Vec<VecDeque<(usize, u64)>>,
}

impl RemoteQueues {
    /// No request for any of `robots` robots.
    pub(super) fn new(robots: usize) -> RemoteQueues {
        RemoteQueues {
            serving: vec![VecDeque::new(); robots],
        }
    }

    /// Robot `caller` asks robot `target` for remote work (its request `req`).
    pub(super) fn request(&mut self, target: usize, caller: usize, req: u64) {
        self.serving[target].push_back((caller, req));
    }

    /// Robot `r` ended the remote work it served first: (caller, request number).
    pub(super) fn served(&mut self, r: usize) -> Option<(usize, u64)> {
        self.serving[r].pop_front()
    }
}
