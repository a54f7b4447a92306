"""pymavlink (MAVLink 2, unsigned) in the codec benchmark, and the choice of the MAVLink message
whose payload the peers carry."""

from __future__ import annotations

import argparse
import importlib
import random
from collections.abc import Callable
from typing import Any

from .common import Case, Stack, chunks, expect, expect_count, rand_scalar

# MAVLink wire types -> struct format characters (also used for the
# pySerialTransfer payload layout so both peers carry the same field types).
MAVLINK_STRUCT = {
    "uint8_t": "B",
    "int8_t": "b",
    "uint16_t": "H",
    "int16_t": "h",
    "uint32_t": "I",
    "int32_t": "i",
    "uint64_t": "Q",
    "int64_t": "q",
    "float": "f",
    "double": "d",
}
MAVLINK2_OVERHEAD = 12  # 10-byte header + 2-byte CRC, unsigned frames


def mavlink_module() -> Any:
    # ardupilotmega includes common and has more char-free messages, so more
    # payload sizes have an exact match.
    return importlib.import_module("pymavlink.dialects.v20.ardupilotmega")


def mavlink_wire_fields(cls: Any) -> list[tuple[str, str, int]]:
    """(name, struct char, array length or 0) in wire order."""
    types_by_name = dict(zip(cls.fieldnames, cls.fieldtypes, strict=True))
    return [
        (name, MAVLINK_STRUCT[types_by_name[name]], alen)
        for name, alen in zip(cls.ordered_fieldnames, cls.array_lengths, strict=True)
    ]


def choose_mavlink_message(mod: Any, size: int, n_fields: int | None, name: str | None) -> Any:
    """The message whose payload length is nearest ``size``.

    Messages with char[] fields are skipped (they are strings, not telemetry,
    and need no random numeric values). Ties go to the field count closest to
    the RoverLink message (per-field work dominates pure-Python codecs), then
    to the lowest message id (the core, widely used messages).
    """
    if name:
        for cls in mod.mavlink_map.values():
            if cls.msgname == name.upper():
                return cls
        raise SystemExit(f"unknown MAVLink message {name!r}")
    candidates = [c for c in mod.mavlink_map.values() if "char" not in c.fieldtypes]
    return min(
        candidates,
        key=lambda c: (
            abs(c.unpacker.size - size),
            abs(len(c.fieldnames) - n_fields) if n_fields else 0,
            c.id,
        ),
    )


def random_field_values(cls: Any, rng: random.Random) -> list[Any]:
    """Random non-zero values for every field of a MAVLink message, in constructor order."""
    fmt_by_name = {name: (fmt, alen) for name, fmt, alen in mavlink_wire_fields(cls)}
    out: list[Any] = []
    for name in cls.fieldnames:  # constructor order
        fmt, alen = fmt_by_name[name]
        if alen:
            out.append([rand_scalar(fmt, rng) for _ in range(alen)])
        else:
            out.append(rand_scalar(fmt, rng))
    return out


def build_pymavlink(n: int, size: int, n_fields: int | None, args: argparse.Namespace) -> Stack:
    mod = mavlink_module()
    cls = choose_mavlink_message(mod, size, n_fields, args.mavlink_message)

    def new_mav() -> Any:
        mav = mod.MAVLink(None, srcSystem=1, srcComponent=1)
        mav.signing.sign_outgoing = False  # explicit: unsigned MAVLink 2
        return mav

    values, stream = _reference_frames(cls, n, random.Random(args.seed), new_mav())
    return Stack(
        key="pymavlink",
        label="pymavlink",
        message=f"{cls.msgname} (MAVLink 2, {mod.__name__.rsplit('.', 1)[-1]})",
        payload_bytes=cls.unpacker.size,
        wire_bytes_per_frame=len(stream) / n,
        cases=[
            _encode_case(cls, values, stream, new_mav),
            _decode_case(cls, values, chunks(stream, args.chunk), new_mav),
        ],
        notes=[f"fastcrc in use: {mod.mcrf4xx is not None}"],
    )


def _reference_frames(cls: Any, n: int, rng: random.Random, probe: Any) -> tuple[list[list[Any]], bytes]:
    """N frames' field values and their stream. A frame whose trailing payload bytes are zero is
    drawn again (MAVLink 2 would truncate it and the frame would be shorter)."""
    frame_len = cls.unpacker.size + MAVLINK2_OVERHEAD
    values: list[list[Any]] = []
    frames: list[bytes] = []
    while len(values) < n:
        vals = random_field_values(cls, rng)
        probe.seq = len(values) & 0xFF
        frame = cls(*vals).pack(probe)
        if len(frame) == frame_len:
            values.append(vals)
            frames.append(frame)
    return values, b"".join(frames)


def _encode_case(cls: Any, values: list[list[Any]], stream: bytes, new_mav: Callable[[], Any]) -> Case:
    def prepare() -> Callable[[], list[bytes]]:
        mav = new_mav()

        def run() -> list[bytes]:
            out: list[bytes] = []
            append = out.append
            for i, vals in enumerate(values):
                mav.seq = i & 0xFF
                append(cls(*vals).pack(mav))
            return out

        return run

    def check(out: list[bytes]) -> None:
        expect_count("pymavlink", "encode", len(out), len(values))
        expect(b"".join(out) == stream, "pymavlink encode: bytes differ from reference")

    return Case("encode", prepare, check)


def _decode_case(cls: Any, values: list[list[Any]], pieces: list[bytes], new_mav: Callable[[], Any]) -> Case:
    def prepare() -> Callable[[], list[Any]]:
        mav = new_mav()

        def run() -> list[Any]:
            out: list[Any] = []
            parse = mav.parse_buffer
            for chunk in pieces:
                msgs = parse(chunk)
                if msgs:
                    out.extend(msgs)
            return out

        return run

    def check(msgs: list[Any]) -> None:
        expect_count("pymavlink", "decode", len(msgs), len(values))
        for i, (m, vals) in enumerate(zip(msgs, values, strict=True)):
            got = [getattr(m, f) for f in cls.fieldnames]
            expect(
                m.get_msgId() == cls.id and m.get_seq() == i & 0xFF and got == vals,
                f"pymavlink decode: frame {i} differs from what was encoded",
            )

    return Case("decode", prepare, check)
