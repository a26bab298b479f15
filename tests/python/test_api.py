"""The `vworks` Python package: every name, with its error cases.

Built into the test virtualenv by scripts/test (`maturin develop`); the stub check
(`mypy.stubtest vworks`) runs there too.
"""

import inspect
import json
import math
import os
import pathlib
import subprocess
import tempfile
import threading
import time
import warnings

import numpy as np
import pytest

import vworks

ROOT = pathlib.Path(__file__).resolve().parents[2]
HANDOFF = ROOT / "workcells" / "handoff" / "cell.toml"
MAGIC = b"WSLB"  # the bytecode format's magic (crates/vm/src/bytecode/encode.rs)


def golden(name):
    """A golden trace's event lines and its `# outcome` line."""
    lines = (ROOT / "tests" / "golden" / f"{name}.trace").read_text().splitlines()
    return [l for l in lines if not l.startswith("#")], [l for l in lines if l.startswith("# outcome")]


def write_cell(tmp, programs, extra=""):
    """A one- or two-robot cell in `tmp` running `programs` (robot name → WSL source)."""
    tmp = pathlib.Path(tmp)
    toml = 'name = "t"\n' + extra
    for i, (name, source) in enumerate(programs.items()):
        (tmp / f"{name}.wsl").write_text(source)
        toml += f'[[robot]]\nname = "{name}"\nmodel = "irb120"\nprogram = "{name}.wsl"\n'
        toml += f'base = {{ xyz = ["{i * 2000}mm", "0mm", "0mm"] }}\n'
    (tmp / "cell.toml").write_text(toml)
    return tmp / "cell.toml"


# --- every public name is documented, and the package is what the stub says -------------


def test_every_public_name_has_a_docstring():
    for name in vworks.__all__:
        if name == "__version__":
            continue
        obj = getattr(vworks, name)
        assert (obj.__doc__ or "").strip(), name
        if inspect.isclass(obj) and not issubclass(obj, BaseException):
            for attr, member in vars(obj).items():
                if not attr.startswith("_"):
                    assert (member.__doc__ or "").strip(), f"{name}.{attr}"
    assert vworks.__version__.count(".") == 2


def test_exception_hierarchy():
    for e in (vworks.CompileError, vworks.LinkError, vworks.CellError, vworks.SimulationError):
        assert issubclass(e, vworks.Error)
    assert issubclass(vworks.Error, Exception)


# --- compile ------------------------------------------------------------------------------


def test_compile_gives_a_module():
    src = "global parts = 0;\nconst home = joints(0deg, 0deg, 0deg, 0deg, 30deg, 0deg);\n" \
          "func twice(x: int) -> int { return 2 * x; }\nproc main() { move_j home; parts = twice(parts); }\n"
    m = vworks.compile(src, "cell/r1.wsl")
    assert m.path == "cell/r1.wsl"
    assert m.globals == ["parts"]
    assert m.procs == ["twice", "main"]
    assert m.warnings == []
    listing = m.disasm()
    assert "move_j home;" in listing and "parts = twice(parts);" in listing
    assert m.to_bytes().startswith(MAGIC)
    assert "cell/r1.wsl" in repr(m)


def test_compile_default_path_and_warnings():
    m = vworks.compile("proc main() { var unused = 1; }")
    assert m.path == "x.wsl"
    assert all(isinstance(w, vworks.Diagnostic) and w.severity == "warning" for w in m.warnings)


def test_compile_error_carries_every_diagnostic():
    src = "proc main() {\n    delay 2;\n    x = 1;\n}\n"
    with pytest.raises(vworks.CompileError) as info:
        vworks.compile(src, "bad.wsl")
    diags = info.value.diagnostics
    assert len(diags) >= 2
    first = diags[0]
    assert (first.file, first.line, first.severity) == ("bad.wsl", 2, "error")
    assert first.code.startswith("E") and first.col > 0
    assert "write 2s" in (first.help or "") + first.rendered
    assert "bad.wsl:2:" in first.rendered and "^" in first.rendered
    assert str(first) == first.rendered
    assert "bad.wsl" in str(info.value)


RAPID = """MODULE Main
  ! A RAPID module: one PERS (the cell's global), a FUNC, a motion.
  PERS num nParts := 0;
  CONST robtarget pA := [[400,0,400],[0,1,0,0],[0,0,0,0],[9E9,9E9,9E9,9E9,9E9,9E9]];
  FUNC num Twice(num x)
    RETURN 2 * x;
  ENDFUNC
  PROC Main()
    MoveL Offs(pA, 0, 0, 100), v100, fine, tool0;
    nParts := Twice(nParts);
  ENDPROC
ENDMODULE
"""


