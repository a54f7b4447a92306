"""Frames replayed from a video file or a folder of images (sorted by name).

With `fps` the frames are paced at that rate (a video's own rate otherwise, for a folder as fast
as they are read); `fps=0` reads as fast as they decode. The end is a SensorClosedError saying how
many frames there were, never a wait.
"""

from __future__ import annotations

import time
from pathlib import Path
from typing import Any

from host_sdk.extras import require
from host_sdk.sensors.camera.frame import Capture
from host_sdk.sensors.errors import SensorClosedError, SensorOpenError

IMAGE_SUFFIXES = (".jpg", ".jpeg", ".png", ".bmp", ".tif", ".tiff", ".webp")


class ReplayBackend:
    queued = False
    virtual = False
    skipped = 0

    def __init__(self, path: Path, *, fps: float | None) -> None:
        self._cv2 = cv2 = require("cv2", "vision", "the camera")
        self.source = str(path)
        self._cap: Any = None
        self._images: list[Path] = []
        if path.is_dir():
            self._images = sorted(p for p in path.iterdir() if p.suffix.lower() in IMAGE_SUFFIXES)
            if not self._images:
                raise SensorOpenError(f"camera {path}: the folder has no images ({', '.join(IMAGE_SUFFIXES)})")
            own = None
            what = f"{len(self._images)} images"
        else:
            self._cap = cv2.VideoCapture(str(path))
            if not self._cap.isOpened():
                raise SensorOpenError(f"camera {path}: OpenCV could not open it as a video")
            own = float(self._cap.get(cv2.CAP_PROP_FPS)) or None
            what = "video"
        self.fps = own if fps is None else (fps or own)
        self._period = 1.0 / fps if fps else (1.0 / own if own and fps is None else 0.0)
        self._index = 0
        self._start: float | None = None
        self.detail = f"replay of {what} at " + (f"{1 / self._period:g} fps" if self._period else "read speed")

    def clock(self) -> float:
        return time.monotonic()

    def fetch(self, timeout_s: float) -> list[Capture]:
        image, device_t = self._next()
        now = time.monotonic()
        if self._period:  # frame i is not given before start + i periods
            self._start = now if self._start is None else self._start
            wait = self._start + self._index * self._period - now
            if wait > 0:
                time.sleep(wait)
                now = time.monotonic()
        self._index += 1
        return [Capture(now, image=image, device_t=device_t)]

    def _next(self) -> tuple[Any, float | None]:
        cv2 = self._cv2
        if self._cap is not None:
            ok, image = self._cap.read()
            if not ok or image is None:
                raise SensorClosedError(f"{self.source}: end of the video after {self._index} frames")
            return image, float(self._cap.get(cv2.CAP_PROP_POS_MSEC)) / 1000.0
        while self._index < len(self._images):
            image = cv2.imread(str(self._images[self._index]), cv2.IMREAD_COLOR)
            if image is not None:
                return image, self._index * self._period if self._period else None
            self._images.pop(self._index)  # not an image after all: skip it
        raise SensorClosedError(f"{self.source}: end of the folder after {self._index} images")

    def heard(self) -> str:
        return f"{self._index} frames replayed"

    def close(self) -> None:
        if self._cap is not None:
            self._cap.release()
