"""Type stubs of the `vworks._vworks` extension (kept true by `mypy.stubtest` in the tests)."""

import os
import pathlib
from collections.abc import Iterator, Mapping
from typing import Any, Literal, Optional, Union, final, overload

import numpy as np
import numpy.typing as npt

__version__: str
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
    "__version__",
    "cell_files",
    "compile",
    "compile_files",
    "load_cell",
    "read_log",
    "run_variants",
    "write_report",
]

class Error(Exception):
    """Every error vworks raises."""

class CompileError(Error):
    """A program does not compile."""

    diagnostics: list[Diagnostic]

class LinkError(Error):
    """The cell's programs compile but do not fit together."""

    diagnostics: list[Diagnostic]

class CellError(Error):
    """A workcell file (or a robot model it names) is wrong."""

class SimulationError(Error):
    """A robot's program failed while running."""

    robot: Optional[str]
    file: Optional[str]
    line: int
    col: int
    result: Optional[Result]

@final
class Diagnostic:
    """One compiler or linker diagnostic."""

    @property
    def code(self) -> str: ...
    @property
    def severity(self) -> str: ...
    @property
    def message(self) -> str: ...
    @property
    def file(self) -> str: ...
    @property
    def line(self) -> int: ...
    @property
    def col(self) -> int: ...
    @property
    def help(self) -> Optional[str]: ...
    @property
    def rendered(self) -> str: ...

@final
class Module:
    """A compiled WSL module."""

    @property
    def path(self) -> str: ...
    @property
    def files(self) -> list[str]: ...
    @property
    def globals(self) -> list[str]: ...
    @property
    def procs(self) -> list[str]: ...
    @property
    def warnings(self) -> list[Diagnostic]: ...
    def disasm(self) -> str: ...
    def to_bytes(self) -> bytes: ...

def compile(
    source: str,
    path: Optional[str] = None,
    language: Optional[Literal["wsl", "rapid"]] = None,
) -> Module:
    """Compiles WSL or ABB RAPID `source` (`language`, else `path`'s extension: `.mod`,
    `.modx`, `.sys`, `.sysx`, `.prg` are RAPID); raises `CompileError` if it does not
    compile."""

def compile_files(
    files: list[tuple[str, str]],
    language: Optional[Literal["wsl", "rapid"]] = None,
) -> Module:
    """Compiles one program of several files, `files` as (path, text) in order: a RAPID
    task's modules, or a WSL program and its library files (`language`, else the paths'
    extensions, all of one language: else `ValueError`); raises `CompileError` if it does
    not compile."""

def load_cell(path: Union[str, os.PathLike[str]]) -> Cell:
    """Loads a workcell file; raises `CellError`, `CompileError` or `LinkError`."""

def read_log(path: Union[str, os.PathLike[str]]) -> EventList:
    """The events of an MCAP log written by vworks."""

def run_variants(
    cell: Union[str, os.PathLike[str]],
    variants: list[list[tuple[str, Union[float, int, str, bool]]]],
    variables: list[str],
    jobs: Optional[int] = None,
    until: Optional[float] = None,
    files: Optional[dict[str, bytes]] = None,
    offset: int = 0,
) -> tuple[list[str], list[list[Any]]]:
    """Runs variants of a workcell; the sweep table's columns and rows (see vworks.sweep)."""

def cell_files(cell: Union[str, os.PathLike[str]]) -> dict[str, bytes]:
    """Every file the workcell reads, by the paths the loader uses."""

def write_report(
    log: Union[str, os.PathLike[str]], output: Optional[Union[str, os.PathLike[str]]] = None
) -> pathlib.Path:
    """Writes the run's HTML report from its log; returns the path written."""

@final
class Cell:
    """A loaded workcell."""

    @property
    def name(self) -> str: ...
    @property
    def file(self) -> pathlib.Path: ...
    @property
    def cycle(self) -> float: ...
    @property
    def robots(self) -> list[str]: ...
    @property
    def devices(self) -> list[str]: ...
    @property
    def parts(self) -> list[str]: ...
    def run(
        self,
        until: Optional[float] = None,
        log: Union[str, os.PathLike[str], None] = None,
        log_every: int = 1,
        check: bool = True,
    ) -> Result: ...
    def simulation(self) -> Simulation: ...

@final
class Event:
    """One event of a run."""

    @property
    def time(self) -> float: ...
    @property
    def time_ns(self) -> int: ...
    @property
    def robot(self) -> Optional[str]: ...
    @property
    def kind(self) -> str: ...
    @property
    def details(self) -> str: ...
    @property
    def file(self) -> Optional[str]: ...
    @property
    def line(self) -> int: ...
    @property
    def col(self) -> int: ...
    @property
    def data(self) -> Optional[dict[str, Any]]: ...
    def trace_line(self) -> str: ...

