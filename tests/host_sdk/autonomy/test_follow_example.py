"""examples/follow.py, the whole follow-while-avoiding robot program, runs as its docstring says and
is built from host_sdk alone (a user's program must not need the command package)."""

from __future__ import annotations

import ast
import re
import subprocess
import sys
from pathlib import Path

EXAMPLE = Path(__file__).resolve().parents[3] / "examples" / "follow.py"


def test_the_example_imports_only_the_sdk() -> None:
    tops = set()
    for node in ast.walk(ast.parse(EXAMPLE.read_text(encoding="utf-8"))):
        if isinstance(node, ast.Import):
            tops |= {alias.name.split(".")[0] for alias in node.names}
        elif isinstance(node, ast.ImportFrom) and node.module:
            tops.add(node.module.split(".")[0])
    assert "host_sdk" in tops
    assert not tops & {"roverlink", "emulator"}


def test_the_example_follows_on_the_emulator_as_documented() -> None:
    doc = EXAMPLE.read_text(encoding="utf-8")
    url = re.search(r"--url '(emu://[^']+)'", doc)
    assert url is not None and "clock=virtual" in url.group(1)
    done = subprocess.run(
        [sys.executable, str(EXAMPLE), "--url", url.group(1), "--duration", "8"],
        capture_output=True,
        text=True,
        timeout=300,
        check=False,
    )
    assert done.returncode == 0, done.stderr
    lines = re.findall(r"^\s*([\d.]+) s  (\w+)\s+x\s+([-\d.]+) m  y\s+([-\d.]+) m$", done.stdout, re.M)
    assert len(lines) == 8  # a line a second
    modes = {mode for _, mode, _, _ in lines}
    assert modes - {"waiting", "stop"}, modes  # it decided to do something
    moved = max(abs(float(x)) + abs(float(y)) for _, _, x, y in lines)
    assert moved > 0.1  # and the robot drove


def test_the_example_takes_a_robot_file(tmp_path: Path) -> None:
    from protocol.robotfile import reference_path

    mine = tmp_path / "mine.toml"
    mine.write_text(reference_path("picar").read_text())
    url = "emu://picar?world=random:3&lidar=ydlidar-f4&imu=jy901&camera=320x240&clock=virtual"
    done = subprocess.run(
        [sys.executable, str(EXAMPLE), "--url", url, "--robot", str(mine), "--duration", "2"],
        capture_output=True,
        text=True,
        timeout=300,
        check=False,
    )
    assert done.returncode == 0, done.stderr
    assert len(re.findall(r"^\s*[\d.]+ s  \w+", done.stdout, re.M)) == 2
    bad = tmp_path / "bad.toml"
    bad.write_text(mine.read_text().replace('kind = "ackermann"', 'kind = "differential"', 1))
    done = subprocess.run(
        [sys.executable, str(EXAMPLE), "--url", url, "--robot", str(bad), "--duration", "2"],
        capture_output=True,
        text=True,
        timeout=300,
        check=False,
    )
    assert done.returncode != 0 and str(bad) in done.stderr  # another robot: not driven
