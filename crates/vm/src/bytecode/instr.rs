//! The instruction set: one table gives every instruction its opcode, name and operands.
//!
//! The machine is a stack machine over untyped 64-bit slots; instructions are typed (the
//! compiler knows every type), so the interpreter never inspects a tag. A value takes
//! [`Type::width`](crate::Type::width) slots. Jump targets are instruction indices relative
//! to the start of the enclosing procedure. `docs/bytecode.md` documents each row; a test
//! keeps that table and this one in step.

use super::{Module, ProcInfo};
use crate::types::{MAX_AXES, POSE_WIDTH};

/// A comparison, the operand of `CmpI`, `CmpF` and `CmpB`.
#[derive(Clone, Copy, PartialEq, Eq, Debug, Hash)]
pub enum Cmp {
    /// `==`
    Eq = 0,
    /// `!=`
    Ne = 1,
    /// `<`
    Lt = 2,
    /// `<=`
    Le = 3,
    /// `>`
    Gt = 4,
    /// `>=`
    Ge = 5,
}

impl Cmp {
    /// Whether the comparison holds for two operands ordered `o` (the interpreter and the
    /// compiler's constant folding both ask this).
    pub fn holds(self, o: std::cmp::Ordering) -> bool {
        use std::cmp::Ordering::*;
        match self {
            Cmp::Eq => o == Equal,
            Cmp::Ne => o != Equal,
            Cmp::Lt => o == Less,
            Cmp::Le => o != Greater,
            Cmp::Gt => o == Greater,
            Cmp::Ge => o != Less,
        }
    }

    /// The operator as written in WSL.
    pub fn symbol(self) -> &'static str {
        match self {
            Cmp::Eq => "==",
            Cmp::Ne => "!=",
            Cmp::Lt => "<",
            Cmp::Le => "<=",
            Cmp::Gt => ">",
            Cmp::Ge => ">=",
        }
    }

    fn from_u8(b: u8) -> Option<Cmp> {
        Some(match b {
            0 => Cmp::Eq,
            1 => Cmp::Ne,
            2 => Cmp::Lt,
            3 => Cmp::Le,
            4 => Cmp::Gt,
            5 => Cmp::Ge,
            _ => return None,
        })
    }
}

/// The operand of the motion instructions: what the stack holds for them.
#[derive(Clone, Copy, PartialEq, Eq, Debug, Hash, Default)]
pub struct MoveFlags(pub u16);

impl MoveFlags {
    /// The target is a `joints` value (else a `pose`).
    pub const TARGET_JOINTS: u16 = 1;
    /// The `via` point of `move_c` is a `joints` value (else a `pose`).
    pub const VIA_JOINTS: u16 = 2;
    /// A `speed` operand is on the stack.
    pub const SPEED: u16 = 4;
    /// An `accel` operand is on the stack.
    pub const ACCEL: u16 = 8;
    /// A `zone` operand (radius in m; 0 for `zone fine`) is on the stack.
    pub const ZONE: u16 = 16;
    /// A `tool` operand (a pose: the TCP in the tool link's frame) is on the stack, on top;
    /// it becomes the robot's TCP from this motion on.
    pub const TOOL: u16 = 32;
    /// The `speed` operand of a `move_j` is a TCP speed (m/s), not a ratio.
    pub const TCP_SPEED: u16 = 64;
    /// An `orient` operand (rad/s: how fast a `move_l`/`move_c` may turn the TCP) is on the
    /// stack, above `accel`.
    pub const ORIENT: u16 = 128;
    /// A `duration` operand (s: how long the motion takes, instead of its speed) is on
    /// the stack, on top (above `tool`).
    pub const DURATION: u16 = 256;
    /// An orientation zone follows the `zone` operand, above it: its radius (m, a TCP
    /// distance from the point, RAPID's `pzone_ori`) and its angle (rad, `zone_ori`; π
    /// bounds nothing). Only with `ZONE`.
    pub const ZONE_ORI: u16 = 512;
    /// Every flag.
    pub const ALL: u16 = 1023;

