"""`odometry/filtered` (wheel odometry + the JY901's gyro in the SDK's EKF), `tf_from: fused`, the
IMU's covariances, `~/reset_odometry` and `~/set_pose`, and refusals that name `~/arm`: a real
bridge process against the emulated diff-drive car with a JY901, on the real clock."""

from __future__ import annotations

import math
import subprocess
import sys
import time
import uuid
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from ros_env import require_ros

require_ros()

from bridge_harness import ROOT, BridgeProcess, Probe, logged, values, yaw  # noqa: E402
from geometry_msgs.msg import PoseWithCovarianceStamped  # noqa: E402
from nav_msgs.msg import Odometry  # noqa: E402
from rclpy.qos import qos_profile_sensor_data  # noqa: E402
from sensor_msgs.msg import Imu  # noqa: E402

from roverlink.ros2.params import IMU_ACCEL_VARIANCE, IMU_GYRO_VARIANCE  # noqa: E402

URL = "emu://diffdrive-tb6612?seed=5&imu=jy901&track_scale=1.04"
"""The car's real track is 4 % wider than its configuration says (a track width measured between
the tyres' inner edges, say): wheel odometry over-reads every turn, the gyro does not."""
ORIENTATION_VARIANCE = [0.001, 0.002, 0.003]


@pytest.fixture(scope="module")
def fused(ros: None, tf2_msgs: Path, tmp_path_factory: pytest.TempPathFactory) -> Iterator[Probe]:
    from tf2_msgs.msg import TFMessage

    ns = f"/fused_{uuid.uuid4().hex[:6]}"
    params = {"tf_from": "fused", "imu_orientation_covariance_diagonal": str(ORIENTATION_VARIANCE)}
    proc = BridgeProcess(ns, URL, tmp_path_factory.mktemp("ros2"), params=params)
    probe = Probe(ns)
    probe.subscribe("filtered", Odometry, "odometry/filtered")
    probe.subscribe("imu", Imu, "imu", qos_profile_sensor_data)
    probe.subscribe("tf", TFMessage, "tf", 100)
    probe.set_pose = probe.node.create_publisher(PoseWithCovarianceStamped, "roverlink/set_pose", 10)  # type: ignore[attr-defined]
    probe.proc = proc  # type: ignore[attr-defined]
    with logged(proc, probe):
        probe.wait_for("the bridge's services", lambda: probe.clients["arm"].wait_for_service(timeout_sec=0.1), 20)
        probe.wait_status("imu", lambda s: s.level == b"\x00", 20)
        probe.wait_message("filtered", timeout_s=10)
        yield probe


def covariance3(msg: Any) -> np.ndarray:
    """(x, y, yaw) block of a 6x6 pose covariance."""
    c = np.array(msg.pose.covariance).reshape(6, 6)
    return c[np.ix_([0, 1, 5], [0, 1, 5])]


def pose3(msg: Any) -> tuple[float, float, float]:
    p = msg.pose.pose
    return p.position.x, p.position.y, yaw(p.orientation)


def wait_odom_still(probe: Probe, key: str = "odom") -> Any:
    def still() -> Any:
        recent = probe.since(key, time.monotonic() - 0.3)
        ok = len(recent) >= 3 and all(abs(r.msg.twist.twist.linear.x) < 1e-3 for r in recent)
        ok = ok and all(abs(r.msg.twist.twist.angular.z) < 0.02 for r in recent)
        return recent[-1].msg if ok else None

    return probe.wait_for(f"{key} to stand still", still, 5)


def test_cmd_vel_refused_before_arming_names_the_arm_service(fused: Probe) -> None:
    """The robot starts disarmed: the SDK's NotArmedError says to call robot.arm(); the node names
    its service instead (and so after ~/disarm)."""
    ns = fused.node.get_namespace()
    hint = f"call the {ns}/roverlink/arm service (ros2 service call {ns}/roverlink/arm std_srvs/srv/Trigger)"
    log = fused.proc.log  # type: ignore[attr-defined]
    fused.drive(0.2, 0.0, 0.3)
    status = fused.wait_status("robot", lambda s: "not armed" in values(s)["last refusal"])
    assert hint in values(status)["last refusal"], values(status)["last refusal"]
    fused.wait_for("the refusal in the log", lambda: hint in log())
    assert "robot.arm()" not in log()
    assert fused.call("arm").success
    fused.drive(0.0, 0.0, 0.2)
    assert fused.call("disarm").success
    fused.drive(0.2, 0.0, 0.3)
    status = fused.wait_status("robot", lambda s: "~/disarm" in values(s)["last refusal"])
    assert hint in values(status)["last refusal"], values(status)["last refusal"]


