"""Which sensors a command reads: named on the command line, or those an `emu://` URL attached.

    roverlink record /dev/ttyACM0 -o run.mcap --lidar /dev/ttyUSB0 --lidar-model rplidar-a1 \\
        --imu /dev/ttyUSB1 --camera libcamera
    roverlink record "emu://picar?lidar=ydlidar-f4&imu=jy901&camera=1" -o run.mcap   # no options needed

An `emu://` robot lists the devices its URL attached in `robot.transport.endpoints`; they are used
unless `--no-sensors` is given, and an option names a device instead of the URL's. A lidar's model
decides its protocol: `--lidar-model`, else the emulated device's, else the lidar the robot's
reference profile carries (protocol/spec/sensors.toml), else rplidar-a1.
"""

from __future__ import annotations

import argparse
from collections.abc import Sequence
from dataclasses import dataclass

from host_sdk import Robot
from host_sdk.profiles import profile_for_example
from host_sdk.sensors.hub import Sensors, short_source
from host_sdk.sensors.imu import DEFAULT_BAUD
from host_sdk.sensors.lidar import MODELS
from protocol.sensors import ROBOT_SENSORS
from roverlink.argtypes import BAUD
from roverlink.emulated import emulator_of

KINDS = ("lidar", "imu", "camera")
CAMERA_HELP = (
    "picamera2[:N] (a Raspberry Pi camera on Raspberry Pi OS), a V4L2 device (/dev/video0, or its number), "
    "jetson-csi or libcamera (the usual GStreamer pipeline, with an OpenCV built with GStreamer; "
    "jetson-csi?flip=rotate-180 turns the picture), any GStreamer "
    "pipeline (text with '!'), an MJPEG URL (http://.../stream), or a video file or image folder to replay; "
    "`roverlink cameras` lists this machine's"
)


@dataclass(frozen=True, slots=True)
class SensorChoice:
    """The devices to open (None: not there)."""

    lidar: str | None = None
    lidar_model: str = MODELS[0]
    imu: str | None = None
    imu_baud: int = DEFAULT_BAUD
    camera: str | int | None = None

    def lines(self) -> list[str]:
        """One line per device: what it is and where."""
        out = []
        if self.lidar is not None:
            out.append(f"lidar {self.lidar_model} on {self.lidar}")
        if self.imu is not None:
            out.append(f"imu jy901 on {self.imu}")
        if self.camera is not None:
            out.append(f"camera {short_source(self.camera)}")
        return out


def add_sensor_args(p: argparse.ArgumentParser, kinds: Sequence[str] = KINDS, off: str = "--no-sensors") -> None:
    """--lidar, --lidar-model, --imu, --imu-baud, --camera (those of `kinds`) and `off`
    (--no-sensors: use none, not even those an emu:// URL attached)."""
    g = p.add_argument_group("sensors", "devices beside the board; an emu:// URL's own are used without these")
    if "lidar" in kinds:
        g.add_argument("--lidar", metavar="PORT", help="the lidar's serial port, e.g. /dev/ttyUSB0")
        g.add_argument(
            "--lidar-model",
            choices=MODELS,
            default=None,
            help="its protocol (default: the robot profile's lidar, else rplidar-a1)",
        )
    if "imu" in kinds:
        g.add_argument("--imu", metavar="PORT", help="the JY901's serial port, e.g. /dev/ttyUSB1")
        g.add_argument(
            "--imu-baud", type=BAUD, default=DEFAULT_BAUD, metavar="BAUD", help=f"its baud (default {DEFAULT_BAUD})"
        )
    if "camera" in kinds:
        g.add_argument("--camera", metavar="SOURCE", help=CAMERA_HELP)
    what = "sensors" if len(kinds) > 1 else {"imu": "IMU"}.get(kinds[0], kinds[0])
    g.add_argument(off, dest="no_sensors", action="store_true", help=f"use no {what}, not even an emu:// URL's")


def camera_source(text: str) -> str | int:
    """A --camera value as CameraSource takes it (a V4L2 device's number as an int)."""
    return int(text) if text.isdigit() else text


def choose_sensors(args: argparse.Namespace, robot: Robot, kinds: Sequence[str] = KINDS) -> SensorChoice:
    """The devices of `kinds` the command line names, completed with those the robot's emu:// URL
    attached."""
    if getattr(args, "no_sensors", False):
        return SensorChoice()
    attached = robot.transport.endpoints
    endpoints = {kind: url for kind, url in attached.items() if kind in kinds}
    lidar = getattr(args, "lidar", None) or endpoints.get("lidar")
    imu = getattr(args, "imu", None) or endpoints.get("imu")
    camera_text = getattr(args, "camera", None)
    camera = camera_source(camera_text) if camera_text else endpoints.get("camera")
    model = getattr(args, "lidar_model", None)
    if lidar is not None and model is None:
        model = (_emulated(robot, "lidar") if lidar == endpoints.get("lidar") else None) or _profile_lidar(robot)
    return SensorChoice(
        lidar=lidar,
        lidar_model=model or MODELS[0],
        imu=imu,
        imu_baud=getattr(args, "imu_baud", DEFAULT_BAUD),
        camera=camera,
    )


def open_sensors(choice: SensorChoice) -> Sensors:
    """Open the chosen devices (host_sdk.sensors.Sensors.open)."""
    return Sensors.open(lidar=choice.lidar, lidar_model=choice.lidar_model, imu=choice.imu,
                        imu_baud=choice.imu_baud, camera=choice.camera)  # fmt: skip


def _emulated(robot: Robot, kind: str) -> str | None:
    """The model of the device of `kind` an emu:// robot's URL attached."""
    with emulator_of(robot) as emu:
        rig = getattr(emu, "sensors", None)
        device = rig.devices.get(kind) if rig is not None else None
        return str(device.spec.name) if device is not None else None


def _profile_name(robot: Robot) -> str | None:
    name = robot.transport.profile
    if name is None:
        profile = profile_for_example(robot.identity.robot_name)
        name = profile.name if profile is not None else None
    return name


def _profile_lidar(robot: Robot) -> str | None:
    """The lidar the robot's reference profile carries (sensors.toml), if any."""
    body = ROBOT_SENSORS.get(_profile_name(robot) or "")
    mount = body.mount("lidar") if body is not None else None
    return mount.device if mount is not None and mount.device in MODELS else None
