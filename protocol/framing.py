"""The frame codec: `encode_frame(msg, seq)` and the streaming `FrameDecoder` (sans-I/O: bytes in,
values out), over the spec's messages.

>>> from protocol.framing import FrameDecoder, encode_frame
>>> from protocol.generated.messages import SetWheelSpeeds
>>> wire = encode_frame(SetWheelSpeeds(left_mm_s=120, right_mm_s=-80), seq=7)
>>> [event] = FrameDecoder().feed(wire)
>>> event.message, event.seq
(SetWheelSpeeds(left_mm_s=120, right_mm_s=-80), 7)

Wire format: COBS(msg_id | seq | payload | crc16_le) followed by 0x00, where the CRC covers
msg_id, seq, payload and then the message's CRC_EXTRA byte (see docs/protocol.md).

The layers: protocol.codec (COBS, CRC, the message base class) knows no message;
protocol.generated (the messages, the counter set) builds on it; this module joins the two. The
decoder knows every message of the spec (`MESSAGES`) unless given another `MessageTable`.
"""

from __future__ import annotations

import enum
from binascii import crc_hqx
from collections.abc import Iterable
from dataclasses import asdict, dataclass
from typing import NamedTuple

from cobs import cobs as _cobs

from protocol.codec.cobs import cobs_encode
from protocol.codec.message import Message
from protocol.errors import ArgumentTypeError, EncodeError
from protocol.generated.constants import MAX_FRAME
from protocol.generated.messages import ALL_MESSAGES
from protocol.generated.structs import DecoderCounters

__all__ = [
    "MESSAGES",
    "BadFrame",
    "DecoderStats",
    "Frame",
    "FrameDecoder",
    "FrameErrorKind",
    "MessageTable",
    "encode_frame",
]

_DELIM = b"\x00"


class MessageTable:
    """The messages a decoder knows, indexed by msg_id for the per-frame lookup.

    `max_frame` is the longest frame the protocol allows on the wire, delimiter included (the
    spec's MAX_FRAME): a run of bytes longer than that without a delimiter cannot be a frame.
    """

    __slots__ = ("by_id", "max_frame", "rows")

    def __init__(self, messages: Iterable[type[Message]], max_frame: int) -> None:
        # rows[msg_id]: (class, CRC_EXTRA as one byte, min payload, max payload) or None.
        self.rows: list[tuple[type[Message], bytes, int, int] | None] = [None] * 256
        self.by_id: dict[int, type[Message]] = {}
        for cls in messages:
            if self.rows[cls.MSG_ID] is not None:
                raise ValueError(f"msg_id 0x{cls.MSG_ID:02X} is used by two messages")
            self.rows[cls.MSG_ID] = (cls, bytes((cls.CRC_EXTRA,)), cls.PAYLOAD_SIZE, cls.PAYLOAD_MAX)
            self.by_id[cls.MSG_ID] = cls
            body = 4 + cls.PAYLOAD_MAX
            if body + body // 254 + 2 > max_frame:  # COBS adds a code byte per 254, then the delimiter
                raise ValueError(f"{cls.NAME} frames can be longer than max_frame = {max_frame}")
        self.max_frame = max_frame


def encode_frame(msg: Message, seq: int) -> bytes:
    """The whole frame for `msg` with sequence number `seq`, trailing 0x00 included.

    Raises EncodeError (a ValueError) naming the field if a value is outside the spec.
    """
    if not isinstance(msg, Message):
        raise ArgumentTypeError("msg", msg, "a RoverLink message (an instance of one of the generated messages)")
    if not (isinstance(seq, int) and not isinstance(seq, bool) and 0 <= seq <= 0xFF):
        raise EncodeError(msg.NAME, "seq", seq, "an integer in 0..255")
    body = bytes((msg.MSG_ID, seq)) + msg.pack()
    crc = crc_hqx(bytes((msg.CRC_EXTRA,)), crc_hqx(body, 0xFFFF))
    return cobs_encode(body + crc.to_bytes(2, "little")) + _DELIM


class Frame(NamedTuple):
    """A valid frame: the decoded message and the sender's sequence number.

    A NamedTuple rather than a dataclass: one is built per frame and a tuple is three times cheaper.
    """

    message: Message
    seq: int


class FrameErrorKind(enum.Enum):
    COBS = "cobs"
    """Not valid COBS, or longer than any frame can be without a delimiter."""
    LENGTH = "length"
    """Shorter than a frame, or a payload length that does not fit its msg_id."""
    UNKNOWN_ID = "unknown_id"
    """A msg_id the spec does not define."""
    CRC = "crc"
    """CRC mismatch (corruption, or a peer built from another definition of the message)."""
    VALUE = "value"
    """CRC good but a field holds a value the spec does not allow (e.g. an unknown enum value)."""


@dataclass(frozen=True, slots=True)
class BadFrame:
    """A chunk between delimiters that is not a valid frame; its bytes were discarded."""

    kind: FrameErrorKind
    data: bytes
    """The chunk as received (still COBS-encoded, delimiter excluded; capped at the longest frame)."""
    msg_id: int | None
    detail: str


