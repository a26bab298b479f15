//! The architecture's rules, checked (ARCHITECTURE.md, "Invariants" and "Dependency
//! rules"), as rust-analyzer checks its own:
//!
//! - crates depend on each other only down the run's data flow, and the named rules hold
//!   ("`se` never depends on `report`", "only `cell` calls the compiler" among the crates
//!   that simulate, "`log` depends on no engine crate and the report on no engine");
//! - no two top-level modules of one crate import each other, directly or around a loop,
//!   the crate's root (`lib.rs`, `main.rs`) counted as a module;
//! - no struct has more than 20 fields (split it into components that own their state);
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

/// A source text without what is not code for the import graph: unit tests (at the end of
/// a file, they may use any module) and comments (doc links are not imports).
fn code_of(whole: &str) -> String {
    whole
        .split("#[cfg(test)]")
        .next()
        .unwrap_or("")
        .lines()
        .filter(|l| !l.trim_start().starts_with("//"))
        .collect::<Vec<_>>()
        .join("\n")
}

/// The first segment of each path a `crate::` at `rest` names: `trace` for
/// `crate::trace::Kind`, `trace` and `Compiled` for `crate::{trace::Kind, Compiled}`.
fn first_segments(rest: &str) -> Vec<String> {
    let word = |t: &str| -> String {
        t.trim_start()
            .chars()
            .take_while(|c| c.is_alphanumeric() || *c == '_')
            .collect()
    };
    let Some(group) = rest.strip_prefix('{') else {
        return vec![word(rest)];
    };
    // The group's top-level items, up to its closing brace.
    let (mut depth, mut items, mut start) = (0usize, Vec::new(), 0usize);
    for (i, c) in group.char_indices() {
        match c {
            '{' => depth += 1,
            '}' if depth == 0 => {
                items.push(word(&group[start..i]));
                break;
            }
            '}' => depth -= 1,
            ',' if depth == 0 => {
                items.push(word(&group[start..i]));
                start = i + 1;
            }
            _ => {}
        }
    }
    items
}

