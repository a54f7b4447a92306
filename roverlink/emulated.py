"""The emulator behind an `emu://` robot, for the tools that let it play the user.

On hardware a person puts the robot on a stand or reads a tape measure; on `emu://` the tools
ask the emulator instead (its ground truth). On the wall clock the SDK's I/O thread drives the
emulator, so it is held still (the transport's lock) while it is read or changed.
"""

from __future__ import annotations

import contextlib
from collections.abc import Iterator
from typing import Any

from host_sdk import PROFILES, Robot


@contextlib.contextmanager
def emulator_of(robot: Robot) -> Iterator[Any]:
    """The robot's `emulator.Emulator` (held still for the block), or None on hardware."""
    emu = robot.emulator
    if emu is None:
        yield None
        return
    locked = getattr(robot.transport, "locked", None)
    if robot.virtual_clock or locked is None:
        yield emu
        return
    with locked() as held:
        yield held


def emu_robot(url: str | None) -> str | None:
    """The reference robot an `emu://` URL runs (`emu://` alone: the emulator's default); None for
    another URL, one naming a robot file, or one the emulator refuses (connecting says why)."""
    from emulator.transport.inprocess import parse_emu_url  # noqa: PLC0415 (only emu:// URLs need it)

    if not url or not url.startswith("emu://"):
        return None
    try:
        options = parse_emu_url(url)
    except ValueError:
        return None
    return options.profile if not options.robot and options.profile in PROFILES else None


def place_on_stand(robot: Robot, on: bool) -> bool:
    """Lift an emulated robot onto its stand (or put it down); False on hardware (the user does it)."""
    with emulator_of(robot) as emu:
        if emu is None:
            return False
        emu.set_stand(on)
        return True


def on_stand(robot: Robot) -> bool | None:
    """Whether an emulated robot is on its stand (None on hardware: only the user knows)."""
    with emulator_of(robot) as emu:
        return None if emu is None else bool(emu.truth.plant.on_stand)


def first_collision(robot: Robot) -> str | None:
    """What an emulated robot in a world ran into first, as text (None: nothing, or hardware)."""
    with emulator_of(robot) as emu:
        world = emu.truth.world if emu is not None else None
    if world is None or not world.collisions:
        return None
    c = world.collisions[0]
    return f"{c.obstacle} at ({c.x_m:.2f}, {c.y_m:.2f}) m, {c.time_us / 1e6:.1f} s in, at {c.speed_m_s:.2f} m/s"
