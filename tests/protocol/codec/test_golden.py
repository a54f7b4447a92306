"""Golden vectors: the fast codec and the construct oracle against protocol/vectors/*.json.

The vectors come from the generator's own reference encoder (a textbook COBS loop and a
bit-by-bit CRC) and are shared with the firmware's native tests, so these checks tie the Python
codec to the same bytes the C++ codec is held to.
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import pytest
from codec_oracle import codec_values, oracle_values

from host_sdk import messages
from host_sdk.framing import Frame, FrameDecoder, encode_frame
from protocol.codec.cobs import cobs_decode
from protocol.codec.message import FieldInfo, Message
from protocol.generated import oracle

VECTOR_DIR = Path(__file__).resolve().parents[3] / "protocol" / "vectors"
VECTOR_FILES = sorted(VECTOR_DIR.glob("*.json"))
BY_NAME: dict[str, type[Message]] = {cls.NAME: cls for cls in messages.ALL_MESSAGES}


def _load(path: Path) -> dict[str, Any]:
    data: dict[str, Any] = json.loads(path.read_text(encoding="utf-8"))
    return data


FILES = {path.stem: _load(path) for path in VECTOR_FILES}
VECTORS = [(doc["message"], vector) for doc in FILES.values() for vector in doc["vectors"]]
VECTOR_IDS = [f"{name}-{v['case']}-seq{v['seq']}" for name, v in VECTORS]


# -- building messages from JSON -------------------------------------------------------------------
def _element(info: FieldInfo, raw: Any) -> Any:
    if info.kind in ("enum", "flags"):
        assert info.enum is not None
        assert isinstance(raw, int), f"{info.name}: enum values are JSON ints"
        return info.enum(raw)
    if info.kind == "float":
        assert isinstance(raw, (int, float))
        return float(raw)
    assert isinstance(raw, int) and not isinstance(raw, bool), f"{info.name}: {raw!r} is not an int"
    return raw


def field_from_json(info: FieldInfo, raw: Any) -> Any:
    """A field's value as the message class takes it, from its JSON form in a vector file."""
    if info.kind == "str":
        assert isinstance(raw, str), f"{info.name}: char arrays are JSON strings"
        return raw
    if info.kind == "bytes":
        assert isinstance(raw, str), f"{info.name}: u8 arrays of variable length are hex strings"
        return bytes.fromhex(raw)
    if info.count is not None:
        assert isinstance(raw, list) and len(raw) == info.count, f"{info.name}: expected {info.count} elements"
        return tuple(_element(info, x) for x in raw)
    return _element(info, raw)


def message_from_json(cls: type[Message], fields: dict[str, Any]) -> Message:
    assert list(fields) == [info.name for info in cls.FIELDS], "vector fields are the class's, in wire order"
    return cls(**{info.name: field_from_json(info, fields[info.name]) for info in cls.FIELDS})


# -- comparing field values exactly ---------------------------------------------------------------
# -- the vector files themselves --------------------------------------------------------------------
def test_there_are_vectors() -> None:
    assert VECTOR_FILES, f"no golden vectors in {VECTOR_DIR}"


def test_every_message_class_has_a_vector_file() -> None:
    names_in_files = {doc["message"] for doc in FILES.values()}
    missing = sorted(set(BY_NAME) - names_in_files)
    assert not missing, f"message classes without golden vectors: {missing}"


@pytest.mark.parametrize("stem", sorted(FILES))
def test_vector_file_names_an_existing_message(stem: str) -> None:
    doc = FILES[stem]
    assert doc["message"] in BY_NAME, f"{stem}.json: no message class named {doc['message']}"
    cls = BY_NAME[doc["message"]]
    assert stem == cls.NAME.lower()
    assert doc["msg_id"] == cls.MSG_ID
    assert doc["crc_extra"] == cls.CRC_EXTRA
    assert oracle.NAMES[cls.MSG_ID] == cls.NAME
    assert oracle.CRC_EXTRA[cls.MSG_ID] == cls.CRC_EXTRA
    assert doc["vectors"], f"{stem}.json has no vectors"


# -- every vector -----------------------------------------------------------------------------------
@pytest.mark.parametrize(("name", "vector"), VECTORS, ids=VECTOR_IDS)
def test_encode_matches_golden(name: str, vector: dict[str, Any]) -> None:
    cls = BY_NAME[name]
    msg = message_from_json(cls, vector["fields"])
    payload, frame = bytes.fromhex(vector["payload"]), bytes.fromhex(vector["frame"])
    assert msg.pack() == payload
    assert encode_frame(msg, vector["seq"]) == frame


@pytest.mark.parametrize(("name", "vector"), VECTORS, ids=VECTOR_IDS)
def test_decode_matches_golden(name: str, vector: dict[str, Any]) -> None:
    cls = BY_NAME[name]
    expected = message_from_json(cls, vector["fields"])
    payload, frame = bytes.fromhex(vector["payload"]), bytes.fromhex(vector["frame"])

    decoder = FrameDecoder()
    events = decoder.feed(frame)
    assert events == [Frame(expected, vector["seq"])]
    [event] = events
    assert isinstance(event, Frame)
    assert type(event.message) is cls
    assert codec_values(event.message) == codec_values(expected)  # floats bit for bit
    for info in cls.FIELDS:  # enums come back as their enum class, not bare ints
        if info.kind in ("enum", "flags") and info.count is None:
            assert type(getattr(event.message, info.name)) is info.enum
    assert decoder.stats.frames_ok == 1
    assert decoder.stats.bytes_received == len(frame)
    assert decoder.stats.bytes_discarded == 0

    unpacked = cls.unpack(payload)
    assert unpacked == expected
    assert codec_values(unpacked) == codec_values(expected)


@pytest.mark.parametrize(("name", "vector"), VECTORS, ids=VECTOR_IDS)
def test_oracle_agrees_on_golden_payload(name: str, vector: dict[str, Any]) -> None:
    cls = BY_NAME[name]
    payload = bytes.fromhex(vector["payload"])
    assert oracle_values(cls, payload) == codec_values(cls.unpack(payload))
    frame = bytes.fromhex(vector["frame"])
    body = cobs_decode(frame[:-1])
    assert body is not None
    parsed = oracle.BODY.parse(body)
    assert (parsed.msg_id, parsed.seq) == (cls.MSG_ID, vector["seq"])
    assert bytes(parsed.rest[:-2]) == payload
