"""`Driving`, the part of a Robot that drives: body twist, wheel speeds, Ackermann speed and steering, stop.

Each call checks its arguments, turns them into one setpoint within the robot's limits
(host_sdk.limits, from the board's live configuration) and sends it; the session keeps it live
(repeated) for `hold_s`, then goes quiet so the board's watchdog acts if the program stops.
"""

from __future__ import annotations

import math
from collections.abc import Callable

from host_sdk import checks
from host_sdk.errors import UnsupportedError
from host_sdk.kinematics import MAX_RATE
from host_sdk.limits import DriveLimits, Setpoint
from host_sdk.robot.link import Link
from host_sdk.session import RobotConfig
from protocol.generated.enums import Capability

_ROBOT_KINDS = {
    Capability.DIFF_DRIVE: "a differential-drive robot",
    Capability.ACKERMANN: "an Ackermann (steered) robot",
}


def _speed(name: str, value: object) -> float:
    return checks.number(name, value, -MAX_RATE, MAX_RATE, unit="m/s")


class Driving:
    """Owns the default `clamp` and the limits built from the board's configuration; `rearm` is
    the robot's arm(), called before a command when auto_rearm is on and the board wants it."""

    def __init__(self, link: Link, rearm: Callable[[], None], clamp: bool) -> None:
        self._link = link
        self._rearm = rearm
        self.clamp = checks.flag("clamp", clamp)
        self._limits: tuple[RobotConfig | None, DriveLimits | None] = (None, None)

    # == driving ===================================================================================
    def drive(
        self, linear_m_s: float, angular_rad_s: float, *, clamp: bool | None = None, hold_s: float | None = None
    ) -> None:
        """Drive with a body twist: forward speed (m/s) and turn rate (rad/s, counter-clockwise).

        Differential drive: wheel speeds from the track width. Ackermann: the steering angle that
        gives this turn rate at this speed. Beyond the limits raises CommandRangeError, or with
        clamp=True scales both wheels down together (the path's curvature is kept).
        The command stays live for `hold_s` (default command_timeout_s): renew it before then.
        """
        linear = _speed("linear_m_s", linear_m_s)
        angular = checks.number("angular_rad_s", angular_rad_s, -MAX_RATE, MAX_RATE, unit="rad/s")

        def setpoint(limits: DriveLimits, clamp: bool) -> Setpoint:
            kin = self._link.session.kinematics
            if kin is None:
                raise UnsupportedError(
                    "drive() needs the robot's kinematics: pass profile=... or kinematics=... to Robot.connect, "
                    "or use set_wheel_speeds()/drive_ackermann()"
                )
            return limits.twist_setpoint(kin, linear, angular, clamp)

        self._command(setpoint, clamp, hold_s)

    def set_wheel_speeds(
        self, left_m_s: float, right_m_s: float, *, clamp: bool | None = None, hold_s: float | None = None
    ) -> None:
        """Differential drive: each wheel's rim speed (m/s, positive forward)."""
        left, right = _speed("left_m_s", left_m_s), _speed("right_m_s", right_m_s)

        def setpoint(limits: DriveLimits, clamp: bool) -> Setpoint:
            self._require(Capability.DIFF_DRIVE, "set_wheel_speeds", "drive_ackermann() or drive()")
            return limits.wheel_setpoint(left, right, clamp)

        self._command(setpoint, clamp, hold_s)

    def drive_ackermann(
        self, speed_m_s: float, steering_rad: float, *, clamp: bool | None = None, hold_s: float | None = None
    ) -> None:
        """Ackermann: rear-axle speed (m/s) and front-wheel angle (rad, positive turns left)."""
        speed = _speed("speed_m_s", speed_m_s)
        steer = checks.number("steering_rad", steering_rad, -math.pi, math.pi, unit="rad")

        def setpoint(limits: DriveLimits, clamp: bool) -> Setpoint:
            self._require(Capability.ACKERMANN, "drive_ackermann", "set_wheel_speeds() or drive()")
            return limits.ackermann_setpoint(speed, steer, clamp)

        self._command(setpoint, clamp, hold_s)

    def stop(self) -> None:
        """Zero speed (steering centred). Does nothing when the robot is not armed: it is stopped already."""
        link = self._link
        with link.lock:
            link.runner.check()
            seq = link.session.stop(link.clock())
            if seq is not None:
                link.last_command_seq = seq
                link.runner.flush()

    def _command(
        self, setpoint: Callable[[DriveLimits, bool], Setpoint], clamp: bool | None, hold_s: float | None
    ) -> None:
        """Check the call, build its setpoint within the limits, send it and keep it live for `hold_s`."""
        clamp_ = self.clamp if clamp is None else checks.flag("clamp", clamp)
        hold = checks.optional(checks.seconds, "hold_s", hold_s)
        link = self._link
        runner, s = link.runner, link.session
        with link.lock:
            runner.check()
            msg = setpoint(self._drive_limits(), clamp_)
            error = s.take_command_error()
            if error is not None:
                raise error
        if link.options.auto_rearm and s.wants_rearm():
            self._rearm()
        with link.lock:
            runner.check()
            error = s.take_command_error()
            if error is not None:
                raise error
            if not s.armed:
                raise s.not_armed_error()
            link.last_command_seq = s.command(msg, link.clock(), hold)
            runner.flush()

    def _drive_limits(self) -> DriveLimits:
        """The limits of the current configuration (lock held), built once per configuration."""
        config = self._link.session.config
        assert config is not None
        cached_for, limits = self._limits
        if cached_for is not config or limits is None:
            limits = DriveLimits.of(config)
            self._limits = (config, limits)
        return limits

    def _require(self, capability: Capability, what: str, instead: str) -> None:
        identity = self._link.session.identity
        if identity is not None and not identity.capabilities & capability:
            raise UnsupportedError(
                f"{what}() needs {_ROBOT_KINDS.get(capability, capability.name)}; "
                f"{identity.robot_name or 'this robot'} is not one: use {instead}",
                capability,
            )
