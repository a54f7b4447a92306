"""Encode errors, property-tested from the spec metadata: a value just outside a field's range,
of the wrong type, or not representable is refused with an EncodeError naming the message, the
field, the value and what is allowed (the wire encoder's checks, the last line of defence)."""

from __future__ import annotations

import dataclasses
import math
import struct
from pathlib import Path
from typing import Any

import pytest
from hypothesis import example, given, settings
from hypothesis import strategies as st

from host_sdk import messages
from host_sdk.errors import EncodeError
from host_sdk.framing import Frame, encode_frame
from host_sdk.testing import strategies as rls
from protocol.codec.message import FieldInfo, Message

ALL: tuple[type[Message], ...] = messages.ALL_MESSAGES
BY_ID: dict[int, type[Message]] = {cls.MSG_ID: cls for cls in ALL}
OVERHEAD = 6  # COBS code, msg_id, seq, CRC x2, delimiter (docs/protocol.md)
VECTOR_DIR = Path(__file__).resolve().parents[3] / "protocol" / "vectors"


def _name(cls: type[Message]) -> str:
    return cls.NAME


# -- encode errors ------------------------------------------------------------------------------------------
def _fmt(x: float) -> str:
    return str(int(x)) if float(x).is_integer() else repr(x)


def _f32_step(x: float, up: bool) -> float:
    """The next float32 value beyond the float32 value `x`."""
    (bits,) = struct.unpack("<i", struct.pack("<f", x))
    if x == 0.0:
        return 1.401298464324817e-45 if up else -1.401298464324817e-45
    neighbour: float = struct.unpack("<f", struct.pack("<i", bits + (1 if (x > 0) == up else -1)))[0]
    return neighbour


def just_outside(info: FieldInfo) -> list[float]:
    if info.kind == "float":
        return [
            math.nextafter(info.lo, -math.inf),
            math.nextafter(info.hi, math.inf),
            _f32_step(info.lo, up=False),
            _f32_step(info.hi, up=True),
        ]
    return [int(info.lo) - 1, int(info.hi) + 1]


NUMERIC_FIELDS = [
    pytest.param(cls, i, id=f"{cls.NAME}.{info.name}")
    for cls in ALL
    for i, info in enumerate(cls.FIELDS)
    if info.kind in ("int", "float")
]
FLOAT_FIELDS = [p for p in NUMERIC_FIELDS if p.values[0].FIELDS[p.values[1]].kind == "float"]  # type: ignore[union-attr,index]
ALL_FIELDS = [pytest.param(cls, i, id=f"{cls.NAME}.{info.name}") for cls in ALL for i, info in enumerate(cls.FIELDS)]


