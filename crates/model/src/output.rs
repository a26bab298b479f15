//! Writing an output file safely — what every file vworks writes goes through (the CLI's
//! `build`, `report`, `run --log`, `sweep`'s table and page, the report crate's
//! `write_report`): the output is refused if it is one of the command's inputs (the same
//! file by path or by inode: through a symlink, a hard link or `./x`), and it is written
//! to a temporary file in the same folder, then renamed over the output, so a failure
//! (a full disk, a kill) never leaves a truncated output or destroys the old one.
//!
//! The temporary file is `NAME.PID.partial` beside the output: visible, so what a killed
//! command had written can be found. An output that is not a regular file (`/dev/stdout`,
//! `/dev/null`, a pipe) is written in place: there is nothing to rename over.
//!
//! Every failure is an [`OutputError`] naming the file and saying what to do; a full disk
//! says "no space left on device".

use std::fs::File;
use std::io::{self, BufWriter, Write};
use std::path::{Path, PathBuf};

/// Why an output cannot be written.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum OutputError {
    /// The output is one of the inputs: writing it would destroy it.
    #[error(
        "`{output}` is the input `{input}`: writing it would destroy it; choose another output file"
    )]
    IsInput {
        /// The output as given.
        output: String,
        /// The input it is.
        input: String,
    },
    /// Writing (or creating, or renaming) failed.
    #[error("cannot write `{file}`: {reason}")]
    Write {
        /// The output as given.
        file: String,
        /// What went wrong and what to do.
        reason: String,
    },
}

impl OutputError {
    /// A write error on `file`, its reason in words a user can act on.
    pub fn write(file: &Path, e: &io::Error) -> OutputError {
        OutputError::Write {
            file: file.display().to_string(),
            reason: reason(e),
        }
    }
}

/// What `e` means for someone writing a file: a full disk, a missing folder, no
/// permission, or the system's own words.
pub fn reason(e: &io::Error) -> String {
    const ENOSPC: i32 = 28;
    if e.kind() == io::ErrorKind::StorageFull || e.raw_os_error() == Some(ENOSPC) {
        return "no space left on device; free some space, or write it elsewhere".into();
    }
    match e.kind() {
        io::ErrorKind::NotFound => {
            format!("{e}; check that its folder exists")
        }
        io::ErrorKind::PermissionDenied | io::ErrorKind::ReadOnlyFilesystem => {
            format!("{e}; check that its folder is writable")
        }
        _ => e.to_string(),
    }
}

/// The same file: equal paths, or (if both exist) the same device and inode.
pub fn same_file(a: &Path, b: &Path) -> bool {
    if a == b {
        return true;
    }
    let (Ok(ma), Ok(mb)) = (std::fs::metadata(a), std::fs::metadata(b)) else {
        return false;
    };
    #[cfg(unix)]
    {
        use std::os::unix::fs::MetadataExt;
        ma.dev() == mb.dev() && ma.ino() == mb.ino()
    }
    #[cfg(not(unix))]
    {
        let _ = (ma, mb);
        match (std::fs::canonicalize(a), std::fs::canonicalize(b)) {
            (Ok(x), Ok(y)) => x == y,
            _ => false,
        }
    }
}

/// `Err` if `output` is one of `inputs`.
pub fn refuse_input<P: AsRef<Path>>(output: &Path, inputs: &[P]) -> Result<(), OutputError> {
    match inputs.iter().find(|i| same_file(output, i.as_ref())) {
        Some(input) => Err(OutputError::IsInput {
            output: output.display().to_string(),
            input: input.as_ref().display().to_string(),
        }),
        None => Ok(()),
    }
}

/// An output being written: a temporary file beside it until [`Output::commit`] renames
/// it over the output. Dropped without a commit, it removes the temporary file.
#[derive(Debug)]
pub struct Output {
    path: PathBuf,
    /// The temporary file (`None`: the output is written in place).
    temp: Option<PathBuf>,
    file: BufWriter<File>,
}

