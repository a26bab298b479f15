//! The vworks simulation engine (SE): the paper's simulation management module. It takes
//! a loaded cell ([`vworks_cell::Cell`]) and runs it.
//!
//! Along the run's data flow:
//! - [`engine`]: the event queue, the wait and when lists (through each VM), cycle
//!   boundaries, routing of sets, signals and remote requests, races, deadlocks:
//!   [`engine::Simulation`].
//! - [`world`]: the robots' joints and link frames and the parts' poses at a boundary.
//! - [`collide`]: collision checks at cycle boundaries and the sweep between them (parry3d).
//! - [`trace`]: the typed event vocabulary every consumer of a run shares; [`place`]: where
//!   in the programs something happened (the motions in a collision, the lines logged).
//! - [`stats`]: time per robot, one fold over those events; [`result`]: what a run
//!   produced, and its JSON form.
//! - [`sink`]: consumers attached to a run; [`mcaplog`], the MCAP log, is one.
//!
//! ```no_run
//! let cell = std::sync::Arc::new(vworks_cell::load("workcells/handoff/cell.toml".as_ref()).unwrap());
//! let result = vworks_se::engine::Simulation::new(cell).run(None);
//! println!("{} at {} ns", result.outcome.name(), result.end_time_ns);
//! ```

pub mod collide;
pub mod engine;
pub mod mcaplog;
pub mod place;
pub mod result;
pub mod sink;
pub mod stats;
pub mod trace;
pub mod world;
