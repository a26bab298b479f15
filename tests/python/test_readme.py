"""The README's Python example runs as written, and prints what its comments say."""

import contextlib
import io
import re
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]


def test_the_readme_python_example_runs(tmp_path, monkeypatch):
    readme = (ROOT / "README.md").read_text()
    (block,) = re.findall(r"```python\n(.*?)```", readme, re.S)
    # Run where the example's relative paths resolve, writing its log in a scratch folder.
    (tmp_path / "workcells").symlink_to(ROOT / "workcells")
    monkeypatch.chdir(tmp_path)
    out = io.StringIO()
    with contextlib.redirect_stdout(out):
        exec(compile(block, "README.md", "exec"), {})
    printed = out.getvalue()
    assert "completed 46.491264457" in printed, printed
    assert "r1 46.491264457" in printed
    assert "error[E0021]" in printed  # the compile error, rendered
    assert (tmp_path / "run.mcap").stat().st_size > 100_000
    assert "<svg id=\"gantt\"" in (tmp_path / "run.html").read_text()


def tour_blocks(readme):
    """The tour's command blocks: (command, expected output lines), in README order."""
    blocks = []
    for block in re.findall(r"```text\n(.*?)```", readme, re.S):
        lines = block.rstrip("\n").split("\n")
        if lines[0].startswith("$ vworks "):
            blocks.append((lines[0][2:], lines[1:]))
    return blocks


def normal(lines):
    """Output lines with what changes from run to run (wall-clock speeds) made equal."""
    lines = [re.sub(r"\d+x real time", "Nx real time", l) for l in lines]
    return [re.sub(r" in [\d.]+ s \([\d.]+ variants/s", " in T s (R variants/s", l) for l in lines]


def test_the_readme_tour_prints_what_it_shows(tmp_path):
    """Every `$ vworks …` block of the README's tour, run as a newcomer would (in a fresh
    folder, a copy of the examples beside it), prints exactly what the README shows, but
    for the speeds (`Nx real time`, the sweep's time and rate)."""
    import os
    import subprocess

    vworks = os.environ.get("VWORKS", str(ROOT / "target" / "debug" / "vworks"))
    readme = (ROOT / "README.md").read_text()
    import shutil

    shutil.copytree(ROOT / "workcells", tmp_path / "workcells",
                    ignore=shutil.ignore_patterns("sweep.csv", "sweep.html", "*.mcap"))
    blocks = tour_blocks(readme)
    commands = [c for c, _ in blocks]
    assert commands[:4] == ["vworks new mycell", "vworks check mycell/r1.wsl",
                            "vworks run mycell --log run.mcap", "vworks run workcells/crash"], commands
    ran = 0
    for command, expected in blocks:
        if command.startswith("vworks run mycell"):
            # The tour's fix before it runs the cell.
            r1 = tmp_path / "mycell" / "r1.wsl"
            r1.write_text(r1.read_text().replace("delay 2;", "delay 2s;"))
        out = subprocess.run(
            vworks + command[len("vworks"):], shell=True, cwd=tmp_path, capture_output=False,
            stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True,
            env={**os.environ, "NO_COLOR": "1"},
        )
        assert normal(out.stdout.rstrip("\n").split("\n")) == normal(expected), command
        ran += 1
        if command == "vworks new mycell":
            # The program the tour writes, mistake and all.
            (block,) = re.findall(r"```wsl\n(.*?)```", readme, re.S)
            (tmp_path / "mycell" / "r1.wsl").write_text(block)
    assert ran == len(blocks) and any(c.startswith("vworks sweep") for c in commands)
    # The cell check the tour describes in words.
    check = subprocess.run([vworks, "check", "mycell"], cwd=tmp_path, capture_output=True, text=True)
    assert check.stderr.endswith("checked cell mycell: 1 program, 0 errors, 0 warnings\n"), check.stderr


def test_the_readme_counts_the_error_cases():
    readme = (ROOT / "README.md").read_text()
    (count,) = re.findall(r"`tests/errors/` holds (\d+) of them", readme)
    assert int(count) == len(list((ROOT / "tests" / "errors").glob("*.case")))
