"""Property tests of the codec, driven by the public strategies in host_sdk.testing.

Everything here is derived from the spec metadata (`cls.FIELDS`), so new messages are covered by
regenerating the code. Profiles (tests/conftest.py): HYPOTHESIS_PROFILE=ci (default) or thorough.

About strictness: a CRC-16 lets a random chunk through with probability 2**-16 only once it is
valid COBS, names a known msg_id and has exactly that message's length, so for garbage not built
from real frames the chance of a false Frame is far below 1e-7 per chunk. The tests therefore
insist on *no* Frame from garbage, corrupted frames or damaged streams. The one exception is
`test_well_formed_bodies_are_classified`, which makes valid-CRC bodies on purpose.
"""

from __future__ import annotations

import itertools
import json
from collections.abc import Iterable, Iterator
from pathlib import Path

import pytest
from codec_oracle import codec_values, oracle_values
from hypothesis import given, note
from hypothesis import strategies as st

from host_sdk import messages
from host_sdk.errors import EncodeError
from host_sdk.framing import BadFrame, Frame, FrameDecoder, FrameErrorKind, encode_frame
from host_sdk.testing import strategies as rls
from protocol.codec.cobs import cobs_decode, cobs_encode
from protocol.codec.crc import frame_crc
from protocol.codec.message import Message
from protocol.generated import oracle
from protocol.generated.constants import MAX_FRAME, MAX_PAYLOAD

ALL: tuple[type[Message], ...] = messages.ALL_MESSAGES
BY_ID: dict[int, type[Message]] = {cls.MSG_ID: cls for cls in ALL}
OVERHEAD = 6  # COBS code, msg_id, seq, CRC x2, delimiter (docs/protocol.md)
VECTOR_DIR = Path(__file__).resolve().parents[3] / "protocol" / "vectors"


def _name(cls: type[Message]) -> str:
    return cls.NAME


# -- helpers --------------------------------------------------------------------------------------
def feed_pieces(decoder: FrameDecoder, pieces: Iterable[bytes]) -> list[Frame | BadFrame]:
    """Feed `pieces` in order, checking after each that the decoder's buffer stays bounded."""
    events: list[Frame | BadFrame] = []
    for piece in pieces:
        events += decoder.feed(piece)
        assert len(decoder._pending) <= MAX_FRAME
    return events


def split(data: bytes, sizes: list[int]) -> list[bytes]:
    """`data` cut into pieces of the given sizes (the rest as a last piece)."""
    pieces, at = [], 0
    for size in sizes:
        if at >= len(data):
            break
        pieces.append(data[at : at + size])
        at += size
    if at < len(data):
        pieces.append(data[at:])
    return pieces


def piece_sizes() -> st.SearchStrategy[list[int]]:
    """Chunk sizes for feeding a stream; shrinks towards 1-byte chunks."""
    return st.lists(st.integers(min_value=1, max_value=2 * MAX_FRAME), max_size=400)


def frames_only(events: Iterable[Frame | BadFrame]) -> list[Frame]:
    return [e for e in events if isinstance(e, Frame)]


def assert_accounted(decoder: FrameDecoder, fed: bytes, events: list[Frame | BadFrame]) -> None:
    """Every byte fed is a delimiter, part of a good frame, discarded, or still pending; every
    event is counted once: a Frame in frames_ok, a BadFrame in exactly one error counter."""
    stats = decoder.stats
    good = frames_only(events)
    assert stats.bytes_received == len(fed)
    in_good_frames = sum(len(encode_frame(msg, seq)) - 1 for msg, seq in good)
    pending = len(decoder._pending)
    assert stats.bytes_received == fed.count(0) + in_good_frames + stats.bytes_discarded + pending, stats
    assert stats.frames_ok == len(good)
    errors = stats.crc_errors + stats.cobs_errors + stats.length_errors + stats.unknown_ids + stats.value_errors
    assert errors == len(events) - len(good), stats


