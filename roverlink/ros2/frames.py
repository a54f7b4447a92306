"""The robot's fixed frames: base_footprint and its sensors' mounts as transforms from base_link.

One source for the URDF (`roverlink robot urdf`, roverlink.ros2.urdf) and the node's `/tf_static`
(roverlink.ros2.static_tf), so a URDF loaded into robot_state_publisher and the node's own static
transforms can never disagree. Plain Python: no rclpy.

base_link is the pose point (the middle of the driven axle, where odometry's origin is) on the
ground plane: the robot file's mounts are relative to it, their z the height above the ground
(the emulated camera renders the floor from that height).
"""

from __future__ import annotations

import math
from collections.abc import Iterable
from dataclasses import dataclass

from protocol.generated.profiles import ROBOT_SENSORS
from protocol.robotfile import RobotFile
from protocol.sensors import Mount
from roverlink.ros2.params import BY_NAME

SENSOR_KINDS = ("lidar", "imu", "camera")


def _default(name: str) -> str:
    return str(BY_NAME[name].default)


@dataclass(frozen=True, slots=True)
class FrameNames:
    """Frame and joint names; the defaults are the node's parameter defaults (roverlink.ros2.params)."""

    base: str = _default("base_frame")
    footprint: str = "base_footprint"
    lidar: str = _default("lidar_frame")
    imu: str = _default("imu_frame")
    camera: str = "camera_link"
    camera_optical: str = "camera_optical_frame"
    """REP-103 optical frame of the camera: z forward, x right, y down."""
    wheel_joints: tuple[str, ...] = ()
    """Empty: the node's joint_states names (roverlink.ros2.convert.default_wheel_joints)."""
    steering_joint: str = _default("steering_joint")

    def sensor(self, kind: str) -> str:
        return {"lidar": self.lidar, "imu": self.imu, "camera": self.camera}[kind]


@dataclass(frozen=True, slots=True)
class StaticFrame:
    """A fixed transform `parent` -> `child`: translation in m, rotation as roll, pitch, yaw in rad."""

    parent: str
    child: str
    x: float
    y: float
    z: float
    roll: float = 0.0
    pitch: float = 0.0
    yaw: float = 0.0


DEFAULT_NAMES = FrameNames()

# The optical frame's rotation from the camera link (REP-103: z forward, x right, y down).
OPTICAL_RPY = (-math.pi / 2, 0.0, -math.pi / 2)


def mounts_of(source: RobotFile | str, kinds: Iterable[str] | None = None) -> tuple[Mount, ...]:
    """The sensors' mounts: a robot file's (all it carries, or those of `kinds` it carries), or a
    reference robot's for each of `kinds` (where it carries that device, else where the emulator
    puts one: protocol.sensors RobotSensors.placed). Always in SENSOR_KINDS order."""
    if isinstance(source, RobotFile):
        wanted = set(SENSOR_KINDS if kinds is None else kinds)
        return tuple(m for m in source.mounts() if m.name in wanted)
    body = ROBOT_SENSORS[source]
    wanted = set(kinds if kinds is not None else (m.name for m in body.mounts))
    return tuple(body.placed(kind) for kind in SENSOR_KINDS if kind in wanted)


def static_frames(
    source: RobotFile | str, names: FrameNames = DEFAULT_NAMES, kinds: Iterable[str] | None = None
) -> tuple[StaticFrame, ...]:
    """base_link -> base_footprint (REP-120: the same place), base_link -> each sensor at its mount,
    and camera -> its optical frame. `source`: a robot file or a reference robot's name; `kinds`:
    see mounts_of. A base frame named as the footprint (`base_frame: base_footprint`, as many
    ros_arduino_bridge set-ups have it) is that frame itself: no transform from a frame to itself."""
    out = [] if names.base == names.footprint else [StaticFrame(names.base, names.footprint, 0.0, 0.0, 0.0)]
    for m in mounts_of(source, kinds):
        out.append(StaticFrame(names.base, names.sensor(m.name), m.x_m, m.y_m, m.z_m, yaw=m.yaw_rad))
        if m.name == "camera":
            out.append(StaticFrame(names.camera, names.camera_optical, 0.0, 0.0, 0.0, *OPTICAL_RPY))
    return tuple(out)
