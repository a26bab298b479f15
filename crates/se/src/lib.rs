//! The vworks simulation engine (SE): the paper's simulation management module. It takes
//! a loaded cell ([`vworks_cell::Cell`]) and runs it, recording the run in the vocabulary
//! of `vworks_log` (typed events, statistics, the result, sinks such as the MCAP log).
//!
//! Along the run's data flow:
//! - [`engine`]: the event queue, the wait and when lists (through each VM), cycle
//!   boundaries, routing of sets, signals and remote requests, races, deadlocks:
//!   [`engine::Simulation`].
//! - [`world`]: the robots' joints and link frames and the parts' poses at a boundary.
//! - [`collide`]: collision checks at cycle boundaries and the sweep between them (parry3d).
//! - [`describe`]: the cell as the log sees it (`vworks_log::cell::CellInfo`), its names
//!   for resolving events, statements' text.
//!
//! ```no_run
//! let cell = std::sync::Arc::new(vworks_cell::load("workcells/handoff/cell.toml".as_ref()).unwrap());
//! let result = vworks_se::engine::Simulation::new(cell).run(None);
//! println!("{} at {} ns", result.outcome.name(), result.end_time_ns);
//! ```

pub mod collide;
pub mod describe;
pub mod engine;
pub mod world;
