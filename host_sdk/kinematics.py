"""Robot kinematics: body twist <-> wheel commands, and encoder counts -> travelled arc.

Two models, both exact for motion at constant curvature:

- DiffDrive: two independently driven wheels `track_m` apart.
- Ackermann: a bicycle model with the rear (driven, encoded) axle `wheelbase_m` behind the steered
  front axle.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from host_sdk.errors import RoverLinkError


class KinematicsError(RoverLinkError, ValueError):
    """A kinematic request that cannot be met (e.g. a turn tighter than the steering allows)."""


def _positive(name: str, value: float) -> None:
    if not (math.isfinite(value) and value > 0):
        raise KinematicsError(f"{name} = {value!r} is not allowed: a finite number > 0")


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
        _positive("wheel_radius_m", self.wheel_radius_m)
        _positive("track_m", self.track_m)
        _positive("counts_per_rev", self.counts_per_rev)

    @property
    def metres_per_count(self) -> float:
        return 2 * math.pi * self.wheel_radius_m / self.counts_per_rev

    def wheel_speeds(self, linear_m_s: float, angular_rad_s: float, max_wheel_m_s: float) -> tuple[float, float]:
        """(left, right) for a body twist. If either wheel would exceed `max_wheel_m_s`, both are
        scaled down by the same factor, so the path's curvature is kept and only speed is lost."""
        half = angular_rad_s * self.track_m / 2
        left, right = linear_m_s - half, linear_m_s + half
        peak = max(abs(left), abs(right))
        if peak > max_wheel_m_s > 0:
            scale = max_wheel_m_s / peak
            left, right = left * scale, right * scale
        return left, right

    def twist(self, left_m_s: float, right_m_s: float) -> tuple[float, float]:
        """Body (linear m/s, angular rad/s) from wheel speeds."""
        return (left_m_s + right_m_s) / 2, (right_m_s - left_m_s) / self.track_m

    def arc(self, left_counts: int, right_counts: int) -> Arc:
        """The arc travelled for count increments of each wheel."""
        dl = left_counts * self.metres_per_count
        dr = right_counts * self.metres_per_count
        return Arc((dl + dr) / 2, (dr - dl) / self.track_m)


@dataclass(frozen=True, slots=True)
class Ackermann:
    """Bicycle model: steering angle positive to the left; the encoder measures the rear axle."""

    wheelbase_m: float
    wheel_radius_m: float
    counts_per_rev: int
    max_steering_rad: float = math.radians(25)

    def __post_init__(self) -> None:
        _positive("wheelbase_m", self.wheelbase_m)
        _positive("wheel_radius_m", self.wheel_radius_m)
        _positive("counts_per_rev", self.counts_per_rev)
        _positive("max_steering_rad", self.max_steering_rad)

    @property
    def metres_per_count(self) -> float:
        return 2 * math.pi * self.wheel_radius_m / self.counts_per_rev

    def steering_for(self, linear_m_s: float, angular_rad_s: float) -> float:
        """Steering angle that turns at `angular_rad_s` while moving at `linear_m_s`.

        Raises KinematicsError for a turn in place or tighter than max_steering_rad allows."""
        if angular_rad_s == 0:
            return 0.0
        if linear_m_s == 0:
            raise KinematicsError("an Ackermann robot cannot turn in place: angular_rad_s needs linear_m_s != 0")
        steer = math.atan(angular_rad_s * self.wheelbase_m / linear_m_s)
        if abs(steer) > self.max_steering_rad + 1e-12:
            radius = abs(linear_m_s / angular_rad_s)
            raise KinematicsError(
                f"turn radius {radius:.3f} m needs steering {steer:.3f} rad; allowed -{self.max_steering_rad:.3f}.."
                f"{self.max_steering_rad:.3f} rad (minimum radius {self.min_turn_radius_m:.3f} m)"
            )
        return steer

    @property
    def min_turn_radius_m(self) -> float:
        return self.wheelbase_m / math.tan(self.max_steering_rad)

    def arc(self, counts: int, steering_rad: float) -> Arc:
        distance = counts * self.metres_per_count
        return Arc(distance, distance * math.tan(steering_rad) / self.wheelbase_m)
