"""The examples run as documented, and the pytest plugin works for a user's own test file."""

from __future__ import annotations

import runpy
import subprocess
import sys
from pathlib import Path

import pytest

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"


@pytest.mark.parametrize("script", ["drive_square.py", "read_odometry.py", "tune_pid.py"])
def test_example_runs_against_the_emulator(script: str, capsys: pytest.CaptureFixture[str]) -> None:
    module = runpy.run_path(str(EXAMPLES / script))
    module["main"]("emu://?clock=virtual")
    assert capsys.readouterr().out


def test_the_plugin_fixtures_work_in_a_users_test_run(tmp_path: Path) -> None:
    """`pytest examples/test_my_robot.py` in a fresh process: the plugin comes from the pytest11 entry point."""
    result = subprocess.run(
        [
            sys.executable,
            "-m",
            "pytest",
            "-q",
            "-p",
            "no:cacheprovider",
            "--rootdir",
            str(tmp_path),
            str(EXAMPLES / "test_my_robot.py"),
        ],
        capture_output=True,
        text=True,
        timeout=300,
        cwd=tmp_path,
        check=False,
    )
    assert result.returncode == 0, result.stdout + result.stderr
    assert "3 passed" in result.stdout


def test_demo_command_reports_odometry_against_truth(capsys: pytest.CaptureFixture[str]) -> None:
    from roverlink.cli import main

    assert main(["demo", "--fast", "--side", "0.5"]) == 0
    out = capsys.readouterr().out
    assert "position error" in out and "round trip (PING/PONG)" in out and "CRC / COBS / length errors" in out


def test_demo_plot(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    from roverlink.cli import main

    target = tmp_path / "square.png"
    assert main(["demo", "--fast", "--side", "0.5", "--plot", str(target)]) == 0
    assert target.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
