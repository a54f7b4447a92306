"""Scan stamps the lidar's LaserScanner rewrote, for the lidar's diagnostics status.

A revolution's stamp is its own fitted measurement time unless late reads made that impossible
(host_sdk.sensors.laserscan): its time line refitted, its stamp moved after the previous one, or the
revolution dropped. Each is counted over the node's life (the scanner is made afresh at each open)
and the status is WARN while any happened in the last `WINDOW_S`: a consumer is then getting scans
whose stamps are not plain measurements.
"""

from __future__ import annotations

import dataclasses
import threading
from collections import deque
from typing import Protocol

from roverlink.ros2.diagnostics import OK, WARN, Report

WINDOW_S = 5.0
KINDS = ("refitted", "retimed", "dropped")
LABELS = {
    "refitted": "scan stamps refitted",
    "retimed": "scan stamps retimed",
    "dropped": "scans dropped (no ordered stamp)",
}


class Rewriter(Protocol):
    """LaserScanner's counters."""

    @property
    def refitted(self) -> int: ...
    @property
    def retimed(self) -> int: ...
    @property
    def dropped(self) -> int: ...


class StampRewrites:
    """Totals and recent times of a lidar's stamp rewrites (updated on its thread, read on the
    diagnostics timer's)."""

    def __init__(self, window_s: float = WINDOW_S) -> None:
        self.window_s = window_s
        self.totals = dict.fromkeys(KINDS, 0)
        self._scanner: Rewriter | None = None
        self._seen = dict.fromkeys(KINDS, 0)
        self._recent: deque[float] = deque()
        self._lock = threading.Lock()

    def update(self, scanner: Rewriter, now_s: float) -> None:
        """Take what `scanner` counted since the last update (a new scanner counts from zero)."""
        if scanner is not self._scanner:
            self._scanner, self._seen = scanner, dict.fromkeys(KINDS, 0)
        counts = {kind: int(getattr(scanner, kind)) for kind in KINDS}
        with self._lock:
            for kind in KINDS:
                added = counts[kind] - self._seen[kind]
                if added > 0:
                    self.totals[kind] += added
                    self._recent.extend([now_s] * added)
            self._seen = counts

    def recent(self, now_s: float) -> int:
        """Rewrites in the last `window_s`."""
        with self._lock:
            while self._recent and self._recent[0] <= now_s - self.window_s:
                self._recent.popleft()
            return len(self._recent)

    def apply(self, report: Report, now_s: float) -> Report:
        """The lidar's `report` with the totals as values, WARN (if it was OK) while rewrites are recent."""
        values = report.values + tuple((LABELS[kind], str(self.totals[kind])) for kind in KINDS)
        recent = self.recent(now_s)
        if not recent or report.level != OK:
            return dataclasses.replace(report, values=values)
        message = f"{report.message}; scan stamps rewritten (late reads): {recent} in the last {self.window_s:g} s"
        return dataclasses.replace(report, level=WARN, message=message, values=values)
