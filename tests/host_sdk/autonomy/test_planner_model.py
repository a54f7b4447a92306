"""The follow planner's motion model against the board it drives: the speed ramp the planner assumes
is the one the emulated wheels follow. A planner that assumes a slower start than the car's sends it
farther than it predicts, into what it meant to stop short of."""

from __future__ import annotations

import numpy as np
import pytest

from host_sdk import Robot
from host_sdk.autonomy import FollowPilot
from host_sdk.geometry import robot_geometry

SPEED_M_S = 0.35


def measured_ramp(robot: Robot) -> float:
    """m/s^2 between 20 % and 80 % of a step from standing to SPEED_M_S (the odometry's speed)."""
    robot.arm()
    t0, samples = robot.now(), []
    while robot.now() - t0 < 1.0:
        robot.drive(SPEED_M_S, 0.0)
        robot.wait_feedback()
        samples.append((robot.now() - t0, robot.odometry.pose.linear_m_s))
    robot.stop()
    t20 = next(t for t, v in samples if v >= 0.2 * SPEED_M_S)
    t80 = next(t for t, v in samples if v >= 0.8 * SPEED_M_S)
    return 0.6 * SPEED_M_S / (t80 - t20)


@pytest.mark.parametrize("profile", ["diffdrive-tb6612", "diffdrive-bts7960", "picar"])
def test_the_planner_assumes_the_ramp_the_wheels_follow(profile: str) -> None:
    with Robot.connect(f"emu://{profile}?clock=virtual&world=empty") as robot:
        pilot = FollowPilot.for_robot(robot_geometry(robot), np.full((40, 20, 3), 200, np.uint8))
        assumed = pilot.follower.planner.params.accel_m_s2
        ramp = measured_ramp(robot)
    assert assumed == pytest.approx(ramp, rel=0.2), f"planner {assumed} m/s^2, wheels {ramp:.2f} m/s^2"
