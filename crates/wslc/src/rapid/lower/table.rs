//! RAPID's built-in instructions and functions: the one table of what the front-end
//! runs. Each row gives the name as docs/rapid.md writes it, how many positional
//! arguments it takes, the optional arguments (`\Conc`, `\T`, …) it accepts, how it is
//! lowered, and one line of documentation; the translation dispatches through it
//! ([`Tr::instruction`], [`Tr::builtin_function`]) and checks every call's arguments
//! against its row before lowering. docs/rapid.md is checked against this table (a test
//! below), as docs/language.md is against WSL's built-ins.
//!
//! A next front-end (KRL) writes a table like this one and lowering functions; the
//! dispatch and the argument checks are the same.

use std::ops::RangeInclusive;

use super::data::{Ty, build as b};
use super::{Tr, Val};
use crate::rapid::syntax::{self as r, Arg};
use crate::syntax::{self as w, Span};

/// A call of a built-in, its arguments checked against its row.
pub(crate) struct Call<'a> {
    /// The name in lower case (rows shared by several names read it).
    pub(crate) key: &'a str,
    /// The name as written.
    pub(crate) name: &'a r::Name,
    /// The whole call.
    pub(crate) span: Span,
    /// The positional arguments: as many as the row allows.
    pub(crate) pos: Vec<&'a r::Expr>,
    /// The optional arguments given, each as (lower-case name, name as written, value):
    /// only names the row lists.
    pub(crate) opts: Vec<(String, &'a r::Name, Option<&'a r::Expr>)>,
}

/// An instruction's lowering: WSL statements onto `out`.
pub(crate) type InstrFn = for<'t, 'a> fn(&mut Tr<'t>, &Call<'a>, &mut Vec<w::Stmt>);

/// A function's lowering: its value (`None` after a diagnostic).
pub(crate) type FuncFn = for<'t, 'a> fn(&mut Tr<'t>, &Call<'a>) -> Option<Val>;

/// How an instruction is lowered.
#[derive(Clone, Copy)]
pub(crate) enum InstrLowering {
    /// Arguments checked, then lowered by the function.
    Lower(InstrFn),
    /// Accepted with any arguments; nothing to simulate.
    NoOp,
    /// RAPID that vworks does not run: E0300 with this help, whatever the arguments.
    NotRun(&'static str),
}

/// How a function is lowered.
#[derive(Clone, Copy)]
pub(crate) enum FuncLowering {
    /// Arguments checked, then lowered by the function.
    Lower(FuncFn),
}

/// One row of a table.
pub(crate) struct Row<L> {
    /// The name as RAPID's manuals and docs/rapid.md write it (matched in any case).
    pub(crate) name: &'static str,
    /// How many positional arguments it takes.
    pub(crate) args: RangeInclusive<usize>,
    /// The optional arguments it accepts, as written (`Conc`, `WObj`), in the order the
    /// diagnostic for another one lists them.
    pub(crate) optional: &'static [&'static str],
    /// How it is lowered.
    pub(crate) lower: L,
    /// What it does in vworks, in one line.
    pub(crate) doc: &'static str,
}

const fn row<L>(
    name: &'static str,
    args: RangeInclusive<usize>,
    optional: &'static [&'static str],
    lower: L,
    doc: &'static str,
) -> Row<L> {
    Row {
        name,
        args,
        optional,
        lower,
        doc,
    }
}

use InstrLowering::{Lower as I, NoOp, NotRun};

const MOTION_OPTIONS: &[&str] = &[
    "Conc", "ID", "V", "T", "Z", "InPos", "WObj", "TLoad", "NoEOffs", "Corr",
];
const WAIT_OPTIONS: &[&str] = &["MaxTime", "TimeFlag"];
const INTERRUPT_OPTIONS: &[&str] = &["Single", "SingleSafe"];
const INTERRUPTS_HELD: &str = "IDisable holds every interrupt of the task back until IEnable, then runs them; put the interrupts to sleep one by one with ISleep and wake them with IWatch (which discards, not holds, what happens meanwhile)";

