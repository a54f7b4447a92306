"""Every RoverLink message class (generated from protocol/spec/roverlink.toml).

Each is a frozen, slotted dataclass with MSG_ID, NAME, CRC_EXTRA, PAYLOAD_SIZE, PAYLOAD_MAX,
DIRECTION, DELIVERY and FIELDS class attributes, `pack()` and `unpack()`. Their base class and
field metadata live in protocol.codec.message.
"""

from protocol.generated.messages import *  # noqa: F403
from protocol.generated.messages import __all__ as __all__  # noqa: PLC0414
