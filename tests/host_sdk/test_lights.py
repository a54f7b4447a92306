"""Robot.set_lights and Robot.lights on the emulator (virtual clock): each mode as the board reports
it and as its LEDs show it, the argument checks, a robot without turn signals, a new session, the
robot file's power-up mode, and the text form the ROS 2 bridge reads."""

from __future__ import annotations

import asyncio
from pathlib import Path
from typing import Any

import pytest

from host_sdk import (
    ArgumentTypeError,
    AsyncRobot,
    CommandRangeError,
    Robot,
    RobotMismatchError,
    SessionResetError,
    UnsupportedError,
    lights,
)
from host_sdk.lights import Lights, LightsStatus
from host_sdk.testing import emulated_robot
from protocol.generated.enums import Capability, LightsMode
from protocol.robotfile import reference_path

TB6612 = "diffdrive-tb6612"


def leds(robot: Robot) -> int:
    """The LED pins' mask as the emulated board shows it now (ground truth)."""
    emulator: Any = robot.emulator
    states = emulator.truth.plant.leds
    return sum(
        1 << i for i, name in enumerate(("front_left", "front_right", "rear_left", "rear_right")) if states[name]
    )


def shown(robot: Robot, seconds: float = 0.66, drive: tuple[float, float] | None = None) -> set[int]:
    """Every LED mask shown over `seconds` (one blink period by default), sampled every tick, while
    driving at `drive` (linear, angular) when given."""
    seen = set()
    for _ in range(round(seconds / 0.01)):
        if drive is not None:
            robot.drive(*drive)
        robot.sleep(0.01)
        seen.add(leds(robot))
    return seen


def test_each_mode_is_reported_and_shown() -> None:
    with emulated_robot(profile=TB6612) as robot:
        state = robot.lights()
        assert state.mode is LightsMode.AUTO and state.steady == state.slow == state.fast == Lights(0)
        assert shown(robot) == {3, 12}  # not armed: front and rear alternate
        state = robot.set_lights("manual", steady="front_left", slow="rear_left", fast=Lights.REAR_RIGHT)
        assert (state.mode, int(state.steady), int(state.slow), int(state.fast)) == (LightsMode.MANUAL, 1, 4, 8)
        assert shown(robot) == {1, 5, 9, 13}  # steady, plus each mix of the 1.5 Hz and 3 Hz blinks
        assert robot.lights().lit == Lights(leds(robot))  # reported as shown
        assert robot.set_lights(steady="all").lit == Lights(15)
        dark = robot.set_lights("off")
        assert dark.mode is LightsMode.OFF and dark.lit == Lights(0)  # read back after the tick that applied it
        assert shown(robot) == {0}
        lit = robot.set_lights("manual", steady="front")
        assert lit.lit == Lights.FRONT_LEFT | Lights.FRONT_RIGHT == Lights(leds(robot))
        robot.set_lights(slow="left")  # lamps without a mode: MANUAL
        assert shown(robot) == {0, 5}
        assert robot.set_lights(LightsMode.AUTO).describe().startswith("auto lit=")
        assert shown(robot) == {3, 12}


def test_manual_lamps_hold_while_driving_and_failsafe_blinks_all_four() -> None:
    with emulated_robot(profile=TB6612, armed=True) as robot:
        assert shown(robot, drive=(0.2, 1.0)) == {0, 5}  # AUTO, a left turn: the left pair
        robot.set_lights(steady="all")
        assert shown(robot, drive=(0.2, 1.0)) == {15}
        robot.set_lights("off")
        emulator: Any = robot.emulator
        emulator.cut_link()  # silence: the watchdog latches FAILSAFE
        emulator.advance(0.4)
        seen = set()
        for _ in range(66):
            emulator.advance(0.01)
            seen.add(leds(robot))
        assert seen == {0, 15}  # all four at 3 Hz, the host's OFF notwithstanding


