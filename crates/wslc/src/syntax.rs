//! The syntax tree of one WSL module, as the parser builds it.
//!
//! Every node has a [`Span`] (byte offsets into the source). Nodes that failed to parse are
//! kept as `Error` variants so later passes can go on and report other problems without
//! repeating the parse error.

use vworks_vm::Dim;

/// A byte range in the source.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default, Hash)]
pub struct Span {
    /// First byte.
    pub start: u32,
    /// One past the last byte.
    pub end: u32,
}

impl Span {
    /// A span from byte offsets (saturating at 4 GiB).
    pub fn new(start: usize, end: usize) -> Span {
        Span {
            start: u32::try_from(start).unwrap_or(u32::MAX),
            end: u32::try_from(end).unwrap_or(u32::MAX),
        }
    }
    /// The span moved `by` bytes later (saturating at 4 GiB).
    pub fn shifted(self, by: usize) -> Span {
        Span::new(self.start as usize + by, self.end as usize + by)
    }
    /// The smallest span covering both.
    pub fn to(self, other: Span) -> Span {
        Span {
            start: self.start.min(other.start),
            end: self.end.max(other.end),
        }
    }
    /// As a `Range<usize>`.
    pub fn range(self) -> std::ops::Range<usize> {
        self.start as usize..self.end as usize
    }
}

/// A name as written.
#[derive(Clone, Debug, PartialEq)]
pub struct Ident {
    /// The text.
    pub name: String,
    /// Where.
    pub span: Span,
}

/// A whole file.
#[derive(Clone, Debug, PartialEq, Default)]
pub struct SourceModule {
    /// Declarations in order.
    pub items: Vec<Item>,
    /// Text values are allowed: the type `text`, and text literals in expressions. True
    /// for a translation from RAPID, whose strings are values; WSL writes text only in
    /// `log` and `fail` (E0034), so its parser leaves this false.
    pub texts: bool,
}

/// A module-level declaration.
#[derive(Clone, Debug, PartialEq)]
pub enum Item {
    /// `global name = value;`
    Global(VarDecl),
    /// `const name = value;`
    Const(VarDecl),
    /// `param name = value;`: a constant a workcell or a sweep may override.
    Param(VarDecl),
    /// `var name = value;`
    Var(VarDecl),
    /// `proc` or `func`.
    Proc(ProcDecl),
}

/// `var`/`const`/`global`/`param` declaration.
#[derive(Clone, Debug, PartialEq)]
pub struct VarDecl {
    /// Name.
    pub name: Ident,
    /// Optional `: type`.
    pub ty: Option<Ident>,
    /// Optional `= value`.
    pub init: Option<Expr>,
    /// The whole declaration.
    pub span: Span,
}

/// A `proc` or `func`.
#[derive(Clone, Debug, PartialEq)]
pub struct ProcDecl {
    /// `func` (returns a value, zero time) rather than `proc`.
    pub is_func: bool,
    /// Name.
    pub name: Ident,
    /// Parameters.
    pub params: Vec<Param>,
    /// `-> type` of a func.
    pub ret: Option<Ident>,
    /// Body.
    pub body: Block,
    /// Its error handler (only in a translation from RAPID: an `ERROR` clause).
    pub handler: Option<Block>,
    /// From the keyword to the end of the parameter list.
    pub span: Span,
}

/// `name: type`.
#[derive(Clone, Debug, PartialEq)]
pub struct Param {
    /// Name.
    pub name: Ident,
    /// Type name.
    pub ty: Ident,
}

/// `{ statements }`.
#[derive(Clone, Debug, PartialEq)]
pub struct Block {
    /// Statements.
    pub stmts: Vec<Stmt>,
    /// Braces included.
    pub span: Span,
}

/// A statement.
#[derive(Clone, Debug, PartialEq)]
pub struct Stmt {
    /// What it is.
    pub kind: StmtKind,
    /// Where.
    pub span: Span,
}

/// The motion commands.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum MoveKind {
    /// `move_j`
    J,
    /// `move_l`
    L,
    /// `move_c`
    C,
}

impl MoveKind {
    /// The keyword.
    pub fn keyword(self) -> &'static str {
        match self {
            MoveKind::J => "move_j",
            MoveKind::L => "move_l",
            MoveKind::C => "move_c",
        }
    }
}

