"""Which sensors a command reads: named on the command line, or those an `emu://` URL attached.

    roverlink record /dev/ttyACM0 -o run.mcap --lidar /dev/ttyUSB0 --lidar-model rplidar-a1 \\
        --imu /dev/ttyUSB1 --camera libcamera
    roverlink record "emu://picar?lidar=ydlidar-f4&imu=jy901&camera=1" -o run.mcap   # no options needed

Every command that reads sensors beside the board takes them the same way (`add_sensor_args`,
`sensors_for`), in this order: an option names a device; else an `emu://` robot's own (its URL
attached them: `robot.transport.endpoints`); else, on a real port, the `--robot FILE`'s
`[sensors.lidar] port`, `[sensors.imu] port` and `[sensors.camera] source`. `--no-sensors` uses
none. A lidar's model decides its protocol: `--lidar-model`, else the emulated device's, else the
robot file's, else the lidar the robot's reference profile carries (protocol/spec/sensors.toml),
else rplidar-a1; the IMU's baud: `--imu-baud`, else the file's `[sensors.imu] baud`, else the
JY901's default.
"""

from __future__ import annotations

import argparse
from collections.abc import Sequence
from dataclasses import dataclass, field

from host_sdk import Robot, RobotDescription, RoverLinkError
from host_sdk.profiles import profile_for_example
from host_sdk.sensors import hub
from host_sdk.sensors.errors import SensorOpenError
from host_sdk.sensors.hub import Sensors, short_source
from host_sdk.sensors.imu import DEFAULT_BAUD, Jy901
from host_sdk.sensors.lidar import MODELS, Lidar
from protocol.generated.profiles import ROBOT_SENSORS
from roverlink.argtypes import BAUD
from roverlink.emulated import emu_robot, emulator_of

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
    #: where a device came from when not from the command line: kind -> e.g. "[sensors.lidar] port in car.toml"
    origin: dict[str, str] = field(default_factory=dict)

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


def add_sensor_args(p: argparse.ArgumentParser, kinds: Sequence[str] = KINDS, off: str | None = "--no-sensors") -> None:
    """--lidar, --lidar-model, --imu, --imu-baud, --camera (those of `kinds`) and `off`
    (--no-sensors: use none, not even those an emu:// URL attached; None: no such option)."""
    g = p.add_argument_group(
        "sensors", "devices beside the board; without these an emu:// URL's own, else the --robot FILE's ports"
    )
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
            "--imu-baud",
            type=BAUD,
            default=None,
            metavar="BAUD",
            help=f"its baud (default: the robot file's [sensors.imu] baud, else {DEFAULT_BAUD})",
        )
    if "camera" in kinds:
        g.add_argument("--camera", metavar="SOURCE", help=CAMERA_HELP)
    if off is None:
        return
    what = "sensors" if len(kinds) > 1 else {"imu": "IMU"}.get(kinds[0], kinds[0])
    g.add_argument(off, dest="no_sensors", action="store_true", help=f"use no {what}, not even an emu:// URL's")


def camera_source(text: str) -> str | int:
    """A --camera value as CameraSource takes it (a V4L2 device's number as an int)."""
    return int(text) if text.isdigit() else text


def choose_sensors(args: argparse.Namespace, robot: Robot, kinds: Sequence[str] = KINDS) -> SensorChoice:
    """The devices of `kinds` the command line names, completed with those the robot's emu:// URL
    attached, else the --robot FILE's ports."""
    if getattr(args, "no_sensors", False):
        return SensorChoice()
    description = getattr(args, "robot", None)
    return sensors_for(
        robot,
        description if isinstance(description, RobotDescription) else None,
        kinds,
        lidar=getattr(args, "lidar", None),
        lidar_model=getattr(args, "lidar_model", None),
        imu=getattr(args, "imu", None),
        imu_baud=getattr(args, "imu_baud", None),
        camera=getattr(args, "camera", None),
    )


