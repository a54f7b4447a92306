"""The robot's planar pose, as the perception and autonomy code pass it around.

`Pose2D` is the bare (x m, y m, theta rad) tuple the numpy-heavy code computes with; `RobotPose`
is the same pose with the time it holds for and the speeds the board measured then, which is what a
pose source hands to a pilot (so the follower need not re-estimate speed from pose differences).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

Pose2D = tuple[float, float, float]
"""x, y (m), theta (rad) in the odometry frame (REP-103: x forward, y left, theta CCW)."""


@dataclass(frozen=True, slots=True)
class RobotPose:
    """Where the robot was at `time_s` and how fast it was moving (measured, not commanded)."""

    time_s: float
    x_m: float
    y_m: float
    theta_rad: float
    linear_m_s: float = 0.0
    angular_rad_s: float = 0.0

    @property
    def xyt(self) -> Pose2D:
        return self.x_m, self.y_m, self.theta_rad

    def moved_to(self, time_s: float, xyt: Pose2D) -> RobotPose:
        """The same speeds at another time and place (an interpolated pose)."""
        return RobotPose(time_s, xyt[0], xyt[1], xyt[2], self.linear_m_s, self.angular_rad_s)


PoseAt = Callable[[float], RobotPose]
"""The robot's pose at any recent time (`PoseSource.at`): what de-skews a lidar revolution."""


def interpolate(a: Pose2D, b: Pose2D, f: float) -> Pose2D:
    """The pose a fraction `f` of the way from `a` to `b` (the turn taken the short way round)."""
    turn = math.remainder(b[2] - a[2], 2 * math.pi)
    return a[0] + f * (b[0] - a[0]), a[1] + f * (b[1] - a[1]), a[2] + f * turn
