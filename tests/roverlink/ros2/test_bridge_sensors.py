"""`scan` and `imu`: the SLAM robot with its RPLIDAR A1 and a JY901 in an emulated room, through a
real bridge process. The IMU's turn rate and heading change are checked against the odometry's
while the robot spins in place."""

from __future__ import annotations

import contextlib
import itertools
import math
import statistics
import time
import uuid
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest
from ros_env import require_ros

require_ros()

from bridge_harness import BridgeProcess, Probe, stamp_s, values, yaw  # noqa: E402
from rclpy.qos import qos_profile_sensor_data  # noqa: E402
from sensor_msgs.msg import Imu, LaserScan  # noqa: E402

URL = "emu://diffdrive-bts7960?seed=2&world=random:2&lidar=rplidar-a1&imu=jy901"


@contextlib.contextmanager
def _bridge(prefix: str, url: str, log_dir: Path) -> Iterator[Probe]:
    """A bridge on `url` and a probe subscribed to its `scan` and `imu` (its log printed on failure)."""
    ns = f"/{prefix}_{uuid.uuid4().hex[:6]}"
    proc = BridgeProcess(ns, url, log_dir)
    probe = Probe(ns)
    probe.subscribe("scan", LaserScan, "scan", qos_profile_sensor_data)
    probe.subscribe("imu", Imu, "imu", qos_profile_sensor_data)
    try:
        yield probe
    except BaseException:
        print(proc.log())
        raise
    finally:
        probe.close()
        assert proc.stop() == 0


def _streaming(status: Any) -> bool:
    """OK with the rate, or (the lidar on a busy host, its emulator on the wall clock) WARN because
    late reads made its scanner rewrite stamps, which the counts then show."""
    if status.level == b"\x00":
        return bool(status.message.endswith("Hz"))
    rewrites = ("scan stamps refitted", "scan stamps retimed", "scans dropped (no ordered stamp)")
    return (
        status.level == b"\x01"
        and "scan stamps rewritten" in status.message
        and sum(int(values(status)[k]) for k in rewrites) > 0
    )


@pytest.fixture(scope="module")
def sensed(ros: None, tmp_path_factory: pytest.TempPathFactory) -> Iterator[Probe]:
    with _bridge("sensors", URL, tmp_path_factory.mktemp("ros2")) as probe:
        probe.wait_status("lidar", _streaming, 20)
        probe.wait_status("imu", lambda s: s.level == b"\x00", 5)
        yield probe


def test_scan_is_a_laserscan_of_the_room(sensed: Probe) -> None:
    t0 = time.monotonic()
    sensed.wait_for("4 scans", lambda: len(sensed.since("scan", t0)) >= 4, 5)
    scans = [r.msg for r in sensed.since("scan", t0)]
    scan = scans[-1]
    assert scan.header.frame_id == "laser" and len(scan.ranges) == 360
    assert scan.angle_min == pytest.approx(-math.pi) and scan.angle_increment == pytest.approx(2 * math.pi / 360)
    walls = [r for r in scan.ranges if math.isfinite(r)]
    assert len(walls) > 300, "a closed room: nearly every bearing sees a wall"
    assert all(scan.range_min <= r <= scan.range_max for r in walls)
    stamps = [stamp_s(m.header.stamp) for m in scans]
    period = statistics.median(b - a for a, b in itertools.pairwise(stamps))
    assert period == pytest.approx(scan.scan_time, rel=0.2)  # one message per revolution
    status = values(sensed.status("lidar"))
    assert status["framing errors"] == "0" and status["checksum errors"] == "0"
    assert {"scan stamps refitted", "scan stamps retimed", "scans dropped (no ordered stamp)"} <= status.keys()


