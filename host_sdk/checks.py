"""Argument checks for the SDK's public calls.

Each check returns the value in the type the SDK computes with, or raises an `ArgumentTypeError`
(a TypeError: not a number, a bool where a number goes...) or a `CommandRangeError` (a ValueError:
NaN, infinity, out of range) that names the argument, the value and what is allowed. `bool` is an
`int` to Python but never a number here: `drive(True, 0)` is a bug, not 1 m/s.

A number is any `numbers.Real` (int, float, Fraction, and numpy's integer and floating scalars such
as `numpy.float32(0.2)`, which numpy registers there), so numpy is never imported for the check;
complex numbers, strings and bools (numpy's too) are refused.
"""

from __future__ import annotations

import math
import numbers
import operator
from collections.abc import Callable, Iterable
from typing import Any, TypeVar

from host_sdk.errors import ArgumentTypeError, CommandRangeError

T = TypeVar("T")

MAX_WAIT_S = 86_400.0
"""Longest wait any call accepts (a day): a longer timeout is a unit mistake, not a wish."""


def _fmt(x: float) -> str:
    return f"{x:g}" if abs(x) < 1e15 else f"{x:.3e}"


def number(
    name: str,
    value: object,
    lo: float = -math.inf,
    hi: float = math.inf,
    *,
    unit: str = "",
    lo_open: bool = False,
    hi_open: bool = False,
    error: type[CommandRangeError] = CommandRangeError,
) -> float:
    """A finite real number in lo..hi (an end excluded when `lo_open`/`hi_open`)."""
    # numpy.bool_ is no numbers.Real; Python's bool is (an int), so it is refused by name.
    if not isinstance(value, numbers.Real) or isinstance(value, bool):
        raise ArgumentTypeError(name, value, _range_text(lo, hi, unit, lo_open, hi_open))
    try:
        x = float(value)
    except OverflowError:  # an int beyond any float
        raise error(name, value, _range_text(lo, hi, unit, lo_open, hi_open)) from None
    if not (lo < x < hi or (x == lo and not lo_open) or (x == hi and not hi_open)) or not math.isfinite(x):
        raise error(name, value, _range_text(lo, hi, unit, lo_open, hi_open))
    return x


def _range_text(lo: float, hi: float, unit: str, lo_open: bool, hi_open: bool = False) -> str:
    u = f" {unit}" if unit else ""
    lo_op, hi_op = (">" if lo_open else ">="), ("<" if hi_open else "<=")
    if lo == -math.inf and hi == math.inf:
        return "a finite number (not NaN or infinity)"
    if hi == math.inf:
        return f"a finite number {lo_op} {_fmt(lo)}{u}"
    if lo == -math.inf:
        return f"a finite number {hi_op} {_fmt(hi)}{u}"
    if lo_open or hi_open:
        return f"a finite number {lo_op} {_fmt(lo)} and {hi_op} {_fmt(hi)}{u}"
    return f"a finite number in {_fmt(lo)}..{_fmt(hi)}{u}"


def seconds(name: str, value: object, *, zero: bool = False, hi: float = MAX_WAIT_S) -> float:
    """A duration in seconds: > 0 (>= 0 with `zero`) and at most `hi`."""
    return number(name, value, 0.0, hi, unit="s", lo_open=not zero)


def integer(name: str, value: object, lo: int, hi: int, *, what: str = "an integer") -> int:
    """An integer (an int or a numpy integer; not a bool, not a float) in lo..hi, as an int."""
    if not isinstance(value, numbers.Integral) or isinstance(value, bool):
        raise ArgumentTypeError(name, value, f"{what} in {lo}..{hi}")
    n = operator.index(value)
    if not lo <= n <= hi:
        raise CommandRangeError(name, value, f"{what} in {lo}..{hi}")
    return n


def flag(name: str, value: object) -> bool:
    """True or False (not 0/1, not a string)."""
    if not isinstance(value, bool):
        raise ArgumentTypeError(name, value, "True or False")
    return value


def optional(check: Callable[..., T], name: str, value: object, *args: Any, **kwargs: Any) -> T | None:
    """None, or what `check` accepts."""
    return None if value is None else check(name, value, *args, **kwargs)


def callback(name: str, value: object) -> Callable[..., Any]:
    """Something callable."""
    if not callable(value):
        raise ArgumentTypeError(name, value, "a callable (a function, method or lambda)")
    return value


def text(name: str, value: object, *, allowed: str = "a non-empty str") -> str:
    """A non-empty str."""
    if not isinstance(value, str):
        raise ArgumentTypeError(name, value, allowed)
    if not value:
        raise CommandRangeError(name, value, allowed)
    return value


def choice(name: str, value: object, choices: Iterable[str]) -> str:
    """One of `choices` (strings)."""
    options = list(choices)
    allowed = "one of " + ", ".join(repr(c) for c in options)
    if not isinstance(value, str):
        raise ArgumentTypeError(name, value, allowed)
    if value not in options:
        raise CommandRangeError(name, value, allowed)
    return value


def instance(name: str, value: object, kinds: type[T] | tuple[type[T], ...], allowed: str) -> T:
    """An instance of `kinds`."""
    if not isinstance(value, kinds):
        raise ArgumentTypeError(name, value, allowed)
    return value
