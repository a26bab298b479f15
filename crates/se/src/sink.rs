//! Consumers of a run: the MCAP log today, a live stream or a progress display later. A
//! sink is attached to a `Simulation` (`engine`) with `with_sink` and sees every
//! event as it is recorded and the cell's state at cycle boundaries, without the engine
//! knowing what it does with them.

use std::collections::BTreeMap;

use vworks_cell::Cell;

use crate::result::Outcome;
use crate::stats::RobotStats;
use crate::trace::TraceEvent;
use crate::world::World;

/// How a run ended, as handed to every sink's [`RunSink::finish`].
#[derive(Clone, Copy, Debug)]
pub struct RunEnd<'a> {
    /// The outcome.
    pub outcome: Outcome,
    /// The simulated end time (ns).
    pub end_time_ns: i64,
    /// Time per robot (the run's statistics).
    pub robots: &'a [RobotStats],
}

/// A consumer of a run (`Sync`, so that a simulation can be shared, as Python does).
/// Errors are the sink's own (a full disk): the engine drops a sink
/// that fails and reports its first error in the run's result (`log_error`); the run goes
/// on.
pub trait RunSink: Send + Sync + std::fmt::Debug {
    /// An event, just recorded (events come in trace order).
    fn event(&mut self, cell: &Cell, e: &TraceEvent) -> Result<(), String>;

    /// The cell's state at cycle boundary `t`, after its collision check (every boundary
    /// while any sink [`RunSink::records_cycles`]; otherwise the engine may skip
    /// boundaries where nothing moves).
    fn cycle(&mut self, _cell: &Cell, _t: i64, _world: &World) -> Result<(), String> {
        Ok(())
    }

    /// Whether this sink needs every cycle boundary, moving or not.
    fn records_cycles(&self) -> bool {
        false
    }

    /// The run is over: finish (a file's summary). Returns counts to report, by name (the
    /// log's messages per topic).
    fn finish(&mut self, end: &RunEnd<'_>) -> Result<BTreeMap<&'static str, u64>, String>;
}
