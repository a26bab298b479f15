#!/usr/bin/env python3
"""How close are vworks's straight-line and circular motions (`move_l`, `move_c`) to the
time-optimal motion along the same path under the same limits? toppra (time-optimal path
parameterisation, PyPI `toppra`) is the oracle.

For each built-in 6-axis arm (irb120, kr6r900, lrmate200id, ur5) and N random cases:

1. Start joints at random in a sane part of the workspace (elbow bent, wrist axis 5 at
   least 25 degrees from 0, model by model: `START` below), a straight line from the TCP
   there, translated by a random vector of 50-600 mm with the same orientation, at a TCP
   speed drawn from 100 mm/s, 500 mm/s, 1 m/s, 2 m/s, 4 m/s. An arc case (`--kind arc`)
   has the same start, target and speed as the line case of its number, and a via point:
   the chord's midpoint pushed sideways by 20-45 % of the chord length, in a random
   direction perpendicular to the chord (its own generator, so the line cases do not
   change), the same orientation throughout; the program's last motion is then
   `move_c offset(current_pose(), vx, vy, vz), offset(current_pose(), dx, dy, dz) speed V`
   (both offsets from the start pose).
2. A one-robot workcell in a temporary folder runs
   `move_j START; move_l offset(current_pose(), dx, dy, dz) speed V;` (a fine point, the
   model's default acceleration). The move_l's (move_c's) duration is its motion_start to
   its motion_end (events, ns). A case vworks cannot run (unreachable on the way, a joint
   limit, a self-collision, a singularity) is skipped and counted. A Simulation is then stepped through
   the motion on a uniform grid of about 1 ms (T / ceil(T / 1 ms)), reading the joints
   and the TCP. `path_error_mm` is the largest distance of the recorded TCP from the line
   through start and target (a line) or from the circle through start, via and target
   (an arc); for an arc `via_miss_mm` is the distance from the via point to the recorded
   polyline (the arc passes through it, not the other way round the circle).
3. The path for toppra: the joints as a cubic spline (scipy, through toppra's
   SplineInterpolator) of s, the TCP's arc length along the recorded positions (samples
   closer than L/4000 in s are dropped, as at the ends, where the TCP is at rest), plus a
   virtual 7th joint equal to s. Constraints (toppra JointVelocityConstraint and
   JointAccelerationConstraint, interpolation scheme, 801 gridpoints): each axis's URDF
   velocity limit and acceleration limit (velocity / 0.3 s where a URDF gives none;
   the built-in arms give theirs, docs/models.md), and for s the programmed TCP
   speed V (at most the model's `<tcp_limits speed>`) and the model's TCP acceleration
   (`<tcp_limits acceleration>`; none where the model gives none: the axes alone bound the
   path, as vworks does; on an arc the TCP's whole acceleration, along it and towards
   its centre, through three more virtual joints, the TCP's position, and a
   SecondOrderConstraint; `tcp_accel_ratio` in the JSON is the recorded peak TCP
   acceleration, as a vector, over that limit). toppra's duration is
   sum 2 ds / (sd_i + sd_i+1) over its grid (piecewise-constant path acceleration).
4. From the recorded joints: peak joint speed and peak joint acceleration as ratios of
   the limits (largest over the axes), by finite differences on the ~1 ms grid (first
   differences for speed, second differences for acceleration). A case whose joints move
   faster than 2x a limit between two samples is a "jump": the joints along the line
   leave one configuration for another (the TCP stays on the path); there is no smooth
   path for toppra, so it is counted but left out of the ratios and peaks.

The table gives per model and kind (line, arc): cases run and skipped, the ratio vworks time / toppra time
(median, worst = largest, best = smallest), how many cases vworks is faster than toppra
(ratio below 1 - 1e-3: faster than the limits allow, which can only be by leaving
one of them, e.g. the axis accelerations, which move_l does not bound: docs/engine.md,
"Zones"), and the largest peak joint speed and acceleration ratios. `--json FILE`
writes every case.

    .venv/bin/python bench/fidelity.py --cases 15 [--kind line|arc|both] [--seed 1] [--json fidelity.json]

Needs toppra (`.venv/bin/python -m pip install toppra`, which brings scipy). Deterministic
for a given seed: case i of a model is the same whatever --cases is.
"""

import argparse
import json
import math
import sys
import tempfile
import time
import warnings
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
MODELS_DIR = ROOT / "crates" / "model" / "models"

