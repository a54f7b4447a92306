"""`emudev://KEY/KIND`: the sensors of an in-process emulator, as byte pipes the SDK's drivers open.

An `emu://...?lidar=rplidar-a1&imu=jy901&camera=1` transport registers its sensors here and lists
their URLs in `transport.endpoints`; the SDK opens them through the `roverlink.transports` entry
point `emudev` like any other port, so robot code is the same for a real robot and an emulated one.
The endpoint shares the emulator's clock and lock with the board's transport: on the virtual clock,
waiting for lidar bytes runs the emulator exactly as waiting for feedback does.

A camera endpoint carries the camera's MJPEG parts (emulator.sensors.mjpeg). With a camera in a
world that has a target, a `target` endpoint carries one part: the target's picture, as a user would
photograph it for the tracker (emulator.sensors.target). Frames wait in a
buffer of BUFFERED_FRAMES, as in a V4L2 driver's queue: a reader that falls behind loses the oldest
(it sees the gap in the frame counter).
"""

from __future__ import annotations

import math
from collections import deque
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any, Protocol
from urllib.parse import urlsplit

from emulator.device import Emulator
from emulator.errors import EmulatorValueError
from emulator.sensors.camera import MAX_DISTRACTORS
from emulator.sensors.mjpeg import CameraDevice, Frame
from emulator.sensors.rig import IMUS, LIDARS, SensorRig, attach, camera_options
from emulator.sensors.target import render_target
from protocol.errors import import_optional

SENSOR_PARAMS = ("world", "lidar", "lidar_hz", "imu", "camera", "look", "distractors")
BUFFERED_FRAMES = 4
TARGET = "target"


class _Transport(Protocol):
    emulator: Emulator
    virtual: bool
    endpoints: dict[str, str]

    def read_from(self, source: Callable[[], bytes], timeout_s: float) -> bytes: ...

    def locked(self) -> Any: ...

    def clock(self) -> float: ...


@dataclass(frozen=True, slots=True)
class SensorOptions:
    world: str | None = None
    lidar: str | None = None
    lidar_hz: float | None = None
    imu: str | None = None
    camera: str | None = None
    """None, or WIDTHxHEIGHT."""
    look: str = "plain"
    """The camera's look: plain or photo (emulator/sensors/photo.py)."""
    distractors: int | None = None

    def attach(self, emu: Emulator, seed: int) -> None:
        opts = camera_options(self.camera, look=self.look, distractors=self.distractors) if self.camera else False
        # A lidar or a camera needs something to see: a random room by default. An IMU alone does
        # not, and a room's walls would stop a robot driven for calibration: an open floor.
        world = self.world or (f"random:{seed}" if self.lidar or self.camera else "empty")
        attach(emu, world, lidar=self.lidar, imu=self.imu, camera=opts, lidar_hz=self.lidar_hz)


def sensor_options(values: dict[str, str | None]) -> SensorOptions | None:
    """SensorOptions from URL/command-line values (None when none is given)."""
    if not any(values.get(k) for k in SENSOR_PARAMS):
        return None
    lidar, imu, camera = values.get("lidar"), values.get("imu"), values.get("camera")
    if lidar and lidar not in LIDARS:
        raise EmulatorValueError("lidar", lidar, " or ".join(LIDARS))
    if imu and imu not in IMUS:
        raise EmulatorValueError("imu", imu, " or ".join(IMUS))
    hz_text = values.get("lidar_hz")
    hz = None
    if hz_text:
        try:
            hz = float(hz_text)
        except ValueError:
            hz = math.nan
        if not math.isfinite(hz) or hz <= 0:
            raise EmulatorValueError("lidar_hz", hz_text, "a scan rate in Hz > 0")
    if camera in ("0", "false", ""):
        camera = None
    elif camera in ("1", "true"):
        camera = "320x240"
    look, distractors = _camera_look(values, camera)
    return SensorOptions(values.get("world") or None, lidar or None, hz, imu or None, camera, look, distractors)


