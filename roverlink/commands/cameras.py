"""`roverlink cameras`: the cameras this machine can open, and the `--camera` value of each.

roverlink cameras            # picamera2's cameras, /dev/video* devices, what this OpenCV can open
roverlink cameras --probe    # and open each: one frame's size and the measured frame rate
roverlink cameras --json
"""

from __future__ import annotations

import argparse
import dataclasses
import json
from pathlib import Path
from typing import Any

from host_sdk.sensors.camera.listing import CameraListing, ProbeResult, list_cameras, probe

NONE_FOUND = (
    "no cameras found on this machine. A USB webcam shows up as /dev/videoN (--camera /dev/video0); a Raspberry Pi "
    "camera is read through picamera2 (--camera picamera2); an ESP32-CAM or IP camera by its URL (--camera "
    "http://HOST:81/stream); a recording by its path (--camera run.mp4 or a folder of images)"
)


def cmd_cameras(args: argparse.Namespace) -> int:
    """List the cameras this machine can open (picamera2, V4L2) and the --camera value for each."""
    listing = list_cameras(args.root)
    probes = {c.value: probe(c.value, args.seconds) for c in listing.cameras if c.usable} if args.probe else {}
    if args.json:
        print(json.dumps(_as_json(listing, probes), indent=2))
    else:
        _print(listing, probes)
    return 1 if any(p.error for p in probes.values()) else 0


def _print(listing: CameraListing, probes: dict[str, ProbeResult]) -> None:
    if listing.opencv is not None:
        cv = listing.opencv
        yes = {True: "yes", False: "no"}
        print(f"OpenCV {cv.version}: GStreamer {yes[cv.gstreamer]}, FFmpeg {yes[cv.ffmpeg]}, V4L2 {yes[cv.v4l2]}")
        if not cv.gstreamer:
            print("  (no GStreamer: pipelines, --camera libcamera and jetson-csi cannot open with this OpenCV)")
    else:
        print(f"OpenCV: {listing.opencv_missing}")
    print(f"picamera2: {listing.picamera2 or 'available'}")
    if not listing.cameras:
        print(NONE_FOUND)
        return
    for cam in listing.cameras:
        value = f"--camera {cam.value}" if cam.usable else f"({cam.value})"
        print(f"  {value:<24} {cam.route:<9} {cam.name}" + (f": {cam.note}" if cam.note else ""))
        result = probes.get(cam.value)
        if result is not None:
            print(f"      {_probe_line(result)}")


def _probe_line(result: ProbeResult) -> str:
    if result.error is not None:
        return f"probe failed: {result.error}"
    size = f"{result.size[0]}x{result.size[1]}" if result.size else "?"
    fps = f"{result.fps:.1f} fps measured" if result.fps else "rate not measured"
    return f"{size}, {fps} ({result.detail})"


def _as_json(listing: CameraListing, probes: dict[str, ProbeResult]) -> dict[str, Any]:
    cameras = []
    for cam in listing.cameras:
        entry: dict[str, Any] = dataclasses.asdict(cam)
        if cam.value in probes:
            entry["probe"] = dataclasses.asdict(probes[cam.value])
        cameras.append(entry)
    opencv = dataclasses.asdict(listing.opencv) if listing.opencv is not None else None
    return {
        "cameras": cameras,
        "picamera2": listing.picamera2,
        "opencv": opencv,
        "opencv_missing": listing.opencv_missing,
    }


def add_parser(sub: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    p = sub.add_parser("cameras", help=cmd_cameras.__doc__, description=cmd_cameras.__doc__)
    p.add_argument("--probe", action="store_true", help="open each camera: one frame's size and the measured fps")
    p.add_argument("--seconds", type=float, default=1.0, help="how long --probe measures the rate (default 1)")
    p.add_argument("--json", action="store_true", help="print the listing as JSON")
    p.add_argument("--root", type=Path, default=Path("/"), help=argparse.SUPPRESS)  # a fake /sys and /dev in tests
    p.set_defaults(func=cmd_cameras)