/// Every instruction the front-end knows, in docs/rapid.md's order.
pub(crate) const INSTRUCTIONS: &[Row<InstrLowering>] = &[
    row(
        "Incr",
        1..=1,
        &[],
        I(|t, c, out| t.step(c, out)),
        "x := x + 1 on a num",
    ),
    row(
        "Decr",
        1..=1,
        &[],
        I(|t, c, out| t.step(c, out)),
        "x := x - 1 on a num",
    ),
    row(
        "Add",
        2..=2,
        &[],
        I(|t, c, out| t.step(c, out)),
        "x := x + e on a num",
    ),
    row(
        "WaitTime",
        1..=1,
        &["InPos"],
        I(|t, c, out| t.wait_time(c, out)),
        "delay t s",
    ),
    row(
        "WaitUntil",
        1..=1,
        &["InPos", "MaxTime", "TimeFlag", "PollRate"],
        I(|t, c, out| t.wait_until(c, out)),
        "wait_until c, polled every \\PollRate from the wait's start",
    ),
    row(
        "TPWrite",
        1..=1,
        &["Num", "Dnum", "Bool", "Pos", "Orient"],
        I(|t, c, out| t.tp_write(c, out)),
        "log the text and the value",
    ),
    row(
        "ErrWrite",
        2..=6,
        &["W", "I", "RL2", "RL3", "RL4"],
        I(|t, c, out| t.err_write(c, out)),
        "log \"ErrWrite: header reason …\"",
    ),
    row(
        "Stop",
        0..=0,
        &["NoRegain", "AllMoveTasks"],
        I(|t, c, out| t.stop(c, out)),
        "the program ends",
    ),
    row(
        "Break",
        0..=0,
        &["NoRegain", "AllMoveTasks"],
        I(|t, c, out| t.stop(c, out)),
        "the program ends",
    ),
    row(
        "ConfJ",
        0..=usize::MAX,
        &[],
        NoOp,
        "accepted; the IK keeps the configuration",
    ),
    row(
        "ConfL",
        0..=usize::MAX,
        &[],
        NoOp,
        "accepted; the IK keeps the configuration",
    ),
    row(
        "SingArea",
        0..=usize::MAX,
        &[],
        NoOp,
        "accepted; nothing to simulate",
    ),
    row(
        "TPErase",
        0..=usize::MAX,
        &[],
        NoOp,
        "accepted; nothing to simulate",
    ),
    row(
        "PathResol",
        0..=usize::MAX,
        &[],
        NoOp,
        "accepted; nothing to simulate",
    ),
    row(
        "GripLoad",
        1..=1,
        &[],
        I(|t, c, out| t.grip_load(c, out)),
        "grip the part the loaddata names; load0 releases it",
    ),
    row(
        "WaitRob",
        0..=0,
        &["InPos", "ZeroSpeed"],
        I(|t, c, out| t.wait_rob(c, out)),
        "wait until the robot stands at its point",
    ),
    row(
        "BookErrNo",
        1..=1,
        &[],
        I(|t, c, out| t.book_errno(c, out)),
        "an errnum gets an error number of its own for RAISE",
    ),
    row(
        "ClkReset",
        1..=1,
        &[],
        I(|t, c, out| t.clock(c, out)),
        "a clock to zero (a running clock runs on)",
    ),
    row(
        "ClkStart",
        1..=1,
        &[],
        I(|t, c, out| t.clock(c, out)),
        "a clock runs from the simulated time now",
    ),
    row(
        "ClkStop",
        1..=1,
        &[],
        I(|t, c, out| t.clock(c, out)),
        "a clock stops, keeping its time",
    ),
    row(
        "MoveL",
        4..=4,
        MOTION_OPTIONS,
        I(|t, c, out| t.motion(c, out)),
        "move_l to a robtarget",
    ),
    row(
        "MoveC",
        5..=5,
        MOTION_OPTIONS,
        I(|t, c, out| t.motion(c, out)),
        "move_c through a via point",
    ),
    row(
        "MoveJ",
        4..=4,
        MOTION_OPTIONS,
        I(|t, c, out| t.motion(c, out)),
        "move_j to a robtarget",
    ),
    row(
        "MoveAbsJ",
        4..=4,
        MOTION_OPTIONS,
        I(|t, c, out| t.motion(c, out)),
        "move_j to a jointtarget",
    ),
    row(
        "SetDO",
        2..=2,
        &["SDelay", "Sync"],
        I(|t, c, out| t.set_signal(c, out)),
        "s = v (a set event)",
    ),
    row(
        "SetGO",
        2..=2,
        &["SDelay", "Sync"],
        I(|t, c, out| t.set_signal(c, out)),
        "s = v (a set event)",
    ),
    row(
        "Set",
        1..=1,
        &[],
        I(|t, c, out| t.set_reset(c, out)),
        "s = 1 on a digital output",
    ),
    row(
        "Reset",
        1..=1,
        &[],
        I(|t, c, out| t.set_reset(c, out)),
        "s = 0 on a digital output",
    ),
    row(
        "PulseDO",
        1..=1,
        &["High", "PLength"],
        I(|t, c, out| t.pulse_do(c, out)),
        "pulse s for t (0.2 s by default)",
    ),
    row(
        "WaitDI",
        2..=2,
        WAIT_OPTIONS,
        I(|t, c, out| t.wait_signal(c, out)),
        "wait_until s == v",
    ),
    row(
        "WaitDO",
        2..=2,
        WAIT_OPTIONS,
        I(|t, c, out| t.wait_signal(c, out)),
        "wait_until s == v",
    ),
    row(
        "WaitGI",
        2..=2,
        WAIT_OPTIONS,
        I(|t, c, out| t.wait_signal(c, out)),
        "wait_until s == v",
    ),
    row(
        "WaitGO",
        2..=2,
        WAIT_OPTIONS,
        I(|t, c, out| t.wait_signal(c, out)),
        "wait_until s == v",
    ),
    row(
        "ISignalDI",
        3..=3,
        INTERRUPT_OPTIONS,
        I(|t, c, out| t.interrupt_on_signal(c, out)),
        "when s == v do trap()",
    ),
    row(
        "ISignalDO",
        3..=3,
        INTERRUPT_OPTIONS,
        I(|t, c, out| t.interrupt_on_signal(c, out)),
        "when s == v do trap()",
    ),
    row(
        "ISignalGI",
        3..=3,
        INTERRUPT_OPTIONS,
        I(|t, c, out| t.interrupt_on_signal(c, out)),
        "when s == v do trap()",
    ),
    row(
        "ISignalGO",
        3..=3,
        INTERRUPT_OPTIONS,
        I(|t, c, out| t.interrupt_on_signal(c, out)),
        "when s == v do trap()",
    ),
    row(
        "ITimer",
        2..=2,
        INTERRUPT_OPTIONS,
        I(|t, c, out| t.interrupt_timer(c, out)),
        "when every t s do trap() (\\Single: after)",
    ),
    row(
        "IDelete",
        1..=1,
        &[],
        I(|t, c, out| t.interrupt_off(c, out)),
        "disable trap",
    ),
    row(
        "ISleep",
        1..=1,
        &[],
        I(|t, c, out| t.interrupt_off(c, out)),
        "disable trap",
    ),
    row(
        "IWatch",
        1..=1,
        &[],
        I(|t, c, out| t.interrupt_watch(c, out)),
        "disable trap, then the task's one order of the interrupt again",
    ),
    row(
        "IEnable",
        0..=usize::MAX,
        &[],
        NotRun(INTERRUPTS_HELD),
        "E0300",
    ),
    row(
        "IDisable",
        0..=usize::MAX,
        &[],
        NotRun(INTERRUPTS_HELD),
        "E0300",
    ),
    row(
        "WaitSyncTask",
        2..=2,
        &["InPos", "TimeOut"],
        I(|t, c, out| t.wait_sync_task(c, out)),
        "sync s with the tasks of the list",
    ),
];

