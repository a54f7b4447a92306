"""Frame encoder and streaming frame decoder (sans-I/O: bytes in, values out).

Wire format: COBS(msg_id | seq | payload | crc16_le) followed by 0x00, where the CRC covers
msg_id, seq, payload and then the message's CRC_EXTRA byte (see docs/protocol.md).
"""

from __future__ import annotations

import enum
from binascii import crc_hqx
from dataclasses import asdict, dataclass
from typing import NamedTuple

from cobs import cobs as _cobs

from host_sdk._generated.constants import MAX_FRAME
from host_sdk._generated.messages import BY_ID
from host_sdk.codec.cobs import cobs_encode
from host_sdk.codec.message import Message
from host_sdk.errors import EncodeError

_DELIM = b"\x00"
_MAX_CHUNK = MAX_FRAME - 1  # longest COBS chunk, delimiter excluded

# Indexed by msg_id: (class, CRC_EXTRA as one byte, min payload, max payload) or None.
_TABLE: list[tuple[type[Message], bytes, int, int] | None] = [None] * 256
for _cls in BY_ID.values():
    _TABLE[_cls.MSG_ID] = (_cls, bytes((_cls.CRC_EXTRA,)), _cls.PAYLOAD_SIZE, _cls.PAYLOAD_MAX)


def encode_frame(msg: Message, seq: int) -> bytes:
    """The whole frame for `msg` with sequence number `seq`, trailing 0x00 included.

    Raises EncodeError (a ValueError) naming the field if a value is outside the spec.
    """
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
    """The chunk as received (still COBS-encoded, delimiter excluded; capped at MAX_FRAME bytes)."""
    msg_id: int | None
    detail: str


@dataclass(slots=True)
class DecoderStats:
    """Counters of everything the decoder has seen. Every received byte is accounted for."""

    bytes_received: int = 0
    frames_ok: int = 0
    crc_errors: int = 0
    cobs_errors: int = 0
    length_errors: int = 0
    unknown_ids: int = 0
    value_errors: int = 0
    bytes_discarded: int = 0

    def as_dict(self) -> dict[str, int]:
        return asdict(self)


class FrameDecoder:
    """Turns a byte stream, in chunks of any size, into Frame and BadFrame events, in order.

    Never raises on input: bad data is counted in `stats` and reported as BadFrame. Memory is
    bounded: a run longer than any frame without a delimiter is discarded (one COBS error) and
    the decoder resynchronises at the next 0x00.
    """

    __slots__ = ("_pending", "_skipping", "stats")

    def __init__(self) -> None:
        self._pending = b""
        self._skipping = False
        self.stats = DecoderStats()

    def reset(self) -> None:
        """Drop a partial frame (e.g. after the port was reopened); counters are kept."""
        self.stats.bytes_discarded += len(self._pending)
        self._pending = b""
        self._skipping = False

    def feed(self, data: bytes) -> list[Frame | BadFrame]:
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
        table = _TABLE
        cobs_decode = _cobs.decode
        cobs_error = _cobs.DecodeError
        # The per-frame path is inlined here (no method calls) because it dominates decode time.
        for chunk in chunks:
            if not chunk:
                continue  # 0x00 0x00 is a harmless resync, not an error
            if len(chunk) > _MAX_CHUNK:
                append(self._bad(FrameErrorKind.COBS, chunk, None, f"over {_MAX_CHUNK} bytes without a delimiter"))
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
        if len(tail) > _MAX_CHUNK:
            stats.cobs_errors += 1
            stats.bytes_discarded += len(tail)
            out.append(
                BadFrame(FrameErrorKind.COBS, tail[:MAX_FRAME], None, f"over {_MAX_CHUNK} bytes without a delimiter")
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
        return BadFrame(kind, chunk[:MAX_FRAME], msg_id, detail)
