"""Time sync: PING/PONG round trips into a least-squares ClockSync (MCU time -> host time)."""

from __future__ import annotations

from host_sdk.session.counters import HostCounters
from host_sdk.session.options import EPS, SessionOptions
from host_sdk.session.wire import Wire
from host_sdk.timesync import ClockSync
from protocol.generated.messages import Ping, Pong


class TimeSync:
    """The PINGs in flight and when the next is due; `clock` maps MCU time to host time."""

    __slots__ = ("_n", "_next_ping", "_options", "_pings", "_wire", "clock")

    def __init__(self, options: SessionOptions, wire: Wire, counters: HostCounters) -> None:
        self._options = options
        self._wire = wire
        self._n = counters
        self.clock = ClockSync()
        self._pings: dict[int, float] = {}  # stamp sent -> host time sent
        self._next_ping = 0.0

    @property
    def next_ping(self) -> float:
        return self._next_ping

    def due(self, now: float) -> bool:
        return now >= self._next_ping - EPS

    def start(self, now: float) -> None:
        """A session opened: the first PING goes out soon."""
        self._next_ping = now + 0.02

    def postpone(self, now: float) -> None:
        """Not now (a PING would feed the board's watchdog): look again in a quarter interval."""
        self._next_ping = now + self._options.ping_interval_s / 4

    def send_ping(self, now: float) -> None:
        stamp = round(now * 1e6) & 0xFFFFFFFF
        self._pings[stamp] = now
        if len(self._pings) > 16:
            del self._pings[next(iter(self._pings))]
        self._wire.send(Ping(host_time_us=stamp), now)
        self._n.pings_sent += 1
        interval = self._options.ping_interval_s
        early = self.clock.samples < 8  # sync fast at first
        self._next_ping = now + (min(0.2, interval) if early else interval)

    def on_pong(self, msg: Pong, now: float, session_open: bool) -> None:
        """A PONG: a clock sample if it answers a PING of ours and the session is (still) open."""
        sent = self._pings.pop(msg.host_time_us, None)
        if sent is None:
            return
        self._n.pongs_received += 1
        if not session_open:
            return
        self._n.rtt(now - sent)
        self.clock.add(sent, now, msg.mcu_time_us)

    def reset(self) -> None:
        """The board rebooted: its clock starts again, PINGs in flight will not be answered."""
        self.clock.reset()
        self._pings.clear()