# -- round trips ---------------------------------------------------------------------------------------
@pytest.mark.parametrize("cls", ALL, ids=_name)
@given(data=st.data())
def test_frame_round_trip(cls: type[Message], data: st.DataObject) -> None:
    msg = data.draw(rls.message(cls), label="message")
    seq = data.draw(rls.seqs(), label="seq")
    wire = encode_frame(msg, seq)
    assert wire.index(0) == len(wire) - 1, "exactly one 0x00, at the end"
    assert len(wire) == len(msg.pack()) + OVERHEAD
    assert len(wire) <= MAX_FRAME

    decoder = FrameDecoder()
    events = decoder.feed(wire)
    assert events == [Frame(msg, seq)]
    [event] = events
    assert isinstance(event, Frame)
    assert type(event.message) is cls
    assert codec_values(event.message) == codec_values(msg)  # floats bit for bit
    assert decoder.stats.frames_ok == 1
    assert_accounted(decoder, wire, events)


@pytest.mark.parametrize("cls", ALL, ids=_name)
@given(data=st.data())
def test_pack_unpack_round_trip(cls: type[Message], data: st.DataObject) -> None:
    msg = data.draw(rls.message(cls), label="message")
    payload = msg.pack()
    assert cls.PAYLOAD_SIZE <= len(payload) <= cls.PAYLOAD_MAX
    back = cls.unpack(payload)
    assert back == msg
    assert codec_values(back) == codec_values(msg)
    assert back.pack() == payload
    for info in cls.FIELDS:
        value = getattr(back, info.name)
        if info.kind in ("enum", "flags") and info.count is None:
            assert type(value) is info.enum, f"{info.name} decodes to its enum class"
        if info.count is not None:
            assert isinstance(value, tuple) and len(value) == info.count


@pytest.mark.parametrize("cls", ALL, ids=_name)
@given(data=st.data())
def test_oracle_agrees_with_codec(cls: type[Message], data: st.DataObject) -> None:
    """The construct declarations parse every frame's payload to the fast codec's values."""
    msg = data.draw(rls.message(cls), label="message")
    seq = data.draw(rls.seqs(), label="seq")
    wire = encode_frame(msg, seq)
    body = cobs_decode(wire[:-1])
    assert body is not None
    parsed = oracle.BODY.parse(body)
    assert (parsed.msg_id, parsed.seq) == (cls.MSG_ID, seq)
    payload = bytes(parsed.rest[:-2])
    assert int.from_bytes(parsed.rest[-2:], "little") == frame_crc(body[:-2], oracle.CRC_EXTRA[cls.MSG_ID])
    assert oracle_values(cls, payload) == codec_values(msg)


# -- streams ---------------------------------------------------------------------------------------------
@given(stream=rls.streams(max_frames=12), sizes=piece_sizes())
def test_stream_in_any_chunks_decodes_like_whole(stream: rls.Stream, sizes: list[int]) -> None:
    whole = FrameDecoder()
    expected = whole.feed(stream.wire)
    assert expected == stream.frames
    assert whole.stats.frames_ok == len(stream.frames)
    assert whole.stats.bytes_discarded == 0
    assert whole._pending == b""

    pieces = split(stream.wire, sizes)
    note(f"piece sizes: {[len(p) for p in pieces]}")
    chunked = FrameDecoder()
    assert feed_pieces(chunked, pieces) == expected
    assert chunked.stats == whole.stats

    bytewise = FrameDecoder()
    events = feed_pieces(bytewise, (stream.wire[i : i + 1] for i in range(len(stream.wire))))
    assert events == expected
    assert bytewise.stats == whole.stats
    assert_accounted(bytewise, stream.wire, events)


@given(stream=rls.streams(max_frames=6), sizes=piece_sizes())
def test_empty_pieces_and_extra_delimiters_are_harmless(stream: rls.Stream, sizes: list[int]) -> None:
    wire = b"\x00" + stream.wire.replace(b"\x00", b"\x00\x00")  # 0x00 0x00 is a resync, not an error
    decoder = FrameDecoder()
    pieces = [p for piece in split(wire, sizes) for p in (b"", piece)]
    events = feed_pieces(decoder, pieces)
    assert events == stream.frames
    assert decoder.stats.bytes_discarded == 0
    assert_accounted(decoder, wire, events)


