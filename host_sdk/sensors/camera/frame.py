"""A camera frame, and the interface every camera backend gives `CameraSource`."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Protocol

import numpy as np
from numpy.typing import NDArray


@dataclass(frozen=True, slots=True, eq=False)
class CameraFrame:
    image: NDArray[np.uint8]
    """BGR, height x width x 3."""
    time_s: float
    seq: int
    """Frames delivered by this source so far (1 first)."""
    device_time_s: float | None = None
    """The capture time the source itself carried, if any: the emulated camera's X-Timestamp, the
    sensor timestamp of a Pi camera (CLOCK_BOOTTIME seconds), a video file's position."""
    jpeg: bytes | None = None
    """The JPEG as the stream carried it (MJPEG streams), so it can be recorded or forwarded
    without encoding it again; None from a capture device."""


@dataclass(frozen=True, slots=True, eq=False)
class Capture:
    """What a backend took off its device: a decoded image, or a JPEG still to decode."""

    t: float
    """When it was taken off the device (the backend's clock)."""
    image: NDArray[np.uint8] | None = None
    jpeg: bytes | None = None
    counter: int | None = None
    """The stream's own frame counter (gaps: frames missed), if it has one."""
    device_t: float | None = None


class CameraBackend(Protocol):
    """One route to frames (picamera2, V4L2, GStreamer, MJPEG over HTTP, a byte stream, a replay).

    A queued backend keeps what arrived until it is taken: `fetch(timeout_s)` returns it all,
    waiting at most `timeout_s` for something (an empty list: nothing came). Any other backend
    captures on demand: `fetch` returns one capture, waiting for it (SensorTimeoutError: none came;
    SensorClosedError: the stream ended)."""

    queued: bool
    virtual: bool
    fps: float | None
    """The frame rate the device delivers (None: not known)."""
    skipped: int
    """Frames without a counter that the backend let go before they were taken (a full queue)."""
    detail: str
    """What was opened, as the device gave it (route, size, format, rate)."""

    def clock(self) -> float: ...

    def fetch(self, timeout_s: float) -> list[Capture]: ...

    def heard(self) -> str:
        """What arrived so far, for a timeout's message."""
        ...

    def close(self) -> None: ...