def test_filtered_odometry_has_a_positive_covariance_that_grows_while_driving(fused: Probe) -> None:
    assert fused.call("arm").success
    first = fused.wait_message("filtered", after=time.monotonic())
    assert (first.header.frame_id, first.child_frame_id) == ("odom", "base_link")
    before = covariance3(first)
    assert np.all(np.linalg.eigvalsh(before) > 0), before  # positive definite, so not zero either
    fused.drive(0.3, 0.0, 1.5)
    after = covariance3(fused.wait_message("filtered", after=time.monotonic()))
    assert np.all(np.linalg.eigvalsh(after) > 0), after
    assert after[0, 0] + after[1, 1] > 2 * (before[0, 0] + before[1, 1]), (before, after)
    assert np.array(first.pose.covariance)[14] == pytest.approx(0.001)  # z: pose_covariance_diagonal's
    fused.drive(0.0, 0.0, 0.3)


def test_fused_yaw_follows_ground_truth_while_spinning(fused: Probe) -> None:
    assert fused.call("arm").success
    fused.drive(0.0, 0.0, 0.3)
    wait_odom_still(fused)
    truth0 = fused.wait_message("truth", after=time.monotonic())
    odom0, filtered0 = fused.last("odom"), fused.last("filtered")
    fused.drive(0.0, 1.2, 4.0)
    fused.drive(0.0, 0.0, 0.3)
    odom1 = wait_odom_still(fused)
    filtered1 = fused.wait_message("filtered", after=time.monotonic())
    truth1 = fused.wait_message("truth", after=time.monotonic())

    def turned(a: Any, b: Any) -> float:
        return yaw(b.pose.pose.orientation) - yaw(a.pose.pose.orientation)

    truth = turned(truth0, truth1)
    assert abs(truth) > 1.0, "the robot hardly turned"
    odom_error = abs(math.remainder(turned(odom0, odom1) - truth, math.tau))
    fused_error = abs(math.remainder(turned(filtered0, filtered1) - truth, math.tau))
    errors = {"turned": math.degrees(truth), "odom": math.degrees(odom_error), "fused": math.degrees(fused_error)}
    assert odom_error > 0.03 * abs(truth), errors  # the track's 4 %
    assert fused_error < 0.3 * odom_error and math.degrees(fused_error) < 1.5, errors


def test_tf_from_fused_is_the_filtered_pose(fused: Probe) -> None:
    assert fused.call("arm").success
    t0 = time.monotonic()
    fused.drive(0.2, 0.5, 1.0)
    fused.wait_for("20 transforms", lambda: len(fused.since("tf", t0)) >= 20)
    transforms = [tf for r in fused.since("tf", t0) for tf in r.msg.transforms]

    def filtered_poses() -> dict[tuple[int, int], tuple[float, float, float]]:
        return {
            (m.header.stamp.sec, m.header.stamp.nanosec): pose3(m) for m in (r.msg for r in fused.since("filtered"))
        }

    def stamp_of(tf: Any) -> tuple[int, int]:
        return tf.header.stamp.sec, tf.header.stamp.nanosec

    # The two topics reach the probe through separate subscriptions, in either order: wait (with a
    # deadline) for the filtered messages of the transforms already here.
    def all_filtered() -> dict[tuple[int, int], tuple[float, float, float]] | None:
        poses = filtered_poses()
        return poses if all(stamp_of(tf) in poses for tf in transforms) else None

    filtered = fused.wait_for("odometry/filtered at every transform's stamp", all_filtered, 5)
    for tf in transforms:  # every one is a fused pose (the wheel odometry's is not published)
        assert (tf.header.frame_id, tf.child_frame_id) == ("odom", "base_link")
        x, y, theta = filtered[stamp_of(tf)]
        assert (tf.transform.translation.x, tf.transform.translation.y) == (x, y)
        assert math.remainder(yaw(tf.transform.rotation) - theta, math.tau) == pytest.approx(0.0, abs=1e-9)
    fused.drive(0.0, 0.0, 0.3)


