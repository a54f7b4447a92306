"""Emit golden vectors: message + field values + seq -> exact frame bytes, one JSON file per message.

The bytes come from this module's own reference encoder (field by field from the model, a
textbook COBS loop and the bit-by-bit CRC in protocol.generator.hashing), so the Python and C++ codecs are
checked against an implementation they share no code with.
"""

from __future__ import annotations

import struct
from typing import Any

from protocol.generator import hashing
from protocol.generator.emit.common import json_with_banner
from protocol.generator.model import PRIMITIVES, Field, Message, Spec

DIR = "protocol/vectors"


def emit(spec: Spec) -> dict[str, str]:
    return {f"{DIR}/{m.name.lower()}.json": _file(spec, m) for m in spec.messages}


def _file(spec: Spec, m: Message) -> str:
    vectors = [_vector(spec, m, case, values, seq) for case, values, seq in _cases(m)]
    return json_with_banner(spec, {"message": m.name, "msg_id": m.id, "crc_extra": m.crc_extra, "vectors": vectors})


# -- field values per case -------------------------------------------------------------------------
def _f32(x: float) -> float:
    """Round to the nearest f32 so the JSON value survives the wire exactly."""
    return float(struct.unpack("<f", struct.pack("<f", x))[0])


class _Rng:
    """xorshift32: deterministic on every Python version, unlike `random` across releases."""

    def __init__(self, seed: int) -> None:
        self.state = (seed * 2654435761 + 1) & 0xFFFFFFFF or 1

    def next(self) -> int:
        x = self.state
        x ^= (x << 13) & 0xFFFFFFFF
        x ^= x >> 17
        x ^= (x << 5) & 0xFFFFFFFF
        self.state = x
        return x

    def between(self, lo: int, hi: int) -> int:
        return lo + self.next() % (hi - lo + 1)


def _scalar(f: Field, case: str, rng: _Rng) -> Any:
    if f.enum is not None:
        values = sorted(v.value for v in f.enum.values)
        if f.enum.flags:
            return {"zero": 0, "min": values[0], "max": f.enum.mask}.get(case, rng.between(0, f.enum.mask))
        return {"zero": values[0], "min": values[0], "max": values[-1]}.get(case, values[rng.next() % len(values)])
    lo, hi = f.lo, f.hi
    if f.is_float:
        if case == "typical":
            span = min(hi, 1e6) - max(lo, -1e6)
            return _f32(max(lo, -1e6) + span * (rng.next() / 0xFFFFFFFF))
        return _f32({"zero": min(max(0.0, lo), hi), "min": lo, "max": hi}[case])
    ilo, ihi = int(lo), int(hi)
    return {"zero": min(max(0, ilo), ihi), "min": ilo, "max": ihi}.get(case, rng.between(ilo, ihi))


def _value(f: Field, case: str, rng: _Rng) -> Any:
    if f.max_len is not None:
        length = {"zero": 0, "min": 1, "max": f.max_len}.get(case, rng.between(0, f.max_len))
        if f.prim == "char":
            alphabet = "RoverLink 0123456789-_.:/abcdefghijklmnopqrstuvwxyz"
            return "".join(alphabet[rng.next() % len(alphabet)] for _ in range(length))
        return bytes(rng.next() & 0xFF for _ in range(length)).hex()
    if f.count is not None:
        return [_scalar(f, case, rng) for _ in range(f.count)]
    return _scalar(f, case, rng)


def _cases(m: Message) -> list[tuple[str, dict[str, Any], int]]:
    """zero (COBS worst case), min (negative extremes), max, and two seeded typical ones."""
    out = []
    for case, seq in (("zero", 0), ("min", 1), ("max", 255), ("typical", 0x5A), ("typical", 0xA5)):
        rng = _Rng(m.id * 256 + seq)
        out.append((case, {f.name: _value(f, case, rng) for f in m.fields}, seq))
    return out


# -- reference encoder --------------------------------------------------------------------------------
def _pack_field(f: Field, value: Any) -> bytes:
    code = "<" + PRIMITIVES[f.prim][2]
    if f.max_len is not None:
        return value.encode("ascii") if f.prim == "char" else bytes.fromhex(value)
    if f.count is not None:
        return b"".join(struct.pack(code, v) for v in value)
    return struct.pack(code, value)


def _cobs(data: bytes) -> bytes:
    out = bytearray([0])
    code_at, code = 0, 1
    for byte in data:
        if byte == 0:
            out[code_at] = code
            code_at, code = len(out), 1
            out.append(0)
            continue
        out.append(byte)
        code += 1
        if code == 0xFF:
            out[code_at] = code
            code_at, code = len(out), 1
            out.append(0)
    out[code_at] = code
    return bytes(out)


def _vector(spec: Spec, m: Message, case: str, values: dict[str, Any], seq: int) -> dict[str, Any]:
    payload = b"".join(_pack_field(f, values[f.name]) for f in m.fields)
    assert m.payload_size <= len(payload) <= m.payload_max <= spec.max_payload
    body = bytes((m.id, seq)) + payload
    crc = hashing.crc16(body + bytes((m.crc_extra,)))
    frame = _cobs(body + crc.to_bytes(2, "little")) + b"\x00"
    return {
        "case": case,
        "seq": seq,
        "fields": values,
        "payload": payload.hex(),
        "frame": frame.hex(),
    }
