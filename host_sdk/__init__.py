"""RoverLink host SDK: talk to a RoverLink robot (board, simulator or emulator) from Python."""

from host_sdk import enums, messages
from host_sdk._generated.constants import PROTOCOL_VERSION, SPEC_HASH
from host_sdk.errors import CodecError, DecodeError, EncodeError, RoverLinkError

__all__ = [
    "PROTOCOL_VERSION",
    "SPEC_HASH",
    "CodecError",
    "DecodeError",
    "EncodeError",
    "RoverLinkError",
    "enums",
    "messages",
]
__version__ = "0.1.0"
