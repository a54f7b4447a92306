"""Waiting for a condition with a deadline: the one way the tests wait on wall time.

A test never sleeps to synchronise. It polls what it is waiting for and fails, naming it, when the
deadline passes first:

    value = wait_until(lambda: robot.feedback, what="the first FEEDBACK", timeout_s=5)
    if not wait_until(done, timeout_s=2, fail=False): ...   # a bool instead of a failure

`Deadline` is for loops that hand the time left to a blocking read (`sock.recv(timeout=...)`).
"""

from __future__ import annotations

import time
from collections.abc import Awaitable, Callable
from typing import Literal, TypeVar, overload

T = TypeVar("T")

DEFAULT_TIMEOUT_S = 10.0
DEFAULT_POLL_S = 0.01


class Deadline:
    """A point in `time.monotonic()` seconds from now."""

    def __init__(self, seconds: float) -> None:
        self.seconds = seconds
        self.at = time.monotonic() + seconds

    def remaining(self, floor: float = 0.0) -> float:
        """Seconds left, never below `floor` (a read timeout of 0 would mean "poll")."""
        return max(floor, self.at - time.monotonic())

    def expired(self) -> bool:
        return time.monotonic() >= self.at


def _timed_out(what: str, timeout_s: float, last: object) -> AssertionError:
    return AssertionError(f"timed out after {timeout_s:g} s waiting for {what} (last seen: {last!r})")


@overload
def wait_until(
    check: Callable[[], T],
    timeout_s: float = ...,
    what: str = ...,
    *,
    poll_s: float = ...,
    step: Callable[[], object] | None = ...,
    fail: Literal[True] = ...,
) -> T: ...


@overload
def wait_until(
    check: Callable[[], T],
    timeout_s: float = ...,
    what: str = ...,
    *,
    poll_s: float = ...,
    step: Callable[[], object] | None = ...,
    fail: Literal[False],
) -> T | None: ...


def wait_until(
    check: Callable[[], T],
    timeout_s: float = DEFAULT_TIMEOUT_S,
    what: str = "the condition",
    *,
    poll_s: float = DEFAULT_POLL_S,
    step: Callable[[], object] | None = None,
    fail: bool = True,
) -> T | None:
    """Call `check()` until it returns something truthy and return that.

    `step`, when given, runs between checks instead of the `poll_s` pause (pump a socket, press a
    key, drive one period). When the deadline passes first: an AssertionError naming `what`, the
    timeout and the last value seen, or None with `fail=False`.
    """
    deadline = Deadline(timeout_s)
    while True:
        value = check()
        if value:
            return value
        if deadline.expired():
            if fail:
                raise _timed_out(what, timeout_s, value)
            return None
        if step is not None:
            step()
        else:
            time.sleep(poll_s)


async def wait_until_async(
    check: Callable[[], T],
    pause: Callable[[float], Awaitable[object]],
    timeout_s: float = DEFAULT_TIMEOUT_S,
    what: str = "the condition",
    *,
    poll_s: float = 0.05,
    fail: bool = True,
) -> T | None:
    """`wait_until` for an event loop: `await pause(poll_s)` between checks (asyncio.sleep, a
    Textual pilot's pause), so the loop's own tasks run while the test waits."""
    deadline = Deadline(timeout_s)
    while True:
        value = check()
        if value:
            return value
        if deadline.expired():
            if fail:
                raise _timed_out(what, timeout_s, value)
            return None
        await pause(poll_s)
