"""The host-side sensors a robot program reads beside the board, and what they last showed.

    sensors = Sensors.open(lidar="/dev/ttyUSB0", lidar_model="rplidar-a1", imu="/dev/ttyUSB1", camera=0)
    sensors.on_scan(print)              # LidarScan / ImuSample / CameraFrame, as the drivers deliver them
    sensors.start()                     # the lidar spins up and scans
    while running:
        robot.sleep(0.05)
        sensors.poll()                  # reads the devices on an emulator's virtual clock
    print(sensors.status())             # rates, point counts, nearest obstacle, yaw, fps, drops
    sensors.close()

Each device is read by a `DeviceReader` (host_sdk.sensors.reader): a thread of its own on a real
port, `poll()` on an emulator's virtual clock. Listeners are called on the reading thread.

A device that fails (unplugged, closed) stops being read; `status().errors` says why, and the
other devices and the robot carry on.
"""

from __future__ import annotations

import contextlib
import math
import threading
from collections import deque
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np

from host_sdk.errors import RoverLinkError, TransportError
from host_sdk.extras import require
from host_sdk.sensors.camera import CameraFrame, CameraSource
from host_sdk.sensors.errors import SensorOpenError, SensorTimeoutError
from host_sdk.sensors.imu import DEFAULT_BAUD, Jy901
from host_sdk.sensors.lidar import Lidar
from host_sdk.sensors.reader import DeviceReader
from host_sdk.sensors.scan import LidarScan
from host_sdk.sensors.wit import ImuSample

RATE_WINDOW_S = 2.0


class _Rate:
    """Events per second over the last RATE_WINDOW_S of their own timestamps. Events read in a
    batch share its arrival time: those of the window's first batch arrived before the window's
    span began, so they are not counted in it."""

    def __init__(self) -> None:
        self._times: deque[float] = deque()

    def add(self, t: float) -> None:
        self._times.append(t)
        while self._times and self._times[0] < t - RATE_WINDOW_S:
            self._times.popleft()

    @property
    def hz(self) -> float | None:
        if len(self._times) < 2:
            return None
        first = self._times[0]
        span = self._times[-1] - first
        in_span = len(self._times) - sum(1 for t in self._times if t == first)
        return in_span / span if span > 0 else None


@dataclass(frozen=True, slots=True)
class LidarStatus:
    model: str
    url: str
    scans: int
    rate_hz: float | None
    points: int
    """Points in the last revolution."""
    valid: int
    """Of which returns (the others: too near, too far, too dark)."""
    nearest_m: float | None
    nearest_bearing_deg: float | None
    """Where the nearest return was, counter-clockwise from the lidar's front."""
    errors: int
    """Framing and checksum errors so far."""


@dataclass(frozen=True, slots=True)
class ImuStatus:
    url: str
    samples: int
    rate_hz: float | None
    angles_deg: tuple[float, float, float] | None
    """roll, pitch, yaw of the last sample."""
    rates_dps: tuple[float, float, float] | None
    """Angular velocity about x, y, z of the last sample."""
    errors: int


@dataclass(frozen=True, slots=True)
class CameraStatus:
    source: str
    frames: int
    fps: float | None
    dropped: int
    size: tuple[int, int] | None
    """width, height of the last frame."""


@dataclass(frozen=True, slots=True)
class SensorStatus:
    lidar: LidarStatus | None = None
    imu: ImuStatus | None = None
    camera: CameraStatus | None = None
    errors: tuple[str, ...] = ()
    """Devices that stopped being read, and why."""


def open_lidar(url: str, model: str = "rplidar-a1") -> Lidar:
    """`Lidar.open`, with a port that will not open as SensorOpenError naming the lidar (kind "lidar")."""
    try:
        return Lidar.open(url, model)
    except (TransportError, SensorTimeoutError, OSError) as exc:
        raise SensorOpenError(f"lidar {model} on {url}: {exc}", "lidar") from exc


def open_imu(url: str, baud: int = DEFAULT_BAUD) -> Jy901:
    """`Jy901.open`, with a port that will not open as SensorOpenError naming the IMU (kind "imu")."""
    try:
        return Jy901.open(url, baud)
    except (TransportError, SensorTimeoutError, OSError) as exc:
        raise SensorOpenError(f"imu jy901 on {url} at {baud} baud: {exc}", "imu") from exc


