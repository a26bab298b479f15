//! WSL bytecode: one compiled `.wsl` file is one [`Module`].
//!
//! A module holds its procedures' code and every table the linker, the SE and the VM need
//! without re-reading the source: constants, module variables, the globals it declares,
//! for each `wait_until`/`when` condition the globals it reads, the signals it sends and
//! waits for, the remote calls, part and joint-vector sites it must have checked at link
//! time, and a line table from instruction to `line:col`.
//!
//! [`Module::encode`] writes the `.wslb` bytes; [`Module::decode`] reads untrusted bytes and
//! [`Module::verify`]s them, so a loaded module is always safe to run: every index is in
//! range and every procedure's stack height is consistent on every path.

mod disasm;
mod encode;
mod instr;
mod verify;

pub use disasm::disassemble;
pub use encode::{FORMAT_VERSION, MAGIC};
pub use instr::{Cmp, Instr, MoveFlags, StackEffect};
pub use verify::{CodeProblem, MAX_FRAME, MAX_STACK, RuleRef, StringUser, VerifyError};

use crate::types::{ConstValue, Type};

/// A position in a source file, 1-based; `col` counts characters. `file` indexes the
/// module's [`Module::files`] (0, the first file, for a program of one file).
#[derive(Clone, Copy, PartialEq, Eq, Debug, Default, Hash, PartialOrd, Ord)]
pub struct SrcPos {
    /// Which of the module's source files, from 0.
    pub file: u32,
    /// Line, from 1.
    pub line: u32,
    /// Column in characters, from 1.
    pub col: u32,
}

impl std::fmt::Display for SrcPos {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}:{}", self.line, self.col)
    }
}

/// Why bytes could not be loaded as a module.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum LoadError {
    /// The bytes do not start with the `WSLB` magic: not a vworks bytecode file.
    #[error(
        "not a vworks bytecode file (it does not start with \"WSLB\"); compile the program with `vworks build`"
    )]
    BadMagic,
    /// The format version is one this build does not read.
    #[error(
        "bytecode format version {found} is not supported (this build reads version {supported}); rebuild the module with this vworks"
    )]
    Version {
        /// Version in the file.
        found: u16,
        /// Version this build reads.
        supported: u16,
    },
    /// The checksum does not match: the file was truncated or altered.
    #[error("checksum mismatch: the file is damaged or truncated; rebuild it with `vworks build`")]
    Checksum,
    /// The bytes are malformed at a byte offset.
    #[error("malformed bytecode at byte {offset}: {message}")]
    Malformed {
        /// Byte offset of the problem.
        offset: usize,
        /// What is wrong.
        message: String,
    },
    /// The structure decoded, but the module is inconsistent: what and where.
    #[error("invalid module: {0}")]
    Invalid(#[from] VerifyError),
}

/// What kind of code a procedure entry holds.
#[derive(Clone, Copy, PartialEq, Eq, Debug, Hash)]
pub enum ProcKind {
    /// A `proc`: may take time, never returns a value.
    Proc,
    /// A `func`: zero time, returns a value.
    Func,
    /// A compiled `wait_until`/`when` condition: a bool function of its captured locals.
    Cond,
    /// The action of a `when` handler: evaluates the handler's arguments and calls it.
    Handler,
}

impl ProcKind {
    fn code(self) -> u8 {
        self as u8
    }
    fn from_code(b: u8) -> Option<ProcKind> {
        Some(match b {
            0 => ProcKind::Proc,
            1 => ProcKind::Func,
            2 => ProcKind::Cond,
            3 => ProcKind::Handler,
            _ => return None,
        })
    }
    /// `proc`, `func`, `cond` or `handler`.
    pub fn keyword(self) -> &'static str {
        match self {
            ProcKind::Proc => "proc",
            ProcKind::Func => "func",
            ProcKind::Cond => "cond",
            ProcKind::Handler => "handler",
        }
    }
}

/// A parameter of a procedure.
#[derive(Clone, PartialEq, Debug)]
pub struct ParamInfo {
    /// Name (string index).
    pub name: u32,
    /// Type.
    pub ty: Type,
}

