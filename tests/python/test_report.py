"""`vworks report`: the HTML report of a run, opened in headless Chromium.

Chromium renders the page (its JavaScript included) and takes a screenshot; the test
asserts on the page as Chromium built it (the DOM after the scripts ran) and on the
screenshot's pixels: the Gantt chart must be visible, with its colours where the rows are.
The screenshot is written to a temporary folder and not kept.
"""

import os
import re
import shutil
import subprocess
from pathlib import Path

import numpy as np
import pytest
from PIL import Image

ROOT = Path(__file__).resolve().parents[2]
VWORKS = os.environ.get("VWORKS", str(ROOT / "target" / "debug" / "vworks"))

MOVING = (0x2F, 0x6F, 0xDF)
WAITING = (0xF0, 0xA0, 0x30)
COLLISION = (0xD6, 0x27, 0x28)


def chromium():
    for name in ("chromium", "chromium-browser", "google-chrome"):
        path = shutil.which(name)
        if path:
            return path
    pytest.fail("headless Chromium is needed: apt-get install chromium (scripts/test installs it)")


def browse(page, tmp, *args):
    return subprocess.run(
        [chromium(), "--headless", "--no-sandbox", "--disable-gpu", "--hide-scrollbars",
         "--window-size=1280,1000", f"--user-data-dir={tmp / 'profile'}", *args, page.as_uri()],
        capture_output=True, text=True, timeout=120, check=True,
    ).stdout


def report(cell, tmp, *run_args):
    log = tmp / f"{cell}.mcap"
    subprocess.run([VWORKS, "run", str(ROOT / "workcells" / cell / "cell.toml"), "--log", str(log),
                    *run_args], capture_output=True, check=False)
    out = subprocess.run([VWORKS, "report", str(log), "-o", str(tmp / f"{cell}.html")],
                         capture_output=True, text=True)
    assert out.returncode == 0, out.stderr
    assert re.match(r"wrote .*\.html \(\d+ robots, \d+ events, \d+ collisions\)", out.stderr)
    return tmp / f"{cell}.html"


def pixels(png, colour, box):
    """How many pixels of `box` have `colour` (within 6 per channel)."""
    image = np.asarray(Image.open(png).convert("RGB").crop(box)).astype(int)
    return int((np.abs(image - np.array(colour)).max(axis=2) <= 6).sum())


def test_the_handoff_report_renders_with_a_visible_gantt_chart(tmp_path):
    page = report("handoff", tmp_path)
    dom = browse(page, tmp_path, "--dump-dom")
    # The page as Chromium built it: title, cycle times, one chart row per robot, the
    # event table filled and counted by the page's script.
    assert "<title>vworks report: handoff</title>" in dom
    assert re.search(r"<td>r1</td><td class=\"num\">63\.418 s</td>", dom)
    assert re.search(r"<td>r2</td><td class=\"num\">56\.198 s</td>", dom)
    assert dom.count('<g class="row"') == 2
    assert dom.count('class="moving"') > 20 and dom.count('class="waiting"') > 5
    assert dom.count('class="signal"') >= 5
    assert "187 of 187 events shown" in dom  # written by the script, so it ran
    assert "No collision." in dom
    shot = tmp_path / "handoff.png"
    browse(page, tmp_path, f"--screenshot={shot}")
    assert Image.open(shot).size == (1280, 1000)
    # The chart sits below the cycle-time table: its bars are on screen, in both colours.
    chart = (0, 250, 1280, 450)
    assert pixels(shot, MOVING, chart) > 10_000
    assert pixels(shot, WAITING, chart) > 5_000


def test_a_collision_is_marked_in_the_chart_and_listed(tmp_path):
    page = report("crash", tmp_path)
    dom = browse(page, tmp_path, "--dump-dom")
    assert dom.count('class="collision"') == 1
    assert re.search(r"<table id=\"collisions\">.*left\.link_6 right\.link_6", dom, re.S)
    assert "near miss" in dom  # the warning before the collision
    shot = tmp_path / "crash.png"
    browse(page, tmp_path, f"--screenshot={shot}")
    assert pixels(shot, COLLISION, (0, 200, 1280, 480)) > 20


def test_the_event_filter_narrows_the_table(tmp_path):
    page = report("handoff", tmp_path)
    # The page's script filters by the selects' values when it loads: a copy with the kind
    # `signal` preselected must show exactly the signal rows.
    text = page.read_text()
    filtered = tmp_path / "filtered.html"
    filtered.write_text(text.replace("<option>signal</option>", "<option selected>signal</option>", 1))
    dom = browse(filtered, tmp_path, "--dump-dom")
    shown = re.search(r"(\d+) of 187 events shown", dom)
    assert shown and 0 < int(shown.group(1)) < 187
    assert int(shown.group(1)) == text.count('data-kind="signal"')
    assert dom.count('style="display: none;"') == 187 - int(shown.group(1))


def test_a_missing_log_is_an_error_that_names_it(tmp_path):
    out = subprocess.run([VWORKS, "report", str(tmp_path / "nope.mcap")], capture_output=True, text=True)
    assert out.returncode == 1
    assert "nope.mcap" in out.stderr


def test_python_writes_the_same_report(tmp_path):
    import vworks

    log = tmp_path / "handoff.mcap"
    vworks.load_cell(str(ROOT / "workcells" / "handoff" / "cell.toml")).run(log=str(log))
    written = vworks.write_report(log)
    assert written == tmp_path / "handoff.html"
    cli = tmp_path / "cli.html"
    subprocess.run([VWORKS, "report", str(log), "-o", str(cli)], check=True, capture_output=True)
    assert written.read_text() == cli.read_text()
    with pytest.raises(vworks.Error, match="not an MCAP file"):
        vworks.write_report(ROOT / "README.md", tmp_path / "x.html")
