//! Workcell files (TOML): robots, devices, parts and settings, loaded into a [`Cell`]
//! ready to simulate — models loaded, programs compiled and linked, shapes built.
//!
//! Plain numbers are SI (m, rad, s); strings carry units exactly as in WSL (`"4ms"`,
//! `"250mm/s"`, `"90deg"`). Paths are relative to the workcell file. Every problem is a
//! [`CellError`] naming the file, the key and what to do.
//!
//! A workcell sets its programs' `param`s (`[params]`, `[robot.params]`: module
//! [`params`]), and [`Loader`] loads many variants of one workcell, each with a few values
//! changed by their dotted paths (`robot.r2.base.xyz.0`), compiling each program and
//! loading each model once (module [`variants`]).

mod cache;
mod cell;
mod context;
mod error;
mod file;
mod io;
mod load;
pub mod params;
mod paths;
pub mod variants;

pub use cell::{Body, Cell, DEFAULT_GRIP_DISTANCE, Robot, same_link};
pub use error::CellError;
pub use load::{load, load_checking, load_with, unknown_keys};
pub use variants::{Loader, Override};
pub use vworks_model::files::{Disk, Files, MemoryFiles};
pub use vworks_wslc::Stage;
/// Quantities as a workcell reads them (`"250mm"`, `0.25`), with WSL's units.
pub use vworks_wslc::units::{Quantity, parse_quantity};
