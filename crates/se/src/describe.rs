//! The loaded cell as the run's vocabulary and log see it (`vworks_log`): a
//! [`CellInfo`] for a log to keep ([`describe`]), the names events resolve with, borrowed
//! from the cell without copying anything ([`CellNames`]), and a statement's text from the
//! cell's sources ([`statement_at`]).

use vworks_cell::Cell;
use vworks_log::cell::{BodyInfo, CellInfo, GlobalInfo, Names, RobotInfo};
use vworks_log::place::statement_in;
use vworks_vm::Type;
use vworks_vm::bytecode::{Module, SrcPos};

/// What the log needs of `cell`: its names, programs, models, bodies and files (copied:
/// made once per log).
pub fn describe(cell: &Cell) -> CellInfo {
    let body = |b: &vworks_cell::Body| BodyInfo {
        name: b.name.clone(),
        geometry: b.geometry.clone(),
        pose: b.pose,
    };
    CellInfo {
        name: cell.name.clone(),
        file: cell.file.display().to_string(),
        cycle_ns: cell.cycle_ns,
        clearance: cell.clearance,
        robots: cell
            .robots
            .iter()
            .map(|r| RobotInfo {
                name: r.name.clone(),
                model: r.model.clone(),
                base: r.base,
                tool: r.tool,
                module: r.module.clone(),
            })
            .collect(),
        devices: cell.devices.iter().map(body).collect(),
        parts: cell.parts.iter().map(body).collect(),
        globals: cell
            .linked
            .globals
            .iter()
            .map(|g| GlobalInfo {
                name: g.name.clone(),
                ty: g.ty,
            })
            .collect(),
        sources: cell.sources.clone(),
        files: cell.files.clone(),
        overrides: cell.overrides.clone(),
    }
}

/// A cell's names, borrowed: resolves recorded events (`TraceEvent::line`,
/// `TraceEvent::resolve`) with the loaded cell itself.
#[derive(Clone, Copy, Debug)]
pub struct CellNames<'a>(pub &'a Cell);

impl Names for CellNames<'_> {
    fn robot_name(&self, r: usize) -> Option<&str> {
        self.0.robots.get(r).map(|r| r.name.as_str())
    }

    fn module(&self, r: usize) -> Option<&Module> {
        self.0.robots.get(r).map(|r| &*r.module)
    }

    fn global(&self, g: usize) -> Option<(&str, Type)> {
        self.0
            .linked
            .globals
            .get(g)
            .map(|g| (g.name.as_str(), g.ty))
    }
}

/// The statement at `pos` of robot `r`'s program as written ([`statement_in`]); empty if
/// the source is not in the cell.
pub fn statement_at(cell: &Cell, r: usize, pos: SrcPos) -> String {
    let Some(robot) = cell.robots.get(r) else {
        return String::new();
    };
    let file = robot.module.file_of(pos);
    match cell.sources.iter().find(|(p, _)| p == file) {
        Some((_, text)) => statement_in(text, pos),
        None => String::new(),
    }
}
