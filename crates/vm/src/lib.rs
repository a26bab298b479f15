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
//!
//! The interpreter itself (execution segments, motion) arrives with issue 4; the format is
//! documented in `docs/bytecode.md`.

pub mod bytecode;
pub mod exec;
pub mod machine;
pub mod math;
pub mod motion;
pub mod types;

pub use bytecode::{Instr, LoadError, Module};
pub use types::{ConstValue, Dim, MAX_AXES, Type};
