//! The cell's kinematic state at a cycle boundary: every robot's joints and link frames,
//! which robot holds which part, and where the parts are. The collider brings it up to
//! date at each boundary it checks ([`crate::collide::Collider::check`]); sinks such as
//! the log read it there, as a [`WorldView`] ([`vworks_log::sink::RunSink::cycle`]).

use vworks_cell::Cell;
use vworks_log::sink::WorldView;
use vworks_model::math::Iso;
use vworks_vm::MAX_AXES;

/// The state of a cell's robots and parts as of the last boundary checked.
#[derive(Clone, Debug)]
pub struct World {
    /// Per robot: the joints `frames` are the forward kinematics of (`MAX_AXES` slots, the
    /// robot's axes first; NaN before the first check).
    pub(crate) joints: Vec<[f64; MAX_AXES]>,
    /// Per robot: every link's frame in the cell.
    pub(crate) frames: Vec<Vec<Iso>>,
    /// Per robot: its active tool (the TCP in its tool link's frame: the tool of the
    /// motion it is making or made last, else the workcell's `tool`).
    pub(crate) tools: Vec<Iso>,
    /// Per part: the robot holding it and the part's pose in that robot's tool-link frame.
    pub(crate) held: Vec<Option<(usize, Iso)>>,
    /// Per part: its pose in the cell when not held.
    pub(crate) part_pose: Vec<Iso>,
    /// Per robot: its model's tool link (what a held part's offset is from).
    tool_links: Vec<usize>,
}

impl World {
    /// The cell before its first boundary: parts where the workcell puts them, no frames
    /// computed yet.
    pub fn new(cell: &Cell) -> World {
        World {
            joints: vec![[f64::NAN; MAX_AXES]; cell.robots.len()],
            frames: cell
                .robots
                .iter()
                .map(|r| r.model.frames_buffer())
                .collect(),
            tools: cell.robots.iter().map(|r| r.tool).collect(),
            held: vec![None; cell.parts.len()],
            part_pose: cell.parts.iter().map(|p| p.pose).collect(),
            tool_links: cell.robots.iter().map(|r| r.model.tool_link).collect(),
        }
    }

    /// Every robot's joints (`MAX_AXES` slots, the robot's axes first).
    pub fn joints(&self) -> &[[f64; MAX_AXES]] {
        &self.joints
    }

    /// Every robot's link frames in the cell.
    pub fn frames(&self) -> &[Vec<Iso>] {
        &self.frames
    }

    /// Every robot's active tool: its TCP in its tool link's frame.
    pub fn tools(&self) -> &[Iso] {
        &self.tools
    }

    /// The robot holding part `p`, if one does.
    pub fn holder(&self, p: usize) -> Option<usize> {
        self.held.get(p).copied().flatten().map(|(r, _)| r)
    }

    /// Part `p`'s pose in the cell (identity if there is no part `p`).
    pub fn part_pose(&self, p: usize) -> Iso {
        match self.held.get(p).copied().flatten() {
            Some((r, offset)) => self.frames[r][self.tool_links[r]].mul(&offset),
            None => self.part_pose.get(p).copied().unwrap_or(Iso::IDENTITY),
        }
    }
}

impl WorldView for World {
    fn joints(&self) -> &[[f64; MAX_AXES]] {
        &self.joints
    }

    fn frames(&self) -> &[Vec<Iso>] {
        &self.frames
    }

    fn tools(&self) -> &[Iso] {
        &self.tools
    }

    fn part_poses_into(&self, out: &mut Vec<Iso>) {
        out.clear();
        out.extend((0..self.part_pose.len()).map(|p| self.part_pose(p)));
    }
}
