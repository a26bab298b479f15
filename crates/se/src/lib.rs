//! The vworks simulation engine (SE): the paper's simulation management module. It takes
//! a loaded cell ([`vworks_cell::Cell`]) and runs it, recording the run in the vocabulary
//! of `vworks_log` (typed events, statistics, the result, sinks such as the MCAP log).
//!
//! Its API, declared here (the modules behind it are private), along the run's data flow:
//! - [`Simulation`] (module `engine`): the event queue, the wait and when lists (through
//!   each VM), cycle boundaries, routing of sets, signals and remote requests, races,
//!   deadlocks; [`robot_vms`], the robots' VMs for a cell; [`EVENT_LIMIT`], [`INSTANT_LIMIT`].
//! - [`World`]: the robots' joints and link frames and the parts' poses at a boundary.
//! - [`Collider`] (module `collide`): collision checks at cycle boundaries and the sweep
//!   between them (parry3d), reading robots through [`RobotPoses`].
//! - [`describe()`]: the cell as the log sees it (`vworks_log::cell::CellInfo`);
//!   [`CellNames`], its names for resolving events; [`statement_at`], statements' text.
//!
//! ```no_run
//! let cell = std::sync::Arc::new(vworks_cell::load("workcells/handoff/cell.toml".as_ref()).unwrap());
//! let result = vworks_se::Simulation::new(cell).run(None);
//! println!("{} at {} ns", result.outcome.name(), result.end_time_ns);
//! ```

mod collide;
mod describe;
mod engine;
mod world;

// The engine's API: what a program embedding vworks, the CLI, Python and the tests use.
// The modules behind it are private, so what is public is declared here, once.
pub use collide::{Collider, CollisionEvent, RobotPoses, SWEEP_MIN_STEP_NS};
pub use describe::{CellNames, describe, statement_at};
pub use engine::{EVENT_LIMIT, INSTANT_LIMIT, Simulation, robot_vms};
pub use world::World;