def test_imu_carries_the_parameter_covariances(fused: Probe) -> None:
    imu = fused.wait_message("imu", after=time.monotonic())
    assert list(imu.orientation_covariance) == pytest.approx(list(np.diag(ORIENTATION_VARIANCE).ravel()))
    assert list(imu.angular_velocity_covariance) == pytest.approx(list(np.diag(IMU_GYRO_VARIANCE).ravel()))
    assert list(imu.linear_acceleration_covariance) == pytest.approx(list(np.diag(IMU_ACCEL_VARIANCE).ravel()))


def test_reset_odometry_while_driving_then_odometry_goes_on(fused: Probe) -> None:
    assert fused.call("arm").success
    fused.drive(0.3, 0.4, 1.5)
    fused.twist(0.3, 0.4)  # still driving while the service runs (cmd_vel_timeout 0.5 s)
    t = time.monotonic()
    answer = fused.call("reset_odometry")
    assert answer.success, answer.message
    assert "set to x=0.000 m, y=0.000 m, yaw=0.0 deg" in answer.message and "EKF" in answer.message
    assert "joint angles unchanged" in answer.message
    for key in ("odom", "filtered"):
        fused.wait_for(f"5 {key} after the reset", lambda k=key: len(fused.since(k, t)) >= 5)
        poses = [pose3(r.msg) for r in fused.since(key, t)]
        at_zero = [i for i, (x, y, theta) in enumerate(poses) if math.hypot(x, y) < 0.003 and abs(theta) < 0.003]
        assert at_zero, (key, poses)
        before, after = poses[: at_zero[0]], poses[at_zero[0] :]
        assert all(math.hypot(x, y) > 0.2 for x, y, _ in before), (key, poses)  # driven before the reset
        # From zero on, one 20 ms step at a time (0.3 m/s): nothing integrated before the reset follows.
        assert all(math.hypot(x, y) < 0.007 * (i + 1) for i, (x, y, _) in enumerate(after)), (key, poses)
    fused.drive(0.3, 0.0, 1.0)
    for key in ("odom", "filtered"):
        x, _, _ = pose3(fused.wait_message(key, after=time.monotonic()))
        assert x > 0.1, (key, x, fused.proc.log()[-3000:])  # type: ignore[attr-defined]  # integrating again
    fused.drive(0.0, 0.0, 0.3)


def test_set_pose_puts_odometry_at_the_given_pose(fused: Probe) -> None:
    fused.call("disarm")  # works disarmed too
    wait_odom_still(fused)
    msg = PoseWithCovarianceStamped()
    msg.header.frame_id = "odom"
    msg.pose.pose.position.x, msg.pose.pose.position.y = 1.5, -2.0
    msg.pose.pose.orientation.z, msg.pose.pose.orientation.w = math.sin(0.35), math.cos(0.35)  # yaw 0.7
    t = time.monotonic()
    fused.set_pose.publish(msg)  # type: ignore[attr-defined]

    def at_pose(key: str) -> Any:
        for r in reversed(fused.since(key, t)):
            x, y, theta = pose3(r.msg)
            if math.hypot(x - 1.5, y + 2.0) < 0.003 and abs(theta - 0.7) < 1e-3:
                return r.msg
        return None

    for key in ("odom", "filtered"):
        fused.wait_for(f"{key} at the set pose", lambda k=key: at_pose(k), 5)
    said = "~/set_pose: wheel odometry and the EKF set to x=1.500 m, y=-2.000 m, yaw=40.1 deg"
    fused.wait_for("the log line", lambda: said in fused.proc.log())  # type: ignore[attr-defined]


def test_tf_from_fused_without_an_imu_is_refused_at_start(ros: None) -> None:
    args = [sys.executable, "-m", "roverlink", "ros2", "--url", "emu://diffdrive-tb6612", "--ros-args"]
    args += ["-r", f"__ns:=/nofuse_{uuid.uuid4().hex[:6]}", "-p", "tf_from:=fused"]
    done = subprocess.run(args, cwd=ROOT, capture_output=True, text=True, timeout=60, check=False)
    assert done.returncode == 1, done.stderr
    assert "parameter tf_from" in done.stderr and "imu_url" in done.stderr, done.stderr
