"""The cameras this machine can open, and the `--camera` value of each (`roverlink cameras`).

picamera2's cameras when the module imports; V4L2 devices from sysfs (`/sys/class/video4linux/*/name`,
no library needed; `root` is injectable for tests); and what the OpenCV in use was built with.
`probe(value)` opens one and measures a frame's size and the frame rate.
"""

from __future__ import annotations

import os
import re
import time
from dataclasses import dataclass
from pathlib import Path

from host_sdk.extras import MissingDependencyError, NumpyAbiError, require
from host_sdk.sensors.camera.opencv import VIDEO_GROUP
from host_sdk.sensors.camera.picam import describe, import_picamera2, picamera2_cameras
from host_sdk.sensors.camera.pipelines import OpenCvBuild, opencv_build
from host_sdk.sensors.camera.source import CameraSource
from host_sdk.sensors.errors import CameraBackendError, SensorClosedError, SensorOpenError, SensorTimeoutError

# V4L2 nodes on a Raspberry Pi that are codecs, the ISP or the CSI receiver: not cameras to open.
NOT_CAMERAS = re.compile(r"bcm2835-(codec|isp)|rpi-hevc|pispbe|rp1-cfe|unicam|rpivid", re.IGNORECASE)


@dataclass(frozen=True, slots=True)
class CameraEntry:
    value: str
    """What to give `--camera` (CameraSource)."""
    route: str
    """picamera2 or v4l2."""
    name: str
    usable: bool
    note: str = ""


@dataclass(frozen=True, slots=True)
class CameraListing:
    cameras: tuple[CameraEntry, ...]
    picamera2: str | None
    """Why picamera2 cannot be used (None: it imports)."""
    opencv: OpenCvBuild | None
    opencv_missing: str | None = None


def list_cameras(root: Path = Path("/")) -> CameraListing:
    cameras: list[CameraEntry] = []
    picamera2_problem: str | None = None
    try:
        module = import_picamera2("picamera2")
        cameras += [
            CameraEntry(f"picamera2:{i}", "picamera2", describe(i, c).split(" ", 1)[1], True)
            for i, c in enumerate(picamera2_cameras(module))
        ]
    except CameraBackendError as exc:
        picamera2_problem = f"not available: {exc.module}; {exc.install}"
    except NumpyAbiError as exc:
        picamera2_problem = str(exc)
    except Exception as exc:  # libcamera itself failing to start is worth showing, not raising
        picamera2_problem = f"picamera2 could not list its cameras ({exc})"
    cameras += v4l2_devices(root)
    try:
        build: OpenCvBuild | None = opencv_build(require("cv2", "vision", "the camera"))
        missing = None
    except MissingDependencyError as exc:
        build, missing = None, str(exc)
    return CameraListing(tuple(cameras), picamera2_problem, build, missing)


def v4l2_devices(root: Path = Path("/")) -> list[CameraEntry]:
    """The /dev/videoN nodes sysfs lists, with their names; those that cannot be a stream, or this
    user cannot open, are marked."""
    base = root / "sys" / "class" / "video4linux"
    nodes = sorted(base.glob("video*"), key=lambda p: int(re.sub(r"\D", "", p.name) or 0)) if base.is_dir() else []
    out = []
    for node in nodes:
        name = _read(node / "name") or "?"
        dev = root / "dev" / node.name
        value = f"/dev/{node.name}"
        if NOT_CAMERAS.search(name):
            out.append(CameraEntry(value, "v4l2", name, False, "a codec or ISP node of the Pi, not a camera"))
        elif _read(node / "index") not in ("", "0"):
            out.append(CameraEntry(value, "v4l2", name, False, "the device's metadata node, not its stream"))
        elif not dev.exists():
            out.append(CameraEntry(value, "v4l2", name, False, f"{dev} is missing (udev did not create it)"))
        elif not os.access(dev, os.R_OK | os.W_OK):
            out.append(CameraEntry(value, "v4l2", name, False, f"not readable by this user: {VIDEO_GROUP}"))
        else:
            out.append(CameraEntry(value, "v4l2", name, True))
    return out


def _read(path: Path) -> str:
    try:
        return path.read_text().strip()
    except OSError:
        return ""


@dataclass(frozen=True, slots=True)
class ProbeResult:
    value: str
    size: tuple[int, int] | None = None
    fps: float | None = None
    """Frames per second measured over `seconds`."""
    detail: str = ""
    error: str | None = None


def probe(value: str, seconds: float = 1.0, timeout_s: float = 5.0) -> ProbeResult:
    """Open `value`, read one frame (its size), then count frames for `seconds` (the rate)."""
    try:
        with CameraSource(value, timeout_s=timeout_s) as cam:
            first = cam.read(timeout_s)
            height, width = first.image.shape[:2]
            start, count, last = time.monotonic(), 0, first.time_s
            while time.monotonic() - start < seconds:
                frames = cam.poll(timeout_s) if cam.queued else [cam.read(timeout_s)]
                count += len(frames)
                last = frames[-1].time_s if frames else last
            span = last - first.time_s
            return ProbeResult(value, (int(width), int(height)), count / span if span > 0 else None, cam.detail)
    except (SensorOpenError, SensorTimeoutError, SensorClosedError, MissingDependencyError, OSError) as exc:
        return ProbeResult(value, error=str(exc))
