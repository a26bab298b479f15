//! The verifier rejects each kind of unsafe module, and accepts a minimal good one.
//! Modules are built by hand here, so these tests do not depend on the compiler.

#![allow(clippy::panic, clippy::unwrap_used, clippy::expect_used)] // tests fail by panicking

use vworks_vm::bytecode::ConstInfo;
use vworks_vm::bytecode::{
    CodeProblem, ErrorHandler, Instr, LoadError, ProcInfo, ProcKind, SrcPos, StringUser,
    VerifyError,
};
use vworks_vm::{ConstValue, Module, Type};

fn module(code: Vec<Instr>, kind: ProcKind, ret: Option<Type>, frame: u32) -> Module {
    Module {
        files: vec!["hand.wsl".into()],
        strings: vec!["p".into()],
        procs: vec![ProcInfo {
            name: 0,
            kind,
            params: vec![],
            ret,
            frame_slots: frame,
            code_start: 0,
            code_len: code.len() as u32,
            pos: SrcPos {
                file: 0,
                line: 1,
                col: 1,
            },
            max_stack: 0,
            handler: None,
        }],
        code,
        ..Module::default()
    }
}

/// The verifier's error for `m`, which it must reject.
fn rejection(mut m: Module) -> VerifyError {
    match m.verify() {
        Err(LoadError::Invalid(e)) => e,
        other => panic!("expected an invalid module, got {other:?}"),
    }
}

/// The problem at an instruction of procedure 0 (`p`) that the verifier must find, and
/// the instruction's offset.
fn code_problem(m: Module) -> (usize, CodeProblem) {
    match rejection(m) {
        VerifyError::Code {
            procedure: 0,
            offset,
            problem,
            ..
        } => (offset, problem),
        other => panic!("expected a problem in procedure 0's code, got {other:?}"),
    }
}

#[test]
fn a_good_module_verifies_and_gets_its_stack_depth() {
    let mut m = module(
        vec![
            Instr::PushInt(1),
            Instr::PushInt(2),
            Instr::AddI,
            Instr::StoreLocal(0),
            Instr::Ret,
        ],
        ProcKind::Proc,
        None,
        1,
    );
    m.verify().unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(m.procs[0].max_stack, 2);
    // And survives the binary round trip.
    assert_eq!(Module::decode(&m.encode()), Ok(m));
}

/// An error handler's entries (the handler, and where `Retry`/`TryNext` go) start with an
/// empty stack and lie inside the procedure; its table survives the round trip.
#[test]
fn error_handlers_are_checked_as_entries() {
    // 0..2: one statement (push, store); 2: Ret; 3..5: the handler (push 7, raise).
    let code = vec![
        Instr::PushInt(1),
        Instr::StoreLocal(0),
        Instr::Ret,
        Instr::PushInt(7),
        Instr::Raise(0),
    ];
    let mut m = module(code.clone(), ProcKind::Proc, None, 1);
    m.procs[0].handler = Some(ErrorHandler {
        pc: 3,
        stmts: vec![(0, 2)],
    });
    m.verify().unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(Module::decode(&m.encode()), Ok(m.clone()));
    // A handler past the end.
    m.procs[0].handler = Some(ErrorHandler {
        pc: 9,
        stmts: vec![],
    });
    assert!(matches!(
        code_problem(m.clone()),
        (0, CodeProblem::HandlerOutside { len: 5 })
    ));
    // A statement whose start has a value on the stack: `Retry` would go there with none.
    m.procs[0].handler = Some(ErrorHandler {
        pc: 3,
        stmts: vec![(1, 2)],
    });
    assert!(matches!(
        code_problem(m),
        (
            1,
            CodeProblem::HeightMismatch { .. } | CodeProblem::Underflow { .. }
        )
    ));
}

#[test]
fn stack_underflow() {
    assert_eq!(
        code_problem(module(
            vec![Instr::AddI, Instr::Ret],
            ProcKind::Proc,
            None,
            0
        )),
        (
            0,
            CodeProblem::Underflow {
                instr: Instr::AddI,
                pops: 2,
                height: 0
            }
        )
    );
}

#[test]
fn inconsistent_heights_at_a_join() {
    // Instruction 4 is reached with height 1 (through 2 and 3) and with height 0 (from 1).
    let code = vec![
        Instr::PushBool(true),
        Instr::JumpIfFalse(4),
        Instr::PushInt(1),
        Instr::Jump(4),
        Instr::Pop(1),
        Instr::Ret,
    ];
    assert_eq!(
        code_problem(module(code, ProcKind::Proc, None, 0)),
        (
            4,
            CodeProblem::HeightMismatch {
                height: 0,
                other: 1
            }
        )
    );
}

#[test]
fn jump_outside_the_procedure() {
    assert_eq!(
        code_problem(module(
            vec![Instr::Jump(7), Instr::Ret],
            ProcKind::Proc,
            None,
            0
        )),
        (0, CodeProblem::JumpOutside { target: 7, len: 2 })
    );
}

#[test]
fn falling_off_the_end() {
    assert_eq!(
        code_problem(module(
            vec![Instr::PushInt(1), Instr::Pop(1)],
            ProcKind::Proc,
            None,
            0,
        )),
        (1, CodeProblem::FallsOffEnd)
    );
}

