"""Reading a device beside the robot's loop: a thread on a real port, `poll()` on a virtual clock.

A real port is read by a thread of its own, so every sample is stamped when it arrives whatever
the program's loop does, and a camera's blocking capture never holds that loop up. A device on an
emulator's virtual clock (an `emudev://` endpoint of an `emu://...?clock=virtual` robot) cannot
have a thread: reading it is what moves the emulator's time, which belongs to the loop that drives
the robot; `poll()` reads it there, and does nothing for a threaded reader.

A device that fails (unplugged, closed) stops being read and `error` says why; a timeout (a capture
device with no frame this time) is not a failure.
"""

from __future__ import annotations

import threading
from collections.abc import Callable, Sequence
from typing import Generic, TypeVar

from host_sdk.errors import RoverLinkError
from host_sdk.sensors.camera import CameraFrame, CameraSource
from host_sdk.sensors.errors import SensorTimeoutError

T = TypeVar("T")
READ_SLICE_S = 0.05
"""How long a reading thread waits for bytes before it looks at its stop flag again."""


class DeviceReader(Generic[T]):
    """`pump(timeout_s)` returns what arrived; each item goes to `deliver` (on the reading thread)."""

    def __init__(
        self, name: str, pump: Callable[[float], Sequence[T]], deliver: Callable[[T], None], *, threaded: bool
    ) -> None:
        self.name = name
        self.threaded = threaded
        self.error: str | None = None
        self._pump = pump
        self._deliver = deliver
        self._stop = threading.Event()
        self._thread: threading.Thread | None = None

    def start(self) -> None:
        if self.threaded and self._thread is None:
            self._thread = threading.Thread(target=self._run, name=f"roverlink-{self.name}", daemon=True)
            self._thread.start()

    def poll(self) -> None:
        """Read what is there now (a reader on a virtual clock); nothing for a threaded one."""
        if not self.threaded and self.error is None:
            self._once(0.0)

    def _once(self, timeout_s: float) -> None:
        try:
            items = self._pump(timeout_s)
        except SensorTimeoutError:
            return
        except (RoverLinkError, OSError) as exc:
            self.error = f"{self.name}: {exc}"
            return
        for item in items:
            self._deliver(item)

    def _run(self) -> None:
        while not self._stop.is_set() and self.error is None:
            self._once(READ_SLICE_S)

    def stop(self) -> None:
        self._stop.set()
        if self._thread is not None:
            self._thread.join(timeout=2.0)


class FrameGrabber:
    """The newest camera frame without waiting. A byte-stream source queues its frames (the
    emulator's in-process camera): take the newest. An OpenCV capture blocks in `read()` until the
    next frame, up to a frame period, or longer when the camera stalls: read it on a thread."""

    def __init__(self, camera: CameraSource) -> None:
        self.camera = camera
        self._frame: CameraFrame | None = None
        self._lock = threading.Lock()
        self._reader: DeviceReader[CameraFrame] | None = None
        if not camera.queued:
            self._reader = DeviceReader("camera", camera.poll, self._keep, threaded=True)
            self._reader.start()

    def _keep(self, frame: CameraFrame) -> None:
        with self._lock:
            self._frame = frame

    @property
    def error(self) -> str | None:
        """Why the camera stopped being read (None: it is read)."""
        return self._reader.error if self._reader is not None else None

    def latest(self) -> CameraFrame | None:
        """The newest frame not taken before (None: none came since)."""
        if self._reader is None:
            return self.camera.latest()
        with self._lock:
            frame, self._frame = self._frame, None
        return frame

    def close(self) -> None:
        if self._reader is not None:
            self._reader.stop()