def _camera_look(values: dict[str, str | None], camera: str | None) -> tuple[str, int | None]:
    """The camera's look and distractor count from URL/command-line values, checked."""
    look, text = values.get("look") or "plain", values.get("distractors") or None
    if look != "plain" and not camera:
        raise EmulatorValueError("camera look", look, "a camera to apply to (camera=WxH; --camera)")
    if text is not None and not camera:
        raise EmulatorValueError("camera distractors", text, "a camera to apply to (camera=WxH; --camera)")
    distractors = None
    if text is not None:
        try:
            distractors = int(text)
        except ValueError:
            raise EmulatorValueError("camera distractors", text, f"0..{MAX_DISTRACTORS}") from None
    if camera:
        camera_options(camera, look=look, distractors=distractors)  # checks the size, the look and the count
    return look, distractors


_REGISTRY: dict[str, _Transport] = {}


def register(transport: _Transport) -> dict[str, str]:
    """Make the transport's sensors reachable; returns their URLs by kind."""
    key = f"{id(transport):x}"
    _REGISTRY[key] = transport
    rig = transport.emulator.sensors
    kinds = list(rig.devices)
    if "camera" in rig.devices and rig.world.scene.target is not None:
        kinds.append(TARGET)
    return {kind: f"emudev://{key}/{kind}" for kind in kinds}


def unregister(transport: object) -> None:
    for key, value in list(_REGISTRY.items()):
        if value is transport:
            del _REGISTRY[key]


class DeviceEndpoint:
    """One sensor's byte pipe (duck-typed for host_sdk.transport.plugins)."""

    def __init__(self, url: str, transport: _Transport, kind: str) -> None:
        self.url = url
        self.virtual = transport.virtual
        self.transport = transport
        self.kind = kind
        rig = transport.emulator.sensors
        self.device = rig.devices[kind if kind != TARGET else "camera"]
        self._closed = False
        self._frames: deque[bytes] = deque(maxlen=BUFFERED_FRAMES)
        if kind == TARGET:
            self._frames.append(target_part(rig))
        elif isinstance(self.device, CameraDevice):
            self.device.listeners.append(self._on_frame)

    def _on_frame(self, frame: Frame) -> None:
        self._frames.append(frame.part())

    def _take(self) -> bytes:
        if isinstance(self.device, CameraDevice) or self.kind == TARGET:
            out = b"".join(self._frames)
            self._frames.clear()
            return out
        return bytes(self.device.host_read(self.transport.emulator.now_us))

    def read(self, timeout_s: float) -> bytes:
        if self._closed:
            raise OSError(f"{self.url} is closed")
        return self.transport.read_from(self._take, timeout_s)

    def write(self, data: bytes) -> None:
        if self._closed:
            raise OSError(f"{self.url} is closed")
        if isinstance(self.device, CameraDevice):
            return
        with self.transport.locked() as emu:
            self.device.host_write(data, emu.now_us)

    def clock(self) -> float:
        return self.transport.clock()

    def close(self) -> None:
        if not self._closed and isinstance(self.device, CameraDevice) and self.kind != TARGET:
            self.device.listeners.remove(self._on_frame)
        self._closed = True


def open_url(url: str, baud: int = 0) -> DeviceEndpoint:
    """The `roverlink.transports` entry point for `emudev://`."""
    parts = urlsplit(url)
    transport = _REGISTRY.get(parts.netloc)
    kind = parts.path.strip("/")
    if parts.scheme != "emudev" or transport is None:
        raise EmulatorValueError("url", url, "the emudev:// URL of a sensor of an open emu:// transport")
    if kind not in transport.endpoints:
        raise EmulatorValueError("url", url, f"one of {', '.join(transport.endpoints.values())}")
    return DeviceEndpoint(url, transport, kind)


def target_part(rig: SensorRig) -> bytes:
    """The world's target as one MJPEG part (frame 1), rendered by the rig's camera model."""
    cv2 = import_optional("cv2", "vision", "the emulated camera")
    camera = rig.devices["camera"]
    look = camera.options.look if isinstance(camera, CameraDevice) else "plain"
    template = render_target(rig.world.scene, rig.mount_for("camera", "pi-camera-v2"), look=look)
    ok, jpeg = cv2.imencode(".jpg", template.image[..., :3], [cv2.IMWRITE_JPEG_QUALITY, 95])
    if not ok:
        raise OSError("the target's picture could not be encoded")
    return Frame(1, 0, jpeg.tobytes()).part()
