"""argparse value checkers for the commands' options (numbers, calibration files).

Each returns a `type=` callable: a bad value ends the command before any work starts, with
argparse's own message (`error: argument --side: ...`) and exit status 2.
"""

from __future__ import annotations

import argparse
import math
import shlex
from collections.abc import Callable
from pathlib import Path

from host_sdk import RobotDescription, RobotFileError
from host_sdk.calibration import CalibrationFile, KinematicsFileError, read_calibration


def _fmt(x: float) -> str:
    return str(int(x)) if float(x).is_integer() else f"{x:g}"


def positive(text: str) -> float:
    """A number > 0 (seconds, metres, m/s...)."""
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r} is not a number") from None
    if not value > 0:
        raise argparse.ArgumentTypeError(f"{text} is not allowed: a number > 0")
    return value


def number(lo: float, hi: float, unit: str = "", *, lo_open: bool = False) -> Callable[[str], float]:
    """A finite number in lo..hi (lo excluded with `lo_open`)."""
    u = f" {unit}" if unit else ""
    allowed = f"a number > {_fmt(lo)} and <= {_fmt(hi)}{u}" if lo_open else f"a number in {_fmt(lo)}..{_fmt(hi)}{u}"

    def parse(text: str) -> float:
        try:
            value = float(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"{text!r} is not a number: {allowed}") from None
        if not math.isfinite(value) or value < lo or value > hi or (lo_open and value == lo):
            raise argparse.ArgumentTypeError(f"{text!r} is not allowed: {allowed}")
        return value

    return parse


def integer(lo: int, hi: int, unit: str = "") -> Callable[[str], int]:
    """An integer in lo..hi."""
    allowed = f"an integer in {lo}..{hi}{' ' + unit if unit else ''}"

    def parse(text: str) -> int:
        try:
            value = int(text, 0)
        except ValueError:
            raise argparse.ArgumentTypeError(f"{text!r} is not an integer: {allowed}") from None
        if not lo <= value <= hi:
            raise argparse.ArgumentTypeError(f"{text!r} is not allowed: {allowed}")
        return value

    return parse


SEED = integer(0, 2**63, "")
"""Emulator seeds (the range the emulator takes)."""
BAUD = integer(50, 4_000_000, "bit/s")
"""Line speeds a serial port may be opened at."""


def kinematics_arg(text: str) -> CalibrationFile:
    """argparse `type=` for --kinematics FILE: a bad file ends the command before it connects."""
    try:
        return read_calibration(text)
    except OSError as exc:
        raise argparse.ArgumentTypeError(f"{text}: {exc.strerror or exc}") from None
    except KinematicsFileError as exc:
        raise argparse.ArgumentTypeError(str(exc)) from None


def robot_file_arg(text: str) -> RobotDescription:
    """argparse `type=` for --robot FILE: a bad robot file ends the command (exit 2) before it
    connects, with every problem of the file."""
    try:
        return RobotDescription.load(text)
    except RobotFileError as exc:
        raise argparse.ArgumentTypeError(str(exc)) from None


def usage_lines(path: Path, url: str) -> list[str]:
    """How to use a calibration file: the commands' option and the SDK call."""
    return [
        f"use it with every command: roverlink teleop {shlex.quote(url)} --kinematics {shlex.quote(str(path))}",
        f"and in code: Robot.connect({url!r}, kinematics=host_sdk.calibration.load_kinematics({str(path)!r}))",
    ]
