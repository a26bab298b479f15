"""bench/compare.py keeps working: its Pinocchio, PyBullet and SimPy sides on a few cycles
(the full run, with the Rust benches, is `bench/compare.py`)."""

import os
import sys

import pytest

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
sys.path.insert(0, os.path.join(ROOT, "bench"))

import compare  # noqa: E402


@pytest.mark.oracle
def test_pinocchio_and_pybullet_run_the_benchmark_cell(monkeypatch):
    monkeypatch.setattr(compare, "CYCLES", 25)
    qs, bases = compare.trajectory()
    assert len(qs) == 25 and len(qs[0]) == 24
    assert bases == [[0.0, 0.0, 0.0], [1.2, 0.0, 0.0], [0.0, 1.2, 0.0], [1.2, 1.2, 0.0]]
    seconds, pairs, collisions = compare.pinocchio(qs, bases)
    # 4 robots x 7 shapes: 6 x 49 pairs between robots, 10 within each robot (links two
    # or more apart), less those overlapping at the zero pose.
    assert 300 < pairs <= 6 * 49 + 4 * 15
    # The cell has no collision, as vworks finds: the shapes and their placements agree.
    assert collisions == 0
    # ... and it is not blind: with the second arm 35 cm in front of the first, the first
    # reaches into it.
    close = [[0.0, 0.0, 0.0], [0.35, 0.0, 0.0]] + bases[2:]
    assert compare.pinocchio(qs, close)[2] > 0
    assert 0 < seconds < 0.01
    assert 0 < compare.pybullet(qs, bases) < 0.01


def test_vworks_also_sees_the_arms_35_cm_apart_collide(tmp_path):
    import vworks

    cell = open(compare.CELL).read().replace('"1200mm", "0mm"', '"350mm", "0mm"', 1)
    (tmp_path / "cell.toml").write_text(cell)
    arm = os.path.join(os.path.dirname(compare.CELL), "arm.wsl")
    (tmp_path / "arm.wsl").write_text(open(arm).read())
    result = vworks.load_cell(str(tmp_path / "cell.toml")).run(until=0.1)
    assert result.collisions, result.outcome


@pytest.mark.oracle
def test_the_simpy_models_count_their_events():
    ping_pong, ring = compare.simpy_models()
    assert ping_pong(100) >= 200
    assert ring(4, 25) >= 100
