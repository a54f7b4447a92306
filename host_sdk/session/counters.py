"""The link's counters (every part of the session counts what it sends and hears here) and the
LinkStatistics snapshot made of them."""

from __future__ import annotations

from collections import deque
from dataclasses import dataclass, field, fields

from host_sdk.framing import DecoderStats
from host_sdk.session.types import LinkStatistics, RttStats
from host_sdk.timesync import ClockSync
from protocol.generated.structs import DECODER_COUNTERS


@dataclass(slots=True)
class HostCounters:
    """The host's own counts, under LinkStatistics' names."""

    frames_sent: int = 0
    bytes_sent: int = 0
    seq_gaps: int = 0
    feedback_received: int = 0
    setpoints_sent: int = 0
    keepalives_sent: int = 0
    paced_late: int = 0
    hellos_sent: int = 0
    requests_sent: int = 0
    retries: int = 0
    request_timeouts: int = 0
    pings_sent: int = 0
    pongs_received: int = 0
    resets_detected: int = 0
    reconnects: int = 0
    nacks: dict[str, int] = field(default_factory=dict)
    rtts: deque[float] = field(default_factory=lambda: deque(maxlen=64))
    rtt_count: int = 0

    def counts(self) -> dict[str, int]:
        """The counts LinkStatistics reports under the same names (every int field but rtt_count)."""
        return {f.name: getattr(self, f.name) for f in fields(self) if f.name not in ("nacks", "rtts", "rtt_count")}

    def nack(self, reason: str) -> None:
        self.nacks[reason] = self.nacks.get(reason, 0) + 1

    def rtt(self, rtt_s: float) -> None:
        self.rtts.append(rtt_s)
        self.rtt_count += 1


def link_statistics(
    n: HostCounters, d: DecoderStats, clock: ClockSync, now: float, connect_time_s: float | None
) -> LinkStatistics:
    """The snapshot of the host's counts `n`, the decoder's counts `d` and the time sync at `now`."""
    rtt = None
    if n.rtts:
        rtts = list(n.rtts)
        rtt = RttStats(rtts[-1], min(rtts), sum(rtts) / len(rtts), max(rtts), n.rtt_count)
    return LinkStatistics(
        **{name: getattr(d, name) for name in DECODER_COUNTERS},
        **n.counts(),
        bytes_received=d.bytes_received,
        nacks=dict(n.nacks),
        rtt=rtt,
        clock_offset_us=clock.offset_us(now) if clock.synced else None,
        clock_drift_ppm=clock.drift_ppm if clock.samples >= 2 else None,
        connect_time_s=connect_time_s,
    )