class Sensors:
    """A lidar, an IMU and a camera (any of them None), read together; see the module docstring."""

    def __init__(
        self, *, lidar: Lidar | None = None, imu: Jy901 | None = None, camera: CameraSource | None = None
    ) -> None:
        self.lidar = lidar
        self.imu = imu
        self.camera = camera
        self._lock = threading.Lock()
        self._listeners: dict[str, list[Callable[[Any], None]]] = {"scan": [], "imu": [], "frame": []}
        self._readers: list[DeviceReader[Any]] = []
        self._started = False
        self._closed = False
        self._last_scan: LidarScan | None = None
        self._last_imu: ImuSample | None = None
        self._last_frame: CameraFrame | None = None
        self._counts = {"scan": 0, "imu": 0, "frame": 0}
        self._rates = {"scan": _Rate(), "imu": _Rate(), "frame": _Rate()}

    @classmethod
    def open(
        cls,
        *,
        lidar: str | None = None,
        lidar_model: str = "rplidar-a1",
        imu: str | None = None,
        imu_baud: int = DEFAULT_BAUD,
        camera: str | int | None = None,
    ) -> Sensors:
        """Open the devices given by URL (None: not there). SensorOpenError names the one that failed
        (those already open are closed again); the camera needs OpenCV (the `vision` extra:
        MissingDependencyError says so)."""
        sensors = cls()
        try:
            if lidar is not None:
                sensors.lidar = open_lidar(lidar, lidar_model)
            if imu is not None:
                sensors.imu = open_imu(imu, imu_baud)
            if camera is not None:
                require("cv2", "vision", "the camera")
                try:
                    sensors.camera = CameraSource(camera)
                except (TransportError, SensorTimeoutError, OSError) as exc:
                    raise SensorOpenError(f"camera on {short_source(camera)}: {exc}", "camera") from exc
        except BaseException:
            sensors.close()
            raise
        return sensors

    @property
    def empty(self) -> bool:
        return self.lidar is None and self.imu is None and self.camera is None

    def kinds(self) -> list[str]:
        """lidar, imu, camera: the devices present."""
        present = (("lidar", self.lidar), ("imu", self.imu), ("camera", self.camera))
        return [kind for kind, dev in present if dev is not None]

    # -- listeners ---------------------------------------------------------------------------------
    def _subscribe(self, kind: str, callback: Callable[[Any], None]) -> Callable[[], None]:
        with self._lock:
            self._listeners[kind].append(callback)

        def unsubscribe() -> None:
            with self._lock, contextlib.suppress(ValueError):
                self._listeners[kind].remove(callback)

        return unsubscribe

    def on_scan(self, callback: Callable[[LidarScan], None]) -> Callable[[], None]:
        """Call `callback(scan)` for every whole revolution; returns the unsubscribe function."""
        return self._subscribe("scan", callback)

    def on_imu(self, callback: Callable[[ImuSample], None]) -> Callable[[], None]:
        """Call `callback(sample)` for every IMU output period."""
        return self._subscribe("imu", callback)

    def on_frame(self, callback: Callable[[CameraFrame], None]) -> Callable[[], None]:
        """Call `callback(frame)` for every camera frame."""
        return self._subscribe("frame", callback)

    def _deliver(self, kind: str, event: Any, t: float) -> None:
        with self._lock:
            self._counts[kind] += 1
            self._rates[kind].add(t)
            if kind == "scan":
                self._last_scan = event
            elif kind == "imu":
                self._last_imu = event
            else:
                self._last_frame = event
            listeners = list(self._listeners[kind])
        for callback in listeners:
            callback(event)

    # -- reading -----------------------------------------------------------------------------------
    def start(self) -> None:
        """Start the lidar scanning and the reading threads of the devices on real ports. What the
        IMU and the camera sent before is dropped: it would carry the time it was read, not taken."""
        if self._started:
            return
        self._started = True
        if self.imu is not None:
            self.imu.poll(0.0)
        if self.camera is not None and self.camera.virtual:  # (a capture device's read would block)
            self.camera.poll(0.0)
        if self.lidar is not None:
            lidar = self.lidar
            if lidar.is_rplidar:
                with contextlib.suppress(SensorTimeoutError):
                    lidar.sample_rate()  # the device's own sample period times the points
            lidar.start()
            self._readers.append(
                DeviceReader(
                    "lidar", lidar.poll, lambda s: self._deliver("scan", s, s.time_s), threaded=not lidar.port.virtual
                )
            )
        if self.imu is not None:
            imu = self.imu
            self._readers.append(
                DeviceReader("imu", imu.poll, lambda s: self._deliver("imu", s, s.t), threaded=not imu.port.virtual)
            )
        if self.camera is not None:
            camera = self.camera
            self._readers.append(
                DeviceReader(
                    "camera",
                    camera.poll,
                    lambda f: self._deliver("frame", f, _frame_time(f)),
                    threaded=not camera.virtual,
                )
            )
        for reader in self._readers:
            reader.start()

    def poll(self) -> None:
        """Read the devices on a virtual clock (the others have threads). Cheap when nothing came."""
        for reader in self._readers:
            reader.poll()

    @property
    def virtual(self) -> bool:
        """True when some device is read by `poll()` (call it at least every 100 ms: an emulated
        camera keeps only a few frames, as a V4L2 queue does)."""
        return any(not r.threaded for r in self._readers)

    # -- what they show ----------------------------------------------------------------------------
    def status(self) -> SensorStatus:
        with self._lock:
            scan, sample, frame = self._last_scan, self._last_imu, self._last_frame
            counts = dict(self._counts)
            rates = {kind: rate.hz for kind, rate in self._rates.items()}
        errors = tuple(r.error for r in self._readers if r.error is not None)
        return SensorStatus(
            lidar=self._lidar_status(scan, counts["scan"], rates["scan"]) if self.lidar is not None else None,
            imu=self._imu_status(sample, counts["imu"], rates["imu"]) if self.imu is not None else None,
            camera=self._camera_status(frame, counts["frame"], rates["frame"]) if self.camera is not None else None,
            errors=errors,
        )

    def _lidar_status(self, scan: LidarScan | None, count: int, hz: float | None) -> LidarStatus:
        lidar = self.lidar
        assert lidar is not None
        c = lidar.counters
        nearest = bearing = None
        valid = 0
        if scan is not None and len(scan):
            ok = scan.valid
            valid = int(ok.sum())
            if valid:
                i = int(np.nanargmin(np.where(ok, scan.ranges_m, np.inf)))
                nearest, bearing = float(scan.ranges_m[i]), math.degrees(float(scan.angles_rad[i]))
        return LidarStatus(
            model=lidar.model,
            url=lidar.port.url,
            scans=count,
            rate_hz=hz,
            points=len(scan) if scan is not None else 0,
            valid=valid,
            nearest_m=nearest,
            nearest_bearing_deg=bearing,
            errors=c.framing_errors + c.checksum_errors,
        )

    def _imu_status(self, sample: ImuSample | None, count: int, hz: float | None) -> ImuStatus:
        imu = self.imu
        assert imu is not None
        angles = rates = None
        if sample is not None and sample.angle is not None:
            roll, pitch, yaw = (math.degrees(a) for a in sample.angle)
            angles = (roll, pitch, yaw)
        if sample is not None and sample.gyro is not None:
            gx, gy, gz = (math.degrees(w) for w in sample.gyro)
            rates = (gx, gy, gz)
        return ImuStatus(imu.port.url, count, hz, angles, rates, imu.counters.checksum_errors)

    def _camera_status(self, frame: CameraFrame | None, count: int, hz: float | None) -> CameraStatus:
        camera = self.camera
        assert camera is not None
        size = (int(frame.image.shape[1]), int(frame.image.shape[0])) if frame is not None else None
        return CameraStatus(str(camera.source), count, hz, camera.dropped, size)

    def close(self) -> None:
        """Stop reading, stop the lidar (best effort) and release every port. Idempotent."""
        if self._closed:
            return
        self._closed = True
        for reader in self._readers:
            reader.stop()
        if self.lidar is not None and self._started:
            with contextlib.suppress(RoverLinkError, OSError):
                self.lidar.stop()
        for device in (self.lidar, self.imu, self.camera):
            if device is not None:
                with contextlib.suppress(RoverLinkError, OSError):
                    device.close()

    def __enter__(self) -> Sensors:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()


def _frame_time(frame: CameraFrame) -> float:
    """The capture time when the stream carries one (its spacing is the camera's), else arrival."""
    return frame.device_time_s if frame.device_time_s is not None else frame.time_s


def short_source(source: str | int) -> str:
    """A device or pipeline for messages (a GStreamer pipeline can be long)."""
    text = str(source)
    return text if len(text) <= 48 else text[:45] + "..."
