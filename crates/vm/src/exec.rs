//! The interpreter: runs zero-time code of one thread until it reaches an event
//! instruction (or returns from its bottom frame), without allocating per instruction.
//!
//! A [`Thread`] is a stack of frames over one operand stack and one locals area, both
//! reserved up front from the module's verified `max_stack` and `frame_slots`, so pushes
//! never reallocate in steady state. The dispatch loop counts instructions against a
//! budget: an endless zero-time loop becomes a runtime error naming its line instead of a
//! hang. Pure instructions run here; instructions with effects outside the thread (events)
//! stop the loop, leaving `pc` on them.

use crate::bytecode::{Cmp, Instr, Module, ProcInfo, SrcPos};
use crate::math;
use crate::texts::{self, Texts};

/// One activation record.
#[derive(Clone, Copy, Debug)]
pub struct Frame {
    /// The procedure.
    pub proc: u32,
    /// Where to continue in the caller (absolute pc).
    pub ret_pc: u32,
    /// First slot of this frame in the locals area.
    pub base: u32,
    /// The operand stack's height when the frame started (its arguments taken).
    pub stack_base: u32,
    /// While its error handler runs: the instruction that failed (absolute), else
    /// `u32::MAX`.
    pub failed_at: u32,
    /// The `Retry`s of the statement last retried (`retried`), counted until another
    /// statement fails.
    pub retries: u8,
    /// The statement (its first instruction, relative) the handler last retried, else
    /// `u32::MAX`.
    pub retried: u32,
}

impl Frame {
    fn new(proc: u32, ret_pc: u32, base: u32, stack_base: u32) -> Frame {
        Frame {
            proc,
            ret_pc,
            base,
            stack_base,
            failed_at: u32::MAX,
            retries: 0,
            retried: u32::MAX,
        }
    }
}

/// How many times an error handler may `Retry` one error (RAPID's default): more is the
/// error ERR_EXCRTYMAX, which no handler catches.
pub const MAX_RETRIES: u8 = 4;

/// An execution context: the main program, a handler, or a remote request.
#[derive(Clone, Debug, Default)]
pub struct Thread {
    /// Frames, innermost last.
    pub frames: Vec<Frame>,
    /// Operand stack.
    pub stack: Vec<u64>,
    /// Locals of all frames.
    pub locals: Vec<u64>,
    /// Absolute pc of the next instruction.
    pub pc: u32,
    /// The number of the most recent error raised (RAPID's `ERRNO`), 0 before any.
    pub errno: i64,
}

/// Why the interpreter stopped.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Stop {
    /// At an event instruction (not executed; `pc` points at it).
    Event(Instr),
    /// The bottom frame returned: the thread is finished.
    Finished,
}

/// A runtime error, with the position of the instruction that caused it.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[error("{message}")]
pub struct RuntimeError {
    /// What went wrong, in plain words.
    pub message: String,
    /// Absolute pc of the offending instruction.
    pub pc: u32,
    /// Its source position.
    pub pos: SrcPos,
    /// The error's number, if an error handler may catch it (`Raise`, RAPID's errors);
    /// `None`: it stops the program.
    pub errno: Option<i64>,
}

/// What zero-time code may read from the robot and the cell.
pub trait Reader {
    /// The value of module global `g` (slot bits), read by the instruction at `pc`.
    fn global(&self, g: u32, pc: u32) -> u64;
    /// Simulated time (s).
    fn now_s(&self) -> f64;
    /// Cycle count.
    fn cycle(&self) -> i64;
    /// Whether the last timed wait expired.
    fn timed_out(&self) -> bool;
    /// The robot's joints now.
    fn joints(&self) -> [f64; crate::MAX_AXES];
    /// The robot's TCP now: x, y, z, rx, ry, rz.
    fn tcp(&self) -> [f64; 6];
    /// The robot's active tool now (its TCP in the tool link's frame): x, y, z, rx, ry, rz.
    fn tool(&self) -> [f64; 6];
    /// The robot's number of axes.
    fn axes(&self) -> usize;
}

