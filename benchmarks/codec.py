"""Codec throughput benchmark: RoverLink vs pymavlink (MAVLink 2) vs pySerialTransfer.

What is measured
----------------
For each stack, in one process on one machine, with the same payload size:

* **encode**: Python field values -> message object -> wire bytes, for N frames.
  - RoverLink: ``encode_frame(MsgClass(*values), seq)``.
  - pymavlink: ``MsgClass(*values).pack(mav)`` (MAVLink 2, no signing), with
    ``mav.seq`` set per frame.
  - pySerialTransfer: ``tx_obj(value, pos, val_type_override=fmt)`` per field,
    then ``send(payload_len)``; the port is an in-memory object whose
    ``write()`` appends to a bytearray, so the packet is built but nothing
    touches hardware.
* **decode**: one stream of N concatenated frames -> decoded field values.
  - RoverLink: ``FrameDecoder().feed(stream)``.
  - pymavlink: ``MAVLink.parse_buffer(stream)`` (the library's bulk entry point;
    ``parse_char`` is the same code fed one buffer at a time).
  - pySerialTransfer: ``available()`` driven until the in-memory port is empty,
    plus ``rx_obj(fmt, pos)`` for every field of each packet (``available()``
    alone only fills ``rx_buff``; users need ``rx_obj`` to get values). The
    figure without ``rx_obj`` is also printed as "parse only".

Why this is fair
----------------
* Same payload size for every stack. The RoverLink message is picked at run
  time and the peers follow its ``PAYLOAD_SIZE``. The MAVLink message is the
  char-free ardupilotmega message whose payload length is nearest to that size
  (exact for most sizes; every size used is printed). The pySerialTransfer
  payload has the same field types as that MAVLink message, padded or
  trimmed to exactly the target size.
* Peer values are random and non-zero, so MAVLink 2 trailing-zero truncation
  cannot shrink frames; every frame's length is checked before timing.
* Parser objects and input data are built before timing starts. Timing uses
  ``time.perf_counter`` with the garbage collector paused, as ``timeit``
  does, and keeps the best of K repeats. Repeats go round-robin across stacks
  so clock drift and thermal effects hit every stack alike.
* After every timed run, untimed, the output is checked: exactly N frames,
  with the values that went in. A run that decodes nothing therefore fails
  loudly instead of reporting a huge rate.
* The pySerialTransfer port is the cheapest possible fake: no syscalls. A real
  pyserial port costs more per ``read()``, so its figures here are an upper
  bound.

Run ``python benchmarks/codec.py --help`` for options (``--json``, ``--quick``).
"""

from __future__ import annotations

import argparse
import dataclasses
import enum
import gc
import importlib
import importlib.metadata
import json
import math
import platform
import random
import struct
import sys
import time
import types
import typing
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any

REPO_ROOT = Path(__file__).resolve().parent.parent
# Used only when RoverLink is unavailable: the size of the robot's Feedback
# telemetry payload, so peer-only runs stay comparable with full runs.
DEFAULT_PAYLOAD_SIZE = 33
MAX_ROVERLINK_PAYLOAD = 64

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
PST_OVERHEAD = 6  # start, id, overhead, length, CRC8, stop


class BenchmarkError(RuntimeError):
    """Raised when a stack produced wrong output; the figures would be bogus."""


class Skip(Exception):
    """Raised when a stack cannot be measured in this environment."""


@dataclasses.dataclass
class Case:
    """One timed operation. ``prepare`` builds fresh state (untimed) and
    returns the callable to time; ``check`` validates its result (untimed)."""

    op: str
    prepare: Callable[[], Callable[[], Any]]
    check: Callable[[Any], None]
    times: list[float] = dataclasses.field(default_factory=list)


@dataclasses.dataclass
class Stack:
    key: str
    label: str
    message: str
    payload_bytes: int
    wire_bytes_per_frame: float
    cases: list[Case]
    notes: list[str] = dataclasses.field(default_factory=list)


