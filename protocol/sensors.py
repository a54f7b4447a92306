"""The host-side sensors' datasheet facts (spec/sensors.toml), and the types of a robot's mounts.

One file feeds both sides: the SDK's drivers (default sample rates, range limits) and the emulator's
models (the same numbers, plus noise), so a driver and the device it is tested against cannot
disagree about a fact. Where a robot carries its sensors is its robot file's ([sensors.*],
[footprint]; the reference robots': protocol.generated.profiles.ROBOT_SENSORS).

    >>> from protocol.sensors import DEVICES
    >>> DEVICES["rplidar-a1"].range_max_m
    12.0
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace
from importlib import resources
from typing import Any

from protocol.errors import RoverLinkError
from protocol.toml import tomllib

__all__ = [
    "DEVICES",
    "CameraSpec",
    "ImuSpec",
    "LidarSpec",
    "Mount",
    "RobotSensors",
    "SensorSpecError",
    "device",
]


class SensorSpecError(RoverLinkError, ValueError):
    """sensors.toml (or a mount built in code) breaks a rule; names the entry and the rule."""


@dataclass(frozen=True, slots=True)
class LidarSpec:
    name: str
    doc: str
    protocol: str
    """rplidar or ydlidar: the wire protocol."""
    baud: int
    range_min_m: float
    range_max_m: float
    scan_hz: float
    scan_hz_min: float
    scan_hz_max: float
    sample_rate_hz: float
    clockwise: bool
    range_sigma_m: float
    range_sigma_fraction: float
    model: int
    firmware: tuple[int, int]
    hardware: int
    express_sample_us: int = 0
    kind: str = "lidar"

    def range_sigma(self, range_m: float) -> float:
        """Standard deviation of one range reading at `range_m`."""
        return max(self.range_sigma_m, self.range_sigma_fraction * range_m)


@dataclass(frozen=True, slots=True)
class ImuSpec:
    name: str
    doc: str
    protocol: str
    baud: int
    rate_hz: float
    outputs: tuple[str, ...]
    accel_range_g: float
    gyro_range_dps: float
    accel_sigma_g: float
    gyro_sigma_dps: float
    gyro_bias_dps: float
    gyro_bias_walk_dps: float
    mag_field_mg: float
    mag_sigma_mg: float
    heading_filter_s: float
    angle_sigma_deg: float
    heading_sigma_deg: float
    """Accuracy of the module's own yaw (9-axis, magnetometer calibrated)."""
    kind: str = "imu"


@dataclass(frozen=True, slots=True)
class CameraSpec:
    name: str
    doc: str
    protocol: str
    hfov_deg: float
    vfov_deg: float
    width: int
    height: int
    fps: float
    sizes: tuple[tuple[int, int], ...]
    kind: str = "camera"


DeviceSpec = LidarSpec | ImuSpec | CameraSpec
DEFAULT_DEVICES = {"lidar": "rplidar-a1", "imu": "jy901", "camera": "pi-camera-v2"}
"""The device of each kind a robot that carries none gets (in the emulator, and for its geometry)."""


@dataclass(frozen=True, slots=True)
class Mount:
    """Where a device sits on the robot (REP-103, relative to the pose point)."""

    device: str
    name: str
    """lidar, imu or camera: how robot code asks for it."""
    x_m: float = 0.0
    y_m: float = 0.0
    z_m: float = 0.0
    yaw_deg: float = 0.0

    @property
    def yaw_rad(self) -> float:
        return math.radians(self.yaw_deg)


@dataclass(frozen=True, slots=True)
class RobotSensors:
    profile: str
    footprint_radius_m: float
    footprint_x_m: float
    mounts: tuple[Mount, ...]

    def mount(self, name: str) -> Mount | None:
        return next((m for m in self.mounts if m.name == name), None)

    def placed(self, name: str, device: str | None = None) -> Mount:
        """Where the robot carries its `name` device, or where a device of that kind is put when it
        carries none (both the SDK and the emulator use these spots): the lidar on top of the pose
        point, the IMU on it, the camera at the front of the footprint. `device` names the device
        put there (default: the carried one, else the kind's usual: rplidar-a1, jy901, pi-camera-v2)."""
        found = self.mount(name)
        if found is not None:
            return found if device is None else replace(found, device=device)
        front = self.footprint_x_m + 0.8 * self.footprint_radius_m
        x, z = {"lidar": (0.0, 0.2), "imu": (0.0, 0.05), "camera": (front, 0.12)}[name]
        return Mount(device or DEFAULT_DEVICES[name], name, x, 0.0, z, 0.0)


_KINDS: dict[str, type[LidarSpec] | type[ImuSpec] | type[CameraSpec]] = {
    "lidar": LidarSpec,
    "imu": ImuSpec,
    "camera": CameraSpec,
}


def _device(name: str, table: dict[str, Any]) -> DeviceSpec:
    kind = table.get("kind")
    cls = _KINDS.get(str(kind))
    if cls is None:
        raise SensorSpecError(f"sensors.toml devices.{name}: kind = {kind!r} is not one of {', '.join(_KINDS)}")
    values = {k: v for k, v in table.items() if k != "kind"}
    for key in ("firmware", "outputs"):
        if key in values:
            values[key] = tuple(values[key])
    if "sizes" in values:
        values["sizes"] = tuple(tuple(s) for s in values["sizes"])
    try:
        spec = cls(name=name, **values)
    except TypeError as exc:
        raise SensorSpecError(f"sensors.toml devices.{name}: {exc}") from None
    return spec


def _load() -> dict[str, DeviceSpec]:
    text = resources.files("protocol").joinpath("spec/sensors.toml").read_text(encoding="utf-8")
    data = tomllib.loads(text)
    return {name: _device(name, table) for name, table in data["devices"].items()}


DEVICES = _load()
"""Every device by name (rplidar-a1, ydlidar-f4, jy901, pi-camera-v2). Where a robot carries
which: its robot file's [sensors.*] (the reference robots': protocol.generated.profiles.ROBOT_SENSORS)."""


def device(name: str, kind: str | None = None) -> DeviceSpec:
    """The device called `name` (of `kind`, if given); SensorSpecError lists the choices."""
    spec = DEVICES.get(name)
    if spec is None or (kind is not None and spec.kind != kind):
        choices = [n for n, d in DEVICES.items() if kind is None or d.kind == kind]
        raise SensorSpecError(f"{kind or 'device'} {name!r} is not one of {', '.join(choices)}")
    return spec
