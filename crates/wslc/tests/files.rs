//! Programs of several files: a RAPID task's modules and a WSL program's library files
//! compile into one module whose positions name their own file, and whose diagnostics
//! name the file and the line in it.

use vworks_vm::Module;
use vworks_wslc::{Language, compile_files, compile_program, rapid};

const MAIN: &str =
    "MODULE MainMod\n  PERS num nParts := 0;\n  PROC main()\n    Pick;\n  ENDPROC\nENDMODULE\n";
const TOOLS: &str = "! tools\nMODULE Tools\n  PROC Pick()\n    WaitTime 0.5;\n    Incr nParts;\n  ENDPROC\nENDMODULE\n";

#[test]
fn a_rapid_task_of_two_files_is_one_module_with_positions_in_each() {
    let out = rapid::compile_files(&[("main.mod", MAIN), ("tools.mod", TOOLS)], None)
        .unwrap_or_else(|e| panic!("{e}"));
    let m = &out.module;
    assert_eq!(m.files, ["main.mod", "tools.mod"]);
    assert_eq!(m.source_path(), "main.mod");
    let pick = m.proc("pick").unwrap_or_else(|| panic!("no pick"));
    assert_eq!((pick.pos.file, pick.pos.line, pick.pos.col), (1, 3, 8));
    assert_eq!(m.file_of(pick.pos), "tools.mod");
    let main = m.proc("main").unwrap_or_else(|| panic!("no main"));
    assert_eq!((main.pos.file, main.pos.line), (0, 3));
    // Code of both files is in the line table, each row with its file.
    let files: Vec<u32> = m.lines.iter().map(|l| l.pos.file).collect();
    assert!(files.contains(&0) && files.contains(&1), "{files:?}");
    // The file list and the positions survive the bytecode.
    let back = Module::decode(&m.encode()).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(&back, m);
}

#[test]
fn the_order_of_the_files_does_not_change_what_the_task_does() {
    let a = rapid::compile_files(&[("main.mod", MAIN), ("tools.mod", TOOLS)], None)
        .unwrap_or_else(|e| panic!("{e}"));
    let b = rapid::compile_files(&[("tools.mod", TOOLS), ("main.mod", MAIN)], None)
        .unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(b.module.files, ["tools.mod", "main.mod"]);
    let pick = |m: &Module| {
        m.proc("pick")
            .map(|p| (m.file_of(p.pos).to_string(), p.pos.line))
    };
    assert_eq!(pick(&a.module), pick(&b.module));
}

#[test]
fn diagnostics_name_their_file_and_its_line() {
    let bad = TOOLS.replace("Incr nParts;", "Incr nPart;");
    let e = rapid::compile_files(&[("main.mod", MAIN), ("tools.mod", &bad)], None)
        .err()
        .unwrap_or_else(|| panic!("compiled"));
    let d = &e.diagnostics[0];
    assert_eq!(
        (d.at.file.as_str(), d.at.line, d.at.col),
        ("tools.mod", 5, 10)
    );
    // The span is the file's own, for rendering with its text.
    let span = d.at.span.unwrap_or_default();
    assert_eq!(&bad[span.start as usize..span.end as usize], "nPart");
    assert!(
        d.help.as_deref().is_some_and(|h| h.contains("nParts")),
        "{:?}",
        d.help
    );
}

#[test]
fn a_file_without_a_module_is_named() {
    let e = rapid::compile_files(
        &[
            ("main.mod", MAIN),
            ("tools.mod", TOOLS),
            ("notes.mod", "! nothing\n"),
        ],
        None,
    )
    .err()
    .unwrap_or_else(|| panic!("compiled"));
    assert_eq!(e.diagnostics.len(), 1, "{e}");
    let d = &e.diagnostics[0];
    assert_eq!(d.code.as_str(), "E0005");
    assert_eq!((d.at.file.as_str(), d.at.line), ("notes.mod", 1));
}

#[test]
fn a_name_declared_in_two_files_points_at_both() {
    let again = "MODULE Again\n  PROC pick()\n  ENDPROC\nENDMODULE\n";
    let e = rapid::compile_files(
        &[
            ("main.mod", MAIN),
            ("tools.mod", TOOLS),
            ("again.mod", again),
        ],
        None,
    )
    .err()
    .unwrap_or_else(|| panic!("compiled"));
    let d = &e.diagnostics[0];
    assert_eq!(d.code.as_str(), "E0012");
    assert_eq!((d.at.file.as_str(), d.at.line), ("again.mod", 2));
    assert_eq!(
        (d.related[0].at.file.as_str(), d.related[0].at.line),
        ("tools.mod", 3)
    );
}

#[test]
fn a_wsl_program_and_its_library_file() {
    let main = "global parts = 0;\nproc main() {\n    pick();\n}\n";
    let lib = "// library\nproc pick() {\n    delay 500ms;\n    parts = parts + 1;\n}\n";
    let out =
        compile_files(&[("main.wsl", main), ("lib.wsl", lib)]).unwrap_or_else(|e| panic!("{e}"));
    let m = &out.module;
    let pick = m.proc("pick").unwrap_or_else(|| panic!("no pick"));
    assert_eq!((m.file_of(pick.pos), pick.pos.line), ("lib.wsl", 2));
    // An unterminated comment in one file does not swallow the next.
    let e = compile_program(
        Language::Wsl,
        &[("main.wsl", "/* open\n"), ("lib.wsl", lib)],
        None,
    )
    .err()
    .unwrap_or_else(|| panic!("compiled"));
    assert!(e.diagnostics.iter().all(|d| d.at.file == "main.wsl"), "{e}");
}

#[test]
fn a_position_naming_a_file_the_module_lacks_is_rejected_on_load() {
    let out = rapid::compile_files(&[("main.mod", MAIN), ("tools.mod", TOOLS)], None)
        .unwrap_or_else(|e| panic!("{e}"));
    let mut m = out.module;
    m.files.truncate(1);
    let err = Module::decode(&m.encode())
        .err()
        .unwrap_or_else(|| panic!("loaded"));
    assert!(err.to_string().contains("names file 1"), "{err}");
}
