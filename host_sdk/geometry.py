"""A robot's shape and where its sensors sit (for perception and autonomy): from the robot file
it was connected with (docs/robot-file.md: footprint, camera, lidar mount), else from the reference
robots' sensor mounts (protocol/spec/sensors.toml); and its kinematics.

Where a profile carries no device of a kind, the same spot as the emulator's (protocol.sensors:
`RobotSensors.placed`): a lidar on top of the pose point, a camera at the front of the footprint.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

from host_sdk.body import CameraModel, Footprint, LidarMount
from host_sdk.errors import CommandRangeError
from host_sdk.kinematics import Ackermann, DiffDrive
from host_sdk.profiles import profile_for_example, steering_angles
from host_sdk.robot import Robot
from host_sdk.robot_description import RobotDescription
from protocol.generated.messages import SetConfig
from protocol.generated.profiles import ROBOT_SENSORS
from protocol.sensors import Mount


@dataclass(frozen=True, slots=True)
class RobotGeometry:
    footprint: Footprint
    camera: CameraModel
    lidar_mount: LidarMount
    min_turn_radius_m: float
    """0: differential drive."""
    curvatures: tuple[float, ...] | None = None
    """Ackermann: the arcs (1/m, left positive) its steering reaches; None: any up to the tightest."""
    accel_m_s2: float | None = None
    """The board's speed ramp (its config's accel limit), which the wheels follow once the feed-forward
    is tuned: how fast a planner may assume the speed changes. None: not known."""

    @classmethod
    def from_description(
        cls,
        desc: RobotDescription,
        kinematics: DiffDrive | Ackermann | None = None,
        *,
        config: SetConfig | None = None,
    ) -> RobotGeometry:
        """The geometry a robot file gives: its footprint, camera (size, field of view or
        intrinsics, mount) and lidar mount; the turn radius and steering arcs from `kinematics`
        and the board's `config` (default: the file's own), and that config's speed ramp."""
        kin = kinematics or desc.kinematics()
        board = config if config is not None else desc.config()
        arcs = _arcs(kin, board)
        return cls(desc.body(), desc.camera_model(), desc.lidar_mount(), _min_turn(kin), arcs, _ramp(board))


def mount(profile: str, kind: str) -> Mount:
    """Where `profile` carries its `kind` device (sensors.toml), else where the emulator puts one."""
    return ROBOT_SENSORS[profile].placed(kind)


def profile_of(robot: Robot) -> str | None:
    """The reference robot `robot` is (an emulator's profile, or the firmware example's), else None."""
    if robot.transport.profile is not None:
        return robot.transport.profile
    found = profile_for_example(robot.identity.robot_name)
    return found.name if found is not None else None


def description_of(robot: Robot) -> RobotDescription | None:
    """The robot file `robot` was connected with (connect's robot=, or an emu://?robot=PATH's)."""
    if robot.description is not None:
        return robot.description
    path = robot.transport.robot_file
    return RobotDescription.load(path) if path is not None else None


def sensor_mounts(robot: Robot, kinds: Sequence[str]) -> dict[str, Mount]:
    """Where each device of `kinds` sits on the robot (REP-103, from the pose point): its robot
    file's mounts, or the reference robot's, or where the emulator puts a device it carries none
    of; at the pose point on a robot of its own."""
    desc = description_of(robot)
    body = desc.sensors() if desc is not None else ROBOT_SENSORS.get(profile_of(robot) or "")
    return {kind: body.placed(kind) if body is not None else Mount(kind, kind) for kind in kinds}


def robot_geometry(
    robot: Robot,
    profile: str | None = None,
    *,
    description: RobotDescription | None = None,
    width: int = 320,
    height: int = 240,
) -> RobotGeometry:
    """`geometry()` of a connected robot: its kinematics and its board's steering, the mounts of
    `profile`; without one, those of `description` or the robot file it was connected with
    (RobotGeometry.from_description: the file's camera size), else of the reference robot it is."""
    desc = description or (description_of(robot) if profile is None else None)
    if desc is not None and profile is None:
        return RobotGeometry.from_description(desc, robot.kinematics, config=robot.config)
    name = profile or profile_of(robot)
    if name is None:
        raise CommandRangeError("profile", None, f"a reference robot: {', '.join(sorted(ROBOT_SENSORS))}")
    return geometry(name, robot.kinematics, config=robot.config, width=width, height=height)


def geometry(
    profile: str,
    kinematics: DiffDrive | Ackermann | None,
    *,
    config: SetConfig | None = None,
    width: int = 320,
    height: int = 240,
) -> RobotGeometry:
    """The robot's geometry; with the board's `config` an Ackermann robot's arcs are the ones its
    steering servo reaches, and the speed ramp is the board's."""
    body = ROBOT_SENSORS[profile]
    cm, lm = mount(profile, "camera"), mount(profile, "lidar")
    return RobotGeometry(
        Footprint(body.footprint_radius_m, body.footprint_x_m),
        CameraModel.pi_camera_v2(width, height, mount_x_m=cm.x_m, mount_y_m=cm.y_m, mount_yaw_rad=cm.yaw_rad),
        LidarMount(lm.x_m, lm.y_m, lm.yaw_rad),
        _min_turn(kinematics),
        _arcs(kinematics, config),
        _ramp(config),
    )


def _min_turn(kinematics: DiffDrive | Ackermann | None) -> float:
    return kinematics.min_turn_radius_m if isinstance(kinematics, Ackermann) else 0.0


def _ramp(config: SetConfig | None) -> float | None:
    return None if config is None else config.accel_limit_mm_s2 / 1000


def _arcs(kinematics: DiffDrive | Ackermann | None, config: SetConfig | None) -> tuple[float, ...] | None:
    """An Ackermann robot's arcs its steering servo reaches (the board's steps within its limit)."""
    if not isinstance(kinematics, Ackermann) or config is None:
        return None
    limit = kinematics.max_steering_rad
    angles = [a for a in steering_angles(config) if abs(a) <= limit + 1e-9]
    return tuple(math.tan(a) / kinematics.wheelbase_m for a in angles)
