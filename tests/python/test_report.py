"""`vworks report` and `vworks view`: the HTML report of a run, opened in headless Chromium.

Chromium runs the page's scripts, draws the 3D view with its software WebGL (SwiftShader)
and is driven over the DevTools protocol (`browser.py`): the tests read the page's DOM and
JavaScript values, click, hover and drag, take screenshots, and check that the page logged
no error and requested nothing but itself. Expected values come from the log itself (read
here with the `mcap` package and the schemas in the file), not from the page:
- the collision's contact point (from `/events`), projected with the page's camera, must be
  red in the screenshot;
- every link's pose the page shows must be the `/tf` tree replayed at that time.
"""

import os
import re
import shutil
import stat
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest
from PIL import Image

from browser import Browser

ROOT = Path(__file__).resolve().parents[2]
VWORKS = os.environ.get("VWORKS", str(ROOT / "target" / "debug" / "vworks"))
SCREENSHOT = ROOT / "docs" / "images" / "report-handoff.png"

MOVING = (0x2F, 0x6F, 0xDF)
WAITING = (0xF0, 0xA0, 0x30)
COLLISION = (0xD6, 0x27, 0x28)


@pytest.fixture(scope="module")
def browser(tmp_path_factory):
    with Browser(tmp_path_factory.mktemp("chromium")) as b:
        yield b


def load(b, page, fragment="", frames=2):
    """Opens `page` (with `#fragment`), lets it draw, and returns the DevTools events of this
    load only (so errors and requests are this page's)."""
    b.events.clear()
    b.open("about:blank")
    b.events.clear()
    b.open(page.as_uri() + fragment)
    b.frames(frames)


def clean(b, page):
    """No console error or exception, and no request but the page itself."""
    assert b.errors() == []
    assert set(b.requests()) <= {page.as_uri(), "about:blank"}, b.requests()


def table(b, selector):
    """The rendered text of each cell of the table `selector`, row by row (header first):
    what a reader sees, whatever the markup around it."""
    return b.eval(
        f"Array.from(document.querySelectorAll('{selector} tr'))"
        ".map(r => Array.from(r.cells).map(c => c.innerText.trim()))"
    )


def run_and_report(cell, tmp, *run_args, cell_file=None):
    log = tmp / f"{cell}.mcap"
    cell_file = cell_file or ROOT / "workcells" / cell / "cell.toml"
    subprocess.run([VWORKS, "run", str(cell_file), "--log", str(log), *run_args],
                   capture_output=True, check=False)
    out = subprocess.run([VWORKS, "report", str(log), "-o", str(tmp / f"{cell}.html")],
                         capture_output=True, text=True)
    assert out.returncode == 0, out.stderr
    assert re.match(r"wrote .*\.html \(\d+ robots?, \d+ events?, \d+ collisions?\)", out.stderr)
    return tmp / f"{cell}.html", log


def pixels(png, colour, box):
    """How many pixels of `box` have `colour` (within 6 per channel)."""
    image = np.asarray(Image.open(png).convert("RGB").crop(box)).astype(int)
    return int((np.abs(image - np.array(colour)).max(axis=2) <= 6).sum())


def red(png, box):
    """Pixels of `box` that are the collision red, lit or in shade: red well above green and
    blue (the robots are amber, the floor grey)."""
    image = np.asarray(Image.open(png).convert("RGB").crop(box)).astype(int)
    r, g, b = image[..., 0], image[..., 1], image[..., 2]
    return int(((r > 90) & (g < 0.35 * r) & (b < 0.35 * r)).sum())


def rect(b, selector):
    return b.eval(f"(function () {{ var r = document.querySelector({selector!r}).getBoundingClientRect();"
                  " return [r.left, r.top, r.right, r.bottom]; })()")


