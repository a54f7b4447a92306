"""Testing your own robot code against the emulator with the roverlink pytest plugin.

    pip install 'roverlink[dev]'                     # into a venv (a checkout: bash scripts/venv.sh dev)
    .venv/bin/python -m pytest examples/test_my_robot.py

The `roverlink_robot` fixture is a connected Robot on a virtual clock (time moves only when the
robot waits or sleeps, so these run in milliseconds and the same way every time);
`roverlink_emulator` gives ground truth and fault injection. Configure them with @pytest.mark.roverlink(...).
"""

from __future__ import annotations

import pytest

from host_sdk import Robot, SessionResetError


def drive_forward(robot: Robot, metres: float, speed: float = 0.3) -> None:
    """Your robot code: drive straight until odometry says `metres`."""
    start = robot.odometry.pose.x_m
    while robot.odometry.pose.x_m - start < metres:
        robot.drive(speed, 0.0)
        robot.wait_feedback()
    robot.stop()


def test_drive_forward_stops_near_the_goal(roverlink_robot, roverlink_emulator) -> None:
    roverlink_robot.arm()
    drive_forward(roverlink_robot, 0.5)
    roverlink_robot.sleep(0.5)
    assert roverlink_emulator.truth.plant.x_m == pytest.approx(0.5, abs=0.05)


@pytest.mark.roverlink(profile="picar", armed=True)
def test_the_picar_steers_left(roverlink_robot, roverlink_emulator) -> None:
    for _ in range(100):
        roverlink_robot.drive_ackermann(0.4, 0.4)
        roverlink_robot.sleep(0.02)
    assert roverlink_emulator.truth.plant.theta_rad > 0.3


@pytest.mark.roverlink(faults="drop=1e-3")
def test_my_code_notices_a_board_reset(roverlink_robot, roverlink_emulator) -> None:
    roverlink_robot.arm()
    roverlink_emulator.reset_mcu()
    with pytest.raises(SessionResetError):
        for _ in range(500):
            roverlink_robot.drive(0.2, 0.0)
            roverlink_robot.sleep(0.02)
