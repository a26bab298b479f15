#!/usr/bin/env python3
"""The side-by-side benchmarks against the performance targets, in one run; writes BENCHMARKS.md.

    .venv/bin/python bench/compare.py             # everything; rewrites BENCHMARKS.md
    .venv/bin/python bench/compare.py --profile   # also a perf profile of (b) and (c)
    .venv/bin/python bench/compare.py --print     # print the report instead of writing it

What it measures, all on this machine, in this one run:

(a) per-cycle FK + collision checks of a 4-robot cell (bench/cells/grid4): vworks (the
    Rust bench `scaling`, every pair its broadphase keeps queried at every boundary) against
    Pinocchio + coal (`computeCollisions` over every pair of the same primitive shapes) and
    PyBullet (`resetJointState` + `performCollisionDetection` on the same URDF), both fed
    the joint values vworks computes for the cell's first 1,000 cycles;
(b) the cell's simulated minute with and without the full log (Rust bench `scaling`);
(c) scheduler throughput: signal ping-pong and set/wait_until rings (Rust bench `events`)
    against the same models in SimPy;
(d) cost per cycle for 1, 4, 16 and 64 robots (Rust bench `scaling`).

Needs the dev environment of scripts/test (.venv with vworks, pin, pybullet, simpy) and
cargo. `--profile` needs `perf`.
"""

import argparse
import json
import os
import platform
import re
import statistics
import subprocess
import sys
import tempfile
import time
import xml.etree.ElementTree as ET

import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
CELL = os.path.join(ROOT, "bench", "cells", "grid4", "cell.toml")
URDF = os.path.join(ROOT, "crates", "model", "models", "irb120.urdf")
CYCLES = 1000  # (a): the cell's first 4 simulated seconds


# --- the Rust side --------------------------------------------------------------------


def cargo_bench(bench):
    """Runs one criterion bench of vworks-se; returns the lines it prints that start with
    a target's letter, e.g. `(b) ...`."""
    out = subprocess.run(
        ["cargo", "bench", "-q", "-p", "vworks-se", "--bench", bench, "--",
         "--warm-up-time", "1", "--measurement-time", "2"],
        cwd=ROOT, check=True, capture_output=True, text=True,
    ).stdout
    return [line for line in out.splitlines() if re.match(r"^\([a-d]\)", line)]


def number(pattern, lines):
    for line in lines:
        m = re.search(pattern, line)
        if m:
            return [float(g.replace(",", "")) for g in m.groups()]
    raise RuntimeError(f"no line matches {pattern!r} in:\n" + "\n".join(lines))


# --- (a) Pinocchio + coal and PyBullet -----------------------------------------------


def trajectory():
    """The joint values of every robot at each of the cell's first CYCLES boundaries, as
    vworks computes them."""
    import vworks

    cell = vworks.load_cell(CELL)
    sim = cell.simulation()
    qs = []
    for _ in range(CYCLES):
        sim.step_cycle()
        qs.append(np.concatenate([sim.robot(n).joints for n in cell.robots]))
    bases = []
    for line in open(CELL):
        m = re.match(r'base = \{ xyz = \["([-\d.]+)mm", "([-\d.]+)mm", "([-\d.]+)mm"\] \}', line)
        if m:
            bases.append([float(v) / 1000 for v in m.groups()])
    return qs, bases


def placement(el):
    import pinocchio as pin

    o = el.find("origin")
    xyz = [float(v) for v in o.get("xyz", "0 0 0").split()] if o is not None else [0, 0, 0]
    rpy = [float(v) for v in o.get("rpy", "0 0 0").split()] if o is not None else [0, 0, 0]
    return pin.SE3(pin.rpy.rpyToMatrix(*rpy), np.array(xyz))


def coal_shape(geometry):
    import coal

    g = list(geometry)[0]
    if g.tag == "box":
        return coal.Box(*[float(v) for v in g.get("size").split()])
    if g.tag == "capsule":
        return coal.Capsule(float(g.get("radius")), float(g.get("length")))
    if g.tag == "sphere":
        return coal.Sphere(float(g.get("radius")))
    if g.tag == "cylinder":
        return coal.Cylinder(float(g.get("radius")), float(g.get("length")))
    raise ValueError(f"{g.tag} is not a primitive")


