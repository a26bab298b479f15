//! RAPID as it is found on controllers (issue 31): constructs whose diagnostics were
//! wrong, each with what the RAPID reference says of it.

#![allow(clippy::panic, clippy::unwrap_used, clippy::expect_used)] // tests fail by panicking

use vworks_wslc::{Code, Language, compile_as};

/// The codes and positions (line, column) of a module's errors; empty if it compiles.
fn errors(src: &str) -> Vec<(Code, u32, u32)> {
    match compile_as(Language::Rapid, "m.mod", src) {
        Ok(_) => Vec::new(),
        Err(e) => e
            .diagnostics
            .iter()
            .map(|d| (d.code, d.at.line, d.at.col))
            .collect(),
    }
}

/// RAPID's intnum is an alias data type of num, with num's properties (ABB's technical
/// reference manual, data type intnum): an intnum takes a num as its initial value or
/// by assignment, and is a num in arithmetic.
#[test]
fn an_intnum_is_a_num() {
    let src = "MODULE m
    VAR intnum i := 13;
    VAR num n := 0;
    PROC main()
        i := i + 1;
        n := i * 2;
        WaitTime n / 28;
    ENDPROC
ENDMODULE
";
    assert_eq!(errors(src), []);
}

/// An array whose size names a constant declared nowhere is an unknown name (E0010,
/// at the name), as anywhere else; a size that is data, not a constant, is still E0080.
#[test]
fn an_array_size_naming_nothing_is_an_unknown_name() {
    // (Line 3, column 17: the size's name after `    VAR num arr{`.)
    let module = |decl: &str, size: &str| {
        format!(
            "MODULE m\n    {decl}\n    VAR num arr{{{size}}};\n    PROC main()\n        WaitTime 1;\n    ENDPROC\nENDMODULE\n"
        )
    };
    assert_eq!(
        errors(&module("CONST num N := 3;", "M")),
        [(Code::E0010, 3, 17)]
    );
    assert_eq!(
        errors(&module("VAR num k := 3;", "k")),
        [(Code::E0080, 3, 17)]
    );
}

/// Without the workcell's I/O (`vworks check m.mod`), a signal is any name an I/O
/// instruction of the task gives as one: `IF di1 = 1` reads the signal that `WaitDI di1,
/// 1` waits on (before, the read was an unknown name while the wait passed), wherever the
/// two stand; a name no I/O instruction gives is still unknown.
#[test]
fn a_signal_read_in_an_expression_is_the_signal_an_instruction_names() {
    let src = "MODULE m
    PROC main()
        IF di1 = 1 THEN
            WaitTime 1;
        ENDIF
        WHILE DI2 = 0 AND di1 = 1 DO
            WaitTime 0.1;
        ENDWHILE
        Other;
    ENDPROC
    PROC Other()
        WaitDI di1, 1;
        PulseDO \\PLength:=0.1, di2;
    ENDPROC
ENDMODULE
";
    assert_eq!(errors(src), []);
    let src = "MODULE m
    PROC main()
        IF di7 = 1 THEN
            WaitDI di1, 1;
        ENDIF
    ENDPROC
ENDMODULE
";
    assert_eq!(errors(src), [(Code::E0010, 3, 12)]);
}