# --------------------------------------------------------------------------
# Shared helpers
# --------------------------------------------------------------------------


def _expect(cond: bool, what: str) -> None:
    if not cond:
        raise BenchmarkError(what)


def _expect_count(stack: str, op: str, got: int, want: int) -> None:
    _expect(got == want, f"{stack} {op}: produced {got} frames, expected {want}")


def _rand_scalar(fmt: str, rng: random.Random) -> int | float:
    """Random non-zero value for a struct format char (float32 values are
    pre-rounded so that decoded values compare equal)."""
    if fmt == "f":
        x = rng.uniform(-1000.0, 1000.0) or 1.0
        return float(struct.unpack("<f", struct.pack("<f", x))[0])
    if fmt == "d":
        return rng.uniform(-1000.0, 1000.0) or 1.0
    bits = 8 * struct.calcsize("<" + fmt)
    lo, hi = (-(1 << (bits - 1)), (1 << (bits - 1)) - 1) if fmt.islower() else (1, (1 << bits) - 1)
    v = 0
    while v == 0:
        v = rng.randint(lo, hi)
    return v


def _chunks(stream: bytes, size: int) -> list[bytes]:
    if size <= 0:
        return [stream]
    return [stream[i : i + size] for i in range(0, len(stream), size)]


# --------------------------------------------------------------------------
# pymavlink (MAVLink 2)
# --------------------------------------------------------------------------


def _mavlink_module() -> Any:
    # ardupilotmega includes common and has more char-free messages, so more
    # payload sizes have an exact match.
    return importlib.import_module("pymavlink.dialects.v20.ardupilotmega")


def _mavlink_wire_fields(cls: Any) -> list[tuple[str, str, int]]:
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


def build_pymavlink(n: int, size: int, n_fields: int | None, args: argparse.Namespace) -> Stack:
    mod = _mavlink_module()
    cls = choose_mavlink_message(mod, size, n_fields, args.mavlink_message)
    payload = cls.unpacker.size
    frame_len = payload + MAVLINK2_OVERHEAD
    fmt_by_name = {name: (fmt, alen) for name, fmt, alen in _mavlink_wire_fields(cls)}
    rng = random.Random(args.seed)

    def new_mav() -> Any:
        mav = mod.MAVLink(None, srcSystem=1, srcComponent=1)
        mav.signing.sign_outgoing = False  # explicit: unsigned MAVLink 2
        return mav

    def random_values() -> list[Any]:
        out: list[Any] = []
        for name in cls.fieldnames:  # constructor order
            fmt, alen = fmt_by_name[name]
            if alen:
                out.append([_rand_scalar(fmt, rng) for _ in range(alen)])
            else:
                out.append(_rand_scalar(fmt, rng))
        return out

    # Pre-build values; redraw any frame whose trailing payload bytes are zero
    # (MAVLink 2 would truncate it and the frame would be shorter).
    probe = new_mav()
    values: list[list[Any]] = []
    frames: list[bytes] = []
    while len(values) < n:
        vals = random_values()
        probe.seq = len(values) & 0xFF
        frame = cls(*vals).pack(probe)
        if len(frame) == frame_len:
            values.append(vals)
            frames.append(frame)
    stream = b"".join(frames)
    chunks = _chunks(stream, args.chunk)

    def prep_encode() -> Callable[[], list[bytes]]:
        mav = new_mav()

        def run() -> list[bytes]:
            out: list[bytes] = []
            append = out.append
            for i, vals in enumerate(values):
                mav.seq = i & 0xFF
                append(cls(*vals).pack(mav))
            return out

        return run

    def check_encode(out: list[bytes]) -> None:
        _expect_count("pymavlink", "encode", len(out), n)
        _expect(b"".join(out) == stream, "pymavlink encode: bytes differ from reference")

    def prep_decode() -> Callable[[], list[Any]]:
        mav = new_mav()

        def run() -> list[Any]:
            out: list[Any] = []
            parse = mav.parse_buffer
            for chunk in chunks:
                msgs = parse(chunk)
                if msgs:
                    out.extend(msgs)
            return out

        return run

    def check_decode(msgs: list[Any]) -> None:
        _expect_count("pymavlink", "decode", len(msgs), n)
        for i, (m, vals) in enumerate(zip(msgs, values, strict=True)):
            got = [getattr(m, f) for f in cls.fieldnames]
            _expect(
                m.get_msgId() == cls.id and m.get_seq() == i & 0xFF and got == vals,
                f"pymavlink decode: frame {i} differs from what was encoded",
            )

    return Stack(
        key="pymavlink",
        label="pymavlink",
        message=f"{cls.msgname} (MAVLink 2, {mod.__name__.rsplit('.', 1)[-1]})",
        payload_bytes=payload,
        wire_bytes_per_frame=len(stream) / n,
        cases=[
            Case("encode", prep_encode, check_encode),
            Case("decode", prep_decode, check_decode),
        ],
        notes=[f"fastcrc in use: {mod.mcrf4xx is not None}"],
    )


