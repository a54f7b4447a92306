"""Driving a Textual app under test from its pilot.

The Textual tests serve their board from another process (tests.support.emulate): Textual's pilot
waits until the process is idle, and an in-process emulator on the wall clock keeps the test's own
process busy.
"""

from __future__ import annotations

from collections.abc import Callable

from tests.support.wait import wait_until_async


async def until(predicate: Callable[[], bool], pilot: object, timeout_s: float = 10.0) -> bool:
    """Let a Textual app run (its pilot pausing) until `predicate()`, at most `timeout_s`."""
    return bool(await wait_until_async(predicate, pilot.pause, timeout_s, fail=False))  # type: ignore[attr-defined]


async def hold(pilot: object, keys: tuple[str, ...], predicate: Callable[[], bool], timeout_s: float = 5.0) -> bool:
    """Press `keys` the way a held key repeats (every 50 ms) until `predicate()`, at most `timeout_s`."""

    async def press_and_pause(dt: float) -> None:
        await pilot.press(*keys)  # type: ignore[attr-defined]
        await pilot.pause(dt)  # type: ignore[attr-defined]

    return bool(await wait_until_async(predicate, press_and_pause, timeout_s, fail=False))
