"""`RobotDescription`: a robot file (docs/robot-file.md) as the SDK uses it.

    >>> from host_sdk import RobotDescription
    >>> from protocol.robotfile import reference_path
    >>> robot = RobotDescription.load(reference_path("diffdrive-tb6612"))
    >>> robot.kinematics()
    DiffDrive(wheel_radius_m=0.032, track_m=0.2, counts_per_rev=1560)

The file is read and checked in `protocol.robotfile` (the emulator reads the same files and cannot
import the SDK); this adds what only the host needs: kinematics, the footprint and the camera
model host_sdk.geometry and perception take.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from pathlib import Path

from host_sdk.body import CameraModel, Footprint, LidarMount
from host_sdk.kinematics import Ackermann, DiffDrive
from host_sdk.profiles import kinematics_from
from protocol.robotfile import RobotFile, RobotFileError, load
from protocol.sensors import DEVICES, CameraSpec

__all__ = ["RobotDescription", "RobotFileError"]


@dataclass(frozen=True)
class RobotDescription(RobotFile):
    """One robot file, checked: every key as typed fields, and the figures derived from them
    (`config()`, `pid_gains()`, `capabilities()`, `wiring`, `kinematics()`...)."""

    @classmethod
    def load(cls, path: str | Path) -> RobotDescription:
        """The robot file at `path`; RobotFileError (a ValueError) lists every problem in it."""
        robot = load(path)
        return cls(**{f.name: getattr(robot, f.name) for f in dataclasses.fields(robot)})

    def kinematics(self) -> DiffDrive | Ackermann:
        """The drive's kinematics, with the calibrated values where the file has them."""
        kind = "diff" if self.drive.kind == "differential" else "ackermann"
        return kinematics_from(kind, self.track_m, self.geometry.wheelbase_m, self.config())

    def body(self) -> Footprint:
        """The footprint as the disc the avoidance and geometry code take (a box or polygon: the
        smallest disc around it)."""
        radius, x = self.footprint.disc()
        return Footprint(radius, x)

    def lidar_mount(self) -> LidarMount:
        """Where the lidar sits (the pose point if the file has none)."""
        m = self.sensors().placed("lidar")
        return LidarMount(m.x_m, m.y_m, m.yaw_rad)

    def camera_model(self) -> CameraModel:
        """The camera's pinhole model from its size, field of view and mount (the Pi camera v2's
        field of view where the file gives none)."""
        m = self.sensors().placed("camera")
        mount = {"mount_x_m": m.x_m, "mount_y_m": m.y_m, "mount_yaw_rad": m.yaw_rad}
        cam = self.camera
        if cam is None:
            return CameraModel.pi_camera_v2(320, 240, **mount)
        if cam.fx:  # intrinsics given: they win over any field of view
            cx, cy = cam.cx or (cam.width - 1) / 2, cam.cy or (cam.height - 1) / 2
            return CameraModel(cam.width, cam.height, cam.fx, cam.fy or cam.fx, cx, cy, **mount)
        if cam.hfov_deg:
            return CameraModel.from_fov(cam.width, cam.height, cam.hfov_deg, **mount)
        spec = DEVICES.get(cam.model)
        if not isinstance(spec, CameraSpec):
            spec = DEVICES["pi-camera-v2"]
            assert isinstance(spec, CameraSpec)
        return CameraModel.from_fov(cam.width, cam.height, spec.hfov_deg, spec.vfov_deg, **mount)
