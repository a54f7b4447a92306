"""The node's `/tf_static`: base_link -> each sensor's frame at its mount (the robot file's, else the
reference robot's), received by a subscriber that joins late, as tf2's listener does, with
transient-local QoS; none with publish_static_tf:=false."""

from __future__ import annotations

import math
import time
import uuid
from pathlib import Path
from typing import Any

import pytest
from ros_env import require_ros

require_ros()

from bridge_harness import BridgeProcess, Probe, logged, values, yaw  # noqa: E402
from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy  # noqa: E402

from protocol.generated.profiles import ROBOT_SENSORS  # noqa: E402
from protocol.robotfile import reference_path  # noqa: E402
from protocol.sensors import Mount  # noqa: E402

LATE = QoSProfile(depth=10, reliability=ReliabilityPolicy.RELIABLE, durability=DurabilityPolicy.TRANSIENT_LOCAL)
LIDAR = '[sensors.lidar]\nmodel = "rplidar-a1"\nx_m = -0.05\ny_m = 0.02\nz_m = 0.3\nyaw_deg = 90.0\n\n'


def start(tmp_path: Path, url: str, **kw: Any) -> tuple[BridgeProcess, Probe, str]:
    ns = f"/static_tf_{uuid.uuid4().hex[:6]}"
    return BridgeProcess(ns, url, tmp_path, **kw), Probe(ns), ns


def connected(probe: Probe, name: str) -> None:
    """The robot is connected (the node's setup on connecting, static frames included, is done)."""
    probe.wait_status("robot", lambda s: values(s).get("robot") == name, 20)


def late_frames(probe: Probe, tf2_msgs: Path, ns: str, expected: set[str]) -> dict[str, Any]:
    """Subscribe now, after the node published, and return the transforms it gets, by child frame."""
    from tf2_msgs.msg import TFMessage

    probe.wait_for("the node's /tf_static publisher", lambda: probe.node.count_publishers(f"{ns}/tf_static") == 1, 10)
    probe.subscribe("tf_static", TFMessage, f"{ns}/tf_static", LATE)

    def got() -> dict[str, Any] | None:
        last = probe.last("tf_static")
        frames = {t.child_frame_id: t for t in last.transforms} if last is not None else {}
        return frames if set(frames) >= expected else None

    frames: dict[str, Any] = probe.wait_for(f"/tf_static with {sorted(expected)}", got, 10)
    return frames


def assert_at(transform: Any, mount: Mount) -> None:
    assert transform.header.frame_id == "base_link"
    t, q = transform.transform.translation, transform.transform.rotation
    assert (t.x, t.y, t.z) == pytest.approx((mount.x_m, mount.y_m, mount.z_m), abs=1e-9)
    assert (q.x, q.y) == pytest.approx((0.0, 0.0), abs=1e-9)
    assert math.degrees(yaw(q)) == pytest.approx(mount.yaw_deg, abs=1e-6)


def test_a_reference_robots_sensors_at_its_mounts(ros: None, tf2_msgs: Path, tmp_path: Path) -> None:
    proc, probe, ns = start(tmp_path, "emu://diffdrive-bts7960?seed=1&lidar=rplidar-a1&imu=jy901")
    with logged(proc, probe):
        connected(probe, "DiffDriveBTS7960")
        frames = late_frames(probe, tf2_msgs, ns, {"base_footprint", "laser", "imu_link"})
        assert set(frames) == {"base_footprint", "laser", "imu_link"}  # no camera: the node runs none
        body = ROBOT_SENSORS["diffdrive-bts7960"]
        assert_at(frames["laser"], body.placed("lidar"))
        assert_at(frames["imu_link"], body.placed("imu"))  # where the emulator puts the IMU it carries
        assert_at(frames["base_footprint"], Mount("", ""))
        # Once: two more diagnostics reports later it is still the one message.
        after = time.monotonic()
        probe.wait_for("two diagnostics reports", lambda: len(probe.since("diagnostics", after)) >= 2, 10)
        assert len(probe.since("tf_static")) == 1


def test_a_robot_files_moved_lidar(ros: None, tf2_msgs: Path, tmp_path: Path) -> None:
    text = reference_path("diffdrive-tb6612").read_text(encoding="utf-8")
    path = tmp_path / "mine.toml"
    path.write_text(text.replace("[sensors.imu]", LIDAR + "[sensors.imu]"), encoding="utf-8")
    proc, probe, ns = start(tmp_path, "emu://diffdrive-tb6612?seed=1", robot_file=path)
    with logged(proc, probe):
        connected(probe, "diffdrive-tb6612")  # the emulated robot is the file's (its name)
        names = {"base_footprint", "laser", "imu_link", "camera_link", "camera_optical_frame"}
        frames = late_frames(probe, tf2_msgs, ns, names)
        assert set(frames) == names
        assert_at(frames["laser"], Mount("rplidar-a1", "lidar", -0.05, 0.02, 0.3, 90.0))
        assert_at(frames["imu_link"], Mount("jy901", "imu", 0.0, 0.0, 0.05, 0.0))
        assert_at(frames["camera_link"], Mount("pi-camera-v2", "camera", 0.1, 0.0, 0.14, 0.0))
        optical = frames["camera_optical_frame"]
        assert optical.header.frame_id == "camera_link"
        q = optical.transform.rotation
        assert (q.x, q.y, q.z, q.w) == pytest.approx((-0.5, 0.5, -0.5, 0.5))  # REP-103: z forward, y down


def test_publish_static_tf_false_publishes_none(ros: None, tf2_msgs: Path, tmp_path: Path) -> None:
    from tf2_msgs.msg import TFMessage

    url = "emu://diffdrive-bts7960?seed=1&lidar=rplidar-a1&imu=jy901"
    proc, probe, ns = start(tmp_path, url, params={"publish_static_tf": "false"})
    with logged(proc, probe):
        connected(probe, "DiffDriveBTS7960")
        probe.subscribe("tf_static", TFMessage, f"{ns}/tf_static", LATE)  # late: would get what was sent
        after = time.monotonic()
        probe.wait_for("two diagnostics reports", lambda: len(probe.since("diagnostics", after)) >= 2, 10)
        assert probe.node.count_publishers(f"{ns}/tf_static") == 0
        assert probe.since("tf_static") == []
