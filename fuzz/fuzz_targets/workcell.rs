//! Workcell text (and the programs, URDFs and meshes it names, in memory) → loaded cell:
//! never a panic; every failure a `CellError` whose message names the workcell file.
#![no_main]

use libfuzzer_sys::fuzz_target;

#[path = "cellfiles.rs"]
mod cellfiles;

fuzz_target!(|data: &[u8]| {
    let files = cellfiles::files_of(data);
    match vworks_cell::load_with(cellfiles::cell_path(), &files) {
        Ok(cell) => {
            let _ = cell.render_warnings(false);
            assert!(cell.cycle_ns > 0);
        }
        Err(e) => {
            let m = e.to_string();
            assert!(!m.is_empty());
        }
    }
});
