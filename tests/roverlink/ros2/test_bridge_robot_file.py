"""`roverlink ros2 --robot FILE`: the node's odometry and cmd_vel use the file's geometry.

The emulated TB6612 robot is built wider than the reference (track_scale: its true track is
0.25 m, not 0.2 m); a robot file saying so makes a turn in place come out right in odometry,
where the reference profile's track would be 25 % off.
"""

from __future__ import annotations

import math
import time
import uuid
from pathlib import Path

import pytest
from ros_env import require_ros

require_ros()

from bridge_harness import BridgeProcess, Probe, logged, values, yaw  # noqa: E402

from protocol.robotfile import reference_path  # noqa: E402


def test_odometry_uses_the_files_track(ros: None, tmp_path: Path) -> None:
    text = reference_path("diffdrive-tb6612").read_text(encoding="utf-8")
    assert text.count("track_m = 0.2 ") == 1
    path = tmp_path / "wide.toml"
    path.write_text(text.replace("track_m = 0.2 ", "track_m = 0.25 "), encoding="utf-8")
    ns = f"/robot_file_{uuid.uuid4().hex[:6]}"
    proc = BridgeProcess(ns, "emu://diffdrive-tb6612?seed=1&track_scale=1.25", tmp_path, robot_file=path)
    probe = Probe(ns)
    with logged(proc, probe):
        probe.wait_for("the bridge's services", lambda: probe.clients["arm"].wait_for_service(timeout_sec=0.1), 20)
        probe.wait_status("robot", lambda s: values(s).get("robot") == "DiffDriveTB6612", 20)
        assert probe.call("arm").success
        start = yaw(probe.wait_message("truth").pose.pose.orientation)
        odom_start = yaw(probe.wait_message("odom").pose.pose.orientation)
        probe.drive(0.0, 1.0, 1.5)
        probe.drive(0.0, 0.0, 0.3)

        def still() -> object:
            recent = probe.since("odom", time.monotonic() - 0.3)
            ok = len(recent) >= 3 and all(abs(r.msg.twist.twist.angular.z) < 1e-3 for r in recent)
            return recent[-1].msg if ok else None

        odom = probe.wait_for("the robot to stand still", still, 5)
        truth = probe.wait_message("truth", after=time.monotonic())
        turned = math.degrees(math.remainder(yaw(truth.pose.pose.orientation) - start, math.tau))
        odom_turned = math.degrees(math.remainder(yaw(odom.pose.pose.orientation) - odom_start, math.tau))
        assert turned > 45, turned
        assert odom_turned == pytest.approx(turned, abs=1.0)  # the reference track: a quarter off
