"""What every stack of the codec benchmark shares: the records of a stack and its timed cases,
the two errors, and helpers for values, checks and decoder input."""

from __future__ import annotations

import dataclasses
import random
import struct
import typing
from collections.abc import Callable
from typing import Any

# Used only when RoverLink is unavailable: the size of the robot's Feedback
# telemetry payload, so peer-only runs stay comparable with full runs.
DEFAULT_PAYLOAD_SIZE = 33


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


def expect(cond: bool, what: str) -> None:
    if not cond:
        raise BenchmarkError(what)


def expect_count(stack: str, op: str, got: int, want: int) -> None:
    expect(got == want, f"{stack} {op}: produced {got} frames, expected {want}")


def fail(msg: str) -> typing.NoReturn:
    raise BenchmarkError(msg)


def rand_scalar(fmt: str, rng: random.Random) -> int | float:
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


def chunks(stream: bytes, size: int) -> list[bytes]:
    if size <= 0:
        return [stream]
    return [stream[i : i + size] for i in range(0, len(stream), size)]
