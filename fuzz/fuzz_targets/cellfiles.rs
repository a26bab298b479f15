//! The in-memory file set the workcell and whole-run targets read: the `.case` format of
//! `tests/errors/` and `tests/runs/` (`--- NAME` starts a file; lines before the first are
//! ignored, `$ vworks …` included), so those cases seed the corpora as they are. The cell
//! is `cell.toml`.

use std::path::Path;

use vworks_cell::MemoryFiles;

pub fn files_of(data: &[u8]) -> MemoryFiles {
    let mut files = MemoryFiles::default();
    let mut current: Option<(String, Vec<u8>)> = None;
    for line in data.split_inclusive(|b| *b == b'\n') {
        if let Some(name) = line.strip_prefix(b"--- ") {
            if let Some((n, body)) = current.take() {
                files.insert(n, body);
            }
            let name = String::from_utf8_lossy(name).trim().to_string();
            current = Some((name, Vec::new()));
        } else if let Some((_, body)) = current.as_mut() {
            body.extend_from_slice(line);
        }
    }
    if let Some((n, body)) = current {
        files.insert(n, body);
    }
    files
}

pub fn cell_path() -> &'static Path {
    Path::new("cell.toml")
}
