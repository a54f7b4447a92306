"""Enumerations and bit flags of the protocol (generated from protocol/spec/roverlink.toml)."""

from host_sdk._generated.enums import *  # noqa: F403
from host_sdk._generated.enums import __all__ as __all__  # noqa: PLC0414