def project(camera, point):
    """Where the page draws world point `point`: CSS pixels in the viewport."""
    view = np.array(camera["view"]).reshape(4, 4).T  # three.js matrices are column-major
    projection = np.array(camera["projection"]).reshape(4, 4).T
    clip = projection @ view @ np.array([*point, 1.0])
    x, y = clip[0] / clip[3], clip[1] / clip[3]
    r = camera["rect"]
    return r["left"] + (x + 1) / 2 * r["width"], r["top"] + (1 - y) / 2 * r["height"]


def clock(b):
    text = b.eval("document.getElementById('clock').textContent")
    assert text.endswith(" s")
    return float(text[:-2])


# --- the tables and the Gantt chart ---------------------------------------------------


def test_the_handoff_report_renders_with_a_visible_gantt_chart(browser, tmp_path):
    page, _ = run_and_report("handoff", tmp_path)
    load(browser, page)
    dom = browser.eval("document.documentElement.outerHTML")
    # The page as Chromium built it: title, cycle times, one chart row per robot, the
    # event table filled and counted by the page's script.
    assert "<title>vworks report: handoff</title>" in dom
    cycle_times = table(browser, "#cycle-times")
    assert cycle_times[0][:2] == ["robot", "cycle time"], cycle_times
    assert [row[:2] for row in cycle_times[1:]] == [["r1", "46.491 s"], ["r2", "41.203 s"]]
    assert dom.count('<g class="row"') == 2
    assert dom.count('class="moving"') > 20 and dom.count('class="waiting"') > 5
    assert dom.count('class="signal"') >= 5
    assert "187 of 187 events shown" in dom  # written by the script, so it ran
    assert "No collision." in dom
    # The chart is on screen below the 3D view, its bars in both colours.
    browser.eval("document.getElementById('gantt').scrollIntoView()")
    left, top, right, bottom = rect(browser, "#gantt")
    shot = browser.screenshot(tmp_path / "handoff.png")
    assert Image.open(shot).size == (1280, 1000)
    chart = (int(left), int(max(top, 0)), int(right), int(min(bottom, 1000)))
    assert pixels(shot, MOVING, chart) > 10_000
    assert pixels(shot, WAITING, chart) > 5_000
    clean(browser, page)


def test_a_collision_is_marked_in_the_chart_and_listed(browser, tmp_path):
    page, _ = run_and_report("crash", tmp_path)
    load(browser, page)
    dom = browser.eval("document.documentElement.outerHTML")
    assert dom.count('class="collision"') == 1
    collisions = table(browser, "#collisions")
    assert len(collisions) == 2, collisions  # the header and the one collision
    assert "left.link_6 right.link_6" in " ".join(collisions[1]), collisions
    assert "near miss" in dom  # the warning before the collision
    # The collision row names each robot's motion, as rendered text: both arms were in
    # their one move_j (workcells/crash, left.wsl and right.wsl line 3).
    statement = "move_j joints(0deg, 60deg, -30deg, 0deg, 30deg, 0deg) speed 50%;"
    row = browser.eval("document.querySelector('#collisions tr:nth-child(2)').innerText")
    assert f"left moving: left.wsl:3:5 {statement}" in row, row
    assert f"right moving: right.wsl:3:5 {statement}" in row, row
    near = browser.eval("document.querySelector('#issues tr:nth-child(2)').innerText")
    assert "near miss" in near and f"left moving: left.wsl:3:5 {statement}" in near, near
    # Durations in the event table are seconds, like its time column.
    events = browser.eval("document.getElementById('events').innerText")
    assert "move_j duration=" in events and " s\t" in events and "duration=0." in events, events[:400]
    browser.eval("document.getElementById('gantt').scrollIntoView()")
    left, top, right, bottom = rect(browser, "#gantt")
    shot = browser.screenshot(tmp_path / "crash.png")
    assert pixels(shot, COLLISION, (int(left), int(max(top, 0)), int(right), int(min(bottom, 1000)))) > 20
    clean(browser, page)


