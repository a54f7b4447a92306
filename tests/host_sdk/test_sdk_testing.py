"""host_sdk.testing: the pytest plugin's marker (sensors, bad keys), `emulated_robot` inside
Hypothesis tests, the drive-command strategies against the emulator, and every `>>>` example in
host_sdk run as a doctest."""

from __future__ import annotations

import doctest
import importlib
import math
from pathlib import Path

import pytest
from hypothesis import given, settings

from host_sdk import Robot
from host_sdk.emulated import EmulatorHandle
from host_sdk.errors import CommandRangeError
from host_sdk.limits import DriveLimits
from host_sdk.profiles import PROFILES
from host_sdk.testing import Step, emulated_robot, run_steps
from host_sdk.testing import strategies as rls

pytest_plugins = ["pytester"]

ROOT = Path(__file__).resolve().parents[2]


# == the marker =====================================================================================
@pytest.mark.roverlink(profile="picar", imu="jy901", world="empty", camera=True)
def test_the_marker_attaches_sensors(roverlink_robot: Robot, roverlink_emulator: EmulatorHandle) -> None:
    assert set(roverlink_robot.transport.endpoints) >= {"imu", "camera"}
    assert "imu=jy901" in roverlink_robot.url and "world=empty" in roverlink_robot.url
    assert roverlink_emulator.truth.world is not None


def test_a_bad_marker_key_is_named_with_the_allowed_ones(pytester: pytest.Pytester) -> None:
    pytester.makepyfile(
        """
        import pytest

        @pytest.mark.roverlink(imux="jy901")
        def test_it(roverlink_robot):
            pass
        """
    )
    result = pytester.runpytest_inprocess("-p", "no:cacheprovider", "-p", "no:asyncio")
    result.assert_outcomes(errors=1)
    out = result.stdout.str()
    assert "unknown option 'imux'" in out
    assert "TypeError: Robot.connect()" not in out
    assert "During handling of the above exception" not in out  # one message, not the TypeError too
    for allowed in ("profile", "imu", "lidar", "camera", "world", "watchdog_s"):
        assert allowed in out


def test_emulated_robot_refuses_an_unknown_option() -> None:
    with pytest.raises(TypeError, match=r"unknown option 'lidr'.*lidar"), emulated_robot(lidr="rplidar-a1"):
        pass


# == Hypothesis: one emulated robot per example ======================================================
@settings(max_examples=12)
@given(steps=rls.command_sequences("diffdrive-tb6612", max_steps=4))
def test_odometry_agrees_with_the_truth_for_any_drive(steps: list[Step]) -> None:
    with emulated_robot(armed=True) as robot:
        run_steps(robot, steps)
        robot.sleep(0.3)  # stopped: the last FEEDBACK counts every edge
        emu = robot.emulator
        assert emu is not None
        plant, pose = emu.truth.plant, robot.odometry.pose
    tolerance = 0.01 + 0.02 * plant.distance_m
    assert math.hypot(plant.x_m - pose.x_m, plant.y_m - pose.y_m) <= tolerance
    # The tyres scrub as the robot turns (the plant's slip): wheel odometry's heading is off by a
    # fraction of a per cent of the turn (0.2 % in a 5 rad spin at full speed), as on a real car.
    assert abs(plant.theta_rad - pose.theta_rad) <= tolerance + 0.005 * abs(plant.theta_rad)


def test_the_documented_property_test_runs_as_a_users_own(pytester: pytest.Pytester) -> None:
    """docs/sdk.md's "Property tests" block as a test file of a user's project, in a process of its
    own: with Hypothesis' defaults, not this suite's profile (which has no deadline)."""
    section = (ROOT / "docs" / "sdk.md").read_text(encoding="utf-8").split("### Property tests (Hypothesis)")[1]
    pytester.makepyfile(section.split("```python\n")[1].split("```")[0])
    result = pytester.runpytest_subprocess("-p", "no:cacheprovider", "-p", "no:asyncio")
    result.assert_outcomes(passed=1)


@pytest.mark.parametrize("profile", ["diffdrive-tb6612", "picar"])
def test_commands_beyond_the_limits_are_refused_or_clamped(profile: str) -> None:
    limit_mm_s = DriveLimits.of(PROFILES[profile].config).max_speed_m_s * 1000

    @settings(max_examples=10)
    @given(rls.command_sequences(profile, commands=rls.drive_commands(profile, in_range=False), max_steps=3))
    def check(steps: list[Step]) -> None:
        with emulated_robot(profile=profile, armed=True) as robot:
            emu = robot.emulator
            assert emu is not None
            for command, duration_s in steps:
                with pytest.raises(CommandRangeError):
                    command.send(robot)
                run_steps(robot, [Step(command, duration_s)], clamp=True)
                firmware = emu.truth.firmware
                assert firmware is not None
                assert all(abs(t) <= limit_mm_s + 1 for t in firmware.targets_mm_s)

    check()


@pytest.mark.parametrize("profile", list(PROFILES))
def test_commands_within_the_limits_are_accepted_as_they_are(profile: str) -> None:
    @settings(max_examples=10)
    @given(rls.drive_commands(profile))
    def check(command: rls.DriveCommand) -> None:
        with emulated_robot(profile=profile, armed=True) as robot:
            command.send(robot, clamp=False)

    check()


# == every example in host_sdk runs =================================================================
def _modules_with_examples() -> list[str]:
    found = []
    for path in sorted((ROOT / "host_sdk").rglob("*.py")):
        if ">>>" in path.read_text(encoding="utf-8"):
            module = ".".join(path.relative_to(ROOT).with_suffix("").parts)
            found.append(module.removesuffix(".__init__"))
    return found


@pytest.mark.parametrize("module", _modules_with_examples())
def test_the_docstring_examples_run(module: str) -> None:
    result = doctest.testmod(importlib.import_module(module), optionflags=doctest.ELLIPSIS, verbose=False)
    assert result.attempted > 0
    assert result.failed == 0, f"{module}: {result.failed} of {result.attempted} examples failed (output above)"


def test_the_testing_helpers_all_have_examples() -> None:
    modules = set(_modules_with_examples())
    for name in ("commands", "emulated_robot", "strategies"):
        assert f"host_sdk.testing.{name}" in modules
