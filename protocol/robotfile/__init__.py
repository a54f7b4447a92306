"""Robot files: one TOML file per robot (board, drive, pins, geometry, limits, gains, sensors,
footprint, calibration) that the firmware build, the emulators, the SDK and the tools read.

    >>> from protocol.robotfile import load, reference_path
    >>> robot = load(reference_path("picar"))
    >>> robot.config().steering_step_cdeg
    1500

The format, every key and why this lives in `protocol`: docs/robot-file.md.
"""

from __future__ import annotations

import re
from importlib import resources
from pathlib import Path

from protocol.robotfile import build
from protocol.robotfile.errors import Problem, RobotFileError
from protocol.robotfile.model import (
    Calibration,
    Camera,
    Drive,
    Emulator,
    Encoders,
    Esc,
    Feedback,
    Footprint,
    Geometry,
    Limits,
    Pid,
    RobotFile,
    SerialSensor,
    Steering,
)
from protocol.robotfile.reader import Reader
from protocol.toml import tomllib

__all__ = [
    "REFERENCES",
    "Calibration",
    "Camera",
    "Drive",
    "Emulator",
    "Encoders",
    "Esc",
    "Feedback",
    "Footprint",
    "Geometry",
    "Limits",
    "Pid",
    "Problem",
    "RobotFile",
    "RobotFileError",
    "SerialSensor",
    "Steering",
    "check",
    "load",
    "parse",
    "reference_path",
]

_SHIPPED = resources.files("protocol").joinpath("robots").iterdir()
REFERENCES: tuple[str, ...] = tuple(sorted(f.name.removesuffix(".toml") for f in _SHIPPED if f.name.endswith(".toml")))
"""The reference robots: every file in protocol/robots/ (<name>.toml), by name. Each is the one
source of its robot: `python -m protocol generate` writes its firmware example's robot_profile.h,
its profile in protocol/generated/profiles.py and its column of docs/robots.md from it."""


def reference_path(name: str) -> Path:
    """The shipped file of reference robot `name`; RobotFileError names the choices."""
    if name not in REFERENCES:
        raise RobotFileError([Problem(name, "", None, f"no reference robot {name!r} (one of {', '.join(REFERENCES)})")])
    return Path(str(resources.files("protocol").joinpath(f"robots/{name}.toml")))


def parse(text: str, path: str) -> tuple[RobotFile | None, list[Problem]]:
    """The robot in `text` (None when it has problems) and every problem found."""
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        found = re.search(r"at line (\d+)", str(exc))  # older tomllib errors carry no lineno
        return None, [Problem(path, "", int(found.group(1)) if found else None, f"not valid TOML: {exc}")]
    reader = Reader(path, text)
    robot = build.robot(reader, data)
    return (robot if not reader.problems else None), reader.problems


def _read(path: str | Path) -> tuple[RobotFile | None, list[Problem]]:
    name = str(path)
    try:
        text = Path(path).read_text(encoding="utf-8")
    except FileNotFoundError:
        return None, [Problem(name, "", None, "no such file")]
    except (OSError, UnicodeDecodeError) as exc:
        return None, [Problem(name, "", None, f"cannot be read: {exc}")]
    return parse(text, name)


def check(path: str | Path) -> list[Problem]:
    """Every problem of the robot file at `path` (empty: it is fine)."""
    return _read(path)[1]


def load(path: str | Path) -> RobotFile:
    """The robot file at `path`; RobotFileError lists every problem."""
    robot, problems = _read(path)
    if robot is None:
        raise RobotFileError(problems)
    return robot
