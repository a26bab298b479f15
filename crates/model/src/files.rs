//! Where the loaders' files come from: the file system ([`Disk`]), or memory
//! ([`MemoryFiles`]: tests, fuzzing, and applications that generate cells without
//! writing them out). Workcells, programs, URDFs and meshes are all read through
//! [`Files`].

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// A source of files, by path.
pub trait Files {
    /// The bytes of the file at `path`; `NotFound` if there is none.
    fn read(&self, path: &Path) -> std::io::Result<Vec<u8>>;
}

/// The file system.
#[derive(Clone, Copy, Debug, Default)]
pub struct Disk;

impl Files for Disk {
    fn read(&self, path: &Path) -> std::io::Result<Vec<u8>> {
        std::fs::read(path)
    }
}

/// Files held in memory, by path (paths are compared as given: `a/./b` is not `a/b`).
#[derive(Clone, Debug, Default)]
pub struct MemoryFiles {
    /// The files.
    pub files: BTreeMap<PathBuf, Vec<u8>>,
}

impl MemoryFiles {
    /// Adds (or replaces) the file at `path`.
    pub fn insert(&mut self, path: impl Into<PathBuf>, bytes: impl Into<Vec<u8>>) {
        self.files.insert(path.into(), bytes.into());
    }
}

impl Files for MemoryFiles {
    fn read(&self, path: &Path) -> std::io::Result<Vec<u8>> {
        self.files.get(path).cloned().ok_or_else(|| {
            std::io::Error::new(
                std::io::ErrorKind::NotFound,
                format!("no file `{}` in memory", path.display()),
            )
        })
    }
}
