#!/usr/bin/env python3
"""The built-in arms' published standard cycles, run in vworks: the fidelity table of
docs/models.md ("Dynamics of the built-in arms") and BENCHMARKS.md ("Cycle times against
the vendors' figures").

The 1 kg picking cycle of ISO 9283 / the RIA, as ABB words it for the IRB 120: up 25 mm,
300 mm across, down 25 mm, and back the same way. The vendors state neither the corner
zones nor where in the workspace the cycle runs, so the script runs it four ways at two
places and prints them all:

- from pick `a` = (x, -150 mm, z) to place `b` = (x, +150 mm, z), the tool pointing down,
  at (x, z) = (400 mm, 200 mm) and (450 mm, 100 mm) in the robot's base frame;
- `move_j` or `move_l` between the points, at the model's TCP speed (its
  `<tcp_limits speed>`, else 7 m/s: the axes bound it);
- the four upper corners flying by with `zone 25mm`, or all six points `fine`; pick and
  place are always `fine` (the gripper works there).

A cycle is the mean of 10 back-and-forth rounds after a first `move_j` to `a`, from the
programs' own `now()`.

`--oracle` also times the fly-by `move_l` half-cycle (rest at `a`, up, across, down to rest
at `b`: two corners timed as one path) against toppra on the same joint path, recorded
from vworks at 1 ms, within the same axis and TCP limits, the TCP's whole acceleration
(along the path and towards a corner's centre) within the model's (bench/fidelity.py's
oracle, the path's plane being the y-z plane): how far the `move_l` cycle is from the
fastest timing of its own path. `--accel-time T` runs a copy of the model whose axes reach full speed
in T seconds (the way the IRB 120's estimate was fitted: docs/models.md).

    .venv/bin/python bench/cycle.py [--models irb120 kr6r900] [--accel-time 0.07] [--oracle]

The places suit the IRB 120; another arm may not reach them or pass a singularity on the
way, which the table says instead of a time.

Needs the `vworks` Python package (`scripts/test` builds it into .venv).
"""

import argparse
import re
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
MODELS_DIR = ROOT / "crates" / "model" / "models"

# Published standard cycles (s), with their source: docs/models.md says how far each is
# checked. Models without one are run all the same, for the table.
PUBLISHED = {
    "irb120": (0.58, "ABB IRB 120 data sheet, 1 kg picking cycle 25 x 300 x 25 mm"),
}
PLACES = [(400.0, 200.0), (450.0, 100.0)]  # (x, z) of pick and place, mm
ROUNDS = 10
FALLBACK_SPEED = 7.0  # m/s, where a model gives no TCP speed: the axes bound the motion


def tcp_speed(model):
    text = (MODELS_DIR / f"{model}.urdf").read_text()
    m = re.search(r'<tcp_limits[^>]*\bspeed="([^"]+)"', text)
    return float(m.group(1)) if m else FALLBACK_SPEED


def write_cell(folder, model, motion, zone, x, z, accel_time=None):
    """A one-robot cell that runs the cycle ROUNDS times and logs the mean."""
    if accel_time is None:
        robot = f'model = "{model}"'
    else:
        text = (MODELS_DIR / f"{model}.urdf").read_text()
        # Each joint's <limit>: its acceleration replaced by velocity / T (the TCP limits kept).
        def limit(m):
            tag = re.sub(r'\s+acceleration="[^"]*"', "", m.group(0))
            v = float(re.search(r'velocity="([^"]+)"', tag).group(1))
            return tag.replace("<limit", f'<limit acceleration="{v / accel_time:.9f}"', 1)
        text = re.sub(r"<limit\b[^>]*>", limit, text)
        folder.joinpath("model.urdf").write_text(text)
        robot = 'urdf = "model.urdf"'
    folder.joinpath("cell.toml").write_text(
        f'name = "cycle"\n[[robot]]\nname = "r1"\n{robot}\nprogram = "r1.wsl"\n'
        f'default_speed = "{tcp_speed(model) * 1000.0:g}mm/s"\n'
        'home = ["0deg", "0deg", "0deg", "0deg", "90deg", "0deg"]\n')
    up = f"zone {zone}"
    folder.joinpath("r1.wsl").write_text(f"""
const a = pose({x}mm, -150mm, {z}mm, 180deg, 0deg, 0deg);
const b = pose({x}mm, 150mm, {z}mm, 180deg, 0deg, 0deg);
proc main() {{
    move_j a;
    var t0 = now();
    for i in 0..{ROUNDS} {{
        {motion} offset(a, 0mm, 0mm, 25mm) {up};
        {motion} offset(b, 0mm, 0mm, 25mm) {up};
        {motion} b zone fine;
        {motion} offset(b, 0mm, 0mm, 25mm) {up};
        {motion} offset(a, 0mm, 0mm, 25mm) {up};
        {motion} a zone fine;
    }}
    log (now() - t0) / {ROUNDS};
}}
""")
    return folder / "cell.toml"


