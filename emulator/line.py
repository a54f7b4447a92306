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

`SerialLink` is both directions together, plus what the USB-serial adapter shows the host around an
MCU reset (the bootloader's garbage, the break when the sketch's UART starts). The Python emulator
and the firmware-in-the-loop backends (emulator/backends/simavr/) share it, so a fault spec or a
DTR reset looks the same to the host on either.
"""

from __future__ import annotations

import bisect
import random
from collections import deque
from collections.abc import Callable
from dataclasses import dataclass

from emulator.errors import EmulatorValueError
from emulator.rng import Streams
from emulator.truth import LineTruth

_BITS_PER_BYTE = 10  # start + 8 data + stop
BREAK = b"\x00"
"""What the adapter reads when the sketch's Serial.begin() drives TX high after it floated through
the reset: a break, received as 0x00 (it also ends any garbage as a chunk of its own)."""


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
            self._put(sent, start_us, end_us, max(arrival, self._last_arrival), wake)
        self._tx_free = tx
        if self._queue:
            wake.append(self._queue[-1][0])
        return wake

    def send_paced(self, data: bytes, end_us: int) -> None:
        """Bytes the sender's UART has already paced, all on the line by `end_us` (a simulated MCU
        reports what it sent once per step): each arrives `latency_us` after `end_us`, with this
        direction's faults, without being paced a second time."""
        self.stats.bytes_sent += len(data)
        start_us = max(0, end_us - round(self.byte_time_us))
        arrival = max(end_us + self.latency_us, self._last_arrival)
        for sent in data:
            self._sent_index += 1
            self._put(sent, start_us, end_us, arrival, [])
        self._tx_free = max(self._tx_free, end_us * self.baud)

    def _put(self, sent: int, start_us: int, end_us: int, arrival: int, wake: list[int]) -> None:
        """One byte onto the line at `arrival`, through the cut, drop, flip and insert faults."""
        stats = self.stats
        rng = self._rng
        if self.cut:
            stats.bytes_lost_cut += 1
            return
        if self.drop and rng.random() < self.drop:
            stats.bytes_dropped += 1
            self._log(start_us, "drop", f"{self.name} byte #{self._sent_index} 0x{sent:02X} dropped")
            return
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

    def backlog_us(self, now_us: int) -> int:
        """How long the transmitter is still busy with bytes already queued (0: idle)."""
        return max(0, -(-self._tx_free // self.baud) - now_us)

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


class SerialLink:
    """Both directions of the line between the host and the MCU (each with its own seeded stream),
    and the host's view of MCU resets."""

    def __init__(
        self,
        streams: Streams,
        baud: int,
        latency_us: int,
        *,
        log: Callable[[int, str, str], None],
        jitter_us: int = 0,
    ) -> None:
        self.h2m = Line("h2m", baud, latency_us, rng=streams.get("line:h2m"), log=log, jitter_us=jitter_us)
        self.m2h = Line("m2h", baud, latency_us, rng=streams.get("line:m2h"), log=log, jitter_us=jitter_us)
        self._bootloader = streams.get("bootloader")
        self._log = log

    def lines(self, direction: str | None) -> list[Line]:
        """The lines a fault with this direction applies to (None or "both": both)."""
        if direction is None or direction == "both":
            return [self.h2m, self.m2h]
        if direction == "h2m":
            return [self.h2m]
        if direction == "m2h":
            return [self.m2h]
        raise EmulatorValueError("direction", direction, "'h2m', 'm2h' or 'both'")

    def mcu_reset(self, now_us: int, *, bootloader: bool) -> None:
        """The MCU went into reset: what its UART had not started to send is gone. An external or DTR
        reset runs the bootloader (a brown-out or power-on skips it, as Optiboot does): 1..4 random
        bytes reach the host 1..20 ms later."""
        self.m2h.abort_unsent(now_us)
        if bootloader:
            rng = self._bootloader
            garbage = bytes(rng.randrange(256) for _ in range(rng.randint(1, 4)))
            self.m2h.send(garbage, now_us + rng.randint(1000, 20000))
            self._log(now_us, "bootloader_garbage", garbage.hex(" "))

    def sketch_started(self, now_us: int) -> int:
        """The sketch starts: the break goes to the host; returns how many host bytes arrived while
        the MCU was not running (lost)."""
        lost = len(self.h2m.receive(now_us))
        self.m2h.send(BREAK, now_us)
        return lost