#[inline]
fn f(x: u64) -> f64 {
    f64::from_bits(x)
}

#[inline]
fn b(x: f64) -> u64 {
    x.to_bits()
}

impl Thread {
    /// A thread about to run procedure `proc` whose arguments are `args` (slot values).
    pub fn start(&mut self, m: &Module, proc: u32, args: &[u64]) {
        self.frames.clear();
        self.stack.clear();
        self.locals.clear();
        let p = &m.procs[proc as usize];
        self.locals.extend_from_slice(args);
        self.locals.resize(p.frame_slots as usize, 0);
        self.frames.push(Frame::new(proc, u32::MAX, 0, 0));
        self.pc = p.code_start;
        self.errno = 0;
    }

    /// Reserves room for the deepest stack and frames a run may need.
    pub fn reserve(&mut self, m: &Module, depth: usize) {
        let stack = m
            .procs
            .iter()
            .map(|p| p.max_stack as usize)
            .max()
            .unwrap_or(0);
        let frame = m
            .procs
            .iter()
            .map(|p| p.frame_slots as usize)
            .max()
            .unwrap_or(0);
        self.stack.reserve(stack * depth.min(64) + 64);
        self.locals.reserve(frame * depth.min(64) + 64);
        self.frames.reserve(depth.min(1024));
    }

    #[inline]
    fn pop(&mut self) -> u64 {
        self.stack.pop().unwrap_or(0)
    }

    /// Pops `n` slots into the front of `out`.
    pub fn pop_n(&mut self, n: usize, out: &mut [u64]) {
        let at = self.stack.len().saturating_sub(n);
        for (o, v) in out.iter_mut().zip(self.stack.drain(at..)) {
            *o = v;
        }
    }

    fn frame(&self) -> Frame {
        self.frames
            .last()
            .copied()
            .unwrap_or(Frame::new(0, u32::MAX, 0, 0))
    }

    /// Runs until an event instruction or the end of the bottom frame. `budget` counts
    /// down per instruction; at zero the run fails with the line of the loop. An error
    /// with a number goes to the error handler of the procedure it happened in, or of the
    /// nearest caller that has one (the frames above it are left), and the run goes on
    /// there; an error inside an error handler, or one no handler takes, is the result.
    #[allow(clippy::too_many_arguments)]
    pub fn run(
        &mut self,
        m: &Module,
        r: &dyn Reader,
        vars: &mut [u64],
        texts: &mut Texts,
        budget: &mut u64,
        max_depth: usize,
    ) -> Result<Stop, RuntimeError> {
        loop {
            match self.run_segment(m, r, vars, texts, budget, max_depth) {
                Err(e) if e.errno.is_some() && *budget > 0 => {
                    if !self.catch(m, &e) {
                        return Err(e);
                    }
                }
                other => return other,
            }
        }
    }

    /// Hands error `e` to the nearest error handler: true if one takes it.
    fn catch(&mut self, m: &Module, e: &RuntimeError) -> bool {
        let Some(errno) = e.errno else {
            return false;
        };
        self.errno = errno;
        let mut failed = e.pc;
        for k in (0..self.frames.len()).rev() {
            let f = self.frames[k];
            if f.failed_at != u32::MAX {
                return false; // An error inside an error handler.
            }
            let p = &m.procs[f.proc as usize];
            if let Some(h) = &p.handler {
                if let Some(above) = self.frames.get(k + 1) {
                    self.locals.truncate(above.base as usize);
                }
                self.frames.truncate(k + 1);
                self.stack.truncate(f.stack_base as usize);
                // A failure of another statement than the one retried counts anew.
                let stmt = failed
                    .checked_sub(p.code_start)
                    .and_then(|at| h.statement_at(at))
                    .map_or(u32::MAX, |(start, _)| start);
                if let Some(fr) = self.frames.last_mut() {
                    fr.failed_at = failed;
                    if stmt != fr.retried {
                        fr.retries = 0;
                    }
                }
                self.pc = p.code_start + h.pc;
                return true;
            }
            failed = f.ret_pc.wrapping_sub(1);
        }
        false
    }

