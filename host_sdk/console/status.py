"""What the page shows of the robot's state: the link and arming as the supervisor knows them (its
banner, the refusals kept until dismissed, what is stale), the link's counters, and the sensors'
rates, with a sensor that stopped shown as such ("no picture for 4 s"), not as a rate of 0."""

from __future__ import annotations

import time
from typing import Any

from host_sdk.robot import Robot
from host_sdk.supervisor import Health

STALLED_S = 1.0
"""A sensor silent this long is shown as stopped."""
SILENT = {"camera": "no picture", "scans": "no scan"}


def link_view(health: Health) -> dict[str, Any]:
    """The page's `link` state: up or down since when, the banner (what happened, what to do), the
    request under way, the refusals (each with an id the page dismisses it by)."""
    banner = health.banner()
    return {
        "state": health.link,
        "stale": health.stale,
        "since": health.since_wall,
        "banner": None if banner is None else {"level": banner.level, "text": banner.text, "hint": banner.hint},
        "busy": health.busy,
        "refusals": [{"id": r.id, "text": r.line()} for r in health.refusals],
    }


class LinkLines:
    """The link's status lines: its state, the feedback rate (or how long none came), errors, round trip."""

    def __init__(self) -> None:
        self._fed: tuple[float, int] | None = None
        self._hz = 0.0

    def lines(self, robot: Robot, health: Health, now_s: float) -> dict[str, Any]:
        stats = robot.stats
        lines: dict[str, Any] = {"link": health.link if health.stale else robot.state}
        then = self._fed
        self._fed = (now_s, stats.feedback_received)
        if health.stale:
            age = robot.feedback_age_s
            lines["feedback"] = "none" if age is None else f"none for {age:.1f} s"
            self._hz = 0.0
        elif then is not None and now_s - then[0] > 0:
            self._hz = 0.8 * self._hz + 0.2 * (stats.feedback_received - then[1]) / (now_s - then[0])
            lines["feedback"] = f"{self._hz:.0f} Hz"
        lines["link errors"] = stats.crc_errors + stats.cobs_errors + stats.length_errors + stats.seq_gaps
        if stats.rtt is not None:
            lines["round trip"] = f"{stats.rtt.mean_s * 1000:.1f} ms"
        return lines


class Rate:
    """Events per second from their times (smoothed), and how long ago the last one came (the
    program's monotonic clock, whatever clock the events carry)."""

    def __init__(self) -> None:
        self.hz: float | None = None
        self._last: float | None = None
        self._seen: float | None = None

    def tick(self, t: float) -> None:
        last, self._last = self._last, t
        self._seen = time.monotonic()
        if last is not None and t > last:
            now = 1.0 / (t - last)
            self.hz = now if self.hz is None else 0.8 * self.hz + 0.2 * now

    def describe(self, name: str) -> str | None:
        """ "12.0 Hz", "no picture for 3 s" once it stopped, None before the first."""
        if self._seen is None:
            return None
        quiet = time.monotonic() - self._seen
        if quiet >= STALLED_S:
            return f"{SILENT.get(name, 'nothing')} for {quiet:.0f} s"
        return None if self.hz is None else f"{self.hz:.1f} Hz"
