"""A command that needs an extra which is not installed says so in one line and exits 1.

Each command runs in a subprocess in which the extra's module cannot be imported (None in
sys.modules: `import cv2` raises ModuleNotFoundError, as on a Pi without OpenCV), and must print
`roverlink CMD: ... needs the Python package 'cv2' ... pip install 'roverlink[vision]'` and no
traceback."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

# argv[1] is a comma-separated list of modules to make unimportable; the rest is the command line.
BLOCKED_MAIN = (
    "import sys\n"
    "for name in sys.argv.pop(1).split(','):\n"
    "    sys.modules[name] = None\n"
    "import runpy\n"
    "runpy.run_module('roverlink', run_name='__main__', alter_sys=True)\n"
)
EMU = "emu://diffdrive-tb6612?clock=virtual"
TIMEOUT_S = 120.0


def run_without(blocked: str, *argv: str, tty: str = "", cwd: Path | None = None) -> tuple[int, str]:
    """Runs `roverlink ARGV` with `blocked` unimportable; (exit status, stderr). `tty`: "stdin" or
    "stdout" is a pseudo-terminal (the terminal views need one)."""
    master, slave = os.openpty() if tty else (-1, -1)
    try:
        proc = subprocess.run(
            [sys.executable, "-c", BLOCKED_MAIN, blocked, *argv],
            stdin=slave if tty == "stdin" else subprocess.DEVNULL,
            stdout=slave if tty == "stdout" else subprocess.DEVNULL,
            stderr=subprocess.PIPE,
            text=True,
            timeout=TIMEOUT_S,
            check=False,
            cwd=cwd,
        )
    finally:
        if tty:
            os.close(master)
            os.close(slave)
    return proc.returncode, proc.stderr


def assert_names_extra(result: tuple[int, str], command: str, module: str, extra: str) -> None:
    status, stderr = result
    assert "Traceback" not in stderr, stderr
    lines = [line for line in stderr.splitlines() if line.strip()]
    assert len(lines) == 1, stderr
    line = lines[0]
    assert line.startswith(f"roverlink {command}: "), line
    assert f"needs the Python package {module!r}" in line and f"pip install 'roverlink[{extra}]'" in line, line
    assert status == 1, stderr


def test_emulate_camera_without_opencv() -> None:
    assert_names_extra(run_without("cv2", "emulate", "--world", "empty", "--camera"), "emulate", "cv2", "vision")


def test_follow_on_the_emulator_without_opencv() -> None:
    result = run_without("cv2", "follow", "--world", "random:3", "--duration", "1", "--quiet")
    assert_names_extra(result, "follow", "cv2", "vision")


def test_follow_template_without_opencv(tmp_path: Path) -> None:
    (tmp_path / "target.png").write_bytes(b"")
    result = run_without(
        "cv2",
        "follow",
        "--url",
        "/dev/null",
        "--lidar",
        "/dev/null",
        "--camera",
        "0",
        "--template",
        str(tmp_path / "target.png"),
    )
    assert_names_extra(result, "follow", "cv2", "vision")


def test_follow_recording_without_foxglove(tmp_path: Path) -> None:
    result = run_without(
        "foxglove",
        "follow",
        "--world",
        "random:3",
        "--duration",
        "1",
        "--quiet",
        "--foxglove",
        str(tmp_path / "run.mcap"),
    )
    assert_names_extra(result, "follow", "foxglove", "foxglove")


def test_record_without_foxglove(tmp_path: Path) -> None:
    result = run_without("foxglove", "record", EMU, "-o", str(tmp_path / "run.mcap"), "--duration", "0.2")
    assert_names_extra(result, "record", "foxglove", "foxglove")


def test_monitor_live_view_without_foxglove() -> None:
    result = run_without("foxglove", "monitor", EMU, "--plain", "--duration", "0.2", "--foxglove")
    assert_names_extra(result, "monitor", "foxglove", "foxglove")


def test_monitor_terminal_view_without_textual() -> None:
    assert_names_extra(run_without("textual", "monitor", EMU, tty="stdout"), "monitor", "textual.app", "tui")


def test_teleop_without_textual() -> None:
    assert_names_extra(run_without("textual", "teleop", EMU, tty="stdin"), "teleop", "textual.app", "tui")


def test_tune_plot_without_matplotlib_before_the_step_tests(tmp_path: Path) -> None:
    result = run_without("matplotlib", "tune", f"{EMU}&stand=1", "--yes", cwd=tmp_path)
    assert_names_extra(result, "tune", "matplotlib", "plot")
    assert "--plot ''" in result[1]


@pytest.mark.parametrize("module", ["cv2", "textual", "matplotlib", "foxglove"])
def test_commands_without_the_extra_still_work(module: str) -> None:
    """What needs no extra is not refused: the blocker itself leaves the rest importable."""
    status, stderr = run_without(module, "decode", "0303010100")
    assert "Traceback" not in stderr and status in (0, 1), stderr
