//! The vworks virtual machine crate.
//!
//! One VM runs per robot. This crate owns the *instruction set* that the WSL compiler
//! (`vworks-wslc`) targets, so that the format and its interpreter can never drift apart:
//!
//! - [`types`]: value types and physical dimensions (`length`, `angle`, `time`, …) shared by
//!   the compiler and the VM.
//! - [`bytecode`]: instructions, the in-memory [`bytecode::Module`], its binary encoding
//!   (`.wslb`), the loader that verifies untrusted bytes, and the disassembler.
//! - [`math`]: pure pose/joint arithmetic used both for constant folding in the compiler and
//!   by the interpreter, so compile-time and run-time results are bit-identical.
//! - [`exec`]: the interpreter — threads of frames over a slot stack, a per-segment
//!   instruction budget and a call-depth limit, no allocation per instruction.
//! - [`motion`]: trapezoidal profiles, lines and arcs, slerp: joints as a pure function of
//!   time inside a motion.
//! - [`machine`]: [`machine::Vm`], one robot — the segment interface the simulation engine
//!   drives (`next_event` / `perform`), motions, waits, signals, `when` handlers, remote
//!   requests and `parallel` joins.
//!
//! The format is documented in `docs/bytecode.md`, the contract with the engine in
//! `docs/engine.md`.

pub mod bytecode;
pub mod exec;
pub mod machine;
pub mod math;
pub mod motion;
pub mod ramps;
pub mod texts;
pub mod types;

pub use bytecode::{Instr, LoadError, Module};
pub use types::{ConstValue, Dim, MAX_AXES, Type};
