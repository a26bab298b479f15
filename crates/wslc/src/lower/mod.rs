//! Checking and code generation in one walk over the syntax tree, split by what is being
//! compiled:
//!
//! - this file: the driver ([`lower`]), the checking types (`Ty`, `Out`) and the
//!   per-procedure context;
//! - `resolve`: module-level declarations and the symbol table (name resolution), collected
//!   before any body is compiled;
//! - `codegen`: the emitter (instructions, jumps, constants, line table, procedures);
//! - `stmt`: statements, with the zero-time and function rules where each is compiled;
//! - `expr`: expressions, types and units, constant folding, calls, unknown names;
//! - `rules`: conditions and handlers, and the checks closed over the call graph;
//! - `builtins`: the built-in function table and its type rules.
//!
//! Declarations are collected first (procedure signatures, then globals, constants and
//! module variables in order, each initializer evaluated at compile time); then every body
//! is type- and unit-checked while its bytecode is emitted. Each expression yields its
//! [`Ty`] and, when it is constant, its value: the code emitted for a constant
//! subexpression is replaced by one push, which is both constant folding and the
//! evaluator for module-level initializers.
//!
//! `wait_until` and `when` conditions, and the argument lists of `when` handlers, are
//! compiled into synthetic procedures whose parameters are the locals they *capture* (by
//! value, when the wait starts or the handler is enabled). Facts gathered per procedure —
//! does it take time, which globals does it read, does it read clock or robot state, whom
//! does it call — are closed over the call graph at the end to enforce the zero-time rule
//! of handlers and to give every condition the exact set of globals it depends on.

use std::collections::{BTreeSet, HashMap};

use vworks_vm::bytecode::{
    Capture, Cmp, CondInfo, ConstInfo, GlobalInfo, HandlerInfo, Instr, JointsSite, LineEntry,
    LogFormat, LogPart, MoveFlags, ParamInfo, PartSite, ProcInfo, ProcKind, RemoteSite, SignalSite,
    SrcPos, SyncSite, Trigger, VarInfo,
};
use vworks_vm::math;
use vworks_vm::{ConstValue, Dim, MAX_AXES, Module, Type};

use crate::diag::{Code, Diagnostic};
use crate::frontend::program::ProgramText;
use crate::syntax::*;

mod builtins;
mod codegen;
mod expr;
mod from_rapid;
mod resolve;
mod rules;
mod stmt;

pub(crate) use builtins::BUILTINS;
use builtins::builtin_named;

/// A type during checking: the run-time types plus text, "no value" and "already wrong".
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) enum Ty {
    Bool,
    Int,
    Num(Dim),
    Joints,
    Pose,
    /// A text (only in a translation from RAPID: WSL writes text only in `log`/`fail`).
    Text,
    Void,
    Error,
}

impl Ty {
    fn vm(self) -> Option<Type> {
        Some(match self {
            Ty::Bool => Type::Bool,
            Ty::Int => Type::Int,
            Ty::Num(d) => Type::Num(d),
            Ty::Joints => Type::Joints,
            Ty::Pose => Type::Pose,
            Ty::Text => Type::Text,
            _ => return None,
        })
    }
    fn width(self) -> u8 {
        self.vm().map_or(0, Type::width)
    }
    /// How a value of this type is described in messages: "an int", "a length", "a pose".
    fn described(self) -> String {
        match self {
            Ty::Bool => "a bool".into(),
            Ty::Int => "an int".into(),
            Ty::Num(d) => d.described(),
            Ty::Joints => "a joints value".into(),
            Ty::Pose => "a pose".into(),
            Ty::Text => "a text".into(),
            Ty::Void => "no value".into(),
            Ty::Error => "an invalid value".into(),
        }
    }
    fn is_err(self) -> bool {
        self == Ty::Error
    }
}

/// The unit a bare number most likely meant, for "write 2s".
fn default_unit(d: Dim) -> Option<&'static str> {
    Some(match d {
        Dim::LENGTH => "mm",
        Dim::ANGLE => "deg",
        Dim::TIME => "s",
        Dim::SPEED => "mm/s",
        Dim::ANGSPEED => "deg/s",
        Dim::ACCEL => "mm/s2",
        Dim::ANGACCEL => "deg/s2",
        _ => return None,
    })
}