DEFAULT_ACCEL_TIME = 0.3  # s: full speed in 0.3 s, axes without <limit acceleration> (docs/models.md)
END_GRIDPOINTS = 40  # more gridpoints within the first and last two uniform steps
UNBOUNDED = 1e6  # m/s²: the virtual joint s's acceleration where the model gives no TCP limit
SPEEDS = [0.1, 0.5, 1.0, 2.0, 4.0]  # m/s
LENGTH_MM = (50.0, 600.0)
VIA_SIDEWAYS = (0.20, 0.45)  # an arc's via point: the chord's midpoint pushed sideways by this times the chord
KINDS = ("line", "arc")
STEP = 1e-3  # s, the recording grid (at most)
MAX_SAMPLES = 20_000  # a motion longer than 20 s (a vworks slowdown) is recorded on a coarser grid
JUMP = 2.0  # a joint faster than this times its limit between two samples: the IK switched branches
GRIDPOINTS = 801  # toppra's grid
FASTER_TOL = 1e-3  # a ratio below 1 - this counts as "vworks faster than toppra"

# Start joints, degrees, per axis (lo, hi); axis 5 (index 4) is drawn with a random sign
# from the magnitude range given, away from the wrist singularity at 0.
START = {
    # axis 2 upper arm upright to leaning forward, axis 3 forearm horizontal to tilted down
    # (stretched near -77 deg); the arm reaches 0.58 m, so many 600 mm lines leave it
    "irb120": [(-90, 90), (0, 40), (0, 60), (-90, 90), (25, 90), (-90, 90)],
    # upper arm horizontal and the arm stretched at zero: A2 -90 deg is upright, A3 90 deg
    # puts the forearm horizontal
    "kr6r900": [(-90, 90), (-110, -60), (70, 135), (-90, 90), (25, 90), (-90, 90)],
    # like the IRB 120, axis 3 about -y (stretched near +84 deg)
    "lrmate200id": [(-90, 90), (-10, 40), (-50, 20), (-90, 90), (25, 90), (-90, 90)],
    # standard DH, stretched horizontally at zero: shoulder raised, elbow bent, wrist 2
    # away from 0 and 180 deg
    "ur5": [(-90, 90), (-120, -45), (45, 120), (-150, -30), (30, 150), (-90, 90)],
}
WRIST = 4  # the axis drawn with a random sign


def urdf_limits(model):
    """Per moving joint, in file order (the chain of the built-in arms): lower, upper,
    velocity, acceleration (velocity / 0.3 s where the URDF gives none)."""
    rows = []
    for joint in ET.parse(MODELS_DIR / f"{model}.urdf").getroot().iter("joint"):
        if joint.get("type") not in ("revolute", "prismatic", "continuous"):
            continue
        lim = joint.find("limit")
        vel = float(lim.get("velocity"))
        acc = lim.get("acceleration")
        rows.append((float(lim.get("lower", "-inf")), float(lim.get("upper", "inf")), vel,
                     float(acc) if acc is not None else vel / DEFAULT_ACCEL_TIME))
    return np.array(rows)


def urdf_tcp(model):
    """The model's TCP speed and acceleration limits (`<tcp_limits>`; inf where none)."""
    tcp = ET.parse(MODELS_DIR / f"{model}.urdf").getroot().find("tcp_limits")
    get = lambda key: float(tcp.get(key)) if tcp is not None and tcp.get(key) else float("inf")
    return get("speed"), get("acceleration")


def draw_case(model, seed, model_index, case, limits):
    """The case's start joints (rad), offset (m) and TCP speed (m/s): its own generator,
    so case i does not depend on how many cases run."""
    rng = np.random.default_rng([seed, model_index, case])
    q = np.array([rng.uniform(lo, hi) for lo, hi in START[model]])
    q[WRIST] *= rng.choice([-1.0, 1.0])
    q = np.clip(np.radians(q), limits[:, 0], limits[:, 1])
    direction = rng.normal(size=3)
    direction /= np.linalg.norm(direction)
    offset = direction * rng.uniform(*LENGTH_MM) / 1000.0
    speed = float(rng.choice(SPEEDS))
    return q, offset, speed


