"""The console's teleop keeps the avoider's protection, closed loop on the emulator's virtual clock:
a forward key held towards a cylinder stops the car short of it; with the override held it drives
into it, and the ENCODER_FAULT that follows is explained with the obstacle the lidar sees."""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path

import pytest

from host_sdk import Robot
from host_sdk.autonomy import ControlLoop
from host_sdk.console.hub import Drive, Hub
from host_sdk.console.pilot import ConsolePilot
from host_sdk.enums import FailsafeReason
from host_sdk.geometry import robot_geometry
from host_sdk.sensors import CameraSource, Lidar
from tests.support.cylinder_ahead import CylinderAhead

pytest.importorskip("cv2")
FORWARD_M_S = 0.27
"""What the page's W key asks for (0.6 of the console's 0.45 m/s)."""
CYLINDER = CylinderAhead(2.0)
WORDS = "a wheel did not turn under effort: blocked, or its encoder unplugged"


@pytest.fixture
def robot(tmp_path: Path) -> Iterator[Robot]:
    world = CYLINDER.write(tmp_path)
    url = f"emu://diffdrive-tb6612?clock=virtual&seed=1&world={world}&lidar=rplidar-a1&camera=320x240"
    with Robot.connect(url, clamp=True) as robot:
        yield robot


def hold_forward(robot: Robot, *, override: bool, seconds: float) -> tuple[ConsolePilot, list[str]]:
    """The page's forward key held for `seconds` (or until a failsafe): a drive command every period,
    as the page sends them; what the guard said of each."""
    hub = Hub(command_lifetime_s=robot.watchdog_s, clock=robot.now)
    pilot = ConsolePilot(hub, robot, robot_geometry(robot))
    lidar = Lidar.open(robot.transport.endpoints["lidar"], "rplidar-a1")
    camera = CameraSource(robot.transport.endpoints["camera"])
    guard_texts: list[str] = []
    robot.arm()
    with ControlLoop(robot, pilot, lidar=lidar, camera=camera, rearm=False) as loop:
        while robot.now() - loop.started_s < seconds:
            hub.post(drive=Drive(FORWARD_M_S, 0.0, hub.clock(), override=override))
            loop.step()
            if pilot.guarded is not None:
                guard_texts.append(pilot.guarded.text)
            if robot.failsafe is not None:  # (this step showed it on the page)
                break
            loop.wait()
    lidar.close()
    camera.close()
    return pilot, guard_texts


def test_a_held_forward_key_stops_short_of_the_cylinder(robot: Robot) -> None:
    start = CYLINDER.gap(robot)
    pilot, texts = hold_forward(robot, override=False, seconds=5.0)
    truth = robot.emulator.truth.world
    assert truth.collisions == () and not truth.in_contact, truth.collisions
    assert robot.armed and robot.failsafe is None
    assert start > 0.6 and 0.1 < CYLINDER.gap(robot) < 0.2, (start, CYLINDER.gap(robot))  # stopped short
    assert abs(robot.feedback.wheel_speeds_m_s[0]) < 0.01
    assert any(t.startswith("slowing for an obstacle") for t in texts)
    assert "stopped for an obstacle" in texts[-1] and "ahead" in texts[-1], texts[-1]
    _, _, _, state = pilot.hub.latest()
    assert state["guard"]["state"] == "stopped" and state["mode"] == "teleop"


def test_with_the_override_held_it_reaches_the_cylinder_and_the_bump_is_explained(robot: Robot) -> None:
    pilot, texts = hold_forward(robot, override=True, seconds=6.0)
    truth = robot.emulator.truth.world
    assert truth.collisions and truth.collisions[0].kind == "cylinder", truth.collisions
    assert all(t.startswith("override held") for t in texts) and any("not stopping for" in t for t in texts)
    assert robot.failsafe is FailsafeReason.ENCODER_FAULT  # pushing on, the wheels stalled
    _, _, _, state = pilot.hub.latest()
    assert state["failsafe"] == "ENCODER_FAULT"
    text = state["failsafe_text"]
    assert text.startswith(f"ENCODER_FAULT: {WORDS}; the lidar sees an obstacle "), text
    assert "ahead of the body, inside the footprint's 0.08 m margin" in text, text