/// A procedure, function, condition or handler action.
#[derive(Clone, PartialEq, Debug)]
pub struct ProcInfo {
    /// Name (string index). Synthetic entries are named like `when#0` and `cond#1`.
    pub name: u32,
    /// What it is.
    pub kind: ProcKind,
    /// Parameters; their values are the first slots of the frame.
    pub params: Vec<ParamInfo>,
    /// Return type of a function or condition.
    pub ret: Option<Type>,
    /// Slots in a frame: parameters first, then locals.
    pub frame_slots: u32,
    /// First instruction in [`Module::code`].
    pub code_start: u32,
    /// Number of instructions.
    pub code_len: u32,
    /// Where it is declared.
    pub pos: SrcPos,
    /// The deepest the operand stack gets (slots); computed by [`Module::verify`].
    pub max_stack: u32,
    /// Its error handler (RAPID's `ERROR` clause), if it has one.
    pub handler: Option<ErrorHandler>,
}

/// A procedure's error handler: where it starts, and the procedure's statements, for
/// `Retry` (run the statement that failed again) and `TryNext` (go on after it).
#[derive(Clone, PartialEq, Eq, Debug, Default)]
pub struct ErrorHandler {
    /// Its first instruction, relative to the procedure's start.
    pub pc: u32,
    /// Every statement of the procedure's body as `[start, end)` (relative); the
    /// innermost one holding a pc is the statement that failed there.
    pub stmts: Vec<(u32, u32)>,
}

impl ErrorHandler {
    /// The innermost statement holding relative pc `pc`.
    pub fn statement_at(&self, pc: u32) -> Option<(u32, u32)> {
        self.stmts
            .iter()
            .filter(|(s, e)| *s <= pc && pc < *e)
            .min_by_key(|(s, e)| e - s)
            .copied()
    }
}

impl ProcInfo {
    /// Total slots of the parameters.
    pub fn param_width(&self) -> u32 {
        self.params.iter().map(|p| u32::from(p.ty.width())).sum()
    }
    /// The instructions of this procedure (empty if the range is invalid).
    pub fn code<'m>(&self, m: &'m Module) -> &'m [Instr] {
        let start = self.code_start as usize;
        m.code
            .get(start..start.saturating_add(self.code_len as usize))
            .unwrap_or(&[])
    }
}

/// A named constant or a pool entry used by `PushConst`.
#[derive(Clone, PartialEq, Debug)]
pub struct ConstInfo {
    /// The `const` name (string index), or `None` for an anonymous pool entry.
    pub name: Option<u32>,
    /// Type.
    pub ty: Type,
    /// Value.
    pub value: ConstValue,
    /// Declaration (or use) site.
    pub pos: SrcPos,
}

/// A `global` the module declares (or uses: every module lists the globals it touches).
#[derive(Clone, PartialEq, Debug)]
pub struct GlobalInfo {
    /// Name (string index).
    pub name: u32,
    /// Type: `bool`, `int` or a `num`.
    pub ty: Type,
    /// Initial value; must agree across the cell.
    pub init: ConstValue,
    /// Declaration site.
    pub pos: SrcPos,
}

/// A module-level `var` or `param`: lives for the whole run, private to the robot.
#[derive(Clone, PartialEq, Debug)]
pub struct VarInfo {
    /// Name (string index).
    pub name: u32,
    /// Type.
    pub ty: Type,
    /// First slot in the module-variable area.
    pub slot: u32,
    /// Initial value (for a `param`, its default, which the cell loader may replace).
    pub init: ConstValue,
    /// Declaration site.
    pub pos: SrcPos,
    /// A `param`: read-only in the program, its initial value set by the workcell or a
    /// sweep (`vworks_cell`).
    pub param: bool,
}

/// A local copied into a condition or handler when it is created (by value).
#[derive(Clone, Copy, PartialEq, Eq, Debug)]
pub struct Capture {
    /// Slot in the creating frame.
    pub slot: u32,
    /// Width in slots.
    pub width: u8,
}

/// A `wait_until` or `when` condition.
#[derive(Clone, PartialEq, Debug)]
pub struct CondInfo {
    /// The condition function (kind [`ProcKind::Cond`]); its parameters are the captures.
    pub func: u32,
    /// Locals of the creating frame passed to `func`, in parameter order.
    pub captures: Vec<Capture>,
    /// Every global (index into [`Module::globals`]) the condition reads, sorted: the SE
    /// sends `check_wait`/`check_when` to this robot after a `set` of any of them.
    pub globals: Vec<u32>,
    /// Source position of the condition.
    pub pos: SrcPos,
}

