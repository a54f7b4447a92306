"""The bridge node's ROS parameters: names, defaults, allowed values and their meaning, in one table.

The node declares exactly these (with their descriptions and ranges), `BridgeParams.from_values`
checks a full set of values, and docs/ros2.md's parameter table is tested against this list. No
ROS import here: the table and its checks are plain Python.
"""

from __future__ import annotations

import difflib
import math
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from urllib.parse import parse_qs, urlsplit

from host_sdk.errors import CommandRangeError
from host_sdk.robot_description import RobotDescription
from host_sdk.sensors.wit import G
from protocol.generated.constants import (
    FEEDBACK_HZ_DEFAULT,
    FEEDBACK_HZ_MAX,
    WATCHDOG_DEFAULT_MS,
    WATCHDOG_MAX_MS,
    WATCHDOG_MIN_MS,
)
from protocol.generated.profiles import ROBOT_SENSORS
from protocol.robotfile import SerialSensor
from protocol.sensors import DEVICES

ParamValue = bool | int | float | str | list[float] | list[str]

LIDARS = tuple(name for name, spec in DEVICES.items() if spec.kind == "lidar")
"""The lidar models the drivers speak (protocol/spec/sensors.toml)."""

DEFAULT_COVARIANCE = (0.001, 0.001, 0.001, 0.001, 0.001, 0.01)
"""Diagonal of pose and twist covariance (x, y, z, roll, pitch, yaw), as ros2_control's
diff_drive_controller has it."""


def _jy901_variance(figure: str, scale: float) -> float:
    """The square of one of the JY901's datasheet figures (protocol/spec/sensors.toml) times `scale`."""
    sigma = float(getattr(DEVICES["jy901"], figure)) * scale
    return float(f"{sigma * sigma:.3g}")


_DEG = math.pi / 180
_IMU_BAUD = DEVICES["jy901"].baud  # type: ignore[union-attr]
IMU_ORIENTATION_VARIANCE = [_jy901_variance(k, _DEG) for k in ("angle_sigma_deg",) * 2 + ("heading_sigma_deg",)]
"""roll, pitch: the static angle accuracy; yaw: the heading accuracy with a calibrated magnetometer."""
IMU_GYRO_VARIANCE = [_jy901_variance("gyro_sigma_dps", _DEG)] * 3
IMU_ACCEL_VARIANCE = [_jy901_variance("accel_sigma_g", G)] * 3


@dataclass(frozen=True, slots=True)
class ParamSpec:
    name: str
    default: ParamValue
    description: str
    choices: tuple[str, ...] = ()
    low: float | None = None
    high: float | None = None

    @property
    def allowed(self) -> str:
        if self.choices:
            return " or ".join(repr(c) for c in self.choices)
        if self.low is not None and self.high is not None:
            return f"{self.low:g}..{self.high:g}"
        if isinstance(self.default, bool):
            return "true or false"
        if isinstance(self.default, list):
            n = len(self.default)
            return f"a list of {n} numbers >= 0" if "covariance" in self.name else "a list of names"
        return "a string"


