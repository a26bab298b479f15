//! The run's vocabulary and its log: what the simulation engine (`vworks-se`) writes and
//! every consumer of a run (the report, the sweep, the CLI, Python) reads, without
//! depending on the engine.
//!
//! - [`cell`]: what the vocabulary and the log know of a cell ([`cell::CellInfo`]: robots,
//!   programs, globals, bodies, files) and the names events resolve with ([`cell::Names`]).
//! - [`trace`]: the typed event vocabulary (`Kind`, `TraceEvent`, `Event`, `Data`);
//!   [`issue`]: the run's warnings and errors and their kinds ([`issue::IssueKind`]);
//!   [`place`]: where in the programs something happened (the motions in a collision, the
//!   lines logged).
//! - [`stats`]: time per robot, one fold over those events; [`result`]: what a run
//!   produced, and its JSON form.
//! - [`sink`]: consumers attached to a run; [`mcaplog`], the MCAP log (its writer and its
//!   reader), is one.

pub mod cell;
pub mod issue;
pub mod mcaplog;
pub mod place;
pub mod result;
pub mod sink;
pub mod stats;
pub mod trace;
