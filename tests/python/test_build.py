"""The package's build says what it does: its build backend (crates/py/build_backend)
relays cargo's progress to the terminal, which pip, without -v, leaves silent; and keeps
the progress bar out of the output pip collects."""

import importlib.util
import os
import pty
import re
import select
import subprocess
import sys
import time
import zipfile
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
BACKEND = ROOT / "crates" / "py" / "build_backend" / "vworks_build.py"


def backend():
    spec = importlib.util.spec_from_file_location("vworks_build", BACKEND)
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_the_relay_keeps_lines_and_turns_the_bar_into_status_lines():
    forwarded, status = [], []
    relay = backend().Relay(forwarded.append, status.append, time.monotonic())
    # What cargo writes with `term.progress.when = "always"`, in arbitrary chunks.
    stream = (
        b"   Compiling c v0.1.0 (/tmp/c)\n"
        b"    Building [          ] 0/3: c                    \r"
        b"   Compiling b v0.1.0\n"
        b"    Building [=====>    ] 1/3: parry3d-f64, b(build)      \r"
        b"    Building [=====>    ] 1/3: parry3d-f64, b(build)      \r"
        b"warning: unused\n\n"
        b"    Finished `release` profile [optimized] target(s) in 1.2s\n"
        b"tail without a newline"
    )
    for i in range(0, len(stream), 7):
        relay.feed(stream[i : i + 7])
    relay.close()
    assert b"".join(forwarded) == (
        b"   Compiling c v0.1.0 (/tmp/c)\n"
        b"   Compiling b v0.1.0\n"
        b"warning: unused\n\n"
        b"    Finished `release` profile [optimized] target(s) in 1.2s\n"
        b"tail without a newline"
    )
    assert [re.sub(r", \d+m\d\ds", "", s) for s in status] == [
        "vworks: compiling the Rust extension: 0/3 steps; now c",
        "vworks: compiling the Rust extension: 1/3 steps; now parry3d-f64",  # once, not twice
    ]
    # While one crate compiles for minutes, the clock on the line moves.
    relay.start -= 61
    relay.refresh()
    assert re.fullmatch(r"vworks: compiling the Rust extension: 1/3 steps, 1m0[12]s; now parry3d-f64", status[-1])


@pytest.mark.oracle
def test_pip_wheel_shows_cargos_progress_on_the_terminal(tmp_path):
    """`pip wheel ./crates/py` (no -v) in a terminal: the backend's lines are there,
    cargo's own lines are not (pip kept them). Built with the dev profile, whose artifacts
    `maturin develop` left in cargo's target folder, so that the test takes seconds."""
    env = dict(os.environ)
    env["MATURIN_PEP517_ARGS"] = "--profile dev"
    env["PATH"] = f"{Path(sys.executable).parent}{os.pathsep}{env.get('PATH', '')}"  # maturin
    env.pop("VWORKS_BUILD_PROGRESS", None)
    pid, fd = pty.fork()  # the child's controlling terminal is the pty: its /dev/tty
    if pid == 0:  # pragma: no cover - the child
        os.chdir(ROOT)
        os.execve(
            sys.executable,
            [sys.executable, "-m", "pip", "wheel", "--no-deps", "--no-build-isolation",
             "--disable-pip-version-check", "-w", str(tmp_path), "./crates/py"],
            env,
        )
    chunks = []
    deadline = time.monotonic() + 900
    while time.monotonic() < deadline:
        ready, _, _ = select.select([fd], [], [], 5)
        if not ready:
            continue
        try:
            data = os.read(fd, 65536)
        except OSError:  # the child ended and closed the terminal
            break
        if not data:
            break
        chunks.append(data)
    _, status = os.waitpid(pid, 0)
    os.close(fd)
    out = b"".join(chunks).decode(errors="replace")
    assert os.waitstatus_to_exitcode(status) == 0, out
    assert "vworks: compiling the Rust extension; a release build takes minutes" in out, out
    assert re.search(r"vworks: the Rust extension built in \d+m\d\ds", out), out
    assert "   Compiling " not in out and "Finished `dev` profile" not in out, out
    (wheel,) = tmp_path.glob("vworks-*.whl")
    names = zipfile.ZipFile(wheel).namelist()
    assert "vworks/py.typed" in names and "vworks/_vworks.pyi" in names