SPECS: tuple[ParamSpec, ...] = (
    ParamSpec("url", "/dev/ttyACM0", "serial port or URL of the board (emu://PROFILE for the emulator)"),
    ParamSpec("profile", "", "reference robot (empty: from the firmware's identity or the emu:// URL)"),
    ParamSpec(
        "robot_file",
        "",
        "your robot file (docs/robot-file.md; instead of profile): track, wheels and calibration for odom and "
        "cmd_vel, limits and gains set on the board, the board checked against it",
    ),
    ParamSpec("allow_mismatch", False, "connect even if the board differs from robot_file (warned about)"),
    ParamSpec("baud", 115200, "line speed in bit/s", low=1200, high=2_000_000),
    ParamSpec(
        "mode",
        "auto",
        "feedback mode: auto (the robot file's or the profile's), stream (the board sends FEEDBACK at "
        "odom_rate) or lockstep (one FEEDBACK per command; the node commands at odom_rate)",
        choices=("auto", "stream", "lockstep"),
    ),
    ParamSpec(
        "watchdog",
        WATCHDOG_DEFAULT_MS / 1000,
        "board watchdog in s: no valid frame for this long and the board fails safe",
        low=WATCHDOG_MIN_MS / 1000,
        high=WATCHDOG_MAX_MS / 1000,
    ),
    ParamSpec("connect_timeout", 5.0, "seconds one connection attempt may take", low=0.5, high=60),
    ParamSpec("reconnect_delay", 0.5, "first wait in s before reconnecting after the link is lost", low=0.05, high=60),
    ParamSpec(
        "reconnect_delay_max", 5.0, "longest wait in s between reconnection attempts (doubling)", low=0.05, high=300
    ),
    ParamSpec("odom_frame", "odom", "frame of the odometry pose"),
    ParamSpec("base_frame", "base_link", "the robot's body frame (child of odom_frame)"),
    ParamSpec("publish_tf", True, "publish odom_frame -> base_frame on /tf (off when an EKF publishes it)"),
    ParamSpec(
        "publish_static_tf",
        True,
        "publish base_frame -> base_footprint and the sensors' frames at their mounts on /tf_static (off when "
        "robot_state_publisher publishes the URDF of `roverlink robot urdf`)",
    ),
    ParamSpec(
        "odom_rate",
        0,
        "odom and joint_states rate in Hz (the board's feedback rate); 0: the robot file's [feedback] "
        "rate_hz (a reference robot's for a profile)",
        low=0,
        high=FEEDBACK_HZ_MAX,
    ),
    ParamSpec("diagnostics_rate", 1.0, "diagnostics rate in Hz", low=0.1, high=10),
    ParamSpec(
        "odom_qos",
        "reliable",
        "QoS of odom, joint_states and odometry/filtered: reliable, or sensor_data (best effort)",
        choices=("reliable", "sensor_data"),
    ),
    ParamSpec("qos_depth", 10, "history depth of the publishers and the cmd_vel subscription", low=1, high=1000),
    ParamSpec("pose_covariance_diagonal", list(DEFAULT_COVARIANCE), "odom pose covariance: x, y, z, roll, pitch, yaw"),
    ParamSpec("twist_covariance_diagonal", list(DEFAULT_COVARIANCE), "odom twist covariance: the same six axes"),
    ParamSpec("wheel_joints", [], "joint names of the wheels (empty: left/right_wheel_joint, or rear_wheel_joint)"),
    ParamSpec("steering_joint", "steering_joint", "joint name of the steering (Ackermann robots)"),
    ParamSpec("use_stamped_vel", False, "cmd_vel is geometry_msgs/TwistStamped instead of Twist"),
    ParamSpec("cmd_vel_timeout", 0.5, "a cmd_vel older than this in s no longer drives the robot", low=0.02, high=10),
    ParamSpec(
        "on_timeout",
        "stop",
        "after cmd_vel_timeout: stop (hold zero speed, stay armed) or release (send nothing: the board's "
        "watchdog fails it safe, and it needs arming again)",
        choices=("stop", "release"),
    ),
    ParamSpec(
        "limit_policy",
        "clamp",
        "a cmd_vel beyond the board's limits: clamp (scale down, keeping the curvature) or refuse",
        choices=("clamp", "refuse"),
    ),
    ParamSpec(
        "auto_arm", False, "arm at start, and again on the next cmd_vel after a board reset or a watchdog failsafe"
    ),
    ParamSpec("lidar_url", "", "the lidar's port (empty: none, or the emulated one of an emu:// robot)"),
    ParamSpec("lidar_model", LIDARS[0], f"the lidar: {' or '.join(LIDARS)}", choices=LIDARS),
    ParamSpec(
        "lidar_baud",
        0,
        "the lidar's line speed in bit/s (0: the robot file's [sensors.lidar] baud, else the model's datasheet's)",
        low=0,
        high=4_000_000,
    ),
    ParamSpec("lidar_frame", "laser", "frame of scan (placed at the lidar's mount on /tf_static, or by your URDF)"),
    ParamSpec("scan_bins", 360, "scan: the revolution binned on this many evenly spaced angles", low=8, high=8192),
    ParamSpec("imu_url", "", "the JY901 IMU's port (empty: none, or the emulated one of an emu:// robot)"),
    ParamSpec(
        "imu_baud",
        0,
        f"the IMU's line speed in bit/s (0: the robot file's [sensors.imu] baud, else the JY901's {_IMU_BAUD}; "
        "a factory-new JY901 runs at 9600)",
        low=0,
        high=4_000_000,
    ),
    ParamSpec("imu_frame", "imu_link", "frame of imu (placed at the IMU's mount on /tf_static, or by your URDF)"),
    ParamSpec(
        "imu_orientation_covariance_diagonal",
        IMU_ORIENTATION_VARIANCE,
        "imu orientation variances (roll, pitch, yaw) in rad^2: the JY901 datasheet's accuracy",
    ),
    ParamSpec(
        "imu_angular_velocity_covariance_diagonal",
        IMU_GYRO_VARIANCE,
        "imu angular velocity variances (x, y, z) in (rad/s)^2: the JY901 datasheet's gyro stability",
    ),
    ParamSpec(
        "imu_linear_acceleration_covariance_diagonal",
        IMU_ACCEL_VARIANCE,
        "imu acceleration variances (x, y, z) in (m/s^2)^2: the JY901 datasheet's accelerometer stability",
    ),
    ParamSpec(
        "realtime_priority",
        0,
        "every thread of the node under SCHED_FIFO at this priority (0: normal scheduling); for a host whose "
        "cores are busy with other work; needs CAP_SYS_NICE or an rtprio limit",
        low=0,
        high=99,
    ),
    ParamSpec(
        "tf_from",
        "odom",
        "what /tf's odom_frame -> base_frame is: odom (wheel odometry) or fused (the EKF's odometry/filtered; "
        "needs an IMU)",
        choices=("odom", "fused"),
    ),
)

