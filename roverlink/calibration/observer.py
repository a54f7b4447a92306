"""Who looks at the robot during calibration: a person with a tape measure, or the emulator.

The procedure never trusts the robot's own sensors for what it calibrates; it asks an
`Observer`. `PersonObserver` asks the questions a careful builder answers (did the wheel turn
forward, how many turns, how far, how many degrees); `EmulatorObserver` answers them from the
emulator's ground truth, as a perfect tape measure would (`emu://` URLs).

The procedure calls `mark()` before each motion (the person marks the tyre and the floor) and
asks about the motion since the mark afterwards.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, Protocol

from host_sdk import Robot
from roverlink.emulated import emulator_of
from roverlink.interactive import Prompter


class Observer(Protocol):
    def place(self, on_stand: bool) -> None:
        """Put the robot on a stand (wheels free) or on the floor, and confirm."""

    def mark(self) -> None:
        """Mark the wheels and the robot's place on the floor."""

    def turned_forward(self, wheel: int) -> bool:
        """Did the wheel turn so that it would drive the robot forward?"""

    def revolutions(self, wheel: int) -> float:
        """Turns of the wheel since the mark (forward positive)."""

    def displacement(self) -> tuple[float, float]:
        """Where the robot's reference point is now, in metres, in the frame of the mark:
        (forward, to the left)."""

    def rotation_deg(self) -> float:
        """How far the robot turned since the mark, degrees, counter-clockwise positive."""


class PersonObserver:
    """Asks a person through a `Prompter`."""

    def __init__(self, prompter: Prompter) -> None:
        self.prompter = prompter

    def place(self, on_stand: bool) -> None:
        where = (
            "on a stand, wheels off the ground and free to spin"
            if on_stand
            else "on a flat floor with about 2.5 m of clear space ahead (and room to turn in place)"
        )
        if not self.prompter.confirm(f"Put the robot {where}. Ready?", default=True):
            raise KeyboardInterrupt

    def mark(self) -> None:
        self.prompter.say(
            "Mark each tyre and the frame beside it (tape), and the floor under the robot's axle centre "
            "and straight ahead of it."
        )
        if not self.prompter.confirm("Marked?", default=True):
            raise KeyboardInterrupt

    def turned_forward(self, wheel: int) -> bool:
        return self.prompter.confirm(f"Did wheel {wheel} turn in the direction that drives the robot forward?")

    def revolutions(self, wheel: int) -> float:
        return self.prompter.number(f"How many turns did wheel {wheel} make (count the mark; e.g. 9.3)")

    def displacement(self) -> tuple[float, float]:
        forward = self.prompter.number("How far forward is the axle centre now, along the start line (m)")
        left = self.prompter.number("How far to the left of the start line (m, right negative)", 0.0)
        return forward, left

    def rotation_deg(self) -> float:
        return self.prompter.number("How many degrees did the robot turn, counter-clockwise (e.g. 352 or 371)")


@dataclass
class _Mark:
    x: float
    y: float
    theta: float
    wheels: tuple[float, ...]


class EmulatorObserver:
    """The emulator's ground truth, read like a tape measure (and it lifts the robot itself)."""

    def __init__(self, robot: Robot) -> None:
        self.robot = robot
        self._mark: _Mark | None = None

    def _truth(self) -> Any:
        with emulator_of(self.robot) as emu:
            return emu.truth.plant

    def place(self, on_stand: bool) -> None:
        with emulator_of(self.robot) as emu:
            emu.set_stand(on_stand)

    def mark(self) -> None:
        p = self._truth()
        self._mark = _Mark(p.x_m, p.y_m, p.theta_rad, tuple(w.angle_rad for w in p.wheels))

    def _since(self) -> tuple[Any, _Mark]:
        if self._mark is None:
            raise RuntimeError("mark() first")
        return self._truth(), self._mark

    def turned_forward(self, wheel: int) -> bool:
        p, m = self._since()
        return bool(p.wheels[wheel].angle_rad > m.wheels[wheel])

    def revolutions(self, wheel: int) -> float:
        p, m = self._since()
        return float((p.wheels[wheel].angle_rad - m.wheels[wheel]) / (2 * math.pi))

    def displacement(self) -> tuple[float, float]:
        p, m = self._since()
        dx, dy = p.x_m - m.x, p.y_m - m.y
        c, s = math.cos(m.theta), math.sin(m.theta)
        return dx * c + dy * s, -dx * s + dy * c

    def rotation_deg(self) -> float:
        p, m = self._since()
        return math.degrees(p.theta_rad - m.theta)


def observer_for(robot: Robot, prompter: Prompter) -> Observer:
    """The emulator's truth for an emu:// robot, else the person (an IMU, when there is one, is
    added by roverlink.calibration.imu.ImuObserver)."""
    return EmulatorObserver(robot) if robot.emulator is not None else PersonObserver(prompter)
