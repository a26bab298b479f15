#!/usr/bin/env python3
"""How close are vworks's jerk-limited straight lines and arcs to the fastest timing of the
same path within the same axis speeds, accelerations and jerks? toppra has no jerk limits, so this
script carries its own oracle, checked against Ruckig (PyPI `ruckig`), which is exact for
one axis.

**The oracle** (`jerk_time`): the path's timing as a sequence of linear programs (HiGHS,
through scipy), on N steps of the path parameter s:

- variables: x_k = ṡ² at the N + 1 knots and u_k = s̈, constant on each step, so that
  x_{k+1} = x_k + 2 Δs_k u_k (the discretisation of TOPP-RA, Pham & Pham 2018); at rest
  at both ends;
- every axis within its speed at the knots (q′² x ≤ v²) and its acceleration at both ends
  of each step (|q′ u_k + q″ x| ≤ a); the path speed within the TCP speed, |u| within the
  TCP acceleration (a straight line: s is the TCP's arc length);
- **jerk**: the axis's acceleration on a step (at its middle, q′ u_k + q″ x̄) changes from
  one step to the next (and from rest at both ends) by at most j·τ_k, τ_k the time
  between the two steps' middles. τ depends on the timing: it is taken from the previous
  solution (the first from the timing without jerk limits) and the programs are solved
  again until the duration changes by less than 1e-9 of itself (sequential linear
  programming);
- objective: the largest Σ x_k (the faster the path, the larger; without jerk limits this
  gives the time-optimal timing exactly, as TOPP-RA's greedy pass does: the feasible x
  then have a largest element).

The jerk it keeps is the change of acceleration between steps over the time between them,
what sampling the motion measures. On one axis (q = s) it is within 0.2 % of Ruckig's
time-optimal duration at 200 steps and 0.07 % at 800, from below
(`tests/python/test_jerk_oracle.py`).

**The comparison** (`main`): the random straight lines of bench/fidelity.py (seed 1) on the
IRB 120 (or, `--kind arc`, its arcs through their via points), with every axis's jerk
limit set in the workcell so that it ramps to its full acceleration in `--ramp` seconds
(j = a / ramp); vworks's joint path is recorded at 1 ms, splined by TCP arc length
(cubic), and timed by the oracle on 300 steps (and 40 more knots, geometrically closer,
near each end, where a slow line's jerk ramps lie) within the same limits (each axis's
speed and acceleration less 0.05 %, as vworks keeps them); on an arc the TCP's whole
acceleration, along it and towards the centre, within the model's TCP acceleration (the
recorded path's p′ and p″ by the same spline, inside a 64-sided polygon around the disk).

    .venv/bin/python bench/jerk.py [--cases 40] [--ramp 0.02] [--steps 300] [--kind line|arc]

Needs scipy and, for the check of the oracle, ruckig.
"""

import argparse
import math
import sys
import tempfile
import warnings
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
TOLERANCE = 1e-9  # relative change of the duration at which the programs stop
MAX_ROUNDS = 60
LIMIT_SHARE = 1.0 - 5e-4  # vworks times paths within each axis's limits less 0.05 %
END_KNOTS = 40  # more knots within the first and last two uniform steps


def step_times(s, x):
    """Each step's duration with a constant path acceleration: 2 Δs / (ṡ_k + ṡ_k+1)."""
    v = np.sqrt(np.maximum(x, 0.0))
    return 2.0 * np.diff(s) / np.maximum(v[:-1] + v[1:], 1e-300)