def draw_via(seed, model_index, case, offset):
    """An arc case's via point (m, from the start TCP): the chord's midpoint pushed sideways
    by VIA_SIDEWAYS of the chord, in a random direction perpendicular to it. Its own
    generator, so the line cases (draw_case) stay as they are."""
    rng = np.random.default_rng([seed, model_index, case, 1])
    chord = np.linalg.norm(offset)
    u = offset / chord
    while True:
        side = rng.normal(size=3)
        side -= (side @ u) * u
        if np.linalg.norm(side) > 1e-6:
            break
    side /= np.linalg.norm(side)
    return 0.5 * offset + side * rng.uniform(*VIA_SIDEWAYS) * chord


def write_cell(folder, model, q, offset, speed, via=None):
    folder.joinpath("cell.toml").write_text(
        f'name = "fidelity"\n[[robot]]\nname = "r1"\nmodel = "{model}"\nprogram = "r1.wsl"\n')
    joints = ", ".join(f"{v:.15f}rad" for v in q)

    def at(v):
        return "offset(current_pose(), " + ", ".join(f"{x * 1000.0:.12f}mm" for x in v) + ")"

    if via is None:
        motion = f"move_l {at(offset)}"
    else:
        motion = f"move_c {at(via)}, {at(offset)}"
    folder.joinpath("r1.wsl").write_text(
        "proc main() {\n"
        f"    move_j joints({joints});\n"
        f"    {motion} speed {speed * 1000.0:g}mm/s zone fine;\n"
        "}\n")
    return folder / "cell.toml"


def skip_reason(result):
    if result.outcome == "collision":
        c = result.collisions[0]
        return f"collision {c.a} {c.b}"
    if result.errors:
        return result.errors[0].message
    return result.outcome


def record(cell, t0_ns, t1_ns):
    """Step a Simulation through [t0, t1] on a uniform grid of at most STEP: times (s,
    from the sim's own ns clock), joints (n, 6) and TCP positions (n, 3)."""
    sim = cell.simulation()
    robot = sim.robot("r1")
    n = min(MAX_SAMPLES, max(2, math.ceil((t1_ns - t0_ns) * 1e-9 / STEP)))
    times, joints, tcp = [], [], []
    for k in range(n + 1):
        t_ns = t0_ns + round((t1_ns - t0_ns) * k / n)
        sim.run_until(t_ns * 1e-9)
        times.append(sim.time_ns * 1e-9)
        joints.append(robot.joints.copy())
        tcp.append(robot.tcp[:3, 3].copy())
    return np.array(times), np.array(joints), np.array(tcp)


def circle(a, b, c):
    """Centre, unit normal and radius of the circle through three points."""
    ab, ac = b - a, c - a
    n = np.cross(ab, ac)
    nn = n @ n
    centre = a + (np.cross(n, ab) * (ac @ ac) + np.cross(ac, n) * (ab @ ab)) / (2.0 * nn)
    return centre, n / math.sqrt(nn), float(np.linalg.norm(a - centre))


def circle_distance(p, centre, normal, radius):
    """Distance of each point of p (n, 3) from the circle."""
    d = p - centre
    h = d @ normal
    r = np.linalg.norm(d - np.outer(h, normal), axis=1)
    return np.hypot(h, r - radius)


def polyline_distance(x, p):
    """Distance of the point x from the polyline through the points p (n, 3)."""
    a, b = p[:-1], p[1:]
    ab = b - a
    ll = np.einsum("ij,ij->i", ab, ab)
    t = np.clip(np.einsum("ij,ij->i", x - a, ab) / np.where(ll > 0, ll, 1.0), 0.0, 1.0)
    return float(np.linalg.norm(a + t[:, None] * ab - x, axis=1).min())


def path_samples(q, p):
    """(s, q) knots for the spline: s is the cumulative TCP chord length; samples closer
    than L/4000 to the previous knot are dropped (the ends, where the TCP is at rest), and
    the last sample is always a knot."""
    s = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(p, axis=0), axis=1))])
    ds_min = s[-1] / 4000.0
    keep = [0]
    for i in range(1, len(s)):
        if s[i] - s[keep[-1]] >= ds_min:
            keep.append(i)
    if keep[-1] != len(s) - 1:
        keep[-1] = len(s) - 1
    return s[keep], q[keep], p[keep]


