"""When a lidar's samples were measured, from when their bytes arrived.

A driver knows when a read returned, not when the device measured. Between the two lie the bytes'
own time on the wire (the F4 sends a packet only once its last sample is measured: the header
carries that sample's angle and the packet's checksum), the USB-serial adapter's latency, and
however late the read returned after the bytes were in. The first two are physics and subtracted;
the last only ever makes a read late, never early. So each read bounds its samples from above
(sample k was measured at or before the read's time less the transport delay), and a steady
sample stream (sample k at t0 + k * period) is timed by the tightest of the recent bounds: the
lower envelope of the reads of the last `WINDOW_S`.
"""

from __future__ import annotations

from collections import deque

import numpy as np
from numpy.typing import NDArray

F64 = NDArray[np.float64]

ADAPTER_LATENCY_S = 0.001
"""USB-serial adapter latency (a CP210x / CH340 delivers within about 1 ms)."""
WINDOW_S = 0.1
"""Reads older than this no longer bound the newest samples (the sample period may drift)."""
BITS_PER_BYTE = 10
"""8N1: a start bit, 8 data bits, a stop bit."""


class ArrivalClock:
    """Measurement times of a steady sample stream (see the module docstring)."""

    def __init__(self, period_s: float, baud: int, latency_s: float = ADAPTER_LATENCY_S) -> None:
        self.period_s = period_s
        self.byte_s = BITS_PER_BYTE / baud
        self.latency_s = latency_s
        self._count = 0
        self._bounds: deque[tuple[int, float]] = deque()

    def reset(self) -> None:
        """The stream broke (a lost stretch, a restart): earlier reads say nothing of what follows."""
        self._bounds.clear()

    def bound(self, ahead: int, t_s: float, wire_bytes: int) -> None:
        """Sample `ahead` of the next one to be timed was measured before the first of `wire_bytes`
        bytes went on the wire, all of which had arrived by `t_s` (a read's time): at or before
        `t_s` less the latency and their wire time."""
        at = t_s - self.latency_s - wire_bytes * self.byte_s
        bounds = self._bounds
        bounds.append((self._count + ahead, at))
        while bounds and bounds[0][1] < at - WINDOW_S:
            bounds.popleft()

    def times(self, n: int) -> F64:
        """Measurement times of the next `n` samples: the tightest bound of the window, carried
        along the stream at the sample period."""
        k = np.arange(self._count, self._count + n, dtype=np.float64)
        self._count += n
        if not self._bounds:
            return np.full(n, np.nan)
        t0 = min(at - i * self.period_s for i, at in self._bounds)
        return t0 + k * self.period_s