use FuncLowering::Lower as F;

/// Every function the front-end knows, in docs/rapid.md's order.
pub(crate) const FUNCTIONS: &[Row<FuncLowering>] = &[
    row(
        "Offs",
        4..=4,
        &[],
        F(|t, c| t.offs(c)),
        "offset(p, x mm, y mm, z mm)",
    ),
    row(
        "RelTool",
        4..=4,
        &["Rx", "Ry", "Rz"],
        F(|t, c| t.rel_tool(c)),
        "tool_offset, then rotations about the tool's axes",
    ),
    row(
        "PoseMult",
        2..=2,
        &[],
        F(|t, c| t.pose_op(c)),
        "pose_mul(a, b)",
    ),
    row("PoseInv", 1..=1, &[], F(|t, c| t.pose_op(c)), "pose_inv(p)"),
    row(
        "CRobT",
        0..=0,
        &["Tool", "WObj", "TaskRef", "TaskName"],
        F(|t, c| t.c_rob_t(c)),
        "current_pose(), of a tool, in a work object",
    ),
    row(
        "CPos",
        0..=0,
        &["Tool", "WObj"],
        F(|t, c| t.c_pos(c)),
        "current_pose()'s position",
    ),
    row(
        "CJointT",
        0..=0,
        &["TaskRef", "TaskName"],
        F(|t, c| t.c_joint_t(c)),
        "current_joints()",
    ),
    row("Abs", 1..=1, &[], F(|t, c| t.num_function(c)), "abs"),
    row("Sqrt", 1..=1, &[], F(|t, c| t.num_function(c)), "sqrt"),
    row("Sin", 1..=1, &[], F(|t, c| t.trig(c)), "sin of degrees"),
    row("Cos", 1..=1, &[], F(|t, c| t.trig(c)), "cos of degrees"),
    row(
        "Tan",
        1..=1,
        &[],
        F(|t, c| t.trig(c)),
        "sin / cos of degrees",
    ),
    row("ATan2", 2..=2, &[], F(|t, c| t.arc(c)), "atan2 in degrees"),
    row(
        "ATan",
        1..=1,
        &[],
        F(|t, c| t.arc(c)),
        "atan2(x, 1) in degrees",
    ),
    row(
        "ASin",
        1..=1,
        &[],
        F(|t, c| t.arc(c)),
        "atan2(x, sqrt(1 - x²)) in degrees",
    ),
    row(
        "ACos",
        1..=1,
        &[],
        F(|t, c| t.arc(c)),
        "atan2(sqrt(1 - x²), x) in degrees",
    ),
    row(
        "Round",
        1..=1,
        &["Dec"],
        F(|t, c| t.round_trunc(c)),
        "half away from zero",
    ),
    row(
        "Trunc",
        1..=1,
        &["Dec"],
        F(|t, c| t.round_trunc(c)),
        "toward zero",
    ),
    row(
        "OrientZYX",
        3..=3,
        &[],
        F(|t, c| t.orient_zyx(c)),
        "an orient, R = Rz·Ry·Rx",
    ),
    row(
        "Dim",
        2..=2,
        &[],
        F(|t, c| t.dim(c)),
        "an array's length (one dimension)",
    ),
    row(
        "DInput",
        1..=1,
        &[],
        F(|t, c| t.io_function(c)),
        "a digital input's value",
    ),
    row(
        "DOutput",
        1..=1,
        &[],
        F(|t, c| t.io_function(c)),
        "a digital output's value",
    ),
    row(
        "GInput",
        1..=1,
        &[],
        F(|t, c| t.io_function(c)),
        "a group input's value",
    ),
    row(
        "GOutput",
        1..=1,
        &[],
        F(|t, c| t.io_function(c)),
        "a group output's value",
    ),
    row(
        "TestDI",
        1..=1,
        &[],
        F(|t, c| t.io_function(c)),
        "a digital input is 1",
    ),
    row(
        "ClkRead",
        1..=1,
        &["HighRes"],
        F(|t, c| t.clock_read(c)),
        "a clock's time in seconds",
    ),
    row(
        "RobOS",
        0..=0,
        &[],
        F(|_, c| {
            Some(Val::one(
                Ty::Bool,
                b::expr(w::ExprKind::Bool(false), c.span),
            ))
        }),
        "FALSE: vworks is not a real controller (as on a virtual one)",
    ),
    row(
        "Present",
        1..=1,
        &[],
        F(|t, c| t.present(c)),
        "whether an optional parameter was given",
    ),
    row(
        "NumToStr",
        2..=2,
        &["Exp"],
        F(|t, c| t.string_function(c)),
        "a num as text, rounded to the decimals given",
    ),
    row(
        "ValToStr",
        1..=1,
        &[],
        F(|t, c| t.val_to_str(c)),
        "a num or bool as text",
    ),
    row(
        "StrLen",
        1..=1,
        &[],
        F(|t, c| t.string_function(c)),
        "a string's length in characters",
    ),
    row(
        "StrPart",
        3..=3,
        &[],
        F(|t, c| t.string_function(c)),
        "a part of a string",
    ),
    row(
        "StrFind",
        3..=3,
        &["NotInSet"],
        F(|t, c| t.string_function(c)),
        "the position of the first character in (not in) a set",
    ),
    row(
        "StrMatch",
        3..=3,
        &[],
        F(|t, c| t.string_function(c)),
        "the position of a pattern",
    ),
    row(
        "StrMemb",
        3..=3,
        &[],
        F(|t, c| t.string_function(c)),
        "whether a character is in a set",
    ),
    row(
        "StrMap",
        3..=3,
        &[],
        F(|t, c| t.string_function(c)),
        "a string with characters mapped",
    ),
    row(
        "StrToVal",
        2..=2,
        &[],
        F(|t, c| t.str_to_val_here(c)),
        "`ok := StrToVal(text, x);`: the num a text writes",
    ),
];

