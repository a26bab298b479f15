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

/// "The data type intnum is an alias data type for num and thus inherits its
/// properties" (RAPID reference, intnum): an intnum takes a num as its initial value or
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
    let src = "MODULE m
    CONST num N := 3;
    VAR num arr{M};
    PROC main()
        WaitTime 1;
    ENDPROC
ENDMODULE
";
    assert_eq!(errors(src), [(Code::E0010, 3, 17)]);
    let src = "MODULE m
    VAR num k := 3;
    VAR num arr{k};
    PROC main()
        WaitTime 1;
    ENDPROC
ENDMODULE
";
    assert_eq!(errors(src), [(Code::E0080, 3, 17)]);
}
