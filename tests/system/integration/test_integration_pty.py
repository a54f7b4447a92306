"""The SDK over a real pseudo-terminal: `roverlink emulate` in a subprocess serves the emulator in
real time; the SDK opens the pty with pyserial, as it would open /dev/ttyACM0."""

from __future__ import annotations

import math
import os
import subprocess
import sys
import threading

import pytest

from host_sdk import Robot
from tests.support.emulate import emulate

pytestmark = pytest.mark.skipif(not sys.platform.startswith("linux"), reason="needs Linux ptys")


def drive_and_check(robot: Robot, seconds: float = 1.0) -> None:
    robot.arm()
    robot.odometry.reset()
    deadline = robot.now() + seconds
    while robot.now() < deadline:
        robot.drive(0.3, 0.5)
        sample = robot.wait_feedback(1.0)
        assert sample.armed
    pose = robot.odometry.pose
    assert 0.15 < math.hypot(pose.x_m, pose.y_m) < 0.4
    assert 0.15 < pose.theta_rad < 0.7
    robot.stop()


def test_pty_with_dtr_reset_on_open_stream_mode() -> None:
    """Opening the pty resets the board (DTR); the SDK rides through the bootloader with no sleeps."""
    threads, fds = set(threading.enumerate()), len(os.listdir("/proc/self/fd"))
    with (
        emulate("--quiet", "--profile", "diffdrive-tb6612") as board,
        Robot.connect(board.url, profile="diffdrive-tb6612") as robot,
    ):
        ready = robot.stats.connect_time_s
        assert ready is not None and ready < 3.0
        drive_and_check(robot)
        assert robot.stats.rtt is not None and robot.stats.rtt.min_s < 0.05
    assert set(threading.enumerate()) == threads
    assert len(os.listdir("/proc/self/fd")) == fds


def test_pty_lockstep_and_roverlink_info() -> None:
    with emulate("--quiet", "--profile", "diffdrive-bts7960", "--no-dtr-reset") as board:
        port = board.url
        info = subprocess.run(
            [sys.executable, "-c", "import sys; from roverlink.cli import main; sys.exit(main())", "info", port],
            capture_output=True,
            text=True,
            timeout=30,
            check=False,
        )
        assert info.returncode == 0, info.stderr
        assert "DiffDriveBTS7960" in info.stdout and "max_wheel_speed_mm_s" in info.stdout
        with Robot.connect(port, mode="lockstep") as robot:
            assert robot.mode == "lockstep"
            drive_and_check(robot)


def test_pty_simavr_backend_with_seed_faults_and_bootloader() -> None:
    """The compiled firmware behind the pty, with the options the Python backend has: the SDK rides
    through a short bootloader (its garbage included), adapter latency and a lossy line."""
    args = ("--backend", "simavr", "--profile", "diffdrive-tb6612", "--seed", "7", "--bootloader-ms", "300")
    faults = ("--faults", "bitflip=2e-5,drop=1e-4", "--latency-ms", "2")
    with emulate("--quiet", *args, *faults) as board, Robot.connect(board.url, profile="diffdrive-tb6612") as robot:
        ready = robot.stats.connect_time_s
        assert ready is not None and ready < 3.0
        drive_and_check(robot)
