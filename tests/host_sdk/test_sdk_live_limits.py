"""Limits lowered while driving, through the SDK on `emu://`.

docs/control.md 4.4: a lowered max_wheel_speed_mm_s re-limits the running setpoint at the board's
next tick (the session repeats the re-limited one).
"""

from __future__ import annotations

from typing import Any

from emulator.firmware.statemachine import SessionState
from host_sdk import Robot


def drive_for(robot: Robot, seconds: float, linear: float, angular: float = 0.0) -> None:
    end = robot.now() + seconds
    while robot.now() < end:
        robot.drive(linear, angular)
        robot.sleep(0.02)


def test_lowering_the_speed_limit_while_driving_clamps_the_running_setpoint(
    roverlink_robot: Robot, roverlink_emulator: Any
) -> None:
    # Measured on the code before: the board kept 500 mm/s, refused the session's next repeat of
    # it (OUT_OF_RANGE), the session went quiet, the watchdog failed safe 0.3 s later, and the next
    # valid drive raised that stale NackError.
    roverlink_robot.arm()
    roverlink_robot.drive(0.5, 0.2, hold_s=5.0)  # held live by the session's repeats, not by this test
    roverlink_robot.sleep(1.0)
    before = roverlink_emulator.truth.firmware.targets_mm_s
    assert before == (480.0, 520.0)
    roverlink_robot.set_config(max_wheel_speed_mm_s=200)
    fw = roverlink_emulator.truth.firmware
    # Both wheels scaled by one factor (the curvature is kept): 480 * 200 / 520 = 184.6.
    assert fw.targets_mm_s == (185.0, 200.0)
    roverlink_robot.sleep(1.0)  # several repeats of the running setpoint, all accepted
    fw = roverlink_emulator.truth.firmware
    assert fw.state is SessionState.ARMED
    assert fw.targets_mm_s == (185.0, 200.0) and fw.ramped_mm_s == (185.0, 200.0)
    assert roverlink_robot.armed
    roverlink_robot.drive(0.1, 0.0)
    roverlink_robot.sleep(0.05)
    assert roverlink_emulator.truth.firmware.targets_mm_s == (100.0, 100.0)
