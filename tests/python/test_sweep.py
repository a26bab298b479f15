"""`vworks.sweep` and `vworks sweep`: many variants of a workcell, on this machine, on a
local Ray cluster and on a Dask LocalCluster (both on 127.0.0.1 with 2 CPUs), giving the
same table row for row; the CLI's table equal to Python's; the table (`SweepTable`) works
without pandas, and `to_pandas()` makes the DataFrame."""

import csv
import os
import subprocess
import sys
from pathlib import Path

import pytest

import vworks

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
    # The workcell as written (r2 at 600, 600 mm, 4 ms) ends at 63.418 s, as `vworks run`.
    (base,) = [r for r in local if (r["robot.r2.base.xyz.0"], r["robot.r2.base.xyz.1"], r["cycle"]) == (0.6, 0.6, 0.004)]
    assert round(base["end_time"], 6) == 63.417730
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
    for row, want in zip(rows, local):
        assert row["outcome"] == want["outcome"]
        assert float(row["end_time"]) == want["end_time"]
        assert float(row["robot.r2.base.xyz.1"]) == want["robot.r2.base.xyz.1"]
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
    assert len(lines) == 2 and lines[1].startswith('{"variant":1,"robot.r2.base.xyz.0":0.65,"outcome":"until"')
