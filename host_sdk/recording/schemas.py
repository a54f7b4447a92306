"""The recording's channels: topics, JSON schemas, and SDK values turned into JSON messages.

Well-known Foxglove schemas carry what Foxglove draws by itself (the pose and path in the 3D
panel, transforms, log lines, scans and images); RoverLink's own values go on JSON
channels whose JSON schema names every field, so Foxglove's plot and raw-message panels can use
them (`/roverlink/wheels.speed_m_s[0]`). Nothing here imports foxglove: these are plain dicts.
"""

from __future__ import annotations

import dataclasses
import enum
import math
from typing import Any

from host_sdk import FeedbackSample, LinkStatistics
from host_sdk.enums import Status
from host_sdk.sensors import ImuSample

TOPIC_FEEDBACK = "/roverlink/feedback"
TOPIC_WHEELS = "/roverlink/wheels"
TOPIC_SETPOINT = "/roverlink/setpoint"
TOPIC_ODOMETRY = "/roverlink/odometry"
TOPIC_PATH = "/roverlink/path"
TOPIC_TF = "/tf"
TOPIC_LINK = "/roverlink/link"
TOPIC_LOG = "/roverlink/log"
TOPIC_SCAN = "/scan"
TOPIC_IMAGE = "/camera/image/compressed"
TOPIC_IMU = "/imu"
FRAME_ODOM = "odom"
FRAME_BASE = "base_link"
FRAME_LASER = "laser"
FRAME_IMU = "imu"
FRAME_CAMERA = "camera"
SENSOR_FRAMES = {"lidar": FRAME_LASER, "imu": FRAME_IMU, "camera": FRAME_CAMERA}
"""The frame of each kind of sensor (a child of base_link on /tf)."""

_NUMBER = {"type": "number"}
_INTEGER = {"type": "integer"}


def _array(item: dict[str, str]) -> dict[str, Any]:
    return {"type": "array", "items": item}


def _object(title: str, description: str, properties: dict[str, Any]) -> dict[str, Any]:
    return {
        "title": title,
        "description": description,
        "type": "object",
        "properties": properties,
        "required": sorted(properties),
    }


FEEDBACK_SCHEMA = _object(
    "roverlink.Feedback",
    "One FEEDBACK frame as the SDK decoded it (host_sdk.FeedbackSample), every field.",
    {
        "index": {**_INTEGER, "description": "FEEDBACK frames received by this robot object, this one included"},
        "boot_id": {**_INTEGER, "description": "the board's boot_id (a change is a reset)"},
        "received_s": {**_NUMBER, "description": "host clock when the frame arrived"},
        "host_time_s": {**_NUMBER, "description": "host clock of the MCU tick (time-synced)"},
        "mcu_time_us": {**_INTEGER, "description": "MCU clock at the tick, unwrapped"},
        "tick": {**_INTEGER, "description": "control tick, unwrapped"},
        "status": {**_INTEGER, "description": "status bits (Status flags)"},
        "status_flags": {**_array({"type": "string"}), "description": "names of the status bits set"},
        "failsafe_reason": {"type": "string", "description": "latched failsafe reason (NONE when not in failsafe)"},
        "encoder_counts": {**_array({"type": "integer"}), "description": "cumulative counts per wheel"},
        "wheel_speeds_m_s": {**_array({"type": "number"}), "description": "measured wheel rim speeds, m/s"},
        "efforts": {**_array({"type": "number"}), "description": "motor efforts, -1..1"},
        "steering_rad": {**_NUMBER, "description": "front-wheel angle commanded, rad"},
        "ack_seq": {**_INTEGER, "description": "seq of the last setpoint applied"},
        "pose": {
            "type": ["object", "null"],
            "description": "odometry after this sample (null without kinematics)",
            "properties": {
                name: _NUMBER for name in ("x_m", "y_m", "theta_rad", "linear_m_s", "angular_rad_s", "mcu_time_us")
            },
        },
    },
)

WHEELS_SCHEMA = _object(
    "roverlink.Wheels",
    "Per-wheel series to plot: measured speed and effort (index 0 = left or the only wheel).",
    {
        "speed_m_s": _array({"type": "number"}),
        "effort": _array({"type": "number"}),
        "steering_rad": _NUMBER,
        "saturated": {"type": "boolean"},
    },
)

SETPOINT_SCHEMA = _object(
    "roverlink.Setpoint",
    "What the program that records commanded (teleop, tune, follow): wheel rim speeds or speed and steering.",
    {"speed_m_s": _array({"type": "number"}), "steering_rad": _NUMBER},
)

