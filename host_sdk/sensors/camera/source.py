"""`CameraSource`: one interface over every camera route; the route is chosen from the source."""

from __future__ import annotations

import re
from collections import deque
from pathlib import Path
from typing import Any
from urllib.parse import unquote, urlsplit

import numpy as np

from host_sdk.extras import require
from host_sdk.sensors.camera.frame import CameraBackend, CameraFrame, Capture
from host_sdk.sensors.camera.opencv import OpenCvBackend
from host_sdk.sensors.camera.picam import Picamera2Backend
from host_sdk.sensors.camera.pipelines import PIPELINES, gstreamer_pipeline
from host_sdk.sensors.camera.replay import ReplayBackend
from host_sdk.sensors.camera.stream import ByteStreamBackend, HttpMjpegBackend
from host_sdk.sensors.errors import SensorClosedError, SensorOpenError, SensorTimeoutError
from host_sdk.transport.plugins import open_plugin

PICAMERA2 = re.compile(r"picamera2(?::(\d+))?")
SHORTHAND = re.compile(rf"({'|'.join(re.escape(k) for k in PIPELINES)})(?::(\d+))?(?:\?flip=([a-z0-9-]+))?")
V4L2_PATHS = ("/dev/video", "/dev/v4l/")
"""/dev/videoN, and the stable names udev gives them (/dev/v4l/by-id/..., /dev/v4l/by-path/...)."""
SOURCES = (
    "picamera2[:N], a V4L2 device (N, /dev/videoN or /dev/v4l/by-id/...), libcamera or jetson-csi[:N][?flip=F] "
    "(GStreamer; F e.g. rotate-180), a GStreamer pipeline (text with '!'), an http:// MJPEG URL, another URL "
    "OpenCV opens (rtsp://...), or a video file or image folder (a path or file://)"
)


def open_backend(
    source: int | str, *, width: int | None, height: int | None, fps: float | None, timeout_s: float
) -> CameraBackend:
    """The backend for `source` (see SOURCES); errors name what is missing."""
    if isinstance(source, int) or source.isdigit():
        return OpenCvBackend(int(source), width=width, height=height, fps=fps, timeout_s=timeout_s)
    if match := PICAMERA2.fullmatch(source):
        return Picamera2Backend(int(match.group(1) or 0), width=width, height=height, fps=fps)
    if match := SHORTHAND.fullmatch(source):
        size = {"width": width or 640, "height": height or 480, "fps": round(fps or 30)}
        flip = match.group(3) or "none"
        try:
            pipeline = gstreamer_pipeline(match.group(1), **size, sensor=int(match.group(2) or 0), flip=flip)
        except ValueError as exc:
            raise SensorOpenError(f"camera {source}: {exc}") from None
        return OpenCvBackend(pipeline, width=None, height=None, fps=fps, timeout_s=timeout_s)
    scheme = urlsplit(source).scheme if "://" in source else ""
    if scheme in ("http", "https"):
        return HttpMjpegBackend(source, fps=fps, timeout_s=timeout_s)
    if scheme == "file" or (not scheme and Path(source).exists() and not source.startswith("/dev/")):
        path = Path(unquote(urlsplit(source).path)) if scheme == "file" else Path(source)
        if not path.exists():
            raise SensorOpenError(f"camera {source}: no such file or folder")
        return ReplayBackend(path, fps=fps)
    if scheme and (port := open_plugin(source, 0)) is not None:  # a plugin's byte stream (emudev://)
        return ByteStreamBackend(port)
    if scheme or "!" in source or source.startswith(V4L2_PATHS):
        return OpenCvBackend(source, width=width, height=height, fps=fps, timeout_s=timeout_s)
    raise SensorOpenError(f"camera {source!r}: not a source this can open, nor an existing file: {SOURCES}")


