"""Drive commands as values, and timed sequences of them, for tests that generate what to drive.

Each command is one of `Robot`'s drive calls with its arguments; `send(robot)` makes the call.
A `Step` is a command and how long to keep it up; `run_steps(robot, steps)` drives a sequence,
renewing each command so the watchdog never acts, and stops at the end. Hypothesis strategies
that generate them (within a robot's limits, or beyond them) are `drive_commands` and
`command_sequences` in host_sdk.testing.strategies; this module does not need hypothesis.

    >>> from host_sdk.testing import Step, Twist, emulated_robot, run_steps
    >>> with emulated_robot(armed=True) as robot:
    ...     run_steps(robot, [Step(Twist(0.3, 0.0), 1.0), Step(Twist(0.0, 1.0), 0.5)])
    ...     round(robot.odometry.pose.x_m, 1)
    0.3
"""

from __future__ import annotations

import math
from collections.abc import Iterable
from dataclasses import dataclass
from typing import NamedTuple

from host_sdk.robot import Robot

__all__ = ["AckermannCommand", "DriveCommand", "Step", "Twist", "WheelSpeeds", "run_steps"]

RENEW_S = 0.05
"""How often `run_steps` repeats the command of a step (well inside any watchdog's half period)."""


@dataclass(frozen=True, slots=True)
class Twist:
    """`robot.drive(linear_m_s, angular_rad_s)`: a body twist (any kinematics)."""

    linear_m_s: float
    angular_rad_s: float

    def send(self, robot: Robot, *, clamp: bool | None = None) -> None:
        robot.drive(self.linear_m_s, self.angular_rad_s, clamp=clamp)


@dataclass(frozen=True, slots=True)
class WheelSpeeds:
    """`robot.set_wheel_speeds(left_m_s, right_m_s)`: a differential drive's rim speeds."""

    left_m_s: float
    right_m_s: float

    def send(self, robot: Robot, *, clamp: bool | None = None) -> None:
        robot.set_wheel_speeds(self.left_m_s, self.right_m_s, clamp=clamp)


@dataclass(frozen=True, slots=True)
class AckermannCommand:
    """`robot.drive_ackermann(speed_m_s, steering_rad)`: a steered robot's speed and wheel angle."""

    speed_m_s: float
    steering_rad: float

    def send(self, robot: Robot, *, clamp: bool | None = None) -> None:
        robot.drive_ackermann(self.speed_m_s, self.steering_rad, clamp=clamp)


DriveCommand = Twist | WheelSpeeds | AckermannCommand


class Step(NamedTuple):
    """A command and how long (s) to keep it up."""

    command: DriveCommand
    duration_s: float


def run_steps(robot: Robot, steps: Iterable[Step], *, clamp: bool | None = None, renew_s: float = RENEW_S) -> None:
    """Drive `steps` in order (each command renewed every `renew_s`), then `robot.stop()`.

    The robot must be armed. On the virtual clock this takes no wall time: `robot.sleep` runs the
    emulator. `clamp` is passed to every call (None: the robot's default)."""
    for command, duration_s in steps:
        renewals = max(1, math.ceil(duration_s / renew_s - 1e-9))
        for _ in range(renewals):
            command.send(robot, clamp=clamp)
            robot.sleep(duration_s / renewals)
    robot.stop()
