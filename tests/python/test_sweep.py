"""`vworks.sweep` and `vworks sweep`: many variants of a workcell, on this machine, on a
local Ray cluster and on a Dask LocalCluster (both on 127.0.0.1 with 2 CPUs), giving the
same table row for row; the CLI's table equal to Python's; the table (`SweepTable`) works
without pandas, and `to_pandas()` makes the DataFrame."""

import csv
import math
import os
import re
import subprocess
import sys
from pathlib import Path

import pytest

import vworks
from browser import Browser

ROOT = Path(__file__).resolve().parents[2]
VWORKS = os.environ.get("VWORKS", str(ROOT / "target" / "debug" / "vworks"))
CELL = str(ROOT / "workcells" / "handoff" / "cell.toml")

# 40 variants: r2's base (and the params that tell its program where it stands) on a 5 x 4
# grid, with two cycle periods.
VARIABLES = {
    ("robot.r2.base.xyz.0", "robot.r2.params.base_x"): ["250mm", "400mm", "500mm", "600mm", "650mm"],
    ("robot.r2.base.xyz.1", "robot.r2.params.base_y"): [0.25, 0.5, 0.55, 0.6],
    "cycle": ["4ms", "8ms"],
}


@pytest.fixture(scope="module")
def local():
    return vworks.sweep(CELL, VARIABLES)


COLUMNS = [
    "variant", "robot.r2.base.xyz.0", "robot.r2.base.xyz.1", "cycle", "outcome", "end_time",
    "cycle_time.r1", "cycle_time.r2", "collisions", "min_clearance", "error",
]


def test_the_local_table_has_every_variant_and_outcome(local):
    assert isinstance(local, vworks.SweepTable)
    assert len(local) == 40
    assert local.columns == COLUMNS
    assert local["variant"] == list(range(40))
    # The first variable changes slowest; values are SI numbers.
    assert local["robot.r2.base.xyz.0"][:8] == [0.25] * 8
    assert local["cycle"][:2] == [0.004, 0.008]
    outcomes = set(local["outcome"])
    assert {"completed", "collision"} <= outcomes, outcomes
    # The workcell as written (r2 at 600, 600 mm, 4 ms) ends at 46.491 s, as `vworks run`.
    (base,) = [r for r in local if (r["robot.r2.base.xyz.0"], r["robot.r2.base.xyz.1"], r["cycle"]) == (0.6, 0.6, 0.004)]
    assert round(base["end_time"], 6) == 46.491264
    assert base["outcome"] == "completed" and base["collisions"] == 0 and base["error"] == ""
    assert base["min_clearance"] is None  # no two bodies came within the cell's clearance
    collided = [r for r in local if r["outcome"] == "collision"]
    assert all(r["collisions"] >= 1 and r["min_clearance"] == 0 for r in collided)


def test_the_table_as_a_dataframe(local):
    import pandas as pd

    df = local.to_pandas()
    assert isinstance(df, pd.DataFrame) and list(df.columns) == COLUMNS and len(df) == 40
    assert df["end_time"].tolist() == local["end_time"]
    assert df.dtypes["end_time"] == "float64" and df.dtypes["variant"] == "int64"
    best = df[(df.outcome == "completed") & (df.collisions == 0)].nsmallest(3, "end_time")
    assert best["end_time"].tolist() == sorted(
        r["end_time"] for r in local if r["outcome"] == "completed" and r["collisions"] == 0
    )[:3]
    # Empty entries (no clearance measured) are NaN in pandas.
    empty = local["min_clearance"].count(None)
    assert 0 < empty < 40 and df["min_clearance"].isna().sum() == empty


def test_the_table_as_plain_python(local):
    row = local[0]
    assert list(row) == COLUMNS and row["variant"] == 0
    assert local[-1]["variant"] == 39 and local.rows[-1][0] == 39
    assert local.to_dicts()[5] == local[5] == dict(zip(COLUMNS, local.rows[5]))
    assert local.column("cycle") == local["cycle"]
    with pytest.raises(KeyError, match="no column 'speed'; the columns are variant, "):
        local["speed"]
    with pytest.raises(IndexError):
        local[40]
    with pytest.raises(TypeError, match="a column name or a row number"):
        local[1.5]
    assert "40 variants" in repr(local) and "end_time" in repr(local)
    # The table's parts are copies: changing them changes nothing.
    local.columns.append("x")
    local.rows.clear()
    assert local.columns == COLUMNS and len(local.rows) == 40
    assert local != local.to_dicts() and local == vworks.SweepTable(COLUMNS, local.rows)
    assert local != vworks.SweepTable(COLUMNS, local.rows[:-1])
    with pytest.raises(ValueError, match="a row of 2 values in a table of 11 columns"):
        vworks.SweepTable(COLUMNS, [(1, 2)])


