//! The cell's globals as the engine keeps them ([`CellGlobals`]): each one's value and
//! type, and where each robot's module keeps its copy, so that a set reaches every robot
//! that reads the global.

use vworks_cell::Cell;
use vworks_vm::Type;
use vworks_vm::machine::Vm;

/// The cell globals' values and every robot's copies of them.
#[derive(Debug)]
pub(super) struct CellGlobals {
    /// Per cell global: value bits and type.
    values: Vec<(u64, Type)>,
    /// Per robot: cell global index → module global index.
    to_module: Vec<Vec<Option<u32>>>,
}

impl CellGlobals {
    /// `cell`'s globals at their initial values.
    pub(super) fn new(cell: &Cell) -> CellGlobals {
        let values: Vec<(u64, Type)> = cell
            .linked
            .globals
            .iter()
            .map(|g| {
                let mut s = [0u64];
                g.init.write_slots(&mut s);
                (s[0], g.ty)
            })
            .collect();
        let mut to_module = vec![vec![None; values.len()]; cell.robots.len()];
        for (r, links) in cell.linked.robots.iter().enumerate() {
            for (mg, cg) in links.globals.iter().enumerate() {
                to_module[r][*cg as usize] = Some(mg as u32);
            }
        }
        CellGlobals { values, to_module }
    }

    /// Every cell global's value bits and type, in the linked cell's order.
    pub(super) fn values(&self) -> &[(u64, Type)] {
        &self.values
    }

    /// Cell global `cg`'s value bits.
    pub(super) fn value(&self, cg: usize) -> u64 {
        self.values[cg].0
    }

    /// Sets cell global `cg` to `value`, in every robot's copy too (`vms`).
    pub(super) fn set(&mut self, cg: usize, value: u64, vms: &mut [Vm]) {
        self.values[cg].0 = value;
        for (vm, to_module) in vms.iter_mut().zip(&self.to_module) {
            if let Some(mg) = to_module[cg] {
                vm.set_global(mg, value);
            }
        }
    }
}
