//! What the data-driven CLI tests share: a `.case` file (a command and the files it
//! works on) and running it in a fresh folder.

#![allow(clippy::panic, clippy::unwrap_used, clippy::expect_used, dead_code)] // tests fail by panicking

use std::path::{Path, PathBuf};
use std::process::Command;

/// The repository's root.
pub fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

/// The names of the `NAME.case` files in `dir`, sorted.
pub fn case_names(dir: &Path) -> Vec<String> {
    let mut names: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .filter_map(|e| {
            let p = e.unwrap().path();
            if p.extension()? != "case" {
                return None;
            }
            Some(p.file_stem()?.to_string_lossy().into_owned())
        })
        .collect();
    names.sort();
    names
}

/// Runs one test per `NAME.case` in the repository's `folder` (the test is named `NAME`,
/// so a failing case names itself, as ruff's fixture tests do), with libtest-mimic: the
/// usual test arguments work (`cargo test --test runs -- log-lines`, `--list`). A test
/// `the folder holds at least MIN cases` guards against an emptied or moved folder.
/// `check(dir, name)` fails by panicking.
pub fn test_every_case(folder: &'static str, min: usize, check: fn(&Path, &str)) -> ! {
    use libtest_mimic::{Arguments, Failed, Trial};
    let args = Arguments::from_args();
    let dir = root().join(folder);
    let names = case_names(&dir);
    let count = names.len();
    let mut trials = vec![Trial::test(
        format!("the folder holds at least {min} cases"),
        move || {
            if count >= min {
                Ok(())
            } else {
                Err(Failed::from(format!("{folder} holds {count} cases")))
            }
        },
    )];
    for name in names {
        let dir = dir.clone();
        trials.push(Trial::test(name.clone(), move || {
            check(&dir, &name);
            Ok(())
        }));
    }
    libtest_mimic::run(&args, trials).exit()
}

/// A command (`$ vworks …`) and its files (`--- NAME` then the text).
pub struct Case {
    /// The arguments after `vworks`.
    pub args: Vec<String>,
    /// (path, text) of each file.
    pub files: Vec<(String, String)>,
}

/// Reads a `.case` file's text (lines before the command are comments).
pub fn parse(text: &str) -> Case {
    let mut args = Vec::new();
    let mut files: Vec<(String, String)> = Vec::new();
    for line in text.lines() {
        if let Some(cmd) = line.strip_prefix("$ vworks") {
            args = cmd.split_whitespace().map(str::to_string).collect();
        } else if let Some(path) = line.strip_prefix("--- ") {
            files.push((path.to_string(), String::new()));
        } else if let Some((_, body)) = files.last_mut() {
            body.push_str(line);
            body.push('\n');
        }
    }
    Case { args, files }
}

/// Runs the case in a fresh folder: (exit code, stdout, stderr), the folder's path
/// written as `$DIR`.
pub fn run(name: &str, case: &Case) -> (i32, String, String) {
    let dir = std::env::temp_dir().join(format!("vworks-errors-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    for (path, body) in &case.files {
        let p = dir.join(path);
        std::fs::create_dir_all(p.parent().unwrap()).unwrap();
        std::fs::write(p, body).unwrap();
    }
    let out = Command::new(env!("CARGO_BIN_EXE_vworks"))
        .args(&case.args)
        .current_dir(&dir)
        .env("NO_COLOR", "1")
        .output()
        .unwrap();
    let dir_text = dir.display().to_string();
    let clean = |b: &[u8]| String::from_utf8_lossy(b).replace(&dir_text, "$DIR");
    let _ = std::fs::remove_dir_all(&dir);
    (
        out.status.code().unwrap_or(-1),
        clean(&out.stdout),
        clean(&out.stderr),
    )
}

/// `1234x real time` → `Nx real time`: the only thing in an output that depends on the
/// machine.
pub fn mask_speed(text: &str) -> String {
    text.lines()
        .map(|line| match line.find("x real time") {
            Some(end) => {
                let start = line[..end]
                    .rfind(|c: char| !c.is_ascii_digit())
                    .map_or(0, |i| i + 1);
                format!("{}N{}", &line[..start], &line[end..])
            }
            None => line.to_string(),
        })
        .collect::<Vec<_>>()
        .join("\n")
        + if text.ends_with('\n') { "\n" } else { "" }
}
