"""What a robot's ROS 2 parameters files take from its robot file and from the node (roverlink.ros2.configs).

The robot's facts (footprint, speed and acceleration limits, a car's tightest turn, the lidar) come
from the robot file; the frame names from the node's parameter table (`params.SPECS` defaults), the
topic names from `TOPICS` (what the node publishes and subscribes; tests/roverlink/ros2 checks them
against a running node). Plain Python: no ROS import.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

from host_sdk import RobotDescription
from host_sdk.profiles import steering_angles
from protocol.sensors import DEVICES, LidarSpec
from roverlink.ros2.params import BY_NAME

TOPICS = {"cmd_vel": "cmd_vel", "odom": "odom", "scan": "scan", "imu": "imu", "joint_states": "joint_states"}
"""The node's topic names (relative: a namespace moves them)."""
FILTERED_ODOM = "odometry/filtered"
"""robot_localization's EKF output, the odometry topic Nav2 takes when an EKF fuses odom and imu."""
MAP_FRAME = "map"
"""SLAM Toolbox's map frame (Nav2's global frame)."""
MAX_TURN_PER_SCAN_RAD = math.radians(30)
"""The turn rate Nav2 may ask for is capped at this much per lidar revolution: SLAM Toolbox matches
each scan as if taken at one instant, and a scan smeared over a faster turn matches badly."""
FOOTPRINT_SIDES = 12
"""A disc not centred on base_link becomes a polygon of this many sides around it (Nav2's
robot_radius is centred on base_link)."""


def frame(name: str) -> str:
    """A frame name as the node uses it: its parameter's default (params.SPECS)."""
    value = BY_NAME[name].default
    assert isinstance(value, str)
    return value


@dataclass(frozen=True, slots=True)
class RobotFacts:
    """What the parameters files take from a robot file."""

    name: str
    source: str
    """The robot file's name (the files' header names it)."""
    ackermann: bool
    max_speed_m_s: float
    accel_m_s2: float
    decel_m_s2: float
    max_yaw_rate: float
    """rad/s: a differential robot turning in place with both wheels at max_speed_m_s; a car at
    max_speed_m_s on its tightest turn."""
    yaw_accel: float
    """rad/s^2: the same, with the wheels at accel_m_s2."""
    min_turning_radius_m: float
    """The tightest turn the car reaches to both sides (0 for a differential robot)."""
    footprint: tuple[tuple[float, float], ...]
    """Nav2's footprint polygon around base_link; empty when robot_radius says it."""
    robot_radius_m: float
    """The circumscribed radius around base_link (Nav2's robot_radius when footprint is empty)."""
    lidar_model: str
    lidar_port: str
    lidar_range_m: tuple[float, float]
    feedback_hz: float

    @classmethod
    def of(cls, robot: RobotDescription, max_speed_m_s: float | None = None) -> RobotFacts:
        """The facts of `robot`; `max_speed_m_s` lowers the speed Nav2 may ask for."""
        lim = robot.limits
        speed = min(lim.max_wheel_speed_m_s, max_speed_m_s or lim.max_wheel_speed_m_s)
        ackermann = robot.drive.kind == "ackermann"
        if ackermann:
            angles = steering_angles(robot.config())
            steer = min(-min(angles), max(angles))  # the tightest turn both ways
            radius = robot.geometry.wheelbase_m / math.tan(steer)
            yaw, yaw_accel = speed / radius, lim.accel_m_s2 / radius
        else:
            radius = 0.0
            yaw, yaw_accel = 2 * speed / robot.track_m, 2 * lim.accel_m_s2 / robot.track_m
        lidar = robot.lidar
        model = lidar.model if lidar is not None else str(BY_NAME["lidar_model"].default)
        spec = DEVICES[model]
        assert isinstance(spec, LidarSpec)
        yaw = min(yaw, MAX_TURN_PER_SCAN_RAD * spec.scan_hz)
        polygon = footprint_polygon(robot)
        return cls(
            name=robot.name,
            source=Path(robot.path).name,
            ackermann=ackermann,
            max_speed_m_s=speed,
            accel_m_s2=lim.accel_m_s2,
            decel_m_s2=lim.decel_m_s2,
            max_yaw_rate=yaw,
            yaw_accel=yaw_accel,
            min_turning_radius_m=radius,
            footprint=polygon,
            robot_radius_m=max(math.hypot(x, y) for x, y in polygon) if polygon else robot.footprint.disc()[0],
            lidar_model=model,
            lidar_port=lidar.port if lidar is not None and lidar.port else "",
            lidar_range_m=(spec.range_min_m, spec.range_max_m),
            feedback_hz=robot.feedback.rate_hz,
        )


def footprint_polygon(robot: RobotDescription) -> tuple[tuple[float, float], ...]:
    """The robot file's footprint as Nav2's polygon around base_link (the pose point): a polygon as
    it is, a box's corners, a disc off the pose point as a polygon whose sides touch the disc
    (so it covers it). Empty for a disc centred on the pose point (Nav2's robot_radius)."""
    fp = robot.footprint
    if fp.polygon_m is not None:
        return tuple((float(x), float(y)) for x, y in fp.polygon_m)
    if fp.length_m is not None and fp.width_m is not None:
        hl, hw = fp.length_m / 2, fp.width_m / 2
        corners = ((fp.x_m + hl, hw), (fp.x_m - hl, hw), (fp.x_m - hl, -hw), (fp.x_m + hl, -hw))
        return tuple((round(x, 4), round(y, 4)) for x, y in corners)
    assert fp.radius_m is not None
    if fp.x_m == 0:
        return ()
    corner = fp.radius_m / math.cos(math.pi / FOOTPRINT_SIDES)
    steps = (2 * math.pi * (k + 0.5) / FOOTPRINT_SIDES for k in range(FOOTPRINT_SIDES))
    return tuple((round(fp.x_m + corner * math.cos(a), 4), round(corner * math.sin(a), 4)) for a in steps)
