"""A board reset is one event, reported once (docs/sdk.md, "Resets"): as SessionResetError, by
whichever call meets it first, the bootloader's silence before the new boot included; and the
odometry says what the reboot cost it.

Against the emulator on its virtual clock, with the reset injected mid-drive (`faults=reset@T`:
the reset pin, then the bootloader's 1.5 s of silence, then a new boot).
"""

from __future__ import annotations

import math
import re
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any

import pytest

from host_sdk import (
    FeedbackTimeoutError,
    NotArmedError,
    Robot,
    RoverLinkError,
    SessionResetError,
)
from host_sdk.session import OdometryGap

ROOT = Path(__file__).resolve().parents[2]
URL = "emu://diffdrive-tb6612?clock=virtual&seed=3"


def connect(faults: str = "") -> Robot:
    return Robot.connect(URL + (f"&faults={faults}" if faults else ""))


@pytest.fixture
def robot() -> Iterator[Robot]:
    with connect() as robot:
        yield robot


class Recording:
    """The robot, with every exception its calls raise recorded (the program sees them as usual)."""

    def __init__(self, robot: Robot) -> None:
        self._robot = robot
        self.raised: list[type[BaseException]] = []

    def __getattr__(self, name: str) -> Any:
        value = getattr(self._robot, name)
        if not callable(value):
            return value

        def call(*args: Any, **kwargs: Any) -> Any:
            try:
                return value(*args, **kwargs)
            except Exception as exc:
                self.raised.append(type(exc))
                raise

        return call


@pytest.mark.parametrize("fault", ["reset@2", "dtr@2"])
def test_a_drive_loop_sees_one_session_reset_error_across_a_reset(fault: str) -> None:
    with connect(fault) as robot:
        seen: list[type[BaseException]] = []
        robot.arm()
        for _ in range(400):  # 8 s of 50 Hz FEEDBACK, the reset at 2 s
            try:
                robot.drive(0.3, 0.0)
                robot.wait_feedback()
            except RoverLinkError as exc:
                seen.append(type(exc))
                robot.arm()  # whatever it was, carry on driving
        assert seen == [SessionResetError]
        assert robot.stats.resets_detected == 1 and robot.state == "armed"


def documented_recovery_pattern() -> str:
    """The code block of docs/sdk.md's "Resets" section."""
    text = (ROOT / "docs" / "sdk.md").read_text()
    section = text[text.index("## Resets\n") :]
    section = section[: section.index("\n## ", 1)]
    blocks = re.findall(r"```python\n(.*?)```", section, re.S)
    assert len(blocks) == 1, "the Resets section shows one recovery pattern"
    return str(blocks[0])


def test_the_documented_recovery_pattern_runs_as_written_across_a_reset(capsys: pytest.CaptureFixture[str]) -> None:
    with connect("reset@2") as robot:
        recording = Recording(robot)
        exec(compile(documented_recovery_pattern(), "docs/sdk.md", "exec"), {"robot": recording})
        assert recording.raised == [SessionResetError]  # no FeedbackTimeoutError, no FailsafeError
        assert robot.stats.resets_detected == 1 and robot.odometry.pose.x_m >= 1.5
        assert robot.emulator is not None and robot.emulator.truth.plant.x_m > 1.5
    assert capsys.readouterr().out.count("re-arming") == 1


def sleep_through_a_reset(robot: Robot) -> None:
    """Drive, reset the board, and let the new boot announce itself without any call meeting it."""
    robot.arm()
    robot.drive(0.2, 0.0)
    robot.sleep(0.2)
    assert robot.emulator is not None
    robot.emulator.reset_mcu()
    robot.sleep(2.0)
    assert robot.stats.resets_detected == 1


def _drive(robot: Robot) -> None:
    robot.drive(0.2, 0.0)


FIRST_CALLS: dict[str, Callable[[Robot], object]] = {
    "drive": _drive,
    "wait_feedback": lambda robot: robot.wait_feedback(),
    "arm": lambda robot: robot.arm(),
    "read_config": lambda robot: robot.read_config(),
}


@pytest.mark.parametrize("first", list(FIRST_CALLS))
def test_the_first_call_to_meet_a_reset_reports_it_and_no_later_call_does(robot: Robot, first: str) -> None:
    sleep_through_a_reset(robot)
    with pytest.raises(SessionResetError):
        FIRST_CALLS[first](robot)
    robot.wait_feedback()
    robot.read_config()
    with pytest.raises(NotArmedError):
        robot.drive(0.2, 0.0)  # not armed, and it says so, but the reset is not reported twice
    robot.arm()
    robot.drive(0.2, 0.0)


def test_stop_disarm_and_the_feedback_stream_leave_the_reset_to_the_next_call(robot: Robot) -> None:
    sleep_through_a_reset(robot)
    robot.stop()
    robot.disarm()
    next(robot.feedback_stream())
    with pytest.raises(SessionResetError):
        robot.drive(0.2, 0.0)


def test_wait_feedback_waits_out_a_silence_young_enough_to_be_a_reset_then_times_out(robot: Robot) -> None:
    robot.wait_feedback()
    assert robot.emulator is not None
    robot.emulator.cut_link("m2h")  # silence that never ends in a boot
    last = robot.now()
    with pytest.raises(FeedbackTimeoutError) as longer:
        robot.wait_feedback(timeout_s=0.5)
    assert robot.now() - last == pytest.approx(2.0, abs=0.05)  # reset_silence_s after the last frame
    # The message says how long it waited, not only the 0.5 s asked for.
    assert longer.value.waited_s == pytest.approx(2.0, abs=0.05) and "waited" in str(longer.value)
    began = robot.now()
    with pytest.raises(FeedbackTimeoutError) as own:
        robot.wait_feedback(timeout_s=0.5)  # silent too long for a reset: its own timeout
    assert robot.now() - began == pytest.approx(0.5, abs=0.01)
    assert own.value.waited_s == 0.5 and "waited" not in str(own.value)


def test_a_reset_while_moving_leaves_a_gap_and_its_uncertainty_on_the_pose() -> None:
    with connect("reset@2") as robot:
        gaps: list[OdometryGap] = []
        robot.on_odometry_gap(gaps.append)
        robot.arm()
        while robot.now() < 4.5:
            try:
                robot.drive(0.3, 0.6)
                robot.wait_feedback()
            except SessionResetError:
                robot.arm()
        pose = robot.odometry.pose
        assert robot.emulator is not None
        truth = robot.emulator.truth.plant
        # The reboot's counts are lost: the pose is short of the truth, and says by how much it may be.
        error_m = math.hypot(truth.x_m - pose.x_m, truth.y_m - pose.y_m)
        assert error_m > 0.02
        assert pose.gaps == 1 and error_m < pose.position_uncertainty_m < 0.6
        assert abs(truth.theta_rad - pose.theta_rad) < pose.heading_uncertainty_rad < 1.2
        [gap] = gaps
        assert 1.5 < gap.duration_s < 1.7  # the last FEEDBACK to the new boot: the bootloader's time
        assert gap.position_m == pose.position_uncertainty_m and gap.pose.gaps == 1
        robot.odometry.reset()
        assert robot.odometry.pose.gaps == 0 and robot.odometry.pose.position_uncertainty_m == 0.0
