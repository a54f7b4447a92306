"""CRC-16/CCITT-FALSE, CRC_EXTRA and the spec hash.

This is the generator's own bit-by-bit CRC: it computes the golden vectors, so it is deliberately
independent of the table/C implementations used by the codecs it checks.
"""

from __future__ import annotations

import hashlib
import json
from typing import Any


def crc16(data: bytes, crc: int = 0xFFFF, poly: int = 0x1021) -> int:
    """CRC-16/CCITT-FALSE (MSB first, no reflection, no final xor)."""
    for byte in data:
        crc ^= byte << 8
        for _ in range(8):
            crc = ((crc << 1) ^ poly) if crc & 0x8000 else (crc << 1)
            crc &= 0xFFFF
    return crc


def signature(name: str, fields: list[tuple[str, str]]) -> str:
    """The text CRC_EXTRA is derived from: `NAME type1 field1 type2 field2 ...` (single spaces).

    A field's type is its wire primitive with the enum name after a colon and the array suffix,
    e.g. `u8:FeedbackMode`, `i32[2]`, `char[..24]`.
    """
    parts = [name]
    for type_text, field_name in fields:
        parts.append(type_text)
        parts.append(field_name)
    return " ".join(parts)


def crc_extra(sig: str) -> int:
    """Fold the signature's CRC-16 into one byte: low byte xor high byte."""
    crc = crc16(sig.encode("ascii"))
    return (crc & 0xFF) ^ (crc >> 8)


def spec_hash(canonical: Any) -> int:
    """First four bytes (big-endian) of SHA-256 over the canonical JSON of the wire-relevant spec."""
    text = json.dumps(canonical, sort_keys=True, separators=(",", ":"))
    return int.from_bytes(hashlib.sha256(text.encode("utf-8")).digest()[:4], "big")
