"""Connect, arm, drive, feedback and odometry against the in-process emulator (virtual clock), for
every reference robot in each feedback mode it supports.

Odometry is checked against the emulator's ground truth after ~1.5 m of straight line and arcs:
differential drives within 10 mm and 0.5 deg, the Ackermann PiCar within 20 mm and 2 deg (its
servo slews between 15-degree steps, and the host integrates the commanded angle).
"""

from __future__ import annotations

import math
from typing import Any

import pytest

from host_sdk import Robot, enums

CASES = [
    ("diffdrive-tb6612", "stream", 0.010, 0.5),
    ("diffdrive-tb6612", "lockstep", 0.010, 0.5),
    ("diffdrive-bts7960", "stream", 0.010, 0.5),
    ("diffdrive-bts7960", "lockstep", 0.010, 0.5),
    ("picar", "stream", 0.020, 2.0),
]


def truth_in_start_frame(start: Any, now: Any) -> tuple[float, float, float]:
    dx, dy = now.x_m - start.x_m, now.y_m - start.y_m
    c, s = math.cos(-start.theta_rad), math.sin(-start.theta_rad)
    return c * dx - s * dy, s * dx + c * dy, now.theta_rad - start.theta_rad


def drive_pattern(robot: Robot) -> None:
    ackermann = robot.identity.can(enums.Capability.ACKERMANN)
    for seconds, v, w in [(1.5, 0.4, 0.0), (1.5, 0.3, 0.6), (1.5, 0.3, -0.5), (1.0, 0.0, 1.0), (0.5, 0.0, 0.0)]:
        end = robot.now() + seconds
        while robot.now() < end:
            if ackermann:
                robot.drive_ackermann(v if w != 1.0 else 0.2, math.copysign(0.26, w) if w else 0.0)
            else:
                robot.drive(v, w)
            sample = robot.wait_feedback(0.5)
            assert sample.armed and sample.pose is not None
    robot.sleep(0.3)


@pytest.mark.parametrize(("profile", "mode", "tol_m", "tol_deg"), CASES)
def test_drive_and_odometry_match_ground_truth(profile: str, mode: str, tol_m: float, tol_deg: float) -> None:
    with Robot.connect(f"emu://{profile}?clock=virtual&seed=1", mode=mode) as robot:  # type: ignore[arg-type]
        emu = robot.emulator
        assert robot.mode == mode
        robot.arm()
        start = emu.truth.plant
        robot.odometry.reset()
        drive_pattern(robot)
        x, y, theta = truth_in_start_frame(start, emu.truth.plant)
        pose = robot.odometry.pose
        assert emu.truth.plant.distance_m > 1.2
        assert math.hypot(pose.x_m - x, pose.y_m - y) <= tol_m
        assert abs(math.degrees(pose.theta_rad - theta)) <= tol_deg
        fb = robot.feedback
        assert fb is not None
        assert fb.encoder_counts == tuple(emu.truth.firmware.encoder_counts)
        assert fb.host_time_s <= fb.received_s  # MCU time mapped to host time, before the frame arrived
        stats = robot.stats
        assert stats.crc_errors == 0 and stats.seq_gaps == 0 and stats.rtt is not None
        assert stats.clock_offset_us is not None


def test_lost_feedback_loses_no_counts() -> None:
    """Drops, bit flips and a cut: odometry is integrated from cumulative counts, so it still ends
    where the truth is, and the SDK's counts equal the firmware's."""
    url = "emu://diffdrive-tb6612?clock=virtual&seed=2&faults=drop.m2h%3D2e-3,bitflip.m2h%3D2e-4"
    with Robot.connect(url) as robot:
        emu = robot.emulator
        robot.arm()
        start = emu.truth.plant
        robot.odometry.reset()
        end = robot.now() + 3.0
        while robot.now() < end:
            robot.drive(0.3, 0.4)
            robot.sleep(0.02)
        robot.stop()
        robot.sleep(0.5)
        assert robot.stats.seq_gaps > 0 and robot.stats.crc_errors + robot.stats.cobs_errors > 0
        x, y, theta = truth_in_start_frame(start, emu.truth.plant)
        pose = robot.odometry.pose
        assert math.hypot(pose.x_m - x, pose.y_m - y) <= 0.01
        assert abs(pose.theta_rad - theta) <= math.radians(0.5)
        assert robot.feedback is not None
        assert robot.feedback.encoder_counts == tuple(emu.truth.firmware.encoder_counts)
