#!/usr/bin/env python3
"""The report's 3D view on bench/cells/grid4 (four arms, 60 simulated seconds): the file's
size, how soon the first frame is drawn and how fast it plays back, in headless Chromium
with software WebGL (SwiftShader) — BENCHMARKS.md, "The report's 3D view".

    .venv/bin/python bench/report_view.py [--loads 5] [--play 5]

Needs the release binary (`cargo build --release -p vworks-cli`) and the test tools in .venv
(websocket-client, Chromium: `scripts/test` installs them).
- first frame: `performance.now()` when the page has drawn its first 3D frame and the
  renderer has finished it, counted from the navigation's start (the page stores it);
- playback: Play at 1x for `--play` seconds of wall time, frames drawn per second (headless
  Chromium paces animation frames at 60 per second at most);
- render: the mean time to pose, colour and draw one frame and read a pixel back (which
  waits for the frame), 300 frames a simulated 1/30 s apart.
"""

import argparse
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "tests" / "python"))

from browser import Browser  # noqa: E402


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--loads", type=int, default=5, help="page loads for the first frame (median)")
    parser.add_argument("--play", type=float, default=5.0, help="seconds of playback to count frames over")
    args = parser.parse_args()
    vworks = ROOT / "target" / "release" / "vworks"
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        log, page = tmp / "grid4.mcap", tmp / "grid4.html"
        subprocess.run([vworks, "run", ROOT / "bench" / "cells" / "grid4" / "cell.toml", "--log", log],
                       check=True, capture_output=True)
        start = time.perf_counter()
        subprocess.run([vworks, "report", log, "-o", page], check=True, capture_output=True)
        written = time.perf_counter() - start
        size = page.stat().st_size
        with Browser(tmp / "profile") as b:
            first = []
            for _ in range(args.loads):
                b.open("about:blank")
                b.open(page.as_uri())
                first.append(b.eval("window.vworksView.view.firstFrameMs"))
            view = "window.vworksView.view"
            software = b.eval(f"{view}.software")
            render = b.eval(f"{view}.benchmark(300, 33333333)")
            b.eval("window.vworksView.setTime(0)")
            n0, t0 = b.eval(f"{view}.drawn()"), b.eval("performance.now()")
            b.eval("document.getElementById('play').click()")
            time.sleep(args.play)
            n1, t1 = b.eval(f"{view}.drawn()"), b.eval("performance.now()")
            b.eval("document.getElementById('play').click()")
            assert b.errors() == [], b.errors()
    print(f"report of grid4 (60 s, 4 robots): {size:,} bytes")
    print(f"written in {written * 1000:.0f} ms (vworks report, release)")
    print(f"first frame drawn: median {statistics.median(first):.0f} ms after navigation "
          f"(of {args.loads}: {', '.join(f'{v:.0f}' for v in first)})")
    print(f"playback at 1x: {(n1 - n0) / (t1 - t0) * 1000:.1f} frames/s over {args.play:.0f} s")
    print(f"render: {render:.2f} ms per frame ({'software' if software else 'GPU'} WebGL)")


if __name__ == "__main__":
    main()
