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
    assert "completed 63.417729589" in printed, printed
    assert "r1 63.417729589" in printed
    assert "error[E0021]" in printed  # the compile error, rendered
    assert (tmp_path / "run.mcap").stat().st_size > 100_000
    assert "<svg id=\"gantt\"" in (tmp_path / "run.html").read_text()
