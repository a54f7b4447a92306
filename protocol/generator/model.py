"""The spec as frozen dataclasses: what the loader produces and every emitter consumes."""

from __future__ import annotations

import re
from dataclasses import dataclass

# Wire primitives: name -> (size in bytes, signed, struct code, min, max). f32 bounds are None.
PRIMITIVES: dict[str, tuple[int, bool, str, float | None, float | None]] = {
    "u8": (1, False, "B", 0, 0xFF),
    "i8": (1, True, "b", -0x80, 0x7F),
    "u16": (2, False, "H", 0, 0xFFFF),
    "i16": (2, True, "h", -0x8000, 0x7FFF),
    "u32": (4, False, "I", 0, 0xFFFFFFFF),
    "i32": (4, True, "i", -0x80000000, 0x7FFFFFFF),
    "f32": (4, True, "f", None, None),
    "char": (1, False, "B", 0, 0x7F),
}

DIRECTIONS = ("host_to_mcu", "mcu_to_host")
DELIVERY_CLASSES = ("session", "setpoint", "reliable", "telemetry")


def camel(name: str) -> str:
    """HELLO_WORLD -> HelloWorld (message class names on both sides)."""
    return "".join(part.capitalize() for part in name.lower().split("_"))


@dataclass(frozen=True)
class Constant:
    name: str
    type: str
    value: int
    doc: str


@dataclass(frozen=True)
class EnumValue:
    name: str
    value: int
    doc: str


@dataclass(frozen=True)
class Enum:
    name: str
    base: str
    flags: bool
    values: tuple[EnumValue, ...]
    doc: str

    @property
    def mask(self) -> int:
        out = 0
        for v in self.values:
            out |= v.value
        return out

    def accepts(self, value: int) -> bool:
        if self.flags:
            return value & ~self.mask == 0
        return any(v.value == value for v in self.values)


@dataclass(frozen=True)
class Field:
    """One payload field. `count` is a fixed array length; `max_len` a trailing variable array."""

    name: str
    prim: str  # wire primitive (enums: their base)
    enum: Enum | None
    count: int | None
    max_len: int | None
    min: float | None
    max: float | None
    unit: str
    doc: str

    @property
    def size(self) -> int:
        """Bytes in the fixed part of the payload (0 for a variable array)."""
        if self.max_len is not None:
            return 0
        return PRIMITIVES[self.prim][0] * (self.count or 1)

    @property
    def type_text(self) -> str:
        base = self.enum.name if self.enum else self.prim
        if self.count is not None:
            return f"{base}[{self.count}]"
        if self.max_len is not None:
            return f"{base}[..{self.max_len}]"
        return base

    @property
    def is_float(self) -> bool:
        return self.prim == "f32"

    @property
    def lo(self) -> float:
        """Smallest valid element value (spec range, else the type's)."""
        if self.min is not None:
            return self.min
        low = PRIMITIVES[self.prim][3]
        return -3.4028234663852886e38 if low is None else low

    @property
    def hi(self) -> float:
        if self.max is not None:
            return self.max
        high = PRIMITIVES[self.prim][4]
        return 3.4028234663852886e38 if high is None else high

    @property
    def has_explicit_range(self) -> bool:
        return self.min is not None or self.max is not None


@dataclass(frozen=True)
class FieldSet:
    """Fields several messages share, spliced in with `{ include = NAME }`.

    A set that names a `struct` is also a type of its own on both sides (C++ struct, Python
    dataclass): code that keeps those values (the decoder's counters, the link's) keeps them in
    it, and a message that includes the set carries them in the same order (checked in C++).
    """

    name: str
    struct: str | None
    fields: tuple[Field, ...]
    doc: str

    @property
    def size(self) -> int:
        return sum(f.size for f in self.fields)


