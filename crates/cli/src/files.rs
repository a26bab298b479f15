//! The files named on the command line: reading one (size limit, UTF-8, or Latin-1 for RAPID; errors
//! that say what to do), and what each is — a program, a workcell, a sweep file — so a
//! command given the wrong one says which to give.

use std::path::{Path, PathBuf};

/// A file named on the command line: a regular file within the size limit
/// (`vworks_cell::Disk`, as the workcell's files are read).
pub(crate) fn read_bytes(path: &Path) -> Result<Vec<u8>, String> {
    use vworks_cell::Files as _;
    vworks_cell::Disk
        .read(path)
        .map_err(|e| cannot_read(path, &e))
}

pub(crate) fn read(path: &Path) -> Result<String, String> {
    let bytes = read_bytes(path)?;
    vworks_wslc::source_text_of(&path.to_string_lossy(), bytes)
        .map_err(|e| format!("{}: {e}", path.display()))
}

/// "cannot read FILE: why; what to do" for a file named on the command line.
pub(crate) fn cannot_read(path: &Path, e: &std::io::Error) -> String {
    let hint = match e.kind() {
        std::io::ErrorKind::NotFound => "; check the path (relative to the current folder)",
        std::io::ErrorKind::PermissionDenied => "; check the file's permissions",
        _ => "",
    };
    format!("cannot read `{}`: {e}{hint}", path.display())
}

pub(crate) fn display(path: &Path) -> String {
    path.display().to_string()
}

/// True for a program file (by its extension): WSL, RAPID, or bytecode.
pub(crate) fn is_program(path: &Path) -> bool {
    let text = path.to_string_lossy();
    let ext = path.extension().map(|e| e.to_string_lossy().to_lowercase());
    ext.as_deref() == Some("wslb") || vworks_wslc::Language::of_source_file(&text).is_some()
}

/// True for what `check` takes as a workcell: a `.toml` file, or a folder.
pub(crate) fn is_cell(path: &Path) -> bool {
    path.is_dir()
        || path
            .extension()
            .is_some_and(|e| e.eq_ignore_ascii_case("toml"))
}

/// The workcell file that `command` was given as `path`: the path itself, or the
/// `cell.toml` of a folder. A program file, a sweep file, or a folder without a
/// `cell.toml`, is an error saying what to give instead.
pub(crate) fn cell_file(path: &Path, command: &str) -> Result<PathBuf, String> {
    if path.is_dir() {
        let file = path.join("cell.toml");
        if file.is_file() {
            return Ok(file);
        }
        let mut tomls: Vec<String> = std::fs::read_dir(path)
            .map(|entries| {
                entries
                    .filter_map(Result::ok)
                    .map(|e| e.file_name().to_string_lossy().into_owned())
                    .filter(|n| n.ends_with(".toml"))
                    .collect()
            })
            .unwrap_or_default();
        tomls.sort();
        let there = if tomls.is_empty() {
            "; `vworks new NAME` creates a workcell folder".to_string()
        } else {
            let named: Vec<String> = tomls
                .iter()
                .map(|n| format!("`{}`", path.join(n).display()))
                .collect();
            format!("; name the workcell file: {}", named.join(", "))
        };
        return Err(format!(
            "`{}` is a folder without a cell.toml: `vworks {command}` takes a workcell file{there}",
            path.display()
        ));
    }
    if is_program(path) {
        let name = path
            .file_name()
            .map_or_else(String::new, |n| n.to_string_lossy().into_owned());
        let cell = path
            .parent()
            .map_or_else(|| PathBuf::from("cell.toml"), |d| d.join("cell.toml"));
        let what = format!(
            "`{}` is a program, but `vworks {command}` takes a workcell: a cell.toml naming the robots, their models and their programs",
            path.display()
        );
        if cell.is_file() {
            return Err(format!(
                "{what}; the one beside it: `vworks {command} {}`",
                cell.display()
            ));
        }
        return Err(format!(
            "{what}. Write one beside the program:\n\n    [[robot]]\n    name = \"r1\"\n    model = \"irb120\"\n    program = \"{name}\"\n\nthen `vworks {command} {}`; or `vworks new NAME` creates a workcell folder ready to run (`vworks check {}` compiles the program alone)",
            cell.display(),
            path.display()
        ));
    }
    not_a_sweep_file(path, command)?;
    Ok(path.to_path_buf())
}

/// What a TOML file given on the command line is, by its top-level keys: a sweep file
/// (`cell = "…"` and `[[variable]]`s) and the workcell it names, a workcell (its robots'
/// names), or something else (not readable, not TOML, neither: the command says why).
pub(crate) enum Kind {
    Sweep { cell: PathBuf },
    Workcell { robots: Vec<String> },
    Other,
}

/// The top-level keys of a sweep file (`vworks_sweep`'s format).
pub(crate) const SWEEP_KEYS: [&str; 6] =
    ["cell", "combine", "seed", "until", "minimize", "variable"];
/// The top-level keys of a workcell (`vworks_cell`'s format).
pub(crate) const CELL_KEYS: [&str; 11] = [
    "name",
    "cycle",
    "clearance",
    "grip_distance",
    "on_collision",
    "robot",
    "device",
    "part",
    "allow_collision",
    "params",
    "io",
];

pub(crate) fn kind_of(path: &Path) -> Kind {
    if !path.is_file() {
        return Kind::Other;
    }
    let Ok(Ok(file)) = read(path).map(|t| t.parse::<toml::Table>()) else {
        return Kind::Other;
    };
    match file.get("cell") {
        Some(toml::Value::String(cell))
            if file.contains_key("variable")
                || file.keys().all(|k| SWEEP_KEYS.contains(&k.as_str())) =>
        {
            let dir = path.parent().map(Path::to_path_buf).unwrap_or_default();
            Kind::Sweep {
                cell: dir.join(cell),
            }
        }
        None if file.keys().any(|k| CELL_KEYS.contains(&k.as_str())) => Kind::Workcell {
            robots: file
                .get("robot")
                .and_then(toml::Value::as_array)
                .map(|rs| {
                    rs.iter()
                        .filter_map(|r| r.get("name")?.as_str().map(str::to_string))
                        .collect()
                })
                .unwrap_or_default(),
        },
        _ => Kind::Other,
    }
}

/// `Err` if `path`, given to `vworks COMMAND` as a workcell, is a sweep file: how to run
/// it, and the workcell it names.
pub(crate) fn not_a_sweep_file(path: &Path, command: &str) -> Result<(), String> {
    let Kind::Sweep { cell } = kind_of(path) else {
        return Ok(());
    };
    let missing = if cell.is_file() {
        ""
    } else {
        " (not there: check its `cell`, relative to the sweep file)"
    };
    Err(format!(
        "`{}` is a sweep file (the workcell to vary and its `[[variable]]`s), but `vworks {command}` takes a workcell: run the sweep with `vworks sweep {}`, or the workcell it names with `vworks {command} {}`{missing}",
        path.display(),
        path.display(),
        cell.display(),
    ))
}