/// The row named `key` (any case).
pub(crate) fn find<L>(rows: &'static [Row<L>], key: &str) -> Option<&'static Row<L>> {
    rows.iter().find(|r| r.name.eq_ignore_ascii_case(key))
}

impl Tr<'_> {
    /// `args` checked against `row` (E0013, E0301): the call, or `None` after a
    /// diagnostic.
    fn checked<'a, L>(
        &mut self,
        row: &Row<L>,
        key: &'a str,
        name: &'a r::Name,
        args: &'a [Arg],
        span: Span,
    ) -> Option<Call<'a>> {
        let (pos, opts) = self.split_args(name, args, row.args.clone(), row.optional, span)?;
        Some(Call {
            key,
            name,
            span,
            pos,
            opts,
        })
    }

    /// A built-in instruction's statements onto `out`; false if `key` names none.
    pub(crate) fn instruction(
        &mut self,
        key: &str,
        name: &r::Name,
        args: &[Arg],
        span: Span,
        out: &mut Vec<w::Stmt>,
    ) -> bool {
        let Some(row) = find(INSTRUCTIONS, key) else {
            return false;
        };
        match row.lower {
            NoOp => {}
            NotRun(help) => {
                self.unsupported(&format!("`{}`", name.text), name.span, help);
            }
            I(lower) => {
                if let Some(call) = self.checked(row, key, name, args, span) {
                    lower(self, &call, out);
                }
            }
        }
        true
    }

    /// A built-in function's value; `None` if `key` names none (a user FUNC, or unknown),
    /// `Some(None)` after a diagnostic.
    pub(crate) fn builtin_function(
        &mut self,
        key: &str,
        name: &r::Name,
        args: &[Arg],
        span: Span,
    ) -> Option<Option<Val>> {
        let row = find(FUNCTIONS, key)?;
        let F(lower) = row.lower;
        Some(
            self.checked(row, key, name, args, span)
                .and_then(|call| lower(self, &call)),
        )
    }
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used, clippy::expect_used)]
    use super::*;

    const DOC: &str = include_str!("../../../../../docs/rapid.md");

    /// The sections of docs/rapid.md from `first` up to (not including) `end`.
    fn sections(first: &str, end: &str) -> &'static str {
        let from = DOC.find(first).expect("docs/rapid.md has the section");
        let to = DOC[from..].find(end).map_or(DOC.len(), |k| from + k);
        &DOC[from..to]
    }

    /// The names a table's first column calls (`MoveL p, v, z, tool;` → `MoveL`): every
    /// code span's first word written as RAPID writes a routine (a capital first, and a
    /// lower-case letter: not `IF`, `CONNECT`, `x := e;`, `\V:=mm/s`).
    fn called(section: &str) -> Vec<&str> {
        let mut names = Vec::new();
        for line in section.lines().filter(|l| l.starts_with("| `")) {
            let first = line.split(" | ").next().unwrap_or("");
            for code in first.split('`').skip(1).step_by(2) {
                let word: &str = code
                    .split(|c: char| !c.is_ascii_alphanumeric())
                    .next()
                    .unwrap_or("");
                if word.starts_with(|c: char| c.is_ascii_uppercase())
                    && word.contains(|c: char| c.is_ascii_lowercase())
                {
                    names.push(word);
                }
            }
        }
        names
    }

    /// Whether `doc` writes `name` as a call: `` `Name`` then a space, `(`, `;`, `` ` ``
    /// or `\`.
    fn written(doc: &str, name: &str) -> bool {
        doc.match_indices(&format!("`{name}")).any(|(i, m)| {
            doc[i + m.len()..]
                .chars()
                .next()
                .is_some_and(|c| matches!(c, ' ' | '(' | ';' | '`' | '\\' | ','))
        })
    }

    /// docs/rapid.md and the table say the same: every instruction and function vworks
    /// runs is in the reference with every optional argument it accepts, and the
    /// reference's tables call no instruction or function the table does not have.
    #[test]
    fn the_rapid_reference_lists_every_instruction_as_the_table_does() {
        let statements = sections("## Statements and instructions", "## Diagnostics");
        let functions = sections(
            "## Expressions and functions",
            "## Statements and instructions",
        );
        for r in INSTRUCTIONS {
            if matches!(r.lower, NotRun(_)) {
                // Not run: the reference names it as E0300.
                assert!(
                    written(DOC, r.name),
                    "docs/rapid.md does not name `{}`",
                    r.name
                );
                continue;
            }
            assert!(
                written(DOC, r.name),
                "docs/rapid.md does not list the instruction `{}`",
                r.name
            );
        }
        for r in FUNCTIONS {
            assert!(
                written(functions, r.name),
                "docs/rapid.md's functions do not list `{}`",
                r.name
            );
        }
        // Every optional argument an instruction or function accepts is documented.
        let optional = INSTRUCTIONS
            .iter()
            .flat_map(|r| r.optional.iter().map(move |o| (r.name, *o)))
            .chain(
                FUNCTIONS
                    .iter()
                    .flat_map(|r| r.optional.iter().map(move |o| (r.name, *o))),
            );
        let lower_doc = DOC.to_ascii_lowercase();
        for (name, o) in optional {
            let o_lower = format!("\\{}", o.to_ascii_lowercase());
            assert!(
                lower_doc.match_indices(&o_lower).any(|(i, m)| {
                    !lower_doc[i + m.len()..].starts_with(|c: char| c.is_ascii_alphanumeric())
                }),
                "docs/rapid.md does not say what `{name}`'s `\\{o}` does"
            );
        }
        // And the reference calls nothing the table does not have.
        for name in called(statements).into_iter().chain(called(functions)) {
            assert!(
                find(INSTRUCTIONS, name).is_some() || find(FUNCTIONS, name).is_some(),
                "docs/rapid.md lists `{name}`, which is in neither table"
            );
        }
        assert!(called(statements).len() >= 35 && called(functions).len() >= 25);
    }

    /// Every row's name is its own, and the argument counts are ranges.
    #[test]
    fn each_name_has_one_row() {
        for rows in [
            INSTRUCTIONS
                .iter()
                .map(|r| (r.name, &r.args))
                .collect::<Vec<_>>(),
            FUNCTIONS.iter().map(|r| (r.name, &r.args)).collect(),
        ] {
            for (k, (name, args)) in rows.iter().enumerate() {
                assert!(args.start() <= args.end(), "{name}");
                assert!(
                    rows[..k].iter().all(|(n, _)| !n.eq_ignore_ascii_case(name)),
                    "`{name}` twice"
                );
            }
        }
        assert!(find(INSTRUCTIONS, "movel").is_some() && find(FUNCTIONS, "CROBT").is_some());
    }
}