def cycle(vworks, folder, model, motion, zone, x, z, accel_time=None):
    """The mean cycle (s), or the reason it did not run."""
    try:
        result = vworks.load_cell(str(write_cell(folder, model, motion, zone, x, z, accel_time))).run()
    except vworks.Error as e:  # out of reach, a singularity on the way: said, not hidden
        return type(e).__name__
    if result.outcome != "completed":
        return f"{result.outcome}"
    return float(result.logs[-1].text.split()[0].rstrip("s"))


def toppra_half(vworks, folder, model, x, z):
    """The fly-by `move_l` half-cycle a → b: (vworks's time, toppra's time on the same path) in s."""
    import warnings

    sys.path.insert(0, str(ROOT / "bench"))
    import fidelity
    import numpy as np

    folder.joinpath("cell.toml").write_text(
        f'name = "half"\n[[robot]]\nname = "r1"\nmodel = "{model}"\nprogram = "r1.wsl"\n'
        f'default_speed = "{tcp_speed(model) * 1000.0:g}mm/s"\n'
        'home = ["0deg", "0deg", "0deg", "0deg", "90deg", "0deg"]\n')
    folder.joinpath("r1.wsl").write_text(f"""
const a = pose({x}mm, -150mm, {z}mm, 180deg, 0deg, 0deg);
const b = pose({x}mm, 150mm, {z}mm, 180deg, 0deg, 0deg);
proc main() {{
    move_j a;
    move_l offset(a, 0mm, 0mm, 25mm) zone 25mm;
    move_l offset(b, 0mm, 0mm, 25mm) zone 25mm;
    move_l b zone fine;
}}
""")
    cell = vworks.load_cell(str(folder / "cell.toml"))
    events = [e for e in cell.run().events if e.kind in ("motion_start", "motion_end")]
    t0, t1 = events[2].time_ns, events[-1].time_ns  # the first move_l's start, the last's end
    _, q, p = fidelity.record(cell, t0, t1)
    s, qk, pk = fidelity.path_samples(q, p)
    limits = fidelity.urdf_limits(model)
    speed, accel = fidelity.urdf_tcp(model)
    plane = (pk, np.array([0.0, 1.0, 0.0]), np.array([0.0, 0.0, 1.0]))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        best = fidelity.toppra_time(s, qk, limits[:, 2], limits[:, 3], speed, accel, plane)
    return (t1 - t0) * 1e-9, best


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--models", nargs="+", default=list(PUBLISHED),
                        choices=["irb120", "kr6r900", "lrmate200id", "ur5"],
                        help="default: the models with a published cycle")
    parser.add_argument("--accel-time", type=float, help="axes reach full speed in this time (s)")
    parser.add_argument("--oracle", action="store_true",
                        help="also time the fly-by move_l half-cycle against toppra on its own path")
    args = parser.parse_args()
    import vworks

    print("the 25 x 300 x 25 mm cycle (s), mean of 10 rounds; fly-by = zone 25mm at the upper corners")
    if args.accel_time:
        print(f"(axes reach full speed in {args.accel_time} s)")
    print()
    print("| model | (x, z) mm | move_j fly-by | move_j fine | move_l fly-by | move_l fine | published |")
    print("|---|---|---|---|---|---|---|")
    with tempfile.TemporaryDirectory() as tmp:
        for model in args.models:
            published = PUBLISHED.get(model)
            for x, z in PLACES:
                cells = []
                for motion in ("move_j", "move_l"):
                    for zone in ("25mm", "fine"):
                        t = cycle(vworks, Path(tmp), model, motion, zone, x, z, args.accel_time)
                        if isinstance(t, float) and published:
                            cells.append(f"{t:.3f} ({t / published[0] - 1:+.1%})")
                        elif isinstance(t, float):
                            cells.append(f"{t:.3f}")
                        else:
                            cells.append(t)
                pub = f"{published[0]:.2f} ({published[1]})" if published else "none published"
                print(f"| {model} | ({x:g}, {z:g}) | " + " | ".join(cells) + f" | {pub} |")
    if args.oracle and not args.accel_time:
        print()
        print("fly-by move_l half-cycle (rest at a to rest at b) against toppra on the same path:")
        print()
        print("| model | (x, z) mm | vworks | toppra | ratio |")
        print("|---|---|---|---|---|")
        with tempfile.TemporaryDirectory() as tmp:
            for model in args.models:
                for x, z in PLACES:
                    ours, best = toppra_half(vworks, Path(tmp), model, x, z)
                    ratio = f"{ours / best:.4f}" if best else "toppra found no profile"
                    print(f"| {model} | ({x:g}, {z:g}) | {ours:.4f} s | {best or 0:.4f} s | {ratio} |")


if __name__ == "__main__":
    sys.exit(main())
