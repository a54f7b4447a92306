"""The `roverlink` command: tools on top of the SDK, the emulator and the protocol.

Each command is one module in roverlink/commands/ with `add_parser(subparsers)`; roverlink/cli.py
lists them. The firmware build tool they share is roverlink/firmware/.
"""

__version__ = "0.1.0"