/// When a handler fires.
#[derive(Clone, Copy, PartialEq, Eq, Debug)]
pub enum Trigger {
    /// `every N cycles` (N is the int operand of `When`).
    EveryCycles,
    /// `every T` (T is the time operand).
    Every,
    /// `after T`, once.
    After,
    /// On each false→true edge of condition `c` (index into [`Module::conds`]).
    Condition(u32),
}

impl Trigger {
    /// True if `When` pops an operand for this trigger.
    pub fn has_operand(self) -> bool {
        !matches!(self, Trigger::Condition(_))
    }
}

/// A `when … do p(args);` statement.
#[derive(Clone, PartialEq, Debug)]
pub struct HandlerInfo {
    /// When it fires.
    pub trigger: Trigger,
    /// The action (kind [`ProcKind::Handler`]): evaluates the arguments at firing time and
    /// calls `target`; its parameters are the captures.
    pub action: u32,
    /// The procedure the handler calls; `disable p` names it.
    pub target: u32,
    /// Locals of the enabling frame copied into the handler, in parameter order.
    pub captures: Vec<Capture>,
    /// Source position of the `when` statement.
    pub pos: SrcPos,
}

/// A `remote robot.proc(args)` call site.
#[derive(Clone, PartialEq, Debug)]
pub struct RemoteSite {
    /// Robot name (string index).
    pub robot: u32,
    /// Procedure name in that robot's module (string index).
    pub proc: u32,
    /// Types of the arguments, as pushed.
    pub args: Vec<Type>,
    /// Source position.
    pub pos: SrcPos,
}

impl RemoteSite {
    /// Total slots of the arguments.
    pub fn arg_width(&self) -> u32 {
        self.args.iter().map(|t| u32::from(t.width())).sum()
    }
}

/// A `signal robot.name` site.
#[derive(Clone, PartialEq, Debug)]
pub struct SignalSite {
    /// Receiving robot (string index).
    pub robot: u32,
    /// Signal name (string index).
    pub name: u32,
    /// Source position.
    pub pos: SrcPos,
}

/// A `sync` site: a sync point (a barrier) and the tasks that meet there.
#[derive(Clone, PartialEq, Debug)]
pub struct SyncSite {
    /// The sync point's name (string index), cell-wide.
    pub name: u32,
    /// The tasks of its list (string indices), as the program names them: the workcell
    /// robots' `task` names.
    pub tasks: Vec<u32>,
    /// Source position.
    pub pos: SrcPos,
}

/// A `grip`/`release` site.
#[derive(Clone, PartialEq, Debug)]
pub struct PartSite {
    /// Part name (string index).
    pub part: u32,
    /// Source position.
    pub pos: SrcPos,
}

/// A `joints(…)` construction, checked against the robot's axis count at link time.
#[derive(Clone, PartialEq, Debug)]
pub struct JointsSite {
    /// Number of values.
    pub count: u8,
    /// Bit i set: value i is a length (a prismatic axis), else an angle.
    pub linear_mask: u16,
    /// Source position.
    pub pos: SrcPos,
}

/// A piece of a `log`/`fail` message.
#[derive(Clone, PartialEq, Debug)]
pub enum LogPart {
    /// Literal text (string index).
    Text(u32),
    /// A value popped from the stack, printed in display units.
    Value(Type),
}

/// The shape of a `log` or `fail` message.
#[derive(Clone, PartialEq, Debug)]
pub struct LogFormat {
    /// The pieces in order.
    pub parts: Vec<LogPart>,
}

impl LogFormat {
    /// Total slots of the value pieces.
    pub fn value_width(&self) -> u32 {
        self.parts
            .iter()
            .map(|p| match p {
                LogPart::Value(t) => u32::from(t.width()),
                LogPart::Text(_) => 0,
            })
            .sum()
    }
}

/// Line-table row: instructions from `pc` on come from `pos` (until the next row).
#[derive(Clone, Copy, PartialEq, Eq, Debug)]
pub struct LineEntry {
    /// Absolute instruction index.
    pub pc: u32,
    /// Source position.
    pub pos: SrcPos,
}

