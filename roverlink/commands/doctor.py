"""`roverlink doctor`: what this host can do, and the one-line fix for each missing piece.

roverlink doctor          # Python, numpy, OpenCV (GStreamer, V4L2), picamera2, ROS 2, serial ports
roverlink doctor --json
"""

from __future__ import annotations

import argparse
import dataclasses
import json
from pathlib import Path

from roverlink.doctor import findings


def cmd_doctor(args: argparse.Namespace) -> int:
    """Show the Python, numpy, OpenCV, picamera2, ROS 2 and serial ports found, with a fix for each missing piece."""
    found = findings(args.root)
    if args.json:
        print(json.dumps([dataclasses.asdict(f) for f in found], indent=2))
        return 0
    width = max(len(f.name) for f in found)
    for f in found:
        print(f"{f.name:<{width}}  {f.found}")
        if f.fix is not None:
            print(f"{'':<{width}}  fix: {f.fix}")
    missing = sum(f.fix is not None for f in found)
    if missing:
        print(f"\n{missing} missing or wrong (a feature you do not use needs no fix): each `fix:` line says what to do")
    else:
        print("\nnothing missing")
    return 0


def add_parser(sub: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    p = sub.add_parser("doctor", help=cmd_doctor.__doc__, description=cmd_doctor.__doc__)
    p.add_argument("--json", action="store_true", help="print the findings as JSON")
    p.add_argument("--root", type=Path, default=Path("/"), help=argparse.SUPPRESS)  # a fake /etc, /proc in tests
    p.set_defaults(func=cmd_doctor)