#[test]
fn local_outside_the_frame() {
    assert_eq!(
        code_problem(module(
            vec![Instr::LoadLocal(3), Instr::Pop(1), Instr::Ret],
            ProcKind::Proc,
            None,
            2,
        )),
        (
            0,
            CodeProblem::Operand {
                instr: Instr::LoadLocal(3),
                kind: ProcKind::Proc
            }
        )
    );
}

#[test]
fn events_in_zero_time_code() {
    let code = vec![
        Instr::PushNum(1.0),
        Instr::Delay,
        Instr::PushBool(true),
        Instr::RetVal,
    ];
    assert_eq!(
        code_problem(module(code, ProcKind::Func, Some(Type::Bool), 0)),
        (
            1,
            CodeProblem::EventInZeroTime {
                instr: Instr::Delay,
                kind: ProcKind::Func
            }
        )
    );
}

#[test]
fn returning_with_values_left() {
    assert_eq!(
        code_problem(module(
            vec![Instr::PushInt(1), Instr::Ret],
            ProcKind::Proc,
            None,
            0
        )),
        (1, CodeProblem::ReturnWithValues { left: 1 })
    );
}

#[test]
fn non_finite_numbers() {
    let (offset, problem) = code_problem(module(
        vec![Instr::PushNum(f64::NAN), Instr::Pop(1), Instr::Ret],
        ProcKind::Proc,
        None,
        0,
    ));
    // NaN is not equal to itself: match the instruction, not the value.
    assert_eq!(offset, 0);
    assert!(
        matches!(
            problem,
            CodeProblem::Operand {
                instr: Instr::PushNum(x),
                kind: ProcKind::Proc
            } if x.is_nan()
        ),
        "{problem:?}"
    );
    let mut m = module(vec![Instr::Ret], ProcKind::Proc, None, 0);
    m.consts.push(ConstInfo {
        name: None,
        ty: Type::Pose,
        value: ConstValue::Pose([0.0, f64::INFINITY, 0.0, 0.0, 0.0, 0.0]),
        pos: SrcPos::default(),
    });
    assert_eq!(
        rejection(m),
        VerifyError::Constant {
            index: 0,
            ty: Type::Pose
        }
    );
}

#[test]
fn string_index_out_of_range() {
    let mut m = module(vec![Instr::Ret], ProcKind::Proc, None, 0);
    m.procs[0].name = 9;
    assert_eq!(
        rejection(m),
        VerifyError::StringIndex {
            user: StringUser::Procedure(0),
            index: 9,
            count: 1
        }
    );
}

#[test]
fn truncated_and_foreign_files_are_load_errors() {
    let m = module(vec![Instr::Ret], ProcKind::Proc, None, 0);
    let bytes = m.encode();
    assert_eq!(
        Module::decode(&bytes[..bytes.len() - 3])
            .err()
            .map(|e| matches!(e, LoadError::Malformed { .. })),
        Some(true)
    );
    let mut v = bytes.clone();
    v[4] = 9;
    assert_eq!(
        Module::decode(&v),
        Err(LoadError::Version {
            found: 9,
            supported: vworks_vm::bytecode::FORMAT_VERSION
        })
    );
    assert_eq!(Module::decode(b"\x7fELF"), Err(LoadError::BadMagic));
}

#[test]
fn garbage_behind_an_endless_jump_is_rejected_too() {
    // Found by the load_bytecode fuzzer: `Jump 0` makes the rest unreachable, but a
    // loaded module may contain no invalid instruction anywhere.
    let code = vec![
        Instr::Jump(0),
        Instr::PushNum(f64::NAN),
        Instr::Pop(1),
        Instr::Ret,
    ];
    let (offset, problem) = code_problem(module(code, ProcKind::Proc, None, 0));
    assert_eq!(offset, 1);
    assert!(
        matches!(problem, CodeProblem::Operand { instr: Instr::PushNum(x), .. } if x.is_nan()),
        "{problem:?}"
    );
    let code = vec![
        Instr::Jump(0),
        Instr::PushConst(99),
        Instr::Pop(1),
        Instr::Ret,
    ];
    assert_eq!(
        code_problem(module(code, ProcKind::Proc, None, 0)),
        (
            1,
            CodeProblem::Operand {
                instr: Instr::PushConst(99),
                kind: ProcKind::Proc
            }
        )
    );
    let code = vec![Instr::Jump(0), Instr::Jump(40)];
    assert_eq!(
        code_problem(module(code, ProcKind::Proc, None, 0)),
        (1, CodeProblem::JumpOutside { target: 40, len: 2 })
    );
}

#[test]
fn code_outside_every_procedure_is_rejected() {
    // Also found by the fuzzer: a shortened `code_len` left instructions in no procedure.
    let mut m = module(
        vec![Instr::Ret, Instr::PushNum(f64::NAN)],
        ProcKind::Proc,
        None,
        0,
    );
    m.procs[0].code_len = 1;
    assert_eq!(
        rejection(m),
        VerifyError::CodeCoverage {
            covered: 1,
            code: 2
        }
    );
}

#[test]
fn the_message_names_the_procedure_and_the_instruction() {
    // The kinds above are the contract; this pins the text the CLI prints for one of them.
    let e = LoadError::from(rejection(module(
        vec![Instr::AddI, Instr::Ret],
        ProcKind::Proc,
        None,
        0,
    )));
    assert_eq!(
        e.to_string(),
        "invalid module: procedure 0 (p), instruction 0: AddI pops 2 slots but the stack holds 0"
    );
}
