"""A Raspberry Pi camera through picamera2 (libcamera), as Raspberry Pi OS reads it.

picamera2 is not a PyPI dependency: Raspberry Pi OS ships it (`sudo apt install python3-picamera2`)
built against its own libcamera, so a venv sees it only when made with `--system-site-packages`.
The main stream is configured as "RGB888", which picamera2 lays out B, G, R in memory: the BGR
array OpenCV expects, with no conversion. Each frame's `SensorTimestamp` (nanoseconds, the start
of exposure; on the Pi the kernel's monotonic clock, which picamera2 itself compares with
`time.monotonic_ns()`) becomes `device_time_s`.
"""

from __future__ import annotations

import time
from types import ModuleType
from typing import Any

from host_sdk.extras import NumpyAbiError, import_compiled
from host_sdk.sensors.camera.frame import Capture
from host_sdk.sensors.errors import CameraBackendError, SensorOpenError, SensorTimeoutError

INSTALL = (
    "on Raspberry Pi OS install it with `sudo apt install python3-picamera2` and run from the system Python, "
    "or from a venv made with `python3 -m venv --system-site-packages` (pip cannot build it against the Pi's libcamera)"
)
DEFAULT_SIZE = (640, 480)


def import_picamera2(source: str) -> ModuleType:
    """The picamera2 module, or CameraBackendError saying how to get it (NumpyAbiError when it, or
    its simplejpeg, was built for another numpy than the one found first)."""
    try:
        return import_compiled("picamera2")
    except NumpyAbiError:
        raise
    except ImportError as exc:
        raise CameraBackendError(source, f"the Python module 'picamera2' is not importable ({exc})", INSTALL) from exc


def picamera2_cameras(module: ModuleType) -> list[dict[str, Any]]:
    """libcamera's cameras in picamera2's order (index N is `picamera2:N`): Model, Location, Id, ..."""
    return [dict(info) for info in module.Picamera2.global_camera_info()]


def describe(index: int, info: dict[str, Any]) -> str:
    where = " (USB)" if "/usb" in str(info.get("Id", "")) else ""
    return f"picamera2:{index} {info.get('Model', '?')}{where}"


class Picamera2Backend:
    """One picamera2 camera; `capture_request` waits for its next frame, so it is not queued."""

    queued = False
    virtual = False
    skipped = 0

    def __init__(self, index: int, *, width: int | None, height: int | None, fps: float | None) -> None:
        self.source = source = f"picamera2:{index}"
        module = import_picamera2(source)
        cameras = picamera2_cameras(module)
        if not 0 <= index < len(cameras):
            seen = ", ".join(describe(i, c) for i, c in enumerate(cameras)) or "none"
            raise SensorOpenError(
                f"camera {source}: libcamera sees no camera {index} (cameras: {seen}); check the ribbon cable "
                "and that `rpicam-hello --list-cameras` lists it"
            )
        try:
            cam = module.Picamera2(index)
        except (RuntimeError, IndexError, OSError) as exc:
            raise SensorOpenError(f"camera {source}: could not open it ({exc}); is another program using it?") from exc
        size = (width or DEFAULT_SIZE[0], height or DEFAULT_SIZE[1])
        controls = {"FrameRate": float(fps)} if fps else {}
        try:
            cam.configure(cam.create_video_configuration(main={"size": size, "format": "RGB888"}, controls=controls))
            cam.start()
        except Exception as exc:  # picamera2 raises RuntimeError and libcamera's own errors
            cam.close()
            raise SensorOpenError(f"camera {source}: could not start it at {size[0]}x{size[1]} ({exc})") from exc
        self._cam = cam
        self.fps = float(fps) if fps else None
        rate = f" {self.fps:g} fps" if self.fps else ""
        self.detail = f"{describe(index, cameras[index])} {size[0]}x{size[1]} RGB888 (BGR){rate}"

    def clock(self) -> float:
        return time.monotonic()

    def fetch(self, timeout_s: float) -> list[Capture]:
        try:
            request = self._cam.capture_request(wait=max(timeout_s, 0.001))  # a number: seconds, then TimeoutError
        except TimeoutError as exc:
            raise SensorTimeoutError(self.source, "camera frame", timeout_s, "picamera2 gave no frame") from exc
        try:
            image = request.make_array("main")
            stamp = request.get_metadata().get("SensorTimestamp")
        finally:
            request.release()  # the buffer goes back to libcamera at once
        now = time.monotonic()
        return [Capture(now, image=image, device_t=stamp / 1e9 if stamp else None)]

    def heard(self) -> str:
        return self.detail

    def close(self) -> None:
        try:
            self._cam.stop()
        finally:
            self._cam.close()
