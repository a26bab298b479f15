//! How the collider reads the robots ([`RobotPoses`]): their joints, whether they move,
//! their axis speed bounds and their tools at a time. The VM implements it; collision
//! tests drive the collider with scripted robots instead.

use vworks_model::math::Iso;
use vworks_vm::MAX_AXES;
use vworks_vm::machine::Vm;

/// A robot as the collider sees it: where its axes are and how fast they can move.
pub trait RobotPoses {
    /// The robot's joints at time `t` (ns): `MAX_AXES` slots, its axes first (rad or m).
    fn joints_at(&self, t: i64) -> [f64; MAX_AXES];
    /// Whether the robot moves at time `t`.
    fn moving_at(&self, t: i64) -> bool;
    /// Per axis, a bound on its speed under the current motion (rad/s or m/s; 0 when the
    /// robot stands).
    fn axis_rate_bounds(&self) -> [f64; MAX_AXES];
    /// The robot's TCP in its tool link's frame at time `t`.
    fn tool_at(&self, t: i64) -> Iso;
}

impl RobotPoses for Vm {
    fn joints_at(&self, t: i64) -> [f64; MAX_AXES] {
        Vm::joints_at(self, t)
    }

    fn moving_at(&self, t: i64) -> bool {
        Vm::moving_at(self, t)
    }

    fn axis_rate_bounds(&self) -> [f64; MAX_AXES] {
        Vm::axis_rate_bounds(self)
    }

    fn tool_at(&self, t: i64) -> Iso {
        Vm::tool_at(self, t)
    }
}
