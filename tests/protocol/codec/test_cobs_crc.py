"""CRC-16/CCITT-FALSE and COBS, each checked against an implementation that shares no code with it."""

from __future__ import annotations

import crcmod.predefined
from hypothesis import example, given
from hypothesis import strategies as st

from protocol.codec.cobs import cobs_decode, cobs_encode
from protocol.codec.crc import crc16, frame_crc

_crcmod_ccitt_false = crcmod.predefined.mkCrcFun("crc-ccitt-false")


# -- CRC ----------------------------------------------------------------------------------------------
def test_crc_check_value() -> None:
    assert crc16(b"123456789") == 0x29B1
    assert _crcmod_ccitt_false(b"123456789") == 0x29B1  # the reference is the CRC we think it is


def test_crc_of_nothing_is_the_init_value() -> None:
    assert crc16(b"") == 0xFFFF


@given(st.binary(max_size=300))
@example(b"")
@example(b"\x00" * 70)
@example(b"\xff" * 70)
def test_crc_agrees_with_crcmod(data: bytes) -> None:
    assert crc16(data) == _crcmod_ccitt_false(data)


@given(st.binary(max_size=200), st.data())
def test_crc_can_continue_over_pieces(data: bytes, draw: st.DataObject) -> None:
    cut = draw.draw(st.integers(0, len(data)))
    assert crc16(data[cut:], crc16(data[:cut])) == _crcmod_ccitt_false(data)


@given(st.binary(min_size=2, max_size=66), st.integers(0, 0xFF))
def test_frame_crc_appends_crc_extra(body: bytes, crc_extra: int) -> None:
    assert frame_crc(body, crc_extra) == _crcmod_ccitt_false(body + bytes((crc_extra,)))


# -- COBS: a textbook implementation to compare with ----------------------------------------------------
def textbook_cobs_encode(data: bytes) -> bytes:
    """Cheshire and Baker: each block is a code byte (block length + 1) and up to 254 non-zero
    bytes; a code below 0xFF stands for a zero after its block (the last one's is dropped)."""
    out = bytearray()
    block = bytearray()
    for byte in data:
        if byte == 0:
            out.append(len(block) + 1)
            out += block
            block.clear()
            continue
        block.append(byte)
        if len(block) == 254:
            out.append(0xFF)
            out += block
            block.clear()
    out.append(len(block) + 1)
    out += block
    return bytes(out)


def textbook_cobs_decode(data: bytes) -> bytes | None:
    """Inverse of textbook_cobs_encode; None for anything it cannot have produced."""
    if not data:
        return None
    out = bytearray()
    i = 0
    while i < len(data):
        code = data[i]
        end = i + code
        if code == 0 or end > len(data):
            return None
        block = data[i + 1 : end]
        if 0 in block:
            return None
        out += block
        i = end
        if code != 0xFF and i < len(data):
            out.append(0)
    return bytes(out)


def test_textbook_cobs_examples() -> None:
    """Examples from the COBS paper / Wikipedia, so the reference itself is known good."""
    assert textbook_cobs_encode(b"") == b"\x01"
    assert textbook_cobs_encode(b"\x00") == b"\x01\x01"
    assert textbook_cobs_encode(b"\x00\x00") == b"\x01\x01\x01"
    assert textbook_cobs_encode(b"\x11\x22\x00\x33") == b"\x03\x11\x22\x02\x33"
    assert textbook_cobs_encode(b"\x11\x00\x00\x00") == b"\x02\x11\x01\x01\x01"
    run = bytes(range(1, 255))  # 254 non-zero bytes
    assert textbook_cobs_encode(run) == b"\xff" + run + b"\x01"
    assert textbook_cobs_encode(b"\x00" + run) == b"\x01\xff" + run + b"\x01"
    assert textbook_cobs_encode(run + b"\xff") == b"\xff" + run + b"\x02\xff"


def _zero_free(min_size: int, max_size: int) -> st.SearchStrategy[bytes]:
    return st.binary(min_size=min_size, max_size=max_size).map(lambda b: b.replace(b"\x00", b"\x01"))


# Runs around the 254-byte block limit, separated by zeros, are where COBS encoders go wrong.
_blocky = st.lists(st.one_of(_zero_free(250, 260), _zero_free(0, 10), st.just(b"")), min_size=1, max_size=4).map(
    b"\x00".join
)

cobs_inputs = st.one_of(
    st.binary(max_size=600),
    _zero_free(250, 800),  # long zero-free runs: several 0xFF blocks
    st.integers(0, 600).map(bytes),  # all zeros
    _blocky,
)


@given(cobs_inputs)
@example(b"")
@example(b"\x00")
@example(b"\x01" * 253)
@example(b"\x01" * 254)
@example(b"\x01" * 255)
@example(b"\x01" * 508)
@example(b"\x01" * 254 + b"\x00")
@example(b"\x00" * 300)
def test_cobs_round_trip(data: bytes) -> None:
    encoded = cobs_encode(data)
    assert 0 not in encoded
    assert len(encoded) <= len(data) + len(data) // 254 + 1
    assert cobs_decode(encoded) == data


@given(cobs_inputs)
@example(b"")
@example(b"\x01" * 254)
@example(b"\x01" * 254 + b"\x00")
def test_cobs_agrees_with_textbook(data: bytes) -> None:
    encoded = cobs_encode(data)
    assert textbook_cobs_decode(encoded) == data  # what we send, a textbook receiver reads
    assert cobs_decode(textbook_cobs_encode(data)) == data  # and the other way round
    reference = textbook_cobs_encode(data)
    if _ends_in_full_blocks(data):
        # The one licensed difference: after a final block of 254 non-zero bytes the `cobs`
        # package leaves out the textbook's closing 0x01 code (which stands for no bytes at all).
        # Both forms decode to the same data; frames (at most 68 bytes) never reach it.
        assert encoded == reference[:-1]
    else:
        assert encoded == reference


def _ends_in_full_blocks(data: bytes) -> bool:
    """True if the run of non-zero bytes after the last zero is a non-zero multiple of 254 long."""
    tail = len(data) - (data.rfind(0) + 1)
    return tail > 0 and tail % 254 == 0


@given(st.binary(max_size=68))
def test_cobs_frame_bodies_encode_exactly_like_textbook(body: bytes) -> None:
    """Everything a frame can carry (at most 68 bytes) encodes to the textbook bytes exactly."""
    assert cobs_encode(body) == textbook_cobs_encode(body)


@given(st.one_of(st.binary(min_size=1, max_size=300), cobs_inputs.map(textbook_cobs_encode)))
@example(b"\x00")
@example(b"\x02")
@example(b"\x01\x00")
@example(b"\xff" + b"\x01" * 254)
def test_cobs_decode_accepts_exactly_what_textbook_accepts(data: bytes) -> None:
    """Arbitrary chunks: both decoders refuse the same ones and agree on the rest."""
    assert cobs_decode(data) == textbook_cobs_decode(data)


def test_cobs_decode_refuses_empty_chunk() -> None:
    assert cobs_decode(b"") is None
