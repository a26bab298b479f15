"""The `vworks` command as a user meets it: the progress bar on a terminal, `vworks new`,
shell completions."""

import os
import pty
import select
import subprocess
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
VWORKS = os.environ.get("VWORKS", str(ROOT / "target" / "debug" / "vworks"))


def long_cell(tmp):
    """64 arms moving for as long as asked: about 3.3 ms of a debug build per simulated second."""
    toml = 'name = "long"\ncycle = "4ms"\n'
    for i in range(64):
        toml += (f'[[robot]]\nname = "r{i}"\nmodel = "irb120"\nprogram = "arm.wsl"\n'
                 f'base = {{ xyz = ["{(i % 8) * 1200}mm", "{(i // 8) * 1200}mm", "0mm"] }}\n')
    (tmp / "cell.toml").write_text(toml)
    (tmp / "arm.wsl").write_text(
        "proc main() {\n    while true {\n"
        "        move_j joints(40deg, -20deg, 30deg, 0deg, 60deg, 0deg) speed 30%;\n"
        "        move_j joints(-40deg, 0deg, 0deg, 0deg, 30deg, 0deg) speed 30%;\n"
        "    }\n}\n")
    return tmp / "cell.toml"


def on_terminal(args):
    """Runs `args` with stderr on a pseudo-terminal; returns what it wrote there."""
    master, slave = pty.openpty()
    proc = subprocess.Popen(args, stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL, stderr=slave)
    os.close(slave)
    out = b""
    while True:
        ready, _, _ = select.select([master], [], [], 120)
        if not ready:
            break
        try:
            chunk = os.read(master, 4096)
        except OSError:  # the child closed the terminal
            break
        if not chunk:
            break
        out += chunk
    proc.wait(timeout=120)
    os.close(master)
    return proc.returncode, out.decode(errors="replace")


def test_a_long_run_shows_its_progress_on_a_terminal(tmp_path):
    cell = long_cell(tmp_path)
    # (The bar shows after a second of wall time: 300 simulated seconds took 1.0 s of a
    # debug build on an idle machine, and below that nothing shows; 1200 take about 4 s.)
    code, err = on_terminal([VWORKS, "run", str(cell), "--until", "1200s"])
    assert code == 0
    assert "simulated" in err and "x real time" in err, err
    # --quiet, or stderr not a terminal: no bar.
    code, err = on_terminal([VWORKS, "run", str(cell), "--until", "300s", "--quiet"])
    assert code == 0 and "real time" not in err, err
    piped = subprocess.run([VWORKS, "run", str(cell), "--until", "300s"], capture_output=True, text=True)
    assert piped.returncode == 0 and piped.stderr == "", piped.stderr


def test_new_scaffolds_a_cell_that_runs(tmp_path):
    cell = tmp_path / "mycell"
    out = subprocess.run([VWORKS, "new", str(cell)], capture_output=True, text=True)
    assert out.returncode == 0, out.stderr
    assert sorted(p.name for p in cell.iterdir()) == ["README.md", "cell.toml", "r1.wsl"]
    assert 'name = "mycell"' in (cell / "cell.toml").read_text()
    assert (cell / "README.md").read_text().startswith("# mycell\n")
    run = subprocess.run([VWORKS, "run", str(cell / "cell.toml"), "--json"], capture_output=True, text=True)
    assert run.returncode == 0, run.stdout + run.stderr
    assert '"outcome": "completed"' in run.stdout and '"collisions": []' in run.stdout
    # Never over a folder that has files.
    again = subprocess.run([VWORKS, "new", str(cell)], capture_output=True, text=True)
    assert again.returncode == 1
    assert "already exists and is not empty" in again.stderr and "mycell" in again.stderr


def test_completion_scripts_name_every_command():
    for shell in ["bash", "zsh", "fish", "powershell", "elvish"]:
        out = subprocess.run([VWORKS, "completions", shell], capture_output=True, text=True)
        assert out.returncode == 0, out.stderr
        for command in ["check", "build", "disasm", "run", "report", "new", "log", "completions"]:
            assert command in out.stdout, (shell, command)
    bash = subprocess.run([VWORKS, "completions", "bash"], capture_output=True, text=True).stdout
    # The bash script loads and completes `vworks rep` to `report`.
    probe = bash + '\nCOMP_WORDS=(vworks rep); COMP_CWORD=1; COMP_LINE="vworks rep"; COMP_POINT=10\n' \
        '_vworks vworks rep vworks; printf "%s\\n" "${COMPREPLY[@]}"\n'
    done = subprocess.run(["bash", "-c", probe], capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
    assert "report" in done.stdout.split()