# --------------------------------------------------------------------------
# pySerialTransfer
# --------------------------------------------------------------------------


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
    fmts = [fmt for _, fmt, alen in _mavlink_wire_fields(mav_cls) for _ in range(alen or 1)]
    while sum(struct.calcsize(f) for f in fmts) > size:
        fmts.pop()
    fmts += ["B"] * (size - sum(struct.calcsize(f) for f in fmts))
    return fmts


def build_pyserialtransfer(n: int, size: int, n_fields: int | None, args: argparse.Namespace) -> Stack:
    pst = importlib.import_module("pySerialTransfer.pySerialTransfer")
    if not 0 < size <= pst.MAX_PACKET_SIZE:
        raise Skip(f"payload {size} B exceeds pySerialTransfer's {pst.MAX_PACKET_SIZE} B limit")
    mav_cls = choose_mavlink_message(_mavlink_module(), size, n_fields, args.mavlink_message)
    fmts = pst_layout(mav_cls, size)
    offsets = [0]
    for f in fmts:
        offsets.append(offsets[-1] + struct.calcsize(f))
    fields = list(zip(fmts, offsets, strict=False))
    packet_id = 1
    errors = {
        pst.Status.CRC_ERROR,
        pst.Status.PAYLOAD_ERROR,
        pst.Status.STOP_BYTE_ERROR,
    }
    rng = random.Random(args.seed + 1)
    values = [tuple(_rand_scalar(f, rng) for f in fmts) for _ in range(n)]

    def new_link(data: bytes = b"") -> tuple[Any, MemoryPort]:
        # restrict_ports=False skips port enumeration; the pyserial object it
        # creates is never opened and is replaced by the in-memory port.
        link = pst.SerialTransfer("roverlink-bench", restrict_ports=False, debug=False)
        port = MemoryPort(data)
        link.connection = port
        return link, port

    def prep_encode() -> Callable[[], bytearray]:
        link, port = new_link()

        def run() -> bytearray:
            tx, send = link.tx_obj, link.send
            for vals in values:
                pos = 0
                for v, fmt in zip(vals, fmts, strict=True):
                    pos = tx(v, pos, val_type_override=fmt)
                if not send(pos, packet_id=packet_id):
                    raise BenchmarkError("pySerialTransfer send() failed")
            return port.written

        return run

    # Reference stream for decoding, produced by the library itself.
    stream = bytes(prep_encode()())
    _expect(
        len(stream) == n * (size + PST_OVERHEAD),
        "pySerialTransfer: unexpected frame size",
    )

    def check_encode(out: bytearray) -> None:
        _expect_count("pySerialTransfer", "encode", len(out) // (size + PST_OVERHEAD), n)
        _expect(bytes(out) == stream, "pySerialTransfer encode: bytes differ from reference")

    def prep_decode(extract: bool) -> Callable[[], Callable[[], list[Any]]]:
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

        return prepare

    def check_decode(out: list[Any]) -> None:
        _expect_count("pySerialTransfer", "decode", len(out), n)
        _expect(
            out == values,
            "pySerialTransfer decode: values differ from what was encoded",
        )

    def check_parse_only(out: list[Any]) -> None:
        _expect_count("pySerialTransfer", "decode (parse only)", len(out), n)
        _expect(all(i == packet_id for i in out), "pySerialTransfer decode: wrong packet id")

    return Stack(
        key="pyserialtransfer",
        label="pySerialTransfer",
        message=f"{len(fmts)} fields, {mav_cls.msgname} field types",
        payload_bytes=size,
        wire_bytes_per_frame=len(stream) / n,
        cases=[
            Case("encode", prep_encode, check_encode),
            Case("decode", prep_decode(True), check_decode),
            Case("decode_parse_only", prep_decode(False), check_parse_only),
        ],
        notes=["in-memory port (no syscalls): an upper bound for a real serial port"],
    )


# --------------------------------------------------------------------------
# RoverLink
# --------------------------------------------------------------------------


def _import_roverlink() -> tuple[Any, Any]:
    if str(REPO_ROOT) not in sys.path:
        sys.path.insert(0, str(REPO_ROOT))  # benchmark the working tree
    try:
        messages = importlib.import_module("host_sdk.messages")
        framing = importlib.import_module("host_sdk.framing")
    except ImportError as exc:
        raise Skip(f"host_sdk not importable ({exc})") from exc
    for name in ("encode_frame", "FrameDecoder"):
        if not hasattr(framing, name):
            raise Skip(f"host_sdk.framing has no {name} yet")
    return messages, framing


def _field_types(cls: type) -> dict[str, Any]:
    """Resolved annotations of the dataclass fields (ClassVars excluded)."""
    try:
        hints = typing.get_type_hints(cls)
    except (NameError, TypeError):  # unresolvable annotations: use them raw
        hints = {}
    return {f.name: hints.get(f.name, f.type) for f in dataclasses.fields(cls)}


def _strip_optional(tp: Any) -> Any:
    if typing.get_origin(tp) in (typing.Union, types.UnionType):
        args = [a for a in typing.get_args(tp) if a is not type(None)]
        return args[0] if args else tp
    return tp


def _is_numeric(tp: Any) -> bool:
    tp = _strip_optional(tp)
    if typing.get_origin(tp) is tuple:
        return all(a is Ellipsis or _is_numeric(a) for a in typing.get_args(tp))
    return isinstance(tp, type) and issubclass(tp, int | float)  # incl. bool, IntEnum


def _roverlink_classes(messages: Any) -> list[Any]:
    classes = getattr(messages, "ALL_MESSAGES", None)
    if classes is None:
        classes = [getattr(messages, n) for n in getattr(messages, "__all__", ())]
        classes = [c for c in classes if isinstance(c, type) and hasattr(c, "MSG_ID")]
    return [c for c in classes if dataclasses.is_dataclass(c)]


def choose_roverlink_message(messages: Any, name: str | None) -> Any:
    classes = _roverlink_classes(messages)
    by_name = {c.__name__: c for c in classes}
    if name or "Feedback" in by_name:  # Feedback: the robot's telemetry message
        if (name or "Feedback") not in by_name:
            _fail(f"no RoverLink message {name!r}")
        chosen = by_name[name or "Feedback"]
        if not isinstance(getattr(chosen, "PAYLOAD_SIZE", None), int):
            _fail(f"{chosen.__name__} has no fixed PAYLOAD_SIZE")
        return chosen
    fixed = [
        c
        for c in classes
        if isinstance(getattr(c, "PAYLOAD_SIZE", None), int)
        and c.PAYLOAD_SIZE <= MAX_ROVERLINK_PAYLOAD
        and all(_is_numeric(t) for t in _field_types(c).values())
    ]
    if not fixed:
        _fail("no RoverLink message with a fixed numeric payload <= 64 B")
    return max(fixed, key=lambda c: c.PAYLOAD_SIZE)


def _fail(msg: str) -> typing.NoReturn:
    raise BenchmarkError(msg)


def _array_len(f: dataclasses.Field[Any], info: Any) -> int | None:
    """Length of a ``tuple[int, ...]`` field: from the message's optional
    ``FIELDS`` metadata (``count``), else the field default or metadata."""
    if isinstance(getattr(info, "count", None), int):
        return int(info.count)
    default = f.default if f.default is not dataclasses.MISSING else None
    if default is None and f.default_factory is not dataclasses.MISSING:
        default = f.default_factory()
    if isinstance(default, tuple | list | bytes):
        return len(default)
    for key in ("length", "len", "size", "count"):
        if isinstance(f.metadata.get(key), int):
            return int(f.metadata[key])
    return None


def _int_bounds(info: Any) -> tuple[int, int]:
    """1..100, narrowed to the field's ``lo``/``hi`` when the message says."""
    lo, hi = getattr(info, "lo", 1), getattr(info, "hi", 100)
    if not isinstance(lo, int | float) or not isinstance(hi, int | float):
        return 1, 100
    a, b = max(1, math.ceil(lo)), min(100, math.floor(hi))
    return (a, b) if a <= b else (math.ceil(lo), math.ceil(lo))


def _value_for(tp: Any, rng: random.Random | None, length: int, bounds: tuple[int, int]) -> Any:
    """A value for one field; ``rng=None`` means the all-1 fallback."""
    tp = _strip_optional(tp)
    if typing.get_origin(tp) is tuple:
        args = [a for a in typing.get_args(tp) if a is not Ellipsis]
        if Ellipsis not in typing.get_args(tp):
            return tuple(_value_for(a, rng, length, bounds) for a in args)
        return tuple(_value_for(args[0], rng, length, bounds) for _ in range(length))
    if isinstance(tp, type) and issubclass(tp, enum.Enum):
        members = list(tp)
        return members[0] if members else tp(0)  # first member (IntFlag: 0 if none)
    if tp is bool:
        return True if rng is None else rng.random() < 0.5
    if tp is int:
        return 1 if rng is None else rng.randint(*bounds)
    if tp is float:
        # Multiples of 0.25 up to 1.0: exact in float32 and in common fixed-point
        # scalings, and inside 0..1 ranges such as duty cycles.
        return 1.0 if rng is None else rng.randint(1, 4) * 0.25
    if tp is bytes:
        return b"\x01" * length if rng is None else bytes(rng.randint(1, 255) for _ in range(length))
    if tp is str:
        return "a" * length
    raise BenchmarkError(f"RoverLink field type {tp!r} not supported by the benchmark")


def _same(a: Any, b: Any) -> bool:
    """Equality with float tolerance (the wire may use fixed point or float32)."""
    if dataclasses.is_dataclass(a) and not isinstance(a, type):
        return type(a) is type(b) and _same(dataclasses.astuple(a), dataclasses.astuple(b))
    if isinstance(a, tuple | list):
        return len(a) == len(b) and all(_same(x, y) for x, y in zip(a, b, strict=True))
    if isinstance(a, float) or isinstance(b, float):
        return math.isclose(a, b, rel_tol=1e-6, abs_tol=1e-6)
    return bool(a == b)


def build_roverlink(n: int, args: argparse.Namespace) -> tuple[Stack, Any]:
    messages, framing = _import_roverlink()
    encode_frame, frame_decoder = framing.encode_frame, framing.FrameDecoder
    cls = choose_roverlink_message(messages, args.roverlink_message)
    hints = _field_types(cls)
    init_fields = [f for f in dataclasses.fields(cls) if f.init]
    infos = {fi.name: fi for fi in getattr(cls, "FIELDS", ())}  # optional metadata
    plan = [
        (
            hints[f.name],
            _array_len(f, infos.get(f.name)),
            _int_bounds(infos.get(f.name)),
        )
        for f in init_fields
    ]
    rejected = (ValueError, TypeError, OverflowError)

    def build(rng: random.Random | None, length: int, count: int, seq_mod: int) -> tuple[list[Any], bytes]:
        vals = [tuple(_value_for(tp, rng, alen or length, bnd) for tp, alen, bnd in plan) for _ in range(count)]
        return vals, b"".join(encode_frame(cls(*v), i % seq_mod) for i, v in enumerate(vals))

    def seq_modulus(vals: tuple[Any, ...]) -> int:
        # 8-bit seq expected; probe downwards in case it is narrower.
        for m in (256, 128, 64, 16, 8):
            try:
                encode_frame(cls(*vals), m - 1)
                return m
            except rejected:
                continue
        return 1

    def unknown_len(tp: Any, alen: int | None) -> bool:
        tp = _strip_optional(tp)
        return alen is None and (tp in (bytes, str) or Ellipsis in typing.get_args(tp))

    # Random values first; if the codec rejects them (ranges may be unknown),
    # all-1 values. Unknown array lengths are probed from 1 up on a few frames.
    variable = any(unknown_len(tp, alen) for tp, alen, _ in plan)
    lengths = range(1, cls.PAYLOAD_SIZE + 2) if variable else [1]
    built: tuple[list[Any], bytes] | None = None
    mode, seq_mod = "", 1
    for rng, mode in (  # noqa: B007 (mode is reported after the loop)
        (random.Random(args.seed + 2), "random"),
        (None, "all-1 fallback"),
    ):
        for length in lengths:
            try:
                probe, _ = build(rng, length, 8, 1)
                seq_mod = seq_modulus(probe[0])
                built = build(rng, length, n, seq_mod)
                break
            except rejected:
                continue
        if built:
            break
    if built is None:
        _fail(f"cannot build valid {cls.__name__} instances; try --roverlink-message")
    values, stream = built
    chunks = _chunks(stream, args.chunk)
    originals = [cls(*v) for v in values]

    def prep_encode() -> Callable[[], list[bytes]]:
        def run() -> list[bytes]:
            out: list[bytes] = []
            append = out.append
            for i, vals in enumerate(values):
                append(encode_frame(cls(*vals), i % seq_mod))
            return out

        return run

    def check_encode(out: list[bytes]) -> None:
        _expect_count("RoverLink", "encode", len(out), n)
        _expect(b"".join(out) == stream, "RoverLink encode: bytes differ from reference")
        _expect(
            all(f.endswith(b"\x00") for f in out),
            "RoverLink encode: frame not 0x00-terminated",
        )

    def prep_decode() -> Callable[[], tuple[Any, list[Any]]]:
        decoder = frame_decoder()

        def run() -> tuple[Any, list[Any]]:
            out: list[Any] = []
            feed = decoder.feed
            for chunk in chunks:
                out.extend(feed(chunk))
            return decoder, out

        return run

    def check_decode(result: tuple[Any, list[Any]]) -> None:
        decoder, items = result
        frames = [it for it in items if hasattr(it, "message")]
        _expect_count("RoverLink", "decode", len(frames), n)
        stats = getattr(decoder, "stats", None)
        if stats is not None:
            _expect_count("RoverLink", "decode (stats.frames_ok)", stats.frames_ok, n)
        for i, (fr, orig) in enumerate(zip(frames, originals, strict=True)):
            _expect(
                fr.seq == i % seq_mod and _same(fr.message, orig),
                f"RoverLink decode: frame {i} differs from what was encoded",
            )

    stack = Stack(
        key="roverlink",
        label="RoverLink",
        message=f"{cls.__name__} (MSG_ID {getattr(cls, 'MSG_ID', '?')})",
        payload_bytes=int(cls.PAYLOAD_SIZE),
        wire_bytes_per_frame=len(stream) / n,
        cases=[
            Case("encode", prep_encode, check_encode),
            Case("decode", prep_decode, check_decode),
        ],
        notes=[f"field values: {mode}; seq modulo {seq_mod}"],
    )
    return stack, cls


# --------------------------------------------------------------------------
# Timing and reporting
# --------------------------------------------------------------------------


def time_case(case: Case) -> None:
    run = case.prepare()
    gc.collect()
    gc.disable()  # like timeit: keep collector pauses out of the figures
    try:
        t0 = time.perf_counter()
        result = run()
        elapsed = time.perf_counter() - t0
    finally:
        gc.enable()
    case.check(result)
    case.times.append(elapsed)


def figures(case: Case, n: int) -> dict[str, Any]:
    best = min(case.times)
    return {
        "frames_per_s": n / best,
        "us_per_frame": best / n * 1e6,
        "best_s": best,
        "times_s": case.times,
    }


def _version(dist: str) -> str | None:
    try:
        return importlib.metadata.version(dist)
    except importlib.metadata.PackageNotFoundError:
        return None


def parse_args(argv: Sequence[str] | None) -> argparse.Namespace:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0] if __doc__ else None)
    p.add_argument("--frames", type=int, default=20_000, help="frames per run (default 20000)")
    p.add_argument(
        "--repeat",
        type=int,
        default=5,
        help="timed runs per case; best is kept (default 5)",
    )
    p.add_argument("--quick", action="store_true", help="smoke test: 3000 frames, 3 repeats")
    p.add_argument("--json", metavar="PATH", help="also write the figures as JSON to PATH")
    p.add_argument(
        "--chunk",
        type=int,
        default=0,
        help="bytes per RoverLink/pymavlink decoder call (default 0: the whole "
        "stream in one call); pySerialTransfer pulls bytes itself",
    )
    p.add_argument(
        "--payload-size",
        type=int,
        help=f"peer payload size in bytes (default: the RoverLink message's, else {DEFAULT_PAYLOAD_SIZE})",
    )
    p.add_argument("--roverlink-message", help="RoverLink message class name (default: automatic)")
    p.add_argument(
        "--mavlink-message",
        help="MAVLink message name, e.g. COMMAND_LONG (default: automatic)",
    )
    p.add_argument(
        "--require-roverlink",
        action="store_true",
        help="fail instead of skipping RoverLink",
    )
    p.add_argument("--seed", type=int, default=1, help="random seed for field values")
    args = p.parse_args(argv)
    if args.quick:
        args.frames, args.repeat = 3_000, 3
    if args.frames < 1 or args.repeat < 1:
        p.error("--frames and --repeat must be >= 1")
    if args.payload_size is not None and not 1 <= args.payload_size <= 254:
        p.error("--payload-size must be in 1..254")
    return args