def test_the_event_filter_narrows_the_table(browser, tmp_path):
    page, _ = run_and_report("handoff", tmp_path)
    load(browser, page)
    browser.eval("var k = document.getElementById('kind'); k.value = 'signal';"
                 " k.dispatchEvent(new Event('input'))")
    shown = re.search(r"(\d+) of 187 events shown", browser.eval("document.getElementById('count').textContent"))
    assert shown and 0 < int(shown.group(1)) < 187
    assert int(shown.group(1)) == page.read_text().count('data-kind="signal"')
    hidden = browser.eval("document.querySelectorAll('#events tbody tr[style=\"display: none;\"]').length")
    assert hidden == 187 - int(shown.group(1))


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
    assert 'id="vworks-playback"' in cli.read_text()
    with pytest.raises(vworks.Error, match="not an MCAP file"):
        vworks.write_report(ROOT / "README.md", tmp_path / "x.html")


# --- the 3D view ----------------------------------------------------------------------


def collision(log):
    import vworks

    (start,) = [e for e in vworks.read_log(log) if e.kind == "collision_start"]
    point = re.search(r"point=\(([-\d.]+), ([-\d.]+), ([-\d.]+)\)", start.details)
    return start.time_ns, [float(v) for v in point.groups()]


def test_the_colliding_links_are_red_at_the_collision(browser, tmp_path):
    page, log = run_and_report("crash", tmp_path)
    t, point = collision(log)
    load(browser, page, f"#t={t / 1e9:.9f}")
    assert browser.eval("window.vworksView.time()") == pytest.approx(t, abs=1)
    camera = browser.eval("window.vworksView.view.camera()")
    x, y = project(camera, point)
    shot = browser.screenshot(tmp_path / "collision.png")
    around = (int(x) - 30, int(y) - 30, int(x) + 30, int(y) + 30)
    assert red(shot, around) > 150, (x, y)
    # Red only there: the rest of the view has none of it.
    view = camera["rect"]
    whole = red(shot, (int(view["left"]), int(view["top"]), int(view["left"] + view["width"]),
                       int(view["top"] + view["height"])))
    assert whole - red(shot, (int(x) - 80, int(y) - 80, int(x) + 80, int(y) + 80)) == 0
    # At the start nothing is red: the bodies have their own colours.
    load(browser, page, "#t=0")
    assert red(browser.screenshot(tmp_path / "start.png"), around) == 0
    clean(browser, page)


def test_the_robots_move_and_the_table_stays(browser, tmp_path):
    page, log = run_and_report("crash", tmp_path)
    t, _ = collision(log)
    load(browser, page, "#t=0")
    camera = browser.eval("window.vworksView.view.camera()")
    start = np.asarray(Image.open(browser.screenshot(tmp_path / "t0.png")).convert("RGB")).astype(int)
    load(browser, page, f"#t={t / 2e9:.6f}")
    assert browser.eval("window.vworksView.view.camera()") == camera  # the same view
    mid = np.asarray(Image.open(browser.screenshot(tmp_path / "mid.png")).convert("RGB")).astype(int)

    def box(point, half):
        x, y = project(camera, point)
        return slice(int(y) - half, int(y) + half), slice(int(x) - half, int(x) + half)

    # The table (a device, workcells/crash: centre 400, -550, 150 mm; top at 300 mm): its
    # top face's pixels are the same; the robots' forearms (link_3/link_4 of each, as the
    # log places them at t = 0) are drawn elsewhere half-way to the collision.
    table = box((0.4, -0.55, 0.3), 12)
    assert np.array_equal(start[table], mid[table])
    assert (start[table] != 0).any()
    for robot in ("left", "right"):
        forearm = browser.eval(f"window.vworksView.setTime(0); window.vworksView.view.worldPose('{robot}.link_4')")
        region = box(forearm[:3], 25)
        changed = (np.abs(start[region] - mid[region]).max(axis=2) > 30).mean()
        assert changed > 0.2, (robot, changed)
    clean(browser, page)


