"""Deterministic virtual clock with scheduled callbacks.

Time is an integer number of microseconds. Callbacks run in order of (time, priority, the order
they were scheduled), so two runs that schedule the same things see exactly the same order: that,
plus seeded random streams, is what makes the emulator byte-for-byte reproducible.
"""

from __future__ import annotations

import heapq
import itertools
from collections.abc import Callable

from emulator.errors import EmulatorValueError

# Priorities for events that fall on the same microsecond: the plant moves first, then bytes
# reach the MCU, then the MCU's control tick runs, then anything else.
PRIORITY_PHYSICS = 0
PRIORITY_FAULT = 1
PRIORITY_RX = 2
PRIORITY_TICK = 3
PRIORITY_OTHER = 4


class Timer:
    """Handle of a scheduled callback; `cancel()` stops it from running."""

    __slots__ = ("callback", "cancelled", "time_us")

    def __init__(self, time_us: int, callback: Callable[[], None]) -> None:
        self.time_us = time_us
        self.callback = callback
        self.cancelled = False

    def cancel(self) -> None:
        self.cancelled = True


class VirtualClock:
    """Integer-microsecond time that only moves when `advance` or `advance_to` is called."""

    def __init__(self, start_us: int = 0) -> None:
        self._now = start_us
        self._heap: list[tuple[int, int, int, Timer]] = []
        self._order = itertools.count()

    @property
    def now_us(self) -> int:
        return self._now

    def call_at(self, time_us: int, callback: Callable[[], None], priority: int = PRIORITY_OTHER) -> Timer:
        """Run `callback` when the clock reaches `time_us` (now, if that is in the past)."""
        timer = Timer(max(time_us, self._now), callback)
        heapq.heappush(self._heap, (timer.time_us, priority, next(self._order), timer))
        return timer

    def call_later(self, delay_us: int, callback: Callable[[], None], priority: int = PRIORITY_OTHER) -> Timer:
        return self.call_at(self._now + delay_us, callback, priority)

    def next_event_us(self) -> int | None:
        """Time of the next pending callback, or None."""
        heap = self._heap
        while heap and heap[0][3].cancelled:
            heapq.heappop(heap)
        return heap[0][0] if heap else None

    def advance_to(self, time_us: int) -> None:
        """Run every callback due up to and including `time_us`, in order, then set now to it."""
        if time_us < self._now:
            raise EmulatorValueError("time_us", time_us, f"not before now ({self._now} us)")
        heap = self._heap
        pop = heapq.heappop
        while heap and heap[0][0] <= time_us:
            when, _, _, timer = pop(heap)
            if timer.cancelled:
                continue
            self._now = when
            timer.callback()
        self._now = time_us

    def advance(self, delta_us: int) -> None:
        if delta_us < 0:
            raise EmulatorValueError("delta_us", delta_us, "an integer >= 0")
        self.advance_to(self._now + delta_us)