def test_compile_rapid_by_language_or_by_extension():
    by_language = vworks.compile(RAPID, language="rapid")
    assert by_language.path == "x.mod"
    # RAPID names are case-insensitive: the WSL names are in lower case.
    assert by_language.globals == ["nparts"]
    assert by_language.procs == ["twice", "main"]
    assert "MoveL Offs(pA, 0, 0, 100), v100, fine, tool0;" in by_language.disasm()
    by_path = vworks.compile(RAPID, "cell/R1.MOD")
    assert by_path.to_bytes() != b"" and by_path.globals == ["nparts"]
    # The same text read as WSL does not compile.
    with pytest.raises(vworks.CompileError):
        vworks.compile(RAPID, "r1.wsl")
    with pytest.raises(ValueError, match="unknown language"):
        vworks.compile(RAPID, language="krl")


def test_compile_rapid_errors_name_the_rapid_line():
    src = "MODULE m\n  PROC main()\n    SearchL \\Stop, di1, p, p2, v100, tool0;\n  ENDPROC\nENDMODULE\n"
    with pytest.raises(vworks.CompileError) as info:
        vworks.compile(src, "r1.mod")
    first = info.value.diagnostics[0]
    assert (first.code, first.file, first.line, first.col) == ("E0300", "r1.mod", 3, 5)
    assert "SearchL" in first.message


def test_compile_files_makes_one_program_of_a_tasks_modules():
    main = "MODULE MainMod\n  PERS num nParts := 0;\n  PROC main()\n    Pick;\n  ENDPROC\nENDMODULE\n"
    tools = "MODULE Tools\n  PROC Pick()\n    WaitTime 0.5;\n    Incr nParts;\n  ENDPROC\nENDMODULE\n"
    m = vworks.compile_files([("main.mod", main), ("tools.mod", tools)])
    assert m.path == "main.mod" and m.files == ["main.mod", "tools.mod"]
    assert m.procs == ["main", "pick"] and m.globals == ["nparts"]
    listing = m.disasm()
    assert "; tools.mod:3:5" in listing and "| WaitTime 0.5;" in listing
    # Alone, the main module misses Pick; an error in the second file names it.
    with pytest.raises(vworks.CompileError):
        vworks.compile(main, "main.mod")
    with pytest.raises(vworks.CompileError) as info:
        vworks.compile_files([("main.mod", main), ("tools.mod", tools.replace("nParts", "nPart"))])
    first = info.value.diagnostics[0]
    assert (first.code, first.file, first.line, first.col) == ("E0010", "tools.mod", 4, 10)
    assert "tools.mod:4:10" in first.rendered
    with pytest.raises(ValueError, match="at least one"):
        vworks.compile_files([])
    with pytest.raises(ValueError, match="one language"):
        vworks.compile_files([("main.mod", main), ("lib.wsl", "proc f() {}\n")])


def test_a_rapid_cell_runs_from_python():
    r = vworks.load_cell(str(ROOT / "workcells/rapid_handoff/cell.toml")).run()
    assert r.outcome == "completed"
    assert r.end_time == pytest.approx(45.384, abs=5e-4)


# --- load_cell and run --------------------------------------------------------------------


def test_the_readme_line():
    assert vworks.load_cell(str(HANDOFF)).run().end_time == pytest.approx(46.491264457)


def test_cell_properties():
    cell = vworks.load_cell(HANDOFF)
    assert cell.name == "handoff"
    assert isinstance(cell.file, pathlib.Path) and cell.file.name == "cell.toml"
    assert cell.robots == ["r1", "r2"]
    assert cell.cycle == pytest.approx(0.004)
    assert cell.parts == ["part1"]
    assert isinstance(cell.devices, list)
    assert "handoff" in repr(cell)


@pytest.mark.parametrize("name", ["handoff", "weldline", "monitor", "crash", "deadlock", "track", "palletize"])
def test_run_matches_the_golden_trace(name):
    result = vworks.load_cell(ROOT / "workcells" / name / "cell.toml").run()
    lines, outcome = golden(name)
    assert [e.trace_line() for e in result.events] == lines
    assert outcome == [f"# outcome {result.outcome} at {result.end_time_ns} ns"]


