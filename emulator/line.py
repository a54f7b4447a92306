"""One direction of the serial line: baud-rate pacing, latency and injected faults.

Every byte occupies the transmitter for 10 bit times (8N1) at the configured baud; it becomes
readable at the far end `latency_us` after its stop bit (a USB-serial adapter's latency). Time is
kept exactly, in units of 1/baud microseconds, so pacing never drifts.

Faults, drawn from this direction's own seeded random stream when the byte is sent:

* bit flips: each of the 8 data bits flips with probability `bitflip` (per bit);
* drops: the byte is lost with probability `drop` (per byte);
* insertions: a random byte follows it with probability `insert` (per byte);
* noise bursts: during a window, bits flip with probability `ber` and random bytes appear on an
  otherwise idle line (about one byte in four byte times);
* a cut: bytes sent, and bytes still in flight, are lost until the line is restored.

Each fault is counted in `stats` and reported through `log(kind, detail)` with its virtual time.
"""

from __future__ import annotations

import bisect
import random
from collections import deque
from collections.abc import Callable
from dataclasses import dataclass

from emulator.truth import LineTruth

_BITS_PER_BYTE = 10  # start + 8 data + stop


@dataclass(slots=True)
class LineStats:
    bytes_sent: int = 0
    bytes_delivered: int = 0
    bits_flipped: int = 0
    bytes_dropped: int = 0
    bytes_inserted: int = 0
    bytes_lost_cut: int = 0
    noise_bytes: int = 0