_LINK_FIELDS = [f.name for f in dataclasses.fields(LinkStatistics) if f.name not in ("nacks", "rtt")]
LINK_SCHEMA = _object(
    "roverlink.LinkStats",
    "Both sides' link statistics: the host's counters (host_sdk.LinkStatistics), the board's LINK_STATS, "
    "and rates over the last interval.",
    {
        "host": {
            "type": "object",
            "properties": {
                **{name: _NUMBER for name in _LINK_FIELDS},
                "nacks": {"type": "object", "additionalProperties": _INTEGER},
                "rtt_ms": _NUMBER,
            },
        },
        "board": {"type": ["object", "null"], "additionalProperties": _INTEGER},
        "rates": {"type": "object", "additionalProperties": _NUMBER},
    },
)

_NUMBERS_OR_NULL = {"type": ["array", "null"], "items": _NUMBER}
IMU_SCHEMA = {
    **_object(
        "roverlink.Imu",
        "An IMU output period as the driver decoded it (host_sdk.sensors.ImuSample), in the module's "
        "body frame (x forward, y left, z up); null: an output the module was not set to send.",
        {
            "frame_id": {"type": "string"},
            "orientation": {
                **_NUMBERS_OR_NULL,
                "description": "attitude quaternion x, y, z, w (the module's own, else from its angles)",
            },
            "angular_velocity": {**_NUMBERS_OR_NULL, "description": "rad/s about x, y, z"},
            "linear_acceleration": {**_NUMBERS_OR_NULL, "description": "m/s^2, gravity included (+9.81 on z)"},
            "angles_rad": {**_NUMBERS_OR_NULL, "description": "roll, pitch, yaw from the module's filter"},
            "magnetic_field": {**_NUMBERS_OR_NULL, "description": "the magnetometer, in the module's units (mG)"},
            "temperature_c": {"type": ["number", "null"]},
        },
    ),
    "required": ["angular_velocity", "frame_id", "linear_acceleration", "orientation"],
}


def _plain(value: Any) -> Any:
    """A JSON-ready copy: enums by name, flags as their integer, tuples as lists, NaN as None."""
    if isinstance(value, enum.Flag):
        return int(value.value)
    if isinstance(value, enum.Enum):
        return value.name
    if isinstance(value, (tuple, list)):
        return [_plain(v) for v in value]
    if isinstance(value, float) and not math.isfinite(value):
        return None
    if dataclasses.is_dataclass(value) and not isinstance(value, type):
        return {f.name: _plain(getattr(value, f.name)) for f in dataclasses.fields(value)}
    return value


def feedback_message(sample: FeedbackSample) -> dict[str, Any]:
    """Every field of a FeedbackSample, plus the status bits by name."""
    message: dict[str, Any] = {f.name: _plain(getattr(sample, f.name)) for f in dataclasses.fields(sample)}
    message["status_flags"] = [flag.name for flag in type(sample.status) if flag in sample.status and flag.name]
    return message


def wheels_message(sample: FeedbackSample) -> dict[str, Any]:
    return {
        "speed_m_s": list(sample.wheel_speeds_m_s),
        "effort": list(sample.efforts),
        "steering_rad": sample.steering_rad,
        "saturated": bool(sample.status & Status.SATURATED),
    }


def link_message(host: LinkStatistics, board: dict[str, int] | None, rates: dict[str, float]) -> dict[str, Any]:
    host_part: dict[str, Any] = {name: _plain(getattr(host, name)) for name in _LINK_FIELDS}
    host_part["nacks"] = dict(host.nacks)
    host_part["rtt_ms"] = host.rtt.last_s * 1000 if host.rtt is not None else None
    return {"host": host_part, "board": board, "rates": rates}


def imu_message(sample: ImuSample, frame_id: str = FRAME_IMU) -> dict[str, Any]:
    """An ImuSample as a roverlink.Imu message."""
    if sample.quaternion is not None:
        w, x, y, z = sample.quaternion
        orientation: list[float] | None = [x, y, z, w]
    elif sample.angle is not None:
        orientation = list(_quaternion_xyzw(*sample.angle))
    else:
        orientation = None
    return {
        "frame_id": frame_id,
        "orientation": orientation,
        "angular_velocity": _plain(sample.gyro),
        "linear_acceleration": _plain(sample.accel),
        "angles_rad": _plain(sample.angle),
        "magnetic_field": _plain(sample.mag),
        "temperature_c": sample.temperature_c,
    }


def _quaternion_xyzw(roll: float, pitch: float, yaw: float) -> tuple[float, float, float, float]:
    """(x, y, z, w) of Z-Y-X Euler angles."""
    cr, sr = math.cos(roll / 2), math.sin(roll / 2)
    cp, sp = math.cos(pitch / 2), math.sin(pitch / 2)
    cy, sy = math.cos(yaw / 2), math.sin(yaw / 2)
    return (
        sr * cp * cy - cr * sp * sy,
        cr * sp * cy + sr * cp * sy,
        cr * cp * sy - sr * sp * cy,
        cr * cp * cy + sr * sp * sy,
    )