impl Output {
    /// Starts writing `path`, refusing it if it is one of `inputs`.
    pub fn create<P: AsRef<Path>>(path: &Path, inputs: &[P]) -> Result<Output, OutputError> {
        refuse_input(path, inputs)?;
        let fail = |e: io::Error| OutputError::write(path, &e);
        let existing = std::fs::metadata(path).ok();
        if existing
            .as_ref()
            .is_some_and(|m| !m.is_file() && !m.is_dir())
        {
            // A device or a pipe: written in place.
            let file = File::create(path).map_err(fail)?;
            return Ok(Output {
                path: path.to_path_buf(),
                temp: None,
                file: BufWriter::new(file),
            });
        }
        if path.file_name().is_none() {
            return Err(OutputError::Write {
                file: path.display().to_string(),
                reason: "not a file name; write e.g. `out.csv`".into(),
            });
        }
        let mut k = 0;
        let (temp, file) = loop {
            let temp = partial(path, k);
            match File::options().write(true).create_new(true).open(&temp) {
                Ok(f) => break (temp, f),
                Err(e) if e.kind() == io::ErrorKind::AlreadyExists && k < 100 => k += 1,
                Err(e) => return Err(fail(e)),
            }
        };
        if let Some(m) = existing {
            // The new file keeps the old one's permissions.
            let _ = file.set_permissions(m.permissions());
        }
        Ok(Output {
            path: path.to_path_buf(),
            temp: Some(temp),
            file: BufWriter::new(file),
        })
    }

    /// The output's path.
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// Where the bytes go until the commit (the output itself if written in place).
    pub fn temp_path(&self) -> &Path {
        self.temp.as_deref().unwrap_or(&self.path)
    }

    /// Flushes, and renames the temporary file over the output.
    pub fn commit(mut self) -> Result<(), OutputError> {
        let path = self.path.clone();
        let fail = |e: io::Error| OutputError::write(&path, &e);
        self.file.flush().map_err(fail)?;
        if let Some(temp) = self.temp.take() {
            let done = self
                .file
                .get_ref()
                .sync_all()
                .and_then(|()| std::fs::rename(&temp, &path));
            if let Err(e) = done {
                let _ = std::fs::remove_file(&temp);
                return Err(fail(e));
            }
        }
        Ok(())
    }
}

impl Write for Output {
    fn write(&mut self, buf: &[u8]) -> io::Result<usize> {
        self.file.write(buf)
    }

    fn flush(&mut self) -> io::Result<()> {
        self.file.flush()
    }
}

impl Drop for Output {
    fn drop(&mut self) {
        if let Some(temp) = &self.temp {
            let _ = std::fs::remove_file(temp);
        }
    }
}

/// The `k`-th choice of a temporary file beside `path`: `NAME.PID.partial`, then
/// `NAME.PID-k.partial`.
fn partial(path: &Path, k: usize) -> PathBuf {
    let name = path
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    let pid = std::process::id();
    path.with_file_name(match k {
        0 => format!("{name}.{pid}.partial"),
        k => format!("{name}.{pid}-{k}.partial"),
    })
}

/// Where a writer that opens its own file (the run's log) writes `path` until
/// [`finish`]: a temporary file beside it, or `path` itself when it is not a regular
/// file (a device). Refuses `path` if it is one of `inputs`.
pub fn temp_beside<P: AsRef<Path>>(path: &Path, inputs: &[P]) -> Result<PathBuf, OutputError> {
    refuse_input(path, inputs)?;
    if std::fs::metadata(path).is_ok_and(|m| !m.is_file() && !m.is_dir()) {
        return Ok(path.to_path_buf());
    }
    let mut k = 0;
    while k < 100 && partial(path, k).exists() {
        k += 1;
    }
    Ok(partial(path, k))
}

/// Renames a finished `temp` (from [`temp_beside`]) over `path`.
pub fn finish(temp: &Path, path: &Path) -> Result<(), OutputError> {
    if temp == path {
        return Ok(());
    }
    std::fs::rename(temp, path).map_err(|e| {
        let _ = std::fs::remove_file(temp);
        OutputError::write(path, &e)
    })
}

