//! Checking and code generation in one walk over the syntax tree.
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
    SrcPos, Trigger, VarInfo,
};
use vworks_vm::math;
use vworks_vm::{ConstValue, Dim, MAX_AXES, Module, Type};

use crate::diag::{Code, Diagnostic, LineIndex};
use crate::syntax::*;

/// A type during checking: the run-time types plus text, "no value" and "already wrong".
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) enum Ty {
    Bool,
    Int,
    Num(Dim),
    Joints,
    Pose,
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
    path: &str,
    src: &str,
    ast: &SourceModule,
    diags: &mut Vec<Diagnostic>,
) -> Module {
    let mut c = Compiler {
        index: LineIndex::new(src),
        diags,
        m: Module {
            source_path: path.to_string(),
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
    };
    c.module(ast);
    c.m
}

/// A finished procedure's instructions and its (pc, position) rows.
type ProcCode = (Vec<Instr>, Vec<(u32, SrcPos)>);

struct Compiler<'d> {
    index: LineIndex,
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
}

const BUILTINS: &[&str] = &[
    "now",
    "cycle",
    "timed_out",
    "current_joints",
    "current_pose",
    "offset",
    "tool_offset",
    "abs",
    "min",
    "max",
    "sqrt",
    "sin",
    "cos",
    "atan2",
    "int",
    "num",
    "joints",
    "pose",
    "axis_length",
];

const TYPE_NAMES: &str =
    "bool, int, num, length, angle, time, speed, angspeed, accel, angaccel, joints, pose";

pub(crate) fn edit_distance(a: &str, b: &str) -> usize {
    let b: Vec<char> = b.chars().collect();
    let mut prev: Vec<usize> = (0..=b.len()).collect();
    for (i, ca) in a.chars().enumerate() {
        let mut cur = vec![i + 1];
        for (j, cb) in b.iter().enumerate() {
            let sub = prev[j] + usize::from(ca != *cb);
            cur.push(sub.min(prev[j + 1] + 1).min(cur[j] + 1));
        }
        prev = cur;
    }
    prev[b.len()]
}

