# DO NOT EDIT: generated from protocol/spec/roverlink.toml by `python -m protocol generate`.
# spec hash: 0xBDF31659
"""The release's version: every package's, and the firmware's IDENTITY.firmware_version."""

from typing import Final

__version__: Final = "0.1.0"
VERSION: Final = (0, 1, 0)
LICENSE: Final = "MIT"
