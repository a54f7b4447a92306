"""The C++ codec (arduino/RoverLink/src) held against the Python codec (host_sdk), byte for byte.

`make -C tests/firmware/native tools` builds rl_codec, a line-oriented driver of the C++ codec (its command
language is documented at the top of tests/firmware/native/rl_codec.cpp). One AddressSanitizer +
UndefinedBehaviorSanitizer build of it runs for the whole session behind a pipe; any sanitizer
report, crash or non-zero exit fails the session at teardown.

Covered here:

* the native unit tests (`make test`, plain + sanitizers) and the avr-g++ build (`make avr`);
* every golden vector in protocol/vectors/*.json decodes in C++ to the vector's fields and
  re-encodes to the vector's frame;
* Python `encode_frame` == C++ `encode_message` for messages from host_sdk.testing.strategies,
  and C++ decodes those frames to the same field values;
* for byte streams with garbage, hand-built frames (any id, length and payload, a CRC that is
  usually right) and dropped / inserted / flipped bytes, both decoders report the same events
  in the same order and the same counters;
* the session state machine: C++ `proto::step` == Python `emulator.firmware.statemachine.step` for every
  state, event and combination of guards.

Fields are compared in the text form of the generated test header tests/firmware/native/generated/
roverlink_reflect.h (`print_fields`), which `canonical()` (tests/support/rl_codec.py) reproduces from a
Python message.
"""

from __future__ import annotations

import itertools
import json
import math
import shutil
import struct
from binascii import crc_hqx
from typing import Any

import pytest
from hypothesis import example, given
from hypothesis import strategies as st

from emulator.firmware.statemachine import Guard, SessionEvent, SessionState, step
from host_sdk import messages
from host_sdk.framing import Frame, encode_frame
from host_sdk.testing import strategies
from protocol.codec.cobs import cobs_encode
from protocol.codec.message import FieldInfo, Message
from protocol.generated.constants import MAX_PAYLOAD
from tests.support.rl_codec import (
    BY_NAME,
    STAT_NAMES,
    VECTOR_DIR,
    RlCodec,
    assert_decoders_agree,
    field_text,
    frame_item,
    require_make,
)


# -- make targets ---------------------------------------------------------------------------------------
def test_native_unit_tests_pass() -> None:
    result = require_make("test")
    assert "0 failed" in result.stdout, result.stdout


def test_avr_build() -> None:
    if shutil.which("avr-g++") is None:
        pytest.fail("avr-g++ is required (scripts/test.sh installs gcc-avr and avr-libc)", pytrace=False)
    result = require_make("avr")
    assert "SKIPPED" not in result.stdout, result.stdout
    assert "atmega328p" in result.stdout, result.stdout


# -- golden vectors -----------------------------------------------------------------------------------
def _json_element(info: FieldInfo, raw: Any) -> Any:
    if info.kind in ("enum", "flags"):
        assert info.enum is not None
        return info.enum(raw)
    if info.kind == "float":
        return float(raw)
    return int(raw)


def _json_field(info: FieldInfo, raw: Any) -> Any:
    if info.kind == "str":
        return str(raw)
    if info.kind == "bytes":
        return bytes.fromhex(raw)
    if info.count is not None:
        return tuple(_json_element(info, x) for x in raw)
    return _json_element(info, raw)


def _vectors() -> list[Any]:
    params = []
    for path in sorted(VECTOR_DIR.glob("*.json")):
        doc = json.loads(path.read_text(encoding="utf-8"))
        for i, vector in enumerate(doc["vectors"]):
            params.append(pytest.param(doc["message"], vector, id=f"{doc['message']}-{i}-{vector['case']}"))
    return params


VECTORS = _vectors()


def test_there_are_vectors_for_every_message() -> None:
    assert {p.values[0] for p in VECTORS} == set(BY_NAME)


@pytest.mark.parametrize(("name", "vector"), VECTORS)
def test_golden_vector(codec: RlCodec, name: str, vector: dict[str, Any]) -> None:
    cls = BY_NAME[name]
    msg = cls(**{info.name: _json_field(info, vector["fields"][info.name]) for info in cls.FIELDS})
    seq = vector["seq"]
    frame = bytes.fromhex(vector["frame"])

    decoded = codec.decode(frame)
    assert decoded.items == [frame_item(msg, seq)]
    assert decoded.stats == dict.fromkeys(STAT_NAMES, 0) | {"frames_ok": 1}

    assert codec.encode(msg, seq) == f"FRAME {vector['frame']}"


# -- encoder and decoder against Python, from the strategies ------------------------------------------------
@given(strategies.frames())
def test_cpp_encodes_and_decodes_like_python(codec: RlCodec, frame: Frame) -> None:
    msg, seq = frame
    wire = encode_frame(msg, seq)
    assert codec.encode(msg, seq) == f"FRAME {wire.hex()}"
    decoded = codec.decode(wire)
    assert decoded.items == [frame_item(msg, seq)]
    assert decoded.stats == dict.fromkeys(STAT_NAMES, 0) | {"frames_ok": 1}


