"""`roverlink ros2` refuses what cannot work with a message and exit status 1, without a traceback."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
from pathlib import Path

import pytest
from ros_env import ROOT, require_ros

from host_sdk.hostinfo.realtime import allowed
from tests.support.realtime import without_realtime
from tests.support.wait import Deadline

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


def test_a_realtime_priority_out_of_range_or_not_permitted_ends_with_status_1() -> None:
    result = run_bridge("--url", "emu://", "--ros-args", "-p", "realtime_priority:=100")
    assert result.returncode == 1 and "realtime_priority" in result.stderr, result.stderr
    command = [*without_realtime(), sys.executable, "-m", "roverlink", "ros2", "--url", "emu://"]
    command += ["--ros-args", "-p", "realtime_priority:=5"]
    result = subprocess.run(command, capture_output=True, text=True, timeout=60, cwd=ROOT, check=False)
    assert result.returncode == 1 and "Traceback" not in result.stderr, result.stderr
    assert "SCHED_FIFO 5: not permitted (this user's rtprio limit is 0)" in result.stderr


def test_a_realtime_priority_puts_every_thread_of_the_node_under_sched_fifo() -> None:
    if not allowed(5):
        pytest.skip("this process may not use SCHED_FIFO (no CAP_SYS_NICE or rtprio limit, or a container's cgroup)")
    command = [sys.executable, "-m", "roverlink", "ros2", "--url", "emu://", "--ros-args", "-p", "realtime_priority:=5"]
    node = subprocess.Popen(command, cwd=ROOT, text=True, stderr=subprocess.PIPE, stdout=subprocess.DEVNULL)
    assert node.stderr is not None
    try:
        deadline, said = Deadline(60), ""
        while "under SCHED_FIFO 5" not in said and not deadline.expired() and node.poll() is None:
            said = node.stderr.readline()  # the node logs, or exits and this reads the end
        assert "under SCHED_FIFO 5" in said, "the node never said it runs real-time"
        tasks = list(Path(f"/proc/{node.pid}/task").iterdir())
        policies = {(os.sched_getscheduler(int(t.name)), os.sched_getparam(int(t.name)).sched_priority) for t in tasks}
        assert policies == {(os.SCHED_FIFO, 5)}, policies
    finally:
        node.send_signal(signal.SIGINT)
        node.communicate(timeout=30)
    assert node.returncode == 0
