//! Programs at the compiler's limits: what a robot programmer writes in bulk (a dispatch on
//! a program number with hundreds of `else if` branches) compiles; what would overflow the
//! compiler's stack (an expression of 10,000 terms) is E0006, never a crash. These run on
//! the test harness's threads (2 MiB stacks), smaller than a program's main thread.

#![allow(clippy::panic, clippy::unwrap_used, clippy::expect_used)] // tests fail by panicking

use vworks_wslc::{Code, compile};

#[test]
fn an_else_if_chain_of_500_branches_is_not_nesting() {
    let mut src = String::from("proc main() {\n    var n = 3;\n    if n == 0 { log 0; }\n");
    for i in 1..500 {
        src.push_str(&format!("    else if n == {i} {{ log {i}; }}\n"));
    }
    src.push_str("    else { log -1; }\n}\n");
    let out = compile("chain.wsl", &src).unwrap_or_else(|e| panic!("{e}"));
    assert!(out.warnings.is_empty());
    // One test and one jump out per branch: the chain compiles flat.
    let jumps = out
        .module
        .code
        .iter()
        .filter(|i| matches!(i, vworks_vm::Instr::JumpIfFalse(_)))
        .count();
    assert_eq!(jumps, 500);
}

#[test]
fn an_expression_of_10000_terms_is_e0006_not_a_stack_overflow() {
    let terms = vec!["1"; 10_000].join(" + ");
    let src = format!("proc main() {{ var x = {terms}; log x; }}\n");
    let err = compile("long.wsl", &src).unwrap_err();
    assert!(err.diagnostics.iter().any(|d| d.code == Code::E0006));
    // As deep as the limit allows still compiles.
    let terms = vec!["1"; 120].join(" + ");
    let src = format!("proc main() {{ var x = {terms}; log x; }}\n");
    compile("ok.wsl", &src).unwrap_or_else(|e| panic!("{e}"));
}