def sensors_for(
    robot: Robot,
    description: RobotDescription | None,
    kinds: Sequence[str] = KINDS,
    *,
    lidar: str | None = None,
    lidar_model: str | None = None,
    imu: str | None = None,
    imu_baud: int | None = None,
    camera: str | int | None = None,
) -> SensorChoice:
    """The devices of `kinds`: those given, else the emu:// robot's own, else (on a real port) the
    robot file's (module docstring)."""
    attached = {kind: url for kind, url in robot.transport.endpoints.items() if kind in kinds}
    own = description if description is not None and not robot.url.startswith("emu://") else None
    files = {
        "lidar": own.lidar.port if own is not None and own.lidar is not None else "",
        "imu": own.imu.port if own is not None and own.imu is not None else "",
        "camera": own.camera.source if own is not None and own.camera is not None else "",
    }
    files = {kind: port for kind, port in files.items() if kind in kinds}
    given = {"lidar": lidar, "imu": imu, "camera": camera}
    origin = {  # the devices that will come from the file: named by its key if they fail to open
        kind: f"[sensors.{kind}] {'source' if kind == 'camera' else 'port'} in {own.path}"
        for kind, port in files.items()
        if port and own is not None and not attached.get(kind) and given[kind] in (None, "")
    }
    lidar = lidar or attached.get("lidar") or files.get("lidar") or None
    imu = imu or attached.get("imu") or files.get("imu") or None
    if isinstance(camera, str):
        camera = camera_source(camera) if camera else None
    if camera is None:
        text = attached.get("camera") or files.get("camera") or None
        camera = camera_source(text) if text else None
    model = lidar_model
    if lidar is not None and model is None:
        if lidar == attached.get("lidar"):
            model = _emulated(robot, "lidar")
        elif description is not None and description.lidar is not None:
            model = description.lidar.model
        model = model or _profile_lidar(robot)
    baud = imu_baud or (description.imu.baud if description is not None and description.imu is not None else 0)
    return SensorChoice(
        lidar=lidar,
        lidar_model=model or MODELS[0],
        imu=imu,
        imu_baud=baud or DEFAULT_BAUD,
        camera=camera,
        origin=origin,
    )


EMULATED_SENSORS = {"lidar": "lidar=rplidar-a1", "camera": "camera=320x240", "imu": "imu=jy901"}
"""What an emu:// URL adds to attach each device (docs/emulator.md)."""


def require_sensors(choice: SensorChoice, kinds: Sequence[str], url: str | None = None) -> None:
    """RoverLinkError naming each of `kinds` the choice lacks and the three ways to give it; for an
    emu:// `url`, the URL with them added."""
    missing = [kind for kind in kinds if getattr(choice, kind) is None]
    if missing:
        ways = "; ".join(
            f"--{kind} {'SOURCE' if kind == 'camera' else 'PORT'}, "
            f"{'[sensors.camera] source' if kind == 'camera' else f'[sensors.{kind}] port'} in the --robot FILE, "
            f"or {kind}= in an emu:// URL"
            for kind in missing
        )
        hint = ""
        if url is not None and url.startswith("emu://"):
            lidar = _lidar_of(emu_robot(url) or "")
            own = {"lidar": f"lidar={lidar}"} if lidar is not None else {}
            added = "&".join({**EMULATED_SENSORS, **own}[kind] for kind in missing)
            hint = f" (here: '{url}{'&' if '?' in url else '?'}{added}', or no URL for the emulated robot with both)"
        raise RoverLinkError(f"no {' and no '.join(missing)} for this robot: give {ways}{hint}")


def open_sensors(choice: SensorChoice) -> Sensors:
    """Open the chosen devices (host_sdk.sensors.Sensors.open); a device that will not open and
    came from the robot file is named with the file's key, so the user knows what to change."""
    try:
        return Sensors.open(
            lidar=choice.lidar,
            lidar_model=choice.lidar_model,
            imu=choice.imu,
            imu_baud=choice.imu_baud,
            camera=choice.camera,
        )
    except SensorOpenError as exc:
        raise _from_file(choice, exc) from exc


def open_lidar(choice: SensorChoice) -> Lidar:
    """The chosen lidar, opened (the choice must have one); SensorOpenError as `open_sensors` says."""
    assert choice.lidar is not None
    try:
        return hub.open_lidar(choice.lidar, choice.lidar_model)
    except SensorOpenError as exc:
        raise _from_file(choice, exc) from exc


def open_imu(choice: SensorChoice) -> Jy901 | None:
    """The chosen IMU, opened (None when there is none); SensorOpenError as `open_sensors` says."""
    if choice.imu is None:
        return None
    try:
        return hub.open_imu(choice.imu, choice.imu_baud)
    except SensorOpenError as exc:
        raise _from_file(choice, exc) from exc


def _from_file(choice: SensorChoice, exc: SensorOpenError) -> SensorOpenError:
    """`exc`, naming the robot file's key when the device came from there."""
    where = choice.origin.get(exc.kind)
    return exc if where is None else SensorOpenError(f"{exc} (from {where})", exc.kind)


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
    """The lidar the robot's reference profile carries, if any."""
    return _lidar_of(_profile_name(robot) or "")


def _lidar_of(profile: str) -> str | None:
    """The lidar a reference robot carries (its robot file's [sensors.lidar]), if any."""
    body = ROBOT_SENSORS.get(profile)
    mount = body.mount("lidar") if body is not None else None
    return mount.device if mount is not None and mount.device in MODELS else None
