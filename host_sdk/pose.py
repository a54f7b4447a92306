"""The robot's pose: `Pose`, and `Pose2D`, a place.

`Pose` is where the robot is, how fast it moves (measured) and when: what `robot.odometry.pose`
and a pose source give, so a follower need not re-estimate speed from pose differences. `Pose2D`
is a place alone, the bare (x m, y m, theta rad) tuple the numpy-heavy code computes with.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

Pose2D = tuple[float, float, float]
"""x, y (m), theta (rad) in the odometry frame (REP-103: x forward, y left, theta CCW)."""


@dataclass(frozen=True, slots=True)
class Pose:
    """Where the robot is (the odometry frame) and how fast it moves (measured, not commanded).

    `robot.odometry.pose` gives the wheels' (with the board's time and the gaps a reset left); a
    pose source (host_sdk.fusion.PoseSource) gives the fused or the wheels' at a host time, which
    is what a pilot takes."""

    x_m: float
    y_m: float
    theta_rad: float
    """Heading, unwrapped (keeps counting past +-pi so turns can be totalled)."""
    linear_m_s: float = 0.0
    angular_rad_s: float = 0.0
    mcu_time_us: int = 0
    """Unwrapped MCU time of the latest wheel sample (0: before the first, or not from the wheels)."""
    gaps: int = 0
    """Times counts were lost (a board reset: what the wheels turned while it rebooted is not
    counted) since the pose was last set."""
    position_uncertainty_m: float = 0.0
    """How far the position may be off because of those gaps: the speed at the last sample before
    each gap times the time without counts, summed (an estimate, not a bound)."""
    heading_uncertainty_rad: float = 0.0
    """The same for the heading: the turn rate at the last sample times the time without counts."""
    time_s: float = 0.0
    """The session's clock (robot.now()) the pose holds for: when the board sampled the wheels,
    on the host's clock; 0.0 from an `Odometry` fed by hand (it knows the MCU time only)."""

    @property
    def heading_rad(self) -> float:
        """Heading wrapped to (-pi, pi]."""
        return math.atan2(math.sin(self.theta_rad), math.cos(self.theta_rad))

    @property
    def xyt(self) -> Pose2D:
        return self.x_m, self.y_m, self.theta_rad

    def moved_to(self, time_s: float, xyt: Pose2D) -> Pose:
        """The same speeds at another time and place (an interpolated pose)."""
        return Pose(xyt[0], xyt[1], xyt[2], self.linear_m_s, self.angular_rad_s, time_s=time_s)


PoseAt = Callable[[float], Pose]
"""The robot's pose at any recent time (`PoseSource.at`): what de-skews a lidar revolution."""


def interpolate(a: Pose2D, b: Pose2D, f: float) -> Pose2D:
    """The pose a fraction `f` of the way from `a` to `b` (the turn taken the short way round)."""
    turn = math.remainder(b[2] - a[2], 2 * math.pi)
    return a[0] + f * (b[0] - a[0]), a[1] + f * (b[1] - a[1]), a[2] + f * turn
