"""The node's fusion of wheel odometry and the IMU's gyro (roverlink.ros2.fusion), without ROS:
time order across the two threads' streams, the wait for a silent stream, setting the pose, the
clocks the samples are stamped on, and `tf_from: fused` without an IMU."""

from __future__ import annotations

import math
import re
from types import SimpleNamespace

import numpy as np
import pytest

from host_sdk import CommandRangeError, Robot
from host_sdk.sensors import Jy901
from roverlink.ros2 import convert
from roverlink.ros2.fusion import MAX_LAG_S, RESYNC_SAMPLES, Fusion, PoseGate, check_tf_from, imu_time
from roverlink.ros2.params import BridgeParams

PERIOD_S = 0.02  # FEEDBACK at 50 Hz
GYRO_S = 0.005  # the JY901 at 200 Hz


def arc(t: float, v: float = 0.3, w: float = 0.5) -> tuple[float, float, float]:
    """Wheel odometry's pose at `t` on a constant arc from the origin."""
    theta = w * t
    return v / w * math.sin(theta), v / w * (1 - math.cos(theta)), theta


def events(seconds: float, *, gyro_late_s: float = 0.0) -> list[tuple[float, str, float]]:
    """(arrival time, kind, sample time) of a drive, the gyro's samples arriving `gyro_late_s` late."""
    out = [(i * PERIOD_S, "odom", i * PERIOD_S) for i in range(int(seconds / PERIOD_S) + 1)]
    out += [(i * GYRO_S + gyro_late_s, "gyro", i * GYRO_S) for i in range(1, int(seconds / GYRO_S) + 1)]
    return sorted(out)


def feed(fusion: Fusion, stream: list[tuple[float, str, float]], w: float = 0.5) -> list[object]:
    out: list[object] = []
    for _, kind, t in stream:
        if kind == "odom":
            out += fusion.add_odometry(t, arc(t, w=w), 0.3, w)
        else:
            out += fusion.add_gyro(t, w)
    return out


def test_samples_are_fused_in_time_order_whichever_thread_delivers_first() -> None:
    in_order, late = Fusion(0.0, gyro_variance=1e-6), Fusion(0.0, gyro_variance=1e-6)
    feed(in_order, events(3.0))
    feed(late, events(3.0, gyro_late_s=0.05))  # each gyro sample behind the odometry steps it covers
    feed(late, [(9.0, "gyro", 3.0 + GYRO_S)])  # the last steps wait for the gyro to pass them
    a, b = in_order.ekf.pose, late.ekf.pose
    assert (b.x_m, b.y_m, b.theta_rad) == pytest.approx((a.x_m, a.y_m, a.theta_rad), abs=1e-9)
    assert b.theta_rad == pytest.approx(1.5, abs=1e-3) and not b.slipping


def test_odometry_waits_for_the_gyro_but_not_for_long() -> None:
    fusion = Fusion(0.0, gyro_variance=1e-6)
    assert len(fusion.add_odometry(0.02, arc(0.02), 0.3, 0.5)) == 1  # no IMU yet: at once
    fusion.add_gyro(0.021, 0.5)  # then the IMU goes silent
    fused = 1
    for i in range(2, 40):
        newest = PERIOD_S * i
        for step in fusion.add_odometry(newest, arc(newest), 0.3, 0.5):
            fused += 1
            assert MAX_LAG_S - PERIOD_S < newest - step.time_s <= MAX_LAG_S + PERIOD_S + 1e-9  # a period: rounding
    assert fused >= 39 - MAX_LAG_S / PERIOD_S - 2 and fusion.pending <= MAX_LAG_S / PERIOD_S + 1


def test_twist_and_covariances() -> None:
    fusion = Fusion(0.0, gyro_variance=2e-6)
    out = feed(fusion, events(2.0))
    first, last = out[0], out[-1]
    assert last.linear_m_s == 0.3 and last.angular_rad_s == pytest.approx(0.5, abs=0.01)  # type: ignore[attr-defined]
    assert last.angular_variance > 2e-6  # type: ignore[attr-defined]  # the gyro's, and its bias estimate's
    for step in (first, last):
        cov = np.array(step.covariance).reshape(3, 3)  # type: ignore[attr-defined]
        assert np.all(np.linalg.eigvalsh(cov) > 0)
    c0, c1 = (np.array(s.covariance).reshape(3, 3) for s in (first, last))  # type: ignore[attr-defined]
    assert c1[0, 0] + c1[1, 1] > 3 * (c0[0, 0] + c0[1, 1])  # grows with the distance driven
    six = convert.fused_pose_covariance(last.covariance, (0.1, 0.2, 0.3, 0.4, 0.5, 0.6))  # type: ignore[attr-defined]
    assert six[0] == c1[0, 0] and six[1] == c1[0, 1] and six[5] == c1[0, 2] and six[35] == c1[2, 2]
    assert (six[14], six[21], six[28]) == (0.3, 0.4, 0.5)  # z, roll, pitch from the parameter