# -- check_ranges: the C++ layouts' range checks against the spec's ranges -----------------------------
NUMERIC_KINDS = ("int", "float")
F32_MAX = 3.4028234663852886e38


def _base_value(info: FieldInfo) -> Any:
    """A value every check accepts: the low end of a numeric range, an enum's first member."""
    if info.kind == "str":
        return ""
    if info.kind == "bytes":
        return b""
    if info.kind == "enum" and info.enum is not None:
        value: Any = next(iter(info.enum)).value
    elif info.kind in NUMERIC_KINDS:
        value = info.lo
    else:
        value = 0
    return (value,) * info.count if info.count is not None else value


def _edge_values(info: FieldInfo) -> list[float]:
    """Values of one element at and around the field's range, all representable in its wire type."""
    if info.kind == "float":
        out = [info.lo, info.hi, -0.0, 0.0, math.nan, math.inf, -math.inf, F32_MAX, -F32_MAX]
        out += [math.nextafter(info.lo, -math.inf), math.nextafter(info.hi, math.inf)]
        return [v for v in out if math.isnan(v) or abs(v) <= F32_MAX or math.isinf(v)]
    wire = WIRE_RANGES[info.wire_type.split("[")[0]]
    out = [info.lo, info.hi, info.lo - 1, info.hi + 1, wire[0], wire[1], 0, -1, 1]
    return [v for v in out if wire[0] <= v <= wire[1]]


WIRE_RANGES = {
    "u8": (0, 0xFF),
    "i8": (-0x80, 0x7F),
    "u16": (0, 0xFFFF),
    "i16": (-0x8000, 0x7FFF),
    "u32": (0, 0xFFFFFFFF),
    "i32": (-0x80000000, 0x7FFFFFFF),
}


def _in_range(info: FieldInfo, value: float) -> bool:
    if info.kind == "float":
        stored = struct.unpack("<f", struct.pack("<f", value))[0] if not math.isinf(value) else value
        return not math.isnan(stored) and info.lo <= stored <= info.hi  # NaN fails; -0.0 == 0.0
    return info.lo <= value <= info.hi


@pytest.mark.parametrize("cls", messages.ALL_MESSAGES, ids=lambda c: c.NAME)
def test_check_ranges_matches_the_spec(codec: RlCodec, cls: type[Message]) -> None:
    """Every element of every numeric field at the edges of its range, one field at a time."""
    base = {info.name: _base_value(info) for info in cls.FIELDS}
    pairs = {info.name: f"{info.name}={field_text(info, base[info.name])}" for info in cls.FIELDS}
    assert codec.check_ranges(cls.NAME, list(pairs.values())) == 255, "the base values are valid"
    for index, info in enumerate(cls.FIELDS):
        if info.kind not in NUMERIC_KINDS:
            continue
        for element in range(info.count or 1):
            for value in _edge_values(info):
                field = list(base[info.name]) if info.count is not None else value
                if info.count is not None:
                    field[element] = value
                text = dict(pairs, **{info.name: f"{info.name}={field_text(info, field)}"})
                expected = 255 if _in_range(info, value) else index
                got = codec.check_ranges(cls.NAME, list(text.values()))
                assert got == expected, f"{cls.NAME}.{info.name}[{element}] = {value!r}: {got} != {expected}"


def test_encode_rejects_malformed_commands(codec: RlCodec) -> None:
    assert codec.ask("E NO_SUCH_MESSAGE 1").startswith("ERR ")
    assert codec.ask("E PING 256").startswith("ERR ")
    assert codec.ask("E PING 1 no_such_field=3").startswith("ERR ")
    assert codec.ask("E SET_WHEEL_SPEEDS 1 left_mm_s=40000").startswith("ERR ")  # does not fit i16
    assert codec.ask("D 0g").startswith("ERR ")
    assert codec.ask("X").startswith("ERR ")


# -- random byte streams ------------------------------------------------------------------------------------
KNOWN_CLASSES = list(messages.ALL_MESSAGES)


def hand_frame(msg_id: int, seq: int, payload: bytes, crc_extra: int | None = None) -> bytes:
    """A frame around any payload, with a good CRC (using msg_id's CRC_EXTRA unless given)."""
    if crc_extra is None:
        crc_extra = messages.BY_ID[msg_id].CRC_EXTRA
    body = bytes((msg_id, seq)) + payload
    crc = crc_hqx(bytes((crc_extra,)), crc_hqx(body, 0xFFFF))
    return cobs_encode(body + crc.to_bytes(2, "little")) + b"\x00"


def payload_bytes(length: int) -> st.SearchStrategy[bytes]:
    """`length` bytes: Hypothesis's own (which favour 0x00, a valid value of most enums) or uniform."""
    uniform = st.randoms(use_true_random=False).map(lambda rnd: rnd.randbytes(length))
    return st.one_of(st.binary(min_size=length, max_size=length), uniform)


