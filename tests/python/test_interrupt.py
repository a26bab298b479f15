"""Ctrl-C and threads: an endless program's `Cell.run()`, `Simulation.run_until()` and
`vworks.sweep()` end with KeyboardInterrupt on SIGINT (before, the process had to be
killed); a `Robot`'s `.joints` read while another thread steps its simulation raises
RuntimeError (before, pyo3's PanicException); `sweep(batch=...)` is checked."""

import pathlib
import signal
import subprocess
import sys
import textwrap
import threading
import warnings

import pytest

import vworks

# A program that never ends: time passes (a delay), so the engine never calls it a
# zero-time loop, and the run only ends when it is stopped.
ENDLESS = "proc main() { while true { delay 100ms; } }\n"


def endless_cell(tmp, program=ENDLESS):
    tmp = pathlib.Path(tmp)
    (tmp / "r1.wsl").write_text(program)
    (tmp / "cell.toml").write_text(
        'name = "endless"\n[[robot]]\nname = "r1"\nmodel = "turntable"\nprogram = "r1.wsl"\n'
    )
    return tmp / "cell.toml"


def interrupted(tmp, call):
    """Runs `call` (Python lines, with `cell` the endless cell's path) in a child process,
    sends it SIGINT once it is inside the call, and returns the child's exit status, stdout
    and stderr. The child prints `started` just before the call, and `returned` if the call
    returns: an interrupted call never does."""
    cell = endless_cell(tmp)
    script = f"import vworks\ncell = {str(cell)!r}\nprint('started', flush=True)\n{call}\nprint('returned', flush=True)\n"
    child = subprocess.Popen(
        [sys.executable, "-c", script],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )
    try:
        assert child.stdout is not None
        assert child.stdout.readline().strip() == "started"
        # Let it get into the call (a signal before it would be an ordinary
        # KeyboardInterrupt in Python).
        try:
            child.wait(timeout=1.0)
        except subprocess.TimeoutExpired:
            pass
        assert child.poll() is None, "the endless run ended by itself"
        child.send_signal(signal.SIGINT)
        # A guard, not a measurement: before the fix the child never ended on SIGINT.
        out, err = child.communicate(timeout=60)
    finally:
        if child.poll() is None:
            child.kill()
            child.communicate()
    assert "returned" not in out
    return child.returncode, out, err


def test_ctrl_c_ends_an_endless_cell_run_and_finishes_its_log(tmp_path):
    log = tmp_path / "run.mcap"
    code, _, err = interrupted(tmp_path, f"vworks.load_cell(cell).run(log={str(log)!r})")
    # An uncaught KeyboardInterrupt: Python ends by SIGINT.
    assert code == -signal.SIGINT, err
    assert "KeyboardInterrupt" in err, err
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # a damaged log would warn
        events = vworks.read_log(str(log))
    assert len(events) > 0 and events[0].robot == "r1"


def test_ctrl_c_ends_run_until_and_the_simulation_says_interrupted(tmp_path):
    call = textwrap.dedent(
        """
        sim = vworks.load_cell(cell).simulation()
        try:
            sim.run_until(1e9)
        except KeyboardInterrupt:
            r = sim.result()
            print("outcome", r.outcome, r.end_time > 0, flush=True)
            raise
        """
    )
    code, out, err = interrupted(tmp_path, call)
    assert code == -signal.SIGINT, err
    assert "KeyboardInterrupt" in err, err
    assert "outcome interrupted True" in out, (out, err)


def test_ctrl_c_ends_an_endless_sweep(tmp_path):
    code, _, err = interrupted(tmp_path, 'vworks.sweep(cell, {"cycle": ["4ms", "8ms", "10ms"]}, jobs=2)')
    assert code == -signal.SIGINT, err
    assert "KeyboardInterrupt" in err, err


def test_robot_joints_while_another_thread_steps_is_a_runtime_error(tmp_path):
    # Long enough that the reader meets the stepping thread: 100,000 delays.
    cell = endless_cell(tmp_path, "proc main() { for i in 0..100000 { delay 10ms; } }\n")
    sim = vworks.load_cell(str(cell)).simulation()
    robot = sim.robot("r1")
    stepping = threading.Thread(target=lambda: sim.run_until(1e6))
    errors = []
    stepping.start()
    try:
        while stepping.is_alive() and not errors:
            try:
                robot.joints
                robot.tcp
            except RuntimeError as e:
                errors.append(e)
    finally:
        stepping.join()
    assert errors, "the reads never met the stepping thread"
    assert "another thread is stepping this simulation" in str(errors[0])
    # Between steps the robot reads again.
    assert robot.joints.shape == (1,)


@pytest.mark.parametrize("batch", ["2", 2.0, True, [2]])
def test_sweep_batch_must_be_an_int(tmp_path, batch):
    cell = endless_cell(tmp_path, "proc main() { delay 10ms; }\n")
    with pytest.raises(TypeError, match="batch must be a whole number"):
        vworks.sweep(str(cell), {"cycle": ["4ms"]}, batch=batch)


@pytest.mark.parametrize("batch", [0, -3])
def test_sweep_batch_must_be_positive(tmp_path, batch):
    cell = endless_cell(tmp_path, "proc main() { delay 10ms; }\n")
    with pytest.raises(ValueError, match="batch must be 1 or more"):
        vworks.sweep(str(cell), {"cycle": ["4ms"]}, batch=batch)