/// The result of checking an expression.
#[derive(Clone, Debug)]
struct Out {
    ty: Ty,
    /// The value, if known at compile time.
    k: Option<ConstValue>,
    /// A number literal written without unit (for "write 2s" help).
    bare: bool,
}

impl Out {
    fn err() -> Out {
        Out {
            ty: Ty::Error,
            k: None,
            bare: false,
        }
    }
    fn of(ty: Ty) -> Out {
        Out {
            ty,
            k: None,
            bare: false,
        }
    }
    fn is_zero_literal(&self) -> bool {
        self.bare && matches!(self.k, Some(ConstValue::Int(0) | ConstValue::Num(0.0)))
    }
}

#[derive(Clone, Debug)]
enum Sym {
    Global(u32, Ty),
    Const(Ty, ConstValue),
    Var(u32, Ty),
    /// A `param`: a module variable the program only reads.
    Param(u32, Ty),
    Proc(u32),
}

#[derive(Clone, Debug)]
struct Sig {
    name: String,
    is_func: bool,
    params: Vec<(String, Ty)>,
    ret: Ty,
    span: Span,
}

/// Per-procedure facts, closed over the call graph at the end.
#[derive(Clone, Debug, Default)]
struct Facts {
    /// The first statement that takes time: what it is and where.
    time: Option<(String, Span)>,
    /// Calls to user procedures/functions.
    calls: Vec<(u32, Span)>,
    /// Globals read.
    globals: BTreeSet<u32>,
    /// The first read of clock, robot state or a module variable.
    impure: Option<(String, Span)>,
}

#[derive(Clone, Copy, Debug, PartialEq)]
enum FnKind {
    Proc,
    Func,
    Cond,
    Handler,
    /// A module-level initializer: constants only.
    Init,
}

#[derive(Clone, Debug)]
struct Local {
    name: String,
    slot: u32,
    ty: Ty,
    mutable: bool,
}

#[derive(Debug, Default)]
struct Loop {
    breaks: Vec<usize>,
    continues: Vec<usize>,
}

#[derive(Debug)]
struct FnCtx {
    index: u32,
    kind: FnKind,
    ret: Ty,
    code: Vec<Instr>,
    lines: Vec<(u32, SrcPos)>,
    scopes: Vec<Vec<Local>>,
    next_slot: u32,
    loops: Vec<Loop>,
    /// Captured locals of the enclosing procedure: name, its slot there, width, type.
    captures: Vec<(String, u32, u8, Ty)>,
    /// The statements' `[start, end)` of a procedure with an error handler (for `Retry`
    /// and `TryNext`), while its body is compiled.
    stmts: Option<Vec<(u32, u32)>>,
    /// Compiling an error handler: `Retry`, `TryNext` and `RAISE;` may stand here.
    in_handler: bool,
    /// Inside a `parallel` block's local branch: `Some(loops)`, the loops open around
    /// the block (a `break` or `continue` to one of them, or a `return`, would leave the
    /// block before its join: E0063).
    in_parallel: Option<usize>,
}

impl FnCtx {
    fn new(index: u32, kind: FnKind, ret: Ty) -> FnCtx {
        FnCtx {
            index,
            kind,
            ret,
            code: Vec::new(),
            lines: Vec::new(),
            scopes: vec![Vec::new()],
            next_slot: 0,
            loops: Vec::new(),
            captures: Vec::new(),
            stmts: None,
            in_handler: false,
            in_parallel: None,
        }
    }
}

struct PendingCond {
    cond: u32,
    span: Span,
}

struct PendingHandler {
    target: u32,
    span: Span,
}

/// Compiles a parsed module. Diagnostics get spans; the caller resolves positions.
pub(crate) fn lower(
    program: &ProgramText,
    ast: &SourceModule,
    diags: &mut Vec<Diagnostic>,
) -> Module {
    let mut c = Compiler {
        program,
        diags,
        m: Module {
            files: program.paths(),
            ..Module::default()
        },
        strings: HashMap::new(),
        symbols: HashMap::new(),
        sigs: Vec::new(),
        facts: Vec::new(),
        proc_code: Vec::new(),
        fns: Vec::new(),
        pending_conds: Vec::new(),
        pending_handlers: Vec::new(),
        disabled: Vec::new(),
        scratch_facts: Facts::default(),
        texts: ast.texts,
    };
    c.module(ast);
    c.m
}

/// A finished procedure's instructions and its (pc, position) rows.
type ProcCode = (Vec<Instr>, Vec<(u32, SrcPos)>);