def toppra_time(s, q, vlim, alim, speed, accel=float("inf"), plane=None):
    """Time-optimal duration along q(s) (cubic spline), joints within vlim/alim, the
    virtual joint s within speed and accel (inf: none). An arc (`plane`: the TCP's
    positions at the knots and two unit vectors spanning the arc's plane) also keeps the
    TCP's whole acceleration (along the arc and towards its centre) within accel: three
    more virtual joints, the TCP's position, whose acceleration stays inside a 64-sided
    polygon around that disk (at most 0.12 % outside it: this oracle is, if anything,
    faster than the disk allows). None if toppra finds no profile."""
    import toppra as ta
    import toppra.algorithm as algo
    import toppra.constraint as constraint

    curved = plane is not None and np.isfinite(accel)
    way = np.column_stack([q, s] + ([plane[0] - plane[0][0]] if curved else []))
    path = ta.SplineInterpolator(s, way)
    v = np.append(vlim, speed)
    a = np.append(alim, accel if np.isfinite(accel) else UNBOUNDED)
    if curved:
        v = np.append(v, [UNBOUNDED] * 3)
        a = np.append(a, [UNBOUNDED] * 3)
    cons = [constraint.JointVelocityConstraint(np.column_stack([-v, v])),
            constraint.JointAccelerationConstraint(
                np.column_stack([-a, a]), discretization_scheme=constraint.DiscretizationType.Interpolation)]
    if curved:
        e1, e2 = plane[1], plane[2]
        phi = np.arange(64) * 2.0 * np.pi / 64
        faces = np.outer(np.cos(phi), e1) + np.outer(np.sin(phi), e2)
        g = np.full(64, accel)
        cons.append(constraint.SecondOrderConstraint(
            lambda q_, qd_, qdd_: qdd_[-3:], lambda q_: faces, lambda q_: g, dof=way.shape[1],
            discretization_scheme=constraint.DiscretizationType.Interpolation))
    # Uniform, and dense near both ends: a ramp shorter than one uniform step (a slow, long
    # line) would otherwise cost toppra up to a step's time at each end.
    ends = (s[-1] - s[0]) * np.geomspace(1e-6, 2.0 / (GRIDPOINTS - 1), END_GRIDPOINTS)
    grid = np.unique(np.concatenate([np.linspace(s[0], s[-1], GRIDPOINTS), s[0] + ends, s[-1] - ends]))
    instance = algo.TOPPRA(cons, path, gridpoints=grid)
    sdd, sd, _ = instance.compute_parameterization(0.0, 0.0)
    if sd is None or not np.all(np.isfinite(sd)):
        return None
    mean = sd[1:] + sd[:-1]
    if np.any(mean <= 0):
        return None
    return float(np.sum(2.0 * np.diff(grid) / mean))


def peaks(t, q, s, limits, speed, accel=float("inf"), p=None):
    """Peak joint speed and acceleration ratios (largest over the axes, and which axis),
    and the TCP's, by finite differences on the recorded grid (the TCP's acceleration as
    a vector from its positions `p`, so an arc's centripetal part counts; along the path
    without them)."""
    dt = np.diff(t)
    qd = np.diff(q, axis=0) / dt[:, None]
    qdd = np.diff(qd, axis=0) / (0.5 * (t[2:] - t[:-2]))[:, None]
    v_ratio = np.abs(qd).max(axis=0) / limits[:, 2]
    a_ratio = np.abs(qdd).max(axis=0) / limits[:, 3]
    sd = np.diff(s) / dt
    if p is None:
        sdd = np.diff(sd) / (0.5 * (t[2:] - t[:-2]))
    else:
        pd = np.diff(p, axis=0) / dt[:, None]
        sdd = np.linalg.norm(np.diff(pd, axis=0) / (0.5 * (t[2:] - t[:-2]))[:, None], axis=1)
    return {
        "peak_joint_speed_ratio": float(v_ratio.max()), "peak_speed_axis": int(v_ratio.argmax()) + 1,
        "peak_joint_accel_ratio": float(a_ratio.max()), "peak_accel_axis": int(a_ratio.argmax()) + 1,
        "tcp_speed_ratio": float(sd.max() / speed),
        "tcp_accel_ratio": float(np.abs(sdd).max() / accel) if np.isfinite(accel) else None,
    }


