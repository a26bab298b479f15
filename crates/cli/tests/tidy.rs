//! The architecture's rules, checked (ARCHITECTURE.md, "Invariants" and "Dependency
//! rules"), as rust-analyzer checks its own:
//!
//! - crates depend on each other only down the run's data flow, and the named rules hold
//!   ("`se` never depends on `report`", "only `cell` calls the compiler" among the crates
//!   that simulate, "`log` depends on no engine crate and the report on no engine");
//! - no two top-level modules of one crate import each other, directly or around a loop;
//! - no source file is over 1,200 lines;
//! - every path ARCHITECTURE.md's code map names exists, and every source file is on the
//!   map (itself or a folder above it).

#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

fn root() -> PathBuf {
    let r = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../..");
    r.canonicalize().unwrap_or(r)
}

/// Every `.rs` file under `dir`, sorted.
fn rust_files(dir: &Path) -> Vec<PathBuf> {
    let mut out = Vec::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        for e in std::fs::read_dir(&d).unwrap() {
            let p = e.unwrap().path();
            if p.is_dir() {
                stack.push(p);
            } else if p.extension().is_some_and(|x| x == "rs") {
                out.push(p);
            }
        }
    }
    out.sort();
    out
}

/// The workspace's crates (package name without `vworks-`) and their normal (not dev)
/// dependencies, from `cargo metadata`: each other (without `vworks-`) and outside crates
/// (as `extern:NAME`, so that no outside name is taken for one of ours).
fn crate_graph() -> BTreeMap<String, BTreeSet<String>> {
    let out = std::process::Command::new(env!("CARGO"))
        .args([
            "metadata",
            "--format-version",
            "1",
            "--no-deps",
            "--offline",
        ])
        .current_dir(root())
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let mut graph = BTreeMap::new();
    for p in v["packages"].as_array().unwrap() {
        let Some(name) = p["name"].as_str().unwrap().strip_prefix("vworks-") else {
            continue;
        };
        let deps = p["dependencies"]
            .as_array()
            .unwrap()
            .iter()
            .filter(|d| d["kind"].is_null())
            .filter_map(|d| d["name"].as_str())
            .map(|d| match d.strip_prefix("vworks-") {
                Some(ours) => ours.to_string(),
                None => format!("extern:{d}"),
            })
            .collect();
        graph.insert(name.to_string(), deps);
    }
    graph
}

/// The crates in the order of the run's data flow: each may depend only on crates before
/// it (the fuzz targets are outside the workspace).
const LAYERS: [&str; 11] = [
    "model", "vm", "log", "wslc", "cell", "se", "report", "app", "sweep", "cli", "py",
];

#[test]
fn crates_depend_only_down_the_data_flow() {
    let graph = crate_graph();
    let names: BTreeSet<&str> = graph.keys().map(String::as_str).collect();
    assert_eq!(
        names,
        LAYERS.iter().copied().collect(),
        "a crate is missing from LAYERS"
    );
    let layer = |c: &str| LAYERS.iter().position(|l| *l == c).unwrap();
    for (c, deps) in &graph {
        for d in deps.iter().filter(|d| !d.starts_with("extern:")) {
            assert!(
                layer(d) < layer(c),
                "`{c}` depends on `{d}`, which comes after it in the data flow"
            );
        }
    }
    // The named rules (ARCHITECTURE.md).
    assert!(
        !graph["se"].contains("report"),
        "se never depends on report"
    );
    for simulating in ["model", "vm", "se", "report", "app", "sweep"] {
        assert!(
            !graph[simulating].contains("wslc"),
            "only cell calls the compiler among the crates that simulate: `{simulating}` depends on wslc"
        );
    }
    assert!(graph["cell"].contains("wslc"));
    // The run's vocabulary and log stand apart from the engine: the engine writes through
    // them and the report reads a log through them alone.
    for engine_side in ["se", "cell", "wslc", "extern:parry3d-f64"] {
        assert!(
            !graph["log"].contains(engine_side),
            "log depends on no engine, cell, compiler or geometry crate: it depends on `{engine_side}`"
        );
    }
    assert!(graph["se"].contains("log"), "the engine writes through log");
    assert!(
        graph["report"].contains("log") && !graph["report"].contains("se"),
        "the report reads a log through log, never through the engine"
    );
    assert!(
        graph["model"].iter().all(|d| d.starts_with("extern:")),
        "model depends on no other vworks crate"
    );
}

/// The top-level modules of `src` (`engine` for `engine.rs` or `engine/`), and which of
/// them each one refers to through `crate::` paths (`use crate::trace::Kind`,
/// `crate::mcaplog::McapLog`).
fn module_graph(src: &Path) -> BTreeMap<String, BTreeSet<String>> {
    let top = |p: &Path| -> Option<String> {
        let rel = p.strip_prefix(src).ok()?;
        let first = rel
            .components()
            .next()?
            .as_os_str()
            .to_string_lossy()
            .into_owned();
        let name = first.strip_suffix(".rs").unwrap_or(&first).to_string();
        (name != "lib" && name != "main").then_some(name)
    };
    let mut graph: BTreeMap<String, BTreeSet<String>> = BTreeMap::new();
    for file in rust_files(src) {
        let Some(from) = top(&file) else { continue };
        let whole = std::fs::read_to_string(&file).unwrap();
        // Unit tests (at the end of a file) may use any module.
        // Comments (doc links) are not imports.
        let text: String = whole
            .split("#[cfg(test)]")
            .next()
            .unwrap_or("")
            .lines()
            .filter(|l| !l.trim_start().starts_with("//"))
            .collect::<Vec<_>>()
            .join("\n");
        let entry = graph.entry(from.clone()).or_default();
        for (i, _) in text.match_indices("crate::") {
            // `vworks_se::…` is another crate; `crate::` starts a path in this one.
            let before = text[..i].chars().next_back();
            if before.is_some_and(|c| c.is_alphanumeric() || c == '_') {
                continue;
            }
            let rest = &text[i + "crate::".len()..];
            let name: String = rest
                .chars()
                .take_while(|c| c.is_alphanumeric() || *c == '_')
                .collect();
            if !name.is_empty() && name != from {
                entry.insert(name);
            }
        }
    }
    // Only edges between modules (not to items of the crate root).
    let modules: BTreeSet<String> = graph.keys().cloned().collect();
    for deps in graph.values_mut() {
        deps.retain(|d| modules.contains(d));
    }
    graph
}