def test_a_new_session_brings_back_the_power_up_mode() -> None:
    with emulated_robot(profile=TB6612) as robot:
        robot.set_lights("off")
        emulator: Any = robot.emulator
        emulator.reset_mcu()
        while emulator.truth.mcu.phase != "running":
            robot.sleep(0.001)
        robot.sleep(0.1)  # the SDK notices the new boot_id and opens the new session
        with pytest.raises(SessionResetError):  # the first call after a reset reports it
            robot.lights()
        assert robot.lights().mode is LightsMode.AUTO


@pytest.mark.parametrize(
    ("call", "argument"),
    [
        (lambda r: r.set_lights(), "mode"),
        (lambda r: r.set_lights("blink"), "mode"),
        (lambda r: r.set_lights("off", slow="left"), "slow"),
        (lambda r: r.set_lights(steady=16), "steady"),
        (lambda r: r.set_lights(fast="middle"), "fast"),
    ],
)
def test_bad_arguments_are_refused_naming_them(call: Any, argument: str) -> None:
    with emulated_robot(profile=TB6612) as robot:
        with pytest.raises(CommandRangeError) as err:
            call(robot)
        assert err.value.argument == argument
        assert robot.lights().mode is LightsMode.AUTO  # nothing was sent


def test_a_lamp_of_the_wrong_type_is_a_type_error() -> None:
    for bad in (1.5, {"left": 1}, [1, 2]):
        with pytest.raises(ArgumentTypeError):
            lights.request(steady=bad)


def test_a_robot_without_turn_signals_refuses_naming_the_capability() -> None:
    with emulated_robot(profile="picar") as robot:
        for call in (robot.lights, lambda: robot.set_lights("off")):
            with pytest.raises(UnsupportedError) as err:
                call()
            assert err.value.capability is Capability.TURN_SIGNALS and "TURN_SIGNALS" in str(err.value)


def test_async_robot_has_both() -> None:
    async def main(robot: Robot) -> LightsStatus:
        a = AsyncRobot(robot)
        await a.set_lights(fast="front")
        return await a.lights()

    with emulated_robot(profile=TB6612) as robot:
        state = asyncio.run(main(robot))
        assert state.mode is LightsMode.MANUAL and int(state.fast) == 3


def test_the_robot_files_power_up_mode_is_the_boards(tmp_path: Path) -> None:
    text = reference_path(TB6612).read_text(encoding="utf-8")
    assert '\nmode = "auto"' in text
    path = tmp_path / "dark.toml"
    path.write_text(text.replace('\nmode = "auto"', '\nmode = "off"'), encoding="utf-8")
    with Robot.connect(f"emu://?robot={path}&clock=virtual") as robot:
        assert robot.lights().mode is LightsMode.OFF
        assert shown(robot) == {0}
    # The file against a board built with another power-up mode: another build, named.
    url = f"emu://{TB6612}?clock=virtual"
    with pytest.raises(RobotMismatchError) as refused:
        Robot.connect(url, robot=path)
    assert f"{path}: lights.mode = off but the board on {url} has power-up lights mode = AUTO" in str(refused.value)
    with Robot.connect(url, robot=path, allow_mismatch=True) as robot:
        assert [m.key for m in robot.mismatches] == ["lights.mode"]


def test_the_text_form_reads_back() -> None:
    assert lights.parse("auto").mode is LightsMode.AUTO
    m = lights.parse("manual steady=front_left,rear_right slow=- fast=rear")
    assert (m.mode, m.steady, m.slow, m.fast) == (LightsMode.MANUAL, 9, 0, 12)
    state = LightsStatus(LightsMode.MANUAL, Lights(9), Lights(0), Lights(12), Lights(13))
    assert (
        state.describe() == "manual steady=front_left,rear_right slow=- fast=rear lit=front_left,rear_left,rear_right"
    )
    back = lights.parse(state.describe())  # its reading of the lamps lit is not a request
    assert (back.steady, back.slow, back.fast) == (9, 0, 12)
    assert lights.parse("manual slow=5").slow == 5  # the bits, as a number
    for bad in ("", "manual glow=left", "dim", "manual slow=left slow=right", "manual slow=16"):
        with pytest.raises(CommandRangeError):
            lights.parse(bad)