def run_case(vworks, folder, model, index, case, seed, limits, kind="line"):
    """One case: kind "line" (move_l) or "arc" (move_c through a via point)."""
    q0, offset, speed = draw_case(model, seed, index, case, limits)
    via = draw_via(seed, index, case, offset) if kind == "arc" else None
    command = "move_c" if kind == "arc" else "move_l"
    row = {"model": model, "kind": kind, "case": case, "start_deg": np.degrees(q0).round(6).tolist(),
           "offset_mm": (offset * 1000).round(6).tolist(), "length_mm": float(np.linalg.norm(offset) * 1000),
           "speed_mps": speed}
    if via is not None:
        row["via_mm"] = (via * 1000).round(6).tolist()
    try:
        cell = vworks.load_cell(write_cell(folder, model, q0, offset, speed, via))
        result = cell.run(check=False)
    except vworks.Error as e:  # a start outside the limits, a program that does not load
        row["skipped"] = f"{type(e).__name__}: {e}".splitlines()[0]
        return row
    if result.outcome != "completed":
        row["skipped"] = skip_reason(result)
        return row
    events = list(result.events)
    start = next(i for i, e in enumerate(events) if e.kind == "motion_start" and e.data["command"] == command)
    end = next(e for e in events[start:] if e.kind == "motion_end")
    t0, t1 = events[start].time_ns, end.time_ns
    row["slowdown"] = [w.message for w in result.warnings if w.kind == "slowdown"]
    row["vworks_s"] = (t1 - t0) * 1e-9
    if t1 == t0:
        row["skipped"] = f"{command} took no time"
        return row

    tcp_speed, tcp_accel = urdf_tcp(model)
    speed = min(speed, tcp_speed)
    t, q, p = record(cell, t0, t1)
    row["samples"] = len(t)
    if via is None:
        line = p[-1] - p[0]
        u = line / np.linalg.norm(line)
        off_line = p - p[0] - np.outer((p - p[0]) @ u, u)
        row["path_error_mm"] = float(np.linalg.norm(off_line, axis=1).max() * 1000)
    else:
        centre, normal, radius = circle(p[0], p[0] + via, p[0] + offset)  # the programmed circle
        row["radius_mm"] = radius * 1000
        row["path_error_mm"] = float(circle_distance(p, centre, normal, radius).max() * 1000)
        row["via_miss_mm"] = polyline_distance(p[0] + via, p) * 1000
    row["end_error_mm"] = float(np.linalg.norm(p[-1] - p[0] - offset) * 1000)
    s_all = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(p, axis=0), axis=1))])
    row.update(peaks(t, q, s_all, limits, speed, tcp_accel, p))
    if row["peak_joint_speed_ratio"] > JUMP:
        step = np.abs(np.diff(q, axis=0))
        i, j = np.unravel_index(step.argmax(), step.shape)
        row["jump"] = {"time_s": float(t[i + 1] - t[0]), "axis": int(j) + 1, "deg": float(np.degrees(step[i, j])),
                       "path_fraction": float(s_all[i + 1] / s_all[-1])}
        return row  # no smooth path for toppra: left out of the ratios

    s, qk, pk = path_samples(q, p)
    row["knots"] = len(s)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        plane = None
        if via is not None:
            e1 = (p[0] - centre) / np.linalg.norm(p[0] - centre)
            plane = (pk, e1, np.cross(normal, e1))
        best = toppra_time(s, qk, limits[:, 2], limits[:, 3], speed, tcp_accel, plane)
    if best is None:
        row["skipped"] = "toppra found no profile"
        return row
    row["toppra_s"] = best
    row["ratio"] = row["vworks_s"] / best
    return row


def summary(label, rows):
    done = [r for r in rows if "ratio" in r]
    jumps = sum(1 for r in rows if "jump" in r)
    skipped = sum(1 for r in rows if "skipped" in r)
    head = f"{label:<17} {len(done) + jumps:>3} {skipped:>4} {jumps:>4}"
    if not done:
        return head + "   (no case to compare)"
    ratios = np.array([r["ratio"] for r in done])
    faster = int(np.sum(ratios < 1.0 - FASTER_TOL))
    slowed = sum(1 for r in done if r["slowdown"])
    vmax = max(r["peak_joint_speed_ratio"] for r in done)
    amax = max(r["peak_joint_accel_ratio"] for r in done)
    over = sum(1 for r in done if r["peak_joint_accel_ratio"] > 1.0 + FASTER_TOL)
    path = max(r["path_error_mm"] for r in done)
    return (f"{head}   {np.median(ratios):>6.3f} {ratios.max():>6.3f} "
            f"{ratios.min():>6.3f}   {faster:>3}/{len(done):<3} {slowed:>4}   {vmax:>6.2f}   {amax:>6.2f} "
            f"({over} over 1)   {path:.1e}")