/// The module graph of one crate's `src`: its top-level modules (`engine` for `engine.rs`
/// or `engine/`) and its root (`lib` or `main`), and which of them each one uses.
///
/// - A module uses another through `crate::` paths (`use crate::trace::Kind`, grouped
///   `use crate::{trace::Kind, stats}`, `crate::mcaplog::McapLog`).
/// - A module uses the root when it names an item the root defines itself
///   (`crate::Compiled`, a struct in lib.rs); an item the root re-exports
///   (`pub use diag::Code`) is a use of the module it comes from.
/// - The root uses a module when its code names it (`rapid::compile_files(…)`); declaring
///   it (`pub mod rapid;`) or re-exporting its items (`pub use`) is not a use.
fn module_graph(src: &Path) -> BTreeMap<String, BTreeSet<String>> {
    let top = |p: &Path| -> Option<String> {
        let rel = p.strip_prefix(src).ok()?;
        let first = rel
            .components()
            .next()?
            .as_os_str()
            .to_string_lossy()
            .into_owned();
        Some(first.strip_suffix(".rs").unwrap_or(&first).to_string())
    };
    let is_root = |m: &str| m == "lib" || m == "main";
    let files = rust_files(src);
    let modules: BTreeSet<String> = files.iter().filter_map(|f| top(f)).collect();
    // What the root defines, and what it re-exports from which module.
    let mut root_items = BTreeSet::new();
    let mut reexported: BTreeMap<String, String> = BTreeMap::new();
    let mut root_uses = BTreeSet::new();
    for file in files.iter().filter(|f| top(f).is_some_and(|m| is_root(&m))) {
        let text = code_of(&std::fs::read_to_string(file).unwrap());
        for statement in text.split(';') {
            let st = statement.trim();
            if let Some(path) = st.strip_prefix("pub use ") {
                let Some((module, items)) = path.split_once("::") else {
                    continue;
                };
                let items = items.trim_start_matches('{').trim_end_matches('}');
                for item in items.split(',') {
                    let item = item.split(" as ").last().unwrap_or("").trim();
                    let name = item.rsplit("::").next().unwrap_or("").to_string();
                    if !name.is_empty() && modules.contains(module) {
                        reexported.insert(name, module.to_string());
                    }
                }
            }
        }
        for line in text.lines() {
            let t = line.trim_start();
            if t.starts_with("pub mod ")
                || t.starts_with("mod ")
                || t.starts_with("pub use ")
                || t.starts_with("pub(crate) mod ")
            {
                continue;
            }
            let words: Vec<&str> = t
                .split(|c: char| !(c.is_alphanumeric() || c == '_'))
                .collect();
            for kw in ["struct", "enum", "fn", "const", "static", "type", "trait"] {
                if let Some(i) = words.iter().position(|w| *w == kw)
                    && let Some(name) = words.get(i + 1).filter(|n| !n.is_empty())
                {
                    root_items.insert((*name).to_string());
                }
            }
            for m in &modules {
                let pat = format!("{m}::");
                for (i, _) in line.match_indices(&pat) {
                    let before = &line[..i];
                    let is_path_start = before
                        .chars()
                        .next_back()
                        .is_none_or(|c| !(c.is_alphanumeric() || c == '_' || c == ':'))
                        || before.ends_with("crate::")
                        || before.ends_with("self::");
                    if is_path_start && !is_root(m) {
                        root_uses.insert(m.clone());
                    }
                }
            }
        }
    }
    let mut graph: BTreeMap<String, BTreeSet<String>> = BTreeMap::new();
    for file in &files {
        let Some(from) = top(file) else { continue };
        let entry = graph.entry(from.clone()).or_default();
        if is_root(&from) {
            entry.extend(root_uses.iter().cloned());
            continue;
        }
        let text = code_of(&std::fs::read_to_string(file).unwrap());
        for (i, _) in text.match_indices("crate::") {
            // `vworks_se::…` is another crate; `crate::` starts a path in this one.
            let before = text[..i].chars().next_back();
            if before.is_some_and(|c| c.is_alphanumeric() || c == '_') {
                continue;
            }
            for name in first_segments(&text[i + "crate::".len()..]) {
                let to = if modules.contains(&name) {
                    Some(name)
                } else if let Some(m) = reexported.get(&name) {
                    Some(m.clone())
                } else if root_items.contains(&name) {
                    modules.iter().find(|m| is_root(m)).cloned()
                } else {
                    None
                };
                if let Some(to) = to.filter(|t| *t != from) {
                    entry.insert(to);
                }
            }
        }
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
    let mut loops = Vec::new();
    for c in LAYERS {
        let src = root().join("crates").join(c).join("src");
        let graph = module_graph(&src);
        if let Some(cycle) = find_cycle(&graph) {
            loops.push(format!("crates/{c}: {}", cycle.join(" → ")));
        }
        checked += graph.len();
    }
    assert!(loops.is_empty(), "modules import each other: {loops:#?}");
    assert!(checked > 20, "only {checked} modules found");
    // The check finds a loop where there is one.
    let looped = BTreeMap::from([
        ("a".to_string(), BTreeSet::from(["b".to_string()])),
        ("b".to_string(), BTreeSet::from(["a".to_string()])),
    ]);
    assert_eq!(find_cycle(&looped).map(|c| c.len()), Some(3));
    // Grouped imports and the crate root's own items are seen.
    assert_eq!(
        first_segments("{trace::Kind, Compiled, stats::{Fold, X}};"),
        ["trace", "Compiled", "stats"]
    );
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

/// The most fields a struct may have: past it, a struct is several things, each better a
/// component owning its own state behind a narrow interface.
const MAX_FIELDS: usize = 20;

/// Each `struct NAME { … }` of `text` with braces: its name, line and number of fields.
fn structs_of(text: &str) -> Vec<(String, usize, usize)> {
    let lines: Vec<&str> = text.lines().collect();
    let mut out = Vec::new();
    let mut i = 0;
    while i < lines.len() {
        let t = lines[i].trim_start();
        let t = t.strip_prefix("pub ").unwrap_or(t);
        let t = t
            .strip_prefix("pub(crate) ")
            .or_else(|| t.strip_prefix("pub(super) "))
            .unwrap_or(t);
        let Some(rest) = t.strip_prefix("struct ") else {
            i += 1;
            continue;
        };
        if !lines[i].trim_end().ends_with('{') {
            i += 1;
            continue;
        }
        let name: String = rest
            .chars()
            .take_while(|c| c.is_alphanumeric() || *c == '_')
            .collect();
        let (start, mut depth, mut fields) = (i, 1i32, 0usize);
        i += 1;
        while i < lines.len() && depth > 0 {
            let l = lines[i].trim_start();
            if depth == 1 && !l.starts_with("//") && !l.starts_with('#') {
                let l = l.strip_prefix("pub ").unwrap_or(l);
                let l = l
                    .strip_prefix("pub(crate) ")
                    .or_else(|| l.strip_prefix("pub(super) "))
                    .unwrap_or(l);
                let field: String = l
                    .chars()
                    .take_while(|c| c.is_alphanumeric() || *c == '_')
                    .collect();
                if !field.is_empty() && l[field.len()..].trim_start().starts_with(':') {
                    fields += 1;
                }
            }
            depth += lines[i].matches('{').count() as i32 - lines[i].matches('}').count() as i32;
            i += 1;
        }
        out.push((name, start + 1, fields));
    }
    out
}

#[test]
fn no_struct_has_over_20_fields() {
    let mut big = Vec::new();
    let mut seen = 0;
    for file in rust_files(&root().join("crates")) {
        if !file.components().any(|c| c.as_os_str() == "src") {
            continue;
        }
        for (name, line, fields) in structs_of(&std::fs::read_to_string(&file).unwrap()) {
            seen += 1;
            if fields > MAX_FIELDS {
                big.push(format!(
                    "{name} ({}:{line}, {fields} fields)",
                    file.display()
                ));
            }
        }
    }
    assert!(seen > 100, "only {seen} structs found");
    assert!(
        big.is_empty(),
        "split these structs into components: {big:?}"
    );
    // The count sees fields, with attributes, comments and nested braces.
    let sample = "pub struct A {\n    /// doc\n    pub a: u8,\n    #[x]\n    pub(crate) b: Vec<u8>,\n    c: fn() -> u8,\n    d: [u8; 2],\n}\nstruct B { }\n";
    assert_eq!(structs_of(sample), [("A".to_string(), 1, 4)]);
}
