"""Consistent Overhead Byte Stuffing: removes every 0x00 so a 0x00 can end each frame.

The `cobs` package's C implementation is used: in benchmarks/codec.py it makes decoding a
FEEDBACK frame about 2.5 µs faster than a pure-Python loop, a third of the whole decode.
"""

from __future__ import annotations

from cobs import cobs as _cobs


def cobs_encode(data: bytes) -> bytes:
    """Encode `data`; the result holds no 0x00 and is at most len(data) + len(data)//254 + 1 long."""
    return bytes(_cobs.encode(data))


def cobs_decode(data: bytes) -> bytes | None:
    """Decode one COBS chunk (delimiter excluded); None if it is not valid COBS."""
    if not data:
        return None
    try:
        return bytes(_cobs.decode(data))
    except _cobs.DecodeError:
        return None
