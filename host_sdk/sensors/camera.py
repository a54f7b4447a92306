"""Camera frames with capture timestamps and dropped-frame counts, over OpenCV.

    cam = CameraSource(0)                                    # /dev/video0 through V4L2
    cam = CameraSource(gstreamer_pipeline("libcamera"))      # Raspberry Pi camera (libcamerasrc)
    cam = CameraSource(gstreamer_pipeline("jetson-csi"))     # Jetson CSI camera (nvarguscamerasrc)
    cam = CameraSource("http://127.0.0.1:8081/stream.mjpg")  # a network camera, e.g. `roverlink emulate --camera`
    frame = cam.read()                                       # CameraFrame: BGR image, time_s, seq
    frames = cam.poll()                                      # every frame that arrived (streams: no wait)

OpenCV (`opencv-python-headless`, the `vision` extra) is imported when a source opens. Device
paths, GStreamer pipelines (any string with a `!`) and URLs go to `cv2.VideoCapture`; a URL whose
scheme a plugin registered (the emulator's `emudev://`, next to an `emu://` robot) is read as a
multipart JPEG byte stream and decoded with `cv2.imdecode`: the same frames either way.

`time_s` is when the frame was taken off the driver, on the source's clock (the host's monotonic
clock; an emulator's virtual clock in-process). Dropped frames are counted from the stream's frame
counter when it has one (`X-Frame`), otherwise from gaps longer than 1.5 frame periods.
"""

from __future__ import annotations

import time
from collections import deque
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from host_sdk.extras import require
from host_sdk.sensors.errors import SensorClosedError, SensorTimeoutError
from host_sdk.sensors.mjpeg import JpegPart, MjpegParser
from host_sdk.transport import Transport
from host_sdk.transport.plugins import open_plugin

PIPELINES = {
    # Jetson (Nano, Xavier, Orin) CSI camera through the Argus ISP, converted to BGR for OpenCV.
    "jetson-csi": (
        "nvarguscamerasrc sensor-id={sensor} ! video/x-raw(memory:NVMM), width={width}, height={height}, "
        "framerate={fps}/1 ! nvvidconv ! video/x-raw, format=BGRx ! videoconvert ! video/x-raw, format=BGR ! "
        "appsink drop=1 max-buffers=2"
    ),
    # Raspberry Pi camera on the libcamera stack (Bullseye and later).
    "libcamera": (
        "libcamerasrc ! video/x-raw, width={width}, height={height}, framerate={fps}/1 ! videoconvert ! "
        "video/x-raw, format=BGR ! appsink drop=1 max-buffers=2"
    ),
}


def gstreamer_pipeline(kind: str, width: int = 640, height: int = 480, fps: int = 30, sensor: int = 0) -> str:
    """A GStreamer pipeline string for cv2.VideoCapture(..., cv2.CAP_GSTREAMER)."""
    if kind not in PIPELINES:
        raise ValueError(f"pipeline kind {kind!r} is not allowed: one of {', '.join(PIPELINES)}")
    return PIPELINES[kind].format(width=width, height=height, fps=fps, sensor=sensor)


@dataclass(frozen=True, slots=True, eq=False)
class CameraFrame:
    image: NDArray[np.uint8]
    """BGR, height x width x 3."""
    time_s: float
    seq: int
    """Frames delivered by this source so far (1 first)."""
    device_time_s: float | None = None
    """The capture time the stream itself carried (the emulated camera's X-Timestamp), if any."""
    jpeg: bytes | None = None
    """The JPEG as the stream carried it (MJPEG byte streams), so it can be recorded or forwarded
    without encoding it again; None from a capture device."""


