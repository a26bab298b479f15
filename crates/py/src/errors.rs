//! The exceptions Python sees: `vworks.Error` and its subclasses, one per kind of
//! failure (a program, the cell's links, a workcell, a run).

use pyo3::create_exception;
use pyo3::exceptions::PyException;

create_exception!(
    vworks,
    Error,
    PyException,
    "Every error vworks raises: a program that does not compile or link, a workcell that does not load, a simulation that fails, a log that cannot be read."
);
create_exception!(
    vworks,
    CompileError,
    Error,
    "A program does not compile. `.diagnostics` lists every problem (`Diagnostic`: code, message, file, line, col, rendered)."
);
create_exception!(
    vworks,
    LinkError,
    Error,
    "The cell's programs compile but do not fit together (globals, remote calls, signals, parts, joints). `.diagnostics` lists why."
);
create_exception!(
    vworks,
    CellError,
    Error,
    "A workcell file (or a robot model it names) is wrong: the message names the file, the place and what to do."
);
create_exception!(
    vworks,
    SimulationError,
    Error,
    "A robot's program failed while running. `.robot`, `.file`, `.line`, `.col` say where; `.result` holds the run up to the failure when there is one."
);
