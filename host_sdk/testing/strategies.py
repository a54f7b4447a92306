"""Hypothesis strategies for RoverLink messages, frames and byte streams.

Every strategy is derived from the spec metadata on the generated classes (`cls.FIELDS`), so a
message added to `protocol/spec/roverlink.toml` is covered as soon as the code is regenerated; no
strategy is written by hand for a particular message.

What is generated is always *valid*: it encodes without error and decodes back to an equal value.

* integers lie in the field's range (the spec's ``min``/``max``, else the wire type's);
* ``f32`` values are finite, in range and exactly representable as IEEE-754 single precision
  (they survive ``struct.pack("<f", ...)`` unchanged, so decoded messages compare equal);
* enums are members of their enum, flags any combination of their members;
* ``char[..N]`` fields are ASCII strings of at most N characters (NUL included), ``u8[..N]``
  fields bytes of at most N;
* fixed arrays are tuples of exactly ``count`` elements.

Fuzz your own code with them, e.g. a handler that must accept any telemetry the board can send::

    from hypothesis import given
    from host_sdk import messages
    from host_sdk.testing import strategies as rls

    @given(rls.message(messages.Feedback))
    def test_odometry_never_crashes(fb: messages.Feedback) -> None:
        Odometry().update(fb)

    @given(rls.streams(max_frames=20))
    def test_reader_sees_every_frame(stream: rls.Stream) -> None:
        reader = MyReader()
        reader.on_bytes(stream.wire)
        assert reader.received == [f.message for f in stream.frames]

``frames()`` and ``streams()`` give what a port would carry, for testing code that reads bytes.
hypothesis is needed only here: ``import host_sdk`` never imports it (install the ``dev`` extra).
"""

from __future__ import annotations

import enum
import functools
import operator
import struct
from collections.abc import Iterable
from typing import Any, NamedTuple, TypeVar, cast

from hypothesis import strategies as st

from host_sdk.framing import Frame, encode_frame
from protocol.codec.message import FieldInfo, Message
from protocol.generated.messages import ALL_MESSAGES

__all__ = [
    "Stream",
    "field_values",
    "frames",
    "message",
    "messages",
    "seqs",
    "streams",
]

M = TypeVar("M", bound=Message)

_F32 = struct.Struct("<f")
_F32_MAX = 3.4028234663852886e38


class Stream(NamedTuple):
    """Frames in the order they were sent, and the bytes a port would carry for them."""

    frames: list[Frame]
    """(message, seq) pairs; each compares equal to the `Frame` a decoder yields for it."""
    wire: bytes
    """Every frame encoded with `encode_frame`, back to back (each ends with its 0x00)."""


def _to_f32(x: float) -> float:
    """`x` rounded to the nearest single-precision value (what goes on the wire)."""
    rounded: float = _F32.unpack(_F32.pack(x))[0]
    return rounded


def _f32_bounds(lo: float, hi: float) -> tuple[float, float]:
    """The smallest and largest f32 values inside [lo, hi] (the spec's bounds may not be f32)."""
    lo, hi = max(lo, -_F32_MAX), min(hi, _F32_MAX)
    lo32, hi32 = _to_f32(lo), _to_f32(hi)
    if lo32 < lo:  # rounding to nearest is off by at most half an ulp: one step fixes it
        lo32 = _next_f32(lo32, up=True)
    if hi32 > hi:
        hi32 = _next_f32(hi32, up=False)
    if lo32 > hi32:
        raise ValueError(f"no f32 value lies in {lo!r}..{hi!r}")
    return lo32, hi32


def _next_f32(x: float, *, up: bool) -> float:
    """The f32 neighbour of the f32 value `x` (bit pattern plus or minus one)."""
    (bits,) = struct.unpack("<i", _F32.pack(x))
    if x == 0.0:
        return 1.401298464324817e-45 if up else -1.401298464324817e-45
    step = 1 if (x > 0) == up else -1
    neighbour: float = _F32.unpack(struct.pack("<i", bits + step))[0]
    return neighbour


