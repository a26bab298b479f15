"""The build backend of the `vworks` package: maturin's, saying on the terminal what it does.

`pip install ./crates/py` compiles the Rust extension in release mode (about 200 cargo
steps: crates and their build scripts), which takes minutes (docs/python.md, "Install").
pip shows a build backend's output only with
`pip install -v` (pypa/pip#6634): without it the build looks stuck. So while maturin builds
a wheel, this backend asks cargo for its progress bar, keeps the bar's updates out of the
output pip collects (that output, cargo's `Compiling ...` lines, reaches pip unchanged),
and writes one line to the terminal (`/dev/tty`), updated in place:

    vworks: compiling the Rust extension: 57/200 steps, 3m12s; now parry3d-f64

It writes nothing where there is no terminal (CI, a pipe), or with
`VWORKS_BUILD_PROGRESS=0`. Every PEP 517 hook is maturin's; only `build_wheel` and
`build_editable` are wrapped.
"""

from __future__ import annotations

import contextlib
import os
import re
import sys
import threading
import time
from typing import Any, Callable, Iterator, Mapping, Optional, TextIO, Tuple

import maturin  # type: ignore[import-untyped, unused-ignore]

get_requires_for_build_wheel = maturin.get_requires_for_build_wheel
get_requires_for_build_sdist = maturin.get_requires_for_build_sdist
get_requires_for_build_editable = maturin.get_requires_for_build_editable
prepare_metadata_for_build_wheel = maturin.prepare_metadata_for_build_wheel
prepare_metadata_for_build_editable = maturin.prepare_metadata_for_build_editable
build_sdist = maturin.build_sdist

# cargo's progress bar, as it writes it when told to (`term.progress.when = "always"`):
# `    Building [=====>     ] 57/131: parry3d-f64, nalgebra(build)   ` then `\r`.
_BAR = re.compile(rb"^\s*Building \[[^\]]*\]\s+(\d+)/(\d+)(?::\s*(.*?))?\s*$")


class Relay:
    """Splits what cargo writes into lines and progress-bar updates: `forward` gets every
    byte except the bar's updates; `status` gets a line for the terminal per update."""

    def __init__(self, forward: Callable[[bytes], None], status: Callable[[str], None], start: float) -> None:
        self.forward = forward
        self.status = status
        self.start = start
        self.pending = b""
        self.last = ""
        self.bar: Optional[Tuple[str, str, str]] = None  # done, total, what is compiling
        self.lock = threading.Lock()

    def feed(self, data: bytes) -> None:
        self.pending += data
        while True:
            ends = [i for i in (self.pending.find(b"\r"), self.pending.find(b"\n")) if i >= 0]
            if not ends:
                return
            i = min(ends)
            segment, end = self.pending[:i], self.pending[i : i + 1]
            self.pending = self.pending[i + 1 :]
            bar = _BAR.match(segment) if end == b"\r" else None
            if bar is None:
                if segment.strip() or end == b"\n":
                    self.forward(segment + end)
                continue
            now = (bar.group(3) or b"").decode(errors="replace").split(",")[0].strip()
            self.bar = (bar.group(1).decode(), bar.group(2).decode(), now)
            self.refresh()

    def refresh(self) -> None:
        """Shows the last progress with the time now (called again while one crate takes
        minutes to compile, so that the clock moves)."""
        if self.bar is None:
            return
        done, total, now = self.bar
        line = f"vworks: compiling the Rust extension: {done}/{total} steps, {_elapsed(self.start)}"
        if now:
            line += f"; now {now}"
        with self.lock:
            if line != self.last:
                self.last = line
                self.status(line)

    def close(self) -> None:
        if self.pending:
            self.forward(self.pending)
            self.pending = b""


def _elapsed(start: float) -> str:
    s = int(time.monotonic() - start)
    return f"{s // 60}m{s % 60:02d}s"


def _terminal() -> Optional[TextIO]:
    if os.environ.get("VWORKS_BUILD_PROGRESS", "1") in ("0", "false", "no"):
        return None
    try:
        return open("/dev/tty", "w", encoding="utf-8", errors="replace")
    except OSError:
        return None


@contextlib.contextmanager
def _progress() -> Iterator[None]:
    """Shows cargo's progress on the terminal while the block runs (see the module's doc)."""
    tty = _terminal()
    if tty is None:
        yield
        return
    start = time.monotonic()

    def status(line: str) -> None:
        # Two spaces at the end: pip's spinner, on the same line, backs over one of them.
        tty.write("\r\x1b[K" + line[:200] + "  ")
        tty.flush()

    tty.write(
        "\nvworks: compiling the Rust extension; a release build takes minutes (docs/python.md, "
        "'Install'); pip install -v shows cargo's output\n"
    )
    tty.flush()
    saved_env = {k: os.environ.get(k) for k in ("CARGO_TERM_PROGRESS_WHEN", "CARGO_TERM_PROGRESS_WIDTH")}
    os.environ["CARGO_TERM_PROGRESS_WHEN"] = "always"
    os.environ["CARGO_TERM_PROGRESS_WIDTH"] = "160"
    sys.stderr.flush()
    saved_err = os.dup(2)
    read, write = os.pipe()
    os.dup2(write, 2)
    os.close(write)

    def forward(data: bytes) -> None:
        while data:
            data = data[os.write(saved_err, data) :]

    relay = Relay(forward, status, start)

    def pump() -> None:
        while True:
            data = os.read(read, 65536)
            if not data:
                break
            relay.feed(data)
        relay.close()

    thread = threading.Thread(target=pump, daemon=True)
    thread.start()
    ticking = threading.Event()

    def tick() -> None:
        while not ticking.wait(1.0):
            relay.refresh()

    ticker = threading.Thread(target=tick, daemon=True)
    ticker.start()
    ok = False
    try:
        yield
        ok = True
    finally:
        ticking.set()
        ticker.join()
        sys.stderr.flush()
        os.dup2(saved_err, 2)  # the pipe's last writer goes: the pump sees its end
        # ... unless a process cargo started lives on with it (a compiler cache's server):
        # then the pump is left reading, and the build goes on.
        thread.join(timeout=5.0)
        if not thread.is_alive():
            os.close(read)
            os.close(saved_err)
        for k, v in saved_env.items():
            if v is None:
                os.environ.pop(k, None)
            else:
                os.environ[k] = v
        end = "built" if ok else "failed"
        tty.write(f"\r\x1b[Kvworks: the Rust extension {end} in {_elapsed(start)}\n")
        tty.close()


def build_wheel(
    wheel_directory: str,
    config_settings: Optional[Mapping[str, Any]] = None,
    metadata_directory: Optional[str] = None,
) -> str:
    with _progress():
        return str(maturin.build_wheel(wheel_directory, config_settings, metadata_directory))


def build_editable(
    wheel_directory: str,
    config_settings: Optional[Mapping[str, Any]] = None,
    metadata_directory: Optional[str] = None,
) -> str:
    with _progress():
        return str(maturin.build_editable(wheel_directory, config_settings, metadata_directory))