struct Compiler<'d> {
    program: &'d ProgramText,
    diags: &'d mut Vec<Diagnostic>,
    m: Module,
    strings: HashMap<String, u32>,
    symbols: HashMap<String, (Sym, Span)>,
    sigs: Vec<Sig>,
    facts: Vec<Facts>,
    /// Code and line rows (procedure-relative) of each procedure, by index.
    proc_code: Vec<ProcCode>,
    fns: Vec<FnCtx>,
    pending_conds: Vec<PendingCond>,
    pending_handlers: Vec<PendingHandler>,
    disabled: Vec<(u32, Span)>,
    /// Facts of module-level initializers, which are discarded.
    scratch_facts: Facts,
    /// Text values are allowed ([`SourceModule::texts`]: a translation from RAPID).
    texts: bool,
}

const TYPE_NAMES: &str =
    "bool, int, num, length, angle, time, speed, angspeed, accel, angaccel, joints, pose";

impl Compiler<'_> {
    // ---- infrastructure ------------------------------------------------------------------

    fn err(&mut self, d: Diagnostic) {
        self.diags.push(d);
    }

    fn pos(&self, span: Span) -> SrcPos {
        self.program.pos(span.start as usize)
    }

    fn f(&mut self) -> &mut FnCtx {
        let n = self.fns.len();
        &mut self.fns[n - 1]
    }

    fn fk(&self) -> FnKind {
        self.fns.last().map_or(FnKind::Init, |f| f.kind)
    }

    fn facts(&mut self) -> &mut Facts {
        match self.fns.last() {
            Some(f) if f.kind != FnKind::Init && (f.index as usize) < self.facts.len() => {
                &mut self.facts[f.index as usize]
            }
            _ => &mut self.scratch_facts,
        }
    }

    // ---- module ----------------------------------------------------------------------------

    // ---- statements --------------------------------------------------------------------

    // ---- whole-module rules --------------------------------------------------------------

    // ---- expressions -------------------------------------------------------------------
}

fn to_num(k: &Option<ConstValue>) -> Option<ConstValue> {
    match k {
        Some(ConstValue::Int(i)) => Some(ConstValue::Num(*i as f64)),
        other => other.clone(),
    }
}

fn num2(
    a: &Option<ConstValue>,
    b: &Option<ConstValue>,
    f: impl Fn(f64, f64) -> f64,
) -> Option<ConstValue> {
    match (a, b) {
        (Some(ConstValue::Num(x)), Some(ConstValue::Num(y))) => Some(ConstValue::Num(f(*x, *y))),
        _ => None,
    }
}

/// The comparison instruction's operator for a comparison `op`.
fn cmp_of(op: BinOp) -> Cmp {
    match op {
        BinOp::Eq => Cmp::Eq,
        BinOp::Ne => Cmp::Ne,
        BinOp::Lt => Cmp::Lt,
        BinOp::Le => Cmp::Le,
        BinOp::Gt => Cmp::Gt,
        _ => Cmp::Ge,
    }
}

/// Checks and generates code for a syntax tree (if the front-end produced one), verifies
/// the module, and resolves and sorts the diagnostics.
pub(crate) fn finish(
    program: &ProgramText,
    ast: Option<&SourceModule>,
    mut diags: Vec<Diagnostic>,
) -> Result<crate::output::Compiled, crate::output::CompileError> {
    let mut module = if !diags.iter().any(Diagnostic::is_error)
        && let Some(ast) = ast
    {
        Some(lower(program, ast, &mut diags))
    } else {
        None
    };
    if let Some(m) = module.as_mut()
        && !diags.iter().any(Diagnostic::is_error)
        && let Err(e) = m.verify()
    {
        diags.push(
            Diagnostic::error(
                Code::E0900,
                format!("the compiler produced invalid bytecode: {e}"),
                Span::default(),
            )
            .with_help(
                "this is a bug in vworks; please report it with the program that triggers it",
            ),
        );
    }
    for d in &mut diags {
        program.resolve(d);
    }
    diags.sort_by_key(|d| (program.order_of(&d.at.file), d.at.line, d.at.col));
    match module {
        Some(module) if !diags.iter().any(Diagnostic::is_error) => Ok(crate::output::Compiled {
            module,
            warnings: diags,
        }),
        _ => Err(crate::output::CompileError { diagnostics: diags }),
    }
}