BY_NAME = {spec.name: spec for spec in SPECS}


def _bad(spec: ParamSpec, value: object) -> CommandRangeError:
    return CommandRangeError(f"parameter {spec.name}", value, spec.allowed)


def _number(spec: ParamSpec, value: object) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
        raise _bad(spec, value)
    if spec.low is not None and spec.high is not None and not spec.low <= value <= spec.high:
        raise _bad(spec, value)
    return float(value)


def _covariance(spec: ParamSpec, value: object) -> tuple[float, ...]:
    size = len(spec.default) if isinstance(spec.default, list) else 6
    if not isinstance(value, Sequence) or isinstance(value, str) or len(value) != size:
        raise _bad(spec, value)
    out = []
    for item in value:
        if isinstance(item, bool) or not isinstance(item, (int, float)) or not (math.isfinite(item) and item >= 0):
            raise _bad(spec, value)
        out.append(float(item))
    return tuple(out)


@dataclass(frozen=True, slots=True)
class BridgeParams:
    """A checked set of the node's parameters (see SPECS for each one's meaning)."""

    url: str
    profile: str
    robot_file: str
    allow_mismatch: bool
    baud: int
    mode: str
    watchdog: float
    connect_timeout: float
    reconnect_delay: float
    reconnect_delay_max: float
    odom_frame: str
    base_frame: str
    publish_tf: bool
    publish_static_tf: bool
    odom_rate: int
    diagnostics_rate: float
    odom_qos: str
    qos_depth: int
    pose_covariance_diagonal: tuple[float, ...]
    twist_covariance_diagonal: tuple[float, ...]
    wheel_joints: tuple[str, ...]
    steering_joint: str
    use_stamped_vel: bool
    cmd_vel_timeout: float
    on_timeout: str
    limit_policy: str
    auto_arm: bool
    lidar_url: str
    lidar_model: str
    lidar_baud: int
    lidar_frame: str
    scan_bins: int
    imu_url: str
    imu_baud: int
    imu_frame: str
    imu_orientation_covariance_diagonal: tuple[float, ...]
    imu_angular_velocity_covariance_diagonal: tuple[float, ...]
    imu_linear_acceleration_covariance_diagonal: tuple[float, ...]
    realtime_priority: int
    tf_from: str

    @classmethod
    def defaults(cls, **overrides: ParamValue) -> BridgeParams:
        values: dict[str, object] = {spec.name: spec.default for spec in SPECS}
        values.update(overrides)
        return cls.from_values(values)

    @classmethod
    def from_values(cls, values: Mapping[str, object]) -> BridgeParams:
        """Check every value; CommandRangeError (a ValueError) names the parameter and what it allows."""
        unknown = sorted(set(values) - set(BY_NAME))
        if unknown:
            raise CommandRangeError("parameter", unknown[0], f"one of {', '.join(BY_NAME)}")
        out: dict[str, object] = {}
        for spec in SPECS:
            value = values.get(spec.name, spec.default)
            if spec.name.endswith("_covariance_diagonal"):
                out[spec.name] = _covariance(spec, value)
            elif spec.name == "wheel_joints":
                if (
                    not isinstance(value, Sequence)
                    or isinstance(value, str)
                    or not all(isinstance(v, str) for v in value)
                ):
                    raise _bad(spec, value)
                out[spec.name] = tuple(value)
            elif isinstance(spec.default, bool):
                if not isinstance(value, bool):
                    raise _bad(spec, value)
                out[spec.name] = value
            elif isinstance(spec.default, int):
                number = _number(spec, value)
                if not number.is_integer():
                    raise _bad(spec, value)
                out[spec.name] = int(number)
            elif isinstance(spec.default, float):
                out[spec.name] = _number(spec, value)
            else:
                if not isinstance(value, str) or (spec.choices and value not in spec.choices):
                    raise _bad(spec, value)
                out[spec.name] = value
        params = cls(**out)  # type: ignore[arg-type]
        if params.reconnect_delay_max < params.reconnect_delay:
            raise CommandRangeError(
                "parameter reconnect_delay_max",
                params.reconnect_delay_max,
                f">= reconnect_delay ({params.reconnect_delay:g})",
            )
        if params.profile and params.robot_file:
            raise CommandRangeError("parameter robot_file", params.robot_file, "empty when profile is set")
        for name in ("odom_frame", "base_frame", "lidar_frame", "imu_frame"):
            if not getattr(params, name):
                raise CommandRangeError(f"parameter {name}", "", "a frame id (not empty)")
        return params