/// Gives up a `temp` (from [`temp_beside`]) that will not be finished: removes it, unless
/// it is `path` itself (a device, written in place: never removed).
pub fn discard(temp: &Path, path: &Path) {
    if temp != path {
        let _ = std::fs::remove_file(temp);
    }
}

/// Writes `bytes` to `path` through a temporary file, refusing it if it is one of
/// `inputs`.
pub fn write_output<P: AsRef<Path>>(
    path: &Path,
    inputs: &[P],
    bytes: &[u8],
) -> Result<(), OutputError> {
    let mut out = Output::create(path, inputs)?;
    out.write_all(bytes)
        .map_err(|e| OutputError::write(path, &e))?;
    out.commit()
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used, clippy::panic)]

    use super::*;

    fn dir(name: &str) -> PathBuf {
        let d = std::env::temp_dir().join(format!("vworks-output-{name}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&d);
        std::fs::create_dir_all(&d).unwrap();
        d
    }

    #[test]
    fn an_output_replaces_the_old_file_only_when_it_is_complete() {
        let d = dir("replace");
        let out = d.join("t.csv");
        std::fs::write(&out, "old").unwrap();
        let mut o = Output::create(&out, &[] as &[&Path]).unwrap();
        o.write_all(b"new").unwrap();
        o.flush().unwrap();
        assert_eq!(std::fs::read_to_string(&out).unwrap(), "old");
        assert!(o.temp_path().exists());
        let temp = o.temp_path().to_path_buf();
        drop(o); // a failure: no commit
        assert_eq!(std::fs::read_to_string(&out).unwrap(), "old");
        assert!(!temp.exists());
        write_output(&out, &[] as &[&Path], b"new").unwrap();
        assert_eq!(std::fs::read_to_string(&out).unwrap(), "new");
        let left: Vec<_> = std::fs::read_dir(&d).unwrap().collect();
        assert_eq!(left.len(), 1, "no temporary file is left");
    }

    #[test]
    fn an_output_that_is_an_input_is_refused_by_path_link_or_inode() {
        let d = dir("input");
        let input = d.join("cell.toml");
        std::fs::write(&input, "cell").unwrap();
        let inputs = [input.clone()];
        let dotted = d.join(".").join("cell.toml");
        let mut cases = vec![input.clone(), dotted];
        #[cfg(unix)]
        {
            let link = d.join("link.toml");
            std::os::unix::fs::symlink(&input, &link).unwrap();
            let hard = d.join("hard.toml");
            std::fs::hard_link(&input, &hard).unwrap();
            cases.extend([link, hard]);
        }
        for out in cases {
            let e = write_output(&out, &inputs, b"oops")
                .unwrap_err()
                .to_string();
            assert!(e.contains("would destroy it"), "{e}");
            assert_eq!(std::fs::read_to_string(&input).unwrap(), "cell");
        }
        write_output(&d.join("other.toml"), &inputs, b"ok").unwrap();
    }

    #[test]
    fn a_full_disk_says_so() {
        let e = io::Error::from(io::ErrorKind::StorageFull);
        let m = OutputError::write(Path::new("t.csv"), &e).to_string();
        assert_eq!(
            m,
            "cannot write `t.csv`: no space left on device; free some space, or write it elsewhere"
        );
        let e = io::Error::from_raw_os_error(28);
        assert!(reason(&e).starts_with("no space left on device"));
    }

    #[cfg(target_os = "linux")]
    #[test]
    fn a_device_is_written_in_place_and_a_full_one_fails() {
        let e = write_output(Path::new("/dev/full"), &[] as &[&Path], b"x")
            .unwrap_err()
            .to_string();
        assert!(e.contains("no space left on device"), "{e}");
        write_output(Path::new("/dev/null"), &[] as &[&Path], b"x").unwrap();
        // A writer of its own writes the device itself, and giving it up keeps it.
        let temp = temp_beside(Path::new("/dev/null"), &[] as &[&Path]).unwrap();
        assert_eq!(temp, Path::new("/dev/null"));
        discard(&temp, Path::new("/dev/null"));
        assert!(Path::new("/dev/null").exists());
    }
}
