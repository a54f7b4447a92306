"""CRC-16/CCITT-FALSE (poly 0x1021, init 0xFFFF, no reflection, no final xor).

binascii.crc_hqx is exactly this CRC, implemented in C in the standard library.
"""

from __future__ import annotations

from binascii import crc_hqx

CRC_INIT = 0xFFFF


def crc16(data: bytes, crc: int = CRC_INIT) -> int:
    """CRC of `data`, continuing from `crc`; crc16(b"123456789") == 0x29B1."""
    return crc_hqx(data, crc)


def frame_crc(body: bytes, crc_extra: int) -> int:
    """CRC of a frame: id, seq and payload, then the message's CRC_EXTRA byte (never sent)."""
    return crc_hqx(bytes((crc_extra,)), crc_hqx(body, CRC_INIT))
