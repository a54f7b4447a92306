"""Base class and field metadata shared by every generated message."""

from __future__ import annotations

import enum
import math
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any, ClassVar

from protocol.errors import DecodeError, EncodeError


class Direction(enum.Enum):
    HOST_TO_MCU = "host_to_mcu"
    MCU_TO_HOST = "mcu_to_host"


class Delivery(enum.Enum):
    """How a message is delivered: see docs/protocol.md."""

    SESSION = "session"
    SETPOINT = "setpoint"
    RELIABLE = "reliable"
    TELEMETRY = "telemetry"


@dataclass(frozen=True, slots=True)
class FieldInfo:
    """What the spec says about one field; drives validation errors, strategies and docs.

    kind is "int", "float", "enum", "flags", "str" (char array) or "bytes" (u8 array).
    count is a fixed array length, max_len the maximum of a trailing variable array.
    """

    name: str
    wire_type: str
    kind: str
    lo: float
    hi: float
    unit: str = ""
    count: int | None = None
    max_len: int | None = None
    enum: type[enum.IntEnum] | type[enum.IntFlag] | None = None

    def allowed(self) -> str:
        """Human-readable description of the valid values."""
        unit = f" {self.unit}" if self.unit else ""
        if self.kind == "enum" and self.enum is not None:
            names = ", ".join(f"{m.name}={m.value}" for m in self.enum)
            return f"one of {self.enum.__name__}: {names}"
        if self.kind == "flags" and self.enum is not None:
            return f"a combination of {self.enum.__name__} bits (mask {int(self.hi):#x})"
        if self.kind == "str":
            return f"an ASCII str of at most {self.max_len} characters"
        if self.kind == "bytes":
            return f"bytes of at most {self.max_len}"
        lo, hi = (_num(self.lo), _num(self.hi))
        what = "a finite number" if self.kind == "float" else "an integer"
        base = f"{what} in {lo}..{hi}{unit} ({self.wire_type})"
        if self.count is not None:
            return f"a tuple of {self.count} elements, each {base}"
        return base


def _num(x: float) -> str:
    return str(int(x)) if float(x).is_integer() and abs(x) < 1e15 else repr(x)


class Message:
    """A RoverLink message: a frozen dataclass generated from the spec.

    Class attributes: MSG_ID, NAME, CRC_EXTRA, PAYLOAD_SIZE (fixed part), PAYLOAD_MAX (with the
    trailing array at its longest), DIRECTION, DELIVERY and FIELDS.
    """

    __slots__ = ()

    MSG_ID: ClassVar[int]
    NAME: ClassVar[str]
    CRC_EXTRA: ClassVar[int]
    PAYLOAD_SIZE: ClassVar[int]
    PAYLOAD_MAX: ClassVar[int]
    DIRECTION: ClassVar[Direction]
    DELIVERY: ClassVar[Delivery]
    FIELDS: ClassVar[tuple[FieldInfo, ...]]

    def pack(self) -> bytes:
        """Payload bytes; raises EncodeError naming the first invalid field."""
        raise NotImplementedError

    @classmethod
    def unpack(cls, payload: bytes) -> Message:
        """Message from payload bytes; raises DecodeError (a ValueError) if they do not fit."""
        raise NotImplementedError

    def fields(self) -> dict[str, Any]:
        """Field values by name, in wire order."""
        return {f.name: getattr(self, f.name) for f in self.FIELDS}


# -- validation: the slow path, run only when the fast checks in a generated pack() fail -----------
def first_invalid(msg: Message) -> EncodeError:
    """The EncodeError for the first field of `msg` that breaks its spec (type, range, length)."""
    for info in msg.FIELDS:
        value = getattr(msg, info.name)
        if not _field_ok(info, value):
            return EncodeError(msg.NAME, info.name, value, info.allowed())
    return EncodeError(msg.NAME, "(payload)", msg, "values that pack into the payload")


def _field_ok(info: FieldInfo, value: object) -> bool:
    if info.kind == "str":
        return isinstance(value, str) and len(value) <= (info.max_len or 0) and value.isascii()
    if info.kind == "bytes":
        return isinstance(value, (bytes, bytearray)) and len(value) <= (info.max_len or 0)
    if info.count is not None:
        return isinstance(value, (tuple, list)) and len(value) == info.count and all(_scalar_ok(info, v) for v in value)
    return _scalar_ok(info, value)


def _scalar_ok(info: FieldInfo, value: object) -> bool:
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        return False
    if info.kind == "float":
        try:
            finite = math.isfinite(value)
        except OverflowError:  # an int too large for any float (e.g. 10**400): outside every range
            return False
        return finite and info.lo <= value <= info.hi
    if not isinstance(value, int):
        return False
    if info.kind == "flags":
        return value >= 0 and not value & ~int(info.hi)
    if info.kind == "enum" and info.enum is not None:
        return value in {int(m) for m in info.enum}
    return info.lo <= value <= info.hi


def decode_error(cls: type[Message], problem: str) -> DecodeError:
    return DecodeError(cls.NAME, problem)


def slot_setter(cls: type[Message], name: str) -> Callable[[Message, Any], None]:
    """The raw slot writer of a field: how generated unpack() fills a frozen instance quickly."""
    setter: Callable[[Message, Any], None] = cls.__dict__[name].__set__
    return setter
