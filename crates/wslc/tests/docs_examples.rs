//! The examples in `docs/language.md` are real: each ```wsl block compiles without
//! warnings, and each ```wsl-error block fails with the code on its first line.

#![allow(clippy::panic, clippy::unwrap_used, clippy::expect_used)] // tests fail by panicking

use vworks_wslc::{Sources, compile, render};

fn blocks(tag: &str) -> Vec<String> {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../../docs/language.md");
    let doc = std::fs::read_to_string(path).unwrap_or_else(|e| panic!("{path}: {e}"));
    let open = format!("```{tag}\n");
    let mut out = Vec::new();
    let mut rest = doc.as_str();
    while let Some(i) = rest.find(&open) {
        let body = &rest[i + open.len()..];
        let end = body.find("```").unwrap_or(body.len());
        out.push(body[..end].to_string());
        rest = &body[end..];
    }
    out
}

#[test]
fn wsl_blocks_compile() {
    let all = blocks("wsl");
    assert!(all.len() >= 9, "found only {} examples", all.len());
    for (i, src) in all.iter().enumerate() {
        let name = format!("language.md example {}", i + 1);
        match compile(&name, src) {
            Ok(out) => assert!(out.warnings.is_empty(), "{name}: {:?}", out.warnings),
            Err(e) => {
                let mut s = Sources::new();
                s.add(&name, src);
                panic!(
                    "{name} does not compile:\n{}",
                    render(&e.diagnostics, &s, false)
                );
            }
        }
    }
}

#[test]
fn wsl_error_blocks_fail_with_their_code() {
    let all = blocks("wsl-error");
    assert!(!all.is_empty());
    for src in all {
        let code = src
            .lines()
            .next()
            .unwrap_or("")
            .trim_start_matches("//")
            .trim()
            .to_string();
        let e = compile("example.wsl", &src)
            .err()
            .unwrap_or_else(|| panic!("should fail:\n{src}"));
        assert!(
            e.diagnostics.iter().any(|d| d.code.as_str() == code),
            "{code}: {:?}",
            e.diagnostics
        );
    }
}
