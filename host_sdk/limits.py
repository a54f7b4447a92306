"""The robot's limits on drive commands, and the setpoint message each drive call becomes.

Every drive call of `Robot` (`drive`, `set_wheel_speeds`, `drive_ackermann`, for a differential
drive and an Ackermann robot alike) goes through `DriveLimits`, built from the board's live
configuration: the speed limit is `max_wheel_speed_mm_s`, the steering travel the servo's
configured `steering_min/max_cdeg` around its centre. Beyond a limit a call raises
`CommandRangeError` naming the argument, its value and the range, or, with `clamp=True`, is
brought inside: wheel speeds are scaled down together (the path's curvature is kept), a speed is
clamped, a steering angle is held at its stop. The kinematic models are host_sdk.kinematics'.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

from host_sdk.errors import CommandRangeError
from host_sdk.kinematics import Ackermann, DiffDrive
from host_sdk.profiles import steering_limits
from protocol.codec.message import FieldInfo
from protocol.generated.messages import SetAckermann, SetConfig, SetWheelSpeeds

_EPS = 1e-9  # a command exactly at the limit passes despite float rounding
_STEERING = next(f for f in SetAckermann.FIELDS if f.name == "steering_mrad")
_WHEEL = next(f for f in SetWheelSpeeds.FIELDS if f.name == "left_mm_s")
_SPEED = next(f for f in SetAckermann.FIELDS if f.name == "speed_mm_s")

Setpoint = SetWheelSpeeds | SetAckermann


def _wire(value: float, scale: float, info: FieldInfo) -> int:
    """A value in SI units as the integer the setpoint field carries, kept inside the field's range."""
    return max(int(info.lo), min(int(info.hi), round(value * scale)))


