"""cmd_vel -> Robot.drive(): freshness, the timeout policy, lockstep pacing and refusal logging.

No ROS here: the node calls `command()` for each cmd_vel and `tick()` from a timer, with the host
clock; the tests drive it against the emulator on its virtual clock.

- Each cmd_vel is sent at once, live for `cmd_vel_timeout` after it arrived: that is the SDK's
  command expiry, so if this process stops calling (a hung executor), the SDK stops feeding the
  board's watchdog and the board fails safe by itself.
- After the timeout, `on_timeout="stop"` holds zero speed (the robot stays armed, as ros2_control's
  diff_drive_controller does); `"release"` sends nothing, and the board's watchdog fails it safe.
- In lockstep mode the board answers each setpoint with one FEEDBACK. The robot is connected
  `paced`: the SDK's I/O thread sends the live setpoint once per period on the board's tick grid
  (a cmd_vel waits at most one period), so odometry comes evenly at the node's rate whatever the
  rate of cmd_vel and however late the executor runs (a timer of the executor's missed ticks under
  load, and sent two setpoints into one board tick near the ticks). With `on_timeout="stop"` a
  command outlives its timeout by LOCKSTEP_OVERLAP_S, until `tick()` puts the zero-speed hold in
  its place: a gap between the two would be periods without FEEDBACK.
"""

from __future__ import annotations

import re
from collections.abc import Callable
from dataclasses import dataclass
from typing import Protocol

from host_sdk import CommandRangeError, NackError, NotArmedError, RoverLinkError, SessionResetError

ZERO_HOLD_S = 0.5
"""How long one zero-speed hold lives; re-sent every ZERO_RESEND_S while idle."""
ZERO_RESEND_S = 0.2
LOCKSTEP_OVERLAP_S = 0.1
"""Lockstep, on_timeout="stop": how long a command stays live past its timeout (two of the node's
20 Hz ticks) so the zero hold replaces it without a gap."""


class Drivable(Protocol):
    """The part of host_sdk.Robot the driver uses."""

    @property
    def armed(self) -> bool: ...

    def drive(
        self, linear_m_s: float, angular_rad_s: float, *, clamp: bool | None = None, hold_s: float | None = None
    ) -> None: ...


_SDK_ARM = re.compile(r"call robot\.arm\(\)(?: first| when ready| to drive again)?")


def arm_hint(service: str) -> str:
    """What to do instead of the SDK's `robot.arm()`, on the graph: the node's ~/arm service."""
    return f"call the {service} service (ros2 service call {service} std_srvs/srv/Trigger)"


def in_ros_words(text: str, arm_service: str) -> str:
    """An SDK message with its `call robot.arm() ...` advice naming the node's `arm_service` (its
    fully qualified name) instead: a ROS user arms through the service, not the Python API."""
    return _SDK_ARM.sub(arm_hint(arm_service), text) if arm_service else text


class RefusalLog:
    """Logs refused commands once per burst: the first refusal, a change of reason, and how many
    were refused when commands are accepted again (a 20 Hz teleop would otherwise flood the log).
    With `arm_service` (e.g. /roverlink/arm) the SDK's advice to call robot.arm() names it instead."""

    def __init__(self, warn: Callable[[str], None], info: Callable[[str], None], arm_service: str = "") -> None:
        self._warn = warn
        self._info = info
        self.arm_service = arm_service
        self._reason: str | None = None
        self._burst = 0
        self.total = 0
        self.last = ""

    def refused(self, reason: str, text: str) -> None:
        text = in_ros_words(text, self.arm_service)
        self.total += 1
        self._burst += 1
        self.last = text
        if reason != self._reason:
            self._reason = reason
            self._warn(f"cmd_vel refused: {text} (logged once until commands are accepted again)")

    def accepted(self) -> None:
        if self._reason is not None:
            self._info(f"cmd_vel accepted again after {self._burst} refused")
        self._reason = None
        self._burst = 0


@dataclass(frozen=True, slots=True)
class Command:
    linear: float
    angular: float
    received_s: float


class Driver:
    def __init__(
        self,
        robot: Drivable,
        refusals: RefusalLog,
        *,
        timeout_s: float,
        on_timeout: str,
        lockstep: bool,
    ) -> None:
        self.robot = robot
        self.refusals = refusals
        self.timeout_s = timeout_s
        self.on_timeout = on_timeout
        self.lockstep = lockstep
        self.latest: Command | None = None
        self.hold_off: str | None = None
        """Why commands are refused regardless of the robot (e.g. disarmed through ~/disarm)."""
        self._zero_s = -1e9

    def command(self, linear: float, angular: float, now: float) -> None:
        """A cmd_vel arrived (host clock `now`)."""
        self.latest = Command(linear, angular, now)
        if self.hold_off is not None:
            self.refusals.refused("hold_off", self.hold_off)
        else:
            overlap = LOCKSTEP_OVERLAP_S if self.lockstep and self.on_timeout == "stop" else 0.0
            self._send(linear, angular, self.timeout_s + overlap)

    def clear(self) -> None:
        """Forget the current command (on arm and disarm: an old command never resumes)."""
        self.latest = None

    def fresh(self, now: float) -> bool:
        return self.latest is not None and now - self.latest.received_s < self.timeout_s

    def tick(self, now: float) -> None:
        """Run from a timer (20 Hz): after the timeout, the zero-speed hold."""
        if self.hold_off is not None or self.fresh(now):
            return
        if self.on_timeout != "stop" or not self.robot.armed:
            return  # never arm the robot (auto_arm) just to hold it still
        if now - self._zero_s >= ZERO_RESEND_S:
            self._zero_s = now
            self._send(0.0, 0.0, ZERO_HOLD_S, quiet=True)

    def _send(self, linear: float, angular: float, hold_s: float, quiet: bool = False) -> None:
        try:
            self.robot.drive(linear, angular, hold_s=max(hold_s, 1e-3))  # clamp: the robot's limit_policy
        except CommandRangeError as exc:
            self.refusals.refused("range", str(exc))
        except SessionResetError as exc:
            self.refusals.refused("reset", str(exc))
        except NotArmedError as exc:
            if not quiet:
                self.refusals.refused(f"not armed: {exc.state}", str(exc))
        except NackError as exc:
            self.refusals.refused(f"nack {exc.reason}", str(exc))
        except RoverLinkError as exc:  # transport loss: the connection thread reconnects
            if not quiet:
                self.refusals.refused(type(exc).__name__, str(exc))
        else:
            if not quiet:
                self.refusals.accepted()