    /// True if every bit of `bit` is set.
    pub fn has(self, bit: u16) -> bool {
        self.0 & bit == bit
    }
}

/// An operand type of an instruction: how it is written to and read from `.wslb` bytes.
pub(crate) trait Operand: Sized + Copy {
    fn write(self, out: &mut Vec<u8>);
    fn read(r: &mut super::encode::Reader<'_>) -> Result<Self, super::LoadError>;
}

macro_rules! operand_le {
    ($($t:ty),*) => {$(
        impl Operand for $t {
            fn write(self, out: &mut Vec<u8>) {
                out.extend_from_slice(&self.to_le_bytes());
            }
            fn read(r: &mut super::encode::Reader<'_>) -> Result<Self, super::LoadError> {
                Ok(<$t>::from_le_bytes(r.array()?))
            }
        }
    )*};
}
operand_le!(u8, u32, i64, f64);

impl Operand for bool {
    fn write(self, out: &mut Vec<u8>) {
        out.push(u8::from(self));
    }
    fn read(r: &mut super::encode::Reader<'_>) -> Result<Self, super::LoadError> {
        match r.u8()? {
            0 => Ok(false),
            1 => Ok(true),
            b => Err(r.error(format!("a boolean operand must be 0 or 1, found {b}"))),
        }
    }
}

impl Operand for Cmp {
    fn write(self, out: &mut Vec<u8>) {
        out.push(self as u8);
    }
    fn read(r: &mut super::encode::Reader<'_>) -> Result<Self, super::LoadError> {
        let b = r.u8()?;
        Cmp::from_u8(b).ok_or_else(|| r.error(format!("unknown comparison code {b}")))
    }
}

impl Operand for MoveFlags {
    fn write(self, out: &mut Vec<u8>) {
        out.extend_from_slice(&self.0.to_le_bytes());
    }
    fn read(r: &mut super::encode::Reader<'_>) -> Result<Self, super::LoadError> {
        let b = r.u16()?;
        if b & !MoveFlags::ALL != 0 {
            return Err(r.error(format!(
                "motion flags 0x{b:04x} set bits that mean nothing (0x{:04x} are defined)",
                MoveFlags::ALL
            )));
        }
        let f = MoveFlags(b);
        if f.has(MoveFlags::ZONE_ORI) && !f.has(MoveFlags::ZONE) {
            return Err(r.error(format!(
                "motion flags 0x{b:04x} give an orientation zone without a zone"
            )));
        }
        Ok(f)
    }
}

macro_rules! instruction_set {
    ($(
        $(#[doc = $doc:literal])*
        $op:literal $name:ident $( ( $($field:ident : $ty:ty),+ ) )? ;
    )*) => {
        /// One instruction. See `docs/bytecode.md` for the stack effect of each.
        #[derive(Clone, Copy, PartialEq, Debug)]
        pub enum Instr {
            $(
                $(#[doc = $doc])*
                $name $( ( $($ty),+ ) )?,
            )*
        }

        impl Instr {
            /// Every instruction name, in opcode order.
            pub const NAMES: &'static [&'static str] = &[$(stringify!($name)),*];

            /// The opcode byte.
            pub fn opcode(&self) -> u8 {
                match self {
                    $( Instr::$name $( ( $(instruction_set!(@ignore $field)),+ ) )? => $op, )*
                }
            }

            /// The instruction's name as the disassembler prints it.
            pub fn name(&self) -> &'static str {
                match self {
                    $( Instr::$name $( ( $(instruction_set!(@ignore $field)),+ ) )? => stringify!($name), )*
                }
            }

            /// Appends the encoded instruction (opcode, then operands little-endian).
            pub fn encode(&self, out: &mut Vec<u8>) {
                match *self {
                    $( Instr::$name $( ( $($field),+ ) )? => {
                        out.push($op);
                        $( $( Operand::write($field, out); )+ )?
                    } )*
                }
            }

            pub(crate) fn decode(r: &mut super::encode::Reader<'_>) -> Result<Instr, super::LoadError> {
                let op = r.u8()?;
                Ok(match op {
                    $( $op => Instr::$name $( ( $( <$ty as Operand>::read(r)? ),+ ) )?, )*
                    _ => return Err(r.error(format!("unknown opcode {op:#04x}"))),
                })
            }
        }
    };
    (@ignore $f:ident) => { _ };
}

instruction_set! {
    /// Does nothing.
    0x00 Nop;
    /// Pushes a bool.
    0x01 PushBool(b: bool);
    /// Pushes an int.
    0x02 PushInt(i: i64);
    /// Pushes a num (SI units).
    0x03 PushNum(x: f64);
    /// Pushes constant-pool entry `k` (a pose or joints constant takes several slots).
    0x04 PushConst(k: u32);
    /// Discards the top `n` slots.
    0x05 Pop(n: u8);
    /// Pushes local slot `s`.
    0x10 LoadLocal(s: u32);
    /// Pops into local slot `s`.
    0x11 StoreLocal(s: u32);
    /// Pushes `n` slots starting at local slot `s`.
    0x12 LoadLocalN(s: u32, n: u8);
    /// Pops `n` slots into local slots `s..s+n`.
    0x13 StoreLocalN(s: u32, n: u8);
    /// Pops an index and a num; stores the num as axis `index` of the joints at local `s`.
    0x14 StoreLocalJoint(s: u32);
    /// Pushes module-variable slot `s`.
    0x18 LoadVar(s: u32);
    /// Pops into module-variable slot `s`.
    0x19 StoreVar(s: u32);
    /// Pushes `n` module-variable slots from `s`.
    0x1a LoadVarN(s: u32, n: u8);
    /// Pops `n` slots into module-variable slots `s..s+n`.
    0x1b StoreVarN(s: u32, n: u8);
    /// Pops an index and a num; stores axis `index` of the joints in module variable `s`.
    0x1c StoreVarJoint(s: u32);
    /// Pushes global `g` (an index into the module's global table).
    0x20 LoadGlobal(g: u32);
    /// EVENT `set`: pops a value and assigns it to global `g`.
    0x21 StoreGlobal(g: u32);
    /// EVENT `set`: pops a time and sets global `g` (an int or a bool) to 1 now and back to 0 that time later, as a controller's I/O ends a pulse: whatever the program does meanwhile, even after it has ended.
    0x22 PulseGlobal(g: u32);
    /// int `a + b` (overflow is a run-time error).
    0x30 AddI;
    /// int `a - b`.
    0x31 SubI;
    /// int `a * b`.
    0x32 MulI;
    /// int `a / b`, truncating toward zero (division by zero is a run-time error).
    0x33 DivI;
    /// int `a mod b`, with the sign of `a`.
    0x34 ModI;
    /// int `-a`.
    0x35 NegI;
    /// num `a + b`.
    0x38 AddF;
    /// num `a - b`.
    0x39 SubF;
    /// num `a * b`.
    0x3a MulF;
    /// num `a / b` (division by zero is a run-time error).
    0x3b DivF;
    /// num `-a`.
    0x3c NegF;
    /// Converts an int to a num.
    0x3d IntToNum;
    /// Converts a num to an int, truncating toward zero (out of range is a run-time error).
    0x3e NumToInt;
    /// Converts the int just below the top slot to a num (the top slot stays).
    0x3f IntToNumBelow;
    /// Compares two ints, pushes a bool.
    0x40 CmpI(c: Cmp);
    /// Compares two nums, pushes a bool.
    0x41 CmpF(c: Cmp);
    /// Compares two bools (`==` or `!=`), pushes a bool.
    0x42 CmpB(c: Cmp);
    /// Boolean negation.
    0x43 Not;
    /// int `abs(a)`.
    0x48 AbsI;
    /// num `abs(a)`.
    0x49 AbsF;
    /// int `min(a, b)`.
    0x4a MinI;
    /// int `max(a, b)`.
    0x4b MaxI;
    /// num `min(a, b)`.
    0x4c MinF;
    /// num `max(a, b)`.
    0x4d MaxF;
    /// num `sqrt(a)` (negative is a run-time error).
    0x4e Sqrt;
    /// `sin(a)`.
    0x4f Sin;
    /// `cos(a)`.
    0x50 Cos;
    /// `atan2(y, x)`.
    0x51 Atan2;
    /// Pops text b and text a; pushes a followed by b (RAPID's `+` on strings; a text holds
    /// at most 80 characters: more is a run-time error).
    0x90 TextCat;
    /// Compares two texts character by character, pushes a bool.
    0x91 CmpT(c: Cmp);
    /// Pops a text; pushes its length in characters (a num): `StrLen`.
    0x92 TextLen;
    /// Pops a length, a start position (nums) and a text; pushes that part: `StrPart`
    /// (out of the text is a run-time error).
    0x93 TextPart;
    /// Pops a set (text), a start position and a text; pushes the position of the first
    /// character from the start that is in the set (not in it, if `not_in`), or the length
    /// + 1: `StrFind`.
    0x94 TextFind(not_in: bool);
    /// Pops a pattern (text), a start position and a text; pushes the position of the
    /// pattern from the start, or the length + 1: `StrMatch`.
    0x95 TextMatch;
    /// Pops a set (text), a position and a text; pushes whether that character is in the
    /// set: `StrMemb`.
    0x96 TextMemb;
    /// Pops a to-map, a from-map and a text (texts); pushes the text with each character
    /// of the from-map replaced by the one at its place in the to-map: `StrMap`.
    0x97 TextMap;
    /// Pops a number of decimals and a num; pushes the num rounded to them, as text:
    /// `NumToStr`.
    0x98 NumToText;
    /// Pops a value of kind `k` (0: a bool, 1: a num); pushes it as RAPID's `ValToStr`
    /// writes it (`TRUE`; at most 6 significant digits).
    0x99 ValText(k: u8);
    /// Pops a text; pushes whether it writes a number: `StrToVal`'s result.
    0x9a TextIsNum;
    /// Pops a text; pushes the number it writes, or 0: `StrToVal`'s value.
    0x9b TextNum;
    /// Pops an int, an error's number, and raises it with the message of string `s`: the
    /// error handler of this procedure, or of the nearest caller that has one, runs
    /// (RAPID's `RAISE n`, and the errors the translation raises); with none, the program
    /// stops with the message.
    0x9c Raise(s: u32);
    /// In an error handler: raises its error again where the procedure was called
    /// (RAPID's `RAISE;`).
    0x9d RaiseUp;
    /// In an error handler: runs the statement that failed again (RAPID's `RETRY`; a
    /// fifth retry of one error is ERR_EXCRTYMAX, which stops the program).
    0x9e Retry;
    /// In an error handler: goes on after the statement that failed (RAPID's `TRYNEXT`).
    0x9f TryNext;
    /// Pushes the number of the most recent error raised (an int): RAPID's `ERRNO`.
    0xa0 ErrNo;
    /// Pops `n` nums, pushes a joints value (zero-padded to MAX_AXES slots).
    0x58 MakeJoints(n: u8);
    /// Pops an index and a joints value, pushes that axis's value.
    0x59 JointsGet;
    /// Pops a pose, pushes component `f` (0..=5: x, y, z, rx, ry, rz).
    0x5a PoseGet(f: u8);
    /// Pops dz, dy, dx and a pose; pushes the pose translated in the base frame.
    0x5b Offset;
    /// Pops dz, dy, dx and a pose; pushes the pose translated in its own tool frame.
    0x5c ToolOffset;
    /// Pops pose b and pose a; pushes a · b (b given in the frame a).
    0x5d PoseMul;
    /// Pops a pose; pushes its inverse.
    0x5e PoseInv;
    /// Jumps to instruction `t` of this procedure.
    0x60 Jump(t: u32);
    /// Pops a bool; jumps to `t` if it is false.
    0x61 JumpIfFalse(t: u32);
    /// Pops a bool; jumps to `t` if it is true.
    0x62 JumpIfTrue(t: u32);
    /// Calls procedure `p`: its arguments become the first slots of the new frame.
    0x63 Call(p: u32);
    /// Returns from a procedure (stack empty).
    0x64 Ret;
    /// Returns the value on top of the stack from a function.
    0x65 RetVal;
    /// Pushes the simulated time (s).
    0x68 Now;
    /// Pushes the cycle count (int).
    0x69 Cycle;
    /// Pushes whether the last timed wait expired.
    0x6a TimedOut;
    /// Pushes the robot's current joint values.
    0x6b CurrentJoints;
    /// Pushes the robot's current TCP pose in the base frame.
    0x6c CurrentPose;
    /// Pushes the robot's active tool: its TCP in the tool link's frame (the tool the motion now moving or last moved uses, else the workcell's).
    0x6d CurrentTool;
    /// EVENT `motion_start`: joint move. Pops duration, tool, zone, accel and speed (when flagged), then the target.
    0x70 MoveJ(f: MoveFlags);
    /// EVENT `motion_start`: straight-line move. Pops duration, tool, zone, orient, accel and speed (when flagged), then the target.
    0x71 MoveL(f: MoveFlags);
    /// EVENT `motion_start`: circular move. Pops duration, tool, zone, orient, accel and speed (when flagged), then the target and the via point.
    0x72 MoveC(f: MoveFlags);
    /// EVENT: pops a time; the robot holds still that long.
    0x73 Delay;
    /// EVENT `wait_until` on condition `c`; pops a timeout (time) if `t`.
    0x74 WaitUntil(c: u32, t: bool);
    /// EVENT `wait_until` for the signal named by string `s`; pops a timeout if `t`.
    0x75 WaitSignal(s: u32, t: bool);
    /// EVENT `signal`: sends the signal of signal site `s`.
    0x76 Signal(s: u32);
    /// EVENT `wait_until` at the sync point of sync site `s` (a barrier of named tasks): the robot arrives and waits until every task of its list has arrived as often; pops a timeout if `t`.
    0x82 WaitSync(s: u32, t: bool);
    /// Opens a `parallel` block: the interpreter stops at it so that the machine opens a join group (no event).
    0x77 ParBegin;
    /// EVENT `remote_start`: pops the arguments of remote site `r` and asks its robot to run it.
    0x78 Remote(r: u32);
    /// EVENT: waits until every remote started since the matching `ParBegin` has ended.
    0x79 ParJoin;
    /// EVENT `enable_when`: enables handler `h`; pops its trigger operand (cycles or time) if any.
    0x7a When(h: u32);
    /// EVENT `disable_when`: disables every handler of this robot that calls procedure `p`.
    0x7b Disable(p: u32);
    /// EVENT: attaches the part of part site `s` to the tool.
    0x7c Grip(s: u32);
    /// EVENT: detaches the part of part site `s`.
    0x7d Release(s: u32);
    /// EVENT `log`: pops the values of log format `f` and writes the message.
    0x7e Log(f: u32);
    /// EVENT `error`: pops the values of log format `f` and stops the simulation with it.
    0x7f Fail(f: u32);
    /// EVENT `end`: ends this robot's program.
    0x80 Stop;
    /// EVENT `wait_until` on condition `c`, tested at once and then on a grid of the
    /// popped period from the wait's start (a controller polling it); pops the period, then
    /// a timeout (time) if `t`.
    0x81 WaitPoll(c: u32, t: bool);
}

/// What an instruction does to the operand stack, in slots.
#[derive(Clone, Copy, PartialEq, Eq, Debug)]
pub struct StackEffect {
    /// Slots popped.
    pub pops: u32,
    /// Slots pushed.
    pub pushes: u32,
}

const fn eff(pops: u32, pushes: u32) -> StackEffect {
    StackEffect { pops, pushes }
}

impl Instr {
    /// The stack effect of the instruction inside procedure `proc` of module `m`, or `None`
    /// if an operand refers to something the module does not have.
    pub fn stack_effect(&self, m: &Module, proc: &ProcInfo) -> Option<StackEffect> {
        const J: u32 = MAX_AXES as u32;
        const P: u32 = POSE_WIDTH as u32;
        Some(match *self {
            Instr::Nop | Instr::ParBegin | Instr::ParJoin | Instr::Jump(_) | Instr::Stop => {
                eff(0, 0)
            }
            Instr::Signal(_) | Instr::Disable(_) | Instr::Grip(_) | Instr::Release(_) => eff(0, 0),
            Instr::PushBool(_) | Instr::PushInt(_) | Instr::PushNum(_) => eff(0, 1),
            Instr::PushConst(k) => eff(0, u32::from(m.consts.get(k as usize)?.ty.width())),
            Instr::Pop(n) => eff(u32::from(n), 0),
            Instr::LoadLocal(_) | Instr::LoadVar(_) | Instr::LoadGlobal(_) => eff(0, 1),
            Instr::StoreLocal(_)
            | Instr::StoreVar(_)
            | Instr::StoreGlobal(_)
            | Instr::PulseGlobal(_) => eff(1, 0),
            Instr::LoadLocalN(_, n) | Instr::LoadVarN(_, n) => eff(0, u32::from(n)),
            Instr::StoreLocalN(_, n) | Instr::StoreVarN(_, n) => eff(u32::from(n), 0),
            Instr::StoreLocalJoint(_) | Instr::StoreVarJoint(_) => eff(2, 0),
            Instr::AddI | Instr::SubI | Instr::MulI | Instr::DivI | Instr::ModI => eff(2, 1),
            Instr::AddF | Instr::SubF | Instr::MulF | Instr::DivF => eff(2, 1),
            Instr::CmpI(_) | Instr::CmpF(_) | Instr::CmpB(_) => eff(2, 1),
            Instr::MinI | Instr::MaxI | Instr::MinF | Instr::MaxF | Instr::Atan2 => eff(2, 1),
            Instr::IntToNumBelow => eff(2, 2),
            Instr::NegI | Instr::NegF | Instr::IntToNum | Instr::NumToInt | Instr::Not => eff(1, 1),
            Instr::AbsI | Instr::AbsF | Instr::Sqrt | Instr::Sin | Instr::Cos => eff(1, 1),
            Instr::TextCat | Instr::CmpT(_) | Instr::NumToText => eff(2, 1),
            Instr::TextLen | Instr::ValText(_) | Instr::TextIsNum | Instr::TextNum => eff(1, 1),
            Instr::Raise(_) => eff(1, 0),
            Instr::RaiseUp | Instr::Retry | Instr::TryNext => eff(0, 0),
            Instr::ErrNo => eff(0, 1),
            Instr::TextPart
            | Instr::TextFind(_)
            | Instr::TextMatch
            | Instr::TextMemb
            | Instr::TextMap => eff(3, 1),
            Instr::MakeJoints(n) => eff(u32::from(n), J),
            Instr::JointsGet => eff(J + 1, 1),
            Instr::PoseGet(_) => eff(P, 1),
            Instr::Offset | Instr::ToolOffset => eff(P + 3, P),
            Instr::PoseMul => eff(2 * P, P),
            Instr::PoseInv => eff(P, P),
            Instr::JumpIfFalse(_) | Instr::JumpIfTrue(_) => eff(1, 0),
            Instr::Call(p) => {
                let callee = m.procs.get(p as usize)?;
                eff(
                    callee.param_width(),
                    callee.ret.map_or(0, |t| u32::from(t.width())),
                )
            }
            Instr::Ret => eff(0, 0),
            Instr::RetVal => eff(proc.ret.map_or(0, |t| u32::from(t.width())), 0),
            Instr::Now | Instr::Cycle | Instr::TimedOut => eff(0, 1),
            Instr::CurrentJoints => eff(0, J),
            Instr::CurrentPose | Instr::CurrentTool => eff(0, P),
            Instr::MoveJ(f) | Instr::MoveL(f) | Instr::MoveC(f) => {
                let target = if f.has(MoveFlags::TARGET_JOINTS) {
                    J
                } else {
                    P
                };
                let via = match self {
                    Instr::MoveC(_) if f.has(MoveFlags::VIA_JOINTS) => J,
                    Instr::MoveC(_) => P,
                    _ => 0,
                };
                let extra = u32::from(f.has(MoveFlags::SPEED))
                    + u32::from(f.has(MoveFlags::ACCEL))
                    + u32::from(f.has(MoveFlags::ZONE))
                    + 2 * u32::from(f.has(MoveFlags::ZONE | MoveFlags::ZONE_ORI))
                    + u32::from(f.has(MoveFlags::ORIENT))
                    + u32::from(f.has(MoveFlags::DURATION))
                    + if f.has(MoveFlags::TOOL) { P } else { 0 };
                eff(target + via + extra, 0)
            }
            Instr::Delay => eff(1, 0),
            Instr::WaitUntil(_, t) | Instr::WaitSignal(_, t) | Instr::WaitSync(_, t) => {
                eff(u32::from(t), 0)
            }
            Instr::WaitPoll(_, t) => eff(1 + u32::from(t), 0),
            Instr::Remote(r) => eff(m.remotes.get(r as usize)?.arg_width(), 0),
            Instr::When(h) => eff(
                u32::from(m.handlers.get(h as usize)?.trigger.has_operand()),
                0,
            ),
            Instr::Log(f) | Instr::Fail(f) => eff(m.log_formats.get(f as usize)?.value_width(), 0),
        })
    }

