"""MCU clock -> host clock mapping from PING/PONG exchanges.

Each exchange gives the host's send and receive times and the MCU's clock when it answered. The
MCU's reading is paired with the midpoint of the round trip, and a least-squares line through the
recent pairs gives the MCU clock's offset and drift (crystals are off by tens of ppm, which is
milliseconds per minute). Exchanges with a round trip slower than the window's median are left
out of the fit: their extra time was queueing on one leg, which makes the midpoint wrong.
"""

from __future__ import annotations

from collections import deque
from dataclasses import dataclass

from host_sdk import checks

_U32 = (1 << 32) - 1
_MAX_US = 1e18
"""Largest MCU time (us) mapped: 31,700 years of uptime; beyond it, a unit mistake."""


class Unwrapper:
    """Turns a wrapping counter (u32 microseconds, a u16 tick, i32 encoder counts) into one that
    never wraps: each reading moves the total by the shortest step modulo 2**bits, so a reading a
    little older than the last steps back instead of jumping a whole wrap forward.

    This is where the SDK unwraps every counter of the wire; everything above it sees plain ints.
    """

    __slots__ = ("_half", "_last", "_lo", "_mod", "_total")

    def __init__(self, bits: int = 32) -> None:
        checks.integer("bits", bits, 2, 64)
        self._mod = 1 << bits
        self._half = self._mod >> 1
        self._lo = -self._half  # signed readings (i32 counts) are taken too
        self._last: int | None = None
        self._total = 0

    def __call__(self, raw: int) -> int:
        """The unwrapped value of a raw reading (signed or unsigned, within the counter's bits)."""
        return self.step(checks.integer("raw", raw, self._lo, self._mod - 1))

    def step(self, raw: int) -> int:
        """`__call__` without the argument check: the session's per-frame path (wire values)."""
        last = self._last
        self._last = raw
        if last is None:
            self._total = raw
            return raw
        step = (raw - last) % self._mod
        if step >= self._half:
            step -= self._mod
        self._total += step
        return self._total


@dataclass(frozen=True, slots=True)
class SyncSample:
    host_send_s: float
    host_recv_s: float
    mcu_us: int
    """Unwrapped MCU time when it answered."""

    @property
    def rtt_s(self) -> float:
        return self.host_recv_s - self.host_send_s

    @property
    def host_mid_s(self) -> float:
        return (self.host_send_s + self.host_recv_s) / 2


class ClockSync:
    """Least-squares estimate of `mcu_us = offset_us + rate * host_us` over a window of samples."""

    def __init__(self, window: int = 32) -> None:
        checks.integer("window", window, 1, 100_000)
        self._samples: deque[SyncSample] = deque(maxlen=window)
        self._unwrap = Unwrapper()
        self._a = 0.0  # mcu_us at host time 0
        self._b = 1.0  # mcu microseconds per host microsecond

    def reset(self) -> None:
        """Forget everything (the MCU rebooted: its clock restarted)."""
        self._samples.clear()
        self._unwrap = Unwrapper()
        self._a, self._b = 0.0, 1.0

    def unwrap(self, mcu_time_us: int) -> int:
        """Unwrapped MCU time for a raw u32 reading (readings must arrive roughly in order)."""
        return self._unwrap.step(checks.integer("mcu_time_us", mcu_time_us, 0, _U32))

    def unwrap_raw(self, mcu_time_us: int) -> int:
        """`unwrap` without the argument check (the session's per-frame path: a decoded u32)."""
        return self._unwrap.step(mcu_time_us)

    def add(self, host_send_s: float, host_recv_s: float, mcu_time_us: int) -> None:
        """Record one PING/PONG exchange (host times in seconds, MCU time raw u32)."""
        send = checks.number("host_send_s", host_send_s)
        recv = checks.number("host_recv_s", host_recv_s, send, unit=f"s (not before host_send_s = {send:g})")
        self._samples.append(SyncSample(send, recv, self.unwrap(mcu_time_us)))
        self._fit()

    def _fit(self) -> None:
        rtts = sorted(s.rtt_s for s in self._samples)
        limit = rtts[(len(rtts) - 1) // 2]
        used = [s for s in self._samples if s.rtt_s <= limit]
        xs = [s.host_mid_s * 1e6 for s in used]
        ys = [float(s.mcu_us) for s in used]
        n = len(used)
        mx, my = sum(xs) / n, sum(ys) / n
        sxx = sum((x - mx) ** 2 for x in xs)
        # Drift needs a spread of samples in time; until then assume the clocks tick alike.
        b = sum((x - mx) * (y - my) for x, y in zip(xs, ys, strict=True)) / sxx if n >= 2 and sxx > 1e6 else 1.0
        self._a, self._b = my - b * mx, b

    @property
    def samples(self) -> int:
        return len(self._samples)

    @property
    def synced(self) -> bool:
        return bool(self._samples)

    @property
    def drift_ppm(self) -> float:
        """How much faster the MCU clock runs than the host's, in parts per million."""
        return (self._b - 1.0) * 1e6

    def offset_us(self, host_s: float) -> float:
        """MCU clock minus host clock at host time `host_s`, in microseconds."""
        return self._a + (self._b - 1.0) * checks.number("host_s", host_s) * 1e6

    @property
    def rtt_s(self) -> float | None:
        """Smallest round trip in the window (the best case the link offers)."""
        return min((s.rtt_s for s in self._samples), default=None)

    def to_host_s(self, mcu_us_unwrapped: float) -> float:
        """Host time (seconds, same clock as the samples) of an unwrapped MCU timestamp."""
        return (
            (checks.number("mcu_us_unwrapped", mcu_us_unwrapped, -_MAX_US, _MAX_US, unit="us") - self._a)
            / self._b
            / 1e6
        )

    def host_s_of(self, mcu_us_unwrapped: int) -> float:
        """`to_host_s` without the argument check (the session's per-frame path)."""
        return (mcu_us_unwrapped - self._a) / self._b / 1e6