/// A cycle in `graph`, if there is one (as the list of modules around it).
fn find_cycle(graph: &BTreeMap<String, BTreeSet<String>>) -> Option<Vec<String>> {
    fn visit(
        n: &str,
        graph: &BTreeMap<String, BTreeSet<String>>,
        state: &mut BTreeMap<String, u8>,
        path: &mut Vec<String>,
    ) -> Option<Vec<String>> {
        state.insert(n.to_string(), 1);
        path.push(n.to_string());
        for d in graph.get(n).into_iter().flatten() {
            match state.get(d.as_str()) {
                Some(1) => {
                    let at = path.iter().position(|p| p == d).unwrap_or(0);
                    let mut cycle = path[at..].to_vec();
                    cycle.push(d.clone());
                    return Some(cycle);
                }
                Some(_) => {}
                None => {
                    if let Some(c) = visit(d, graph, state, path) {
                        return Some(c);
                    }
                }
            }
        }
        path.pop();
        state.insert(n.to_string(), 2);
        None
    }
    let mut state = BTreeMap::new();
    for n in graph.keys() {
        if !state.contains_key(n.as_str())
            && let Some(c) = visit(n, graph, &mut state, &mut Vec::new())
        {
            return Some(c);
        }
    }
    None
}

#[test]
fn no_import_loops_between_the_modules_of_a_crate() {
    let mut checked = 0;
    for c in LAYERS {
        let src = root().join("crates").join(c).join("src");
        let graph = module_graph(&src);
        if let Some(cycle) = find_cycle(&graph) {
            panic!(
                "crates/{c}: modules import each other: {}",
                cycle.join(" → ")
            );
        }
        checked += graph.len();
    }
    assert!(checked > 20, "only {checked} modules found");
    // The check finds a loop where there is one.
    let looped = BTreeMap::from([
        ("a".to_string(), BTreeSet::from(["b".to_string()])),
        ("b".to_string(), BTreeSet::from(["a".to_string()])),
    ]);
    assert_eq!(find_cycle(&looped).map(|c| c.len()), Some(3));
}

/// The longest a source file may be.
const MAX_LINES: usize = 1200;

#[test]
fn no_source_file_is_over_1200_lines() {
    let mut long = Vec::new();
    for file in rust_files(&root().join("crates")) {
        if !file.components().any(|c| c.as_os_str() == "src") {
            continue;
        }
        let lines = std::fs::read_to_string(&file).unwrap().lines().count();
        if lines > MAX_LINES {
            long.push(format!("{} ({lines} lines)", file.display()));
        }
    }
    assert!(long.is_empty(), "split these files: {long:?}");
}

#[test]
fn the_code_map_matches_the_tree() {
    let map = std::fs::read_to_string(root().join("ARCHITECTURE.md")).unwrap();
    let section = map
        .split("## Code map")
        .nth(1)
        .and_then(|s| s.split("\n## ").next())
        .expect("ARCHITECTURE.md has a code map");
    // Every path in the first column of the table: backticked, with a `/`.
    let mut named = BTreeSet::new();
    for row in section.lines().filter(|l| l.starts_with("| `")) {
        let first = row.split('|').nth(1).unwrap_or("");
        for quoted in first.split('`').skip(1).step_by(2) {
            let path = quoted.split_whitespace().next().unwrap_or("");
            if path.contains('/') {
                named.insert(path.trim_end_matches('/').to_string());
            }
        }
    }
    let missing: Vec<&String> = named.iter().filter(|p| !root().join(p).exists()).collect();
    assert!(
        missing.is_empty(),
        "the code map names paths that do not exist: {missing:?}"
    );
    let mut unmapped = Vec::new();
    for file in rust_files(&root().join("crates")) {
        let rel = file
            .strip_prefix(root())
            .unwrap_or(&file)
            .to_string_lossy()
            .replace('\\', "/");
        if !rel.contains("/src/") {
            continue;
        }
        let on_map = rel
            .match_indices('/')
            .map(|(i, _)| &rel[..i])
            .chain([rel.as_str()])
            .any(|p| named.contains(p) && p.contains("/src"))
            // A crate's root module is on the map with its crate's row.
            || rel
                .strip_suffix("/src/lib.rs")
                .is_some_and(|c| named.contains(c));
        if !on_map {
            unmapped.push(rel);
        }
    }
    assert!(
        unmapped.is_empty(),
        "source files missing from ARCHITECTURE.md's code map: {unmapped:?}"
    );
}
