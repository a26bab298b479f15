//! What the interpreter sees of the robot while it runs a segment ([`View`], a
//! [`Reader`]): globals (their reads noted for race warnings), time, cycle, the robot's
//! joints, TCP and tool.

use std::cell::RefCell;

use super::arm::Arm;
use super::interp::ReadLog;
use crate::MAX_AXES;
use crate::bytecode::Module;
use crate::exec::Reader;
use crate::motion::NS;

/// The robot as a thread sees it, apart from the globals: its module, its motions, the
/// cycle and whether its last timed wait timed out.
pub(super) struct Sight<'a> {
    pub(super) m: &'a Module,
    pub(super) arm: &'a Arm,
    pub(super) cycle_ns: i64,
    pub(super) timed_out: bool,
}

/// The [`Reader`] of a thread running at `t`.
pub(super) struct View<'a> {
    pub(super) sight: &'a Sight<'a>,
    /// Globals as the SE last gave them (slot bits by module global index).
    pub(super) globals: &'a [u64],
    pub(super) t: i64,
    /// Where reads of globals are noted for race warnings: those of the main program and
    /// of handlers, not of conditions (which `check_wait`/`check_when` re-test).
    pub(super) reads: Option<&'a RefCell<ReadLog>>,
}

impl Reader for View<'_> {
    fn global(&self, g: u32, pc: u32) -> u64 {
        if let Some(log) = self.reads {
            log.borrow_mut().note(g, self.t, || self.sight.m.pos_of(pc));
        }
        self.globals.get(g as usize).copied().unwrap_or(0)
    }
    fn now_s(&self) -> f64 {
        self.t as f64 / NS
    }
    fn cycle(&self) -> i64 {
        self.t / self.sight.cycle_ns.max(1)
    }
    fn timed_out(&self) -> bool {
        self.sight.timed_out
    }
    fn joints(&self) -> [f64; MAX_AXES] {
        self.sight.arm.joints_at(self.t)
    }
    fn tcp(&self) -> [f64; 6] {
        let tcp = self.sight.arm.tcp_at(self.t);
        crate::math::pose_of(tcp.r, tcp.t)
    }
    fn tool(&self) -> [f64; 6] {
        let tool = self.sight.arm.tool_at(self.t);
        crate::math::pose_of(tool.r, tool.t)
    }
    fn axes(&self) -> usize {
        self.sight.arm.model().dof()
    }
}