    /// `Retry` (`again`) or `TryNext`: leaves the error handler for the statement that
    /// failed, or the one after it.
    fn resume(&mut self, m: &Module, again: bool) -> Result<(), String> {
        let Some(f) = self.frames.last().copied() else {
            return Err("no procedure is running".into());
        };
        let p = &m.procs[f.proc as usize];
        let (Some(h), true) = (&p.handler, f.failed_at != u32::MAX) else {
            return Err(format!(
                "`{}` outside an error handler",
                if again { "RETRY" } else { "TRYNEXT" }
            ));
        };
        let at = f.failed_at.checked_sub(p.code_start);
        let Some((start, end)) = at.and_then(|at| h.statement_at(at)) else {
            return Err(
                "the statement that failed is not in the procedure's table (a corrupt module)"
                    .into(),
            );
        };
        let retries = if again { f.retries + 1 } else { 0 };
        if retries > MAX_RETRIES {
            return Err(format!(
                "ERR_EXCRTYMAX: the error handler retried error {} more than {MAX_RETRIES} times",
                self.errno
            ));
        }
        self.stack.truncate(f.stack_base as usize);
        if let Some(fr) = self.frames.last_mut() {
            fr.failed_at = u32::MAX;
            fr.retries = retries;
            fr.retried = if again { start } else { u32::MAX };
        }
        self.pc = p.code_start + if again { start } else { end };
        Ok(())
    }