impl Compiler<'_> {
    // ---- infrastructure ------------------------------------------------------------------

    fn err(&mut self, d: Diagnostic) {
        self.diags.push(d);
    }

    fn str(&mut self, s: &str) -> u32 {
        if let Some(&i) = self.strings.get(s) {
            return i;
        }
        let i = self.m.strings.len() as u32;
        self.m.strings.push(s.to_string());
        self.strings.insert(s.to_string(), i);
        i
    }

    fn pos(&self, span: Span) -> SrcPos {
        let (line, col) = self.index.line_col(span.start as usize);
        SrcPos { line, col }
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

    fn emit(&mut self, ins: Instr, span: Span) -> usize {
        let pos = self.pos(span);
        let f = self.f();
        let pc = f.code.len() as u32;
        if f.lines.last().is_none_or(|(_, p)| *p != pos) {
            f.lines.push((pc, pos));
        }
        f.code.push(ins);
        pc as usize
    }

    fn here(&mut self) -> usize {
        self.f().code.len()
    }

    fn patch(&mut self, at: usize, target: usize) {
        let t = target as u32;
        let f = self.f();
        f.code[at] = match f.code[at] {
            Instr::Jump(_) => Instr::Jump(t),
            Instr::JumpIfFalse(_) => Instr::JumpIfFalse(t),
            Instr::JumpIfTrue(_) => Instr::JumpIfTrue(t),
            other => other,
        };
    }

    /// Drops the code emitted since `start` (used when a subexpression folded to a constant).
    fn truncate(&mut self, start: usize) {
        let f = self.f();
        f.code.truncate(start);
        while f.lines.last().is_some_and(|(pc, _)| *pc as usize >= start) {
            f.lines.pop();
        }
    }

    fn push_const(&mut self, v: &ConstValue, ty: Ty, span: Span) {
        match v {
            ConstValue::Bool(b) => {
                self.emit(Instr::PushBool(*b), span);
            }
            ConstValue::Int(i) => {
                self.emit(Instr::PushInt(*i), span);
            }
            ConstValue::Num(x) => {
                self.emit(Instr::PushNum(*x), span);
            }
            ConstValue::Joints(_) | ConstValue::Pose(_) => {
                let k = self.pool(v, ty, span);
                self.emit(Instr::PushConst(k), span);
            }
        }
    }

    fn pool(&mut self, v: &ConstValue, ty: Ty, span: Span) -> u32 {
        let vty = ty.vm().unwrap_or(Type::Pose);
        if let Some(i) = self
            .m
            .consts
            .iter()
            .position(|c| c.ty == vty && &c.value == v)
        {
            return i as u32;
        }
        let pos = self.pos(span);
        self.m.consts.push(ConstInfo {
            name: None,
            ty: vty,
            value: v.clone(),
            pos,
        });
        (self.m.consts.len() - 1) as u32
    }

    fn new_proc(&mut self, name: &str, kind: ProcKind, span: Span) -> u32 {
        let name = self.str(name);
        let pos = self.pos(span);
        self.m.procs.push(ProcInfo {
            name,
            kind,
            params: Vec::new(),
            ret: None,
            frame_slots: 0,
            code_start: 0,
            code_len: 0,
            pos,
            max_stack: 0,
        });
        self.facts.push(Facts::default());
        self.proc_code.push((Vec::new(), Vec::new()));
        (self.m.procs.len() - 1) as u32
    }

    fn finish_fn(&mut self) -> FnCtx {
        let f = self
            .fns
            .pop()
            .unwrap_or_else(|| FnCtx::new(0, FnKind::Init, Ty::Void));
        if f.kind != FnKind::Init
            && let Some(p) = self.m.procs.get_mut(f.index as usize)
        {
            p.frame_slots = f.next_slot;
            self.proc_code[f.index as usize] = (f.code.clone(), f.lines.clone());
        }
        f
    }

    fn resolve_type(&mut self, t: &Ident) -> Ty {
        let d = match t.name.as_str() {
            "bool" => return Ty::Bool,
            "int" => return Ty::Int,
            "num" => Dim::PLAIN,
            "length" => Dim::LENGTH,
            "angle" => Dim::ANGLE,
            "time" => Dim::TIME,
            "speed" => Dim::SPEED,
            "angspeed" => Dim::ANGSPEED,
            "accel" => Dim::ACCEL,
            "angaccel" => Dim::ANGACCEL,
            "joints" => return Ty::Joints,
            "pose" => return Ty::Pose,
            "string" => {
                self.err(
                    Diagnostic::error(
                        Code::E0014,
                        "`string` values cannot be stored or passed",
                        t.span,
                    )
                    .with_help("text is only written directly in `log` and `fail`"),
                );
                return Ty::Error;
            }
            _ => {
                self.err(
                    Diagnostic::error(Code::E0014, format!("unknown type `{}`", t.name), t.span)
                        .with_help(format!("the types are {TYPE_NAMES}")),
                );
                return Ty::Error;
            }
        };
        Ty::Num(d)
    }

    fn declare(&mut self, name: &Ident, sym: Sym) -> bool {
        if BUILTINS.contains(&name.name.as_str()) {
            self.err(
                Diagnostic::error(
                    Code::E0012,
                    format!("`{}` is a built-in function", name.name),
                    name.span,
                )
                .with_help("choose another name"),
            );
            return false;
        }
        if let Some((_, prev)) = self.symbols.get(&name.name) {
            let prev = *prev;
            self.err(
                Diagnostic::error(
                    Code::E0012,
                    format!("`{}` is declared twice", name.name),
                    name.span,
                )
                .with_label("declared again here")
                .with_related(prev, "first declared here"),
            );
            return false;
        }
        self.symbols.insert(name.name.clone(), (sym, name.span));
        true
    }

    // ---- module ----------------------------------------------------------------------------

    fn module(&mut self, ast: &SourceModule) {
        // 1. Procedure signatures, so calls may come before declarations.
        let mut bodies = Vec::new();
        for item in &ast.items {
            if let Item::Proc(p) = item {
                let params: Vec<(String, Ty)> = p
                    .params
                    .iter()
                    .map(|a| (a.name.name.clone(), self.resolve_type(&a.ty)))
                    .collect();
                for (i, a) in p.params.iter().enumerate() {
                    if p.params[..i].iter().any(|b| b.name.name == a.name.name) {
                        self.err(Diagnostic::error(
                            Code::E0012,
                            format!("parameter `{}` is declared twice", a.name.name),
                            a.name.span,
                        ));
                    }
                }
                let ret = match (&p.ret, p.is_func) {
                    (Some(t), true) => self.resolve_type(t),
                    (None, true) => {
                        self.err(
                            Diagnostic::error(
                                Code::E0014,
                                format!("function `{}` needs a return type", p.name.name),
                                p.span,
                            )
                            .with_help(format!(
                                "write `func {}(…) -> length {{ … }}`, or make it a `proc`",
                                p.name.name
                            )),
                        );
                        Ty::Error
                    }
                    (Some(t), false) => {
                        self.err(
                            Diagnostic::error(
                                Code::E0031,
                                "a `proc` does not return a value",
                                t.span,
                            )
                            .with_help(
                                "make it a `func` (which runs in zero time), or drop `-> type`",
                            ),
                        );
                        Ty::Void
                    }
                    (None, false) => Ty::Void,
                };
                let kind = if p.is_func {
                    ProcKind::Func
                } else {
                    ProcKind::Proc
                };
                let idx = self.new_proc(&p.name.name, kind, p.name.span);
                let mut pinfo = Vec::new();
                for (n, t) in &params {
                    let name = self.str(n);
                    pinfo.push(ParamInfo {
                        name,
                        ty: t.vm().unwrap_or(Type::Int),
                    });
                }
                self.m.procs[idx as usize].params = pinfo;
                self.m.procs[idx as usize].ret = if p.is_func {
                    ret.vm().or(Some(Type::Int))
                } else {
                    None
                };
                self.sigs.push(Sig {
                    name: p.name.name.clone(),
                    is_func: p.is_func,
                    params,
                    ret,
                    span: p.name.span,
                });
                if self.declare(&p.name, Sym::Proc(idx)) {
                    bodies.push((idx, p));
                }
            }
        }
        // 2. Globals, constants, module variables, in order.
        for item in &ast.items {
            match item {
                Item::Global(d) => self.global_decl(d),
                Item::Const(d) => self.const_decl(d),
                Item::Var(d) => self.var_decl(d),
                Item::Proc(_) => {}
            }
        }
        // 3. Bodies.
        for (idx, p) in bodies {
            self.proc_body(idx, p);
        }
        // 4. Whole-module rules over the call graph.
        self.check_handlers();
        self.finish_conds();
        self.check_disables();
        // 5. Lay out the code.
        for (i, (code, lines)) in self.proc_code.iter().enumerate() {
            let start = self.m.code.len() as u32;
            self.m.procs[i].code_start = start;
            self.m.procs[i].code_len = code.len() as u32;
            self.m.code.extend_from_slice(code);
            for (pc, pos) in lines {
                let pc = start + pc;
                if self.m.lines.last().is_none_or(|l| l.pos != *pos) {
                    self.m.lines.push(LineEntry { pc, pos: *pos });
                }
            }
        }
    }

    /// Evaluates a module-level initializer; `None` if it is not constant (reported).
    fn init_value(&mut self, d: &VarDecl, what: &str) -> Option<(Ty, ConstValue)> {
        let declared = d.ty.as_ref().map(|t| self.resolve_type(t));
        let Some(init) = &d.init else {
            let ty = declared?;
            return ty.vm().map(|t| (ty, ConstValue::zero(t)));
        };
        self.fns.push(FnCtx::new(0, FnKind::Init, Ty::Void));
        let mut out = self.expr(init);
        if let Some(t) = declared {
            out = self.coerce(out, t, init.span, &format!("the {what} `{}`", d.name.name));
        }
        self.finish_fn();
        if out.ty.is_err() {
            return None;
        }
        match out.k {
            Some(v) => Some((out.ty, v)),
            None => {
                self.err(
                    Diagnostic::error(
                        Code::E0080,
                        format!("the initial value of {what} `{}` is not a constant", d.name.name),
                        init.span,
                    )
                    .with_help("module-level values are computed before the run: use literals, constants declared above, and arithmetic"),
                );
                None
            }
        }
    }

    fn global_decl(&mut self, d: &VarDecl) {
        let Some((ty, v)) = self.init_value(d, "global") else {
            return;
        };
        if !matches!(ty, Ty::Bool | Ty::Int | Ty::Num(_)) {
            self.err(
                Diagnostic::error(Code::E0081, format!("global `{}` would be {}", d.name.name, ty.described()), d.name.span)
                    .with_help("globals are bool, int or a number (with any unit); keep poses and joints in `const` or `var`"),
            );
            return;
        }
        let idx = self.m.globals.len() as u32;
        if self.declare(&d.name, Sym::Global(idx, ty)) {
            let name = self.str(&d.name.name);
            let pos = self.pos(d.name.span);
            self.m.globals.push(GlobalInfo {
                name,
                ty: ty.vm().unwrap_or(Type::Int),
                init: v,
                pos,
            });
        }
    }

    fn const_decl(&mut self, d: &VarDecl) {
        let Some((ty, v)) = self.init_value(d, "constant") else {
            return;
        };
        if self.declare(&d.name, Sym::Const(ty, v.clone())) {
            let name = self.str(&d.name.name);
            let pos = self.pos(d.name.span);
            let vty = ty.vm().unwrap_or(Type::Int);
            // The initializer may have put the same value in the pool: name that entry.
            if let Some(c) = self
                .m
                .consts
                .iter_mut()
                .find(|c| c.name.is_none() && c.ty == vty && c.value == v)
            {
                c.name = Some(name);
                c.pos = pos;
                return;
            }
            self.m.consts.push(ConstInfo {
                name: Some(name),
                ty: ty.vm().unwrap_or(Type::Int),
                value: v,
                pos,
            });
        }
    }

    fn var_decl(&mut self, d: &VarDecl) {
        let Some((ty, v)) = self.init_value(d, "variable") else {
            return;
        };
        let slot = self.m.var_slots;
        if self.declare(&d.name, Sym::Var(slot, ty)) {
            self.m.var_slots += u32::from(ty.width());
            let name = self.str(&d.name.name);
            let pos = self.pos(d.name.span);
            self.m.vars.push(VarInfo {
                name,
                ty: ty.vm().unwrap_or(Type::Int),
                slot,
                init: v,
                pos,
            });
        }
    }

    fn proc_body(&mut self, idx: u32, p: &ProcDecl) {
        let sig = self.sigs[idx as usize].clone();
        let kind = if p.is_func {
            FnKind::Func
        } else {
            FnKind::Proc
        };
        self.fns.push(FnCtx::new(idx, kind, sig.ret));
        for (name, ty) in &sig.params {
            self.add_local(name, *ty, true);
        }
        let diverges = self.block(&p.body);
        if p.is_func {
            if !diverges && !sig.ret.is_err() {
                let end = Span::new(
                    p.body.span.end.saturating_sub(1) as usize,
                    p.body.span.end as usize,
                );
                self.err(
                    Diagnostic::error(
                        Code::E0032,
                        format!(
                            "function `{}` may end without returning a value",
                            p.name.name
                        ),
                        end,
                    )
                    .with_label("the end can be reached here")
                    .with_help("end every path with `return value;` (or `fail \"…\";`)"),
                );
            }
        } else {
            self.emit(
                Instr::Ret,
                Span::new(
                    p.body.span.end.saturating_sub(1) as usize,
                    p.body.span.end as usize,
                ),
            );
        }
        self.finish_fn();
    }

    fn add_local(&mut self, name: &str, ty: Ty, mutable: bool) -> u32 {
        let f = self.f();
        let slot = f.next_slot;
        f.next_slot += u32::from(ty.width());
        if let Some(scope) = f.scopes.last_mut() {
            scope.push(Local {
                name: name.to_string(),
                slot,
                ty,
                mutable,
            });
        }
        slot
    }

    // ---- statements --------------------------------------------------------------------

    /// Compiles a block in a new scope; true if it never completes normally.
    fn block(&mut self, b: &Block) -> bool {
        self.f().scopes.push(Vec::new());
        let mut diverges = false;
        for s in &b.stmts {
            if diverges {
                self.err(
                    Diagnostic::error(Code::W0004, "this statement can never run", s.span)
                        .with_help("remove it, or move it before the `return`/`break`/`stop`"),
                );
                break;
            }
            diverges = self.stmt(s);
        }
        self.f().scopes.pop();
        diverges
    }

    fn takes_time(&mut self, what: &str, span: Span) -> bool {
        match self.fk() {
            FnKind::Func => {
                self.err(
                    Diagnostic::error(Code::E0070, format!("a function may not {what}"), span)
                        .with_label("not allowed in a `func`")
                        .with_help("functions run in zero time; make it a `proc`"),
                );
                false
            }
            _ => {
                let f = self.facts();
                if f.time.is_none() {
                    f.time = Some((what.to_string(), span));
                }
                true
            }
        }
    }

    fn not_in_func(&mut self, what: &str, span: Span) -> bool {
        if self.fk() == FnKind::Func {
            self.err(
                Diagnostic::error(Code::E0070, format!("a function may not {what}"), span)
                    .with_label("not allowed in a `func`")
                    .with_help("functions run in zero time and have no effects outside the robot; make it a `proc`"),
            );
            return false;
        }
        true
    }

    /// Compiles a statement; true if control never continues after it.
    fn stmt(&mut self, s: &Stmt) -> bool {
        let sp = s.span;
        match &s.kind {
            StmtKind::Error => {}
            StmtKind::Var(d) => self.local_var(d),
            StmtKind::Assign { target, op, value } => self.assign(target, *op, value, sp),
            StmtKind::Call { name, args } => {
                let out = self.call(name, args, sp, true);
                let w = out.ty.width();
                if w > 0 {
                    self.emit(Instr::Pop(w), sp);
                }
            }
            StmtKind::If { branches, els } => return self.if_stmt(branches, els.as_ref()),
            StmtKind::While { cond, body } => {
                let top = self.here();
                let c = self.expr(cond);
                self.expect_bool(&c, cond.span, "a `while` condition");
                let exit = self.emit(Instr::JumpIfFalse(0), cond.span);
                self.f().loops.push(Loop::default());
                self.block(body);
                let lp = self.f().loops.pop().unwrap_or_default();
                self.emit(Instr::Jump(top as u32), sp);
                let end = self.here();
                self.patch(exit, end);
                for b in lp.breaks {
                    self.patch(b, end);
                }
                for c in lp.continues {
                    self.patch(c, top);
                }
            }
            StmtKind::For {
                var,
                start,
                end,
                body,
            } => self.for_stmt(var, start, end, body, sp),
            StmtKind::Break | StmtKind::Continue => {
                let is_break = matches!(s.kind, StmtKind::Break);
                if self.f().loops.is_empty() {
                    let w = if is_break { "break" } else { "continue" };
                    self.err(
                        Diagnostic::error(Code::E0030, format!("`{w}` outside a loop"), sp)
                            .with_help("`break` and `continue` belong inside `while` or `for`"),
                    );
                    return false;
                }
                if self
                    .f()
                    .in_parallel
                    .is_some_and(|open| self.f().loops.len() <= open)
                {
                    let w = if is_break { "break" } else { "continue" };
                    self.leaves_parallel(&format!("`{w}`"), sp);
                }
                let j = self.emit(Instr::Jump(0), sp);
                if let Some(l) = self.f().loops.last_mut() {
                    if is_break {
                        l.breaks.push(j)
                    } else {
                        l.continues.push(j)
                    }
                }
                return true;
            }
            StmtKind::Return(value) => {
                if self.f().in_parallel.is_some() {
                    self.leaves_parallel("`return`", sp);
                }
                return self.return_stmt(value.as_ref(), sp);
            }
            StmtKind::Move {
                kind,
                via,
                target,
                speed,
                accel,
            } => self.move_stmt(
                *kind,
                via.as_ref(),
                target,
                speed.as_ref(),
                accel.as_ref(),
                sp,
            ),
            StmtKind::Delay(t) => {
                self.takes_time("delay", sp);
                let out = self.expr(t);
                let out = self.coerce(out, Ty::Num(Dim::TIME), t.span, "`delay`");
                if let Some(ConstValue::Num(x)) = out.k
                    && x < 0.0
                {
                    self.err(Diagnostic::error(
                        Code::E0025,
                        "a delay cannot be negative",
                        t.span,
                    ));
                }
                self.emit(Instr::Delay, sp);
            }
            StmtKind::WaitUntil { cond, timeout } => {
                self.takes_time("wait", sp);
                let c = self.condition(cond, "`wait_until`");
                if let Some(t) = timeout {
                    self.time_operand(t, "a timeout");
                }
                self.emit(Instr::WaitUntil(c, timeout.is_some()), sp);
            }
            StmtKind::WaitSignal { name, timeout } => {
                self.takes_time("wait", sp);
                if let Some(t) = timeout {
                    self.time_operand(t, "a timeout");
                }
                let n = self.str(&name.name);
                if !self.m.signals_awaited.contains(&n) {
                    self.m.signals_awaited.push(n);
                }
                self.emit(Instr::WaitSignal(n, timeout.is_some()), sp);
            }
            StmtKind::Signal { robot, name } => {
                if self.not_in_func("send signals", sp) {
                    let robot = self.str(&robot.name);
                    let name = self.str(&name.name);
                    let pos = self.pos(sp);
                    self.m.signals_sent.push(SignalSite { robot, name, pos });
                    let i = (self.m.signals_sent.len() - 1) as u32;
                    self.emit(Instr::Signal(i), sp);
                }
            }
            StmtKind::Parallel(branches) => self.parallel(branches, sp),
            StmtKind::Remote { args, .. } => {
                self.err(
                    Diagnostic::error(Code::E0060, "`remote` must stand directly inside `parallel`", sp)
                        .with_help("write `parallel { remote r2.p(…); }`: the block waits until the remote work ends"),
                );
                for a in args {
                    self.expr(a);
                }
            }
            StmtKind::When {
                trigger,
                handler,
                args,
            } => self.when_stmt(trigger, handler, args, sp),
            StmtKind::Disable(name) => {
                if self.not_in_func("disable handlers", sp) {
                    match self.symbols.get(&name.name).map(|s| s.0.clone()) {
                        Some(Sym::Proc(p)) if !self.sigs[p as usize].is_func => {
                            self.disabled.push((p, name.span));
                            self.emit(Instr::Disable(p), sp);
                        }
                        _ => self.err(
                            Diagnostic::error(
                                Code::E0011,
                                format!("`{}` is not a procedure of this module", name.name),
                                name.span,
                            )
                            .with_help("`disable p` names the procedure a `when … do p(…)` calls"),
                        ),
                    }
                }
            }
            StmtKind::Grip(part) | StmtKind::Release(part) => {
                let grip = matches!(s.kind, StmtKind::Grip(_));
                let what = if grip {
                    "grip a part"
                } else {
                    "release a part"
                };
                self.takes_time(what, sp);
                let p = self.str(&part.name);
                let pos = self.pos(part.span);
                self.m.parts.push(PartSite { part: p, pos });
                let i = (self.m.parts.len() - 1) as u32;
                self.emit(
                    if grip {
                        Instr::Grip(i)
                    } else {
                        Instr::Release(i)
                    },
                    sp,
                );
            }
            StmtKind::Log(args) => {
                let f = self.log_format(args);
                self.emit(Instr::Log(f), sp);
            }
            StmtKind::Fail(args) => {
                let f = self.log_format(args);
                self.emit(Instr::Fail(f), sp);
                return true;
            }
            StmtKind::Stop => {
                if self.not_in_func("stop the program", sp) {
                    self.emit(Instr::Stop, sp);
                }
                return true;
            }
            StmtKind::Block(b) => return self.block(b),
        }
        false
    }

    fn local_var(&mut self, d: &VarDecl) {
        let declared = d.ty.as_ref().map(|t| self.resolve_type(t));
        let ty = match &d.init {
            Some(init) => {
                let out = self.expr(init);
                let out = match declared {
                    Some(t) => {
                        self.coerce(out, t, init.span, &format!("variable `{}`", d.name.name))
                    }
                    None => out,
                };
                match out.ty {
                    Ty::Void => {
                        self.err(Diagnostic::error(
                            Code::E0020,
                            format!("`{}` cannot hold {}", d.name.name, out.ty.described()),
                            init.span,
                        ));
                        Ty::Error
                    }
                    t => t,
                }
            }
            None => {
                let t = declared.unwrap_or(Ty::Error);
                if let Some(vt) = t.vm() {
                    let z = ConstValue::zero(vt);
                    self.push_const(&z, t, d.span);
                }
                t
            }
        };
        let in_scope = self.fns.last().and_then(|f| {
            f.scopes
                .iter()
                .flatten()
                .find(|l| l.name == d.name.name)
                .cloned()
        });
        if in_scope.is_some() {
            self.err(
                Diagnostic::error(
                    Code::E0012,
                    format!("`{}` is already a local variable here", d.name.name),
                    d.name.span,
                )
                .with_help("choose another name, or assign to the existing variable"),
            );
        } else if let Some((Sym::Global(..), gspan)) = self.symbols.get(&d.name.name) {
            let gspan = *gspan;
            self.err(
                Diagnostic::error(Code::W0001, format!("local `{}` hides the global of the same name", d.name.name), d.name.span)
                    .with_related(gspan, "the global")
                    .with_help("assignments to the local emit no `set` event; rename it if you meant the global"),
            );
        }
        let slot = self.add_local(&d.name.name, ty, true);
        self.store_local(slot, ty, d.span);
    }

    fn store_local(&mut self, slot: u32, ty: Ty, span: Span) {
        let w = ty.width();
        let s = slot;
        match w {
            0 => {}
            1 => {
                self.emit(Instr::StoreLocal(s), span);
            }
            w => {
                self.emit(Instr::StoreLocalN(s, w), span);
            }
        }
    }

    fn load_local(&mut self, slot: u32, ty: Ty, span: Span) {
        let s = slot;
        match ty.width() {
            0 => {}
            1 => {
                self.emit(Instr::LoadLocal(s), span);
            }
            w => {
                self.emit(Instr::LoadLocalN(s, w), span);
            }
        }
    }

    fn lookup_local(&mut self, name: &str) -> Option<Local> {
        let n = self.fns.len();
        let f = self.fns.last()?;
        if let Some(l) = f
            .scopes
            .iter()
            .rev()
            .flat_map(|s| s.iter().rev())
            .find(|l| l.name == name)
        {
            return Some(l.clone());
        }
        if !matches!(f.kind, FnKind::Cond | FnKind::Handler) || n < 2 {
            return None;
        }
        if let Some((_, _, _, ty)) = f.captures.iter().find(|c| c.0 == name) {
            let ty = *ty;
            let slot = self.fns[n - 1]
                .scopes
                .first()
                .and_then(|s| s.iter().find(|l| l.name == name))
                .map_or(0, |l| l.slot);
            return Some(Local {
                name: name.into(),
                slot,
                ty,
                mutable: false,
            });
        }
        let outer = self.fns[n - 2]
            .scopes
            .iter()
            .rev()
            .flat_map(|s| s.iter().rev())
            .find(|l| l.name == name)?
            .clone();
        let f = &mut self.fns[n - 1];
        let slot = f.next_slot;
        f.next_slot += u32::from(outer.ty.width());
        f.captures
            .push((name.to_string(), outer.slot, outer.ty.width(), outer.ty));
        let local = Local {
            name: name.to_string(),
            slot,
            ty: outer.ty,
            mutable: false,
        };
        if let Some(s) = f.scopes.first_mut() {
            s.push(local.clone());
        }
        Some(local)
    }

    fn assign(&mut self, target: &Expr, op: Option<BinOp>, value: &Expr, sp: Span) {
        // Resolve the base variable of the target.
        let (base_name, base_span) = match &target.kind {
            ExprKind::Name(n) => (n.clone(), target.span),
            ExprKind::Field(b, _) | ExprKind::Index(b, _) => match &b.kind {
                ExprKind::Name(n) => (n.clone(), b.span),
                _ => {
                    self.not_assignable(target.span, "this expression");
                    return;
                }
            },
            ExprKind::Error => return,
            _ => {
                self.not_assignable(target.span, "this expression");
                return;
            }
        };
        let (place, ty) = if let Some(l) = self.lookup_local(&base_name) {
            if !l.mutable {
                let what = if matches!(self.fk(), FnKind::Cond | FnKind::Handler) {
                    format!("`{base_name}` (a copy captured by the handler)")
                } else {
                    format!("the loop variable `{base_name}`")
                };
                self.not_assignable(base_span, &what);
                return;
            }
            (Place::Local(l.slot), l.ty)
        } else {
            match self.symbols.get(&base_name).map(|s| s.0.clone()) {
                Some(Sym::Var(slot, ty)) => {
                    self.note_impure(&format!("the module variable `{base_name}`"), base_span);
                    (Place::Var(slot), ty)
                }
                Some(Sym::Global(g, ty)) => {
                    if !self.not_in_func("assign a global (that is a `set` event)", sp) {
                        return;
                    }
                    if !matches!(target.kind, ExprKind::Name(_)) {
                        self.not_assignable(target.span, "a part of a global");
                        return;
                    }
                    (Place::Global(g), ty)
                }
                Some(Sym::Const(..)) => {
                    self.not_assignable(base_span, &format!("the constant `{base_name}`"));
                    return;
                }
                Some(Sym::Proc(_)) => {
                    self.not_assignable(base_span, &format!("the procedure `{base_name}`"));
                    return;
                }
                None => {
                    self.unknown_name(&base_name, base_span);
                    self.expr(value);
                    return;
                }
            }
        };
        // What is assigned: the whole variable, a pose field or a joint.
        match &target.kind {
            ExprKind::Name(_) => {
                if let Some(op) = op {
                    self.load_place(&place_load(&place), ty, target.span);
                    let r = self.expr(value);
                    let out = self.binary_typed(op, Out::of(ty), r, sp, value.span);
                    self.coerce(out, ty, value.span, &format!("`{base_name}`"));
                } else {
                    let out = self.expr(value);
                    self.coerce(out, ty, value.span, &format!("`{base_name}`"));
                }
                match place {
                    Place::Local(s) => self.store_local(s, ty, sp),
                    Place::Var(s) => {
                        let w = ty.width();
                        self.emit(
                            if w == 1 {
                                Instr::StoreVar(s)
                            } else {
                                Instr::StoreVarN(s, w)
                            },
                            sp,
                        );
                    }
                    Place::Global(g) => {
                        self.emit(Instr::StoreGlobal(g), sp);
                    }
                }
            }
            ExprKind::Field(_, field) => {
                if ty != Ty::Pose {
                    if !ty.is_err() {
                        self.err(Diagnostic::error(
                            Code::E0022,
                            format!("`{base_name}` is {}, which has no fields", ty.described()),
                            target.span,
                        ));
                    }
                    return;
                }
                let Some((fi, fty)) = self.pose_field(field) else {
                    return;
                };
                let slot = match place {
                    Place::Local(s) | Place::Var(s) => s + u32::from(fi),
                    Place::Global(_) => return,
                };
                let is_local = matches!(place, Place::Local(_));
                if let Some(op) = op {
                    self.load_place(
                        &if is_local {
                            Load::Local(slot)
                        } else {
                            Load::Var(slot)
                        },
                        fty,
                        target.span,
                    );
                    let r = self.expr(value);
                    let out = self.binary_typed(op, Out::of(fty), r, sp, value.span);
                    self.coerce(
                        out,
                        fty,
                        value.span,
                        &format!("`{base_name}.{}`", field.name),
                    );
                } else {
                    let out = self.expr(value);
                    self.coerce(
                        out,
                        fty,
                        value.span,
                        &format!("`{base_name}.{}`", field.name),
                    );
                }
                if is_local {
                    self.store_local(slot, fty, sp);
                } else {
                    self.emit(Instr::StoreVar(slot), sp);
                }
            }
            ExprKind::Index(_, idx) => {
                if ty != Ty::Joints {
                    if !ty.is_err() {
                        self.err(Diagnostic::error(
                            Code::E0022,
                            format!(
                                "`{base_name}` is {}, which cannot be indexed",
                                ty.described()
                            ),
                            target.span,
                        ));
                    }
                    return;
                }
                if let Some(op) = op {
                    // j[i] op= v  →  v' = j[i] op v, then j[i] = v'.
                    self.load_place(&place_load(&place), Ty::Joints, target.span);
                    let i = self.expr(idx);
                    self.coerce(i, Ty::Int, idx.span, "a joint index");
                    self.emit(Instr::JointsGet, target.span);
                    let r = self.expr(value);
                    let out =
                        self.binary_typed(op, Out::of(Ty::Num(Dim::ANGLE)), r, sp, value.span);
                    self.joint_value(out, value.span);
                } else {
                    let out = self.expr(value);
                    self.joint_value(out, value.span);
                }
                let i = self.expr(idx);
                self.coerce(i, Ty::Int, idx.span, "a joint index");
                match place {
                    Place::Local(s) => {
                        self.emit(Instr::StoreLocalJoint(s), sp);
                    }
                    Place::Var(s) => {
                        self.emit(Instr::StoreVarJoint(s), sp);
                    }
                    Place::Global(_) => {}
                }
            }
            _ => {}
        }
    }

    /// A joint value must be an angle (revolute axis) or a length (prismatic axis).
    fn joint_value(&mut self, out: Out, span: Span) {
        match out.ty {
            Ty::Num(Dim::ANGLE) | Ty::Num(Dim::LENGTH) | Ty::Error => {}
            Ty::Int if out.is_zero_literal() => {
                self.emit(Instr::IntToNum, span);
            }
            Ty::Num(_) if out.is_zero_literal() => {}
            t => {
                let mut d = Diagnostic::error(
                    Code::E0021,
                    format!(
                        "a joint value must be an angle (or a length for a linear axis), found {}",
                        t.described()
                    ),
                    span,
                );
                if out.bare {
                    d = d.with_help("write the unit, e.g. 30deg or 500mm");
                }
                self.err(d);
            }
        }
    }

    fn not_assignable(&mut self, span: Span, what: &str) {
        self.err(
            Diagnostic::error(Code::E0023, format!("cannot assign to {what}"), span).with_help(
                "assign to a variable, a pose field (`p.z = …`) or a joint (`j[2] = …`)",
            ),
        );
    }

    /// An `if` chain; true if every path through it diverges.
    fn if_stmt(&mut self, branches: &[(Expr, Block)], els: Option<&Block>) -> bool {
        let mut to_end = Vec::new();
        let mut all_div = true;
        for (k, (cond, then)) in branches.iter().enumerate() {
            let c = self.expr(cond);
            self.expect_bool(&c, cond.span, "an `if` condition");
            let jf = self.emit(Instr::JumpIfFalse(0), cond.span);
            let then_div = self.block(then);
            all_div &= then_div;
            let last = k + 1 == branches.len() && els.is_none();
            if !then_div && !last {
                to_end.push(self.emit(Instr::Jump(0), then.span));
            }
            let next = self.here();
            self.patch(jf, next);
        }
        match els {
            Some(b) => all_div &= self.block(b),
            None => all_div = false,
        }
        let end = self.here();
        for j in to_end {
            self.patch(j, end);
        }
        all_div
    }

    fn for_stmt(&mut self, var: &Ident, start: &Expr, end: &Expr, body: &Block, sp: Span) {
        self.f().scopes.push(Vec::new());
        let s = self.expr(start);
        self.coerce(s, Ty::Int, start.span, "the start of a `for` range");
        let i = self.add_local(&var.name, Ty::Int, false);
        self.store_local(i, Ty::Int, start.span);
        let e = self.expr(end);
        self.coerce(e, Ty::Int, end.span, "the end of a `for` range");
        let e_slot = self.add_local("", Ty::Int, false);
        self.store_local(e_slot, Ty::Int, end.span);
        let top = self.here();
        self.load_local(i, Ty::Int, var.span);
        self.load_local(e_slot, Ty::Int, end.span);
        self.emit(Instr::CmpI(Cmp::Lt), var.span);
        let exit = self.emit(Instr::JumpIfFalse(0), var.span);
        self.f().loops.push(Loop::default());
        self.block(body);
        let lp = self.f().loops.pop().unwrap_or_default();
        let cont = self.here();
        self.load_local(i, Ty::Int, var.span);
        self.emit(Instr::PushInt(1), var.span);
        self.emit(Instr::AddI, var.span);
        self.store_local(i, Ty::Int, var.span);
        self.emit(Instr::Jump(top as u32), sp);
        let end_pc = self.here();
        self.patch(exit, end_pc);
        for b in lp.breaks {
            self.patch(b, end_pc);
        }
        for c in lp.continues {
            self.patch(c, cont);
        }
        self.f().scopes.pop();
    }

    fn return_stmt(&mut self, value: Option<&Expr>, sp: Span) -> bool {
        let kind = self.fk();
        let ret = self.fns.last().map_or(Ty::Void, |f| f.ret);
        match (kind, value) {
            (FnKind::Func, Some(v)) => {
                let out = self.expr(v);
                self.coerce(out, ret, v.span, "the return value");
                self.emit(Instr::RetVal, sp);
            }
            (FnKind::Func, None) => {
                self.err(
                    Diagnostic::error(Code::E0031, "this function must return a value", sp)
                        .with_help(format!("write `return value;` with {}", ret.described())),
                );
            }
            (_, Some(v)) => {
                self.err(
                    Diagnostic::error(Code::E0031, "a procedure cannot return a value", v.span)
                        .with_help("write `return;`, or make it a `func`"),
                );
                self.expr(v);
            }
            (_, None) => {
                self.emit(Instr::Ret, sp);
            }
        }
        true
    }

    fn move_stmt(
        &mut self,
        kind: MoveKind,
        via: Option<&Expr>,
        target: &Expr,
        speed: Option<&Expr>,
        accel: Option<&Expr>,
        sp: Span,
    ) {
        self.takes_time("move", sp);
        let mut flags = 0;
        if let Some(v) = via {
            let o = self.expr(v);
            match o.ty {
                Ty::Joints => flags |= MoveFlags::VIA_JOINTS,
                Ty::Pose | Ty::Error => {}
                t => self.err(Diagnostic::error(
                    Code::E0020,
                    format!(
                        "the via point of `move_c` must be a pose or joints, found {}",
                        t.described()
                    ),
                    v.span,
                )),
            }
        }
        let o = self.expr(target);
        match o.ty {
            Ty::Joints => flags |= MoveFlags::TARGET_JOINTS,
            Ty::Pose | Ty::Error => {}
            t => self.err(
                Diagnostic::error(
                    Code::E0020,
                    format!(
                        "the target of `{}` must be a pose or joints, found {}",
                        kind.keyword(),
                        t.described()
                    ),
                    target.span,
                )
                .with_help("build one with pose(x, y, z, rx, ry, rz) or joints(a1, …)"),
            ),
        }
        if let Some(s) = speed {
            flags |= MoveFlags::SPEED;
            self.motion_rate(kind, s, Dim::SPEED, "speed");
        }
        if let Some(a) = accel {
            flags |= MoveFlags::ACCEL;
            self.motion_rate(kind, a, Dim::ACCEL, "acceleration");
        }
        let f = MoveFlags(flags);
        self.emit(
            match kind {
                MoveKind::J => Instr::MoveJ(f),
                MoveKind::L => Instr::MoveL(f),
                MoveKind::C => Instr::MoveC(f),
            },
            sp,
        );
    }

    /// The `speed`/`accel` option of a motion: a ratio for `move_j`, else `dim` (> 0).
    fn motion_rate(&mut self, kind: MoveKind, e: &Expr, dim: Dim, what: &str) {
        let out = self.expr(e);
        let what = format!("the {what} of `{}`", kind.keyword());
        if kind == MoveKind::J {
            self.ratio(out, e.span, &what, "50%");
            return;
        }
        let out = self.coerce(out, Ty::Num(dim), e.span, &what);
        if let Some(ConstValue::Num(x)) = out.k
            && x <= 0.0
        {
            self.err(Diagnostic::error(
                Code::E0025,
                format!("{what} must be greater than zero"),
                e.span,
            ));
        }
    }

    /// A ratio such as `50%`: a plain number in (0, 1], written with `%` when literal.
    fn ratio(&mut self, out: Out, span: Span, what: &str, example: &str) {
        if out.bare {
            self.err(
                Diagnostic::error(
                    Code::E0021,
                    format!("{what} is a ratio; a bare number is ambiguous"),
                    span,
                )
                .with_label("write the unit")
                .with_help(format!("write a percentage such as {example}")),
            );
            return;
        }
        let out = self.coerce(out, Ty::Num(Dim::PLAIN), span, what);
        if let Some(ConstValue::Num(x)) = out.k
            && !(x > 0.0 && x <= 1.0)
        {
            self.err(
                Diagnostic::error(
                    Code::E0025,
                    format!("{what} must be more than 0% and at most 100%"),
                    span,
                )
                .with_help("the ratio is of each axis's maximum"),
            );
        }
    }

    fn time_operand(&mut self, e: &Expr, what: &str) -> Out {
        let out = self.expr(e);
        let out = self.coerce(out, Ty::Num(Dim::TIME), e.span, what);
        if let Some(ConstValue::Num(x)) = out.k
            && x < 0.0
        {
            self.err(Diagnostic::error(
                Code::E0025,
                format!("{what} cannot be negative"),
                e.span,
            ));
        }
        out
    }

    /// E0063: `what` would leave a `parallel` block's local branch before its join.
    fn leaves_parallel(&mut self, what: &str, sp: Span) {
        self.err(
            Diagnostic::error(
                Code::E0063,
                format!("{what} cannot leave a `parallel` block: its remote work would never be joined"),
                sp,
            )
            .with_help("end the local branch normally, and decide after the block (set a variable here, test it after `}`)"),
        );
    }

    fn parallel(&mut self, branches: &[Stmt], sp: Span) {
        self.takes_time("run `parallel` work", sp);
        let mut local: Option<&Block> = None;
        let mut remotes = Vec::new();
        for b in branches {
            match &b.kind {
                StmtKind::Remote { robot, proc, args } => remotes.push((robot, proc, args, b.span)),
                StmtKind::Block(blk) => {
                    if let Some(first) = local {
                        self.err(
                            Diagnostic::error(Code::E0061, "a `parallel` block has at most one local branch", blk.span)
                                .with_related(first.span, "the first local branch")
                                .with_help("merge the local branches into one block: this robot can only do one thing at a time"),
                        );
                    } else {
                        local = Some(blk);
                    }
                }
                StmtKind::Error => {}
                _ => self.err(
                    Diagnostic::error(
                        Code::E0062,
                        "only `remote` calls and one `{ … }` block may stand in `parallel`",
                        b.span,
                    )
                    .with_help("put this robot's own statements in one `{ … }` branch"),
                ),
            }
        }
        self.emit(Instr::ParBegin, sp);
        for (robot, proc, args, bsp) in remotes {
            let mut types = Vec::new();
            for a in args {
                let o = self.expr(a);
                match o.ty.vm() {
                    Some(t) => types.push(t),
                    None => {
                        if !o.ty.is_err() {
                            self.err(Diagnostic::error(
                                Code::E0020,
                                format!("a remote argument cannot be {}", o.ty.described()),
                                a.span,
                            ));
                        }
                        types.push(Type::Int);
                    }
                }
            }
            let r = self.str(&robot.name);
            let p = self.str(&proc.name);
            let pos = self.pos(bsp);
            self.m.remotes.push(RemoteSite {
                robot: r,
                proc: p,
                args: types,
                pos,
            });
            let i = (self.m.remotes.len() - 1) as u32;
            self.emit(Instr::Remote(i), bsp);
        }
        if let Some(b) = local {
            let open = self.f().loops.len();
            let was = self.f().in_parallel.replace(open);
            self.block(b);
            self.f().in_parallel = was;
        }
        self.emit(Instr::ParJoin, sp);
    }

    /// Compiles a `wait_until`/`when` condition into a condition function; returns its index.
    fn condition(&mut self, cond: &Expr, what: &str) -> u32 {
        let n = self.m.conds.len();
        let func = self.new_proc(&format!("cond#{n}"), ProcKind::Cond, cond.span);
        self.m.procs[func as usize].ret = Some(Type::Bool);
        self.fns.push(FnCtx::new(func, FnKind::Cond, Ty::Bool));
        let out = self.expr(cond);
        self.expect_bool(&out, cond.span, what);
        if let Some(ConstValue::Bool(_)) = out.k {
            // Constant conditions still compile (as a push) and fail the global rule below.
        }
        self.emit(Instr::RetVal, cond.span);
        let f = self.finish_fn();
        let captures = self.set_capture_params(func, &f);
        let pos = self.pos(cond.span);
        self.m.conds.push(CondInfo {
            func,
            captures,
            globals: Vec::new(),
            pos,
        });
        self.pending_conds.push(PendingCond {
            cond: n as u32,
            span: cond.span,
        });
        n as u32
    }

    fn set_capture_params(&mut self, proc: u32, f: &FnCtx) -> Vec<Capture> {
        let mut params = Vec::new();
        let mut caps = Vec::new();
        for (name, outer_slot, width, ty) in &f.captures {
            let n = self.str(name);
            params.push(ParamInfo {
                name: n,
                ty: ty.vm().unwrap_or(Type::Int),
            });
            caps.push(Capture {
                slot: *outer_slot,
                width: *width,
            });
        }
        self.m.procs[proc as usize].params = params;
        caps
    }

    fn when_stmt(&mut self, trigger: &TriggerExpr, handler: &Ident, args: &[Expr], sp: Span) {
        if !self.not_in_func("enable handlers", sp) {
            return;
        }
        let target = match self.symbols.get(&handler.name).map(|s| s.0.clone()) {
            Some(Sym::Proc(p)) if !self.sigs[p as usize].is_func => Some(p),
            Some(Sym::Proc(_)) => {
                self.err(
                    Diagnostic::error(
                        Code::E0051,
                        format!(
                            "`{}` is a function; a handler must be a procedure",
                            handler.name
                        ),
                        handler.span,
                    )
                    .with_help("make it a `proc`"),
                );
                None
            }
            Some(_) => {
                self.err(Diagnostic::error(
                    Code::E0051,
                    format!("`{}` is not a procedure", handler.name),
                    handler.span,
                ));
                None
            }
            None => {
                self.unknown_proc(&handler.name, handler.span);
                None
            }
        };
        let trig = match trigger {
            TriggerExpr::Cond(c) => Trigger::Condition(self.condition(c, "a `when` condition")),
            TriggerExpr::EveryCycles(_) => Trigger::EveryCycles,
            TriggerExpr::Every(_) => Trigger::Every,
            TriggerExpr::After(_) => Trigger::After,
        };
        let Some(target) = target else {
            for a in args {
                self.expr(a);
            }
            return;
        };
        // The action: evaluates the arguments when the handler fires, then calls the target.
        let h = self.m.handlers.len();
        let action = self.new_proc(&format!("when#{h}"), ProcKind::Handler, sp);
        self.fns.push(FnCtx::new(action, FnKind::Handler, Ty::Void));
        self.call_args(target, args, sp);
        self.emit(Instr::Call(target), sp);
        self.facts().calls.push((target, handler.span));
        self.emit(Instr::Ret, sp);
        let f = self.finish_fn();
        let captures = self.set_capture_params(action, &f);
        self.pending_handlers
            .push(PendingHandler { target, span: sp });
        // The trigger operand, evaluated when the handler is enabled.
        match trigger {
            TriggerExpr::EveryCycles(n) => {
                let o = self.expr(n);
                let o = self.coerce(o, Ty::Int, n.span, "a cycle count");
                if let Some(ConstValue::Int(k)) = o.k
                    && k <= 0
                {
                    self.err(Diagnostic::error(
                        Code::E0025,
                        "the cycle count must be at least 1",
                        n.span,
                    ));
                }
            }
            TriggerExpr::Every(t) | TriggerExpr::After(t) => {
                let o = self.time_operand(t, "a handler period");
                if matches!(trigger, TriggerExpr::Every(_))
                    && let Some(ConstValue::Num(x)) = o.k
                    && x <= 0.0
                {
                    self.err(Diagnostic::error(
                        Code::E0025,
                        "the period must be greater than zero",
                        t.span,
                    ));
                }
            }
            TriggerExpr::Cond(_) => {}
        }
        let pos = self.pos(sp);
        self.m.handlers.push(HandlerInfo {
            trigger: trig,
            action,
            target,
            captures,
            pos,
        });
        self.emit(Instr::When(h as u32), sp);
    }

    fn log_format(&mut self, args: &[Expr]) -> u32 {
        let mut parts = Vec::new();
        for a in args {
            if let ExprKind::Str(s) = &a.kind {
                let i = self.str(s);
                parts.push(LogPart::Text(i));
                continue;
            }
            let o = self.expr(a);
            match o.ty.vm() {
                Some(t) => parts.push(LogPart::Value(t)),
                None if o.ty.is_err() => {}
                None => self.err(Diagnostic::error(
                    Code::E0020,
                    format!("cannot write {} in a message", o.ty.described()),
                    a.span,
                )),
            }
        }
        self.m.log_formats.push(LogFormat { parts });
        (self.m.log_formats.len() - 1) as u32
    }

    // ---- whole-module rules --------------------------------------------------------------

    /// The chain of calls from `from` to a procedure that takes time, if any.
    fn time_path(&self, from: u32) -> Option<(Vec<u32>, String, Span)> {
        let mut seen = vec![false; self.facts.len()];
        let mut stack = vec![(from, vec![from])];
        while let Some((p, path)) = stack.pop() {
            if std::mem::replace(&mut seen[p as usize], true) {
                continue;
            }
            if let Some((what, span)) = &self.facts[p as usize].time {
                return Some((path, what.clone(), *span));
            }
            for (c, _) in self.facts[p as usize].calls.iter().rev() {
                let mut next = path.clone();
                next.push(*c);
                stack.push((*c, next));
            }
        }
        None
    }

    fn check_handlers(&mut self) {
        let pending = std::mem::take(&mut self.pending_handlers);
        let mut reported = BTreeSet::new();
        for h in pending {
            let Some((path, what, span)) = self.time_path(h.target) else {
                continue;
            };
            if !reported.insert((h.target, h.span.start)) {
                continue;
            }
            let names: Vec<&str> = path
                .iter()
                .map(|p| self.sigs[*p as usize].name.as_str())
                .collect();
            let target = names.first().copied().unwrap_or("?").to_string();
            let mut d = Diagnostic::error(Code::E0050, format!("the handler `{target}` may {what}, but handlers run in zero time"), h.span)
                .with_label("handler enabled here")
                .with_related(span, format!("it would {what} here"))
                .with_help("a handler runs while the robot's motion goes on: set a global or send a signal, and let the main program move");
            if names.len() > 1 {
                d = d.with_note(format!("called through {}", names.join(" → ")));
            }
            self.err(d);
        }
    }

    fn finish_conds(&mut self) {
        let pending = std::mem::take(&mut self.pending_conds);
        for pc in pending {
            let func = self.m.conds[pc.cond as usize].func;
            // Every function reachable from the condition.
            let mut globals = BTreeSet::new();
            let mut seen = vec![false; self.facts.len()];
            // (function, the function the condition itself calls on the way to it)
            let mut stack = vec![(func, None::<u32>)];
            let mut impure: Option<(String, Span, u32, u32)> = None;
            while let Some((p, top)) = stack.pop() {
                if std::mem::replace(&mut seen[p as usize], true) {
                    continue;
                }
                let f = &self.facts[p as usize];
                globals.extend(f.globals.iter().copied());
                if let (Some(top), None, Some((what, span))) = (top, &impure, &f.impure) {
                    impure = Some((what.clone(), *span, top, p));
                }
                for (c, _) in f.calls.iter().rev() {
                    stack.push((*c, top.or(Some(*c))));
                }
            }
            if let Some((what, span, top, holder)) = impure {
                let name = |p: u32| {
                    self.sigs
                        .get(p as usize)
                        .map_or(String::new(), |s| s.name.clone())
                };
                let (fname, inner) = (name(top), name(holder));
                let code = if what.starts_with("the module variable") {
                    Code::E0042
                } else {
                    Code::E0041
                };
                self.err(
                    Diagnostic::error(
                        code,
                        if fname == inner {
                            format!("this condition calls `{fname}`, which reads {what}")
                        } else {
                            format!("this condition calls `{fname}`, which (through `{inner}`) reads {what}")
                        },
                        pc.span,
                    )
                    .with_related(span, format!("read here, in `{inner}`"))
                    .with_help("a condition is re-checked only when a global it reads is set, so it may depend only on globals, constants and locals"),
                );
            } else if globals.is_empty() {
                self.err(
                    Diagnostic::error(Code::E0040, "this condition can never change: it reads no global", pc.span)
                        .with_help("a condition is re-checked when a global it reads is set; use a `global`, or `delay`/`timeout`/`after` for time"),
                );
            }
            self.m.conds[pc.cond as usize].globals = globals.into_iter().collect();
        }
    }

    fn check_disables(&mut self) {
        let targets: BTreeSet<u32> = self.m.handlers.iter().map(|h| h.target).collect();
        for (p, span) in std::mem::take(&mut self.disabled) {
            if !targets.contains(&p) {
                let name = self.sigs[p as usize].name.clone();
                self.err(
                    Diagnostic::error(Code::W0002, format!("no `when` in this module calls `{name}`, so `disable {name}` does nothing"), span)
                        .with_help("`disable p` turns off the handlers enabled with `when … do p(…)`"),
                );
            }
        }
    }

    // ---- expressions -------------------------------------------------------------------

    fn expect_bool(&mut self, o: &Out, span: Span, what: &str) {
        if !matches!(o.ty, Ty::Bool | Ty::Error) {
            self.err(
                Diagnostic::error(
                    Code::E0024,
                    format!("{what} must be a bool, found {}", o.ty.described()),
                    span,
                )
                .with_help("compare it, e.g. `parts >= 3`"),
            );
        }
    }

    /// Converts `o` to `want` where allowed (int → num, a literal 0 to any unit), else reports.
    fn coerce(&mut self, o: Out, want: Ty, span: Span, what: &str) -> Out {
        if o.ty == want || o.ty.is_err() || want.is_err() {
            return o;
        }
        match (o.ty, want) {
            (Ty::Int, Ty::Num(d)) if d.is_plain() || o.is_zero_literal() => {
                self.emit(Instr::IntToNum, span);
                let k = match o.k {
                    Some(ConstValue::Int(i)) => Some(ConstValue::Num(i as f64)),
                    _ => None,
                };
                Out {
                    ty: want,
                    k,
                    bare: o.bare,
                }
            }
            (Ty::Num(_), Ty::Num(_)) if o.is_zero_literal() => Out { ty: want, ..o },
            (Ty::Int | Ty::Num(_), Ty::Num(d)) => {
                let found = if o.ty == Ty::Int {
                    Dim::PLAIN
                } else if let Ty::Num(f) = o.ty {
                    f
                } else {
                    Dim::PLAIN
                };
                let mut diag = Diagnostic::error(
                    Code::E0021,
                    format!(
                        "{what} must be {}, found {}",
                        d.described(),
                        if o.ty == Ty::Int {
                            "an int".to_string()
                        } else {
                            found.described()
                        }
                    ),
                    span,
                )
                .with_label(format!("expected {}", d.described()));
                if o.bare
                    && let Some(u) = default_unit(d)
                {
                    let text = match o.k {
                        Some(ConstValue::Int(i)) => i.to_string(),
                        Some(ConstValue::Num(x)) => vworks_vm::types::fmt_num(x),
                        _ => "2".into(),
                    };
                    diag = diag.with_help(format!("write {text}{u}"));
                } else if d.is_plain() && !found.is_plain() {
                    diag = diag.with_help(format!(
                        "divide by a unit to get a plain number, e.g. `x / 1{}`",
                        default_unit(found).unwrap_or("s")
                    ));
                }
                self.err(diag);
                Out::err()
            }
            _ => {
                self.err(
                    Diagnostic::error(
                        Code::E0020,
                        format!(
                            "{what} must be {}, found {}",
                            want.described(),
                            o.ty.described()
                        ),
                        span,
                    )
                    .with_label(format!("expected {}", want.described())),
                );
                Out::err()
            }
        }
    }

    fn unknown_name(&mut self, name: &str, span: Span) {
        let mut candidates: Vec<String> = self.symbols.keys().cloned().collect();
        if let Some(f) = self.fns.last() {
            candidates.extend(f.scopes.iter().flatten().map(|l| l.name.clone()));
        }
        let best = crate::nearest(name, candidates.iter().map(String::as_str));
        let mut d = Diagnostic::error(Code::E0010, format!("unknown name `{name}`"), span)
            .with_label("not declared");
        d = match best {
            Some(c) => d.with_help(format!("did you mean `{c}`?")),
            None => d.with_help("declare it with `var`, `const` or `global` before using it"),
        };
        self.err(d);
    }

    fn unknown_proc(&mut self, name: &str, span: Span) {
        let names = self
            .sigs
            .iter()
            .map(|s| s.name.as_str())
            .chain(BUILTINS.iter().copied());
        let best = crate::nearest(name, names);
        let mut d = Diagnostic::error(
            Code::E0011,
            format!("unknown procedure or function `{name}`"),
            span,
        );
        if let Some(c) = best {
            d = d.with_help(format!("did you mean `{c}`?"));
        }
        self.err(d);
    }

    fn note_impure(&mut self, what: &str, span: Span) {
        match self.fk() {
            FnKind::Cond => self.err(
                Diagnostic::error(Code::E0042, format!("a condition may not read {what}"), span)
                    .with_help("a condition is re-checked only when a global it reads is set; make it a `global`, or copy it into a local before waiting"),
            ),
            FnKind::Init => {}
            _ => {
                let f = self.facts();
                if f.impure.is_none() {
                    f.impure = Some((what.to_string(), span));
                }
            }
        }
    }

    fn state_read(&mut self, name: &str, span: Span) {
        if self.fk() == FnKind::Cond {
            let help = match name {
                "now" | "cycle" => {
                    "time passes without any `set`: use `timeout`, `after` or `every` instead"
                }
                _ => {
                    "robot state changes without a `set` event, so the condition would never be re-checked"
                }
            };
            self.err(
                Diagnostic::error(
                    Code::E0041,
                    format!("`{name}()` is not allowed in a condition"),
                    span,
                )
                .with_help(help),
            );
        } else {
            self.note_impure(&format!("`{name}()`"), span);
        }
    }

    /// Checks and compiles an expression, folding constants.
    fn expr(&mut self, e: &Expr) -> Out {
        let start = self.here();
        let out = self.expr_inner(e);
        if out.k.as_ref().is_some_and(|k| !k.is_finite()) {
            self.err(
                Diagnostic::error(
                    Code::E0026,
                    "this constant is too large to be a number",
                    e.span,
                )
                .with_help("numbers must stay below about 1.8e308 in magnitude"),
            );
            return Out::err();
        }
        if let Some(k) = &out.k
            && self.here() > start + 1
        {
            let k = k.clone();
            self.truncate(start);
            self.push_const(&k, out.ty, e.span);
        }
        out
    }

    fn expr_inner(&mut self, e: &Expr) -> Out {
        let sp = e.span;
        let konst = |this: &mut Self, v: ConstValue, ty: Ty, bare: bool| {
            this.push_const(&v, ty, sp);
            Out {
                ty,
                k: Some(v),
                bare,
            }
        };
        match &e.kind {
            ExprKind::Error => Out::err(),
            ExprKind::Int(i) => konst(self, ConstValue::Int(*i), Ty::Int, true),
            ExprKind::Num(x) => konst(self, ConstValue::Num(*x), Ty::Num(Dim::PLAIN), true),
            ExprKind::Quantity(x, d) => konst(self, ConstValue::Num(*x), Ty::Num(*d), false),
            ExprKind::Bool(b) => konst(self, ConstValue::Bool(*b), Ty::Bool, false),
            ExprKind::Str(_) => {
                self.err(
                    Diagnostic::error(
                        Code::E0034,
                        "text can only be written in `log` and `fail`",
                        sp,
                    )
                    .with_help("write `log \"message\", value;`"),
                );
                Out::err()
            }
            ExprKind::Name(n) => self.name(n, sp),
            ExprKind::Unary(op, x) => {
                let o = self.expr(x);
                match (op, o.ty) {
                    (_, Ty::Error) => Out::err(),
                    (UnOp::Neg, Ty::Int) => {
                        self.emit(Instr::NegI, sp);
                        let k = match o.k {
                            Some(ConstValue::Int(i)) => i.checked_neg().map(ConstValue::Int),
                            _ => None,
                        };
                        Out {
                            ty: Ty::Int,
                            k,
                            bare: o.bare,
                        }
                    }
                    (UnOp::Neg, Ty::Num(d)) => {
                        self.emit(Instr::NegF, sp);
                        let k = match o.k {
                            Some(ConstValue::Num(x)) => Some(ConstValue::Num(-x)),
                            _ => None,
                        };
                        Out {
                            ty: Ty::Num(d),
                            k,
                            bare: o.bare,
                        }
                    }
                    (UnOp::Not, Ty::Bool) => {
                        self.emit(Instr::Not, sp);
                        let k = match o.k {
                            Some(ConstValue::Bool(b)) => Some(ConstValue::Bool(!b)),
                            _ => None,
                        };
                        Out {
                            ty: Ty::Bool,
                            k,
                            bare: false,
                        }
                    }
                    (op, t) => {
                        let sym = if *op == UnOp::Neg { "-" } else { "not" };
                        self.err(Diagnostic::error(
                            Code::E0022,
                            format!("`{sym}` cannot be applied to {}", t.described()),
                            sp,
                        ));
                        Out::err()
                    }
                }
            }
            ExprKind::Binary(op, l, r) => {
                if matches!(op, BinOp::And | BinOp::Or) {
                    return self.logic(*op, l, r, sp);
                }
                let lo = self.expr(l);
                let ro = self.expr(r);
                self.binary_typed(*op, lo, ro, sp, r.span)
            }
            ExprKind::Call(name, args) => self.call(name, args, sp, false),
            ExprKind::Field(base, field) => {
                let o = self.expr(base);
                if o.ty.is_err() {
                    return Out::err();
                }
                if o.ty != Ty::Pose {
                    self.err(
                        Diagnostic::error(
                            Code::E0022,
                            format!("{} has no field `{}`", o.ty.described(), field.name),
                            field.span,
                        )
                        .with_help(if o.ty == Ty::Joints {
                            "index joints with j[i]"
                        } else {
                            "only poses have fields: x, y, z, rx, ry, rz"
                        }),
                    );
                    return Out::err();
                }
                let Some((fi, fty)) = self.pose_field(field) else {
                    return Out::err();
                };
                // A field of a pose variable is one slot: load it directly.
                let last = self.fns.last().and_then(|f| f.code.last().copied());
                let is_name = matches!(base.kind, ExprKind::Name(_));
                if let (true, Some(Instr::LoadLocalN(s, 6))) = (is_name, last) {
                    let start = self.here() - 1;
                    self.truncate(start);
                    self.emit(Instr::LoadLocal(s + u32::from(fi)), sp);
                } else if let (true, Some(Instr::LoadVarN(s, 6))) = (is_name, last) {
                    let start = self.here() - 1;
                    self.truncate(start);
                    self.emit(Instr::LoadVar(s + u32::from(fi)), sp);
                } else {
                    self.emit(Instr::PoseGet(fi), sp);
                }
                let k = match o.k {
                    Some(ConstValue::Pose(p)) => Some(ConstValue::Num(p[fi as usize])),
                    _ => None,
                };
                Out {
                    ty: fty,
                    k,
                    bare: false,
                }
            }
            ExprKind::Index(base, idx) => {
                let o = self.expr(base);
                let i = self.expr(idx);
                let i = self.coerce(i, Ty::Int, idx.span, "an index");
                if o.ty.is_err() {
                    return Out::err();
                }
                if o.ty != Ty::Joints {
                    self.err(
                        Diagnostic::error(
                            Code::E0022,
                            format!("{} cannot be indexed", o.ty.described()),
                            sp,
                        )
                        .with_help("only joints values are indexed: j[0] is the first axis"),
                    );
                    return Out::err();
                }
                self.emit(Instr::JointsGet, sp);
                self.joint_index(o, i, idx.span, Dim::ANGLE)
            }
        }
    }

    fn joint_index(&mut self, o: Out, i: Out, span: Span, dim: Dim) -> Out {
        let k = match (&o.k, &i.k) {
            (Some(ConstValue::Joints(v)), Some(ConstValue::Int(i))) => match usize::try_from(*i)
                .ok()
                .and_then(|i| v.get(i))
            {
                Some(x) => Some(ConstValue::Num(*x)),
                None => {
                    self.err(
                        Diagnostic::error(
                            Code::E0025,
                            format!("index {i} is out of range for joints of {} values", v.len()),
                            span,
                        )
                        .with_help("axes are numbered from 0"),
                    );
                    return Out::err();
                }
            },
            (_, Some(ConstValue::Int(i))) if *i < 0 || *i >= MAX_AXES as i64 => {
                self.err(Diagnostic::error(
                    Code::E0025,
                    format!(
                        "index {i} is out of range: axes are numbered 0 to {}",
                        MAX_AXES - 1
                    ),
                    span,
                ));
                return Out::err();
            }
            _ => None,
        };
        Out {
            ty: Ty::Num(dim),
            k,
            bare: false,
        }
    }

    fn pose_field(&mut self, field: &Ident) -> Option<(u8, Ty)> {
        let i = ["x", "y", "z", "rx", "ry", "rz"]
            .iter()
            .position(|f| *f == field.name);
        match i {
            Some(i) => Some((
                i as u8,
                Ty::Num(if i < 3 { Dim::LENGTH } else { Dim::ANGLE }),
            )),
            None => {
                self.err(
                    Diagnostic::error(
                        Code::E0022,
                        format!("a pose has no field `{}`", field.name),
                        field.span,
                    )
                    .with_help("the fields are x, y, z (lengths) and rx, ry, rz (angles)"),
                );
                None
            }
        }
    }

    fn name(&mut self, n: &str, sp: Span) -> Out {
        if let Some(l) = self.lookup_local(n) {
            self.load_local(l.slot, l.ty, sp);
            return Out::of(l.ty);
        }
        match self.symbols.get(n).map(|s| s.0.clone()) {
            Some(Sym::Const(ty, v)) => {
                self.push_const(&v, ty, sp);
                Out {
                    ty,
                    k: Some(v),
                    bare: false,
                }
            }
            Some(Sym::Var(slot, ty)) => {
                if self.fk() == FnKind::Init {
                    return self.not_const(n, "a module variable", sp);
                }
                self.note_impure(&format!("the module variable `{n}`"), sp);
                let w = ty.width();
                self.emit(
                    if w == 1 {
                        Instr::LoadVar(slot)
                    } else {
                        Instr::LoadVarN(slot, w)
                    },
                    sp,
                );
                Out::of(ty)
            }
            Some(Sym::Global(g, ty)) => {
                if self.fk() == FnKind::Init {
                    return self.not_const(n, "a global", sp);
                }
                self.facts().globals.insert(g);
                self.emit(Instr::LoadGlobal(g), sp);
                Out::of(ty)
            }
            Some(Sym::Proc(_)) => {
                self.err(
                    Diagnostic::error(
                        Code::E0033,
                        format!("`{n}` is a procedure, not a value"),
                        sp,
                    )
                    .with_help(format!("call it: `{n}(…)`")),
                );
                Out::err()
            }
            None => {
                self.unknown_name(n, sp);
                Out::err()
            }
        }
    }

    fn not_const(&mut self, n: &str, what: &str, sp: Span) -> Out {
        self.err(
            Diagnostic::error(Code::E0080, format!("`{n}` is {what}, not a constant"), sp)
                .with_help("module-level initial values may use only literals and constants declared above"),
        );
        Out::err()
    }

    fn logic(&mut self, op: BinOp, l: &Expr, r: &Expr, sp: Span) -> Out {
        let lo = self.expr(l);
        self.expect_bool(&lo, l.span, &format!("the left side of `{}`", op.symbol()));
        let j1 = self.emit(
            if op == BinOp::And {
                Instr::JumpIfFalse(0)
            } else {
                Instr::JumpIfTrue(0)
            },
            sp,
        );
        let ro = self.expr(r);
        self.expect_bool(&ro, r.span, &format!("the right side of `{}`", op.symbol()));
        let j2 = self.emit(Instr::Jump(0), sp);
        let short = self.here();
        self.patch(j1, short);
        self.emit(Instr::PushBool(op == BinOp::Or), sp);
        let end = self.here();
        self.patch(j2, end);
        let k = match (&lo.k, &ro.k) {
            (Some(ConstValue::Bool(a)), Some(ConstValue::Bool(b))) => {
                Some(ConstValue::Bool(if op == BinOp::And {
                    *a && *b
                } else {
                    *a || *b
                }))
            }
            _ => None,
        };
        if lo.ty.is_err() || ro.ty.is_err() {
            return Out::err();
        }
        Out {
            ty: Ty::Bool,
            k,
            bare: false,
        }
    }

    /// Type rules and code of `l op r`, both operands already on the stack.
    fn binary_typed(&mut self, op: BinOp, lo: Out, ro: Out, sp: Span, rspan: Span) -> Out {
        use BinOp::*;
        if lo.ty.is_err() || ro.ty.is_err() {
            return Out::err();
        }
        let mismatch = |this: &mut Self, msg: String, help: Option<String>| {
            let mut d = Diagnostic::error(Code::E0021, msg, sp);
            if let Some(h) = help {
                d = d.with_help(h);
            }
            this.err(d);
            Out::err()
        };
        // A literal 0 takes the unit of the other side: `x > 0`, `0 < x`.
        let zero_ok = matches!(op, Add | Sub | Eq | Ne | Lt | Le | Gt | Ge);
        let (lo, ro) = match (lo.ty, ro.ty) {
            (Ty::Num(d), Ty::Int | Ty::Num(_))
                if zero_ok && ro.is_zero_literal() && ro.ty != lo.ty =>
            {
                if ro.ty == Ty::Int {
                    self.emit(Instr::IntToNum, sp);
                }
                let k = Some(ConstValue::Num(0.0));
                (
                    lo,
                    Out {
                        ty: Ty::Num(d),
                        k,
                        bare: true,
                    },
                )
            }
            (Ty::Int | Ty::Num(_), Ty::Num(d))
                if zero_ok && lo.is_zero_literal() && ro.ty != lo.ty =>
            {
                if lo.ty == Ty::Int {
                    self.emit(Instr::IntToNumBelow, sp);
                }
                let k = Some(ConstValue::Num(0.0));
                (
                    Out {
                        ty: Ty::Num(d),
                        k,
                        bare: true,
                    },
                    ro,
                )
            }
            _ => (lo, ro),
        };
        // Promote an int to a plain num beside a num.
        let (lt, rt) = (lo.ty, ro.ty);
        let (lt, rt, lk, rk) = match (lt, rt) {
            (Ty::Int, Ty::Num(d)) if d.is_plain() || matches!(op, Mul | Div) => {
                self.emit(Instr::IntToNumBelow, sp);
                (Ty::Num(Dim::PLAIN), rt, to_num(&lo.k), ro.k.clone())
            }
            (Ty::Num(d), Ty::Int) if d.is_plain() || matches!(op, Mul | Div) => {
                self.emit(Instr::IntToNum, sp);
                (lt, Ty::Num(Dim::PLAIN), lo.k.clone(), to_num(&ro.k))
            }
            _ => (lt, rt, lo.k.clone(), ro.k.clone()),
        };
        let bare = lo.bare && ro.bare;
        let cmp = cmp_of;
        match (op, lt, rt) {
            (Add | Sub | Mul | Div | Mod, Ty::Int, Ty::Int) => {
                self.emit(
                    match op {
                        Add => Instr::AddI,
                        Sub => Instr::SubI,
                        Mul => Instr::MulI,
                        Div => Instr::DivI,
                        _ => Instr::ModI,
                    },
                    sp,
                );
                let k = match (lk, rk) {
                    (Some(ConstValue::Int(a)), Some(ConstValue::Int(b))) => {
                        let v = match op {
                            Add => a.checked_add(b),
                            Sub => a.checked_sub(b),
                            Mul => a.checked_mul(b),
                            Div => a.checked_div(b),
                            _ => a.checked_rem(b),
                        };
                        match v {
                            Some(v) => Some(ConstValue::Int(v)),
                            None => {
                                let why = if b == 0 && matches!(op, Div | Mod) {
                                    "division by zero"
                                } else {
                                    "integer overflow"
                                };
                                self.err(Diagnostic::error(
                                    Code::E0026,
                                    format!("{why} in a constant expression"),
                                    sp,
                                ));
                                return Out::err();
                            }
                        }
                    }
                    _ => None,
                };
                Out {
                    ty: Ty::Int,
                    k,
                    bare,
                }
            }
            (Add | Sub, Ty::Num(a), Ty::Num(b)) => {
                if a != b {
                    let word = if op == Add { "add" } else { "subtract" };
                    return mismatch(
                        self,
                        format!("cannot {word} {} and {}", a.described(), b.described()),
                        (ro.bare && default_unit(a).is_some())
                            .then(|| format!("write the unit: {}", default_unit(a).unwrap_or(""))),
                    );
                }
                self.emit(if op == Add { Instr::AddF } else { Instr::SubF }, sp);
                let k = num2(&lk, &rk, |x, y| if op == Add { x + y } else { x - y });
                Out {
                    ty: Ty::Num(a),
                    k,
                    bare,
                }
            }
            (Mul | Div, Ty::Num(a), Ty::Num(b)) => {
                let d = if op == Mul { a.times(b) } else { a.per(b) };
                let Some(d) = d else {
                    return mismatch(
                        self,
                        "the unit of this product is out of range".into(),
                        None,
                    );
                };
                if op == Div
                    && let Some(ConstValue::Num(y)) = rk
                    && y == 0.0
                {
                    self.err(Diagnostic::error(
                        Code::E0026,
                        "division by zero in a constant expression",
                        rspan,
                    ));
                    return Out::err();
                }
                self.emit(if op == Mul { Instr::MulF } else { Instr::DivF }, sp);
                let k = num2(&lk, &rk, |x, y| if op == Mul { x * y } else { x / y });
                Out {
                    ty: Ty::Num(d),
                    k,
                    bare,
                }
            }
            (Eq | Ne | Lt | Le | Gt | Ge, Ty::Int, Ty::Int) => {
                self.emit(Instr::CmpI(cmp(op)), sp);
                let k = match (lk, rk) {
                    (Some(ConstValue::Int(a)), Some(ConstValue::Int(b))) => {
                        Some(ConstValue::Bool(cmp_of(op).holds(a.cmp(&b))))
                    }
                    _ => None,
                };
                Out {
                    ty: Ty::Bool,
                    k,
                    bare: false,
                }
            }
            (Eq | Ne | Lt | Le | Gt | Ge, Ty::Num(a), Ty::Num(b)) => {
                if a != b && !ro.is_zero_literal() {
                    return mismatch(
                        self,
                        format!("cannot compare {} with {}", a.described(), b.described()),
                        (ro.bare && default_unit(a).is_some())
                            .then(|| format!("write the unit: {}", default_unit(a).unwrap_or(""))),
                    );
                }
                self.emit(Instr::CmpF(cmp(op)), sp);
                let k = match (lk, rk) {
                    (Some(ConstValue::Num(x)), Some(ConstValue::Num(y))) => x
                        .partial_cmp(&y)
                        .map(|o| ConstValue::Bool(cmp_of(op).holds(o))),
                    _ => None,
                };
                Out {
                    ty: Ty::Bool,
                    k,
                    bare: false,
                }
            }
            (Eq | Ne, Ty::Bool, Ty::Bool) => {
                self.emit(Instr::CmpB(cmp(op)), sp);
                let k = match (lk, rk) {
                    (Some(ConstValue::Bool(a)), Some(ConstValue::Bool(b))) => {
                        Some(ConstValue::Bool((a == b) == (op == Eq)))
                    }
                    _ => None,
                };
                Out {
                    ty: Ty::Bool,
                    k,
                    bare: false,
                }
            }
            (Mod, Ty::Num(_), _) | (Mod, _, Ty::Num(_)) => {
                self.err(
                    Diagnostic::error(Code::E0022, "`mod` works on ints", sp)
                        .with_help("convert with int(x)"),
                );
                Out::err()
            }
            (_, Ty::Num(a), Ty::Int) | (_, Ty::Int, Ty::Num(a)) => mismatch(
                self,
                format!(
                    "cannot combine {} with an int using `{}`",
                    a.described(),
                    op.symbol()
                ),
                Some(if bare || lo.bare || ro.bare {
                    format!(
                        "write the unit on the number, e.g. 2{}",
                        default_unit(a).unwrap_or("")
                    )
                } else {
                    "convert with num(i)".into()
                }),
            ),
            (op, l, r) => {
                self.err(Diagnostic::error(
                    Code::E0022,
                    format!(
                        "`{}` cannot be applied to {} and {}",
                        op.symbol(),
                        l.described(),
                        r.described()
                    ),
                    sp,
                ));
                Out::err()
            }
        }
    }

    fn call_args(&mut self, callee: u32, args: &[Expr], sp: Span) {
        let sig = self.sigs[callee as usize].clone();
        if args.len() != sig.params.len() {
            self.err(
                Diagnostic::error(
                    Code::E0013,
                    format!(
                        "`{}` takes {} argument{}, but {} {} given",
                        sig.name,
                        sig.params.len(),
                        if sig.params.len() == 1 { "" } else { "s" },
                        args.len(),
                        if args.len() == 1 { "was" } else { "were" }
                    ),
                    sp,
                )
                .with_related(sig.span, "declared here"),
            );
            for a in args {
                self.expr(a);
            }
            return;
        }
        for (a, (pname, pty)) in args.iter().zip(&sig.params) {
            let o = self.expr(a);
            self.coerce(
                o,
                *pty,
                a.span,
                &format!("argument `{pname}` of `{}`", sig.name),
            );
        }
    }

    /// A call to a user procedure/function or a built-in.
    fn call(&mut self, name: &Ident, args: &[Expr], sp: Span, statement: bool) -> Out {
        if let Some(Sym::Proc(p)) = self.symbols.get(&name.name).map(|s| s.0.clone()) {
            let sig = self.sigs[p as usize].clone();
            if !sig.is_func {
                if !statement {
                    self.err(
                        Diagnostic::error(
                            Code::E0033,
                            format!("`{}` is a procedure and has no value", name.name),
                            sp,
                        )
                        .with_help(
                            "call it as a statement, or make it a `func` that returns a value",
                        ),
                    );
                    return Out::err();
                }
                if !self.not_in_func(&format!("call the procedure `{}`", name.name), sp) {
                    return Out::err();
                }
            }
            if self.fk() == FnKind::Init {
                return self.not_const(&name.name, "a function", sp);
            }
            self.call_args(p, args, sp);
            self.facts().calls.push((p, name.span));
            self.emit(Instr::Call(p), sp);
            return Out::of(sig.ret);
        }
        if self.lookup_local(&name.name).is_some() || self.symbols.contains_key(&name.name) {
            self.err(Diagnostic::error(
                Code::E0022,
                format!("`{}` is a value, not a function", name.name),
                name.span,
            ));
            return Out::err();
        }
        self.builtin(name, args, sp)
    }

    fn arity(&mut self, name: &Ident, args: &[Expr], n: usize, sp: Span, sig: &str) -> bool {
        if args.len() == n {
            return true;
        }
        self.err(
            Diagnostic::error(
                Code::E0013,
                format!(
                    "`{}` takes {n} argument{}, but {} {} given",
                    name.name,
                    if n == 1 { "" } else { "s" },
                    args.len(),
                    if args.len() == 1 { "was" } else { "were" }
                ),
                sp,
            )
            .with_help(format!("write `{sig}`")),
        );
        for a in args {
            self.expr(a);
        }
        false
    }

    fn builtin(&mut self, name: &Ident, args: &[Expr], sp: Span) -> Out {
        let n = name.name.as_str();
        match n {
            "now" | "cycle" | "timed_out" | "current_joints" | "current_pose" => {
                if !self.arity(name, args, 0, sp, &format!("{n}()")) {
                    return Out::err();
                }
                if self.fk() == FnKind::Init {
                    return self.not_const(n, "known only during the run", sp);
                }
                self.state_read(n, sp);
                let (ins, ty) = match n {
                    "now" => (Instr::Now, Ty::Num(Dim::TIME)),
                    "cycle" => (Instr::Cycle, Ty::Int),
                    "timed_out" => (Instr::TimedOut, Ty::Bool),
                    "current_joints" => (Instr::CurrentJoints, Ty::Joints),
                    _ => (Instr::CurrentPose, Ty::Pose),
                };
                self.emit(ins, sp);
                Out::of(ty)
            }
            "offset" | "tool_offset" => {
                if !self.arity(name, args, 4, sp, &format!("{n}(p, dx, dy, dz)")) {
                    return Out::err();
                }
                let p = self.expr(&args[0]);
                let p = self.coerce(
                    p,
                    Ty::Pose,
                    args[0].span,
                    &format!("the first argument of `{n}`"),
                );
                let mut ds = [0.0; 3];
                let mut all = true;
                for (i, a) in args[1..].iter().enumerate() {
                    let o = self.expr(a);
                    let o = self.coerce(
                        o,
                        Ty::Num(Dim::LENGTH),
                        a.span,
                        &format!("argument {} of `{n}`", i + 2),
                    );
                    match o.k {
                        Some(ConstValue::Num(x)) => ds[i] = x,
                        _ => all = false,
                    }
                }
                self.emit(
                    if n == "offset" {
                        Instr::Offset
                    } else {
                        Instr::ToolOffset
                    },
                    sp,
                );
                let k = match (p.k, all) {
                    (Some(ConstValue::Pose(p)), true) => Some(ConstValue::Pose(if n == "offset" {
                        math::offset(p, ds[0], ds[1], ds[2])
                    } else {
                        math::tool_offset(p, ds[0], ds[1], ds[2])
                    })),
                    _ => None,
                };
                Out {
                    ty: Ty::Pose,
                    k,
                    bare: false,
                }
            }
            "abs" | "sqrt" | "sin" | "cos" | "int" | "num" => {
                if !self.arity(name, args, 1, sp, &format!("{n}(x)")) {
                    return Out::err();
                }
                let o = self.expr(&args[0]);
                self.unary_builtin(n, o, args[0].span, sp)
            }
            "min" | "max" | "atan2" => {
                let sig = if n == "atan2" {
                    "atan2(y, x)"
                } else {
                    "min(a, b)"
                };
                if !self.arity(name, args, 2, sp, sig) {
                    return Out::err();
                }
                let a = self.expr(&args[0]);
                let b = self.expr(&args[1]);
                if a.ty.is_err() || b.ty.is_err() {
                    return Out::err();
                }
                let (ta, tb, ka, kb) = match (a.ty, b.ty) {
                    (Ty::Int, Ty::Num(d)) if d.is_plain() || n == "atan2" => {
                        self.emit(Instr::IntToNumBelow, sp);
                        (Ty::Num(Dim::PLAIN), b.ty, to_num(&a.k), b.k.clone())
                    }
                    (Ty::Num(d), Ty::Int) if d.is_plain() || n == "atan2" => {
                        self.emit(Instr::IntToNum, sp);
                        (a.ty, Ty::Num(Dim::PLAIN), a.k.clone(), to_num(&b.k))
                    }
                    (Ty::Int, Ty::Int) if n == "atan2" => {
                        self.emit(Instr::IntToNumBelow, sp);
                        self.emit(Instr::IntToNum, sp);
                        (
                            Ty::Num(Dim::PLAIN),
                            Ty::Num(Dim::PLAIN),
                            to_num(&a.k),
                            to_num(&b.k),
                        )
                    }
                    _ => (a.ty, b.ty, a.k.clone(), b.k.clone()),
                };
                match (ta, tb) {
                    (Ty::Int, Ty::Int) => {
                        self.emit(if n == "min" { Instr::MinI } else { Instr::MaxI }, sp);
                        let k = match (ka, kb) {
                            (Some(ConstValue::Int(x)), Some(ConstValue::Int(y))) => {
                                Some(ConstValue::Int(if n == "min" {
                                    x.min(y)
                                } else {
                                    x.max(y)
                                }))
                            }
                            _ => None,
                        };
                        Out {
                            ty: Ty::Int,
                            k,
                            bare: false,
                        }
                    }
                    (Ty::Num(x), Ty::Num(y)) if x == y => {
                        let (ins, ty) = match n {
                            "min" => (Instr::MinF, Ty::Num(x)),
                            "max" => (Instr::MaxF, Ty::Num(x)),
                            _ => (Instr::Atan2, Ty::Num(Dim::ANGLE)),
                        };
                        self.emit(ins, sp);
                        let k = num2(&ka, &kb, |p, q| match n {
                            "min" => p.min(q),
                            "max" => p.max(q),
                            _ => p.atan2(q),
                        });
                        Out { ty, k, bare: false }
                    }
                    (Ty::Num(x), Ty::Num(y)) => {
                        self.err(Diagnostic::error(
                            Code::E0021,
                            format!(
                                "`{n}` needs two values of the same unit, found {} and {}",
                                x.described(),
                                y.described()
                            ),
                            sp,
                        ));
                        Out::err()
                    }
                    (x, y) => {
                        self.err(Diagnostic::error(
                            Code::E0020,
                            format!(
                                "`{n}` needs two numbers, found {} and {}",
                                x.described(),
                                y.described()
                            ),
                            sp,
                        ));
                        Out::err()
                    }
                }
            }
            "joints" => {
                if args.is_empty() || args.len() > MAX_AXES {
                    self.err(Diagnostic::error(Code::E0013, format!("`joints` takes 1 to {MAX_AXES} values, but {} were given", args.len()), sp).with_help("one value per robot axis: joints(0deg, -30deg, 30deg, 0deg, 60deg, 0deg)"));
                    for a in args {
                        self.expr(a);
                    }
                    return Out::err();
                }
                let mut vals = Vec::new();
                let mut mask = 0u16;
                let mut all = true;
                for (i, a) in args.iter().enumerate() {
                    let o = self.expr(a);
                    if o.ty == Ty::Num(Dim::LENGTH) {
                        mask |= 1 << i;
                    }
                    let k = o.k.clone();
                    self.joint_value(o, a.span);
                    match k {
                        Some(ConstValue::Num(x)) => vals.push(x),
                        Some(ConstValue::Int(0)) => vals.push(0.0),
                        _ => all = false,
                    }
                }
                let pos = self.pos(sp);
                self.m.joints_sites.push(JointsSite {
                    count: args.len() as u8,
                    linear_mask: mask,
                    pos,
                });
                self.emit(Instr::MakeJoints(args.len() as u8), sp);
                Out {
                    ty: Ty::Joints,
                    k: all.then_some(ConstValue::Joints(vals)),
                    bare: false,
                }
            }
            "pose" => {
                if !self.arity(name, args, 6, sp, "pose(x, y, z, rx, ry, rz)") {
                    return Out::err();
                }
                let mut vals = [0.0; 6];
                let mut all = true;
                for (i, a) in args.iter().enumerate() {
                    let want = if i < 3 { Dim::LENGTH } else { Dim::ANGLE };
                    let o = self.expr(a);
                    let comp = ["x", "y", "z", "rx", "ry", "rz"][i];
                    let o =
                        self.coerce(o, Ty::Num(want), a.span, &format!("the `{comp}` of a pose"));
                    match o.k {
                        Some(ConstValue::Num(x)) => vals[i] = x,
                        _ => all = false,
                    }
                }
                Out {
                    ty: Ty::Pose,
                    k: all.then_some(ConstValue::Pose(vals)),
                    bare: false,
                }
            }
            "axis_length" => {
                if !self.arity(name, args, 2, sp, "axis_length(j, i)") {
                    return Out::err();
                }
                let j = self.expr(&args[0]);
                let j = self.coerce(
                    j,
                    Ty::Joints,
                    args[0].span,
                    "the first argument of `axis_length`",
                );
                let i = self.expr(&args[1]);
                let i = self.coerce(i, Ty::Int, args[1].span, "the axis index");
                if j.ty.is_err() {
                    return Out::err();
                }
                self.emit(Instr::JointsGet, sp);
                self.joint_index(j, i, args[1].span, Dim::LENGTH)
            }
            _ => {
                self.unknown_proc(n, name.span);
                for a in args {
                    self.expr(a);
                }
                Out::err()
            }
        }
    }

    fn unary_builtin(&mut self, n: &str, o: Out, aspan: Span, sp: Span) -> Out {
        if o.ty.is_err() {
            return Out::err();
        }
        let fnum = |k: &Option<ConstValue>, f: fn(f64) -> f64| match k {
            Some(ConstValue::Num(x)) => Some(ConstValue::Num(f(*x))),
            _ => None,
        };
        match (n, o.ty) {
            ("abs", Ty::Int) => {
                self.emit(Instr::AbsI, sp);
                let k = match o.k {
                    Some(ConstValue::Int(i)) => i.checked_abs().map(ConstValue::Int),
                    _ => None,
                };
                Out {
                    ty: Ty::Int,
                    k,
                    bare: o.bare,
                }
            }
            ("abs", Ty::Num(d)) => {
                self.emit(Instr::AbsF, sp);
                Out {
                    ty: Ty::Num(d),
                    k: fnum(&o.k, f64::abs),
                    bare: o.bare,
                }
            }
            ("sqrt", Ty::Int | Ty::Num(_)) => {
                let o = if o.ty == Ty::Int {
                    self.coerce(o, Ty::Num(Dim::PLAIN), aspan, "the argument of `sqrt`")
                } else {
                    o
                };
                let Ty::Num(d) = o.ty else { return Out::err() };
                let Some(half) = d.sqrt() else {
                    self.err(Diagnostic::error(Code::E0021, format!("the square root of {} has no unit", d.described()), aspan).with_help("only squared units have a square root, e.g. sqrt(a*a + b*b) for lengths a and b"));
                    return Out::err();
                };
                if let Some(ConstValue::Num(x)) = o.k
                    && x < 0.0
                {
                    self.err(Diagnostic::error(
                        Code::E0025,
                        "the square root of a negative number",
                        aspan,
                    ));
                    return Out::err();
                }
                self.emit(Instr::Sqrt, sp);
                Out {
                    ty: Ty::Num(half),
                    k: fnum(&o.k, f64::sqrt),
                    bare: false,
                }
            }
            ("sin" | "cos", _) => {
                let o = self.coerce(
                    o,
                    Ty::Num(Dim::ANGLE),
                    aspan,
                    &format!("the argument of `{n}`"),
                );
                if o.ty.is_err() {
                    return Out::err();
                }
                self.emit(if n == "sin" { Instr::Sin } else { Instr::Cos }, sp);
                Out {
                    ty: Ty::Num(Dim::PLAIN),
                    k: fnum(&o.k, if n == "sin" { f64::sin } else { f64::cos }),
                    bare: false,
                }
            }
            ("int", Ty::Int) => o,
            ("int", Ty::Num(d)) => {
                if !d.is_plain() {
                    self.err(
                        Diagnostic::error(
                            Code::E0021,
                            format!("`int` takes a plain number, found {}", d.described()),
                            aspan,
                        )
                        .with_help(format!(
                            "divide by a unit first, e.g. int(t / 1{})",
                            default_unit(d).unwrap_or("s")
                        )),
                    );
                    return Out::err();
                }
                self.emit(Instr::NumToInt, sp);
                let k = match o.k {
                    Some(ConstValue::Num(x)) if x.is_finite() && x.trunc().abs() < 9.2e18 => {
                        Some(ConstValue::Int(x.trunc() as i64))
                    }
                    Some(ConstValue::Num(_)) => {
                        self.err(Diagnostic::error(
                            Code::E0026,
                            "this value does not fit in an int",
                            aspan,
                        ));
                        return Out::err();
                    }
                    _ => None,
                };
                Out {
                    ty: Ty::Int,
                    k,
                    bare: false,
                }
            }
            ("num", Ty::Int) => {
                self.emit(Instr::IntToNum, sp);
                Out {
                    ty: Ty::Num(Dim::PLAIN),
                    k: to_num(&o.k),
                    bare: false,
                }
            }
            ("num", Ty::Num(_)) => o,
            (n, t) => {
                self.err(Diagnostic::error(
                    Code::E0020,
                    format!("`{n}` cannot take {}", t.described()),
                    aspan,
                ));
                Out::err()
            }
        }
    }
}

/// Where an assignment stores.
#[derive(Debug)]
enum Place {
    Local(u32),
    Var(u32),
    Global(u32),
}

/// Where a compound assignment loads from.
#[derive(Debug)]
enum Load {
    Local(u32),
    Var(u32),
    Global(u32),
}

fn place_load(p: &Place) -> Load {
    match p {
        Place::Local(s) => Load::Local(*s),
        Place::Var(s) => Load::Var(*s),
        Place::Global(g) => Load::Global(*g),
    }
}

impl Compiler<'_> {
    fn load_place(&mut self, l: &Load, ty: Ty, span: Span) {
        let w = ty.width();
        match *l {
            Load::Local(s) => self.load_local(s, ty, span),
            Load::Var(s) => {
                self.emit(
                    if w == 1 {
                        Instr::LoadVar(s)
                    } else {
                        Instr::LoadVarN(s, w)
                    },
                    span,
                );
            }
            Load::Global(g) => {
                self.emit(Instr::LoadGlobal(g), span);
            }
        }
    }
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
