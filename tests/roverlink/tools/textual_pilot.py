"""Driving a Textual app under test from its pilot.

The Textual tests serve their board from another process (tests.support.emulate): Textual's pilot
waits until the process is idle, and an in-process emulator on the wall clock keeps the test's own
process busy.
"""

from __future__ import annotations

import time
from collections.abc import Callable


async def until(predicate: Callable[[], bool], pilot: object, timeout_s: float = 10.0) -> bool:
    """Let a Textual app run (its pilot pausing) until `predicate()`, at most `timeout_s`."""
    deadline = time.monotonic() + timeout_s
    while not predicate():
        if time.monotonic() > deadline:
            return False
        await pilot.pause(0.05)  # type: ignore[attr-defined]
    return True
