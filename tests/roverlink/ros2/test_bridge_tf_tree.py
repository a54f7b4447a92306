"""The TF tree a SLAM or Nav2 stack needs, from the first scan on: the SLAM robot (lockstep, its
RPLIDAR A1) through a real bridge process, disarmed and then armed and driving.

A scan can be used when a tf2 buffer can give `odom -> laser` at its stamp: the static
`base_link -> laser` on /tf_static, and `odom -> base_link` transforms stamped at or around the
scan's stamp (tf2 interpolates between two; it never extrapolates).
"""

from __future__ import annotations

import bisect
import time
import uuid
from collections.abc import Iterator

import pytest
from ros_env import require_ros

require_ros()

from bridge_harness import BridgeProcess, Probe, Received, logged, stamp_s  # noqa: E402
from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy, qos_profile_sensor_data  # noqa: E402
from sensor_msgs.msg import LaserScan  # noqa: E402

URL = "emu://diffdrive-bts7960?seed=3&world=random:3&lidar=rplidar-a1"
STATIC_QOS = QoSProfile(depth=1, reliability=ReliabilityPolicy.RELIABLE, durability=DurabilityPolicy.TRANSIENT_LOCAL)


@pytest.fixture(scope="module")
def slam_robot(ros: None, tf2_msgs: object, tmp_path_factory: pytest.TempPathFactory) -> Iterator[Probe]:
    from tf2_msgs.msg import TFMessage

    ns = f"/tftree_{uuid.uuid4().hex[:6]}"
    proc = BridgeProcess(ns, URL, tmp_path_factory.mktemp("ros2"))
    probe = Probe(ns)
    probe.subscribe("scan", LaserScan, "scan", qos_profile_sensor_data)
    probe.subscribe("tf", TFMessage, "tf", 100)
    probe.subscribe("tf_static", TFMessage, "tf_static", STATIC_QOS)
    with logged(proc, probe):
        yield probe


def odom_stamps(probe: Probe, after: float) -> list[float]:
    return sorted(
        stamp_s(t.header.stamp)
        for r in probe.since("tf", after)
        for t in r.msg.transforms
        if t.header.frame_id == "odom" and t.child_frame_id == "base_link"
    )


def usable(probe: Probe, t0: float, t1: float) -> tuple[int, int]:
    """(scans received in [t0, t1], those whose stamp lies within the odom -> base_link transforms)."""
    scans = [r.msg for r in probe.since("scan", t0) if r.at <= t1]
    stamps = odom_stamps(probe, 0.0)
    ok = 0
    for scan in scans:
        s = stamp_s(scan.header.stamp)
        i = bisect.bisect_left(stamps, s)
        exact = i < len(stamps) and stamps[i] == s
        good = exact or (0 < i < len(stamps))
        ok += good
        if not good:
            print(f"scan at {s:.3f}: odom -> base_link from {stamps[0]:.3f} to {stamps[-1]:.3f} ({len(stamps)})")
    return len(scans), ok


def test_every_scan_can_be_placed_from_the_first_second_disarmed_then_armed(slam_robot: Probe) -> None:
    probe = slam_robot
    first_tf = probe.wait_for("the first transform", lambda: probe.since("tf"), 30)[0]
    tf0 = min(stamp_s(t.header.stamp) for t in first_tf.msg.transforms)

    def placeable_scans() -> list[Received]:
        return [r for r in probe.since("scan") if stamp_s(r.msg.header.stamp) > tf0]

    first = probe.wait_for("a scan", placeable_scans, 30)[0]
    # The probe joins the graph as the node starts: what the node published before discovery
    # matched the probe's /tf subscription never reaches it, so scans stamped before the first
    # transform it got cannot be judged here. Counted: every scan from the first one after that
    # (the transforms begin no later than a second after the scans).
    earliest_scan = probe.since("scan")[0]
    assert first_tf.at - earliest_scan.at < 1.0
    # Disarmed (lockstep, no command ever sent): 2 s of scans from the first one on.
    t_end = first.at + 2.0
    probe.wait_for("2 s of scans", lambda: time.monotonic() > t_end + 0.3, 5)
    n, ok = usable(probe, first.at, t_end)
    assert n >= 10 and ok == n, f"disarmed: {ok} of {n} scans have odom -> base_link at their stamp"
    static = [t for r in probe.since("tf_static") for t in r.msg.transforms]
    laser = [t for t in static if t.header.frame_id == "base_link" and t.child_frame_id == "laser"]
    assert laser, f"no base_link -> laser on tf_static: {[(t.header.frame_id, t.child_frame_id) for t in static]}"
    assert laser[0].transform.translation.z == pytest.approx(0.22)  # diffdrive-bts7960's lidar mount
    # Armed and driving.
    assert probe.call("arm").success
    t0 = time.monotonic()
    probe.drive(0.2, 0.5, 2.0)
    t1 = time.monotonic()
    probe.drive(0.0, 0.0, 0.5)
    n, ok = usable(probe, t0, t1)
    assert n >= 10 and ok == n, f"armed: {ok} of {n} scans have odom -> base_link at their stamp"
