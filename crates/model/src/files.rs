//! Where the loaders' files come from: the file system ([`Disk`]), or memory
//! ([`MemoryFiles`]: tests, fuzzing, and applications that generate cells without
//! writing them out). Workcells, programs, URDFs and meshes are all read through
//! [`Files`].
//!
//! The disk is read through [`read_regular`]: regular files only (a symbolic link to one
//! is followed), at most a size limit — `/dev/zero`, a FIFO, or a mesh linked to
//! `/dev/urandom` is an error naming the file, never a read until memory runs out.

use std::collections::BTreeMap;
use std::io::Read as _;
use std::path::{Path, PathBuf};

/// The largest file [`Disk`] reads (256 MiB): workcells, programs, URDFs, meshes, sweep
/// files and bytecode.
pub const MAX_FILE_BYTES: u64 = 256 << 20;

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
        read_regular(path, MAX_FILE_BYTES)
    }
}

/// The bytes of the regular file at `path` (symbolic links followed), if it holds at most
/// `limit` bytes. Anything else is an error whose message says what is wrong and what to
/// do: a folder, a device (`/dev/zero`), a FIFO or a socket (`InvalidInput`); a file over
/// the limit, or one that grows past it while it is read (`FileTooLarge`). A missing file
/// is the system's `NotFound`, as from `std::fs::read`.
pub fn read_regular(path: &Path, limit: u64) -> std::io::Result<Vec<u8>> {
    // Checked before opening (opening a FIFO would wait for a writer), and again on the
    // file opened, in case the path was changed between the two.
    not_regular(&std::fs::metadata(path)?)?;
    let file = std::fs::File::open(path)?;
    let meta = file.metadata()?;
    not_regular(&meta)?;
    if meta.len() > limit {
        return Err(too_large(limit));
    }
    // The length is only a hint (a file may grow, `/proc` files say 0): the read itself is
    // bounded.
    let mut bytes = Vec::with_capacity(usize::try_from(meta.len()).unwrap_or(0));
    file.take(limit.saturating_add(1)).read_to_end(&mut bytes)?;
    if bytes.len() as u64 > limit {
        return Err(too_large(limit));
    }
    Ok(bytes)
}

/// An error if `meta` is not a regular file's.
fn not_regular(meta: &std::fs::Metadata) -> std::io::Result<()> {
    let t = meta.file_type();
    if t.is_file() {
        return Ok(());
    }
    let what = if t.is_dir() {
        "a folder"
    } else {
        special_kind(&t)
    };
    Err(std::io::Error::new(
        std::io::ErrorKind::InvalidInput,
        format!(
            "it is {what}, not a regular file: vworks reads regular files only (or symbolic links to them); name a file"
        ),
    ))
}

/// What kind of special file `t` is.
#[cfg(unix)]
fn special_kind(t: &std::fs::FileType) -> &'static str {
    use std::os::unix::fs::FileTypeExt as _;
    if t.is_char_device() {
        "a character device"
    } else if t.is_block_device() {
        "a block device"
    } else if t.is_fifo() {
        "a FIFO (named pipe)"
    } else if t.is_socket() {
        "a socket"
    } else {
        "a special file"
    }
}

/// What kind of special file `t` is.
#[cfg(not(unix))]
fn special_kind(_: &std::fs::FileType) -> &'static str {
    "a special file"
}

/// The error for a file over `limit` bytes.
fn too_large(limit: u64) -> std::io::Error {
    std::io::Error::new(
        std::io::ErrorKind::FileTooLarge,
        format!(
            "it is larger than {}, the most vworks reads of such a file; check that it is the file meant (a mesh can be simplified to fewer triangles)",
            size(limit)
        ),
    )
}

/// `limit` bytes in MiB or GiB.
fn size(limit: u64) -> String {
    if limit >= 1 << 30 && limit.is_multiple_of(1 << 30) {
        format!("{} GiB", limit >> 30)
    } else if limit >= 1 << 20 {
        format!("{} MiB", limit >> 20)
    } else {
        format!("{limit} bytes")
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

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used, clippy::expect_used)] // tests fail by panicking
    use super::*;

    fn temp(name: &str) -> PathBuf {
        let dir = std::env::temp_dir().join(format!("vworks-files-{name}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).unwrap();
        dir
    }

    #[test]
    fn regular_files_and_links_to_them_are_read_within_the_limit() {
        let dir = temp("regular");
        let file = dir.join("a.txt");
        std::fs::write(&file, b"12345").unwrap();
        assert_eq!(read_regular(&file, 5).unwrap(), b"12345");
        let e = read_regular(&file, 4).unwrap_err();
        assert_eq!(e.kind(), std::io::ErrorKind::FileTooLarge);
        assert!(e.to_string().contains("larger than 4 bytes"), "{e}");
        #[cfg(unix)]
        {
            let link = dir.join("link.txt");
            std::os::unix::fs::symlink(&file, &link).unwrap();
            assert_eq!(Disk.read(&link).unwrap(), b"12345");
        }
        let e = Disk.read(&dir).unwrap_err();
        assert_eq!(e.kind(), std::io::ErrorKind::InvalidInput);
        assert!(
            e.to_string()
                .starts_with("it is a folder, not a regular file"),
            "{e}"
        );
        let e = Disk.read(&dir.join("missing")).unwrap_err();
        assert_eq!(e.kind(), std::io::ErrorKind::NotFound);
        let _ = std::fs::remove_dir_all(&dir);
    }

    #[cfg(unix)]
    #[test]
    fn devices_and_links_to_them_are_refused_without_reading() {
        let dir = temp("devices");
        let link = dir.join("mesh.stl");
        std::os::unix::fs::symlink("/dev/urandom", &link).unwrap();
        for p in [Path::new("/dev/zero"), &link] {
            let e = Disk.read(p).unwrap_err();
            assert_eq!(
                e.kind(),
                std::io::ErrorKind::InvalidInput,
                "{}",
                p.display()
            );
            assert!(e.to_string().contains("a character device"), "{e}");
        }
        let _ = std::fs::remove_dir_all(&dir);
    }

    #[test]
    fn a_file_over_the_limit_is_refused_by_its_length() {
        let dir = temp("large");
        let file = dir.join("big.stl");
        // Sparse: no disk space, and not read.
        let f = std::fs::File::create(&file).unwrap();
        f.set_len(MAX_FILE_BYTES + 1).unwrap();
        let e = Disk.read(&file).unwrap_err();
        assert_eq!(e.kind(), std::io::ErrorKind::FileTooLarge);
        assert!(e.to_string().contains("larger than 256 MiB"), "{e}");
        let _ = std::fs::remove_dir_all(&dir);
    }
}
