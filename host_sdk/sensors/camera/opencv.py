"""Cameras OpenCV opens: V4L2/UVC devices, GStreamer pipelines, and stream URLs (RTSP, ...)."""

from __future__ import annotations

import os
import time

from host_sdk.extras import require
from host_sdk.sensors.camera.frame import Capture
from host_sdk.sensors.camera.pipelines import require_gstreamer
from host_sdk.sensors.errors import SensorOpenError, SensorTimeoutError

VIDEO_GROUP = "add yourself to the video group (sudo usermod -aG video $USER, then log in again)"


def check_device(path: str) -> None:
    """SensorOpenError naming what is wrong with a V4L2 device node (missing, not readable)."""
    if not os.path.exists(path):
        raise SensorOpenError(f"camera {path}: no such device (is it plugged in? `roverlink cameras` lists those here)")
    if not os.access(path, os.R_OK | os.W_OK):
        raise SensorOpenError(f"camera {path}: exists but is not readable by this user: {VIDEO_GROUP}")


class OpenCvBackend:
    """A cv2.VideoCapture: `read()` waits for the next frame, so it is not queued."""

    queued = False
    virtual = False
    skipped = 0

    def __init__(
        self, source: int | str, *, width: int | None, height: int | None, fps: float | None, timeout_s: float
    ) -> None:
        self._cv2 = cv2 = require("cv2", "vision", "the camera")
        self.source = text = str(source)
        if isinstance(source, int) or text.startswith(("/dev/video", "/dev/v4l/")):
            path = f"/dev/video{source}" if isinstance(source, int) else text
            check_device(path)
            cap = cv2.VideoCapture(source, cv2.CAP_V4L2)
            # MJPG first: a UVC webcam gives its larger sizes and full rate only compressed over USB 2.
            cap.set(cv2.CAP_PROP_FOURCC, cv2.VideoWriter.fourcc(*"MJPG"))
            what = f"V4L2 {path}"
        elif "!" in text:
            require_gstreamer(cv2, text)
            cap = cv2.VideoCapture(text, cv2.CAP_GSTREAMER)
            what = "GStreamer pipeline"
        else:
            ms = int(timeout_s * 1000)
            cap = cv2.VideoCapture(
                text, cv2.CAP_ANY, [cv2.CAP_PROP_OPEN_TIMEOUT_MSEC, ms, cv2.CAP_PROP_READ_TIMEOUT_MSEC, ms]
            )
            what = "OpenCV stream"
        if width:
            cap.set(cv2.CAP_PROP_FRAME_WIDTH, width)
        if height:
            cap.set(cv2.CAP_PROP_FRAME_HEIGHT, height)
        if fps:
            cap.set(cv2.CAP_PROP_FPS, fps)
        if not cap.isOpened():
            raise SensorTimeoutError(text, "camera stream", timeout_s, f"{what}: OpenCV could not open it")
        self._cap = cap
        self.fps: float | None = float(cap.get(cv2.CAP_PROP_FPS)) or fps or None
        self.detail = f"{what} {self._actual()}"

    def _actual(self) -> str:
        """What the device gave (it may differ from what was asked)."""
        cv2, cap = self._cv2, self._cap
        w, h = int(cap.get(cv2.CAP_PROP_FRAME_WIDTH)), int(cap.get(cv2.CAP_PROP_FRAME_HEIGHT))
        code = int(cap.get(cv2.CAP_PROP_FOURCC))
        fourcc = "".join(chr((code >> 8 * i) & 0xFF) for i in range(4)).strip("\0 ") if code > 0 else "?"
        return f"{w}x{h} {fourcc} {self.fps or 0:g} fps"

    def clock(self) -> float:
        return time.monotonic()

    def fetch(self, timeout_s: float) -> list[Capture]:
        ok, image = self._cap.read()
        now = time.monotonic()
        if not ok or image is None:
            raise SensorTimeoutError(self.source, "camera frame", timeout_s, "the capture returned no frame")
        return [Capture(now, image=image)]

    def heard(self) -> str:
        return self.detail

    def close(self) -> None:
        self._cap.release()