class CameraSource:
    """Frames from any route (module docstring), with capture times and dropped-frame counts."""

    def __init__(
        self,
        source: int | str,
        *,
        width: int | None = None,
        height: int | None = None,
        fps: float | None = None,
        timeout_s: float = 5.0,
    ) -> None:
        self.source = source
        self.frames = 0
        self.dropped_gaps = 0
        self.bad_frames = 0
        self._last_time: float | None = None
        self._last_counter: int | None = None
        self._closed = False
        self._pending: deque[Capture] = deque()
        self._cv2: Any = None
        self._backend = open_backend(source, width=width, height=height, fps=fps, timeout_s=timeout_s)
        self.fps = self._backend.fps or fps
        if self._backend.queued:  # JPEG parts: decoded here, so say now if OpenCV is missing
            try:
                self._cv2 = require("cv2", "vision", "the camera")
            except BaseException:
                self._backend.close()
                raise

    @property
    def detail(self) -> str:
        """The route and what the device gave: size, format, rate (it may differ from what was asked)."""
        return self._backend.detail

    @property
    def dropped(self) -> int:
        """Frames missed: the stream counter's gaps, gaps over 1.5 periods, frames a full queue let go."""
        return self.dropped_gaps + self._backend.skipped

    def clock(self) -> float:
        return self._backend.clock()

    @property
    def virtual(self) -> bool:
        """True for an emulator's camera on its virtual clock: reading is what moves time, so read
        it from the loop that owns the emulator (no thread)."""
        return self._backend.virtual

    @property
    def queued(self) -> bool:
        """True when frames queue up to be taken (an MJPEG stream: `latest()` never waits); False for
        a capture device (V4L2, GStreamer, picamera2, a replay), whose `read()` waits for the next."""
        return self._backend.queued

    def read(self, timeout_s: float = 1.0) -> CameraFrame:
        """The next frame; SensorTimeoutError when none arrives in time, SensorClosedError at the
        end of a stream or a replay."""
        self._check_open()
        backend = self._backend
        if not backend.queued:
            return self._deliver(backend.fetch(timeout_s)[0])
        deadline = backend.clock() + timeout_s
        while True:
            frame = self._decode_pending()
            if frame is not None:
                return frame
            left = deadline - backend.clock()
            if left <= 0:
                raise SensorTimeoutError(str(self.source), "camera frame", timeout_s, backend.heard())
            self._pending.extend(backend.fetch(min(left, 0.05)))

    def poll(self, timeout_s: float = 0.0) -> list[CameraFrame]:
        """The frames that arrived, oldest first. A queued source is read for at most `timeout_s`; a
        capture device has no non-blocking read, so this waits for its next frame (read such a
        camera from a thread of its own)."""
        self._check_open()
        if not self._backend.queued:
            return [self.read(max(timeout_s, 1.0))]
        self._pending.extend(self._backend.fetch(timeout_s))
        frames = []
        while (frame := self._decode_pending()) is not None:
            frames.append(frame)
        return frames

    def latest(self) -> CameraFrame | None:
        """The newest frame that has arrived, without waiting (None: nothing new); older ones waiting
        are skipped (and counted as dropped) without being decoded. A control loop reads this way.
        A capture source has no queue to look into: this is `read()`."""
        self._check_open()
        if not self._backend.queued:
            return self.read()
        self._pending.extend(self._backend.fetch(0.0))
        captures, self._pending = list(self._pending), deque()
        for capture in reversed(captures):
            frame = self._decoded(capture)
            if frame is not None:
                return frame
        return None

    def _check_open(self) -> None:
        if self._closed:
            raise SensorClosedError(f"{self.source}: the camera was closed")

    def _decode_pending(self) -> CameraFrame | None:
        """The oldest capture that decodes (one that does not is counted and skipped)."""
        while self._pending:
            frame = self._decoded(self._pending.popleft())
            if frame is not None:
                return frame
        return None

    def _decoded(self, capture: Capture) -> CameraFrame | None:
        if capture.jpeg is None or capture.image is not None:
            return self._deliver(capture)
        image = self._cv2.imdecode(np.frombuffer(capture.jpeg, dtype=np.uint8), self._cv2.IMREAD_COLOR)
        if image is None:
            self.bad_frames += 1
            return None
        return self._deliver(capture, image)

    def _deliver(self, capture: Capture, image: Any = None) -> CameraFrame:
        t, counter = capture.t, capture.counter
        if counter is not None and self._last_counter is not None:
            self.dropped_gaps += max(0, counter - self._last_counter - 1)
        elif counter is None and self._last_time is not None and self.fps:
            gap = (t - self._last_time) * self.fps
            if gap > 1.5:
                self.dropped_gaps += round(gap) - 1
        self._last_counter = counter
        self._last_time = t
        self.frames += 1
        image = capture.image if image is None else image
        return CameraFrame(image, t, self.frames, capture.device_t, capture.jpeg)

    def close(self) -> None:
        if self._closed:
            return
        self._closed = True
        self._backend.close()

    def __enter__(self) -> CameraSource:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()