@st.composite
def raw_frames(draw: st.DrawFn) -> bytes:
    """A frame built by hand: any msg_id, payload length and payload bytes; the CRC usually right.

    Reaches what valid messages never do: payload length errors, enum and flag values the spec
    does not define (value errors), unknown ids, bodies too long for a frame.
    """
    if draw(st.integers(0, 4)):
        cls = draw(st.sampled_from(KNOWN_CLASSES))
        msg_id, extra = cls.MSG_ID, cls.CRC_EXTRA
        length = draw(
            st.one_of(
                st.integers(cls.PAYLOAD_SIZE, cls.PAYLOAD_MAX),
                st.integers(max(0, cls.PAYLOAD_SIZE - 2), cls.PAYLOAD_MAX + 2),
                st.integers(0, MAX_PAYLOAD + 2),
            )
        )
    else:
        msg_id, extra = draw(st.integers(0, 255)), draw(st.integers(0, 255))
        length = draw(st.integers(0, MAX_PAYLOAD + 2))
    if not draw(st.integers(0, 5)):
        extra ^= draw(st.integers(1, 0xFF))  # a wrong CRC_EXTRA: a CRC error
    return hand_frame(msg_id, draw(strategies.seqs()), draw(payload_bytes(length)), extra)


VALID_FRAMES = strategies.frames().map(lambda f: encode_frame(f.message, f.seq))
PIECES = st.one_of(
    VALID_FRAMES,
    VALID_FRAMES,
    raw_frames(),
    raw_frames(),
    raw_frames(),
    st.binary(max_size=3).map(lambda body: cobs_encode(body) + b"\x00"),  # shorter than a frame
    st.binary(max_size=40),  # garbage
    st.lists(st.integers(1, 255), min_size=60, max_size=150).map(bytes),  # no delimiter for a while
    st.sampled_from([b"\x00", b"\x00\x00"]),
)

# (operation, position, byte): position is taken modulo the stream length.
EDITS = st.tuples(st.sampled_from(["drop", "insert", "flip"]), st.integers(0, 1 << 16), st.integers(0, 255))


def apply_edits(data: bytes, edits: list[tuple[str, int, int]]) -> bytes:
    buf = bytearray(data)
    for op, pos, value in edits:
        if op == "insert":
            buf.insert(pos % (len(buf) + 1), value)
        elif buf and op == "drop":
            del buf[pos % len(buf)]
        elif buf and op == "flip":
            buf[pos % len(buf)] ^= value or 0x01
    return bytes(buf)


@given(
    st.lists(PIECES, max_size=8),
    st.lists(EDITS, max_size=4),
    st.lists(st.integers(0, 1 << 16), max_size=5),
)
@example([b"\x01" * 69 + b"\x00"], [], [])  # longest chunk that is not over-long: a length error
@example([b"\x01" * 70 + b"\x00"], [], [])  # one byte too long
@example([b"\x01" * 200], [], [35, 69, 70, 140])  # over-long across feeds, never ended
@example([b"\x02" * 70, b"\x00\x00\x00"], [], [70])
@example([b"\x05\x11\x01\x01\x01"], [], [])  # ends inside a COBS block, unterminated
@example([b"\x05\x11\x01\x01\x00"], [], [])  # ends inside a COBS block
@example([hand_frame(messages.Nack.MSG_ID, 1, bytes(4))], [], [])  # NackReason 0 is not defined: value
@example([hand_frame(messages.Feedback.MSG_ID, 2, bytes(13) + b"\x80" + bytes(19))], [], [])  # Status bit 7
@example([hand_frame(messages.Log.MSG_ID, 3, b"\x01hi\x80"), hand_frame(messages.Log.MSG_ID, 4, b"\x01")], [], [9])
@example([hand_frame(messages.Ack.MSG_ID, 5, bytes(3))], [], [])  # CRC good, payload length wrong
@example([hand_frame(0x7F, 6, b"", crc_extra=0)], [], [])  # unknown id
def test_decoders_agree_on_any_stream(
    codec: RlCodec, pieces: list[bytes], edits: list[tuple[str, int, int]], cuts: list[int]
) -> None:
    assert_decoders_agree(codec, apply_edits(b"".join(pieces), edits), cuts)


@given(st.lists(strategies.frames(), min_size=1, max_size=6), st.lists(st.integers(0, 1 << 16), max_size=5))
def test_decoders_agree_on_valid_streams(codec: RlCodec, frames: list[Frame], cuts: list[int]) -> None:
    data = b"".join(encode_frame(msg, seq) for msg, seq in frames)
    assert_decoders_agree(codec, data, cuts)
    assert codec.decode(data).items == [frame_item(msg, seq) for msg, seq in frames]


# -- the session state machine ---------------------------------------------------------------------------
@pytest.mark.parametrize("state", list(SessionState), ids=lambda s: s.name)
def test_state_machine_matches_python(codec: RlCodec, state: SessionState) -> None:
    guards = list(Guard)
    for event in SessionEvent:
        for holds in itertools.product((False, True), repeat=len(guards)):
            truth = dict(zip(guards, holds, strict=True))
            mask = sum(1 << int(g) for g, h in truth.items() if h)
            row = step(state, event, lambda g, truth=truth: truth[g])
            want = (False, int(state), 0) if row is None else (True, int(row.target), int(row.actions))
            assert codec.step(int(state), int(event), mask) == want, f"{state.name} {event.name} {truth}"
