"""`roverlink teleop` with a lidar keeps the avoider's protection: on the emulator's virtual clock the
PiCar, its forward key held (repeating, as a terminal sends it) towards a cylinder, stops short of
it; with Shift held too (Shift+Up) it drives into it; without a lidar the command says it is unprotected."""

from __future__ import annotations

from pathlib import Path

import pytest

from host_sdk import Robot
from host_sdk.autonomy import LidarGuard
from host_sdk.sensors import Lidar
from roverlink.commands.teleop import obstacle_guard
from roverlink.teleop import TeleopController
from tests.support.cylinder_ahead import CylinderAhead

CYLINDER = CylinderAhead(2.3)


def hold(robot: Robot, controller: TeleopController, key: str, seconds: float) -> None:
    """`key` repeating every 0.1 s, the controller ticking every 0.05 s, on the robot's clock."""
    end = robot.now() + seconds
    while robot.now() < end:
        controller.key(key)
        for _ in range(2):
            controller.tick()
            robot.sleep(0.05)


@pytest.fixture
def url(tmp_path: Path) -> str:
    world = CYLINDER.write(tmp_path)
    return f"emu://picar?clock=virtual&seed=3&world={world}&lidar=ydlidar-f4"


@pytest.mark.parametrize("override", [False, True])
def test_the_forward_key_stops_short_of_the_cylinder_unless_shift_is_held(url: str, override: bool) -> None:
    with Robot.connect(url) as robot, Lidar.open(robot.transport.endpoints["lidar"], "ydlidar-f4") as lidar:
        guard = LidarGuard(robot, lidar)
        guard.start()
        controller = TeleopController(robot, key_timeout_s=0.6, level=3, guard=guard)
        controller.arm()
        assert robot.armed, controller.message
        start = CYLINDER.gap(robot)
        hold(robot, controller, "shift+up" if override else "up", 6.0)
        collisions = robot.emulator.truth.world.collisions
        if override:
            assert collisions and collisions[0].kind == "cylinder", collisions
            assert controller.guarded is not None and "override held" in controller.status
        else:
            assert collisions == (), collisions
            assert start > 0.8 and 0.08 < CYLINDER.gap(robot) < 0.3, (start, CYLINDER.gap(robot))
            assert robot.armed and abs(robot.feedback.wheel_speeds_m_s[0]) < 0.01
            assert "stopped for an obstacle" in controller.status and "ahead" in controller.status
            hold(robot, controller, "down", 1.0)  # backing away is allowed
            assert CYLINDER.gap(robot) > 0.3


def test_without_a_lidar_teleop_says_it_drives_unprotected(capsys: pytest.CaptureFixture[str]) -> None:
    import argparse

    args = argparse.Namespace(no_sensors=False, lidar=None, lidar_model=None)
    with Robot.connect("emu://picar?clock=virtual&world=empty") as robot, obstacle_guard(args, robot) as guard:
        assert guard is None
    assert "no lidar" in capsys.readouterr().err