def test_set_pose_skips_samples_integrated_before_it_and_starts_at_the_first_after() -> None:
    fusion = Fusion(0.0, gyro_variance=1e-6)
    feed(fusion, events(1.0))
    flushed = fusion.set_pose(1.0, 2.0, 0.5)
    assert fusion.pending == 0 and isinstance(flushed, list)
    assert fusion.ekf.pose.covariance[0, 0] < 1e-5  # known again
    fusion.add_gyro(1.005, 0.5)
    assert fusion.add_odometry(1.02, arc(1.02), 0.3, 0.5) == []  # integrated before the reset: skipped
    fusion.add_gyro(1.03, 0.5)
    fusion.add_gyro(1.045, 0.5)
    (anchor,) = fusion.add_odometry(1.04, (1.0, 2.0, 0.5), 0.3, 0.5)  # the odometry's first sample there
    assert (anchor.x_m, anchor.y_m, anchor.theta_rad) == (1.0, 2.0, 0.5)
    fusion.add_gyro(1.06, 0.5)
    (step,) = fusion.add_odometry(1.06, (1.006, 2.0033, 0.51), 0.3, 0.5)
    assert math.hypot(step.x_m - 1.0, step.y_m - 2.0) < 0.01 and step.theta_rad == pytest.approx(0.51, abs=1e-3)
    assert not step.slipping  # the gyro's turn before the new start was dropped with the counts


def test_pose_gate_opens_after_resync_samples() -> None:
    gate = PoseGate()
    assert gate.accept((5.0, 0.0, 0.0))
    gate.expect(0.0, 0.0, 0.0)
    assert not any(gate.accept((5.0, 0.0, 0.0)) for _ in range(RESYNC_SAMPLES))
    assert gate.accept((5.0, 0.0, 0.0)) and gate.accept((6.0, 0.0, 0.0))


def test_imu_time_maps_the_ports_clock_to_the_robots() -> None:
    assert imu_time(10.0, port_now=10.5, robot_now=110.5) == 110.0


def test_feedback_and_imu_samples_are_on_the_same_clock_against_the_emulator() -> None:
    with Robot.connect("emu://diffdrive-tb6612?clock=virtual&imu=jy901&seed=2") as robot:
        imu = Jy901.open(robot.transport.endpoints["imu"])
        try:
            sample = imu.read(timeout_s=1.0)
            assert imu.port.clock() == robot.now()  # one virtual clock: no offset to map
            feedback = robot.wait_feedback()
            assert abs(sample.t - feedback.host_time_s) < 1.0
            assert imu_time(sample.t, imu.port.clock(), robot.now()) == sample.t
        finally:
            imu.close()


def test_tf_from_fused_needs_an_imu() -> None:
    check_tf_from(BridgeParams.defaults(tf_from="fused", imu_url="/dev/ttyUSB1"), has_imu=True)
    check_tf_from(BridgeParams.defaults(), has_imu=False)
    with pytest.raises(CommandRangeError, match=re.escape("parameter tf_from")) as error:
        check_tf_from(BridgeParams.defaults(tf_from="fused"), has_imu=False)
    assert "imu_url" in str(error.value) and "imu=jy901" in str(error.value)


def test_bad_fusion_inputs_are_refused_by_name() -> None:
    with pytest.raises(CommandRangeError, match="gyro_variance"):
        Fusion(0.0, gyro_variance=-1.0)
    with pytest.raises(CommandRangeError, match="rate_rad_s"):
        Fusion(0.0, gyro_variance=0.0).add_gyro(1.0, math.nan)
    with pytest.raises(CommandRangeError, match="x_m"):
        Fusion(0.0, gyro_variance=0.0).set_pose(math.inf, 0.0, 0.0)


def test_emu_options_with_an_imu() -> None:
    from roverlink.ros2.fusion import imu_expected

    with_imu = SimpleNamespace(sensors=SimpleNamespace(imu="jy901"))
    assert imu_expected(BridgeParams.defaults(), with_imu)
    assert not imu_expected(BridgeParams.defaults(), SimpleNamespace(sensors=None))
    assert imu_expected(BridgeParams.defaults(imu_url="/dev/ttyUSB1"), None)