# The per-field error tests below run once per field (hundreds of tests) and draw their bad value
# from a short list, so a twentieth of the profile's examples (at least 10) covers them.
per_field = settings(max_examples=max(10, settings().max_examples // 20))


def _replace(msg: Message, info: FieldInfo, value: Any, data: st.DataObject) -> tuple[Message, Any]:
    """`msg` with `value` put in field `info` (in one drawn element for a fixed array)."""
    if info.count is not None:
        current = list(getattr(msg, info.name))
        current[data.draw(st.integers(0, info.count - 1), label="element")] = value
        value = tuple(current)
    return dataclasses.replace(msg, **{info.name: value}), value  # type: ignore[type-var]


def _assert_refused(broken: Message, info: FieldInfo, shown: Any) -> None:
    for encode in (broken.pack, lambda: encode_frame(broken, 0)):
        with pytest.raises(EncodeError) as caught:
            encode()
        err = caught.value
        assert isinstance(err, ValueError)
        assert (err.message, err.field) == (broken.NAME, info.name)
        assert err.value is shown or err.value == shown
        text = str(err)
        assert broken.NAME in text and info.name in text and repr(shown) in text, text
        if info.kind in ("int", "float"):
            assert f"{_fmt(info.lo)}..{_fmt(info.hi)}" in text, text


@pytest.mark.parametrize(("cls", "index"), NUMERIC_FIELDS)
@per_field
@given(data=st.data())
def test_value_just_outside_range_is_refused(cls: type[Message], index: int, data: st.DataObject) -> None:
    info = cls.FIELDS[index]
    msg = data.draw(rls.message(cls), label="valid message")
    bad = data.draw(st.sampled_from(just_outside(info)), label="bad value")
    broken, shown = _replace(msg, info, bad, data)
    _assert_refused(broken, info, shown)


@pytest.mark.parametrize(("cls", "index"), FLOAT_FIELDS)
@per_field
@given(data=st.data())
def test_nan_and_infinity_are_refused(cls: type[Message], index: int, data: st.DataObject) -> None:
    info = cls.FIELDS[index]
    msg = data.draw(rls.message(cls), label="valid message")
    bad = data.draw(st.sampled_from([math.nan, math.inf, -math.inf]), label="bad value")
    broken, shown = _replace(msg, info, bad, data)
    _assert_refused(broken, info, shown)


def wrong_values(info: FieldInfo) -> list[Any]:
    """Values of the wrong type (or outside an enum, flag mask or length) for a field."""
    if info.kind == "str":
        return ["é", "x" * ((info.max_len or 0) + 1), b"abc", None, 3]
    if info.kind == "bytes":
        return ["abc", b"x" * ((info.max_len or 0) + 1), None, 3]
    common: list[Any] = ["1", None, b"\x01", [1]]
    if info.kind == "int":
        return [*common, 1.0, 0.5]
    if info.kind == "float":
        return [*common, "nan", 10**400, -(10**400)]
    assert info.enum is not None
    members = {int(m) for m in info.enum}  # type: ignore[attr-defined]
    if info.kind == "enum":
        outside = next(v for v in range(256) if v not in members)
        return [*common, outside, -1, 1.0, next(iter(info.enum)).name]
    return [*common, int(info.hi) + 1, -1, 1.0]


@pytest.mark.parametrize(("cls", "index"), ALL_FIELDS)
@per_field
@given(data=st.data())
def test_wrong_type_is_refused(cls: type[Message], index: int, data: st.DataObject) -> None:
    info = cls.FIELDS[index]
    msg = data.draw(rls.message(cls), label="valid message")
    bad = data.draw(st.sampled_from(wrong_values(info)), label="bad value")
    broken, shown = _replace(msg, info, bad, data)
    _assert_refused(broken, info, shown)


def simplest(cls: type[Message]) -> Message:
    """A valid message from the metadata alone: each value as near 0 as its range allows."""
    values: dict[str, Any] = {}
    for info in cls.FIELDS:
        if info.kind in ("str", "bytes"):
            values[info.name] = "" if info.kind == "str" else b""
            continue
        if info.kind == "enum":
            assert info.enum is not None
            element: Any = next(iter(info.enum))
        elif info.kind == "flags":
            assert info.enum is not None
            element = info.enum(0)
        else:
            element = min(max(0, info.lo), info.hi)
            element = float(element) if info.kind == "float" else int(element)
        values[info.name] = element if info.count is None else (element,) * info.count
    msg = cls(**values)
    msg.pack()
    return msg


def bools_in_range(info: FieldInfo) -> list[bool]:
    """True and False where their int values would be valid (elsewhere any check refuses them)."""
    if info.kind == "flags":
        return [True, False]
    if info.kind == "enum":
        assert info.enum is not None
        return [b for b in (True, False) if int(b) in {int(m) for m in info.enum}]  # type: ignore[attr-defined]
    return [b for b in (True, False) if info.lo <= b <= info.hi]


# Not a Hypothesis test: it walks every numeric field of every message once.
def test_bools_are_refused() -> None:
    accepted = []
    for cls in ALL:
        base = simplest(cls)
        for info in cls.FIELDS:
            if info.kind in ("str", "bytes"):
                continue
            for flag in bools_in_range(info):
                value: Any = flag if info.count is None else (flag, *getattr(base, info.name)[1:])
                try:
                    dataclasses.replace(base, **{info.name: value}).pack()  # type: ignore[type-var]
                except EncodeError as err:
                    assert err.field == info.name
                else:
                    accepted.append(f"{cls.NAME}.{info.name}={flag}")
    assert not accepted, f"pack() accepted bools: {accepted}"


@pytest.mark.parametrize(("cls", "index"), [p for p in ALL_FIELDS if p.values[0].FIELDS[p.values[1]].count])  # type: ignore[union-attr,index]
@per_field
@given(data=st.data())
def test_fixed_array_of_wrong_length_is_refused(cls: type[Message], index: int, data: st.DataObject) -> None:
    info = cls.FIELDS[index]
    assert info.count is not None
    msg = data.draw(rls.message(cls), label="valid message")
    element = data.draw(rls.field_values(dataclasses.replace(info, count=None)), label="element")
    length = data.draw(st.sampled_from([0, info.count - 1, info.count + 1]), label="length")
    bad = (element,) * length
    broken = dataclasses.replace(msg, **{info.name: bad})  # type: ignore[type-var]
    _assert_refused(broken, info, bad)


@given(frame=rls.frames(), seq=st.one_of(st.integers(max_value=-1), st.integers(min_value=256)))
@example(frame=Frame(messages.Disarm(), 0), seq=-1)
@example(frame=Frame(messages.Disarm(), 0), seq=256)
def test_seq_outside_byte_is_refused(frame: Frame, seq: int) -> None:
    with pytest.raises(EncodeError) as caught:
        encode_frame(frame.message, seq)
    assert isinstance(caught.value, ValueError)
    assert caught.value.field == "seq" and caught.value.message == frame.message.NAME
    assert "0..255" in str(caught.value) and repr(seq) in str(caught.value)


@pytest.mark.parametrize("seq", ["1", 1.0, None, True, b"\x01"], ids=repr)
def test_seq_of_wrong_type_is_refused(seq: Any) -> None:
    with pytest.raises(EncodeError):
        encode_frame(messages.Disarm(), seq)


# -- the strategies themselves --------------------------------------------------------------------------
@given(msg=rls.messages())
def test_strategies_make_only_valid_messages(msg: Message) -> None:
    for info in msg.FIELDS:
        value = getattr(msg, info.name)
        values = value if info.count is not None else (value,)
        if info.kind == "float":
            assert all(struct.unpack("<f", struct.pack("<f", v))[0] == v for v in values), "exact f32"
        if info.kind in ("int", "float"):
            assert all(info.lo <= v <= info.hi for v in values)
        if info.kind == "str":
            assert value.isascii() and len(value) <= (info.max_len or 0)


def test_importing_the_sdk_does_not_import_hypothesis() -> None:
    import subprocess
    import sys

    code = "import sys, host_sdk, host_sdk.framing, host_sdk.messages; print('hypothesis' in sys.modules)"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "False"
