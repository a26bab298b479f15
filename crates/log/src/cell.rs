//! What the vocabulary and the log know of a cell, without the cell crate: the robots
//! (names, programs, models, bases, tools), the cell's globals, the devices and parts, and
//! the files a log attaches. The engine builds a [`CellInfo`] from its loaded cell
//! (`vworks_se::describe`); the log's writer keeps one.
//!
//! [`Names`] is the part events are resolved with (a robot's name and module, a global's
//! name and type): [`CellInfo`] has them, and so may a view the engine keeps of its cell,
//! so that resolving an event copies nothing of the cell.

use std::sync::Arc;

use vworks_model::math::Iso;
use vworks_model::model::{Geometry, RobotModel};
use vworks_vm::Type;
use vworks_vm::bytecode::Module;

/// The names a recorded event's indices resolve to ([`crate::trace::TraceEvent::resolve`]).
pub trait Names {
    /// Robot `r`'s name, if there is a robot `r`.
    fn robot_name(&self, r: usize) -> Option<&str>;
    /// Robot `r`'s program (its linked module).
    fn module(&self, r: usize) -> Option<&Module>;
    /// Cell global `g`'s name and type.
    fn global(&self, g: usize) -> Option<(&str, Type)>;
}

/// A cell as the vocabulary and the log see it.
#[derive(Clone, Debug)]
pub struct CellInfo {
    /// The cell's name.
    pub name: String,
    /// The workcell file, as the log's metadata names it.
    pub file: String,
    /// Cycle period (ns).
    pub cycle_ns: i64,
    /// Near-miss distance (m).
    pub clearance: f64,
    /// Robots, in workcell order.
    pub robots: Vec<RobotInfo>,
    /// Static bodies.
    pub devices: Vec<BodyInfo>,
    /// Movable bodies, where the workcell puts them.
    pub parts: Vec<BodyInfo>,
    /// The cell's globals, in the linked order (sorted by name).
    pub globals: Vec<GlobalInfo>,
    /// The workcell file and every program: (path, text).
    pub sources: Vec<(String, String)>,
    /// Every other file the run read (URDFs, meshes): (path, bytes).
    pub files: Vec<(String, Vec<u8>)>,
    /// The values a sweep's variant changed from the workcell file: (path, TOML value).
    pub overrides: Vec<(String, String)>,
}

/// A robot of a [`CellInfo`].
#[derive(Clone, Debug)]
pub struct RobotInfo {
    /// Its name.
    pub name: String,
    /// Its model.
    pub model: Arc<RobotModel>,
    /// Its base in the cell.
    pub base: Iso,
    /// Its tool (the TCP in its tool link's frame) as the workcell sets it.
    pub tool: Iso,
    /// Its program.
    pub module: Arc<Module>,
}

/// A device or a part of a [`CellInfo`].
#[derive(Clone, Debug)]
pub struct BodyInfo {
    /// Its name.
    pub name: String,
    /// Its shape.
    pub geometry: Geometry,
    /// Its pose in the cell (a part's before anyone grips it).
    pub pose: Iso,
}

/// A global of the cell.
#[derive(Clone, Debug)]
pub struct GlobalInfo {
    /// Its name.
    pub name: String,
    /// Its type.
    pub ty: Type,
}

impl Names for CellInfo {
    fn robot_name(&self, r: usize) -> Option<&str> {
        self.robots.get(r).map(|r| r.name.as_str())
    }

    fn module(&self, r: usize) -> Option<&Module> {
        self.robots.get(r).map(|r| &*r.module)
    }

    fn global(&self, g: usize) -> Option<(&str, Type)> {
        self.globals.get(g).map(|g| (g.name.as_str(), g.ty))
    }
}
