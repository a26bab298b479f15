"""vworks: offline programming of robot cells.

Write robot programs in WSL, place robots, devices and parts in a workcell, and run every
robot's program at once, as the controllers would: cycle times, waits, collisions and
deadlocks, before any steel moves.

    import vworks
    cell = vworks.load_cell("workcells/handoff/cell.toml")
    result = cell.run()
    print(result.end_time, [r.end_time for r in result.robots])

Times are seconds (floats) with ``_ns`` twins (integers); lengths metres; angles radians.
"""

from ._vworks import (
    Cell,
    CellError,
    Collision,
    CompileError,
    Diagnostic,
    Error,
    Event,
    EventList,
    Issue,
    LinkError,
    LogLine,
    Module,
    Result,
    Robot,
    RobotMotion,
    RobotStats,
    Simulation,
    SimulationError,
    __version__,
    compile,
    compile_files,
    load_cell,
    read_log,
    write_report,
)
from ._sweep import SweepTable, sweep

__all__ = [
    "Cell",
    "CellError",
    "Collision",
    "CompileError",
    "Diagnostic",
    "Error",
    "Event",
    "EventList",
    "Issue",
    "LinkError",
    "LogLine",
    "Module",
    "Result",
    "Robot",
    "RobotMotion",
    "RobotStats",
    "Simulation",
    "SimulationError",
    "SweepTable",
    "__version__",
    "compile",
    "compile_files",
    "load_cell",
    "read_log",
    "sweep",
    "write_report",
]
