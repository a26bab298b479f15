//! Consumers of a run: the MCAP log today, a live stream or a progress display later. A
//! sink is attached to the engine's `Simulation` with `with_sink` and sees every event as
//! it is recorded and the cell's state at cycle boundaries ([`WorldView`]), without the
//! engine knowing what it does with them. A sink is made for one cell and keeps what it
//! needs of it (names to resolve events with, models, bodies).

use std::collections::BTreeMap;

use vworks_model::math::Iso;
use vworks_vm::MAX_AXES;

use crate::result::Outcome;
use crate::stats::RobotStats;
use crate::trace::TraceEvent;

/// The cell's kinematic state at a cycle boundary, as sinks read it (the engine's world).
pub trait WorldView {
    /// Every robot's joints (`MAX_AXES` slots, the robot's axes first).
    fn joints(&self) -> &[[f64; MAX_AXES]];
    /// Every robot's link frames in the cell.
    fn frames(&self) -> &[Vec<Iso>];
    /// Every robot's active tool: its TCP in its tool link's frame.
    fn tools(&self) -> &[Iso];
    /// Every part's pose in the cell, into `out` (cleared first; reused, so that a
    /// boundary allocates nothing).
    fn part_poses_into(&self, out: &mut Vec<Iso>);
}

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
    fn event(&mut self, e: &TraceEvent) -> Result<(), String>;

    /// The cell's state at cycle boundary `t`, after its collision check (every boundary
    /// while any sink [`RunSink::records_cycles`]; otherwise the engine may skip
    /// boundaries where nothing moves).
    fn cycle(&mut self, _t: i64, _world: &dyn WorldView) -> Result<(), String> {
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
