"""Gains that make a wheel oscillate with its drive saturated are warned about, not silently taken
(a user's kp=ki=500 swung the speed 0.21..0.35 m/s round 0.3 with only a SATURATED bit to show)."""

from __future__ import annotations

import warnings

import pytest

from host_sdk import Robot
from host_sdk.robot.gains_watch import PidGainsWarning

URL = "emu://diffdrive-tb6612?clock=virtual&seed=4"


def drive_for(robot: Robot, seconds: float, speed: float = 0.3) -> None:
    end = robot.now() + seconds
    while robot.now() < end:
        robot.drive(speed, 0.0)
        robot.sleep(0.05)


def test_gains_that_make_the_wheels_oscillate_are_warned_about() -> None:
    with Robot.connect(URL) as robot:
        robot.arm()
        drive_for(robot, 1.0)
        with pytest.warns(PidGainsWarning) as caught:
            robot.set_pid(kp=500, ki=500)
            drive_for(robot, 2.5)
    text = str(caught[0].message)
    assert "kp=500, ki=500" in text and "oscillate" in text and "saturated" in text and "roverlink tune" in text


def test_the_reference_gains_and_a_standing_robot_are_not_warned_about() -> None:
    with Robot.connect(URL) as robot, warnings.catch_warnings():
        warnings.simplefilter("error", PidGainsWarning)
        robot.arm()
        robot.set_pid(kp=500, ki=500)  # too high, but the robot stands: nothing to judge
        drive_for(robot, 1.0, speed=0.0)
        robot.set_pid(kp=1.0, ki=6.0)  # the profile's gains, which replace the watch of the others
        drive_for(robot, 2.5)