    /// True for the instructions before which the VM stops and hands an event to the SE.
    pub fn is_event(&self) -> bool {
        matches!(
            self,
            Instr::StoreGlobal(_)
                | Instr::PulseGlobal(_)
                | Instr::MoveJ(_)
                | Instr::MoveL(_)
                | Instr::MoveC(_)
                | Instr::Delay
                | Instr::WaitUntil(..)
                | Instr::WaitPoll(..)
                | Instr::WaitSignal(..)
                | Instr::WaitSync(..)
                | Instr::Signal(_)
                | Instr::Remote(_)
                | Instr::ParJoin
                | Instr::When(_)
                | Instr::Disable(_)
                | Instr::Grip(_)
                | Instr::Release(_)
                | Instr::Log(_)
                | Instr::Fail(_)
                | Instr::Stop
        )
    }

    /// True for the instructions that may let simulated time pass (a motion, a delay, a
    /// wait, a grip or release, remote work and its join): `when` handlers, which run in
    /// zero time, may not execute them.
    pub fn takes_time(&self) -> bool {
        matches!(
            self,
            Instr::MoveJ(_)
                | Instr::MoveL(_)
                | Instr::MoveC(_)
                | Instr::Delay
                | Instr::WaitUntil(..)
                | Instr::WaitPoll(..)
                | Instr::WaitSignal(..)
                | Instr::WaitSync(..)
                | Instr::Grip(_)
                | Instr::Release(_)
                | Instr::Remote(_)
                | Instr::ParBegin
                | Instr::ParJoin
        )
    }

    /// True if control never falls through to the next instruction.
    pub fn ends_block(&self) -> bool {
        matches!(
            self,
            Instr::Jump(_)
                | Instr::Ret
                | Instr::RetVal
                | Instr::Stop
                | Instr::Fail(_)
                | Instr::Raise(_)
                | Instr::RaiseUp
                | Instr::Retry
                | Instr::TryNext
        )
    }

    /// The jump target, for the three jump instructions.
    pub fn jump_target(&self) -> Option<u32> {
        match *self {
            Instr::Jump(t) | Instr::JumpIfFalse(t) | Instr::JumpIfTrue(t) => Some(t),
            _ => None,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::Instr;

    #[test]
    fn docs_list_every_instruction() {
        let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../../docs/bytecode.md");
        let doc = std::fs::read_to_string(path).unwrap_or_default();
        assert!(!doc.is_empty(), "docs/bytecode.md is missing");
        let rows: Vec<&str> = doc
            .lines()
            .filter(|l| l.starts_with("| `0x"))
            .filter_map(|l| l.split('`').nth(3))
            .collect();
        assert_eq!(
            rows,
            Instr::NAMES,
            "docs/bytecode.md must list every instruction, in opcode order"
        );
    }
}
