"""The `roverlink` subcommands, one module each, in the order `roverlink --help` lists them.

A command module has `add_parser(subparsers)`, which registers its parser and sets `func`.
"""

from __future__ import annotations

from types import ModuleType

from roverlink.commands import decode, demo, emulate, firmware, info, ports, ros2, roundtrip, spec

COMMANDS: tuple[ModuleType, ...] = (demo, info, ports, emulate, ros2, firmware, roundtrip, decode, spec)