    /// The run between errors: until an event, the end, or an error.
    fn run_segment(
        &mut self,
        m: &Module,
        r: &dyn Reader,
        vars: &mut [u64],
        texts: &mut Texts,
        budget: &mut u64,
        max_depth: usize,
    ) -> Result<Stop, RuntimeError> {
        let err = |pc: u32, message: String| RuntimeError {
            message,
            pc,
            pos: m.pos_of(pc),
            errno: None,
        };
        loop {
            let pc = self.pc;
            let Some(&ins) = m.code.get(pc as usize) else {
                return Err(err(
                    pc,
                    "the program ran past its code (a corrupt module)".into(),
                ));
            };
            if *budget == 0 {
                return Err(err(
                    pc,
                    "this loop ran the instruction budget out without time passing (an endless zero-time loop); add a motion, a delay or a wait inside it".into(),
                ));
            }
            *budget -= 1;
            self.pc = pc + 1;
            let base = self.frames.last().map_or(0, |f| f.base) as usize;
            match ins {
                Instr::Nop => {}
                Instr::PushBool(v) => self.stack.push(u64::from(v)),
                Instr::PushInt(i) => self.stack.push(i as u64),
                Instr::PushNum(x) => self.stack.push(b(x)),
                Instr::PushConst(k) => {
                    let c = &m.consts[k as usize];
                    let w = c.ty.width() as usize;
                    let at = self.stack.len();
                    self.stack.resize(at + w, 0);
                    c.value.write_slots(&mut self.stack[at..]);
                }
                Instr::Pop(n) => {
                    let l = self.stack.len().saturating_sub(n as usize);
                    self.stack.truncate(l);
                }
                Instr::LoadLocal(s) => {
                    let v = self.locals[base + s as usize];
                    self.stack.push(v);
                }
                Instr::StoreLocal(s) => {
                    let v = self.pop();
                    self.locals[base + s as usize] = v;
                }
                Instr::LoadLocalN(s, n) => {
                    let at = base + s as usize;
                    self.stack
                        .extend_from_slice(&self.locals[at..at + n as usize]);
                }
                Instr::StoreLocalN(s, n) => {
                    let at = base + s as usize;
                    let from = self.stack.len() - n as usize;
                    self.locals[at..at + n as usize].copy_from_slice(&self.stack[from..]);
                    self.stack.truncate(from);
                }
                Instr::StoreLocalJoint(s) => {
                    let i = self.pop() as i64;
                    let v = self.pop();
                    let i = self.joint_index(i, r.axes()).map_err(|e| err(pc, e))?;
                    self.locals[base + s as usize + i] = v;
                }
                Instr::LoadVar(s) => self.stack.push(vars[s as usize]),
                Instr::StoreVar(s) => vars[s as usize] = self.pop(),
                Instr::LoadVarN(s, n) => self
                    .stack
                    .extend_from_slice(&vars[s as usize..s as usize + n as usize]),
                Instr::StoreVarN(s, n) => {
                    let from = self.stack.len() - n as usize;
                    vars[s as usize..s as usize + n as usize].copy_from_slice(&self.stack[from..]);
                    self.stack.truncate(from);
                }
                Instr::StoreVarJoint(s) => {
                    let i = self.pop() as i64;
                    let v = self.pop();
                    let i = self.joint_index(i, r.axes()).map_err(|e| err(pc, e))?;
                    vars[s as usize + i] = v;
                }
                Instr::LoadGlobal(g) => self.stack.push(r.global(g, pc)),
                Instr::AddI | Instr::SubI | Instr::MulI | Instr::DivI | Instr::ModI => {
                    let y = self.pop() as i64;
                    let x = self.pop() as i64;
                    let v = match ins {
                        Instr::AddI => x.checked_add(y),
                        Instr::SubI => x.checked_sub(y),
                        Instr::MulI => x.checked_mul(y),
                        Instr::DivI => x.checked_div(y),
                        _ => x.checked_rem(y),
                    };
                    let Some(v) = v else {
                        let why = if y == 0 && matches!(ins, Instr::DivI | Instr::ModI) {
                            "division by zero"
                        } else {
                            "integer overflow"
                        };
                        return Err(err(pc, format!("{why} ({x} and {y})")));
                    };
                    self.stack.push(v as u64);
                }
                Instr::NegI => {
                    let x = self.pop() as i64;
                    let v = x
                        .checked_neg()
                        .ok_or_else(|| err(pc, "integer overflow".into()))?;
                    self.stack.push(v as u64);
                }
                Instr::AddF | Instr::SubF | Instr::MulF | Instr::DivF => {
                    let y = f(self.pop());
                    let x = f(self.pop());
                    if matches!(ins, Instr::DivF) && y == 0.0 {
                        return Err(err(pc, "division by zero".into()));
                    }
                    let v = match ins {
                        Instr::AddF => x + y,
                        Instr::SubF => x - y,
                        Instr::MulF => x * y,
                        _ => x / y,
                    };
                    if !v.is_finite() {
                        return Err(err(pc, "a number became too large (not finite)".into()));
                    }
                    self.stack.push(b(v));
                }
                Instr::NegF => {
                    let x = f(self.pop());
                    self.stack.push(b(-x));
                }
                Instr::IntToNum => {
                    let x = self.pop() as i64;
                    self.stack.push(b(x as f64));
                }
                Instr::IntToNumBelow => {
                    let top = self.pop();
                    let x = self.pop() as i64;
                    self.stack.push(b(x as f64));
                    self.stack.push(top);
                }
                Instr::NumToInt => {
                    let x = f(self.pop()).trunc();
                    if !(x.is_finite() && x.abs() < 9.2e18) {
                        return Err(err(pc, format!("{x} does not fit in an int")));
                    }
                    self.stack.push(x as i64 as u64);
                }
                Instr::CmpI(c) => {
                    let y = self.pop() as i64;
                    let x = self.pop() as i64;
                    self.stack.push(u64::from(c.holds(x.cmp(&y))));
                }
                Instr::CmpF(c) => {
                    let y = f(self.pop());
                    let x = f(self.pop());
                    let v = x.partial_cmp(&y).is_some_and(|o| c.holds(o));
                    self.stack.push(u64::from(v));
                }
                Instr::CmpB(c) => {
                    let y = self.pop() != 0;
                    let x = self.pop() != 0;
                    self.stack.push(u64::from((x == y) == (c == Cmp::Eq)));
                }
                Instr::Not => {
                    let x = self.pop();
                    self.stack.push(u64::from(x == 0));
                }
                Instr::AbsI => {
                    let x = self.pop() as i64;
                    let v = x
                        .checked_abs()
                        .ok_or_else(|| err(pc, "integer overflow".into()))?;
                    self.stack.push(v as u64);
                }
                Instr::AbsF => {
                    let x = f(self.pop());
                    self.stack.push(b(x.abs()));
                }
                Instr::MinI | Instr::MaxI => {
                    let y = self.pop() as i64;
                    let x = self.pop() as i64;
                    self.stack.push(if matches!(ins, Instr::MinI) {
                        x.min(y)
                    } else {
                        x.max(y)
                    } as u64);
                }
                Instr::TextCat
                | Instr::CmpT(_)
                | Instr::TextLen
                | Instr::TextPart
                | Instr::TextFind(_)
                | Instr::TextMatch
                | Instr::TextMemb
                | Instr::TextMap
                | Instr::NumToText
                | Instr::ValText(_)
                | Instr::TextIsNum
                | Instr::TextNum => {
                    if let Err((errno, e)) = self.text(ins, m, texts) {
                        return Err(RuntimeError {
                            errno,
                            ..err(pc, e)
                        });
                    }
                }
                Instr::Raise(msg) => {
                    let n = self.pop() as i64;
                    let text = m.strings.get(msg as usize).map_or("", String::as_str);
                    return Err(RuntimeError {
                        errno: Some(n),
                        ..err(pc, format!("{text} (error {n}; no error handler took it)"))
                    });
                }
                Instr::RaiseUp => {
                    let n = self.errno;
                    let fr = self.frames.pop().unwrap_or(Frame::new(0, u32::MAX, 0, 0));
                    self.locals.truncate(fr.base as usize);
                    self.stack.truncate(fr.stack_base as usize);
                    if fr.failed_at == u32::MAX {
                        return Err(err(pc, "`RAISE;` outside an error handler".into()));
                    }
                    if self.frames.is_empty() || fr.ret_pc == u32::MAX {
                        return Err(err(
                            pc,
                            format!(
                                "error {n}, raised on from the error handler of the task's first routine: no error handler took it"
                            ),
                        ));
                    }
                    self.pc = fr.ret_pc;
                    return Err(RuntimeError {
                        errno: Some(n),
                        ..err(
                            fr.ret_pc - 1,
                            format!(
                                "error {n}, raised on by an error handler: no error handler took it"
                            ),
                        )
                    });
                }
                Instr::Retry | Instr::TryNext => self
                    .resume(m, ins == Instr::Retry)
                    .map_err(|e| err(pc, e))?,
                Instr::ErrNo => self.stack.push(self.errno as u64),
                Instr::MinF | Instr::MaxF | Instr::Atan2 => {
                    let y = f(self.pop());
                    let x = f(self.pop());
                    let v = match ins {
                        Instr::MinF => x.min(y),
                        Instr::MaxF => x.max(y),
                        _ => x.atan2(y),
                    };
                    self.stack.push(b(v));
                }
                Instr::Sqrt => {
                    let x = f(self.pop());
                    if x < 0.0 {
                        return Err(err(
                            pc,
                            format!("the square root of a negative number ({x})"),
                        ));
                    }
                    self.stack.push(b(x.sqrt()));
                }
                Instr::Sin | Instr::Cos => {
                    let x = f(self.pop());
                    self.stack.push(b(if matches!(ins, Instr::Sin) {
                        x.sin()
                    } else {
                        x.cos()
                    }));
                }
                Instr::MakeJoints(n) => {
                    let at = self.stack.len();
                    self.stack.resize(at - n as usize + crate::MAX_AXES, 0);
                }
                Instr::JointsGet => {
                    let i = self.pop() as i64;
                    let i = self.joint_index(i, r.axes()).map_err(|e| err(pc, e))?;
                    let at = self.stack.len() - crate::MAX_AXES;
                    let v = self.stack[at + i];
                    self.stack.truncate(at);
                    self.stack.push(v);
                }
                Instr::PoseGet(k) => {
                    let at = self.stack.len() - 6;
                    let v = self.stack[at + k as usize];
                    self.stack.truncate(at);
                    self.stack.push(v);
                }
                Instr::Offset | Instr::ToolOffset => {
                    let dz = f(self.pop());
                    let dy = f(self.pop());
                    let dx = f(self.pop());
                    let at = self.stack.len() - 6;
                    let mut p = [0.0; 6];
                    for (k, v) in p.iter_mut().enumerate() {
                        *v = f(self.stack[at + k]);
                    }
                    let q = if matches!(ins, Instr::Offset) {
                        math::offset(p, dx, dy, dz)
                    } else {
                        math::tool_offset(p, dx, dy, dz)
                    };
                    for (k, v) in q.iter().enumerate() {
                        self.stack[at + k] = b(*v);
                    }
                }
                Instr::PoseMul | Instr::PoseInv => {
                    let read = |s: &[u64]| {
                        let mut p = [0.0; 6];
                        for (v, x) in p.iter_mut().zip(s) {
                            *v = f(*x);
                        }
                        p
                    };
                    let n = self.stack.len();
                    let q = if matches!(ins, Instr::PoseMul) {
                        let r = math::pose_mul(
                            read(&self.stack[n - 12..n - 6]),
                            read(&self.stack[n - 6..]),
                        );
                        self.stack.truncate(n - 6);
                        r
                    } else {
                        math::pose_inv(read(&self.stack[n - 6..]))
                    };
                    let at = self.stack.len() - 6;
                    for (k, v) in q.iter().enumerate() {
                        self.stack[at + k] = b(*v);
                    }
                }
                Instr::Jump(t) => self.pc = self.frame_start(m) + t,
                Instr::JumpIfFalse(t) => {
                    if self.pop() == 0 {
                        self.pc = self.frame_start(m) + t;
                    }
                }
                Instr::JumpIfTrue(t) => {
                    if self.pop() != 0 {
                        self.pc = self.frame_start(m) + t;
                    }
                }
                Instr::Call(p) => {
                    if self.frames.len() >= max_depth {
                        return Err(err(
                            pc,
                            format!("calls nested more than {max_depth} deep (runaway recursion?)"),
                        ));
                    }
                    let callee: &ProcInfo = &m.procs[p as usize];
                    let nargs = callee.param_width() as usize;
                    let new_base = self.frame().base as usize
                        + m.procs[self.frame().proc as usize].frame_slots as usize;
                    self.locals
                        .resize(new_base + callee.frame_slots as usize, 0);
                    let from = self.stack.len() - nargs;
                    self.locals[new_base..new_base + nargs].copy_from_slice(&self.stack[from..]);
                    self.locals[new_base + nargs..]
                        .iter_mut()
                        .for_each(|v| *v = 0);
                    self.stack.truncate(from);
                    self.frames
                        .push(Frame::new(p, pc + 1, new_base as u32, from as u32));
                    self.pc = callee.code_start;
                }
                Instr::Ret | Instr::RetVal => {
                    let fr = self.frames.pop().unwrap_or(Frame::new(0, u32::MAX, 0, 0));
                    self.locals.truncate(fr.base as usize);
                    if self.frames.is_empty() || fr.ret_pc == u32::MAX {
                        self.frames.clear();
                        return Ok(Stop::Finished);
                    }
                    self.pc = fr.ret_pc;
                }
                Instr::Now => self.stack.push(b(r.now_s())),
                Instr::Cycle => self.stack.push(r.cycle() as u64),
                Instr::TimedOut => self.stack.push(u64::from(r.timed_out())),
                Instr::CurrentJoints => {
                    let j = r.joints();
                    self.stack.extend(j.iter().map(|x| b(*x)));
                }
                Instr::CurrentPose => {
                    let p = r.tcp();
                    self.stack.extend(p.iter().map(|x| b(*x)));
                }
                Instr::CurrentTool => {
                    let p = r.tool();
                    self.stack.extend(p.iter().map(|x| b(*x)));
                }
                _ => {
                    // An event (or `ParBegin`, which the machine tracks): stop before it.
                    self.pc = pc;
                    *budget += 1;
                    return Ok(Stop::Event(ins));
                }
            }
        }
    }