def tf_replay(log, times):
    """Every frame's pose in `world` at each of `times` (ns): the latest `/tf` transform of
    each frame at or before the time, composed up the tree (read with the `mcap` package
    and the log's own protobuf schema)."""
    from mcap.reader import make_reader

    sys.path.insert(0, str(Path(__file__).parent))
    from test_log import message_classes

    with open(log, "rb") as f:
        reader = make_reader(f)
        tf = message_classes(reader)["/tf"]
        messages = [(m.log_time, tf.FromString(m.data)) for _, _, m in reader.iter_messages(topics=["/tf"])]
    out, latest, k = {}, {}, 0
    for t in sorted(times):
        while k < len(messages) and messages[k][0] <= t:
            for tr in messages[k][1].transforms:
                r, p = tr.rotation, tr.translation
                latest[tr.child_frame_id] = (tr.parent_frame_id, np.array([p.x, p.y, p.z]),
                                             np.array([r.x, r.y, r.z, r.w]))
            k += 1
        poses = {}
        for frame in latest:
            p, q, at = np.zeros(3), np.array([0.0, 0.0, 0.0, 1.0]), frame
            while at in latest:
                parent, tp, tq = latest[at]
                p, q = tp + rotate(tq, p), quat_mul(tq, q)
                at = parent
            poses[frame] = (p, q)
        out[t] = poses
    return out


def quat_mul(a, b):
    ax, ay, az, aw = a
    bx, by, bz, bw = b
    return np.array([aw * bx + ax * bw + ay * bz - az * by, aw * by - ax * bz + ay * bw + az * bx,
                     aw * bz + ax * by - ay * bx + az * bw, aw * bw - ax * bx - ay * by - az * bz])


def rotate(q, v):
    return quat_mul(quat_mul(q, [*v, 0.0]), [-q[0], -q[1], -q[2], q[3]])[:3]