def mode_for(params: BridgeParams, profile_mode: str | None) -> str:
    """The feedback mode to ask for: the parameter, or with "auto" the profile's (else stream)."""
    if params.mode != "auto":
        return params.mode
    return profile_mode or "stream"


def odom_rate_for(params: BridgeParams, robot: RobotDescription | None) -> int:
    """The rate to ask for: the parameter, or with 0 the robot's feedback rate (a robot file's, or
    the reference robot's), else FEEDBACK_HZ_DEFAULT."""
    if params.odom_rate:
        return params.odom_rate
    if robot is None:
        return FEEDBACK_HZ_DEFAULT
    return max(1, min(FEEDBACK_HZ_MAX, round(robot.feedback.rate_hz)))


def robot_url(params: BridgeParams) -> str:
    """The URL to connect to: an emu:// robot is the robot file's (`emu://?robot=FILE`, the rest of
    the URL kept), as `roverlink follow --robot` emulates it, so the emulated wheels, lidar and
    camera sit where the file says and the node's odometry and /tf_static describe that robot."""
    url, path = params.url, params.robot_file
    if not (path and url.startswith("emu://")) or "robot=" in url:
        return url
    query = url.partition("?")[2]
    return f"emu://?robot={Path(path).resolve()}" + (f"&{query}" if query else "")