    fn frame_start(&self, m: &Module) -> u32 {
        m.procs[self.frame().proc as usize].code_start
    }

    fn joint_index(&self, i: i64, axes: usize) -> Result<usize, String> {
        if i < 0 || i as usize >= axes {
            return Err(format!(
                "joint index {i} is out of range: this robot has axes 0 to {}",
                axes.saturating_sub(1)
            ));
        }
        Ok(i as usize)
    }
}

impl Thread {
    /// A text instruction ([`crate::texts`]): pops its operands, pushes its result.
    /// An error a handler may take carries RAPID's number (ERR_STRTOOLNG, ERR_OUTOFBND).
    fn text(
        &mut self,
        ins: Instr,
        m: &Module,
        texts: &mut Texts,
    ) -> Result<(), (Option<i64>, String)> {
        fn text_of<'a>(
            t: &'a Texts,
            m: &'a Module,
            h: u64,
        ) -> Result<&'a str, (Option<i64>, String)> {
            t.get(m, h).ok_or_else(|| {
                (
                    None,
                    format!("a text handle no text has ({h}): a corrupt module"),
                )
            })
        }
        let v = match ins {
            Instr::TextCat => {
                let (y, x) = (self.pop(), self.pop());
                let s = format!("{}{}", text_of(texts, m, x)?, text_of(texts, m, y)?);
                texts.make(m, s)?
            }
            Instr::CmpT(c) => {
                let (y, x) = (self.pop(), self.pop());
                let o = text_of(texts, m, x)?.cmp(text_of(texts, m, y)?);
                u64::from(c.holds(o))
            }
            Instr::TextLen => b(text_of(texts, m, self.pop())?.chars().count() as f64),
            Instr::TextPart => {
                let (len, start, s) = (f(self.pop()), f(self.pop()), self.pop());
                let part = texts::part(text_of(texts, m, s)?, start, len)?;
                texts.make(m, part)?
            }
            Instr::TextFind(_) | Instr::TextMatch | Instr::TextMemb => {
                let (set, at, s) = (self.pop(), f(self.pop()), self.pop());
                let (s, set) = (text_of(texts, m, s)?, text_of(texts, m, set)?);
                match ins {
                    Instr::TextFind(not_in) => b(texts::find(s, at, set, not_in)?),
                    Instr::TextMatch => b(texts::find_text(s, at, set)?),
                    _ => u64::from(texts::member(s, at, set)?),
                }
            }
            Instr::TextMap => {
                let (to, from, s) = (self.pop(), self.pop(), self.pop());
                let mapped = texts::map(
                    text_of(texts, m, s)?,
                    text_of(texts, m, from)?,
                    text_of(texts, m, to)?,
                );
                texts.make(m, mapped)?
            }
            Instr::NumToText => {
                let (dec, x) = (f(self.pop()), f(self.pop()));
                texts.make(m, texts::num_to_str(x, dec)?)?
            }
            Instr::ValText(k) => {
                let x = self.pop();
                let s = match k {
                    0 => (if x != 0 { "TRUE" } else { "FALSE" }).to_string(),
                    _ => texts::num_value(f(x)),
                };
                texts.make(m, s)?
            }
            Instr::TextIsNum => {
                u64::from(texts::parse_num(text_of(texts, m, self.pop())?).is_some())
            }
            Instr::TextNum => b(texts::parse_num(text_of(texts, m, self.pop())?).unwrap_or(0.0)),
            _ => {
                return Err((None, format!("`{}` is not a text instruction", ins.name())));
            }
        };
        self.stack.push(v);
        Ok(())
    }
}