def pinocchio_robot(prefix):
    """The irb120 as a Pinocchio model (kinematics from the URDF) and a coal geometry model
    of the same primitive shapes (urdfdom cannot read `<capsule>`, so they are built here)."""
    import pinocchio as pin

    root = ET.parse(URDF).getroot()
    for el in root.iter():
        if el.tag in ("link", "joint") and el.get("name"):
            el.set("name", prefix + el.get("name"))
        if el.tag in ("parent", "child"):
            el.set("link", prefix + el.get("link"))
    kinematics = ET.fromstring(ET.tostring(root))
    for link in kinematics.findall("link"):
        for c in link.findall("collision"):
            link.remove(c)
    model = pin.buildModelFromXML(ET.tostring(kinematics, encoding="unicode"))
    geom = pin.GeometryModel()
    for link in root.findall("link"):
        for k, c in enumerate(link.findall("collision")):
            f = model.getFrameId(link.get("name"))
            frame = model.frames[f]
            geom.addGeometryObject(pin.GeometryObject(
                f"{link.get('name')}#{k}", frame.parentJoint, f,
                frame.placement * placement(c), coal_shape(c.find("geometry"))))
    return model, geom


def pinocchio(qs, bases):
    import pinocchio as pin

    model, geom = pinocchio_robot("r0/")
    for i, (x, y, z) in enumerate(bases[1:], start=1):
        m, g = pinocchio_robot(f"r{i}/")
        model, geom = pin.appendModel(model, m, geom, g, 0, pin.SE3(np.eye(3), np.array([x, y, z])))
    objs = geom.geometryObjects
    robot = [o.name.split("/")[0] for o in objs]
    # Every pair of two robots' shapes and of one robot's non-adjacent links; then, as
    # vworks does, drop the pairs that overlap at the zero pose.
    link = [o.name.split("/")[1].split("#")[0] for o in objs]
    order = ["base_link"] + [f"link_{k}" for k in range(1, 7)]
    for a in range(len(objs)):
        for b in range(a + 1, len(objs)):
            if robot[a] != robot[b] or abs(order.index(link[a]) - order.index(link[b])) >= 2:
                geom.addCollisionPair(pin.CollisionPair(a, b))
    data, gdata = model.createData(), geom.createData()
    pin.computeCollisions(model, data, geom, gdata, np.zeros(model.nq), False)
    overlapping = [k for k, r in enumerate(gdata.collisionResults) if r.isCollision()]
    for k in reversed(overlapping):
        geom.removeCollisionPair(geom.collisionPairs[k])
    data, gdata = model.createData(), geom.createData()
    collisions = sum(pin.computeCollisions(model, data, geom, gdata, q, False) for q in qs)
    best = min(timed(lambda: [pin.computeCollisions(model, data, geom, gdata, q, False) for q in qs])
               for _ in range(7))
    return best / len(qs), len(geom.collisionPairs), collisions


def pybullet(qs, bases):
    import pybullet as p

    cid = p.connect(p.DIRECT)
    flags = p.URDF_USE_SELF_COLLISION | p.URDF_USE_SELF_COLLISION_EXCLUDE_PARENT
    with quiet():
        bodies = [p.loadURDF(URDF, b, useFixedBase=True, flags=flags, physicsClientId=cid) for b in bases]

    def run():
        for q in qs:
            for i, body in enumerate(bodies):
                for j in range(6):
                    p.resetJointState(body, j, q[6 * i + j], physicsClientId=cid)
            p.performCollisionDetection(physicsClientId=cid)

    best = min(timed(run) for _ in range(7))
    p.disconnect(cid)
    return best / len(qs)


class quiet:
    """Silences the C++ warnings loaders print on stdout/stderr."""

    def __enter__(self):
        self.saved = [os.dup(1), os.dup(2)]
        null = os.open(os.devnull, os.O_WRONLY)
        os.dup2(null, 1)
        os.dup2(null, 2)
        os.close(null)

    def __exit__(self, *exc):
        os.dup2(self.saved[0], 1)
        os.dup2(self.saved[1], 2)
        for fd in self.saved:
            os.close(fd)


def timed(f):
    t0 = time.perf_counter()
    f()
    return time.perf_counter() - t0


# --- (c) SimPy -----------------------------------------------------------------------


def simpy_models():
    import simpy

    class Counted(simpy.Environment):
        def __init__(self):
            super().__init__()
            self.processed = 0

        def step(self):
            self.processed += 1
            super().step()

    def ping_pong(rounds):
        env = Counted()
        ping, pong = [env.event()], [env.event()]

        def a():
            for _ in range(rounds):
                ping[0].succeed()
                yield pong[0]
                pong[0] = env.event()

        def b():
            for _ in range(rounds):
                yield ping[0]
                ping[0] = env.event()
                pong[0].succeed()

        env.process(a())
        env.process(b())
        env.run()
        return env.processed

    def ring(n, rounds):
        # Each of n processes waits until `turn` is its own, then advances it: a condition
        # re-tested on every change, as wait_until is.
        env = Counted()
        state = {"turn": 0, "changed": env.event()}

        def robot(k):
            for i in range(rounds):
                while state["turn"] != i * n + k:
                    yield state["changed"]
                state["turn"] += 1
                changed, state["changed"] = state["changed"], env.event()
                changed.succeed()

        for k in range(n):
            env.process(robot(k))
        env.run()
        return env.processed

    return ping_pong, ring


