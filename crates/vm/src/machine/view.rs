//! What the interpreter sees of the robot while it runs a segment ([`Reader`]): globals
//! (their reads noted for race warnings), time, cycle, the robot's joints, TCP and tool.

use super::*;

pub(super) struct View<'a> {
    pub(super) vm: &'a Vm,
    pub(super) t: i64,
    /// Where reads of globals are noted for race warnings: those of the main program and
    /// of handlers, not of conditions (which `check_wait`/`check_when` re-test).
    pub(super) reads: Option<&'a std::cell::RefCell<ReadLog>>,
}

impl Reader for View<'_> {
    fn global(&self, g: u32, pc: u32) -> u64 {
        if let Some(log) = self.reads {
            let log = &mut *log.borrow_mut();
            if let Some(at) = log.at.get_mut(g as usize)
                && *at != self.t
            {
                *at = self.t;
                log.new.push((g, self.vm.m.pos_of(pc)));
            }
        }
        self.vm.globals.get(g as usize).copied().unwrap_or(0)
    }
    fn now_s(&self) -> f64 {
        self.t as f64 / NS
    }
    fn cycle(&self) -> i64 {
        self.t / self.vm.cfg.cycle_ns.max(1)
    }
    fn timed_out(&self) -> bool {
        self.vm.timed_out
    }
    fn joints(&self) -> [f64; MAX_AXES] {
        self.vm.joints_at(self.t)
    }
    fn tcp(&self) -> [f64; 6] {
        let tcp = self.vm.tcp_at(self.t);
        crate::math::pose_of(tcp.r, tcp.t)
    }
    fn tool(&self) -> [f64; 6] {
        let tool = self.vm.tool_at(self.t);
        crate::math::pose_of(tool.r, tool.t)
    }
    fn axes(&self) -> usize {
        self.vm.model.dof()
    }
}
