"""Robot kinematics: body twist <-> wheel commands, and encoder counts -> travelled arc.

Two models, both exact for motion at constant curvature:

- DiffDrive: two independently driven wheels `track_m` apart.
- Ackermann: a bicycle model with the rear (driven, encoded) axle `wheelbase_m` behind the steered
  front axle.

Every argument is checked (KinematicsError, a CommandRangeError, names it); the robot's limits on
top of these models (the board's speed limit, the servo's travel) are host_sdk.limits'.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from host_sdk import checks
from host_sdk.errors import KinematicsError
from protocol.generated.messages import SetConfig

__all__ = ["MAX_RATE", "Ackermann", "Arc", "DiffDrive", "KinematicsError"]

MAX_LENGTH_M = 100.0
"""Largest wheel radius, track or wheelbase accepted (a unit mistake beyond it, mm for m)."""
MAX_RATE = 1e6
"""Largest speed (m/s) or turn rate (rad/s) the models compute with; beyond it the maths overflows."""
MAX_COUNTS = 1 << 62
"""Largest count increment per interval (unwrapped counts stay far below it)."""
_CPR = next(f for f in SetConfig.FIELDS if f.name == "encoder_cpr")


def _length(name: str, value: object) -> float:
    return checks.number(name, value, 0.0, MAX_LENGTH_M, unit="m", lo_open=True, error=KinematicsError)


def _rate(name: str, value: object, unit: str) -> float:
    return checks.number(name, value, -MAX_RATE, MAX_RATE, unit=unit, error=KinematicsError)


def _counts(name: str, value: object) -> int:
    return checks.integer(name, value, -MAX_COUNTS, MAX_COUNTS, what="an integer count")


def _cpr(value: object) -> int:
    return checks.integer("counts_per_rev", value, int(_CPR.lo), int(_CPR.hi), what="counts per revolution")


@dataclass(frozen=True, slots=True)
class Arc:
    """Motion over one interval: distance along the path and heading change (radians, CCW)."""

    distance_m: float
    dtheta_rad: float


@dataclass(frozen=True, slots=True)
class DiffDrive:
    """Differential drive. Wheel speeds are rim speeds in m/s, positive forward."""

    wheel_radius_m: float
    track_m: float
    counts_per_rev: int

    def __post_init__(self) -> None:
        _length("wheel_radius_m", self.wheel_radius_m)
        _length("track_m", self.track_m)
        _cpr(self.counts_per_rev)

    @property
    def metres_per_count(self) -> float:
        return 2 * math.pi * self.wheel_radius_m / self.counts_per_rev

    def wheel_speeds(self, linear_m_s: float, angular_rad_s: float, max_wheel_m_s: float) -> tuple[float, float]:
        """(left, right) for a body twist. If either wheel would exceed `max_wheel_m_s`, both are
        scaled down by the same factor, so the path's curvature is kept and only speed is lost
        (0: no limit)."""
        v = _rate("linear_m_s", linear_m_s, "m/s")
        w = _rate("angular_rad_s", angular_rad_s, "rad/s")
        limit = checks.number("max_wheel_m_s", max_wheel_m_s, 0.0, MAX_RATE, unit="m/s (0: no limit)")
        left, right = self.wheels(v, w)
        peak = max(abs(left), abs(right))
        if peak > limit > 0:
            scale = limit / peak
            left, right = left * scale, right * scale
        return left, right

    def wheels(self, linear: float, angular: float) -> tuple[float, float]:
        """(left, right) for a body twist, unchecked and unscaled (callers have checked the numbers)."""
        half = angular * self.track_m / 2
        return linear - half, linear + half

    def twist(self, left_m_s: float, right_m_s: float) -> tuple[float, float]:
        """Body (linear m/s, angular rad/s) from wheel speeds."""
        left = _rate("left_m_s", left_m_s, "m/s")
        right = _rate("right_m_s", right_m_s, "m/s")
        return (left + right) / 2, (right - left) / self.track_m

    def arc(self, left_counts: int, right_counts: int) -> Arc:
        """The arc travelled for count increments of each wheel."""
        return self.arc_of(_counts("left_counts", left_counts), _counts("right_counts", right_counts))

    def arc_of(self, left_counts: int, right_counts: int) -> Arc:
        """`arc` without the checks."""
        return Arc(*self.motion(left_counts, right_counts))

    def motion(self, left_counts: int, right_counts: int) -> tuple[float, float]:
        """(distance, heading change) for count increments, unchecked: odometry's per-sample path."""
        mpc = self.metres_per_count
        dl = left_counts * mpc
        dr = right_counts * mpc
        return (dl + dr) / 2, (dr - dl) / self.track_m