class CameraSource:
    def __init__(self, source: int | str, *, width: int | None = None, height: int | None = None,
                 fps: float | None = None, timeout_s: float = 5.0) -> None:  # fmt: skip
        self._cv2 = cv2 = require("cv2", "vision", "the camera")
        self.source = source
        self.frames = 0
        self.dropped = 0
        self.fps = fps
        self._last_time: float | None = None
        self._last_counter: int | None = None
        self._closed = False
        self._port: Transport | None = None
        self._parser: MjpegParser | None = None
        self._pending: deque[JpegPart] = deque()
        self._cap: Any = None
        text = str(source)
        self._port = open_plugin(text, 0) if isinstance(source, str) else None
        if self._port is not None:  # a plugin's byte stream (emudev://): MJPEG parts
            self._parser = MjpegParser()
            return
        if isinstance(source, int) or text.startswith("/dev/video"):
            cap = cv2.VideoCapture(source if isinstance(source, int) else text, cv2.CAP_V4L2)
        elif "!" in text:
            cap = cv2.VideoCapture(text, cv2.CAP_GSTREAMER)
        else:
            params = [cv2.CAP_PROP_OPEN_TIMEOUT_MSEC, int(timeout_s * 1000), cv2.CAP_PROP_READ_TIMEOUT_MSEC,
                      int(timeout_s * 1000)]  # fmt: skip
            cap = cv2.VideoCapture(text, cv2.CAP_ANY, params)
        if width:
            cap.set(cv2.CAP_PROP_FRAME_WIDTH, width)
        if height:
            cap.set(cv2.CAP_PROP_FRAME_HEIGHT, height)
        if fps:
            cap.set(cv2.CAP_PROP_FPS, fps)
        if not cap.isOpened():
            raise SensorTimeoutError(text, "camera stream", timeout_s, "OpenCV could not open it")
        self._cap = cap
        self.fps = fps or (cap.get(cv2.CAP_PROP_FPS) or None)

    def clock(self) -> float:
        return self._port.clock() if self._port is not None else time.monotonic()

    @property
    def virtual(self) -> bool:
        """True for an emulator's camera on its virtual clock: reading is what moves time, so read
        it from the loop that owns the emulator (no thread)."""
        return self._port is not None and self._port.virtual

    @property
    def queued(self) -> bool:
        """True when frames queue up to be taken (a byte stream: `latest()` never waits); False for an
        OpenCV capture, whose `read()` waits for the next frame."""
        return self._port is not None

    def read(self, timeout_s: float = 1.0) -> CameraFrame:
        """The next frame; SensorTimeoutError when none arrives in time."""
        self._check_open()
        if self._port is not None:
            return self._read_stream(timeout_s)
        ok, image = self._cap.read()
        now = time.monotonic()
        if not ok or image is None:
            raise SensorTimeoutError(str(self.source), "camera frame", timeout_s, "the capture returned no frame")
        return self._deliver(image, now, None, None, None)

    def poll(self, timeout_s: float = 0.0) -> list[CameraFrame]:
        """The frames that arrived, oldest first. A byte stream is read for at most `timeout_s`; a
        capture device (V4L2, GStreamer, a URL through OpenCV) has no non-blocking read, so this
        waits for its next frame (read such a camera from a thread of its own)."""
        self._check_open()
        if self._port is None:
            return [self.read(max(timeout_s, 1.0))]
        self._receive(timeout_s)
        frames = []
        while (frame := self._decode_pending()) is not None:
            frames.append(frame)
        return frames

    def _check_open(self) -> None:
        if self._closed:
            raise SensorClosedError(f"{self.source}: the camera was closed")

    def _receive(self, timeout_s: float) -> None:
        port, parser = self._port, self._parser
        assert port is not None and parser is not None
        data = port.read(timeout_s)
        if data:
            parser.receive_data(data, port.clock())
            self._pending.extend(parser.parts())

    def _decode_pending(self) -> CameraFrame | None:
        """The oldest complete part that decodes (a part that does not is counted and skipped)."""
        parser = self._parser
        assert parser is not None
        while self._pending:
            part = self._pending.popleft()
            image = self._cv2.imdecode(np.frombuffer(part.jpeg, dtype=np.uint8), self._cv2.IMREAD_COLOR)
            if image is None:
                parser.counters.bad_parts += 1
                continue
            return self._deliver(image, part.t, part.frame, part.timestamp, part.jpeg)
        return None

    def latest(self) -> CameraFrame | None:
        """The newest frame that has arrived, without waiting (None: nothing new); older ones waiting
        are skipped (and counted as dropped) without being decoded. A control loop reads this way.
        A capture source (V4L2, GStreamer, URL) has no queue to look into: this is `read()`."""
        if self._closed:
            raise SensorClosedError(f"{self.source}: the camera was closed")
        if self._port is None:
            return self.read()
        parser = self._parser
        assert parser is not None
        self._receive(0.0)
        parts, self._pending = list(self._pending), deque()
        for part in reversed(parts):
            image = self._cv2.imdecode(np.frombuffer(part.jpeg, dtype=np.uint8), self._cv2.IMREAD_COLOR)
            if image is not None:
                return self._deliver(image, part.t, part.frame, part.timestamp, part.jpeg)
            parser.counters.bad_parts += 1
        return None

    def _read_stream(self, timeout_s: float) -> CameraFrame:
        port, parser = self._port, self._parser
        assert port is not None and parser is not None
        deadline = port.clock() + timeout_s
        while True:
            frame = self._decode_pending()
            if frame is not None:
                return frame
            left = deadline - port.clock()
            if left <= 0:
                heard = f"{parser.counters.bytes_received} bytes, {parser.counters.parts} frames"
                raise SensorTimeoutError(str(self.source), "camera frame", timeout_s, heard)
            self._receive(min(left, 0.05))

    def _deliver(
        self, image: Any, t: float, counter: int | None, device_t: float | None, jpeg: bytes | None
    ) -> CameraFrame:
        if counter is not None and self._last_counter is not None:
            self.dropped += max(0, counter - self._last_counter - 1)
        elif counter is None and self._last_time is not None and self.fps:
            gap = (t - self._last_time) * self.fps
            if gap > 1.5:
                self.dropped += round(gap) - 1
        self._last_counter = counter
        self._last_time = t
        self.frames += 1
        return CameraFrame(image, t, self.frames, device_t, jpeg)

    def close(self) -> None:
        if self._closed:
            return
        self._closed = True
        if self._cap is not None:
            self._cap.release()
        if self._port is not None:
            self._port.close()

    def __enter__(self) -> CameraSource:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()
