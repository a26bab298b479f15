"""docs/python.md's examples run as written and print what their `# →` comments say, and
the page names every public name of the package."""

import contextlib
import io
import re
from pathlib import Path

import vworks

ROOT = Path(__file__).resolve().parents[2]
DOC = ROOT / "docs" / "python.md"


def blocks():
    return re.findall(r"^```python\n(.*?)^```", DOC.read_text(), re.S | re.M)


def test_every_example_runs_and_prints_what_it_says(tmp_path, monkeypatch):
    found = blocks()
    assert len(found) >= 10, len(found)
    # Run where the examples' relative paths resolve (workcells/...), writing their files
    # (run.mcap, run.html, a cell of their own) in a scratch folder.
    (tmp_path / "workcells").symlink_to(ROOT / "workcells")
    monkeypatch.chdir(tmp_path)
    namespace: dict = {}
    checked = 0
    for n, block in enumerate(found, 1):
        out = io.StringIO()
        with contextlib.redirect_stdout(out):
            exec(compile(block, f"docs/python.md, python block {n}", "exec"), namespace)
        printed = out.getvalue().splitlines()
        # Each `# → TEXT` is the start of a line the block prints, in order.
        at = 0
        for want in re.findall(r"# → (.*)$", block, re.M):
            want = want.rstrip()
            while at < len(printed) and not printed[at].startswith(want):
                at += 1
            assert at < len(printed), f"block {n}: no printed line starts with {want!r}; it printed:\n" + "\n".join(printed)
            at += 1
            checked += 1
    assert checked >= 25, checked
    assert (tmp_path / "run.mcap").stat().st_size > 100_000
    assert "<svg id=\"gantt\"" in (tmp_path / "run.html").read_text()


def test_the_page_names_every_public_name():
    text = DOC.read_text()
    missing = [name for name in vworks.__all__ if not re.search(rf"`(vworks\.)?{re.escape(name)}[`(]", text)]
    assert missing == []