def test_the_same_with_one_thread(local):
    assert vworks.sweep(CELL, VARIABLES, jobs=1) == local


def test_a_local_sweep_needs_no_pandas():
    # A process where pandas cannot be imported (as after `pip install vworks`): the sweep
    # runs and returns its table; only to_pandas() asks for pandas.
    code = (
        "import sys; sys.modules['pandas'] = None\n"
        "import vworks\n"
        f"t = vworks.sweep({CELL!r}, {{'cycle': ['4ms', '8ms']}}, until=1.0)\n"
        "print(len(t), t['outcome'], t['end_time'])\n"
        "try:\n"
        "    t.to_pandas()\n"
        "except ImportError as e:\n"
        "    print(e)\n"
        "print(sys.modules['pandas'])\n"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert out.returncode == 0, out.stderr
    lines = out.stdout.splitlines()
    assert lines[0] == "2 ['until', 'until'] [1.0, 1.0]", out.stdout
    assert lines[1] == "SweepTable.to_pandas needs pandas: pip install pandas (or 'vworks[pandas]')"
    assert lines[2] == "None"  # nothing replaced the block: pandas was never imported


@pytest.mark.oracle
def test_a_local_ray_cluster_gives_the_same_table(local):
    import ray
    ray.init(address="local", num_cpus=2, include_dashboard=False, _node_ip_address="127.0.0.1",
             log_to_driver=False)
    try:
        assert ray.cluster_resources()["CPU"] == 2
        remote = vworks.sweep(CELL, VARIABLES, backend="ray")
        assert remote == local
        # Small batches: many tasks, the same rows in the same order.
        assert vworks.sweep(CELL, VARIABLES, backend="ray", batch=3) == local
    finally:
        ray.shutdown()


@pytest.mark.oracle
def test_a_dask_local_cluster_gives_the_same_table(local):
    from dask.distributed import Client, LocalCluster

    with LocalCluster(n_workers=2, threads_per_worker=1, host="127.0.0.1", dashboard_address=None,
                      processes=True) as cluster, Client(cluster):
        assert vworks.sweep(CELL, VARIABLES, backend="dask") == local


def test_the_cli_writes_the_same_table(local, tmp_path):
    sweep = tmp_path / "sweep.toml"
    (tmp_path / "cell.toml").write_text(Path(CELL).read_text())
    for f in ("r1.wsl", "r2.wsl"):
        (tmp_path / f).write_text((ROOT / "workcells" / "handoff" / f).read_text())
    sweep.write_text(
        'cell = "cell.toml"\n'
        '[[variable]]\npath = ["robot.r2.base.xyz.0", "robot.r2.params.base_x"]\n'
        'values = ["250mm", "400mm", "500mm", "600mm", "650mm"]\n'
        '[[variable]]\npath = ["robot.r2.base.xyz.1", "robot.r2.params.base_y"]\n'
        'values = [0.25, 0.5, 0.55, 0.6]\n'
        '[[variable]]\npath = "cycle"\nvalues = ["4ms", "8ms"]\n'
    )
    out = subprocess.run([VWORKS, "sweep", str(sweep), "--jobs", "2", "--best", "3"], capture_output=True,
                         text=True)
    assert out.returncode == 0, out.stderr
    assert "40 variants in" in out.stderr
    assert out.stdout.startswith("best by end_time (completed, no collision):")
    with open(tmp_path / "sweep.csv") as f:
        rows = list(csv.DictReader(f))
    assert len(rows) == 40
    # The file states units: x was written in mm (shown so); y in plain SI numbers (no
    # unit); times in s. The Python table keeps SI numbers under the bare names.
    assert list(rows[0])[:6] == ["variant", "robot.r2.base.xyz.0 [mm]", "robot.r2.base.xyz.1", "cycle [ms]",
                                 "outcome", "end_time [s]"]
    for row, want in zip(rows, local):
        assert row["outcome"] == want["outcome"]
        assert float(row["end_time [s]"]) == want["end_time"]
        assert float(row["robot.r2.base.xyz.0 [mm]"]) == pytest.approx(want["robot.r2.base.xyz.0"] * 1000, abs=1e-9)
        assert float(row["robot.r2.base.xyz.1"]) == want["robot.r2.base.xyz.1"]
        assert float(row["cycle [ms]"]) == pytest.approx(want["cycle"] * 1000, abs=1e-12)
    page = (tmp_path / "sweep.html").read_text()
    assert '<svg id="chart"' in page and "class=\"cell\"" in page  # a heatmap over two variables


def test_a_list_of_variants_and_bad_input():
    table = vworks.sweep(CELL, [{"cycle": "4ms"}, {"cycle": "8ms", "clearance": 0.01}], until=5.0)
    assert table.columns[:3] == ["variant", "cycle", "clearance"]
    assert table["outcome"] == ["until", "until"]
    assert table["clearance"] == [None, 0.01]
    assert table.to_pandas()["clearance"].isna().tolist() == [True, False]
    with pytest.raises(vworks.CellError, match=r"robot\.r3\.base\.xyz\.0: not a value of this workcell; the nearest are .*robot\.r1\.base\.xyz\.0"):
        vworks.sweep(CELL, {"robot.r3.base.xyz.0": [0.5]})
    with pytest.raises(ValueError, match="not a number, a string with a unit or a bool"):
        vworks.sweep(CELL, {"cycle": [[4]]})
    with pytest.raises(ValueError, match="backend is 'local', 'ray' or 'dask'"):
        vworks.sweep(CELL, {"cycle": ["4ms"]}, backend="spark")
    # A value the workcell does not accept there: a row that says why.
    bad = vworks.sweep(CELL, {"robot.r2.base.xyz.0": ["tall"]})
    assert bad["outcome"] == ["invalid"] and "tall" in str(bad["error"][0])


def test_until_zero_is_the_start_for_a_run_and_a_sweep_alike(tmp_path):
    # Cell.run took until=0 while a sweep refused it: both now stop at the start, as
    # `vworks run --until 0s` and a sweep file's `until = "0s"` do.
    r = vworks.load_cell(CELL).run(until=0)
    assert (r.outcome, r.end_time_ns) == ("until", 0)
    table = vworks.sweep(CELL, [{"cycle": "4ms"}, {"cycle": "8ms"}], until=0)
    assert table["outcome"] == ["until", "until"] and table["end_time"] == [0.0, 0.0]
    for bad in (-1, math.nan, math.inf):
        with pytest.raises(ValueError, match="until"):
            vworks.load_cell(CELL).run(until=bad)
        with pytest.raises(ValueError, match="until"):
            vworks.sweep(CELL, [{"cycle": "4ms"}], until=bad)
    sweep_file = tmp_path / "s.toml"
    sweep_file.write_text(f'cell = "{CELL}"\nuntil = "0s"\n[[variable]]\npath = "cycle"\nvalues = ["4ms", "8ms"]\n')
    out = tmp_path / "t.csv"
    subprocess.run([VWORKS, "sweep", str(sweep_file), "-q", "-o", str(out)], check=True, capture_output=True)
    assert [row["outcome"] for row in csv.DictReader(out.open())] == ["until", "until"]


def test_the_package_imports_without_ray_or_dask():
    code = (
        "import sys; sys.modules['ray'] = None; sys.modules['dask'] = None\n"
        "import vworks\n"
        "try:\n"
        f"    vworks.sweep({CELL!r}, {{'cycle': ['4ms']}}, backend='ray')\n"
        "except ImportError as e:\n"
        "    print(e)\n"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert out.returncode == 0, out.stderr
    assert "pip install 'vworks[ray]'" in out.stdout


def test_keep_logs_writes_each_variants_log_with_its_values(tmp_path):
    from mcap.reader import make_reader

    sweep = tmp_path / "sweep.toml"
    sweep.write_text(
        f'cell = "{CELL}"\nuntil = "2s"\n[[variable]]\npath = "robot.r2.base.xyz.0"\nvalues = ["600mm", 0.65]\n'
    )
    logs = tmp_path / "logs"
    out = subprocess.run([VWORKS, "sweep", str(sweep), "--keep-logs", str(logs), "-o", str(tmp_path / "t.jsonl")],
                         capture_output=True, text=True)
    assert out.returncode == 0, out.stderr
    assert sorted(p.name for p in logs.iterdir()) == ["variant-00000.mcap", "variant-00001.mcap"]
    with open(logs / "variant-00001.mcap", "rb") as f:
        (meta,) = [m for m in make_reader(f).iter_metadata() if m.name == "vworks"]
    assert meta.metadata["overrides"] == "robot.r2.base.xyz.0 = 0.65"
    lines = (tmp_path / "t.jsonl").read_text().splitlines()
    # 0.65 (SI) in the column of "600mm": 650 mm.
    assert len(lines) == 2 and lines[1].startswith('{"variant":1,"robot.r2.base.xyz.0 [mm]":650.0,"outcome":"until"')


@pytest.fixture(scope="module")
def browser(tmp_path_factory):
    with Browser(tmp_path_factory.mktemp("chromium")) as b:
        yield b


def open_page(b, page):
    """Opens `page` in Chromium with this load's events only."""
    b.events.clear()
    b.open("about:blank")
    b.events.clear()
    b.open(page.as_uri())
    b.frames(2)


def clean(b, page):
    """No console error or exception, and no request but the page itself."""
    assert b.errors() == []
    assert set(b.requests()) <= {page.as_uri(), "about:blank"}, b.requests()


def handoff_in(tmp_path, sweep_text):
    """The handoff cell copied into `tmp_path` with a sweep file; runs `vworks sweep` and
    returns (the table's rows, the page's path)."""
    for f in ("cell.toml", "r1.wsl", "r2.wsl"):
        (tmp_path / f).write_text((ROOT / "workcells" / "handoff" / f).read_text())
    (tmp_path / "sweep.toml").write_text(sweep_text)
    out = subprocess.run([VWORKS, "sweep", str(tmp_path / "sweep.toml"), "-q"], capture_output=True, text=True)
    assert out.returncode == 0, out.stderr
    with open(tmp_path / "sweep.csv") as f:
        rows = list(csv.DictReader(f))
    return rows, tmp_path / "sweep.html"


def boxes(b, selector):
    """The rendered boxes (x, y, width, height) of the elements matching `selector`."""
    return b.eval(
        f"Array.from(document.querySelectorAll({selector!r})).map(function (e) {{"
        " var r = e.getBoundingClientRect(); return [r.x, r.y, r.width, r.height]; })"
    )


def texts(b, selector):
    return b.eval(f"Array.from(document.querySelectorAll({selector!r})).map(function (e) {{ return e.textContent; }})")


def test_the_heatmap_has_labelled_axes_a_colour_bar_and_a_legend(browser, tmp_path):
    """The heatmap had no colour scale, no legend for red and grey, no ticks: in Chromium,
    its axes are titled with their units and ticked with each value as written, the colour
    bar spans the best end times, and the legend explains every colour, with counts that
    match the table."""
    xs, ys = ["250mm", "500mm", "600mm"], ["250mm", "450mm", "600mm"]
    rows, page = handoff_in(
        tmp_path,
        'cell = "cell.toml"\n'
        f'[[variable]]\npath = ["robot.r2.base.xyz.0", "robot.r2.params.base_x"]\nvalues = {xs!r}\n'.replace("'", '"')
        + f'[[variable]]\npath = ["robot.r2.base.xyz.1", "robot.r2.params.base_y"]\nvalues = {ys!r}\n'.replace("'", '"'),
    )
    assert len(rows) == 9
    open_page(browser, page)
    clean(browser, page)
    # Axes: titles with units, a tick per value, as written (without the unit), in order.
    assert texts(browser, "#x-title") == ["robot.r2.base.xyz.0 [mm]"]
    assert texts(browser, "#y-title") == ["robot.r2.base.xyz.1 [mm]"]
    assert texts(browser, ".x-tick text") == [v.removesuffix("mm") for v in xs]
    assert sorted(texts(browser, ".y-tick text"), key=float) == [v.removesuffix("mm") for v in ys]
    x_ticks = boxes(browser, ".x-tick text")
    assert all(w > 0 and h > 0 for _, _, w, h in x_ticks)
    assert [x for x, *_ in x_ticks] == sorted(x for x, *_ in x_ticks)
    # Left to right, each tick's label lies under its column of cells.
    cells = boxes(browser, "rect.cell")
    columns = sorted({round(x + w / 2) for x, _, w, _ in cells})
    assert [round(x + w / 2) for x, _, w, _ in x_ticks] == pytest.approx(columns, abs=2)
    # The colour bar: drawn, titled with the objective and its unit, ticked within the best
    # end times of the variants that completed without a collision.
    ((_, _, bar_w, bar_h),) = boxes(browser, "#colorbar rect")
    assert bar_w > 5 and bar_h > 100
    assert texts(browser, "#colorbar-title") == ["end_time [s]"]
    feasible = [float(r["end_time [s]"]) for r in rows if r["outcome"] == "completed" and r["collisions"] == "0"]
    assert len(feasible) >= 2
    ticks = [float(t) for t in texts(browser, ".bar-tick text")]
    assert len(ticks) >= 2
    lo, hi = min(feasible), max(feasible)
    assert all(lo - 1e-3 <= t <= hi + 1e-3 for t in ticks), (ticks, lo, hi)
    # The legend: every colour said, with as many cells as the table gives.
    legend = texts(browser, "#legend li")
    assert len(legend) == 4, legend
    assert all(w > 0 and h > 0 for _, _, w, h in boxes(browser, "#legend li"))
    collided = sum(1 for r in rows if r["outcome"] == "collision")
    others = sum(1 for r in rows if r["outcome"] not in ("completed", "collision"))
    assert f"({len(feasible)} cells)" in legend[0] and "colour bar" in legend[0]
    assert "collided" in legend[1] and f"({collided} cells)" in legend[1]
    assert "none completed" in legend[2] and f"({others} cells)" in legend[2]
    assert "no variant (0 cells)" in legend[3]
    fills = browser.eval("Array.from(document.querySelectorAll('rect.cell')).map(function (e) { return e.getAttribute('fill'); })")
    assert fills.count("#d62728") == collided and collided >= 1
    # The tables' headers say the units too.
    headers = texts(browser, "#all th")
    assert "robot.r2.base.xyz.0 [mm]" in headers and "end_time [s]" in headers


def test_the_one_variable_chart_has_ticks_and_a_legend(browser, tmp_path):
    rows, page = handoff_in(
        tmp_path,
        'cell = "cell.toml"\n[[variable]]\npath = "robot.r2.base.rpy.2"\n'
        'range = { from = "170deg", to = "190deg", steps = 5 }\n',
    )
    assert [r["robot.r2.base.rpy.2 [deg]"] for r in rows] == ["170", "175", "180", "185", "190"]
    open_page(browser, page)
    clean(browser, page)
    assert texts(browser, "#x-title") == ["robot.r2.base.rpy.2 [deg]"]
    assert texts(browser, "#y-title") == ["end_time [s]"]
    x_ticks = [float(t) for t in texts(browser, ".x-tick text")]
    assert len(x_ticks) >= 3 and x_ticks == sorted(x_ticks) and 170 <= x_ticks[0] and x_ticks[-1] <= 190
    assert len(texts(browser, ".y-tick text")) >= 2
    # The legend: each mark said, with as many variants as the table gives.
    legend = texts(browser, "#legend li")
    feasible = sum(1 for r in rows if r["outcome"] == "completed" and r["collisions"] == "0")
    collided = sum(1 for r in rows if r["outcome"] == "collision")
    assert legend[0] == f"completed without a collision ({feasible})"
    assert legend[1] == f"collision ({collided})"
    assert legend[2].startswith("did not complete") and legend[2].endswith(f"({5 - feasible - collided})")
    assert browser.eval("document.querySelectorAll('#chart circle.feasible').length") == feasible
    assert all(w > 0 for _, _, w, _ in boxes(browser, "#legend li"))
    # Nothing from elsewhere: one file.
    assert not re.search(r"""(src|href)=["']?(https?:|//)""", page.read_text())