/// What fires a `when` handler.
#[derive(Clone, Debug, PartialEq)]
pub enum TriggerExpr {
    /// `every N cycles`
    EveryCycles(Expr),
    /// `every T`
    Every(Expr),
    /// `after T`
    After(Expr),
    /// `when condition do …`
    Cond(Expr),
}

/// Statement kinds.
// Built once per compilation, never in a hot loop: a motion's options in line are
// simpler than boxing them.
#[allow(clippy::large_enum_variant)]
#[derive(Clone, Debug, PartialEq)]
pub enum StmtKind {
    /// `var x = e;`
    Var(VarDecl),
    /// `target = e;` or `target += e;` (`op` is the arithmetic of a compound assignment).
    Assign {
        /// A name, `p.x` or `j[i]`.
        target: Expr,
        /// `+`, `-`, `*`, `/` for `+=` …
        op: Option<BinOp>,
        /// Right-hand side.
        value: Expr,
    },
    /// `name(args);`
    Call {
        /// Callee.
        name: Ident,
        /// Arguments.
        args: Vec<Expr>,
    },
    /// `if c { } else …`
    /// `if c { } else if d { } … else { }`: the chain is flat (a dispatch on a program
    /// number may have hundreds of branches; it is not nesting).
    If {
        /// Each condition and its block, in order: the `if`, then every `else if`.
        branches: Vec<(Expr, Block)>,
        /// The final `else { }`.
        els: Option<Block>,
    },
    /// `while c { }`
    While {
        /// Condition.
        cond: Expr,
        /// Body.
        body: Block,
    },
    /// `for i in a..b { }`
    For {
        /// Loop variable.
        var: Ident,
        /// Start (inclusive).
        start: Expr,
        /// End (exclusive).
        end: Expr,
        /// Body.
        body: Block,
    },
    /// `break;`
    Break,
    /// `continue;`
    Continue,
    /// `return;` or `return e;`
    Return(Option<Expr>),
    /// `move_j/move_l/move_c`.
    Move {
        /// Which command.
        kind: MoveKind,
        /// `via` point of `move_c`.
        via: Option<Expr>,
        /// Target.
        target: Expr,
        /// `speed e`.
        speed: Option<Expr>,
        /// `accel e`.
        accel: Option<Expr>,
        /// `orient e`: the largest orientation speed of `move_l`/`move_c`.
        orient: Option<Expr>,
        /// `zone e` or `zone fine`.
        zone: Option<Zone>,
        /// `tool e`: the TCP (a pose in the tool link's frame) from this motion on.
        tool: Option<Expr>,
        /// `duration e`: how long the motion takes, instead of a speed.
        duration: Option<Expr>,
    },
    /// `delay t;`
    Delay(Expr),
    /// `pulse g for t;`: global `g` to 1 now, back to 0 after `t`.
    Pulse {
        /// The global.
        global: Ident,
        /// How long.
        length: Expr,
    },
    /// `wait_until c [timeout t];`
    WaitUntil {
        /// Condition over globals.
        cond: Expr,
        /// Optional timeout.
        timeout: Option<Expr>,
        /// `poll p`: tested at once, then every `p` from the wait's start.
        poll: Option<Expr>,
    },
    /// `signal robot.name;`
    Signal {
        /// Receiver.
        robot: Ident,
        /// Signal name.
        name: Ident,
    },
    /// `sync name with task, task… [timeout t];`: this robot arrives at sync point `name`
    /// and waits until every task of the list has arrived as often.
    Sync {
        /// The sync point (cell-wide).
        name: Ident,
        /// The tasks that meet there (the workcell robots' `task` names).
        tasks: Vec<Ident>,
        /// Optional timeout.
        timeout: Option<Expr>,
    },
    /// `wait_signal name [timeout t];`
    WaitSignal {
        /// Signal name.
        name: Ident,
        /// Optional timeout.
        timeout: Option<Expr>,
    },
    /// `parallel { branches }`
    Parallel(Vec<Stmt>),
    /// `remote robot.proc(args);`
    Remote {
        /// Robot.
        robot: Ident,
        /// Procedure in its module.
        proc: Ident,
        /// Arguments.
        args: Vec<Expr>,
    },
    /// `when trigger do handler(args);`
    When {
        /// What fires it.
        trigger: TriggerExpr,
        /// The procedure to run.
        handler: Ident,
        /// Its arguments, evaluated at firing time.
        args: Vec<Expr>,
    },
    /// `disable handler;`
    Disable(Ident),
    /// `grip part;`
    Grip(Ident),
    /// `release part;`
    Release(Ident),
    /// `log a, b, …;`
    Log(Vec<Expr>),
    /// `fail a, b, …;`
    Fail(Vec<Expr>),
    /// `stop;`
    Stop,
    /// Raises error `errno` (an int) with `message`, or, with `None` in an error handler,
    /// its error again where the procedure was called (a translation from RAPID only:
    /// `RAISE`).
    Raise(Option<Expr>, String),
    /// In an error handler: run the statement that failed again (`RETRY`).
    Retry,
    /// In an error handler: go on after the statement that failed (`TRYNEXT`).
    TryNext,
    /// One statement of a procedure with an error handler, as `Retry` runs it again and
    /// `TryNext` goes on after it (a translation from RAPID: one RAPID statement).
    Recover(Block),
    /// `{ … }`
    Block(Block),
    /// A statement that did not parse (already reported).
    Error,
}

