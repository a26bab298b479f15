"""`move_j` durations with jerk limits, checked against Ruckig (the `ruckig` wheel).

vworks plans a jerk-limited `move_j` as Ruckig does with its default time
synchronisation: each axis's time-optimal rest-to-rest profile within its speed,
acceleration and jerk, the slowest setting the duration. Random robots (URDF 1.0 files
whose `<limit>` carries `acceleration` and `jerk`, read whatever the URDF version) run
random `move_j` programs; every `motion_start` duration must equal Ruckig's to 1 µs.
Cases: single-axis moves (one axis changes) and six-axis moves, with speed and
acceleration ratios, 240 in all.
"""

import math
import pathlib
import random

import pytest
from ruckig import InputParameter, Result, Ruckig, Trajectory

import vworks

AXES = 6
MOVES_PER_ROBOT = 40
ROBOTS = 6  # 240 cases
TOLERANCE_S = 1e-6

worst = {"diff": 0.0}


def chain_urdf(name, limits):
    """A serial chain of revolute joints (z axes, 0.1 m apart) with the given limits."""
    links = "".join(f'<link name="l{i}"/>' for i in range(AXES + 1))
    joints = ""
    for i, (v, a, j) in enumerate(limits):
        joints += (
            f'<joint name="j{i + 1}" type="revolute"><parent link="l{i}"/><child link="l{i + 1}"/>'
            f'<origin xyz="0 0 0.1"/><axis xyz="0 0 1"/>'
            f'<limit lower="-3" upper="3" effort="1" velocity="{v!r}" acceleration="{a!r}" jerk="{j!r}"/></joint>'
        )
    return f'<?xml version="1.0"?><robot name="{name}">{links}{joints}</robot>'


def ruckig_duration(start, goal, v, a, j):
    inp = InputParameter(len(start))
    inp.current_position = list(start)
    inp.target_position = list(goal)
    inp.max_velocity = list(v)
    inp.max_acceleration = list(a)
    inp.max_jerk = list(j)
    traj = Trajectory(len(start))
    assert Ruckig(len(start)).calculate(inp, traj) in (Result.Working, Result.Finished)
    return traj.duration


def fmt_joints(q):
    return "joints(" + ", ".join(f"{x!r}rad" for x in q) + ")"


@pytest.mark.parametrize("seed", range(ROBOTS))
def test_move_j_durations_equal_ruckig(tmp_path, seed):
    rng = random.Random(seed)
    limits = [
        (rng.uniform(0.5, 4.0), rng.uniform(1.0, 20.0), rng.uniform(5.0, 400.0)) for _ in range(AXES)
    ]
    (tmp_path / "arm.urdf").write_text(chain_urdf(f"arm{seed}", limits))
    q = [0.0] * AXES
    lines, cases = [], []
    for k in range(MOVES_PER_ROBOT):
        goal = list(q)
        if k % 2 == 0:  # one axis moves
            i = rng.randrange(AXES)
            goal[i] = rng.uniform(-3.0, 3.0)
        else:  # all of them
            goal = [rng.uniform(-3.0, 3.0) for _ in range(AXES)]
        ratio = rng.choice([1.0, rng.uniform(0.1, 1.0)])
        aratio = rng.choice([1.0, rng.uniform(0.1, 1.0)])
        lines.append(f"    move_j {fmt_joints(goal)} speed {ratio * 100!r}% accel {aratio * 100!r}%;")
        v = [lim[0] * ratio for lim in limits]
        a = [lim[1] * aratio for lim in limits]
        j = [lim[2] for lim in limits]
        cases.append(ruckig_duration(q, goal, v, a, j))
        q = goal
    (tmp_path / "r.wsl").write_text("proc main() {\n" + "\n".join(lines) + "\n}\n")
    (tmp_path / "cell.toml").write_text(
        'name = "ruckig"\n[[robot]]\nname = "r"\nurdf = "arm.urdf"\nprogram = "r.wsl"\n'
    )
    result = vworks.load_cell(tmp_path / "cell.toml").run()
    got = [e.data["duration_ns"] for e in result.events if e.kind == "motion_start"]
    assert len(got) == len(cases)
    for k, (ns, expected) in enumerate(zip(got, cases)):
        diff = abs(ns / 1e9 - expected)
        worst["diff"] = max(worst["diff"], diff)
        assert diff <= TOLERANCE_S, f"move {k}: vworks {ns} ns, Ruckig {expected!r} s"
    # The duration is Ruckig's rounded up to a whole nanosecond.
    assert all(ns >= math.floor(expected * 1e9) for ns, expected in zip(got, cases))


def test_worst_difference_is_reported():
    # Runs after the cases above (pytest keeps file order): the worst difference, in the
    # output of `pytest -s` and as a bound.
    print(f"worst |vworks - Ruckig| over {ROBOTS * MOVES_PER_ROBOT} move_j: {worst['diff'] * 1e9:.3f} ns")
    assert worst["diff"] <= TOLERANCE_S


def test_a_trapezoid_robot_keeps_its_closed_form(tmp_path):
    # Without jerk limits, a one-axis move of d at speed v and acceleration a takes
    # d/v + v/a: 2 rad at 1 rad/s and 4 rad/s² → 2.25 s.
    urdf = chain_urdf("trap", [(1.0, 4.0, 1.0)] * AXES).replace(' jerk="1.0"', "")
    (tmp_path / "arm.urdf").write_text(urdf)
    (tmp_path / "r.wsl").write_text("proc main() { move_j joints(2rad, 0rad, 0rad, 0rad, 0rad, 0rad); }\n")
    (tmp_path / "cell.toml").write_text(
        'name = "trap"\n[[robot]]\nname = "r"\nurdf = "arm.urdf"\nprogram = "r.wsl"\n'
    )
    result = vworks.load_cell(tmp_path / "cell.toml").run()
    (ns,) = [e.data["duration_ns"] for e in result.events if e.kind == "motion_start"]
    assert ns == 2_250_000_000
