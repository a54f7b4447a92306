"""The robot's body as the applications see it: its footprint, where its lidar sits, and its camera.

`Footprint` and `LidarMount` are where things are on the robot (REP-103: x forward, y left);
`CameraModel` is a pinhole camera on the robot: pixels to bearings, apparent size to range.
They sit in the core (below perception) because a robot file describes them (RobotDescription).

    cam = CameraModel.pi_camera_v2(320, 240, mount_x_m=0.30)
    cam.bearing(u)                      # rad, counter-clockwise (left positive) from the robot's forward axis
    cam.range_from_size(h_px=40, height_m=0.3)      # metres along the optical axis

Square pixels from the field of view (the Pi Camera v2's 62.2 x 48.8 degrees, from
protocol/spec/sensors.toml), principal point at the image centre, no distortion (what a calibrated
and undistorted stream looks like; pass fx/fy/cx/cy from a calibration otherwise).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from host_sdk.errors import CommandRangeError
from protocol.sensors import DEVICES, CameraSpec


@dataclass(frozen=True, slots=True)
class CameraModel:
    width: int
    height: int
    fx: float
    fy: float
    cx: float
    cy: float
    mount_x_m: float = 0.0
    """Where the camera sits relative to the robot's pose point (x forward, y left) and its yaw."""
    mount_y_m: float = 0.0
    mount_yaw_rad: float = 0.0

    def __post_init__(self) -> None:
        for name in ("width", "height"):
            value = getattr(self, name)
            if not (isinstance(value, int) and value > 0):
                raise CommandRangeError(name, value, "a whole number of pixels > 0")
        for name in ("fx", "fy"):
            value = getattr(self, name)
            if not (math.isfinite(value) and value > 0):
                raise CommandRangeError(name, value, "a focal length in pixels > 0")

    @classmethod
    def from_fov(
        cls, width: int, height: int, hfov_deg: float, vfov_deg: float | None = None, **mount: float
    ) -> CameraModel:
        if not (0 < hfov_deg < 180):
            raise CommandRangeError("hfov_deg", hfov_deg, "0..180 degrees")
        fx = (width / 2) / math.tan(math.radians(hfov_deg) / 2)
        fy = fx if vfov_deg is None else (height / 2) / math.tan(math.radians(vfov_deg) / 2)
        return cls(width, height, fx, fy, (width - 1) / 2, (height - 1) / 2, **mount)

    @classmethod
    def pi_camera_v2(cls, width: int = 320, height: int = 240, **mount: float) -> CameraModel:
        spec = DEVICES["pi-camera-v2"]
        assert isinstance(spec, CameraSpec)
        return cls.from_fov(width, height, spec.hfov_deg, spec.vfov_deg, **mount)

    def bearing(self, u: float) -> float:
        """Bearing of image column `u` from the robot's forward axis (rad, left positive)."""
        return math.atan2(self.cx - u, self.fx) + self.mount_yaw_rad

    def column(self, bearing_rad: float) -> float:
        """Image column of a bearing (the inverse of `bearing`)."""
        return self.cx - self.fx * math.tan(bearing_rad - self.mount_yaw_rad)

    @property
    def half_fov_rad(self) -> float:
        return math.atan2(self.width / 2, self.fx)

    def off_axis_rad(self, x_m: float, y_m: float) -> float:
        """How far a base-frame point is from the optical axis, seen from the camera (rad, left
        positive): within `half_fov_rad` either way it is in the picture."""
        return math.remainder(math.atan2(y_m - self.mount_y_m, x_m - self.mount_x_m) - self.mount_yaw_rad, 2 * math.pi)

    def range_from_size(
        self,
        *,
        w_px: float | None = None,
        h_px: float | None = None,
        width_m: float | None = None,
        height_m: float | None = None,
    ) -> float | None:
        """Depth (m, along the optical axis) of an object of known width and/or height from its
        apparent size; None when no size is known. With both, the mean of the two estimates."""
        est = []
        if width_m and w_px and w_px > 0:
            est.append(self.fx * width_m / w_px)
        if height_m and h_px and h_px > 0:
            est.append(self.fy * height_m / h_px)
        return sum(est) / len(est) if est else None

    def point(self, bearing_rad: float, depth_m: float) -> tuple[float, float]:
        """Base-frame (x, y) of something at `depth_m` along the optical axis in direction `bearing_rad`."""
        rel = bearing_rad - self.mount_yaw_rad
        slant = depth_m / math.cos(rel)
        return (self.mount_x_m + slant * math.cos(bearing_rad), self.mount_y_m + slant * math.sin(bearing_rad))


@dataclass(frozen=True, slots=True)
class Footprint:
    """The robot's body as a disc of `radius_m` centred `x_m` ahead of the pose point."""

    radius_m: float
    x_m: float = 0.0

    def __post_init__(self) -> None:
        if not (math.isfinite(self.radius_m) and self.radius_m > 0):
            raise CommandRangeError("radius_m", self.radius_m, "a radius > 0 in metres")


@dataclass(frozen=True, slots=True)
class LidarMount:
    """Where the lidar sits relative to the robot's pose point (REP-103: x forward, y left)."""

    x_m: float = 0.0
    y_m: float = 0.0
    yaw_rad: float = 0.0
