"""RoverLink in the codec benchmark: ``encode_frame`` and ``FrameDecoder`` of the working tree, on
``Feedback`` (or the largest all-numeric fixed-size message, or the one asked for)."""

from __future__ import annotations

import argparse
import dataclasses
import enum
import importlib
import math
import random
import sys
import types
import typing
from collections.abc import Callable
from pathlib import Path
from typing import Any

from .common import BenchmarkError, Case, Skip, Stack, chunks, expect, expect_count, fail

REPO_ROOT = Path(__file__).resolve().parents[2]
MAX_ROVERLINK_PAYLOAD = 64
# What the codec raises for values outside the message's ranges (or a seq too wide).
REJECTED = (ValueError, TypeError, OverflowError)

# Per init field, in order: its type, its array length (None: unknown) and its int bounds.
Plan = list[tuple[Any, int | None, tuple[int, int]]]


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
            fail(f"no RoverLink message {name!r}")
        chosen = by_name[name or "Feedback"]
        if not isinstance(getattr(chosen, "PAYLOAD_SIZE", None), int):
            fail(f"{chosen.__name__} has no fixed PAYLOAD_SIZE")
        return chosen
    fixed = [
        c
        for c in classes
        if isinstance(getattr(c, "PAYLOAD_SIZE", None), int)
        and c.PAYLOAD_SIZE <= MAX_ROVERLINK_PAYLOAD
        and all(_is_numeric(t) for t in _field_types(c).values())
    ]
    if not fixed:
        fail("no RoverLink message with a fixed numeric payload <= 64 B")
    return max(fixed, key=lambda c: c.PAYLOAD_SIZE)


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
    encode_frame = framing.encode_frame
    cls = choose_roverlink_message(messages, args.roverlink_message)
    values, stream, mode, seq_mod = _reference_frames(cls, encode_frame, n, args.seed + 2)
    stack = Stack(
        key="roverlink",
        label="RoverLink",
        message=f"{cls.__name__} (MSG_ID {getattr(cls, 'MSG_ID', '?')})",
        payload_bytes=int(cls.PAYLOAD_SIZE),
        wire_bytes_per_frame=len(stream) / n,
        cases=[
            _encode_case(cls, encode_frame, values, stream, seq_mod),
            _decode_case(framing.FrameDecoder, chunks(stream, args.chunk), [cls(*v) for v in values], seq_mod),
        ],
        notes=[f"field values: {mode}; seq modulo {seq_mod}"],
    )
    return stack, cls


def _value_plan(cls: Any) -> Plan:
    hints = _field_types(cls)
    infos = {fi.name: fi for fi in getattr(cls, "FIELDS", ())}  # optional metadata
    return [
        (
            hints[f.name],
            _array_len(f, infos.get(f.name)),
            _int_bounds(infos.get(f.name)),
        )
        for f in dataclasses.fields(cls)
        if f.init
    ]


def _reference_frames(
    cls: Any, encode_frame: Callable[[Any, int], bytes], n: int, seed: int
) -> tuple[list[Any], bytes, str, int]:
    """N frames' field values, their stream, how the values were made and the seq modulus.

    Random values first; if the codec rejects them (ranges may be unknown),
    all-1 values. Unknown array lengths are probed from 1 up on a few frames."""
    plan = _value_plan(cls)

    def build(rng: random.Random | None, length: int, count: int, seq_mod: int) -> tuple[list[Any], bytes]:
        vals = [tuple(_value_for(tp, rng, alen or length, bnd) for tp, alen, bnd in plan) for _ in range(count)]
        return vals, b"".join(encode_frame(cls(*v), i % seq_mod) for i, v in enumerate(vals))

    def seq_modulus(vals: tuple[Any, ...]) -> int:
        # 8-bit seq expected; probe downwards in case it is narrower.
        for m in (256, 128, 64, 16, 8):
            try:
                encode_frame(cls(*vals), m - 1)
                return m
            except REJECTED:
                continue
        return 1

    def unknown_len(tp: Any, alen: int | None) -> bool:
        tp = _strip_optional(tp)
        return alen is None and (tp in (bytes, str) or Ellipsis in typing.get_args(tp))

    variable = any(unknown_len(tp, alen) for tp, alen, _ in plan)
    lengths = range(1, cls.PAYLOAD_SIZE + 2) if variable else [1]
    for rng, mode in ((random.Random(seed), "random"), (None, "all-1 fallback")):
        for length in lengths:
            try:
                probe, _ = build(rng, length, 8, 1)
                seq_mod = seq_modulus(probe[0])
                values, stream = build(rng, length, n, seq_mod)
                return values, stream, mode, seq_mod
            except REJECTED:
                continue
    fail(f"cannot build valid {cls.__name__} instances; try --roverlink-message")


def _encode_case(
    cls: Any, encode_frame: Callable[[Any, int], bytes], values: list[Any], stream: bytes, seq_mod: int
) -> Case:
    def prepare() -> Callable[[], list[bytes]]:
        def run() -> list[bytes]:
            out: list[bytes] = []
            append = out.append
            for i, vals in enumerate(values):
                append(encode_frame(cls(*vals), i % seq_mod))
            return out

        return run

    def check(out: list[bytes]) -> None:
        expect_count("RoverLink", "encode", len(out), len(values))
        expect(b"".join(out) == stream, "RoverLink encode: bytes differ from reference")
        expect(
            all(f.endswith(b"\x00") for f in out),
            "RoverLink encode: frame not 0x00-terminated",
        )

    return Case("encode", prepare, check)


def _decode_case(frame_decoder: Callable[[], Any], pieces: list[bytes], originals: list[Any], seq_mod: int) -> Case:
    n = len(originals)

    def prepare() -> Callable[[], tuple[Any, list[Any]]]:
        decoder = frame_decoder()

        def run() -> tuple[Any, list[Any]]:
            out: list[Any] = []
            feed = decoder.feed
            for chunk in pieces:
                out.extend(feed(chunk))
            return decoder, out

        return run

    def check(result: tuple[Any, list[Any]]) -> None:
        decoder, items = result
        frames = [it for it in items if hasattr(it, "message")]
        expect_count("RoverLink", "decode", len(frames), n)
        stats = getattr(decoder, "stats", None)
        if stats is not None:
            expect_count("RoverLink", "decode (stats.frames_ok)", stats.frames_ok, n)
        for i, (fr, orig) in enumerate(zip(frames, originals, strict=True)):
            expect(
                fr.seq == i % seq_mod and _same(fr.message, orig),
                f"RoverLink decode: frame {i} differs from what was encoded",
            )

    return Case("decode", prepare, check)