@dataclass(frozen=True)
class Message:
    id: int
    name: str
    direction: str
    delivery: str
    fields: tuple[Field, ...]
    doc: str
    crc_extra: int
    includes: tuple[str, ...] = ()
    """Names of the field sets spliced in, in order."""

    @property
    def class_name(self) -> str:
        return camel(self.name)

    @property
    def payload_size(self) -> int:
        """Fixed part of the payload."""
        return sum(f.size for f in self.fields)

    @property
    def payload_max(self) -> int:
        tail = self.fields[-1] if self.fields else None
        extra = tail.max_len if tail is not None and tail.max_len is not None else 0
        return self.payload_size + extra * (PRIMITIVES[tail.prim][0] if tail else 0)

    @property
    def trailing(self) -> Field | None:
        if self.fields and self.fields[-1].max_len is not None:
            return self.fields[-1]
        return None


@dataclass(frozen=True)
class Named:
    name: str
    doc: str


@dataclass(frozen=True)
class Transition:
    sources: tuple[str, ...]  # expanded: never "*"
    event: str
    guard: str | None
    negated: bool
    target: str | None  # None: stay in the source state
    actions: tuple[str, ...]


@dataclass(frozen=True)
class StateMachine:
    initial: str
    states: tuple[Named, ...]
    events: tuple[Named, ...]
    guards: tuple[Named, ...]
    actions: tuple[Named, ...]
    transitions: tuple[Transition, ...]
    doc: str

    def rows(self) -> list[tuple[str, str, str | None, bool, str, tuple[str, ...]]]:
        """Flat table, one row per source state, in spec order: (from, event, guard, negated, to, actions)."""
        out = []
        for t in self.transitions:
            for src in t.sources:
                out.append((src, t.event, t.guard, t.negated, t.target or src, t.actions))
        return out


_RELEASE = re.compile(r"(0|[1-9][0-9]{0,2})(\.(0|[1-9][0-9]{0,2})){2}")


def release_parts(text: str) -> tuple[int, int, int] | None:
    """(major, minor, patch) of "MAJOR.MINOR.PATCH", each 0..255 without leading zeros; else None."""
    if not _RELEASE.fullmatch(text):
        return None
    major, minor, patch = (int(p) for p in text.split("."))
    return (major, minor, patch) if max(major, minor, patch) <= 0xFF else None


@dataclass(frozen=True)
class Spec:
    path: str  # repository-relative, for DO NOT EDIT lines
    name: str
    version: int
    max_payload: int
    crc_name: str
    crc_poly: int
    crc_init: int
    crc_xorout: int
    crc_check: int
    constants: tuple[Constant, ...]
    enums: tuple[Enum, ...]
    messages: tuple[Message, ...]
    state_machine: StateMachine
    spec_hash: int
    doc: str
    field_sets: tuple[FieldSet, ...] = ()
    release: tuple[int, int, int] = (0, 0, 0)
    """The release's version ([release] in the spec): every package's and the firmware's. Not part
    of the spec hash: two releases that speak the same wire talk to each other."""

    @property
    def release_text(self) -> str:
        return ".".join(str(part) for part in self.release)

    @property
    def structs(self) -> tuple[FieldSet, ...]:
        """The field sets that are types of their own, in spec order."""
        return tuple(s for s in self.field_sets if s.struct is not None)

    @property
    def max_body(self) -> int:
        return self.max_payload + 4

    @property
    def max_frame(self) -> int:
        """Longest frame on the wire: COBS adds one byte per 254 (at least one), plus the delimiter."""
        return self.max_body + (self.max_body // 254) + 1 + 1

    def enum(self, name: str) -> Enum:
        return next(e for e in self.enums if e.name == name)

    def message(self, name: str) -> Message:
        return next(m for m in self.messages if m.name == name)

    def field_set(self, name: str) -> FieldSet:
        return next(s for s in self.field_sets if s.name == name)


SNAKE = re.compile(r"^[a-z][a-z0-9_]*$")
UPPER = re.compile(r"^[A-Z][A-Z0-9_]*$")
CAMEL = re.compile(r"^[A-Z][A-Za-z0-9]*$")
