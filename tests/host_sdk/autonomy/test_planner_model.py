"""The follow planner's motion model against the board it drives: the planner assumes the speed
ramps up at the board's accel limit, which the emulated wheels follow (a planner that assumes a
slower start than the car's sends it farther than it predicts, into what it meant to stop short of),
and it assumes slowing no faster than the wheels slow (it errs towards the car running on)."""

from __future__ import annotations

import numpy as np
import pytest

from host_sdk import Robot
from host_sdk.autonomy import FollowPilot
from host_sdk.geometry import robot_geometry

SPEED_M_S = 0.35


def _rate(robot: Robot, command: float, seconds: float, lo: float, hi: float) -> float:
    """m/s^2 while the odometry's speed goes from `lo` to `hi` (m/s) after `command` is sent."""
    t0, samples = robot.now(), []
    while robot.now() - t0 < seconds:
        robot.drive(command, 0.0)
        robot.wait_feedback()
        samples.append((robot.now() - t0, robot.odometry.pose.linear_m_s))
    rising = hi > lo
    t_lo = next(t for t, v in samples if (v >= lo if rising else v <= lo))
    t_hi = next(t for t, v in samples if (v >= hi if rising else v <= hi))
    return abs(hi - lo) / (t_hi - t_lo)


@pytest.mark.parametrize("profile", ["diffdrive-tb6612", "diffdrive-bts7960", "picar"])
def test_the_planner_assumes_the_ramp_the_wheels_follow(profile: str) -> None:
    with Robot.connect(f"emu://{profile}?clock=virtual&world=empty") as robot:
        pilot = FollowPilot.for_robot(robot_geometry(robot), np.full((40, 20, 3), 200, np.uint8))
        assumed = pilot.follower.planner.params.accel_m_s2
        robot.arm()
        up = _rate(robot, SPEED_M_S, 1.0, 0.2 * SPEED_M_S, 0.8 * SPEED_M_S)
        down = _rate(robot, 0.0, 1.0, 0.8 * SPEED_M_S, 0.2 * SPEED_M_S)
        robot.stop()
    assert assumed == pytest.approx(up, rel=0.2), f"planner {assumed} m/s^2, wheels speed up at {up:.2f}"
    assert assumed <= down, f"planner slows at {assumed} m/s^2, wheels at {down:.2f}: it would stop short"