# -- bit flips ---------------------------------------------------------------------------------------------
def _vector_frames() -> list[tuple[type[Message], bytes]]:
    """Every golden frame: fixed, varied value sets (zeros: most COBS blocks; min; max; typical)."""
    by_name = {cls.NAME: cls for cls in ALL}
    out = []
    for path in sorted(VECTOR_DIR.glob("*.json")):
        doc = json.loads(path.read_text(encoding="utf-8"))
        out += [(by_name[doc["message"]], bytes.fromhex(v["frame"])) for v in doc["vectors"]]
    return out


VECTOR_FRAMES = _vector_frames()


def _flip(wire: bytes, bits: Iterable[int]) -> bytes:
    damaged = bytearray(wire)
    for bit in bits:
        damaged[bit // 8] ^= 1 << (bit % 8)
    return bytes(damaged)


def decodes_to_any_frame(wire: bytes) -> list[Frame]:
    """Frames a fresh decoder yields from `wire`, plus a 0x00 to close a chunk a flipped
    delimiter left open. A flip that makes a 0x00 splits the frame in two chunks: neither may
    decode."""
    return frames_only(FrameDecoder().feed(wire + b"\x00"))


def _short_frames(max_len: int) -> dict[str, list[bytes]]:
    out: dict[str, list[bytes]] = {}
    for cls, wire in VECTOR_FRAMES:
        if len(wire) <= max_len:
            out.setdefault(cls.NAME, []).append(wire)
    return out


SHORT_FRAMES = _short_frames(16)
EMPTY_PAYLOAD = {cls.NAME for cls in ALL if cls.PAYLOAD_MAX == 0}
FOUR_BYTE_PAYLOAD = {cls.NAME for cls in ALL if cls.PAYLOAD_SIZE == cls.PAYLOAD_MAX == 4}


def test_flip_tests_have_frames_to_work_on() -> None:
    assert len(SHORT_FRAMES) >= 10
    assert EMPTY_PAYLOAD and set(SHORT_FRAMES) >= EMPTY_PAYLOAD
    assert FOUR_BYTE_PAYLOAD and set(SHORT_FRAMES) >= FOUR_BYTE_PAYLOAD


def _all_flips(wire: bytes, n_bits: int) -> Iterator[tuple[tuple[int, ...], bytes]]:
    for bits in itertools.combinations(range(len(wire) * 8), n_bits):
        yield bits, _flip(wire, bits)


def _assert_all_flips_rejected(name: str, frames: list[bytes], n_bits: int) -> int:
    tried = 0
    for wire in frames:
        assert len(decodes_to_any_frame(wire)) == 1, "the undamaged frame decodes"
        for bits, damaged in _all_flips(wire, n_bits):
            tried += 1
            got = decodes_to_any_frame(damaged)
            assert not got, f"{name} frame {wire.hex()} with bits {bits} flipped ({damaged.hex()}) gave {got}"
    return tried


@pytest.mark.parametrize("name", sorted(SHORT_FRAMES))
def test_every_single_bit_flip_is_rejected(name: str) -> None:
    assert _assert_all_flips_rejected(name, SHORT_FRAMES[name], 1) > 0


@pytest.mark.parametrize("name", sorted(EMPTY_PAYLOAD | FOUR_BYTE_PAYLOAD))
def test_every_two_bit_flip_is_rejected(name: str) -> None:
    assert _assert_all_flips_rejected(name, SHORT_FRAMES[name], 2) > 0


@pytest.mark.parametrize("name", sorted(EMPTY_PAYLOAD))
def test_every_three_bit_flip_is_rejected(name: str) -> None:
    assert _assert_all_flips_rejected(name, SHORT_FRAMES[name], 3) > 0


@given(frame=rls.frames())
def test_every_single_bit_flip_of_any_frame_is_rejected(frame: Frame) -> None:
    wire = encode_frame(*frame)
    for bits, damaged in _all_flips(wire, 1):
        got = decodes_to_any_frame(damaged)
        assert not got, f"bit {bits[0]} flipped: {damaged.hex()} gave {got}"


# -- resynchronisation ------------------------------------------------------------------------------------
@st.composite
def damaged_streams(draw: st.DrawFn) -> tuple[rls.Stream, bytes, int, str]:
    """A stream, one byte dropped, inserted or flipped, and the index of the frame it hits."""
    stream = draw(rls.streams(min_frames=1, max_frames=8), label="stream")
    wire = stream.wire
    owner = [i for i, (msg, seq) in enumerate(stream.frames) for _ in encode_frame(msg, seq)]
    kind = draw(st.sampled_from(["drop", "insert", "flip"]), label="damage")
    if kind == "insert":
        pos = draw(st.integers(0, len(wire)), label="position")
        byte = draw(st.integers(0, 0xFF), label="inserted byte")
        damaged = wire[:pos] + bytes((byte,)) + wire[pos:]
    else:
        pos = draw(st.integers(0, len(wire) - 1), label="position")
        if kind == "drop":
            damaged = wire[:pos] + wire[pos + 1 :]
        else:
            mask = draw(st.integers(1, 0xFF), label="xor mask")
            damaged = wire[:pos] + bytes((wire[pos] ^ mask,)) + wire[pos + 1 :]
    hit = owner[pos] if pos < len(owner) else len(stream.frames)
    return stream, damaged, hit, kind


@given(damage=damaged_streams(), sizes=piece_sizes())
def test_damage_loses_at_most_the_hit_frame_and_the_next(
    damage: tuple[rls.Stream, bytes, int, str], sizes: list[int]
) -> None:
    stream, damaged, hit, kind = damage
    note(f"{kind} in frame {hit} of {len(stream.frames)}")
    decoder = FrameDecoder()
    events = feed_pieces(decoder, split(damaged, sizes))
    got = frames_only(events)
    sent = stream.frames
    allowed = [[f for i, f in enumerate(sent) if i not in lost] for lost in (set(), {hit}, {hit, hit + 1})]
    assert got in allowed, f"sent {sent}\ngot {got}"
    assert_accounted(decoder, damaged, events)


@given(stream=rls.streams(min_frames=2, max_frames=6), run=st.binary(min_size=MAX_FRAME, max_size=400))
def test_over_long_run_is_dropped_and_decoder_resynchronises(stream: rls.Stream, run: bytes) -> None:
    run = run.replace(b"\x00", b"\x01")  # no delimiter: longer than any frame can be
    first, *rest = stream.frames
    wire = encode_frame(*first) + run + b"\x00" + b"".join(encode_frame(m, s) for m, s in rest)
    for pieces in ([wire], [wire[i : i + 1] for i in range(len(wire))], split(wire, [3, 50, 7, 61, 1])):
        decoder = FrameDecoder()
        events = feed_pieces(decoder, pieces)
        assert events[0] == first
        bad = events[1]
        assert isinstance(bad, BadFrame) and bad.kind is FrameErrorKind.COBS
        assert len(bad.data) <= MAX_FRAME
        assert events[2:] == rest
        assert decoder.stats.cobs_errors == 1
        assert decoder.stats.bytes_discarded == len(run)
        assert_accounted(decoder, wire, events)


# -- garbage ------------------------------------------------------------------------------------------------
def _check_garbage(garbage: bytes, sizes: list[int]) -> None:
    decoder = FrameDecoder()
    events = feed_pieces(decoder, split(garbage, sizes))  # never raises, buffer stays bounded
    assert frames_only(events) == [], "garbage decoded to a frame"
    assert all(isinstance(e, BadFrame) and len(e.data) <= MAX_FRAME for e in events)
    assert_accounted(decoder, garbage, events)


@given(garbage=st.binary(max_size=2000), sizes=piece_sizes())
def test_random_bytes_never_decode(garbage: bytes, sizes: list[int]) -> None:
    _check_garbage(garbage, sizes)


@given(
    chunks=st.lists(st.binary(max_size=2 * MAX_FRAME).map(lambda b: b.replace(b"\x00", b"")), max_size=30),
    sizes=piece_sizes(),
)
def test_random_chunks_between_delimiters_never_decode(chunks: list[bytes], sizes: list[int]) -> None:
    _check_garbage(b"\x00".join(chunks), sizes)


@given(
    run=st.binary(min_size=MAX_FRAME, max_size=3000).map(lambda b: b.replace(b"\x00", b"\xa5")),
    sizes=piece_sizes(),
)
def test_over_long_runs_never_decode(run: bytes, sizes: list[int]) -> None:
    _check_garbage(run, sizes)
    _check_garbage(run + b"\x00" + run, sizes)


@given(bodies=st.lists(st.binary(min_size=1, max_size=80), max_size=12), sizes=piece_sizes())
def test_valid_cobs_garbage_never_decodes(bodies: list[bytes], sizes: list[int]) -> None:
    """Chunks that are valid COBS but whose bodies are random: rejected at id, length or CRC."""
    _check_garbage(b"".join(cobs_encode(body) + b"\x00" for body in bodies), sizes)


@st.composite
def well_formed_bodies(draw: st.DrawFn) -> bytes:
    """A body with a correct CRC: a real msg_id with a length that fits or is one off, random
    payload bytes (so enum and flag fields may hold values the spec does not allow), or an
    unknown msg_id."""
    msg_id = draw(st.one_of(st.sampled_from(sorted(BY_ID)), st.integers(0, 0xFF)), label="msg_id")
    cls = BY_ID.get(msg_id)
    lo, hi = (cls.PAYLOAD_SIZE, cls.PAYLOAD_MAX) if cls else (0, MAX_PAYLOAD)
    size = draw(st.integers(max(lo - 1, 0), min(hi + 1, MAX_PAYLOAD)), label="payload size")
    payload = draw(st.binary(min_size=size, max_size=size), label="payload")
    seq = draw(rls.seqs(), label="seq")
    extra = cls.CRC_EXTRA if cls else draw(st.integers(0, 0xFF))
    body = bytes((msg_id, seq)) + payload
    return body + frame_crc(body, extra).to_bytes(2, "little")


@given(bodies=st.lists(well_formed_bodies(), min_size=1, max_size=8))
def test_well_formed_bodies_are_classified(bodies: list[bytes]) -> None:
    """Valid COBS and CRC: each chunk is a Frame exactly when its payload decodes, else it is
    reported as the right kind of error; a Frame carries exactly the payload's values and, when
    they are within the spec, re-encodes to the very chunk it came from."""
    chunks = [cobs_encode(body) for body in bodies]
    decoder = FrameDecoder()
    events = decoder.feed(b"".join(chunk + b"\x00" for chunk in chunks))
    assert len(events) == len(chunks)
    for body, chunk, event in zip(bodies, chunks, events, strict=True):
        cls, payload = BY_ID.get(body[0]), body[2:-2]
        if cls is None:
            assert isinstance(event, BadFrame) and event.kind is FrameErrorKind.UNKNOWN_ID
        elif not cls.PAYLOAD_SIZE <= len(payload) <= cls.PAYLOAD_MAX:
            assert isinstance(event, BadFrame) and event.kind is FrameErrorKind.LENGTH
        else:
            try:
                expected = cls.unpack(payload)
            except ValueError:
                assert isinstance(event, BadFrame) and event.kind is FrameErrorKind.VALUE
                continue
            # Compared by value, bit for bit: a payload may decode to a NaN, which != itself.
            assert isinstance(event, Frame) and type(event.message) is cls and event.seq == body[1]
            assert codec_values(event.message) == codec_values(expected) == oracle_values(cls, payload)
            try:
                again = encode_frame(expected, body[1])
            except EncodeError:
                # The decoder checks enums, flags and ASCII but not numeric ranges: a payload with,
                # say, PID.kf = 2048.0 decodes but will not encode. The oracle check above shows
                # nothing was lost; whether decode should refuse it is a design question.
                note(f"decoded out-of-spec {expected}")
            else:
                assert again == chunk + b"\x00"
            continue
        assert event.data == chunk and event.msg_id == body[0]