@pytest.mark.parametrize("cell", ["handoff", "track"])
def test_every_link_is_where_the_log_puts_it(browser, tmp_path, cell):
    # Sample times (k / 30 s) and the end, through grips and releases (handoff's part is
    # carried by r1, then r2) and a turntable (track).
    page, log = run_and_report(cell, tmp_path)
    load(browser, page)
    end = browser.eval("window.vworksView.end")
    step = 1_000_000_000 // 30
    times = sorted({k * step for k in range(0, end // step + 1, max(1, end // step // 12))} | {end})
    expected = tf_replay(log, times)
    frames = browser.eval("JSON.parse(document.getElementById('vworks-playback').textContent).frames")
    checked = 0
    for t in times:
        browser.eval(f"window.vworksView.setTime({t})")
        shown = browser.eval("(function () { var v = window.vworksView.view, out = {};"
                             f" {frames!r}.forEach(function (f) {{ out[f] = v.worldPose(f); }}); return out; }})()")
        for frame, (p, q) in expected[t].items():
            got = shown[frame]
            assert np.allclose(got[:3], p, atol=2e-6), (cell, t, frame, got, p)
            same = np.allclose(got[3:], q, atol=2e-6) or np.allclose(got[3:], -q, atol=2e-6)
            assert same, (cell, t, frame, got, q)
            checked += 1
    assert checked > 150
    if cell == "handoff":
        # The part moves (r1 carries it, r2 brings it back) and was checked on the way.
        first = expected[times[0]]["part1"][0]
        assert any(not np.allclose(expected[t]["part1"][0], first) for t in times)
    clean(browser, page)


def test_clicking_the_gantt_chart_or_a_row_moves_the_time(browser, tmp_path):
    page, _ = run_and_report("handoff", tmp_path)
    load(browser, page)
    assert clock(browser) == 0.0
    # The third of r1's moving bars: its title gives its span.
    browser.eval("document.getElementById('gantt').scrollIntoView()")
    title = browser.eval("document.querySelectorAll('g[data-robot=\"r1\"] rect.moving')[2].textContent")
    a, b = (float(v) for v in re.findall(r"([\d.]+) s", title))
    left, top, right, bottom = rect(browser, 'g[data-robot="r1"] rect.moving:nth-of-type(4)')
    browser.click((left + right) / 2, (top + bottom) / 2)
    assert a <= clock(browser) <= b, (title, clock(browser))
    # The playback cursor is drawn at that time.
    cursor = rect(browser, "#gantt-cursor")
    assert abs((cursor[0] + cursor[2]) / 2 - (left + right) / 2) < 1.5
    # An event row: the 40th.
    row_t = browser.eval("var r = document.querySelectorAll('#events tbody tr')[40];"
                         " r.scrollIntoView({block: 'center'}); r.dataset.t")
    left, top, right, bottom = rect(browser, "#events tbody tr:nth-child(41)")
    browser.click((left + right) / 2, (top + bottom) / 2)
    assert browser.eval("window.vworksView.time()") == int(row_t)
    assert clock(browser) == round(int(row_t) / 1e9, 3)
    # Play moves the time on; pausing stops it.
    browser.eval("window.vworksView.setTime(0); document.getElementById('play').click()")
    browser.frames(20)
    browser.eval("document.getElementById('play').click()")
    played = browser.eval("window.vworksView.time()")
    assert 0 < played < 2e9
    browser.frames(5)
    assert browser.eval("window.vworksView.time()") == played
    # Keys: the right arrow steps 1/30 s, with Shift 1 s; End goes to the end.
    browser.eval("document.activeElement.blur()")
    for key, code in (("ArrowRight", 39), ("ArrowRight", 39)):
        browser.send("Input.dispatchKeyEvent", type="rawKeyDown", key=key, windowsVirtualKeyCode=code)
        browser.send("Input.dispatchKeyEvent", type="keyUp", key=key, windowsVirtualKeyCode=code)
    assert browser.eval("window.vworksView.time()") == pytest.approx(played + 2e9 / 30)
    browser.send("Input.dispatchKeyEvent", type="rawKeyDown", key="End", windowsVirtualKeyCode=35)
    assert browser.eval("window.vworksView.time()") == browser.eval("window.vworksView.end")
    clean(browser, page)


def test_names_on_hover_reset_view_and_trails(browser, tmp_path):
    page, _ = run_and_report("handoff", tmp_path)
    load(browser, page, "#t=5")
    view = "window.vworksView.view"
    camera = browser.eval(f"{view}.camera()")
    # Hovering the middle of r1's upper arm names it.
    a = browser.eval(f"{view}.worldPose('r1.link_2')")
    b = browser.eval(f"{view}.worldPose('r1.link_3')")
    x, y = project(camera, [(a[i] + b[i]) / 2 for i in range(3)])
    browser.send("Input.dispatchMouseEvent", type="mouseMoved", x=x, y=y)
    browser.frames(1)
    assert browser.eval("document.getElementById('tip').hidden") is False
    assert browser.eval("document.getElementById('tip').textContent").startswith("r1 · link_")
    # Dragging orbits the camera; Reset view brings it back.
    r = camera["rect"]
    cx, cy = r["left"] + r["width"] / 2, r["top"] + r["height"] / 2
    browser.send("Input.dispatchMouseEvent", type="mousePressed", x=cx, y=cy, button="left", clickCount=1)
    for k in range(1, 6):
        browser.send("Input.dispatchMouseEvent", type="mouseMoved", x=cx + 40 * k, y=cy + 10 * k, button="left",
                     buttons=1)
    browser.send("Input.dispatchMouseEvent", type="mouseReleased", x=cx + 200, y=cy + 50, button="left",
                 clickCount=1)
    moved = browser.eval(f"{view}.camera()")
    assert not np.allclose(moved["view"], camera["view"])
    browser.eval("document.getElementById('reset-view').click()")
    assert np.allclose(browser.eval(f"{view}.camera()")["view"], camera["view"], atol=1e-9)
    # The TCP trails: computing them leaves the robots where they were.
    before = browser.eval(f"{view}.worldPose('r1.link_6')")
    browser.eval("document.getElementById('trail').click()")
    browser.frames(2)
    assert browser.eval(f"{view}.trails()") == 2
    assert browser.eval(f"{view}.worldPose('r1.link_6')") == before
    clean(browser, page)


def test_without_webgl_the_report_says_so_and_keeps_the_timeline(tmp_path):
    page, _ = run_and_report("handoff", tmp_path)
    with Browser(tmp_path / "profile", flags=("--disable-webgl",)) as b:
        load(b, page)
        assert b.eval("document.getElementById('view-note').hidden") is False
        assert "no WebGL" in b.eval("document.getElementById('view-note').textContent")
        # Neither the empty canvas nor its buttons take room: the note is one line.
        assert b.eval("document.getElementById('canvas3d').offsetParent") is None
        assert b.eval("document.getElementById('view-tools').offsetParent") is None
        assert b.eval("document.getElementById('stage').getBoundingClientRect().height") < 80
        assert b.eval("window.vworksView.view") is None
        b.eval("window.vworksView.setTime(12e9)")
        assert clock(b) == 12.0
        clean(b, page)


def test_a_log_without_poses_gives_the_report_with_a_note(browser, tmp_path):
    from mcap.reader import make_reader
    from mcap.writer import Writer

    _, log = run_and_report("handoff", tmp_path)
    # What an older vworks wrote: the events and the metadata, no /tf, no /scene.
    old = tmp_path / "old.mcap"
    with open(log, "rb") as f, open(old, "wb") as out:
        reader = make_reader(f)
        summary = reader.get_summary()
        writer = Writer(out)
        writer.start()
        ids = {}
        for channel in summary.channels.values():
            if channel.topic == "/events":
                schema = summary.schemas[channel.schema_id]
                sid = writer.register_schema(schema.name, schema.encoding, schema.data)
                ids[channel.id] = writer.register_channel(channel.topic, channel.message_encoding, sid)
        for _, channel, m in reader.iter_messages(topics=["/events"]):
            writer.add_message(ids[channel.id], m.log_time, m.data, m.publish_time)
        for meta in reader.iter_metadata():
            writer.add_metadata(meta.name, meta.metadata)
        writer.finish()
    html = tmp_path / "old.html"
    out = subprocess.run([VWORKS, "report", str(old), "-o", str(html)], capture_output=True, text=True)
    assert out.returncode == 0, out.stderr
    assert "no 3D view: the log has no poses" in out.stderr
    assert "var THREE=" not in html.read_text()  # no 3D view: three.js is left out
    load(browser, html)
    assert "No 3D view: this log has no /scene" in browser.eval("document.getElementById('view-note').textContent")
    assert "187 of 187 events shown" in browser.eval("document.getElementById('count').textContent")
    browser.eval("window.vworksView.setTime(3e9)")
    assert clock(browser) == 3.0
    clean(browser, html)


def test_a_damaged_log_gives_the_report_of_what_was_read(browser, tmp_path):
    _, log = run_and_report("handoff", tmp_path)
    cut = tmp_path / "cut.mcap"
    data = log.read_bytes()
    cut.write_bytes(data[: len(data) * 2 // 3])
    html = tmp_path / "cut.html"
    out = subprocess.run([VWORKS, "report", str(cut), "-o", str(html)], capture_output=True, text=True)
    assert out.returncode == 1
    assert "unfinished or damaged" in out.stderr and "the report shows what was read" in out.stderr
    load(browser, html)
    assert "damaged" in browser.eval("document.querySelector('.damage').textContent")
    # The poses read before the damage play back.
    assert browser.eval("window.vworksView.view.bodies") > 10
    clean(browser, html)


def test_the_60_s_four_robot_report_stays_small(tmp_path):
    page, _ = run_and_report("grid4", tmp_path, cell_file=ROOT / "bench" / "cells" / "grid4" / "cell.toml")
    size = page.stat().st_size
    assert size < 3_000_000, size


def test_vworks_view_opens_the_report_in_a_browser(tmp_path):
    _, log = run_and_report("crash", tmp_path)
    opened = tmp_path / "opened.txt"
    fake = tmp_path / "fake-browser"
    fake.write_text(f"#!/bin/sh\necho \"$1\" > {opened}\n")
    fake.chmod(0o755)
    env = {k: v for k, v in os.environ.items() if k not in ("DISPLAY", "WAYLAND_DISPLAY", "BROWSER")}
    out = subprocess.run([VWORKS, "view", str(log)], capture_output=True, text=True,
                         env={**env, "BROWSER": str(fake), "TMPDIR": str(tmp_path)})
    assert out.returncode == 0, out.stderr
    # A new folder of the user's own in TMPDIR (never a fixed, shared path).
    match = re.search(r"opened (\S+) \(with ", out.stderr)
    assert match, out.stderr
    written = Path(match.group(1))
    assert written.name == "crash.html" and written.parent.parent == tmp_path
    assert written.parent.name.startswith("vworks-view-")
    assert stat.S_IMODE(written.parent.lstat().st_mode) == 0o700
    for _ in range(100):  # the browser runs beside vworks, which does not wait for it
        if opened.exists() and opened.read_text().strip():
            break
        time.sleep(0.05)
    assert opened.read_text().strip() == str(written)
    assert 'id="vworks-playback"' in written.read_text()
    # No browser and no display: the path is printed.
    out = subprocess.run([VWORKS, "view", str(log)], capture_output=True, text=True,
                         env={**env, "TMPDIR": str(tmp_path)})
    assert out.returncode == 0, out.stderr
    again = Path(out.stdout.strip())
    assert again.name == "crash.html" and again.parent.parent == tmp_path
    assert again.parent != written.parent, "each view makes a folder of its own"
    assert "no display" in out.stderr


def test_the_readme_screenshot_is_the_report_of_today(tmp_path):
    """docs/images/report-handoff.png, shown in the README, is made here: the handoff cell at
    the moment r1 hands the part over. `VWORKS_UPDATE_SCREENSHOTS=1` rewrites it; otherwise
    the 3D view of a fresh screenshot must match it (software WebGL draws the same)."""
    # Run where the log is, so that the heading names `handoff.mcap`, not a temporary path.
    cell = ROOT / "workcells" / "handoff" / "cell.toml"
    subprocess.run([VWORKS, "run", str(cell), "--log", "handoff.mcap"], cwd=tmp_path, check=True,
                   capture_output=True)
    subprocess.run([VWORKS, "report", "handoff.mcap"], cwd=tmp_path, check=True, capture_output=True)
    page = tmp_path / "handoff.html"
    with Browser(tmp_path / "profile", width=1100, height=720) as b:
        load(b, page, "#t=24.5", frames=3)
        b.eval("document.getElementById('trail').click()")
        b.frames(2)
        camera = b.eval("window.vworksView.view.camera()")
        shot = b.screenshot(tmp_path / "readme.png")
        clean(b, page)
    if os.environ.get("VWORKS_UPDATE_SCREENSHOTS") == "1":
        SCREENSHOT.parent.mkdir(parents=True, exist_ok=True)
        shutil.copy(shot, SCREENSHOT)
    committed = np.asarray(Image.open(SCREENSHOT).convert("RGB")).astype(int)
    fresh = np.asarray(Image.open(shot).convert("RGB")).astype(int)
    assert committed.shape == fresh.shape
    r = camera["rect"]
    view = (slice(int(r["top"]), int(r["top"] + r["height"])), slice(int(r["left"]), int(r["left"] + r["width"])))
    differ = (np.abs(committed[view] - fresh[view]).max(axis=2) > 40).mean()
    assert differ < 0.01, f"{differ:.2%} of the 3D view differs: VWORKS_UPDATE_SCREENSHOTS=1 rewrites it"