def main(argv: Sequence[str] | None = None) -> int:
    args = parse_args(argv)
    n = args.frames

    stacks: list[Stack] = []
    skipped: dict[str, str] = {}
    n_fields: int | None = None
    size = args.payload_size
    try:
        rl_stack, rl_cls = build_roverlink(n, args)
        stacks.append(rl_stack)
        n_fields = len([f for f in dataclasses.fields(rl_cls) if f.init])
        if size is None:
            size = rl_stack.payload_bytes
        elif size != rl_stack.payload_bytes:
            print(
                f"warning: peers use {size} B payloads but {rl_stack.message} has "
                f"{rl_stack.payload_bytes} B: the ratios are not like for like"
            )
    except Skip as exc:
        if args.require_roverlink:
            print(f"error: RoverLink unavailable: {exc}", file=sys.stderr)
            return 1
        skipped["roverlink"] = str(exc)
        print(f"RoverLink: skipped ({exc}); measuring peers only.")
    size = size or DEFAULT_PAYLOAD_SIZE

    for key, build in (
        ("pymavlink", build_pymavlink),
        ("pyserialtransfer", build_pyserialtransfer),
    ):
        try:
            stacks.append(build(n, size, n_fields, args))
        except Skip as exc:
            skipped[key] = str(exc)
            print(f"{key}: skipped ({exc})")

    # Round-robin the repeats so drift affects every stack equally.
    for _ in range(args.repeat):
        for stack in stacks:
            for case in stack.cases:
                time_case(case)

    results = {stack.key: stack_results(stack, n) for stack in stacks}
    ratios = compute_ratios(results)
    print_report(args, size, stacks, results, ratios)
    if args.json:
        write_json(args, size, results, skipped, ratios)
        print(f"\nwrote {args.json}")
    return 0


