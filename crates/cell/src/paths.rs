//! Helpers of the loader: the files a workcell names (programs, ROS packages) and the
//! words of its errors.

use std::path::{Path, PathBuf};

use crate::context::Ctx;
use crate::error::CellError;

/// Where ROS keeps packages, searched for `package://` meshes after the workcell's
/// `package_path`: each folder of `ROS_PACKAGE_PATH` (ROS 1), and `PREFIX/share` for each
/// prefix of `AMENT_PREFIX_PATH` (ROS 2), in order.
pub(crate) fn ros_package_paths() -> Vec<PathBuf> {
    let split = |var: &str| -> Vec<PathBuf> {
        std::env::var_os(var)
            .map(|v| {
                std::env::split_paths(&v)
                    .filter(|p| !p.as_os_str().is_empty())
                    .collect()
            })
            .unwrap_or_default()
    };
    let mut paths = split("ROS_PACKAGE_PATH");
    paths.extend(
        split("AMENT_PREFIX_PATH")
            .into_iter()
            .map(|p| p.join("share")),
    );
    paths
}

/// serde's "unknown field `cylce`, expected one of `name`, `cycle`, …" with the nearest
/// valid key named: "…; did you mean `cycle`?".
pub(crate) fn with_suggestion(msg: &str) -> String {
    let Some(rest) = msg.strip_prefix("unknown field `") else {
        return msg.to_string();
    };
    let Some((field, expected)) = rest.split_once('`') else {
        return msg.to_string();
    };
    let valid = expected.split('`').skip(1).step_by(2);
    match vworks_wslc::nearest(field, valid) {
        Some(near) => format!("{msg}; did you mean `{near}`?"),
        None => msg.to_string(),
    }
}

/// The program files of robot `key` (`program`: one path, or a list of paths to files of
/// one language), each joined to the workcell's folder `dir`.
pub(crate) fn program_files(
    cx: &Ctx<'_>,
    key: &str,
    program: &toml::Value,
    dir: &Path,
) -> Result<Vec<String>, CellError> {
    let at = format!("{key}.program");
    let how = "write one file (`program = \"r1.wsl\"`) or a list of files of one language (`program = [\"main.mod\", \"tools.mod\"]`)";
    let names: Vec<&str> = match program {
        toml::Value::String(s) => vec![s.as_str()],
        toml::Value::Array(list) if !list.is_empty() => {
            let mut names = Vec::with_capacity(list.len());
            for (k, v) in list.iter().enumerate() {
                let Some(s) = v.as_str() else {
                    return Err(cx.bad(
                        &format!("{at}[{k}]"),
                        format!("`{v}` is not a file name; {how}"),
                    ));
                };
                names.push(s);
            }
            names
        }
        toml::Value::Array(_) => {
            return Err(cx.bad(&at, format!("lists no files; {how}")));
        }
        v => return Err(cx.bad(&at, format!("`{v}` is not a file name; {how}"))),
    };
    let paths: Vec<String> = names
        .iter()
        .map(|n| dir.join(n).display().to_string())
        .collect();
    if let Err((k, why)) = vworks_wslc::Language::of_files(&names) {
        return Err(cx.bad(
            &format!("{at}[{k}]"),
            format!("{why} (give a robot of each language its own program)"),
        ));
    }
    // The same file however it is written (`main.mod`, `./main.mod`).
    let same: Vec<PathBuf> = names
        .iter()
        .map(|n| {
            Path::new(n)
                .components()
                .filter(|c| !matches!(c, std::path::Component::CurDir))
                .collect()
        })
        .collect();
    if let Some(k) = (1..same.len()).find(|&k| same[..k].contains(&same[k])) {
        return Err(cx.bad(
            &format!("{at}[{k}]"),
            format!("lists `{}` a second time; name each file once", names[k]),
        ));
    }
    Ok(paths)
}

/// A TOML or schema error of the workcell file's text, at its line and column.
pub(crate) fn parse_error(cx: &Ctx<'_>, text: &str, e: &toml::de::Error) -> CellError {
    let msg = with_suggestion(e.message());
    let place = e.span().map(|s| {
        let before = &text[..s.start.min(text.len())];
        let line = before.matches('\n').count() + 1;
        let col = before.len() - before.rfind('\n').map_or(0, |i| i + 1) + 1;
        format!("line {line}, column {col}")
    });
    cx.bad(
        &place.unwrap_or_else(|| "file".into()),
        format!("{msg}; the workcell format, key by key, is in docs/engine.md"),
    )
}