def jerk_time(s, dq, ddq, vlim, alim, jlim, speed=math.inf, accel=math.inf, tcp=None):
    """The fastest timing of the path q(s) found (see the module's doc): (duration (s), x, u,
    duration without the jerk limits). `s`: the N + 1 knots; `dq`, `ddq`: q′ and q″ there,
    (N + 1, axes); limits per axis (`jlim` inf: none). `tcp`: for an arc, (p′, p″, e1, e2):
    the TCP's position's derivatives by s at the knots ((N + 1, 3) each) and two unit
    vectors spanning its plane; its whole acceleration p′·u + p″·ṡ² then stays within
    `accel` at both ends of each step (inside a 64-sided polygon around that disk, at most
    0.12 % outside it), not only |u|. None if a program has no solution."""
    from scipy.optimize import linprog
    from scipy.sparse import coo_matrix

    n_steps, axes = len(s) - 1, dq.shape[1]
    ds = np.diff(s)
    nx = n_steps + 1
    nvar = nx + n_steps  # x_0..x_N, u_0..u_N-1

    def matrix(rows, cols, vals, n_rows):
        return coo_matrix((vals, (rows, cols)), shape=(n_rows, nvar)).tocsr()

    # x_k+1 - x_k - 2 Δs_k u_k = 0; x_0 = x_N = 0
    k = np.arange(n_steps)
    eq = matrix(np.concatenate([k, k, k, [n_steps, n_steps + 1]]),
                np.concatenate([k + 1, k, nx + k, [0, n_steps]]),
                np.concatenate([np.ones(n_steps), -np.ones(n_steps), -2.0 * ds, [1.0, 1.0]]),
                n_steps + 2)
    beq = np.zeros(n_steps + 2)
    # speeds: bounds on x
    with np.errstate(divide="ignore"):
        xmax = np.min(np.where(dq != 0.0, (np.asarray(vlim) / dq) ** 2, np.inf), axis=1)
    xmax = np.minimum(xmax, speed ** 2)
    ubound = accel if math.isfinite(accel) and tcp is None else None
    bounds = ([(0.0, float(m) if math.isfinite(m) else None) for m in xmax]
              + [(-ubound if ubound else None, ubound)] * n_steps)
    # accelerations at both ends of each step: ±(q′ u_k + q″ x) ≤ a
    rows, cols, vals, rhs = [], [], [], []
    r = 0
    for end in (0, 1):
        for i in range(axes):
            for sign in (1.0, -1.0):
                idx = np.arange(n_steps)
                knot = idx + end
                rows += [r + idx, r + idx]
                cols += [nx + idx, knot]
                vals += [sign * dq[knot, i], sign * ddq[knot, i]]
                rhs.append(np.full(n_steps, alim[i]))
                r += n_steps
    # an arc: the TCP's whole acceleration, faces f·(p′ u_k + p″ x) ≤ accel
    if tcp is not None and math.isfinite(accel):
        p1, p2, e1, e2 = tcp
        phi = np.arange(64) * 2.0 * np.pi / 64
        faces = np.outer(np.cos(phi), e1) + np.outer(np.sin(phi), e2)
        for end in (0, 1):
            idx = np.arange(n_steps)
            knot = idx + end
            for f in faces:
                rows += [r + idx, r + idx]
                cols += [nx + idx, knot]
                vals += [p1[knot] @ f, p2[knot] @ f]
                rhs.append(np.full(n_steps, accel))
                r += n_steps
    accel_rows = (np.concatenate(rows), np.concatenate(cols), np.concatenate(vals), np.concatenate(rhs), r)
    # jerk: ±(acc of step k − acc of step k−1) ≤ j τ_k, k = 0..N (steps −1 and N at rest)
    dqm, ddqm = 0.5 * (dq[:-1] + dq[1:]), 0.5 * (ddq[:-1] + ddq[1:])
    jerk_terms = []  # (row offset, rows, cols, vals) without the right-hand side
    r = 0
    limited = [i for i in range(axes) if math.isfinite(jlim[i])]
    for i in limited:
        for sign in (1.0, -1.0):
            jr, jc, jv = [], [], []
            for step, factor in ((0, sign), (-1, -sign)):  # step k with +, step k-1 with −
                kk = np.arange(n_steps + 1) + step
                ok = (kk >= 0) & (kk < n_steps)
                row = np.arange(n_steps + 1)[ok]
                kk = kk[ok]
                jr += [row, row, row]
                jc += [nx + kk, kk, kk + 1]
                jv += [factor * dqm[kk, i], factor * 0.5 * ddqm[kk, i], factor * 0.5 * ddqm[kk, i]]
            jerk_terms.append((r, np.concatenate(jr), np.concatenate(jc), np.concatenate(jv), jlim[i]))
            r += n_steps + 1
    jerk_count = r
    # (Every knot alike: on a grid denser near the ends, weights by step length would let
    # the short end steps go slow at no cost.)
    c = np.zeros(nvar)
    c[:nx] = -1.0


    def solve(tau):
        ar, ac, av, ab, n_acc = accel_rows
        rows, cols, vals, rhs = [ar], [ac], [av], [ab]
        if tau is not None and jerk_count:
            for off, jr, jc, jv, j in jerk_terms:
                rows.append(jr + n_acc + off)
                cols.append(jc)
                vals.append(jv)
                rhs.append(j * tau)
        n_rows = n_acc + (jerk_count if tau is not None else 0)
        a_ub = matrix(np.concatenate(rows), np.concatenate(cols), np.concatenate(vals), n_rows)
        res = linprog(c, A_ub=a_ub, b_ub=np.concatenate(rhs), A_eq=eq, b_eq=beq, bounds=bounds,
                      method="highs")
        return None if res.status != 0 else (res.x[:nx], res.x[nx:])

    first = solve(None)
    if first is None:
        return None
    x, u = first
    without = float(step_times(s, x).sum())
    if not limited:
        return without, x, u, without
    previous = None
    for _ in range(MAX_ROUNDS):
        dt = step_times(s, x)
        tau = np.concatenate([[0.5 * dt[0]], 0.5 * (dt[:-1] + dt[1:]), [0.5 * dt[-1]]])
        got = solve(tau)
        if got is None:
            return None
        x, u = got
        duration = float(step_times(s, x).sum())
        if previous is not None and abs(previous - duration) <= TOLERANCE * duration:
            break
        previous = duration
    else:
        warnings.warn(f"jerk_time: no fixed point after {MAX_ROUNDS} rounds (last {duration:.9f} s)")
    return duration, x, u, without


