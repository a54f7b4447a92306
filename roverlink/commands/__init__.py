"""The `roverlink` subcommands, one module each, in the order `roverlink --help` lists them.

A command module has `add_parser(subparsers)`, which registers its parser and sets `func`.
"""

from __future__ import annotations

from types import ModuleType

from roverlink.commands import (
    calibrate,
    cameras,
    console,
    decode,
    demo,
    doctor,
    emulate,
    firmware,
    follow,
    info,
    monitor,
    ports,
    record,
    robot,
    ros2,
    roundtrip,
    spec,
    teleop,
    tune,
)

COMMANDS: tuple[ModuleType, ...] = (
    demo,
    doctor,
    info,
    robot,
    ports,
    cameras,
    emulate,
    firmware,
    monitor,
    teleop,
    console,
    calibrate,
    tune,
    record,
    ros2,
    follow,
    roundtrip,
    decode,
    spec,
)