/// A compiled WSL module.
#[derive(Clone, PartialEq, Debug, Default)]
pub struct Module {
    /// The source files it was compiled from, as given to the compiler, in order: a
    /// robot task may be several files (RAPID modules). The first names the module; a
    /// [`SrcPos`]'s `file` indexes this list.
    pub files: Vec<String>,
    /// Interned names and texts.
    pub strings: Vec<String>,
    /// Named constants and the constant pool.
    pub consts: Vec<ConstInfo>,
    /// Globals the module declares.
    pub globals: Vec<GlobalInfo>,
    /// Module variables.
    pub vars: Vec<VarInfo>,
    /// Slots of the module-variable area.
    pub var_slots: u32,
    /// Procedures, functions, conditions and handler actions.
    pub procs: Vec<ProcInfo>,
    /// All code, procedure after procedure.
    pub code: Vec<Instr>,
    /// Conditions of `wait_until` and `when`.
    pub conds: Vec<CondInfo>,
    /// `when` handlers.
    pub handlers: Vec<HandlerInfo>,
    /// `remote` call sites.
    pub remotes: Vec<RemoteSite>,
    /// `signal` sites.
    pub signals_sent: Vec<SignalSite>,
    /// Names (string indices) of the signals this module waits for, without repeats.
    pub signals_awaited: Vec<u32>,
    /// `sync` sites (sync points and their task lists).
    pub syncs: Vec<SyncSite>,
    /// `grip`/`release` sites.
    pub parts: Vec<PartSite>,
    /// `joints(…)` sites.
    pub joints_sites: Vec<JointsSite>,
    /// `log`/`fail` message shapes.
    pub log_formats: Vec<LogFormat>,
    /// Line table, sorted by `pc`.
    pub lines: Vec<LineEntry>,
}

impl Module {
    /// The file that names the module: its first source file (empty if it has none).
    pub fn source_path(&self) -> &str {
        self.files.first().map_or("", String::as_str)
    }

    /// The source file a position refers to (the first file for an index out of range;
    /// verified modules have none).
    pub fn file_of(&self, pos: SrcPos) -> &str {
        self.files
            .get(pos.file as usize)
            .map_or(self.source_path(), String::as_str)
    }

    /// The name (last path component) of the file a position refers to, as messages and
    /// listings show it.
    pub fn file_name_of(&self, pos: SrcPos) -> &str {
        let path = self.file_of(pos);
        std::path::Path::new(path)
            .file_name()
            .and_then(|n| n.to_str())
            .unwrap_or(path)
    }

    /// The string at index `i` (empty if out of range; verified modules never are).
    pub fn str(&self, i: u32) -> &str {
        self.strings.get(i as usize).map_or("", String::as_str)
    }

    /// The index of a procedure, function or handler target by name.
    pub fn proc_index(&self, name: &str) -> Option<u32> {
        self.procs
            .iter()
            .position(|p| {
                matches!(p.kind, ProcKind::Proc | ProcKind::Func) && self.str(p.name) == name
            })
            .map(|i| i as u32)
    }

    /// The procedure named `name`, if it is a `proc` or `func`.
    pub fn proc(&self, name: &str) -> Option<&ProcInfo> {
        self.proc_index(name)
            .and_then(|i| self.procs.get(i as usize))
    }

    /// The index of a global by name.
    pub fn global_index(&self, name: &str) -> Option<u32> {
        self.globals
            .iter()
            .position(|g| self.str(g.name) == name)
            .map(|i| i as u32)
    }

    /// The source position of the instruction at absolute index `pc`.
    pub fn pos_of(&self, pc: u32) -> SrcPos {
        match self.lines.binary_search_by_key(&pc, |e| e.pc) {
            Ok(i) => self.lines[i].pos,
            Err(0) => SrcPos::default(),
            Err(i) => self.lines[i - 1].pos,
        }
    }

    /// Which procedure contains absolute instruction `pc`.
    pub fn proc_at(&self, pc: u32) -> Option<u32> {
        self.procs
            .iter()
            .position(|p| pc >= p.code_start && pc - p.code_start < p.code_len)
            .map(|i| i as u32)
    }
}