/// Unary operators.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum UnOp {
    /// `-`
    Neg,
    /// `not` / `!`
    Not,
}

/// Binary operators.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[allow(missing_docs)]
pub enum BinOp {
    Add,
    Sub,
    Mul,
    Div,
    Mod,
    Eq,
    Ne,
    Lt,
    Le,
    Gt,
    Ge,
    And,
    Or,
}

impl BinOp {
    /// The operator as written.
    pub fn symbol(self) -> &'static str {
        use BinOp::*;
        match self {
            Add => "+",
            Sub => "-",
            Mul => "*",
            Div => "/",
            Mod => "mod",
            Eq => "==",
            Ne => "!=",
            Lt => "<",
            Le => "<=",
            Gt => ">",
            Ge => ">=",
            And => "and",
            Or => "or",
        }
    }
}

/// An expression.
#[derive(Clone, Debug, PartialEq)]
pub struct Expr {
    /// What it is.
    pub kind: ExprKind,
    /// Where.
    pub span: Span,
}

/// Expression kinds.
#[derive(Clone, Debug, PartialEq)]
pub enum ExprKind {
    /// `42`
    Int(i64),
    /// `3.5`
    Num(f64),
    /// `250mm/s`, in SI.
    Quantity(f64, Dim),
    /// `true`/`false`
    Bool(bool),
    /// `"text"`
    Str(String),
    /// A name.
    Name(String),
    /// `-e`, `not e`
    Unary(UnOp, Box<Expr>),
    /// `a op b`
    Binary(BinOp, Box<Expr>, Box<Expr>),
    /// `f(args)`
    Call(Ident, Vec<Expr>),
    /// `e.field`
    Field(Box<Expr>, Ident),
    /// `e[i]`
    Index(Box<Expr>, Box<Expr>),
    /// Did not parse (already reported).
    Error,
}

/// The `zone` option of a motion.
#[derive(Clone, Debug, PartialEq)]
pub enum Zone {
    /// `zone fine`: stop at the point.
    Fine,
    /// `zone e`: fly by within the radius `e` (a length).
    Radius(Expr),
    /// `zone e ori d [a]`: fly by within the radius `e`, the tool turning towards the next
    /// motion from where the TCP comes within `d` of the point (RAPID's `pzone_ori`),
    /// turning it by at most `a` there (an angle, `zone_ori`).
    Extended(Box<ExtendedZone>),
}

/// A zone with an orientation zone: `zone e ori d [a]` ([`Zone::Extended`]).
#[derive(Clone, Debug, PartialEq)]
pub struct ExtendedZone {
    /// The zone's radius (a length).
    pub radius: Expr,
    /// The orientation zone's radius (a length).
    pub ori: Expr,
    /// The most the orientation zone turns the tool (an angle), if bounded.
    pub angle: Option<Expr>,
}
