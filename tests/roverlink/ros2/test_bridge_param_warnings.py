"""Parameters that say what they do, on a running node (real rclpy, DDS on this host).

One node, given a robot file unlike the emulated board it connects to (a wheel diameter of 0.07 m
where the board has 0.064), allowed with allow_mismatch, whose `[sensors.imu] baud = 9600` (a
factory JY901) names the IMU on a pty, `base_frame: base_footprint` and ros_arduino_bridge's and
misspelt parameter names: /diagnostics WARNs naming the difference, the IMU's port is set to 9600
baud, /tf_static has no transform from a frame to itself, the log names each ignored parameter and
the one to use. A second node, on a reference profile with no lidar_url, warns naming it.
"""

from __future__ import annotations

import os
import pty
import termios
import uuid
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest
from ros_env import require_ros

require_ros()

from bridge_harness import BridgeProcess, Probe, logged, values  # noqa: E402
from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy  # noqa: E402

from protocol.robotfile import reference_path  # noqa: E402
from roverlink.ros2.diagnostics import WARN  # noqa: E402
from tests.support.wait import wait_until  # noqa: E402

LATE = QoSProfile(depth=10, reliability=ReliabilityPolicy.RELIABLE, durability=DurabilityPolicy.TRANSIENT_LOCAL)


def _robot_file(tmp_path: Path) -> Path:
    text = reference_path("diffdrive-tb6612").read_text(encoding="utf-8")
    assert text.count("wheel_diameter_m = 0.064 ") == 1
    text = text.replace("wheel_diameter_m = 0.064 ", "wheel_diameter_m = 0.07 ")
    imu = 'model = "jy901"'
    assert text.count(imu) == 1
    path = tmp_path / "mine.toml"
    path.write_text(text.replace(imu, f"{imu}\nbaud = 9600"), encoding="utf-8")
    return path


class _Node:
    def __init__(self, proc: BridgeProcess, probe: Probe, ns: str, imu_fd: int) -> None:
        self.proc, self.probe, self.ns, self.imu_fd = proc, probe, ns, imu_fd


@pytest.fixture(scope="module")
def node(ros: None, tf2_msgs: Path, tmp_path_factory: pytest.TempPathFactory) -> Iterator[_Node]:
    tmp_path = tmp_path_factory.mktemp("param_warnings")
    master, slave = pty.openpty()
    ns = f"/params_{uuid.uuid4().hex[:6]}"
    board = f"emu://?robot={reference_path('diffdrive-tb6612')}&seed=1"  # the reference board, not the file's
    params: dict[str, Any] = {
        "allow_mismatch": "true",
        "imu_url": os.ttyname(slave),
        "base_frame": "base_footprint",
        "wheel_diameter": 0.065,
        "Kp": 20.0,
        "odom_rat": 50,
    }
    proc = BridgeProcess(ns, board, tmp_path, robot_file=_robot_file(tmp_path), params=params)
    probe = Probe(ns)
    try:
        with logged(proc, probe):
            yield _Node(proc, probe, ns, slave)
    finally:
        os.close(master)
        os.close(slave)


def test_an_allowed_mismatch_is_a_warn_in_diagnostics_naming_the_difference(node: _Node) -> None:
    status = node.probe.wait_status("robot", lambda s: values(s).get("robot") == "diffdrive-tb6612", 20)
    assert status.level == bytes([WARN]), (status.level, status.message)
    assert "differs from the robot file" in status.message
    assert "geometry.wheel_diameter_m = 0.07" in status.message, status.message
    assert "geometry.wheel_diameter_m" in values(status)["mismatch 1"]


def test_the_imu_is_opened_at_the_robot_files_baud(node: _Node) -> None:
    speeds = wait_until(
        lambda: (s := termios.tcgetattr(node.imu_fd)[4:6]) == [termios.B9600] * 2 and s,
        20,
        "the IMU's pty set to 9600 baud",
        fail=False,
    )
    assert speeds, (termios.tcgetattr(node.imu_fd)[4:6], node.proc.log())
    imu = node.probe.wait_status("imu", lambda s: "baud" in values(s), 20)
    assert values(imu)["baud"] == "9600"


def test_base_frame_base_footprint_publishes_no_transform_to_itself(node: _Node) -> None:
    from tf2_msgs.msg import TFMessage

    probe = node.probe
    probe.wait_for("the /tf_static publisher", lambda: probe.node.count_publishers(f"{node.ns}/tf_static") == 1, 20)
    probe.subscribe("tf_static", TFMessage, f"{node.ns}/tf_static", LATE)
    last = probe.wait_for("/tf_static", lambda: probe.last("tf_static"), 20)
    pairs = {(t.header.frame_id, t.child_frame_id) for t in last.transforms}
    assert ("base_footprint", "imu_link") in pairs, pairs
    assert all(parent != child for parent, child in pairs), pairs


def test_old_and_unknown_parameters_are_warned_with_the_name_to_use(node: _Node) -> None:
    lines = (
        "parameter Kp is ros_arduino_bridge's and is ignored: RoverLink's is the robot file's [pid] kp",
        "parameter wheel_diameter is ros_arduino_bridge's and is ignored: RoverLink's is the robot file's "
        "[geometry] wheel_diameter_m",
        "unknown parameter odom_rat is ignored: did you mean odom_rate",
    )
    log = wait_until(
        lambda: (text := node.proc.log()) and all(line in text for line in lines) and text,
        20,
        "the warnings in the log",
        fail=False,
    )
    assert log, node.proc.log()
    assert "use_sim_time" not in log  # rclpy's own parameter is no unknown one


def test_a_profile_with_a_lidar_and_no_lidar_url_warns_naming_the_parameter(ros: None, tmp_path: Path) -> None:
    proc = BridgeProcess(f"/no_lidar_{uuid.uuid4().hex[:6]}", "/dev/roverlink-no-such-port", tmp_path, profile="picar")
    try:
        said = "the picar robot carries a ydlidar-f4 but the lidar_url parameter is empty: no scan and no laser frame"
        log = wait_until(lambda: said in (text := proc.log()) and text, 20, "the lidar_url warning", fail=False)
        assert log, proc.log()
        assert "imu_url" not in log  # the PiCar carries no IMU
    finally:
        proc.stop()
