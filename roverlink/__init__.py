"""The `roverlink` command: tools on top of the SDK, the emulator and the protocol.

Each command is one module in roverlink/commands/ with `add_parser(subparsers)`; roverlink/cli.py
lists them. The firmware build tool they share is roverlink/firmware/.
"""

from protocol.generated.version import __version__

__all__ = ["__version__"]
