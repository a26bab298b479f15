//! The syntax tree of RAPID modules, as the parser builds it.
//!
//! Names keep their spelling; the front-end compares them case-insensitively. Every node
//! has a [`Span`] into the task's text.

use crate::syntax::Span;

/// A name as written.
#[derive(Clone, Debug, PartialEq)]
pub struct Name {
    /// The text as written.
    pub text: String,
    /// Where.
    pub span: Span,
}

impl Name {
    /// The name in lower case: RAPID is case-insensitive.
    pub fn key(&self) -> String {
        self.text.to_ascii_lowercase()
    }
}

/// One `MODULE … ENDMODULE`.
#[derive(Clone, Debug, PartialEq)]
pub struct RapidModule {
    /// Its name.
    pub name: Name,
    /// Data declarations and routines, in order.
    pub items: Vec<Item>,
}

/// A module-level declaration.
#[derive(Clone, Debug, PartialEq)]
pub enum Item {
    /// `VAR`/`PERS`/`CONST` data.
    Data(DataDecl),
    /// `PROC`, `FUNC` or `TRAP`.
    Routine(Routine),
    /// `RECORD name … ENDRECORD`: a data type of named components.
    Record(RecordDecl),
}

/// `RECORD name` with its components (`num x;`, `robtarget p;`), `ENDRECORD`.
#[derive(Clone, Debug, PartialEq)]
pub struct RecordDecl {
    /// `LOCAL`: its module's own.
    pub local: bool,
    /// The type's name.
    pub name: Name,
    /// Each component: its type's name and its name.
    pub fields: Vec<(Name, Name)>,
    /// Where.
    pub span: Span,
}

/// How data is stored.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Storage {
    /// `VAR`: a variable.
    Var,
    /// `PERS`: persistent, shared by every task that declares it.
    Pers,
    /// `CONST`: a constant.
    Const,
}

impl Storage {
    /// The keyword.
    pub fn keyword(self) -> &'static str {
        match self {
            Storage::Var => "VAR",
            Storage::Pers => "PERS",
            Storage::Const => "CONST",
        }
    }
}

/// `[LOCAL] VAR num n{3} := …;`
#[derive(Clone, Debug, PartialEq)]
pub struct DataDecl {
    /// `LOCAL` or `TASK` given.
    pub local: bool,
    /// VAR, PERS or CONST.
    pub storage: Storage,
    /// The data type's name.
    pub ty: Name,
    /// The name.
    pub name: Name,
    /// Array dimensions (`{3}`, `{2,3}`), empty for a scalar.
    pub dims: Vec<Expr>,
    /// `:= value`.
    pub init: Option<Expr>,
    /// The whole declaration.
    pub span: Span,
}

/// What kind of routine.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum RoutineKind {
    /// `PROC`
    Proc,
    /// `FUNC type`
    Func,
    /// `TRAP`: an interrupt routine.
    Trap,
}

/// A `PROC`, `FUNC` or `TRAP`.
#[derive(Clone, Debug, PartialEq)]
pub struct Routine {
    /// `LOCAL` given.
    pub local: bool,
    /// Which kind.
    pub kind: RoutineKind,
    /// A function's result type.
    pub ret: Option<Name>,
    /// Its name.
    pub name: Name,
    /// Parameters.
    pub params: Vec<ParamDecl>,
    /// Local data declared at the start of the body.
    pub locals: Vec<DataDecl>,
    /// The statements.
    pub body: Vec<Stmt>,
    /// The `ERROR` handler: where its keyword is, and its statements.
    pub handler: Option<(Span, Vec<Stmt>)>,
    /// A `BACKWARD` or `UNDO` handler given (not supported; where).
    pub other_handler: Option<Span>,
    /// From the keyword to the end of the parameter list.
    pub span: Span,
}

/// How a parameter is passed.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Mode {
    /// By value (the default).
    In,
    /// `VAR`, `PERS` or `INOUT`: by reference.
    Ref,
}