def test_imu_agrees_with_odometry_while_turning(sensed: Probe) -> None:
    imu = sensed.wait_message("imu")
    assert imu.header.frame_id == "imu_link"
    q = imu.orientation
    assert math.sqrt(q.x**2 + q.y**2 + q.z**2 + q.w**2) == pytest.approx(1.0, abs=1e-3)
    assert imu.linear_acceleration.z == pytest.approx(9.81, abs=0.5)  # gravity, the module lying flat
    assert sensed.call("arm").success
    sensed.drive(0.0, 1.0, 0.6)  # spin up
    t0 = time.monotonic()
    odom0 = sensed.last("odom")
    sensed.drive(0.0, 1.0, 1.5)
    odom1 = sensed.last("odom")
    sensed.wait_for(
        "IMU messages past the last odom", lambda: _imu_yaw_at(sensed, stamp_s(odom1.header.stamp)) is not None
    )
    rates = [r.msg.angular_velocity.z for r in sensed.since("imu", t0)]
    assert statistics.median(rates) == pytest.approx(1.0, abs=0.15)
    # Compared at the same stamps: the last message of each topic may have arrived tens of ms apart.
    turned_odom = math.remainder(yaw(odom1.pose.pose.orientation) - yaw(odom0.pose.pose.orientation), math.tau)
    yaw0, yaw1 = (_imu_yaw_at(sensed, stamp_s(m.header.stamp)) for m in (odom0, odom1))
    assert yaw0 is not None and yaw1 is not None
    turned_imu = math.remainder(yaw1 - yaw0, math.tau)
    assert turned_odom > 1.0
    assert math.degrees(abs(turned_imu - turned_odom)) < 5.0
    sensed.drive(0.0, 0.0, 0.3)


def _imu_yaw_at(probe: Probe, t: float) -> float | None:
    """The IMU's yaw at stamp `t`, between the two messages stamped around it (None until both came)."""
    msgs = sorted((r.msg for r in probe.since("imu")), key=lambda m: stamp_s(m.header.stamp))
    for a, b in itertools.pairwise(msgs):
        ta, tb = stamp_s(a.header.stamp), stamp_s(b.header.stamp)
        if ta <= t <= tb and tb > ta:
            ya = yaw(a.orientation)
            return ya + (t - ta) / (tb - ta) * math.remainder(yaw(b.orientation) - ya, math.tau)
    return None


def test_sensor_diagnostics(sensed: Probe) -> None:
    for kind in ("lidar", "imu"):
        status = sensed.status(kind)
        if kind == "lidar":
            assert _streaming(status), status.message
        else:
            assert status.level == b"\x00" and status.message.endswith("Hz")
        v = values(status)
        assert v["url"].startswith("emudev://") and int(v[f"{kind} messages"]) > 0


def test_an_open_world_scans_plus_inf_with_a_stamp_per_revolution(ros: None, tmp_path: Path) -> None:
    """REP 117 through a real bridge: nothing in range is +inf (NaN only where no sample fell);
    one revolution per message, cut at the rear, stamped with ray 0's measurement time."""
    with _bridge("open", "emu://diffdrive-bts7960?seed=2&world=empty&lidar=rplidar-a1", tmp_path) as probe:
        probe.wait_for("6 scans", lambda: len(probe.since("scan")) >= 6, 20)
        scans = [r.msg for r in probe.since("scan")]
        for scan in scans:
            assert scan.angle_min == pytest.approx(-math.pi) and len(scan.ranges) == 360
            assert scan.angle_increment == pytest.approx(2 * math.pi / 360)
            assert scan.time_increment == pytest.approx(-scan.scan_time / 360, rel=0.05)  # clockwise
            assert not any(math.isfinite(r) or r < 0 for r in scan.ranges)
            assert sum(math.isinf(r) for r in scan.ranges) > 0.9 * 360, "open: +inf, not NaN"
        # The emulator runs on the wall clock here: a busy machine jitters single periods.
        stamps = [stamp_s(m.header.stamp) for m in scans]
        period = statistics.median(b - a for a, b in itertools.pairwise(stamps))
        assert period == pytest.approx(statistics.median(s.scan_time for s in scans), rel=0.2)
        assert all(b > a for a, b in itertools.pairwise(stamps))
