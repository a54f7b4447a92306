"""Which lidar points are the tracked target: the camera's ray matched against the scan.

The PiCar team's unfinished step: with the camera and the lidar working apart, the object being
followed, straight ahead, is an obstacle to the lidar. Here the tracked bearing (a ray from the
camera's position, not the robot's pose point: on the PiCar they are 0.3 m apart) and, when the
object's size is known, the camera's range estimate select the lidar returns along that ray; the
nearest is the target's surface, and the returns around it within the object's size are its
cluster. Those points are the target: the follower measures its distance with them (the lidar's
range is far better than an apparent size) and the avoider does not steer away from them.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from host_sdk.body import CameraModel

F64 = NDArray[np.float64]


@dataclass(frozen=True, slots=True, eq=False)
class TargetFix:
    """Where the target is now, in the robot's base frame."""

    x_m: float
    """The target's nearest surface point (lidar), or the camera's estimate of it."""
    y_m: float
    mask: NDArray[np.bool_]
    """Which of the obstacle points given belong to the target."""
    from_lidar: bool

    @property
    def bearing_rad(self) -> float:
        return math.atan2(self.y_m, self.x_m)

    @property
    def range_m(self) -> float:
        return math.hypot(self.x_m, self.y_m)


def locate_target(
    px: F64,
    py: F64,
    camera: CameraModel,
    bearing_rad: float,
    depth_m: float | None,
    *,
    size_m: float = 0.3,
    bearing_tol_rad: float = math.radians(3.0),
) -> TargetFix | None:
    """The target among obstacle points (base frame) seen by `camera` at `bearing_rad` (from the
    camera model: the ray leaves the camera), `depth_m` its estimated depth if known, `size_m` about
    how wide it is. None when neither the lidar nor a depth estimate places it."""
    cx, cy = camera.mount_x_m, camera.mount_y_m
    dx, dy = math.cos(bearing_rad), math.sin(bearing_rad)
    n = np.asarray(px).shape[0]
    mask = np.zeros(n, dtype=bool)
    slant = None if depth_m is None else depth_m / max(math.cos(bearing_rad - camera.mount_yaw_rad), 0.2)
    if n:
        rx, ry = px - cx, py - cy
        along = rx * dx + ry * dy
        across = np.abs(-rx * dy + ry * dx)
        near_ray = (along > 0.05) & (across < size_m / 2 + 0.05 + along * math.tan(bearing_tol_rad))
        if slant is not None:
            near_ray &= np.abs(along - slant) < max(0.3, 0.35 * slant)
        if near_ray.any():
            seed = int(np.flatnonzero(near_ray)[np.argmin(along[near_ray])])
            sx, sy = float(px[seed]), float(py[seed])
            mask = np.hypot(px - sx, py - sy) < 0.6 * size_m + 0.05
            return TargetFix(sx, sy, mask, True)
    if slant is None:
        return None
    return TargetFix(cx + slant * dx, cy + slant * dy, mask, False)
