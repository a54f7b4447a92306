"""The `roverlink` subcommands, one module each, in the order `roverlink --help` lists them.

A command module has `add_parser(subparsers)`, which registers its parser and sets `func`.
"""

from __future__ import annotations

from types import ModuleType

from roverlink.commands import decode, demo, emulate, firmware, follow, info, ports, roundtrip, spec

COMMANDS: tuple[ModuleType, ...] = (demo, info, ports, emulate, firmware, roundtrip, decode, spec, follow)