def line_case(vworks, folder, case, ramp, steps, seed=1):
    """Case `case` of bench/fidelity.py's lines on the IRB 120 with jerk limits: a dict."""
    return path_case(vworks, folder, case, ramp, steps, seed, "line")


def path_case(vworks, folder, case, ramp, steps, seed=1, kind="line"):
    """Case `case` of bench/fidelity.py's lines (`kind` "line", a move_l) or arcs ("arc", a
    move_c through its via point) on the IRB 120 with jerk limits: a dict."""
    sys.path.insert(0, str(ROOT / "bench"))
    import fidelity
    from scipy.interpolate import CubicSpline

    model = "irb120"
    limits = fidelity.urdf_limits(model)
    jerks = limits[:, 3] / ramp
    q0, offset, speed = fidelity.draw_case(model, seed, 0, case, limits)
    via = fidelity.draw_via(seed, 0, case, offset) if kind == "arc" else None
    command = "move_c" if kind == "arc" else "move_l"
    cell = fidelity.write_cell(folder, model, q0, offset, speed, via)
    cell.write_text(cell.read_text()
                    + "jerk = [" + ", ".join(f'"{math.degrees(j):.9f}deg/s3"' for j in jerks) + "]\n")
    row = {"case": case, "length_mm": float(np.linalg.norm(offset) * 1000.0), "speed_mps": speed}
    try:
        loaded = vworks.load_cell(str(cell))
        result = loaded.run(check=False)
    except vworks.Error as e:
        row["skipped"] = str(e).splitlines()[0]
        return row
    if result.outcome != "completed":
        row["skipped"] = fidelity.skip_reason(result)
        return row
    events = list(result.events)
    start = next(i for i, e in enumerate(events) if e.kind == "motion_start" and e.data["command"] == command)
    t0, t1 = events[start].time_ns, next(e for e in events[start:] if e.kind == "motion_end").time_ns
    _, q, p = fidelity.record(loaded, t0, t1)
    s, qk, pk = fidelity.path_samples(q, p)
    spline = CubicSpline(s, qk)
    # Uniform, and denser near both ends, where a slow line's jerk ramps are short.
    length = s[-1] - s[0]
    ends = length * np.geomspace(1e-6, 2.0 / steps, END_KNOTS)
    grid = np.unique(np.concatenate([np.linspace(s[0], s[-1], steps + 1), s[0] + ends, s[-1] - ends]))
    grid = grid[np.concatenate([[True], np.diff(grid) > 1e-12 * length])]  # (no step of no length)
    tcp_speed, tcp_accel = fidelity.urdf_tcp(model)
    tcp = None
    if via is not None:
        centre, normal, _ = fidelity.circle(p[0], p[0] + via, p[0] + offset)  # the programmed circle
        e1 = (p[0] - centre) / np.linalg.norm(p[0] - centre)
        at = CubicSpline(s, pk)
        tcp = (at(grid, 1), at(grid, 2), e1, np.cross(normal, e1))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        got = jerk_time(grid, spline(grid, 1), spline(grid, 2), limits[:, 2] * LIMIT_SHARE,
                        limits[:, 3] * LIMIT_SHARE, jerks, min(speed, tcp_speed), tcp_accel, tcp)
    if got is None:
        row["skipped"] = "the oracle found no timing"
        return row
    row["vworks_s"] = (t1 - t0) * 1e-9
    row["oracle_s"], _, _, row["without_jerk_s"] = got
    row["ratio"] = row["vworks_s"] / row["oracle_s"]
    return row


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--cases", type=int, default=40)
    parser.add_argument("--ramp", type=float, default=0.02, help="each axis reaches its acceleration in this time (s)")
    parser.add_argument("--steps", type=int, default=300)
    parser.add_argument("--kind", choices=["line", "arc"], default="line",
                        help="straight lines (move_l) or circular arcs (move_c)")
    args = parser.parse_args()
    import vworks

    ratios, skipped = [], 0
    with tempfile.TemporaryDirectory() as tmp:
        for case in range(args.cases):
            row = path_case(vworks, Path(tmp), case, args.ramp, args.steps, kind=args.kind)
            if "skipped" in row:
                skipped += 1
                continue
            ratios.append(row["ratio"])
            print(f"{args.kind} {case:3d}: {row['length_mm']:5.0f} mm at {row['speed_mps']:g} m/s: vworks "
                  f"{row['vworks_s']:.4f} s, oracle {row['oracle_s']:.4f} s ({row['ratio']:.4f}), "
                  f"without jerk limits {row['without_jerk_s']:.4f} s", flush=True)
    if ratios:
        print(f"\n{len(ratios)} {args.kind}s run, {skipped} skipped; vworks / oracle: median "
              f"{np.median(ratios):.4f}, worst {max(ratios):.4f}, best {min(ratios):.4f}")


if __name__ == "__main__":
    sys.exit(main())
