//! `vworks view`: a run's report written to a new private temporary folder and opened in
//! the browser (or its path printed where none can be opened).

use std::path::{Path, PathBuf};
use std::process::ExitCode;

use crate::output::out;
use crate::report::report_to;

/// `vworks view`: the report in a temporary file, opened in the browser (`$BROWSER`, else
/// the system's opener where there is a display), or its path printed. The file is made
/// new in a folder of this user's own ([`private_dir`]): nothing another user planted in
/// the temporary folder is followed or written.
pub(crate) fn view(log: &Path) -> Result<ExitCode, String> {
    let dir = private_dir()?;
    let stem = log
        .file_stem()
        .map_or("run".into(), |s| s.to_string_lossy());
    let out = dir.join(format!("{stem}.html"));
    std::fs::OpenOptions::new()
        .write(true)
        .create_new(true)
        .open(&out)
        .map_err(|e| format!("cannot create `{}`: {e}", out.display()))?;
    let (_, code) = report_to(log, &out)?;
    match open_in_browser(&out) {
        Ok(how) => eprintln!("opened {} ({how})", out.display()),
        Err(why) => {
            eprintln!("{why}: open it yourself");
            out!("{}", out.display());
        }
    }
    Ok(code)
}

/// A new folder in the temporary folder that only this user can enter (mode 0700 on Unix),
/// with a random name: `create_dir` makes it or fails (it never follows a link planted
/// there, nor takes a folder that exists), and what it made is checked.
fn private_dir() -> Result<PathBuf, String> {
    use std::hash::{BuildHasher as _, Hasher as _};
    let tmp = std::env::temp_dir();
    let mut builder = std::fs::DirBuilder::new();
    #[cfg(unix)]
    std::os::unix::fs::DirBuilderExt::mode(&mut builder, 0o700);
    for attempt in 0..16u32 {
        // RandomState's keys are random per process; the attempt varies them within one.
        let mut h = std::collections::hash_map::RandomState::new().build_hasher();
        h.write_u32(std::process::id());
        h.write_u32(attempt);
        let dir = tmp.join(format!("vworks-view-{:016x}", h.finish()));
        match builder.create(&dir) {
            Ok(()) => {
                let meta = std::fs::symlink_metadata(&dir).map_err(|e| e.to_string());
                #[cfg(unix)]
                let private = meta.as_ref().is_ok_and(|m| {
                    std::os::unix::fs::PermissionsExt::mode(&m.permissions()) & 0o077 == 0
                });
                #[cfg(not(unix))]
                let private = true;
                if meta.is_ok_and(|m| m.is_dir()) && private {
                    return Ok(dir);
                }
                return Err(format!(
                    "`{}` is not the private folder just made; set TMPDIR to a folder of your own",
                    dir.display()
                ));
            }
            Err(e) if e.kind() == std::io::ErrorKind::AlreadyExists => {}
            Err(e) => {
                return Err(format!(
                    "cannot create `{}`: {e}; set TMPDIR to a writable folder",
                    dir.display()
                ));
            }
        }
    }
    Err(format!(
        "cannot make a new folder in `{}`: 16 random names were taken; set TMPDIR to a folder of your own",
        tmp.display()
    ))
}

/// Opens `page` in a browser: `$BROWSER` (its `%s` replaced by the path, else the path
/// appended), else `open` (macOS), `cmd /c start` (Windows) or `xdg-open` (elsewhere, with
/// a display). Returns what it ran, or why no browser could be.
fn open_in_browser(page: &Path) -> Result<String, String> {
    use std::process::{Command, Stdio};
    let path = page.display().to_string();
    let mut command = if let Some(browser) = std::env::var_os("BROWSER").filter(|b| !b.is_empty()) {
        let browser = browser.to_string_lossy().into_owned();
        let mut words = browser.split_whitespace().map(str::to_string);
        let program = words.next().unwrap_or_default();
        let mut args: Vec<String> = words.map(|w| w.replace("%s", &path)).collect();
        if !browser.contains("%s") {
            args.push(path.clone());
        }
        let mut c = Command::new(program);
        c.args(args);
        c
    } else if cfg!(target_os = "macos") {
        let mut c = Command::new("open");
        c.arg(&path);
        c
    } else if cfg!(windows) {
        let mut c = Command::new("cmd");
        c.args(["/c", "start", "", &path]);
        c
    } else {
        let display = ["DISPLAY", "WAYLAND_DISPLAY"]
            .iter()
            .any(|v| std::env::var_os(v).is_some_and(|x| !x.is_empty()));
        if !display {
            return Err("no browser: no display here (DISPLAY and WAYLAND_DISPLAY are unset) and BROWSER is not set".into());
        }
        let mut c = Command::new("xdg-open");
        c.arg(&path);
        c
    };
    let shown = format!("{:?}", command.get_program());
    command
        .stdin(Stdio::null())
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
        .map(|_| format!("with {}", shown.trim_matches('"')))
        .map_err(|e| {
            format!(
                "no browser: {} cannot be run ({e})",
                shown.trim_matches('"')
            )
        })
}