@dataclass(slots=True)
class DecoderStats(DecoderCounters):
    """Counters of everything the decoder has seen. Every received byte is accounted for.

    The counters the spec names (DecoderCounters: the ones the firmware reports in LINK_STATS, in
    the same order), plus the bytes fed in.
    """

    bytes_received: int = 0

    def as_dict(self) -> dict[str, int]:
        return asdict(self)


class FrameDecoder:
    """Turns a byte stream, in chunks of any size, into Frame and BadFrame events, in order.

    Never raises on input: bad data is counted in `stats` and reported as BadFrame. Memory is
    bounded: a run longer than any frame without a delimiter is discarded (one COBS error) and
    the decoder resynchronises at the next 0x00. Knows every message of the spec unless given
    another `table`.
    """

    __slots__ = ("_max_chunk", "_max_frame", "_pending", "_rows", "_skipping", "stats")

    def __init__(self, table: MessageTable | None = None) -> None:
        if table is None:
            table = MESSAGES
        elif not isinstance(table, MessageTable):
            raise ArgumentTypeError("table", table, "a MessageTable")
        self._rows = table.rows
        self._max_frame = table.max_frame
        self._max_chunk = table.max_frame - 1  # longest COBS chunk, delimiter excluded
        self._pending = b""
        self._skipping = False
        self.stats = DecoderStats()

    def reset(self) -> None:
        """Drop a partial frame (e.g. after the port was reopened); counters are kept."""
        self.stats.bytes_discarded += len(self._pending)
        self._pending = b""
        self._skipping = False

    def feed(self, data: bytes) -> list[Frame | BadFrame]:
        """Events for the frames `data` completes (bytes, bytearray or memoryview; any length)."""
        if type(data) is not bytes:
            if not isinstance(data, (bytes, bytearray, memoryview)):
                raise ArgumentTypeError("data", data, "bytes (or a bytearray or memoryview)")
            data = bytes(data)
        stats = self.stats
        stats.bytes_received += len(data)
        if self._skipping:
            end = data.find(_DELIM)
            if end < 0:
                stats.bytes_discarded += len(data)
                return []
            stats.bytes_discarded += end
            data = data[end + 1 :]
            self._skipping = False
        buf = self._pending + data if self._pending else bytes(data)
        chunks = buf.split(_DELIM)
        tail = chunks.pop()
        out: list[Frame | BadFrame] = []
        append = out.append
        table = self._rows
        max_chunk = self._max_chunk
        cobs_decode = _cobs.decode
        cobs_error = _cobs.DecodeError
        # The per-frame path is inlined here (no method calls) because it dominates decode time.
        for chunk in chunks:
            if not chunk:
                continue  # 0x00 0x00 is a harmless resync, not an error
            if len(chunk) > max_chunk:
                append(self._bad(FrameErrorKind.COBS, chunk, None, f"over {max_chunk} bytes without a delimiter"))
                continue
            try:
                body = cobs_decode(chunk)
            except cobs_error:
                append(self._bad(FrameErrorKind.COBS, chunk, None, "invalid COBS"))
                continue
            if len(body) < 4:
                append(self._bad(FrameErrorKind.LENGTH, chunk, None, f"{len(body)} bytes is shorter than a frame"))
                continue
            entry = table[body[0]]
            if entry is None:
                append(self._bad(FrameErrorKind.UNKNOWN_ID, chunk, body[0], f"unknown msg_id 0x{body[0]:02X}"))
                continue
            cls, extra, lo, hi = entry
            if crc_hqx(extra, crc_hqx(body[:-2], 0xFFFF)) != body[-2] | body[-1] << 8:
                append(self._bad(FrameErrorKind.CRC, chunk, body[0], f"CRC mismatch for {cls.NAME}"))
                continue
            n = len(body) - 4
            if not lo <= n <= hi:
                detail = f"{cls.NAME} payload of {n} bytes, allowed {lo}..{hi}"
                append(self._bad(FrameErrorKind.LENGTH, chunk, body[0], detail))
                continue
            try:
                msg = cls.unpack(body[2:-2])
            except ValueError as exc:
                append(self._bad(FrameErrorKind.VALUE, chunk, body[0], str(exc)))
                continue
            stats.frames_ok += 1
            append(Frame(msg, body[1]))
        if len(tail) > max_chunk:
            stats.cobs_errors += 1
            stats.bytes_discarded += len(tail)
            out.append(
                BadFrame(
                    FrameErrorKind.COBS, tail[: self._max_frame], None, f"over {max_chunk} bytes without a delimiter"
                )
            )
            tail = b""
            self._skipping = True
        self._pending = tail
        return out

    def _bad(self, kind: FrameErrorKind, chunk: bytes, msg_id: int | None, detail: str) -> BadFrame:
        stats = self.stats
        if kind is FrameErrorKind.COBS:
            stats.cobs_errors += 1
        elif kind is FrameErrorKind.LENGTH:
            stats.length_errors += 1
        elif kind is FrameErrorKind.UNKNOWN_ID:
            stats.unknown_ids += 1
        elif kind is FrameErrorKind.CRC:
            stats.crc_errors += 1
        else:
            stats.value_errors += 1
        stats.bytes_discarded += len(chunk)
        return BadFrame(kind, chunk[: self._max_frame], msg_id, detail)


MESSAGES = MessageTable(ALL_MESSAGES, MAX_FRAME)
"""Every message of the spec, by msg_id."""
