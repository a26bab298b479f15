"""`vworks.sweep` and `vworks sweep`: many variants of a workcell, on this machine, on a
local Ray cluster and on a Dask LocalCluster (both on 127.0.0.1 with 2 CPUs), giving the
same table row for row; and the CLI's table equal to Python's."""

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


def test_the_local_table_has_every_variant_and_outcome(local):
    assert len(local) == 40
    assert list(local.columns) == [
        "variant", "robot.r2.base.xyz.0", "robot.r2.base.xyz.1", "cycle", "outcome", "end_time",
        "cycle_time.r1", "cycle_time.r2", "collisions", "min_clearance", "error",
    ]
    assert list(local["variant"]) == list(range(40))
    # The first variable changes slowest; values are SI numbers.
    assert list(local["robot.r2.base.xyz.0"][:8]) == [0.25] * 8
    assert list(local["cycle"][:2]) == [0.004, 0.008]
    outcomes = set(local["outcome"])
    assert {"completed", "collision"} <= outcomes, outcomes
    # The workcell as written (r2 at 600, 600 mm, 4 ms) ends at 63.418 s, as `vworks run`.
    base = local[(local["robot.r2.base.xyz.0"] == 0.6) & (local["robot.r2.base.xyz.1"] == 0.6)
                 & (local["cycle"] == 0.004)]
    assert base["end_time"].round(6).tolist() == [63.417730]
    collided = local[local["outcome"] == "collision"]
    assert (collided["collisions"] >= 1).all() and (collided["min_clearance"] == 0).all()


def test_the_same_with_one_thread(local):
    assert vworks.sweep(CELL, VARIABLES, jobs=1).equals(local)


def test_a_local_ray_cluster_gives_the_same_table(local):
    import ray
    ray.init(address="local", num_cpus=2, include_dashboard=False, _node_ip_address="127.0.0.1",
             log_to_driver=False)
    try:
        assert ray.cluster_resources()["CPU"] == 2
        remote = vworks.sweep(CELL, VARIABLES, backend="ray")
        assert remote.equals(local)
        # Small batches: many tasks, the same rows in the same order.
        assert vworks.sweep(CELL, VARIABLES, backend="ray", batch=3).equals(local)
    finally:
        ray.shutdown()


def test_a_dask_local_cluster_gives_the_same_table(local):
    from dask.distributed import Client, LocalCluster

    with LocalCluster(n_workers=2, threads_per_worker=1, host="127.0.0.1", dashboard_address=None,
                      processes=True) as cluster, Client(cluster):
        assert vworks.sweep(CELL, VARIABLES, backend="dask").equals(local)


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
    for row, (_, want) in zip(rows, local.iterrows()):
        assert row["outcome"] == want["outcome"]
        assert float(row["end_time"]) == want["end_time"]
        assert float(row["robot.r2.base.xyz.1"]) == want["robot.r2.base.xyz.1"]
    page = (tmp_path / "sweep.html").read_text()
    assert '<svg id="chart"' in page and "class=\"cell\"" in page  # a heatmap over two variables


def test_a_list_of_variants_and_bad_input():
    df = vworks.sweep(CELL, [{"cycle": "4ms"}, {"cycle": "8ms", "clearance": 0.01}], until=5.0)
    assert list(df.columns[:3]) == ["variant", "cycle", "clearance"]
    assert list(df["outcome"]) == ["until", "until"]
    assert df["clearance"].isna().tolist() == [True, False]
    with pytest.raises(vworks.CellError, match=r"robot\.r3\.base\.xyz\.0: not a value of this workcell; the nearest are .*robot\.r1\.base\.xyz\.0"):
        vworks.sweep(CELL, {"robot.r3.base.xyz.0": [0.5]})
    with pytest.raises(ValueError, match="not a number, a string with a unit or a bool"):
        vworks.sweep(CELL, {"cycle": [[4]]})
    with pytest.raises(ValueError, match="backend is 'local', 'ray' or 'dask'"):
        vworks.sweep(CELL, {"cycle": ["4ms"]}, backend="spark")
    # A value the workcell does not accept there: a row that says why.
    bad = vworks.sweep(CELL, {"robot.r2.base.xyz.0": ["tall"]})
    assert bad["outcome"].tolist() == ["invalid"] and "tall" in bad["error"][0]


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