def stack_results(stack: Stack, n: int) -> dict[str, Any]:
    entry: dict[str, Any] = {
        "message": stack.message,
        "payload_bytes": stack.payload_bytes,
        "wire_bytes_per_frame": stack.wire_bytes_per_frame,
        "notes": stack.notes,
    }
    for case in stack.cases:
        entry[case.op] = figures(case, n)
    return entry


PEERS = (("pymavlink", "pymavlink"), ("pyserialtransfer", "pySerialTransfer"))


def compute_ratios(results: dict[str, Any]) -> dict[str, dict[str, float] | None]:
    """RoverLink frames/s divided by peer frames/s (> 1: RoverLink faster)."""
    ratios: dict[str, dict[str, float] | None] = {}
    for peer, _ in PEERS:
        ratios[f"roverlink/{peer}"] = (
            {
                op: results["roverlink"][op]["frames_per_s"] / results[peer][op]["frames_per_s"]
                for op in ("encode", "decode")
            }
            if "roverlink" in results and peer in results
            else None
        )
    return ratios


def print_report(
    args: argparse.Namespace,
    size: int,
    stacks: list[Stack],
    results: dict[str, Any],
    ratios: dict[str, dict[str, float] | None],
) -> None:
    feed = "the whole stream per call" if args.chunk <= 0 else f"{args.chunk} B per call"
    print(
        f"\nCodec throughput: {args.frames} frames, best of {args.repeat}, "
        f"Python {platform.python_version()} ({platform.machine()})"
    )
    print(f"target payload: {size} B; decoders fed {feed}")
    head = f"{'stack':<17}{'op':<18}{'frames/s':>11}{'us/frame':>9}{'payload':>9}{'wire':>8}  message"
    print(head)
    print("-" * len(head))
    for stack in stacks:
        for case in stack.cases:
            fig = results[stack.key][case.op]
            print(
                f"{stack.label:<17}{case.op:<18}{fig['frames_per_s']:>11,.0f}"
                f"{fig['us_per_frame']:>9.2f}{stack.payload_bytes:>7} B"
                f"{stack.wire_bytes_per_frame:>6.1f} B  {stack.message}"
            )
    for stack in stacks:
        for note in stack.notes:
            print(f"note: {stack.label}: {note}")
    if "roverlink" in results:
        print("\nRatios, RoverLink frames/s / peer frames/s (> 1: RoverLink faster):")
        for peer, label in PEERS:
            r = ratios[f"roverlink/{peer}"]
            if r is not None:
                print(f"  RoverLink/{label:<17} encode {r['encode']:6.2f}x   decode {r['decode']:6.2f}x")


def write_json(
    args: argparse.Namespace,
    size: int,
    results: dict[str, Any],
    skipped: dict[str, str],
    ratios: dict[str, dict[str, float] | None],
) -> None:
    packages = ("pymavlink", "pySerialTransfer", "fastcrc", "pyserial")
    doc = {
        "benchmark": "roverlink-codec",
        "params": {
            "frames": args.frames,
            "repeat": args.repeat,
            "chunk": args.chunk,
            "seed": args.seed,
            "target_payload_bytes": size,
        },
        "environment": {
            "python": platform.python_version(),
            "implementation": platform.python_implementation(),
            "platform": platform.platform(),
            "machine": platform.machine(),
            "packages": {d: _version(d) for d in packages},
        },
        "stacks": results,
        "skipped": skipped,
        "ratios": ratios,
    }
    Path(args.json).write_text(json.dumps(doc, indent=2) + "\n")


if __name__ == "__main__":
    try:
        sys.exit(main())
    except BenchmarkError as exc:
        print(f"BENCHMARK INVALID: {exc}", file=sys.stderr)
        sys.exit(1)