/// A routine's parameter.
#[derive(Clone, Debug, PartialEq)]
pub struct ParamDecl {
    /// `\`: optional.
    pub optional: bool,
    /// How it is passed.
    pub mode: Mode,
    /// Its type.
    pub ty: Name,
    /// Its name.
    pub name: Name,
    /// `{*}`: an array parameter.
    pub array: bool,
    /// Where.
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

/// An argument of a call: `expr`, `\Name`, `\Name:=expr`.
#[derive(Clone, Debug, PartialEq)]
pub enum Arg {
    /// A required (positional) argument.
    Pos(Expr),
    /// An optional argument by name, with its value (a switch has none).
    Opt(Name, Option<Expr>),
    /// `\Name?x`: the optional argument given if, and as, the caller's optional parameter
    /// `x` was given to it.
    Cond(Name, Name),
}

/// Statement kinds.
#[derive(Clone, Debug, PartialEq)]
pub enum StmtKind {
    /// `target := value;`
    Assign {
        /// A name, `a.b`, `a{i}`.
        target: Expr,
        /// The value.
        value: Expr,
    },
    /// `Name arg, arg \Opt:=v;`: a procedure or instruction call.
    Call {
        /// The procedure.
        name: Name,
        /// Arguments in order.
        args: Vec<Arg>,
    },
    /// `IF … THEN … ELSEIF … ELSE … ENDIF`, and the one-line `IF cond stmt`.
    If {
        /// Conditions and bodies: the `IF`, then each `ELSEIF`.
        branches: Vec<(Expr, Vec<Stmt>)>,
        /// `ELSE`.
        els: Option<Vec<Stmt>>,
    },
    /// `WHILE c DO … ENDWHILE`
    While {
        /// Condition.
        cond: Expr,
        /// Body.
        body: Vec<Stmt>,
    },
    /// `FOR i FROM a TO b [STEP s] DO … ENDFOR`
    For {
        /// Loop variable.
        var: Name,
        /// Start.
        from: Expr,
        /// End (inclusive).
        to: Expr,
        /// Step (default 1).
        step: Option<Expr>,
        /// Body.
        body: Vec<Stmt>,
    },
    /// `TEST e CASE a, b: … DEFAULT: … ENDTEST`
    Test {
        /// The tested value.
        value: Expr,
        /// Each `CASE` list and its body.
        cases: Vec<(Vec<Expr>, Vec<Stmt>)>,
        /// `DEFAULT:`
        default: Option<Vec<Stmt>>,
    },
    /// `RETURN [e];`
    Return(Option<Expr>),
    /// `EXIT;`: ends the program.
    Exit,
    /// `CONNECT intno WITH trap;`
    Connect {
        /// The interrupt variable.
        intno: Expr,
        /// The trap routine.
        trap: Name,
    },
    /// `RAISE [errno];`
    Raise(Option<Expr>),
    /// `RETRY;`
    Retry,
    /// `GOTO label;`
    Goto(Name),
    /// `label:`
    Label(Name),
    /// `TRYNEXT;`
    TryNext,
    /// A construct the front-end does not run (already parsed so the message names it):
    /// `GOTO`, labels, late binding.
    Unsupported(&'static str),
    /// A statement that did not parse (already reported).
    Error,
}

/// Unary operators.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum UnOp {
    /// `-`
    Neg,
    /// `+`
    Plus,
    /// `NOT`
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
    IntDiv,
    Mod,
    Eq,
    Ne,
    Lt,
    Le,
    Gt,
    Ge,
    And,
    Or,
    Xor,
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
            IntDiv => "DIV",
            Mod => "MOD",
            Eq => "=",
            Ne => "<>",
            Lt => "<",
            Le => "<=",
            Gt => ">",
            Ge => ">=",
            And => "AND",
            Or => "OR",
            Xor => "XOR",
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
    /// A number.
    Num(f64),
    /// A string.
    Str(String),
    /// `TRUE`/`FALSE`
    Bool(bool),
    /// A data name.
    Name(Name),
    /// `[a, b, …]`: an aggregate (a record's or an array's value).
    Aggregate(Vec<Expr>),
    /// `-e`, `NOT e`
    Unary(UnOp, Box<Expr>),
    /// `a op b`
    Binary(BinOp, Box<Expr>, Box<Expr>),
    /// `F(args)`
    Call(Name, Vec<Arg>),
    /// `e.field`
    Field(Box<Expr>, Name),
    /// `e{i}` or `e{i, j}`
    Index(Box<Expr>, Vec<Expr>),
    /// Did not parse (already reported).
    Error,
}