class Line:
    def __init__(
        self,
        name: str,
        baud: int,
        latency_us: int,
        *,
        rng: random.Random,
        log: Callable[[int, str, str], None],
        jitter_us: int = 0,
    ) -> None:
        self.name = name
        self.baud = baud
        self.latency_us = latency_us
        self.jitter_us = jitter_us
        self.bitflip = 0.0
        self.drop = 0.0
        self.insert = 0.0
        self.cut = False
        self.stats = LineStats()
        self._rng = rng
        self._log = log
        self._tx_free = 0  # transmitter free again at this time, in 1/baud us
        self._last_arrival = 0
        # (arrival_us, tx_start_us, byte), in arrival order
        self._queue: deque[tuple[int, int, int]] = deque()
        self._noise: list[tuple[int, int]] = []  # (arrival_us, byte), sorted
        self._bursts: list[tuple[int, int, float]] = []  # (start_us, end_us, bit error rate)
        self._sent_index = 0

    @property
    def byte_time_us(self) -> float:
        return _BITS_PER_BYTE * 1_000_000 / self.baud

    def send(self, data: bytes, now_us: int) -> list[int]:
        """Queue `data` for transmission from `now_us`; returns the arrival times at which the far
        end should look (each delimiter's, and the last byte's)."""
        baud = self.baud
        unit = _BITS_PER_BYTE * 1_000_000
        tx = max(now_us * baud, self._tx_free)
        wake: list[int] = []
        rng = self._rng
        stats = self.stats
        for sent in data:
            start_us = tx // baud
            tx += unit
            end_us = -(-tx // baud)
            stats.bytes_sent += 1
            self._sent_index += 1
            arrival = end_us + self.latency_us
            if self.jitter_us:
                arrival += rng.randint(0, self.jitter_us)
            arrival = max(arrival, self._last_arrival)
            if self.cut:
                stats.bytes_lost_cut += 1
                continue
            if self.drop and rng.random() < self.drop:
                stats.bytes_dropped += 1
                self._log(start_us, "drop", f"{self.name} byte #{self._sent_index} 0x{sent:02X} dropped")
                continue
            byte = self._flip(sent, start_us, end_us)
            self._last_arrival = arrival
            self._queue.append((arrival, start_us, byte))
            if byte == 0:
                wake.append(arrival)
            if self.insert and rng.random() < self.insert:
                extra = rng.randrange(256)
                stats.bytes_inserted += 1
                self._log(start_us, "insert", f"{self.name} byte 0x{extra:02X} inserted after #{self._sent_index}")
                self._queue.append((arrival, start_us, extra))
                if extra == 0:
                    wake.append(arrival)
        self._tx_free = tx
        if self._queue:
            wake.append(self._queue[-1][0])
        return wake

    def _flip(self, byte: int, start_us: int, end_us: int) -> int:
        p = self.bitflip
        for b_start, b_end, ber in self._bursts:
            if start_us < b_end and end_us > b_start:
                p = max(p, ber)
        if not p:
            return byte
        rng = self._rng
        for bit in range(8):
            if rng.random() < p:
                byte ^= 1 << bit
                self.stats.bits_flipped += 1
                self._log(start_us, "bitflip", f"{self.name} byte #{self._sent_index} bit {bit}")
        return byte

    def receive(self, now_us: int) -> bytes:
        """Every byte that has arrived by `now_us`, in arrival order."""
        return bytes(b for _, b in self.receive_timed(now_us))

    def receive_timed(self, now_us: int) -> list[tuple[int, int]]:
        """(arrival_us, byte) of every byte that has arrived by `now_us`."""
        out: list[tuple[int, int]] = []
        queue = self._queue
        while queue and queue[0][0] <= now_us:
            arrival, _, byte = queue.popleft()
            out.append((arrival, byte))
        if self._noise and self._noise[0][0] <= now_us:
            cut = bisect.bisect_right(self._noise, (now_us, 256))
            noise, self._noise = self._noise[:cut], self._noise[cut:]
            out = sorted(out + noise, key=lambda item: item[0]) if out else noise
        self.stats.bytes_delivered += len(out)
        return out

    def pending(self) -> int:
        return len(self._queue) + len(self._noise)

    def set_cut(self, cut: bool, now_us: int) -> None:
        if cut and not self.cut:
            lost = sum(1 for arrival, _, _ in self._queue if arrival > now_us)
            self.stats.bytes_lost_cut += lost
            self._queue = deque(item for item in self._queue if item[0] <= now_us)
            self._noise = [item for item in self._noise if item[0] <= now_us]
            self._last_arrival = min(self._last_arrival, now_us)  # lost bytes hold nothing back
        self.cut = cut

    def abort_unsent(self, now_us: int) -> int:
        """The sender was reset: bytes it had not started to transmit are gone. Returns how many."""
        keep = deque(item for item in self._queue if item[1] < now_us)
        lost = len(self._queue) - len(keep)
        self._queue = keep
        # The transmitter is free once the byte it is sending now (if any) has left.
        busy_until_us = keep[-1][0] - self.latency_us if keep else now_us
        self._tx_free = min(self._tx_free, max(now_us, busy_until_us) * self.baud)
        self._last_arrival = keep[-1][0] if keep else min(self._last_arrival, now_us)
        return lost

    def noise_burst(self, start_us: int, end_us: int, ber: float) -> int:
        """Corrupt bytes in [start, end) and put random bytes on the line; returns end_us."""
        self._bursts.append((start_us, end_us, ber))
        rng = self._rng
        count = int((end_us - start_us) / self.byte_time_us / 4)
        noise = sorted((start_us + rng.randrange(max(1, end_us - start_us)), rng.randrange(256)) for _ in range(count))
        if not self.cut:
            self._noise = sorted(self._noise + [(t + self.latency_us, b) for t, b in noise])
            self.stats.noise_bytes += len(noise)
        self._log(start_us, "noise", f"{self.name} burst {start_us}..{end_us} us, ber {ber}, {len(noise)} noise bytes")
        return end_us + self.latency_us

    def truth(self) -> LineTruth:
        s = self.stats
        return LineTruth(
            bytes_sent=s.bytes_sent,
            bytes_delivered=s.bytes_delivered,
            bits_flipped=s.bits_flipped,
            bytes_dropped=s.bytes_dropped,
            bytes_inserted=s.bytes_inserted,
            bytes_lost_cut=s.bytes_lost_cut,
            noise_bytes=s.noise_bytes,
            cut=self.cut,
            in_flight=self.pending(),
        )