def test_result_fields():
    r = vworks.load_cell(HANDOFF).run()
    assert r.outcome == "completed"
    assert r.end_time == pytest.approx(r.end_time_ns / 1e9)
    assert r.cycles > 11000
    r1, r2 = r.robots
    assert (r1.name, r2.name) == ("r1", "r2")
    assert r1.end_time == pytest.approx(46.491264457) and r1.ended == "ended"
    assert r1.moving + r1.waiting + r1.idle == pytest.approx(r.end_time, abs=1e-6)
    assert r1.motions == 41 and not hasattr(r1, "handler")
    assert r.globals == {"handed": 3}
    assert r.collisions == [] and r.errors == []
    assert isinstance(r.warnings, list)
    assert r.log_counts == {} and r.log_error is None
    events = r.events
    assert len(events) == 187
    e = events[0]
    assert isinstance(e, vworks.Event) and e.time == e.time_ns / 1e9
    assert events[-1].trace_line() == list(events)[-1].trace_line()
    assert [x.kind for x in events[:3]] == [x.kind for x in list(events)[:3]]
    assert len(events[::2]) == 94
    with pytest.raises(IndexError):
        events[1000]
    assert "completed" in repr(r)


def test_logs_are_the_programs_log_lines(tmp_path):
    """By hand (docs/language.md, docs/engine.md "One instant, one serial order"): r1 logs
    at 0 s and after its 1.5 s delay and set; r2, released by that set, logs after r1."""
    cell = write_cell(
        tmp_path,
        {
            "r1": 'global go = false;\nproc main() {\n    log "r1 begins";\n    delay 1500ms;\n'
            '    go = true;\n    log "r1 done";\n}\n',
            "r2": 'global go = false;\nproc main() {\n    wait_until go;\n'
            '    log "r2 released after ", 1500ms;\n}\n',
        },
    )
    r = vworks.load_cell(cell).run()
    got = [(l.time_ns, l.robot, l.text, pathlib.Path(l.file).name, l.line, l.col) for l in r.logs]
    assert got == [
        (0, "r1", "r1 begins", "r1.wsl", 3, 5),
        (1_500_000_000, "r1", "r1 done", "r1.wsl", 6, 5),
        (1_500_000_000, "r2", "r2 released after 1.5s", "r2.wsl", 4, 5),
    ]
    assert all(isinstance(l, vworks.LogLine) and l.time == l.time_ns / 1e9 for l in r.logs)
    assert r.to_dict()["logs"][2]["text"] == "r2 released after 1.5s"
    assert "r2 released" in repr(r.logs[2])


def test_a_collision_names_each_robots_motion():
    """workcells/crash: both arms reach for each other with their one move_j (line 3)."""
    r = vworks.load_cell(ROOT / "workcells" / "crash" / "cell.toml").run()
    (c,) = r.collisions
    statement = "move_j joints(0deg, 60deg, -30deg, 0deg, 30deg, 0deg) speed 50%;"
    assert [(m.robot, m.moving, pathlib.Path(m.file).name, m.line, m.col, m.statement) for m in c.motions] == [
        ("left", True, "left.wsl", 3, 5, statement),
        ("right", True, "right.wsl", 3, 5, statement),
    ]
    assert c.motions[0].describe() == f"left moving: left.wsl:3:5 {statement}"
    (near,) = [w for w in r.warnings if w.kind == "near_miss"]
    assert [m.robot for m in near.motions] == ["left", "right"]
    assert (near.robot, pathlib.Path(near.file).name, near.line) == ("left", "left.wsl", 3)
    assert r.to_dict()["collisions"][0]["motions"][1]["statement"] == statement


def test_events_to_pandas():
    import pandas as pd  # installed in the test environment (requirements-dev.txt)

    df = vworks.load_cell(HANDOFF).run(until=5.0).events.to_pandas()
    assert list(df.columns) == ["time", "time_ns", "robot", "kind", "details", "file", "line", "col"]
    assert len(df) > 10 and (df["kind"] == "motion_start").any()
    assert isinstance(df, pd.DataFrame)