@final
class EventList:
    """A sequence of events, with `to_pandas()`."""

    def __len__(self) -> int: ...
    @overload
    def __getitem__(self, key: int, /) -> Event: ...
    @overload
    def __getitem__(self, key: slice, /) -> EventList: ...
    def __iter__(self) -> Iterator[Event]: ...
    def to_pandas(self) -> Any: ...

@final
class RobotStats:
    """Time spent by one robot."""

    @property
    def name(self) -> str: ...
    @property
    def moving(self) -> float: ...
    @property
    def waiting(self) -> float: ...
    @property
    def idle(self) -> float: ...
    @property
    def motions(self) -> int: ...
    @property
    def end_time(self) -> float: ...
    @property
    def end_time_ns(self) -> int: ...
    @property
    def ended(self) -> str: ...

@final
class Collision:
    """A collision that started."""

    @property
    def time(self) -> float: ...
    @property
    def time_ns(self) -> int: ...
    @property
    def a(self) -> str: ...
    @property
    def b(self) -> str: ...
    @property
    def depth(self) -> float: ...
    @property
    def point(self) -> tuple[float, float, float]: ...
    @property
    def motions(self) -> list[RobotMotion]: ...

@final
class RobotMotion:
    """A robot whose body is in a collision or near miss, and the motion statement it was
    making then (standing: the last one it made)."""

    @property
    def robot(self) -> str: ...
    @property
    def moving(self) -> bool: ...
    @property
    def file(self) -> Optional[str]: ...
    @property
    def line(self) -> int: ...
    @property
    def col(self) -> int: ...
    @property
    def statement(self) -> str: ...
    def describe(self) -> str: ...

@final
class LogLine:
    """A line a robot's program logged (`log`, RAPID's `TPWrite`)."""

    @property
    def time(self) -> float: ...
    @property
    def time_ns(self) -> int: ...
    @property
    def robot(self) -> str: ...
    @property
    def text(self) -> str: ...
    @property
    def file(self) -> Optional[str]: ...
    @property
    def line(self) -> int: ...
    @property
    def col(self) -> int: ...

@final
class Issue:
    """A warning or an error of a run."""

    @property
    def kind(self) -> str: ...
    @property
    def message(self) -> str: ...
    @property
    def robot(self) -> Optional[str]: ...
    @property
    def file(self) -> Optional[str]: ...
    @property
    def distance_m(self) -> Optional[float]: ...
    @property
    def line(self) -> int: ...
    @property
    def col(self) -> int: ...
    @property
    def motions(self) -> list[RobotMotion]: ...

@final
class Result:
    """What a run produced."""

    @property
    def outcome(self) -> str: ...
    @property
    def end_time(self) -> float: ...
    @property
    def end_time_ns(self) -> int: ...
    @property
    def robots(self) -> list[RobotStats]: ...
    @property
    def collisions(self) -> list[Collision]: ...
    @property
    def warnings(self) -> list[Issue]: ...
    @property
    def errors(self) -> list[Issue]: ...
    def to_dict(self) -> dict[str, Any]: ...
    @property
    def globals(self) -> dict[str, Union[bool, int, float]]: ...
    @property
    def events(self) -> EventList: ...
    @property
    def logs(self) -> list[LogLine]: ...
    @property
    def cycles(self) -> int: ...
    @property
    def log_counts(self) -> dict[str, int]: ...
    @property
    def log_error(self) -> Optional[str]: ...

@final
class Simulation:
    """A running simulation of a cell."""

    def step_event(self) -> bool: ...
    def step_cycle(self) -> bool: ...
    def run_until(self, t: float) -> bool: ...
    def run(self) -> Result: ...
    def result(self) -> Result: ...
    @property
    def time(self) -> float: ...
    @property
    def time_ns(self) -> int: ...
    @property
    def outcome(self) -> Optional[str]: ...
    @property
    def robots(self) -> list[str]: ...
    def robot(self, name: str) -> Robot: ...
    @property
    def globals(self) -> Mapping[str, Union[bool, int, float]]: ...
    def events_since(self, i: int = 0) -> EventList: ...

@final
class Robot:
    """A robot of a running simulation."""

    @property
    def name(self) -> str: ...
    @property
    def joints(self) -> npt.NDArray[np.float64]: ...
    @property
    def tcp(self) -> npt.NDArray[np.float64]: ...
