"""A robot's shape and where its sensors sit, from protocol/spec/sensors.toml and its kinematics.

Where a profile carries no device of a kind, the same defaults as the emulator's: a lidar on top of
the pose point, a camera at the front of the footprint.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from host_sdk.kinematics import Ackermann, DiffDrive
from host_sdk.perception import CameraModel, Footprint, LidarMount
from host_sdk.profiles import steering_angles
from protocol.generated.messages import SetConfig
from protocol.sensors import ROBOT_SENSORS, Mount


@dataclass(frozen=True, slots=True)
class RobotGeometry:
    footprint: Footprint
    camera: CameraModel
    lidar_mount: LidarMount
    min_turn_radius_m: float
    """0: differential drive."""
    curvatures: tuple[float, ...] | None = None
    """Ackermann: the arcs (1/m, left positive) its steering reaches; None: any up to the tightest."""


def mount(profile: str, kind: str) -> Mount:
    body = ROBOT_SENSORS[profile]
    found = body.mount(kind)
    if found is not None:
        return found
    if kind == "camera":
        return Mount("pi-camera-v2", "camera", body.footprint_x_m + 0.8 * body.footprint_radius_m, 0.0, 0.12, 0.0)
    return Mount("rplidar-a1", kind, 0.0, 0.0, 0.2, 0.0)


def geometry(profile: str, kinematics: DiffDrive | Ackermann | None, *, config: SetConfig | None = None,
             width: int = 320, height: int = 240) -> RobotGeometry:  # fmt: skip
    """The robot's geometry; with the board's `config` an Ackermann robot's arcs are the ones its
    steering servo reaches."""
    body = ROBOT_SENSORS[profile]
    cm, lm = mount(profile, "camera"), mount(profile, "lidar")
    curvatures = None
    if isinstance(kinematics, Ackermann) and config is not None:
        limit = kinematics.max_steering_rad
        angles = [a for a in steering_angles(config) if abs(a) <= limit + 1e-9]
        curvatures = tuple(math.tan(a) / kinematics.wheelbase_m for a in angles)
    return RobotGeometry(
        Footprint(body.footprint_radius_m, body.footprint_x_m),
        CameraModel.pi_camera_v2(width, height, mount_x_m=cm.x_m, mount_y_m=cm.y_m, mount_yaw_rad=cm.yaw_rad),
        LidarMount(lm.x_m, lm.y_m, lm.yaw_rad),
        kinematics.min_turn_radius_m if isinstance(kinematics, Ackermann) else 0.0,
        curvatures,
    )