@dataclass(frozen=True, slots=True)
class DriveLimits:
    """What the board accepts: the speed limit (m/s) and the steering travel each way (rad, >= 0)."""

    max_speed_m_s: float
    steer_right_rad: float
    steer_left_rad: float

    @classmethod
    def of(cls, config: SetConfig) -> DriveLimits:
        right, left = steering_limits(config)
        return cls(config.max_wheel_speed_mm_s / 1000, right, left)

    # == the checks ===============================================================================
    def speed(self, name: str, value: float, clamp: bool) -> float:
        """One speed (m/s) within the limit."""
        limit = self.max_speed_m_s
        if -limit - _EPS <= value <= limit + _EPS:
            return value
        if clamp:
            return math.copysign(limit, value)
        raise CommandRangeError(name, value, self._speed_range(), "pass clamp=True to clamp instead")

    def wheels(
        self,
        left: float,
        right: float,
        clamp: bool,
        error: Callable[[], CommandRangeError] | None = None,
    ) -> tuple[float, float]:
        """Two wheel speeds within the limit; clamping scales both by one factor (same curvature).
        `error` builds the exception to raise instead of the default one naming the faster wheel."""
        limit = self.max_speed_m_s
        peak = max(abs(left), abs(right))
        if peak <= limit + _EPS:
            return left, right
        if clamp:
            return left * limit / peak, right * limit / peak
        if error is not None:
            raise error()
        name, value = ("left_m_s", left) if abs(left) >= abs(right) else ("right_m_s", right)
        raise CommandRangeError(name, value, self._speed_range(), "pass clamp=True to scale both wheels down together")

    def steering(
        self, name: str, value: float, clamp: bool, error: Callable[[], CommandRangeError] | None = None
    ) -> float:
        """A front-wheel angle (rad, positive left) within the servo's travel."""
        right, left = self.steer_right_rad, self.steer_left_rad
        if -right - _EPS <= value <= left + _EPS:
            return value
        if clamp:
            return max(-right, min(left, value))
        if error is not None:
            raise error()
        raise CommandRangeError(
            name,
            value,
            f"{-right:.3f}..{left:.3f} rad (the servo's configured travel)",
            "pass clamp=True to steer at the limit instead",
        )

    def _speed_range(self) -> str:
        limit = self.max_speed_m_s
        return f"-{limit:g}..{limit:g} m/s (max_wheel_speed_mm_s)"

    # == drive calls -> setpoints ====================================================================
    def wheel_setpoint(self, left: float, right: float, clamp: bool) -> SetWheelSpeeds:
        """`set_wheel_speeds(left, right)`."""
        left, right = self.wheels(left, right, clamp)
        return SetWheelSpeeds(_wire(left, 1000, _WHEEL), _wire(right, 1000, _WHEEL))

    def ackermann_setpoint(self, speed: float, steering: float, clamp: bool) -> SetAckermann:
        """`drive_ackermann(speed, steering)`."""
        speed = self.speed("speed_m_s", speed, clamp)
        steering = self.steering("steering_rad", steering, clamp)
        return SetAckermann(_wire(speed, 1000, _SPEED), _wire(steering, 1000, _STEERING))

    def twist_setpoint(self, kin: DiffDrive | Ackermann, linear: float, angular: float, clamp: bool) -> Setpoint:
        """`drive(linear, angular)`: wheel speeds from the track, or the steering angle for that turn."""
        if isinstance(kin, DiffDrive):
            left, right = kin.wheels(linear, angular)
            left, right = self.wheels(left, right, clamp, lambda: self._twist_error(kin, linear, angular))
            return SetWheelSpeeds(_wire(left, 1000, _WHEEL), _wire(right, 1000, _WHEEL))
        steer = kin.steering_angle(linear, angular)
        steer = self.steering("angular_rad_s", steer, clamp, lambda: self._turn_error(kin, linear, angular))
        speed = self.speed("linear_m_s", linear, clamp)
        return SetAckermann(_wire(speed, 1000, _SPEED), _wire(steer, 1000, _STEERING))

    def _twist_error(self, kin: DiffDrive, linear: float, angular: float) -> CommandRangeError:
        limit = self.max_speed_m_s
        hint = "pass clamp=True to scale both wheels down together (keeps the curvature)"
        if abs(linear) > limit:
            return CommandRangeError("linear_m_s", linear, self._speed_range(), hint)
        w_max = (limit - abs(linear)) * 2 / kin.track_m
        return CommandRangeError(
            "angular_rad_s",
            angular,
            f"-{w_max:.3f}..{w_max:.3f} rad/s at linear_m_s={linear:g} (a wheel would exceed {limit:g} m/s)",
            hint,
        )

    def _turn_error(self, kin: Ackermann, linear: float, angular: float) -> CommandRangeError:
        # The turn rates this speed allows with the steering at either stop.
        right, left = self.steer_right_rad, self.steer_left_rad
        stop = math.pi / 2 - 1e-6  # a servo travel of 90 degrees or more: no turn is too tight
        rates = (linear * math.tan(min(a, stop)) / kin.wheelbase_m for a in (left, -right))
        lo, hi = sorted(rates)
        return CommandRangeError(
            "angular_rad_s",
            angular,
            f"{lo:.3f}..{hi:.3f} rad/s at linear_m_s={linear:g} (steering {-right:.3f}..{left:.3f} rad)",
            "pass clamp=True to steer at the limit instead",
        )


def relimited(setpoint: Setpoint, max_speed_mm_s: int) -> Setpoint:
    """`setpoint` as the board re-limits a running one when max_wheel_speed_mm_s is lowered
    (docs/control.md 4.4): both wheel speeds scaled by max / peak, rounded half away from zero;
    an Ackermann speed clamped. The session repeats this one after a SET_CONFIG, so its repeats are
    never refused under the new limit. Unchanged when within the limit."""
    if isinstance(setpoint, SetAckermann):
        speed = max(-max_speed_mm_s, min(max_speed_mm_s, setpoint.speed_mm_s))
        return setpoint if speed == setpoint.speed_mm_s else SetAckermann(speed, setpoint.steering_mrad)
    peak = max(abs(setpoint.left_mm_s), abs(setpoint.right_mm_s))
    if peak <= max_speed_mm_s:
        return setpoint
    return SetWheelSpeeds(*(_div_round(v * max_speed_mm_s, peak) for v in (setpoint.left_mm_s, setpoint.right_mm_s)))


def _div_round(a: int, b: int) -> int:
    """a / b (b > 0) rounded half away from zero, in integers (as the firmware does it)."""
    return (a + b // 2) // b if a >= 0 else -((-a + b // 2) // b)
