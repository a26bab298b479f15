//! The vworks simulation engine (SE): the paper's simulation management module.
//!
//! - [`workcell`]: workcell files → a [`workcell::Cell`]: models, compiled and linked
//!   programs, devices and parts.
//! - [`engine`]: the event queue, the wait and when lists (through each VM), cycle
//!   boundaries, races, deadlocks, statistics: [`engine::Simulation`].
//! - [`collide`]: collision checks at cycle boundaries (parry3d).
//! - [`mcaplog`]: the MCAP log of a run, playable in Foxglove.
//! - [`report`]: the run report, one self-contained HTML file made from a log.
//!
//! ```no_run
//! let cell = std::sync::Arc::new(vworks_se::workcell::load("workcells/handoff/cell.toml".as_ref()).unwrap());
//! let result = vworks_se::engine::Simulation::new(cell).run(None);
//! println!("{} at {} ns", result.outcome.name(), result.end_time_ns);
//! ```

pub mod collide;
pub mod engine;
pub mod mcaplog;
pub mod report;
pub mod workcell;

pub use vworks_wslc::link;

/// The README's Rust example, compiled by `cargo test --doc` so that it stays true.
#[cfg(doctest)]
#[doc = include_str!("../../../README.md")]
pub struct ReadmeExamples;
