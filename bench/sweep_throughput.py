#!/usr/bin/env python3
"""Sweep throughput on workcells/handoff: a 1,000-variant sweep (r2's base over a 40 x 25
grid, its program's params tied to it) in variants per second — locally with 1 and 2
threads (`vworks sweep --jobs`, release build), and on a local Ray cluster of 2 CPUs
(`vworks.sweep(backend="ray")`); and the overhead of a variant beyond its simulation (the
same sweep stopped at 1 ms of simulated time). BENCHMARKS.md, "Sweeps".

    .venv/bin/python bench/sweep_throughput.py [--variants-per-side 40 25]
"""

import argparse
import re
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
VWORKS = ROOT / "target" / "release" / "vworks"
CELL = ROOT / "workcells" / "handoff" / "cell.toml"


def sweep_file(tmp: Path, nx: int, ny: int, until: str = "") -> Path:
    p = tmp / f"sweep{until.replace(' ', '')}.toml"
    p.write_text(
        f'cell = "{CELL}"\n' + (f'until = "{until}"\n' if until else "")
        + '[[variable]]\npath = ["robot.r2.base.xyz.0", "robot.r2.params.base_x"]\n'
        + f'range = {{ from = "450mm", to = "750mm", steps = {nx} }}\n'
        + '[[variable]]\npath = ["robot.r2.base.xyz.1", "robot.r2.params.base_y"]\n'
        + f'range = {{ from = "450mm", to = "750mm", steps = {ny} }}\n'
    )
    return p


def cli(path: Path, jobs: int, tmp: Path) -> float:
    out = subprocess.run([VWORKS, "sweep", path, "--jobs", str(jobs), "-q", "-o", tmp / "t.csv", "--html",
                          tmp / "t.html"], capture_output=True, text=True, check=True)
    n, seconds = re.search(r"(\d+) variants in ([\d.]+) s", out.stderr).groups()
    return int(n) / float(seconds)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--variants-per-side", nargs=2, type=int, default=[40, 25])
    args = parser.parse_args()
    nx, ny = args.variants_per_side
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        full, short = sweep_file(tmp, nx, ny), sweep_file(tmp, nx, ny, "1ms")
        n = nx * ny
        one, two = cli(full, 1, tmp), cli(full, 2, tmp)
        overhead = 1000.0 / cli(short, 1, tmp)
        print(f"{n} variants of handoff: 1 thread {one:.1f} variants/s, 2 threads {two:.1f} variants/s "
              f"({two / one:.2f}x)")
        print(f"overhead per variant (the same sweep stopped at 1 ms, 1 thread): {overhead:.3f} ms")
        import ray
        import vworks

        ray.init(address="local", num_cpus=2, include_dashboard=False, _node_ip_address="127.0.0.1",
                 log_to_driver=False)
        grid = {
            ("robot.r2.base.xyz.0", "robot.r2.params.base_x"): [0.45 + 0.3 * k / (nx - 1) for k in range(nx)],
            ("robot.r2.base.xyz.1", "robot.r2.params.base_y"): [0.45 + 0.3 * k / (ny - 1) for k in range(ny)],
        }
        start = time.perf_counter()
        df = vworks.sweep(str(CELL), grid, backend="ray")
        seconds = time.perf_counter() - start
        ray.shutdown()
        assert len(df) == n
        print(f"Ray, local cluster of 2 CPUs: {n / seconds:.1f} variants/s ({seconds:.1f} s, cluster already started)")


if __name__ == "__main__":
    sys.exit(main())