def simpy_rates(rounds=20_000):
    ping_pong, ring = simpy_models()
    out = {}
    for name, f, args in [("ping-pong", ping_pong, (rounds,))] + [
            (f"ring of {n}", ring, (n, rounds // n)) for n in (2, 8, 32)]:
        best, processed = float("inf"), 0
        for _ in range(3):
            t0 = time.perf_counter()
            processed = f(*args)
            best = min(best, time.perf_counter() - t0)
        out[name] = (rounds / best, processed / best)
    return out


# --- profiles ------------------------------------------------------------------------


GROUPS = [
    ("collision checks (vworks_se::collide)", r"vworks_se::collide"),
    ("parry3d (narrowphase, GJK)", r"parry3d"),
    ("FK and IK (vworks_model)", r"vworks_model"),
    ("sin/cos/atan2/acos (libm)", r"libm|__sin|__cos|atan|acos"),
    ("VM (vworks_vm)", r"vworks_vm"),
    ("scheduler, trace (vworks_se::engine)", r"vworks_se::engine"),
    ("binary heap", r"binary_heap"),
    ("allocation, memcpy (libc)", r"malloc|free|memmove|memcpy|_int_|libc"),
    ("kernel (page faults)", r"\[k\]"),
]


def profile(bench, filt):
    """Shares of a perf profile of one criterion bench, grouped by where the code lives."""
    exe = subprocess.run(
        ["cargo", "bench", "-q", "-p", "vworks-se", "--bench", bench, "--no-run",
         "--message-format=json"], cwd=ROOT, check=True, capture_output=True, text=True).stdout
    path = re.findall(r'"executable":"([^"]+)"', exe)[-1]
    data = os.path.join(tempfile.mkdtemp(), "perf.data")
    subprocess.run(["perf", "record", "-o", data, path, "--bench", filt, "--profile-time", "5"],
                   cwd=ROOT, check=True, capture_output=True)
    rep = subprocess.run(["perf", "report", "-i", data, "--no-children", "--stdio",
                          "--percent-limit", "0.1"], capture_output=True, text=True).stdout
    shares = {name: 0.0 for name, _ in GROUPS}
    other = 0.0
    for line in rep.splitlines():
        m = re.match(r"\s+([\d.]+)%\s+\S+\s+(\S+)\s+(\[.\])\s+(.*)", line)
        if not m:
            continue
        pct, dso, kind, sym = float(m.group(1)), m.group(2), m.group(3), m.group(4)
        text = f"{dso} {kind} {sym}"
        for name, pat in GROUPS:
            if re.search(pat, text):
                shares[name] += pct
                break
        else:
            other += pct
    shares["other"] = other
    return shares


# --- the report ----------------------------------------------------------------------


def whole_process(cell, runs=7):
    """`vworks run CELL` as a whole process (load included), release build: the median wall
    time of `runs` runs and the simulated span, as (seconds, simulated seconds)."""
    exe = os.path.join(ROOT, "target", "release", "vworks")
    subprocess.run(["cargo", "build", "--release", "--locked", "-q", "-p", "vworks-cli"], cwd=ROOT,
                   check=True)
    out = subprocess.run([exe, "run", cell, "--json"], capture_output=True, text=True, check=True)
    simulated = json.loads(out.stdout)["end_time_ns"] / 1e9
    times = []
    for _ in range(runs):
        start = time.perf_counter()
        subprocess.run([exe, "run", cell, "-q"], capture_output=True, check=True)
        times.append(time.perf_counter() - start)
    return statistics.median(times), simulated


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--profile", action="store_true", help="also profile (b) and (c) with perf")
    ap.add_argument("--print", action="store_true", help="print instead of writing BENCHMARKS.md")
    args = ap.parse_args()

    print("vworks benches (cargo bench)...", file=sys.stderr)
    scaling = cargo_bench("scaling")
    events = cargo_bench("events")
    print("(a) Pinocchio + coal, PyBullet...", file=sys.stderr)
    qs, bases = trajectory()
    pin_s, pin_pairs, pin_collisions = pinocchio(qs, bases)
    pb_s = pybullet(qs, bases)
    print("(c) SimPy...", file=sys.stderr)
    simpy = simpy_rates()
    print("(e) whole processes...", file=sys.stderr)
    shared = os.path.join(ROOT, "bench", "cells", "shared4", "cell.toml")
    e_s, e_sim = whole_process(shared)
    g_s, g_sim = whole_process(CELL)
    shares = None
    if args.profile:
        print("profiles (perf)...", file=sys.stderr)
        shares = [("(b) the 4-robot minute", profile("scaling", "four_robots")),
                  ("(c) set/wait_until ring of 32", profile("events", "ring_32")),
                  ("(c) signal ping-pong", profile("events", "ping_pong"))]

    a_us, a_cycles, a_queries = number(
        r"\(a\).*: ([\d.]+) µs per cycle \((\d+) cycles, ([\d.]+) queries", scaling)
    b = number(r"\(b\) 4 robots, ([\d.]+) simulated s.*?(\d+) cycles, (\d+) queries: ([\d.]+) ms = "
               r"(\d+)x real time; with the full log ([\d.]+) ms = (\d+)x", scaling)
    sim_s, b_cycles, b_queries, b_ms, b_x, bl_ms, bl_x = b
    d = {}
    for n in (1, 4, 16, 64):
        d[n] = number(rf"\(d\)\s+{n} robots: ([\d.]+) µs per cycle \(\d+ cycles, ([\d.]+) queries",
                      scaling)
    c = {}
    for name, key in [("ping-pong", r"ping-pong"), ("ring of 2", r"ring of 2"),
                      ("ring of 8", r"ring of 8"), ("ring of 32", r"ring of 32")]:
        n_events, rate = number(rf"\(c\).*{key}: (\d+) events, ([\d.]+) M events/s", events)
        c[name] = (n_events, rate * 1e6)

    lines = []
    w = lines.append
    w(BEGIN)
    w("Written by `bench/compare.py`, which runs every measurement below in one go")
    w(f"on this machine: {platform.machine()}, {os.cpu_count()} cores, {platform.system()} "
      f"{platform.release()}, Python {platform.python_version()}. The machine is a shared VM:")
    w("repeated runs differ by 10–20 % (docs/log.md). Criterion benches print the numbers")
    w("(`cargo bench -p vworks-se --bench scaling|events`); the script parses them.")
    w("")
    ratio_a = a_us / (pin_s * 1e6)
    w("| Target | Measured | Met? |")
    w("|---|---|---|")
    w(f"| (a) per-cycle FK + collision checks of a 4-robot cell ≤ 0.5 × Pinocchio+coal | "
      f"{ratio_a:.2f}× ({a_us:.2f} µs against {pin_s * 1e6:.1f} µs) | {yes(ratio_a <= 0.5)} |")
    w(f"| (b) 60 s, 4 robots, 4 ms cycles, collision checks: ≥ 1000× real time | "
      f"{b_x:.0f}× ({b_ms:.1f} ms) | {yes(b_x >= 1000)} |")
    w(f"| (b) the same with the full log: ≥ 300× real time | {bl_x:.0f}× ({bl_ms:.1f} ms) | "
      f"{yes(bl_x >= 300)} |")
    rates = [r for _, r in c.values()]
    w(f"| (c) scheduler: ≥ 10 M events/s | {min(rates) / 1e6:.1f}–{max(rates) / 1e6:.1f} M "
      f"events/s | {yes(min(rates) >= 10e6)} |")
    vs = {k: (c[k][1] / c[k][0] * 20_000) / simpy[k][0] for k in c}
    w(f"| (c) ≥ 50× SimPy (rounds of work per second) | {min(vs.values()):.1f}–"
      f"{max(vs.values()):.1f}× | {yes(min(vs.values()) >= 50)} |")
    r64 = d[64][0] / d[4][0]
    w(f"| (d) 64 robots ≤ 20× the per-cycle cost of 4 | {r64:.1f}× | {yes(r64 <= 20)} |")
    e_x = e_sim / e_s
    w(f"| (e) 60 s, 4 robots around one shared table (`bench/cells/shared4`), `vworks run` as a "
      f"whole process: ≥ 1000× real time | {e_x:.0f}× ({e_s * 1e3:.0f} ms for {e_sim:.1f} s; "
      f"grid4 the same way: {g_sim / g_s:.0f}×) | {yes(e_x >= 1000)} |")
    w("")
    w("## (a) Per-cycle FK + collision checks: vworks, Pinocchio + coal, PyBullet")
    w("")
    w("The cell `bench/cells/grid4`: four irb120 arms 1.2 m apart, each looping a joint move")
    w("and a straight-line move. Every tool gets the joint values vworks computes at the")
    w(f"cell's first {CYCLES:,} boundaries (4 ms cycles) and the same primitive shapes (the")
    w("irb120 URDF's boxes, capsules, spheres and cylinders).")
    w("")
    w("| Tool | What one cycle does | µs per cycle | × vworks |")
    w("|---|---|---|---|")
    w(f"| vworks | joint interpolation (VM), FK, broadphase, exact or GJK queries of the "
      f"{a_queries:.1f} pairs per cycle the broadphase keeps | {a_us:.2f} | 1 |")
    w(f"| Pinocchio {pin_version()} + coal | `computeCollisions`: FK, placements, all {pin_pairs} "
      f"pairs (two robots' shapes; one robot's links two or more apart; minus those "
      f"overlapping at the zero pose, as vworks skips them) | {pin_s * 1e6:.1f} | "
      f"{pin_s * 1e6 / a_us:.1f} |")
    w(f"| PyBullet | `resetJointState` × 24 + `performCollisionDetection` (its own broadphase) "
      f"| {pb_s * 1e6:.1f} | {pb_s * 1e6 / a_us:.1f} |")
    w("")
    w(f"Pinocchio reports {pin_collisions} colliding cycles on the trajectory, as vworks finds no")
    w("collision in it. vworks's lead comes from its broadphase (Pinocchio's `computeCollisions`")
    w("queries every pair), from closed-form capsule distances, and from skipping robots that")
    w("did not move; PyBullet pays a Python call per joint.")
    w("")
    w("## (b) The 4-robot minute")
    w("")
    w(f"{sim_s:.1f} simulated seconds, {b_cycles:,.0f} cycles, collision checks with the sweep "
      f"between boundaries and adaptive checking ({b_queries:,.0f} queries): {b_ms:.1f} ms = "
      f"{b_x:.0f}× real time; with the full MCAP log {bl_ms:.1f} ms = {bl_x:.0f}× real time.")
    w("")
    w("## (c) Scheduler throughput against SimPy")
    w("")
    w("| Model (20,000 rounds) | vworks events | vworks M events/s | vworks rounds/s | "
      "SimPy rounds/s (M events/s) | vworks / SimPy |")
    w("|---|---|---|---|---|---|")
    for k, (n_events, rate) in c.items():
        rounds = rate / n_events * 20_000
        w(f"| {k} | {n_events:,.0f} | {rate / 1e6:.2f} | {rounds / 1e3:,.0f} k | "
          f"{simpy[k][0] / 1e3:,.0f} k ({simpy[k][1] / 1e6:.2f}) | {vs[k]:.1f}× |")
    w("")
    w("A vworks round is several trace events (the signal, the wait, its end; a `set`, the")
    w("`check_wait` of every robot waiting on the global, the `wait_end`); SimPy processes")
    w("about two events per round and records nothing.")
    w("")
    w("## (d) Scaling")
    w("")
    w("| Robots | µs per cycle | queries per cycle |")
    w("|---|---|---|")
    for n, (us, q) in sorted(d.items()):
        w(f"| {n} | {us:.2f} | {q:.1f} |")
    w("")
    w(f"64 robots cost {r64:.1f}× the per-cycle cost of 4.")
    if shares:
        w("")
        w("## Where the time goes")
        w("")
        w("Shares of `perf` samples (self time, grouped by where the code lives):")
        w("")
        w("| Group | " + " | ".join(name for name, _ in shares) + " |")
        w("|---|" + "---|" * len(shares))
        for g in [name for name, _ in GROUPS] + ["other"]:
            w(f"| {g} | " + " | ".join(f"{s[g]:.0f} %" for _, s in shares) + " |")
    w(END)
    text = "\n".join(lines)
    if args.print:
        print(text)
        return
    # The numbers replace the generated part of BENCHMARKS.md; the analysis around them is
    # written by hand.
    path = os.path.join(ROOT, "BENCHMARKS.md")
    old = open(path).read() if os.path.exists(path) else "# Benchmarks\n\n" + BEGIN + END + "\n"
    if BEGIN not in old or END not in old:
        old = "# Benchmarks\n\n" + BEGIN + END + "\n" + old
    head, rest = old.split(BEGIN, 1)
    tail = rest.split(END, 1)[1]
    with open(path, "w") as f:
        f.write(head + text + tail)
    print("updated BENCHMARKS.md", file=sys.stderr)


BEGIN = "<!-- generated by bench/compare.py: do not edit by hand -->"
END = "<!-- end of the generated part -->"


def yes(ok):
    return "yes" if ok else "**no**"


def pin_version():
    import pinocchio as pin

    return pin.__version__


if __name__ == "__main__":
    main()