def _scalar(info: FieldInfo) -> st.SearchStrategy[Any]:
    """Values of one element of the field (the field itself unless it is an array)."""
    if info.kind == "int":
        return st.integers(min_value=int(info.lo), max_value=int(info.hi))
    if info.kind == "float":
        lo, hi = _f32_bounds(float(info.lo), float(info.hi))
        return st.floats(min_value=lo, max_value=hi, width=32, allow_nan=False, allow_infinity=False).map(_to_f32)
    if info.kind == "enum":
        if info.enum is None:
            raise TypeError(f"enum field {info.name} has no enum class")
        return st.sampled_from(list(cast("Iterable[enum.IntEnum]", info.enum)))
    if info.kind == "flags":
        if info.enum is None:
            raise TypeError(f"flags field {info.name} has no enum class")
        flag_cls = cast("type[enum.IntFlag]", info.enum)
        members = [m for m in flag_cls if not int(m) & ~int(info.hi)]
        empty = flag_cls(0)
        if not members:
            return st.just(empty)
        return st.sets(st.sampled_from(members)).map(lambda bits: functools.reduce(operator.or_, bits, empty))
    raise ValueError(f"field {info.name}: no strategy for kind {info.kind!r}")


@functools.cache
def field_values(info: FieldInfo) -> st.SearchStrategy[Any]:
    """Valid values of one field, as its message class expects them (tuples for fixed arrays).

    `FieldInfo` is what each generated class lists in `FIELDS`; e.g. ``field_values(
    messages.SetAckermann.FIELDS[1])`` gives steering angles in -1571..1571.
    """
    if info.kind == "str":
        alphabet = st.characters(min_codepoint=int(info.lo), max_codepoint=min(int(info.hi), 127))
        return st.text(alphabet=alphabet, max_size=info.max_len)
    if info.kind == "bytes":
        if info.count is not None:
            return st.binary(min_size=info.count, max_size=info.count)
        return st.binary(max_size=info.max_len)
    element = _scalar(info)
    if info.count is not None:
        return st.tuples(*[element] * info.count)
    return element


# Built once per class (and per tuple of classes): hypothesis strategies are immutable and lazy.
_BY_CLASS: dict[type[Message], st.SearchStrategy[Message]] = {}
_BY_CLASSES: dict[tuple[type[Message], ...], st.SearchStrategy[Message]] = {}


def _message(cls: type[Message]) -> st.SearchStrategy[Message]:
    strategy = _BY_CLASS.get(cls)
    if strategy is None:
        by_name = {info.name: field_values(info) for info in cls.FIELDS}
        strategy = _BY_CLASS[cls] = st.fixed_dictionaries(by_name).map(lambda values: cls(**values))
    return strategy


def message(cls: type[M]) -> st.SearchStrategy[M]:
    """Valid instances of one message class, e.g. ``message(messages.SetWheelSpeeds)``.

    The strategy is built once per class from ``cls.FIELDS`` and cached.
    """
    return cast("st.SearchStrategy[M]", _message(cls))


def _messages(classes: tuple[type[Message], ...]) -> st.SearchStrategy[Message]:
    strategy = _BY_CLASSES.get(classes)
    if strategy is None:
        if not classes:
            raise ValueError("messages() needs at least one message class")
        strategy = _BY_CLASSES[classes] = st.one_of([_message(cls) for cls in classes])
    return strategy


def messages(classes: Iterable[type[Message]] | None = None) -> st.SearchStrategy[Message]:
    """A valid message of any class (or of one of `classes`), e.g. only what the board sends::

    messages(c for c in ALL_MESSAGES if c.DIRECTION is Direction.MCU_TO_HOST)
    """
    return _messages(tuple(ALL_MESSAGES if classes is None else classes))


def seqs() -> st.SearchStrategy[int]:
    """Sequence numbers: 0..255."""
    return st.integers(min_value=0, max_value=0xFF)


def frames(of: st.SearchStrategy[Message] | None = None) -> st.SearchStrategy[Frame]:
    """(message, seq) pairs, as `Frame` tuples: what `FrameDecoder.feed` yields for a good frame.

    `of` defaults to `messages()`; pass e.g. ``message(messages.Feedback)`` to fix the class.
    """
    return st.builds(Frame, messages() if of is None else of, seqs())


def _stream(items: list[Frame]) -> Stream:
    return Stream(items, b"".join([encode_frame(msg, seq) for msg, seq in items]))


def streams(
    of: st.SearchStrategy[Frame] | None = None, *, min_frames: int = 0, max_frames: int = 10
) -> st.SearchStrategy[Stream]:
    """A `Stream`: frames (from `of`, default `frames()`) and their concatenated wire bytes.

    Unpacks as a pair: ``sent, wire = data.draw(streams())``.
    """
    items = st.lists(frames() if of is None else of, min_size=min_frames, max_size=max_frames)
    return items.map(_stream)
