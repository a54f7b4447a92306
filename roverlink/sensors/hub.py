"""The host-side sensors a bring-up tool reads beside the board, and what they last showed.

    sensors = Sensors(lidar=Lidar.open(...), imu=Jy901.open(...), camera=CameraSource(...))
    sensors.on_scan(print)              # LidarScan / ImuSample / CameraFrame, as the drivers deliver them
    sensors.start()                     # the lidar spins up and scans
    while running:
        robot.sleep(0.05)
        sensors.poll()                  # reads the devices on an emulator's virtual clock
    print(sensors.status())             # rates, point counts, nearest obstacle, yaw, fps, drops
    sensors.close()

A real port is read by a thread of its own, so every sample is stamped when it arrives whatever
the program's loop does, and a camera's blocking capture never holds that loop up. A device on an
emulator's virtual clock (an `emudev://` endpoint of an `emu://...?clock=virtual` robot) cannot
have a thread: reading it is what moves the emulator's time, which belongs to the loop that
drives the robot; `poll()` reads it there, and does nothing for the threaded ones. Listeners are
called on the reading thread.

A device that fails (unplugged, closed) stops being read; `status().errors` says why, and the
other devices and the robot carry on.
"""

from __future__ import annotations

import contextlib
import math
import threading
from collections import deque
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from host_sdk import RoverLinkError
from host_sdk.sensors import CameraFrame, CameraSource, ImuSample, Jy901, Lidar, LidarScan, SensorTimeoutError

READ_SLICE_S = 0.05
"""How long a reading thread waits for bytes before it looks at its stop flag again."""
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


@dataclass
class _Reader:
    """One device's reading: `pump(timeout)` returns what arrived; a thread of its own, or `poll()`."""

    name: str
    pump: Callable[[float], Sequence[Any]]
    deliver: Callable[[Any], None]
    threaded: bool
    error: str | None = None
    _stop: threading.Event = field(default_factory=threading.Event)
    _thread: threading.Thread | None = None

    def start(self) -> None:
        if self.threaded and self._thread is None:
            self._thread = threading.Thread(target=self._run, name=f"roverlink-{self.name}", daemon=True)
            self._thread.start()

    def poll(self) -> None:
        if not self.threaded and self.error is None:
            self._once(0.0)

    def _once(self, timeout_s: float) -> None:
        try:
            events = self.pump(timeout_s)
        except SensorTimeoutError:
            return  # a capture device with no frame this time: try again
        except (RoverLinkError, OSError) as exc:
            self.error = f"{self.name}: {exc}"
            return
        for event in events:
            self.deliver(event)

    def _run(self) -> None:
        while not self._stop.is_set() and self.error is None:
            self._once(READ_SLICE_S)

    def stop(self) -> None:
        self._stop.set()
        if self._thread is not None:
            self._thread.join(timeout=2.0)


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
        self._readers: list[_Reader] = []
        self._started = False
        self._closed = False
        self._last_scan: LidarScan | None = None
        self._last_imu: ImuSample | None = None
        self._last_frame: CameraFrame | None = None
        self._counts = {"scan": 0, "imu": 0, "frame": 0}
        self._rates = {"scan": _Rate(), "imu": _Rate(), "frame": _Rate()}

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
                _Reader("lidar", lidar.poll, lambda s: self._deliver("scan", s, s.time_s), not lidar.port.virtual)
            )
        if self.imu is not None:
            imu = self.imu
            self._readers.append(_Reader("imu", imu.poll, lambda s: self._deliver("imu", s, s.t), not imu.port.virtual))
        if self.camera is not None:
            camera = self.camera
            self._readers.append(
                _Reader("camera", camera.poll, lambda f: self._deliver("frame", f, _frame_time(f)), not camera.virtual)
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
