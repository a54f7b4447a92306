"""pySerialTransfer in the codec benchmark, over an in-memory port (no system calls)."""

from __future__ import annotations

import argparse
import importlib
import random
import struct
from collections.abc import Callable
from typing import Any

from .common import BenchmarkError, Case, Skip, Stack, expect, expect_count, rand_scalar
from .mavlink import choose_mavlink_message, mavlink_module, mavlink_wire_fields

PST_OVERHEAD = 6  # start, id, overhead, length, CRC8, stop
PACKET_ID = 1


class MemoryPort:
    """Stand-in for ``serial.Serial``: just the members SerialTransfer uses.

    ``in_waiting`` is a plain attribute kept up to date by ``read`` (not a
    property) so the fake adds as little cost as possible.
    """

    is_open = True

    def __init__(self, data: bytes = b"") -> None:
        self._data = data
        self._pos = 0
        self.in_waiting = len(data)
        self.written = bytearray()

    def read(self, size: int = 1) -> bytes:
        pos = self._pos
        chunk = self._data[pos : pos + size]
        self._pos = pos + len(chunk)
        self.in_waiting -= len(chunk)
        return chunk

    def write(self, data: bytes | bytearray) -> int:
        self.written += data
        return len(data)

    def open(self) -> None:
        pass

    def close(self) -> None:
        pass


def pst_layout(mav_cls: Any, size: int) -> list[str]:
    """Struct chars for each pySerialTransfer field: the MAVLink message's
    fields in wire order (arrays flattened), trimmed or padded with uint8 to
    exactly ``size`` bytes."""
    fmts = [fmt for _, fmt, alen in mavlink_wire_fields(mav_cls) for _ in range(alen or 1)]
    while sum(struct.calcsize(f) for f in fmts) > size:
        fmts.pop()
    fmts += ["B"] * (size - sum(struct.calcsize(f) for f in fmts))
    return fmts


def build_pyserialtransfer(n: int, size: int, n_fields: int | None, args: argparse.Namespace) -> Stack:
    pst = importlib.import_module("pySerialTransfer.pySerialTransfer")
    if not 0 < size <= pst.MAX_PACKET_SIZE:
        raise Skip(f"payload {size} B exceeds pySerialTransfer's {pst.MAX_PACKET_SIZE} B limit")
    mav_cls = choose_mavlink_message(mavlink_module(), size, n_fields, args.mavlink_message)
    fmts = pst_layout(mav_cls, size)
    rng = random.Random(args.seed + 1)
    values = [tuple(rand_scalar(f, rng) for f in fmts) for _ in range(n)]

    def new_link(data: bytes = b"") -> tuple[Any, MemoryPort]:
        # restrict_ports=False skips port enumeration; the pyserial object it
        # creates is never opened and is replaced by the in-memory port.
        link = pst.SerialTransfer("roverlink-bench", restrict_ports=False, debug=False)
        port = MemoryPort(data)
        link.connection = port
        return link, port

    prepare_encode = _encoder(fmts, values, new_link)
    # Reference stream for decoding, produced by the library itself.
    stream = bytes(prepare_encode()())
    expect(
        len(stream) == n * (size + PST_OVERHEAD),
        "pySerialTransfer: unexpected frame size",
    )
    errors = {
        pst.Status.CRC_ERROR,
        pst.Status.PAYLOAD_ERROR,
        pst.Status.STOP_BYTE_ERROR,
    }
    return Stack(
        key="pyserialtransfer",
        label="pySerialTransfer",
        message=f"{len(fmts)} fields, {mav_cls.msgname} field types",
        payload_bytes=size,
        wire_bytes_per_frame=len(stream) / n,
        cases=[
            Case("encode", prepare_encode, _check_encode(stream, size, n)),
            _decode_case(fmts, values, stream, new_link, errors, extract=True),
            _decode_case(fmts, values, stream, new_link, errors, extract=False),
        ],
        notes=["in-memory port (no syscalls): an upper bound for a real serial port"],
    )


def _encoder(
    fmts: list[str], values: list[tuple[Any, ...]], new_link: Callable[..., tuple[Any, MemoryPort]]
) -> Callable[[], Callable[[], bytearray]]:
    def prepare() -> Callable[[], bytearray]:
        link, port = new_link()

        def run() -> bytearray:
            tx, send = link.tx_obj, link.send
            for vals in values:
                pos = 0
                for v, fmt in zip(vals, fmts, strict=True):
                    pos = tx(v, pos, val_type_override=fmt)
                if not send(pos, packet_id=PACKET_ID):
                    raise BenchmarkError("pySerialTransfer send() failed")
            return port.written

        return run

    return prepare


def _check_encode(stream: bytes, size: int, n: int) -> Callable[[bytearray], None]:
    def check(out: bytearray) -> None:
        expect_count("pySerialTransfer", "encode", len(out) // (size + PST_OVERHEAD), n)
        expect(bytes(out) == stream, "pySerialTransfer encode: bytes differ from reference")

    return check


def _decode_case(
    fmts: list[str],
    values: list[tuple[Any, ...]],
    stream: bytes,
    new_link: Callable[..., tuple[Any, MemoryPort]],
    errors: set[Any],
    *,
    extract: bool,
) -> Case:
    """Full decode (``available()`` and ``rx_obj`` per field), or, without ``extract``, the
    parse alone (packets delimited and CRC-checked, no values taken out)."""
    offsets = [0]
    for f in fmts:
        offsets.append(offsets[-1] + struct.calcsize(f))
    fields = list(zip(fmts, offsets, strict=False))

    def prepare() -> Callable[[], list[Any]]:
        link, port = new_link(stream)

        def run() -> list[Any]:
            out: list[Any] = []
            available, rx = link.available, link.rx_obj
            while port.in_waiting:
                if available():
                    if extract:
                        out.append(tuple([rx(fmt, pos) for fmt, pos in fields]))
                    else:
                        out.append(link.id_byte)
                elif link.status in errors:
                    raise BenchmarkError(f"pySerialTransfer decode: {link.status}")
            return out

        return run

    def check_decode(out: list[Any]) -> None:
        expect_count("pySerialTransfer", "decode", len(out), len(values))
        expect(
            out == values,
            "pySerialTransfer decode: values differ from what was encoded",
        )

    def check_parse_only(out: list[Any]) -> None:
        expect_count("pySerialTransfer", "decode (parse only)", len(out), len(values))
        expect(all(i == PACKET_ID for i in out), "pySerialTransfer decode: wrong packet id")

    if extract:
        return Case("decode", prepare, check_decode)
    return Case("decode_parse_only", prepare, check_parse_only)
