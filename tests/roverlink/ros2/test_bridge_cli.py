"""`roverlink ros2` refuses what cannot work with a message and exit status 1, without a traceback."""

from __future__ import annotations

import subprocess
import sys

import pytest
from ros_env import ROOT, require_ros

require_ros()


def run_bridge(*args: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run(
        [sys.executable, "-m", "roverlink", "ros2", *args],
        capture_output=True,
        text=True,
        timeout=60,
        cwd=ROOT,
        check=False,
    )


@pytest.mark.parametrize(
    ("args", "says"),
    [
        (["--url", "emu://", "--ros-args", "-p", "odom_rate:=500"], "odom_rate"),  # rclpy's range check
        (["--url", "emu://", "--ros-args", "-p", "mode:=fast"], "parameter mode = 'fast' is not allowed"),
        (["--url", "emu://", "--ros-args", "-p", "on_timeout:=coast"], "parameter on_timeout"),
        (["--url", "emu://no-such-robot"], "unknown emulator profile 'no-such-robot'"),
    ],
)
def test_what_cannot_work_ends_with_status_1_and_the_reason(args: list[str], says: str) -> None:
    result = run_bridge(*args)
    assert result.returncode == 1, result.stderr
    assert says in result.stderr
    assert "Traceback" not in result.stderr