def test_run_until_and_a_log(tmp_path):
    cell = vworks.load_cell(HANDOFF)
    log = tmp_path / "run.mcap"
    r = cell.run(until=5, log=log, log_every=10)
    assert r.outcome == "until" and r.end_time_ns == 5_000_000_000
    assert r.log_counts["/events"] == len(r.events)
    assert r.log_counts["/state"] == -(-r.cycles // 10)
    read = vworks.read_log(log)
    assert [e.trace_line() for e in read] == [e.trace_line() for e in r.events]
    # The typed details come back from the log as the run gave them.
    assert [e.data for e in read] == [e.data for e in r.events]
    # A cell runs again from the start, the same way.
    again = cell.run(until=5)
    assert [e.trace_line() for e in again.events] == [e.trace_line() for e in r.events]


def test_to_dict_is_the_run_json():
    r = vworks.load_cell(HANDOFF).run(until=5)
    d = r.to_dict()
    # The same object `vworks run --json` prints (one RunResult::to_json in Rust).
    assert d["outcome"] == "until" and d["end_time_ns"] == 5_000_000_000
    assert d["globals"] == r.globals and d["events"] == len(r.events)
    assert [x["name"] for x in d["robots"]] == [s.name for s in r.robots]
    assert [x["idle_ns"] / 1e9 for x in d["robots"]] == pytest.approx([s.idle for s in r.robots])
    assert d["log"] is None
    exe = os.environ.get("VWORKS")
    if exe:  # scripts/test sets it to the binary it just built
        out = subprocess.run([exe, "run", str(HANDOFF), "--until", "5s", "--json"],
                             capture_output=True, text=True, check=True).stdout
        assert json.loads(out) == d


def test_events_carry_typed_data():
    r = vworks.load_cell(HANDOFF).run()
    sets = [e.data for e in r.events if e.kind == "set"]
    # handoff's r1 counts three parts handed over: 0 → 1 → 2 → 3, as ints.
    assert sets == [{"global": "handed", "old": n, "new": n + 1} for n in range(3)]
    motion = next(e for e in r.events if e.kind == "motion_start")
    assert motion.data["command"] in ("move_j", "move_l", "move_c")
    assert motion.data["duration_ns"] == int(motion.details.split("duration=")[1])
    assert next(e for e in r.events if e.kind == "end").data is None


def test_collision_and_deadlock_are_results_not_exceptions():
    crash = vworks.load_cell(ROOT / "workcells" / "crash" / "cell.toml").run()
    assert crash.outcome == "collision"
    (c,) = crash.collisions
    assert {c.a, c.b} == {"left.link_6", "right.link_6"}
    # Found between two 4 ms boundaries (368 and 372 ms) by the sweep, at first contact.
    assert c.depth >= 0 and len(c.point) == 3 and 0.310 < c.time < 0.315
    dead = vworks.load_cell(ROOT / "workcells" / "deadlock" / "cell.toml").run()
    assert dead.outcome == "deadlock" and dead.errors[0].kind == "deadlock"


def test_runtime_error_raises_simulation_error(tmp_path):
    path = write_cell(tmp_path, {"r1": 'proc main() {\n    delay 0.1s;\n    fail "gripper empty";\n}\n'})
    cell = vworks.load_cell(path)
    with pytest.raises(vworks.SimulationError) as info:
        cell.run()
    err = info.value
    assert (err.robot, pathlib.Path(err.file).name, err.line, err.col) == ("r1", "r1.wsl", 3, 5)
    assert "gripper empty" in str(err)
    assert err.result.outcome == "error" and err.result.errors[0].kind == "runtime"
    r = cell.run(check=False)
    assert r.outcome == "error" and r.robots[0].ended == "error"


def test_load_cell_errors(tmp_path):
    with pytest.raises(vworks.CellError, match="nope.toml"):
        vworks.load_cell(tmp_path / "nope.toml")
    (tmp_path / "bad.toml").write_text('[[robot]]\nname = "r1"\nmodel = "irb9999"\nprogram = "r1.wsl"\n')
    (tmp_path / "r1.wsl").write_text("proc main() { }\n")
    with pytest.raises(vworks.CellError, match="irb9999"):
        vworks.load_cell(tmp_path / "bad.toml")
    bad = write_cell(tmp_path, {"r1": "proc main() {\n    delay 2;\n}\n"})
    with pytest.raises(vworks.CompileError) as info:
        vworks.load_cell(bad)
    (d,) = [d for d in info.value.diagnostics if d.severity == "error"]
    assert pathlib.Path(d.file).name == "r1.wsl" and d.line == 2
    assert "delay 2;" in d.rendered


def test_link_error(tmp_path):
    path = write_cell(
        tmp_path,
        {"r1": "global g = 0;\nproc main() { g = 1; }\n", "r2": "global g = 1;\nproc main() { g = 2; }\n"},
    )
    with pytest.raises(vworks.LinkError) as info:
        vworks.load_cell(path)
    assert info.value.diagnostics and info.value.diagnostics[0].code.startswith("E01")
    assert "g" in str(info.value)


def test_bad_arguments(tmp_path):
    cell = vworks.load_cell(HANDOFF)
    with pytest.raises(ValueError, match="until"):
        cell.run(until=-1)
    with pytest.raises(ValueError, match="until"):
        cell.run(until=math.nan)
    with pytest.raises(ValueError, match="log_every"):
        cell.run(log=tmp_path / "x.mcap", log_every=0)
    with pytest.raises(vworks.Error, match="no such dir"):
        cell.run(log=tmp_path / "no such dir" / "x.mcap")


# --- stepping ---------------------------------------------------------------------------


def test_simulation_steps_and_state():
    cell = vworks.load_cell(HANDOFF)
    sim = cell.simulation()
    assert sim.time == 0 and sim.outcome is None and sim.robots == ["r1", "r2"]
    r1 = sim.robot("r1")
    assert r1.name == "r1"
    assert sim.step_event()
    first = sim.events_since(0)
    assert len(first) >= 1
    assert sim.step_cycle()
    assert sim.time_ns % 4_000_000 == 0 and sim.time_ns > 0
    assert sim.run_until(2.0) and sim.time == 2.0
    q = r1.joints
    assert isinstance(q, np.ndarray) and q.shape == (6,) and q.dtype == np.float64
    tcp = r1.tcp
    assert tcp.shape == (4, 4) and np.allclose(tcp[3], [0, 0, 0, 1])
    assert np.allclose(tcp[:3, :3] @ tcp[:3, :3].T, np.eye(3), atol=1e-12)
    # The robot is moving at 2 s: its joints change by 2.5 s.
    seen = len(sim.events_since(0))
    sim.run_until(2.5)
    assert not np.allclose(r1.joints, q)
    new = sim.events_since(seen)
    assert [e.trace_line() for e in new] == [e.trace_line() for e in sim.events_since(0)[seen:]]
    g = sim.globals
    assert dict(g) == {"handed": 0}
    with pytest.raises(TypeError):
        g["handed"] = 5  # read-only
    with pytest.raises(KeyError, match="r3"):
        sim.robot("r3")
    with pytest.raises(ValueError):
        sim.run_until(-1)


def test_stepping_gives_the_same_run_as_run():
    cell = vworks.load_cell(HANDOFF)
    sim = cell.simulation()
    steps = 0
    while sim.step_cycle():
        steps += 1
    assert sim.outcome == "completed" and steps > 11000
    assert sim.globals["handed"] == 3
    stepped = [e.trace_line() for e in sim.events_since()]
    assert stepped == golden("handoff")[0]
    r = sim.result()
    assert r.outcome == "completed" and r.end_time_ns == 46_491_264_457
    assert sim.result() is r
    with pytest.raises(vworks.Error, match="ended"):
        sim.step_event()
    assert sim.time == r.end_time


def test_simulation_run_and_early_result():
    cell = vworks.load_cell(HANDOFF)
    assert cell.simulation().run().end_time_ns == 46_491_264_457
    sim = cell.simulation()
    sim.run_until(10)
    early = sim.result()
    assert early.end_time == 10 and early.robots[0].end_time <= 10


def test_stepping_into_a_runtime_error_raises(tmp_path):
    path = write_cell(tmp_path, {"r1": 'proc main() {\n    delay 0.1s;\n    fail "gripper empty";\n}\n'})
    sim = vworks.load_cell(path).simulation()
    with pytest.raises(vworks.SimulationError) as info:
        while sim.step_event():
            pass
    assert info.value.robot == "r1" and info.value.line == 3
    assert sim.outcome == "error"


def test_the_gil_is_released_while_simulating():
    # Another Python thread keeps running while a long run simulates.
    cell = vworks.load_cell(HANDOFF)
    ticks = []
    done = threading.Event()

    def tick():
        while not done.is_set():
            ticks.append(time.perf_counter())
            time.sleep(0.0005)

    t = threading.Thread(target=tick)
    t.start()
    time.sleep(0.01)  # the ticker is running
    start = time.perf_counter()
    cell.run()  # one call: were the GIL held, the ticker could not run until it returned
    end = time.perf_counter()
    done.set()
    t.join()
    during = [x for x in ticks if start < x < end]
    assert len(during) >= 10, f"{len(during)} ticks while simulating for {end - start:.3f} s"


# --- read_log -----------------------------------------------------------------------------


def test_read_log_errors_and_a_cut_log(tmp_path):
    with pytest.raises(vworks.Error, match="cannot read"):
        vworks.read_log(tmp_path / "missing.mcap")
    (tmp_path / "notes.mcap").write_text("hello")
    with pytest.raises(vworks.Error, match="not an MCAP file"):
        vworks.read_log(tmp_path / "notes.mcap")
    log = tmp_path / "run.mcap"
    full = vworks.load_cell(HANDOFF).run(log=log)
    data = log.read_bytes()
    cut = tmp_path / "cut.mcap"
    cut.write_bytes(data[: len(data) // 2])
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        part = vworks.read_log(cut)
    assert any(issubclass(w.category, RuntimeWarning) and "unfinished" in str(w.message) for w in caught)
    assert 20 < len(part) < len(full.events)
    assert [e.trace_line() for e in part] == [e.trace_line() for e in full.events][: len(part)]


def test_warnings_are_issues():
    r = vworks.load_cell(ROOT / "workcells" / "crash" / "cell.toml").run()
    (w,) = r.warnings
    assert isinstance(w, vworks.Issue)
    assert w.kind == "near_miss" and "left.link_6 and right.link_6" in w.message
    # Its place is the first moving robot's motion (both move: left's), no longer unknown.
    assert (w.robot, pathlib.Path(w.file).name, w.line, w.col) == ("left", "left.wsl", 3, 5)
    assert "near_miss" in repr(w)
    # The message rounds to hundredths of a millimetre; the distance is exact.
    assert "come within 0.69 mm" in w.message
    assert w.distance_m is not None and abs(w.distance_m - 0.000688038101) < 1e-11


def test_compile_and_link_warnings_are_in_the_result(tmp_path):
    (tmp_path / "r1.wsl").write_text("global g = 0;\nproc main() {\n    var g = 1;\n    log g;\n}\n")
    (tmp_path / "cell.toml").write_text('[[robot]]\nname = "r1"\nmodel = "turntable"\nprogram = "r1.wsl"\n')
    r = vworks.load_cell(tmp_path / "cell.toml").run()
    (w,) = r.warnings
    assert (w.kind, w.line, w.col) == ("W0001", 3, 9)
    assert w.file is not None and w.file.endswith("r1.wsl")
    assert w.distance_m is None


def test_to_pandas_without_pandas_says_what_to_install(monkeypatch):
    import sys

    events = vworks.load_cell(HANDOFF).run(until=1.0).events
    monkeypatch.setitem(sys.modules, "pandas", None)  # `import pandas` now fails
    with pytest.raises(ImportError, match="pip install pandas"):
        events.to_pandas()


@pytest.mark.skipif(not pathlib.Path("/dev/full").exists(), reason="needs Linux's /dev/full")
def test_a_log_that_cannot_be_written():
    cell = vworks.load_cell(HANDOFF)
    with pytest.raises(vworks.Error, match="No space left on device"):
        cell.run(until=1.0, log="/dev/full")
    r = cell.run(until=1.0, log="/dev/full", check=False)
    assert r.outcome == "until" and "/dev/full" in r.log_error and r.log_counts == {}


def test_zones_reach_python_and_stepping_sees_the_corner():
    # palletize flies by its approach points: a zoned motion_end carries its zone, the
    # next motion_start the radius it blends within, and between them the robot moves on.
    cell = vworks.load_cell(ROOT / "workcells" / "palletize" / "cell.toml")
    r = cell.run()
    ends = [e for e in r.events if e.kind == "motion_end" and e.data is not None]
    assert ends and all(e.data["zone_m"] <= e.data["programmed_m"] for e in ends)
    assert ends[0].data == {"zone_m": 0.02, "programmed_m": 0.02}
    starts = [e for e in r.events if e.kind == "motion_start" and "blend_m" in (e.data or {})]
    assert starts and all(0.0 <= e.data["blend_m"] <= 0.05 + 1e-9 for e in starts)
    # Stepping: just after the first zoned motion_end the robot has not stopped.
    sim = cell.simulation()
    while not any(e.kind == "motion_end" and e.data for e in sim.events_since(0)):
        assert sim.step_event()
    t = sim.time
    q = sim.robot("r1").joints
    sim.run_until(t + 0.004)
    assert not np.allclose(sim.robot("r1").joints, q)
    # Moving time runs through the corners: the robot never idles in this cell.
    (r1,) = r.to_dict()["robots"]
    assert r1["idle_ns"] == 0 and r1["moving_ns"] == r1["end_time_ns"]