def report(row):
    """One case on stderr (--verbose)."""
    if "ratio" in row:
        what = (f"ratio {row['ratio']:.4f} vworks {row['vworks_s']:.4f} s toppra {row['toppra_s']:.4f} s "
                f"peak speed {row['peak_joint_speed_ratio']:.2f} accel {row['peak_joint_accel_ratio']:.2f} "
                f"path {row['path_error_mm']:.1e} mm" + (" (slowed)" if row["slowdown"] else ""))
    elif "jump" in row:
        what = f"joint jump {row['jump']} vworks {row['vworks_s']:.3f} s"
    else:
        what = f"skipped: {row['skipped']}"
    print(f"  {row['model']} {row['kind']} {row['case']:>3} {row['length_mm']:6.1f} mm {row['speed_mps']:g} m/s  {what}",
          file=sys.stderr)


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--cases", type=int, default=15, help="random cases per model (default 15)")
    parser.add_argument("--seed", type=int, default=1, help="random seed (default 1)")
    parser.add_argument("--models", nargs="+", default=list(START), choices=list(START))
    parser.add_argument("--kind", choices=["line", "arc", "both"], default="both",
                        help="straight lines (move_l), circular arcs (move_c) or both (default)")
    parser.add_argument("--json", type=Path, help="write the per-case data to this file")
    parser.add_argument("-v", "--verbose", action="store_true", help="print each case")
    args = parser.parse_args()

    try:
        import toppra  # noqa: F401
    except ImportError:
        sys.exit("needs toppra: .venv/bin/python -m pip install toppra")
    import logging
    logging.getLogger("toppra").setLevel(logging.ERROR)
    import vworks

    kinds = list(KINDS) if args.kind == "both" else [args.kind]
    began = time.perf_counter()
    rows = {(m, k): [] for m in args.models for k in kinds}
    with tempfile.TemporaryDirectory() as tmp:
        for model in args.models:
            index = list(START).index(model)
            limits = urdf_limits(model)
            for kind in kinds:
                for case in range(args.cases):
                    row = run_case(vworks, Path(tmp), model, index, case, args.seed, limits, kind)
                    rows[model, kind].append(row)
                    if args.verbose:
                        report(row)


    what = {"line": "move_l", "arc": "move_c", "both": "move_l and move_c"}[args.kind]
    print(f"{what} against toppra (time-optimal under the same joint and TCP speed/accel limits), "
          f"{args.cases} cases per model and kind, seed {args.seed}")
    print("ratio = vworks time / toppra time; worst = largest, best = smallest; faster = ratio < 0.999;")
    print("slowed = vworks warned it slowed the motion (an axis speed limit); peaks: max over cases of the")
    print("largest |joint speed| and |joint accel| over its limit, finite differences on a ~1 ms grid;")
    print(f"jump = ran, but a joint moved faster than {JUMP:g}x its limit between two samples (the IK changed")
    print("configuration on the way): no smooth path for toppra, left out of the ratios and peaks;")
    print("path = max over cases of the TCP's largest distance (mm) from the line, or from the circle")
    print("through start, via and target")
    print()
    print(f"{'model':<17} {'run':>3} {'skip':>4} {'jump':>4}   {'median':>6} {'worst':>6} {'best':>6}   {'faster':>7} "
          f"{'slowed':>6}   {'speed':>6}   {'accel':>6}             {'path':>7}")
    for model in args.models:
        for kind in kinds:
            print(summary(f"{model} {kind}", rows[model, kind]))
    reasons = {}
    for key in rows:
        for r in rows[key]:
            if "skipped" in r:
                key = r["skipped"].split(":")[0][:60]
                reasons[key] = reasons.get(key, 0) + 1
    if reasons:
        print("skipped: " + "; ".join(f"{n}x {k}" for k, n in sorted(reasons.items(), key=lambda kv: -kv[1])))
    print(f"took {time.perf_counter() - began:.1f} s")
    if args.json:
        args.json.write_text(json.dumps({"seed": args.seed, "cases": args.cases,
                                         "kind": args.kind, "rows": [r for k in rows for r in rows[k]]}, indent=1))


if __name__ == "__main__":
    main()
