"""GStreamer pipelines for CSI cameras, and what the OpenCV in use was built with.

The OpenCV wheels on PyPI (`opencv-python-headless`) are built without GStreamer, so a pipeline
only opens with a distribution's OpenCV (Raspberry Pi OS / Ubuntu `python3-opencv`, JetPack's).
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from typing import Any

from host_sdk.sensors.errors import CameraBackendError

PIPELINES = {
    # Jetson (Nano, Xavier, Orin) CSI camera through the Argus ISP, turned by nvvidconv (a Pi Camera
    # v2 in the usual Jetson mounts needs rotate-180), converted to BGR for OpenCV.
    "jetson-csi": (
        "nvarguscamerasrc sensor-id={sensor} ! video/x-raw(memory:NVMM), width={width}, height={height}, "
        "framerate={fps}/1 ! nvvidconv flip-method={flip_number} ! video/x-raw, format=BGRx ! videoconvert ! "
        "video/x-raw, format=BGR ! appsink drop=1 max-buffers=2"
    ),
    # Raspberry Pi camera on the libcamera stack (Bullseye and later).
    "libcamera": (
        "libcamerasrc ! video/x-raw, width={width}, height={height}, framerate={fps}/1 ! {videoflip}videoconvert ! "
        "video/x-raw, format=BGR ! appsink drop=1 max-buffers=2"
    ),
}

FLIPS = (
    "none",
    "counterclockwise",
    "rotate-180",
    "clockwise",
    "horizontal-flip",
    "upper-right-diagonal",
    "vertical-flip",
    "upper-left-diagonal",
)
"""The turns and mirrors of a camera's picture, in the order of nvvidconv's flip-method numbers
(GStreamer's videoflip has the same names, numbered otherwise)."""


def flip_name(flip: str | int) -> str:
    """A FLIPS name from a name or nvvidconv's flip-method number (what Jetson guides quote)."""
    text = str(flip).strip()
    if text.isdigit() and int(text) < len(FLIPS):
        return FLIPS[int(text)]
    if text in FLIPS:
        return text
    raise ValueError(f"flip {flip!r} is not allowed: one of {', '.join(FLIPS)} (or nvvidconv's number 0-7)")


DISTRO_OPENCV = (
    "install the distribution's OpenCV, which has it (Raspberry Pi OS / Ubuntu: sudo apt install python3-opencv "
    "gstreamer1.0-plugins-good gstreamer1.0-libcamera; on a Jetson JetPack's OpenCV has it) and use it from a "
    "venv made with --system-site-packages, without opencv-python-headless"
)


def gstreamer_pipeline(
    kind: str, width: int = 640, height: int = 480, fps: int = 30, sensor: int = 0, *, flip: str | int = "none"
) -> str:
    """A GStreamer pipeline string for cv2.VideoCapture(..., cv2.CAP_GSTREAMER); `flip` turns or
    mirrors the picture (FLIPS, e.g. "rotate-180")."""
    if kind not in PIPELINES:
        raise ValueError(f"pipeline kind {kind!r} is not allowed: one of {', '.join(PIPELINES)}")
    name = flip_name(flip)
    videoflip = "" if name == "none" else f"videoflip method={name} ! "
    return PIPELINES[kind].format(
        width=width, height=height, fps=fps, sensor=sensor, flip_number=FLIPS.index(name), videoflip=videoflip
    )


@dataclass(frozen=True, slots=True)
class OpenCvBuild:
    version: str
    gstreamer: bool
    ffmpeg: bool
    v4l2: bool


def opencv_build(cv2: Any) -> OpenCvBuild:
    """What `cv2.getBuildInformation()` says about the video I/O backends."""
    info = str(cv2.getBuildInformation())

    def has(name: str) -> bool:
        match = re.search(rf"^\s*{name}:\s*(\S+)", info, re.MULTILINE | re.IGNORECASE)
        return match is not None and match.group(1).upper() != "NO"

    return OpenCvBuild(str(cv2.__version__), has("GStreamer"), has("FFMPEG"), has("v4l/v4l2") or has("V4L2"))


def require_gstreamer(cv2: Any, pipeline: str) -> None:
    """CameraBackendError unless this OpenCV can open GStreamer pipelines; says what to do instead."""
    if opencv_build(cv2).gstreamer:
        return
    shown = pipeline if len(pipeline) <= 60 else pipeline[:57] + "..."
    where = getattr(cv2, "__file__", "cv2")
    missing = f"this OpenCV ({cv2.__version__}, {where}) was built without GStreamer, so the pipeline cannot open"
    if "libcamerasrc" in pipeline:
        fix = "on a Raspberry Pi use --camera picamera2 (CameraSource('picamera2:0')), or " + DISTRO_OPENCV
    elif "nvarguscamerasrc" in pipeline:
        fix = "on a Jetson use JetPack's OpenCV (it has GStreamer) from a venv made with --system-site-packages"
    else:
        fix = DISTRO_OPENCV
    raise CameraBackendError(shown, missing, fix)