@dataclass(frozen=True, slots=True)
class Ackermann:
    """Bicycle model: steering angle positive to the left; the encoder measures the rear axle."""

    wheelbase_m: float
    wheel_radius_m: float
    counts_per_rev: int
    max_steering_rad: float = math.radians(25)

    def __post_init__(self) -> None:
        _length("wheelbase_m", self.wheelbase_m)
        _length("wheel_radius_m", self.wheel_radius_m)
        _cpr(self.counts_per_rev)
        checks.number(
            "max_steering_rad",
            self.max_steering_rad,
            0.0,
            math.pi / 2,
            unit="rad",
            lo_open=True,
            hi_open=True,
            error=KinematicsError,
        )

    @property
    def metres_per_count(self) -> float:
        return 2 * math.pi * self.wheel_radius_m / self.counts_per_rev

    def steering_angle(self, linear_m_s: float, angular_rad_s: float) -> float:
        """The front-wheel angle that turns at `angular_rad_s` at `linear_m_s`, with no limit
        applied. Raises KinematicsError for a turn in place (no angle does it)."""
        v = _rate("linear_m_s", linear_m_s, "m/s")
        w = _rate("angular_rad_s", angular_rad_s, "rad/s")
        if w == 0:
            return 0.0
        if v == 0:
            raise KinematicsError(
                "angular_rad_s", w, "0 when linear_m_s is 0 (an Ackermann robot cannot turn in place)"
            )
        return math.atan(w * self.wheelbase_m / v)

    def turn_rate(self, linear_m_s: float, steering_rad: float) -> float:
        """The turn rate (rad/s) at `linear_m_s` with the front wheels at `steering_rad`."""
        v = _rate("linear_m_s", linear_m_s, "m/s")
        return v * math.tan(self._steering(steering_rad)) / self.wheelbase_m

    def steering_for(self, linear_m_s: float, angular_rad_s: float) -> float:
        """Steering angle that turns at `angular_rad_s` while moving at `linear_m_s`.

        Raises KinematicsError for a turn in place or tighter than max_steering_rad allows."""
        steer = self.steering_angle(linear_m_s, angular_rad_s)
        if abs(steer) > self.max_steering_rad + 1e-12:
            radius = abs(float(linear_m_s) / float(angular_rad_s))
            w_max = abs(float(linear_m_s)) / self.min_turn_radius_m
            raise KinematicsError(
                "angular_rad_s",
                angular_rad_s,
                f"-{w_max:.3f}..{w_max:.3f} rad/s at linear_m_s={float(linear_m_s):g}: turn radius {radius:.3f} m "
                f"needs steering {steer:.3f} rad; allowed -{self.max_steering_rad:.3f}..{self.max_steering_rad:.3f} "
                f"rad (minimum radius {self.min_turn_radius_m:.3f} m)",
            )
        return steer

    @property
    def min_turn_radius_m(self) -> float:
        return self.wheelbase_m / math.tan(self.max_steering_rad)

    def arc(self, counts: int, steering_rad: float) -> Arc:
        """The arc travelled for a count increment of the rear axle at a steering angle."""
        return self.arc_of(_counts("counts", counts), self._steering(steering_rad))

    def arc_of(self, counts: int, steering_rad: float) -> Arc:
        """`arc` without the checks."""
        return Arc(*self.motion(counts, steering_rad))

    def motion(self, counts: int, steering_rad: float) -> tuple[float, float]:
        """(distance, heading change) for a count increment, unchecked: odometry's per-sample path."""
        distance = counts * self.metres_per_count
        return distance, distance * math.tan(steering_rad) / self.wheelbase_m

    @staticmethod
    def _steering(value: object) -> float:
        return checks.number(
            "steering_rad",
            value,
            -math.pi / 2,
            math.pi / 2,
            unit="rad",
            lo_open=True,
            hi_open=True,
            error=KinematicsError,
        )