OLD_NAMES: dict[str, str] = {
    "port": "the url parameter",
    "timeout": "connect_timeout",
    "rate": "odom_rate",
    "base_controller_rate": "odom_rate",
    "base_controller_timeout": "cmd_vel_timeout",
    "sensorstate_rate": "diagnostics_rate",
    "use_base_controller": "nothing: the node always drives the base from cmd_vel",
    "sensors": "lidar_url and imu_url",
    "wheel_diameter": "the robot file's [geometry] wheel_diameter_m (robot_file)",
    "wheel_track": "the robot file's [geometry] track_m (robot_file)",
    "encoder_resolution": "the robot file's [encoders] counts_per_rev, per wheel revolution (robot_file)",
    "gear_reduction": "the robot file's [encoders] counts_per_rev, gearing included (robot_file)",
    "motors_reversed": "the robot file's [drive] motor_invert (robot_file)",
    "Kp": "the robot file's [pid] kp (robot_file)",
    "Ki": "the robot file's [pid] ki (robot_file)",
    "Kd": "the robot file's [pid] kd (robot_file)",
    "Ko": "nothing: the robot file's [pid] gains are in effort per m/s, with no output scale",
    "accel_limit": "the robot file's [limits] accel_m_s2 (robot_file)",
    "odom_linear_scale_correction": "the robot file's [calibration] wheel_diameter_m (roverlink calibrate)",
    "odom_angular_scale_correction": "the robot file's [calibration] track_m (roverlink calibrate)",
}
"""ros_arduino_bridge's parameters (its arduino_params.yaml) and what RoverLink has instead."""

_ROS_OWN_PREFIXES = ("qos_overrides.",)
"""Parameters rclpy reads itself (a publisher's QoS overrides)."""


def unknown_parameter_warnings(undeclared: Iterable[str]) -> list[str]:
    """One line per parameter set (command line, parameters file) that the node does not have:
    a ros_arduino_bridge name says RoverLink's, another the nearest names (a typo)."""
    out = []
    for name in sorted(set(undeclared) - set(BY_NAME)):
        if name.startswith(_ROS_OWN_PREFIXES):
            continue
        if name in OLD_NAMES:
            out.append(f"parameter {name} is ros_arduino_bridge's and is ignored: RoverLink's is {OLD_NAMES[name]}")
            continue
        near = difflib.get_close_matches(name, BY_NAME, n=2)
        hint = f"did you mean {' or '.join(near)}?" if near else "docs/ros2.md lists the node's parameters"
        out.append(f"unknown parameter {name} is ignored: {hint}")
    return out


def sensor_baud(param: int, device: SerialSensor | None) -> int | None:
    """A sensor's line speed: the parameter, else the robot file's (`baud` of its [sensors.*]),
    else None (the driver's datasheet default)."""
    if param:
        return param
    if device is not None and device.baud:
        return device.baud
    return None


def profile_sensor_warnings(params: BridgeParams) -> list[str]:
    """A reference robot named by the profile parameter that carries a lidar or an IMU, on a real
    port with no lidar_url/imu_url: the node has no such device (no scan and no laser frame), said
    naming the parameter to set."""
    if not params.profile or params.url.startswith("emu://") or params.profile not in ROBOT_SENSORS:
        return []
    out = []
    for kind, url, frame, topic in (
        ("lidar", params.lidar_url, params.lidar_frame, "scan"),
        ("imu", params.imu_url, params.imu_frame, "imu"),
    ):
        mount = ROBOT_SENSORS[params.profile].mount(kind)
        if mount is not None and not url:
            out.append(
                f"the {params.profile} robot carries a {mount.device} but the {kind}_url parameter is empty: "
                f"no {topic} and no {frame} frame; set {kind}_url to its port (e.g. a /dev/serial/by-id/... path)"
            )
    return out


def link_warnings(params: BridgeParams) -> list[str]:
    """Settings that pass without effect or break the handshake: a board baud other than the
    firmware's (ros_arduino_bridge's 57600 carried over), and an emu:// URL's camera (the node
    publishes no image topic)."""
    out = []
    default = next(spec.default for spec in SPECS if spec.name == "baud")
    if params.baud != default and not params.url.startswith("emu://"):
        out.append(
            f"baud {params.baud}: the RoverLink firmware opens its port at {default} "
            f"(ros_arduino_bridge's 57600 does not carry over); the handshake fails unless your sketch's "
            f"Serial.begin says {params.baud} too"
        )
    if params.url.startswith("emu://") and "camera" in parse_qs(urlsplit(params.url).query):
        out.append(
            "the url's camera= is not used: the ROS 2 node publishes no image topic "
            "(the camera is for roverlink console and roverlink follow)"
        )
    return out
