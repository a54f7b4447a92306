"""Enumerations and bit flags of the protocol (generated from protocol/spec/roverlink.toml)."""

from protocol.generated.enums import *  # noqa: F403
from protocol.generated.enums import __all__ as __all__  # noqa: PLC0414
