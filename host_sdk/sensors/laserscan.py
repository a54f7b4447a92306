"""Revolutions as ROS `sensor_msgs/LaserScan` wants them (REP 117), with honest timing.

    scanner = LaserScanner(bins=360, clockwise=lidar.spec.clockwise)
    for scan in scanner.push(lidar.read_scan()):     # 0 or 1 (rarely 2) per revolution read
        publish(scan)                                # a LaserScanData

A LaserScan says ray i (angle `angle_min + i * angle_increment`) was measured at
`stamp + i * time_increment`. The drivers cut revolutions at the device's start flag, at its
front, which lies in the middle of a message whose angles run from -pi: such a message holds the
end of one revolution and the start of the next, and no stamp and increment describe both. So the
points are cut again at the rear, on the boundary behind bin 0 (half a bin past -pi): each
message is one revolution contiguous in time. Then:

* `time_s` (the stamp) is the measurement time of ray 0 and `time_increment_s` the signed time
  from one ray to the next, both from a least-squares line through the points' own measurement
  times (`LidarScan.measurement_times_s`) against their angles; negative for a clockwise device,
  whose ray 0 is the last measured. `scan_time_s` is the revolution's period from that line.
* Stamps strictly increase: a stamp not after the previous message's is moved just after it, but
  never more than its own period (`retimed`); a revolution that cannot be stamped both ways is
  not published (`dropped`). Each stamp starts from its own revolution's times, and a moved one
  is never the base of the next, so a revolution read late affects only those measured before
  its stamp, not the ones after.
* ranges (REP 117): the nearest return in the bin; -inf where the device reported a distance
  below `range_min_m` (too close); +inf where it measured and got no return (range 0 on the wire:
  too far, too dark, glancing) or a distance beyond `range_max_m`; NaN where no sample fell in
  the bin. Of several samples in a bin the smallest wins (-inf < a distance < +inf).

The points before the first rear cut (half a revolution) are never published: that message would
not be whole.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from host_sdk.sensors.scan import LidarScan, RegularScan

F64 = NDArray[np.float64]
MARGIN_RAD = math.radians(20)
"""A revolution is cut once the points are this far past its end: a triangulation lidar's
corrected angles (the F4's vary with range by a few degrees) straggle across the cut."""
MIN_FIT_SHARE = 0.25
"""The time line is fitted on the returns when at least this share of the points are returns."""
GAP_S = 0.05
"""Points this far apart in time were not consecutive (a revolution was lost): start afresh."""
STEP_S = 0.001
"""A stamp moved to keep the order lands this far after the one before: enough to stay in order
through a consumer's mapping to its own clock (which reads two clocks per message)."""


@dataclass(frozen=True, slots=True, eq=False)
class LaserScanData(RegularScan):
    """One rear-cut revolution on even angles: a RegularScan's fields (those of a
    `sensor_msgs/LaserScan`) with the module docstring's meaning: `ranges_m` per ray in metres,
    -inf (too close), +inf (no return, or beyond range_max) or NaN (no sample); `intensities` the
    strongest quality of the bin's returns (0: none); `time_s` when ray 0 was measured (the stamp);
    ray i measured at time_s + i * time_increment_s (negative: a clockwise device); `scan_time_s`
    the revolution's period."""

    index: int
    """Messages built so far by the scanner (0 first)."""

    def ray_times_s(self) -> F64:
        return self.time_s + self.time_increment_s * np.arange(self.ranges_m.shape[0], dtype=np.float64)


@dataclass(frozen=True, slots=True)
class _Points:
    angles: F64
    ranges: F64
    qualities: NDArray[np.int64]
    times: F64
    progress: F64
    """Unwrapped turn since the scanner's first point, radians, increasing in time."""

    def take(self, keep: NDArray[np.bool_]) -> _Points:
        return _Points(
            self.angles[keep], self.ranges[keep], self.qualities[keep], self.times[keep], self.progress[keep]
        )

    @staticmethod
    def join(a: _Points, b: _Points) -> _Points:
        return _Points(*(np.concatenate([x, y]) for x, y in zip(_fields(a), _fields(b), strict=True)))


def _fields(p: _Points) -> tuple[F64, F64, NDArray[np.int64], F64, F64]:
    return p.angles, p.ranges, p.qualities, p.times, p.progress


class LaserScanner:
    """Driver revolutions (cut at the front) in, rear-cut LaserScanData out (module docstring)."""

    def __init__(self, bins: int = 360, *, clockwise: bool) -> None:
        if bins < 8:
            raise ValueError(f"bins = {bins} is not allowed: a whole number >= 8")
        self.bins = bins
        self.sign = -1.0 if clockwise else 1.0
        self.increment = 2 * math.pi / bins
        self.cut_rad = -math.pi - self.increment / 2
        """The rear cut: the boundary behind ray 0 (rays are at the middle of their bins)."""
        self.count = 0
        self.refitted = 0
        """Revolutions whose measured times did not lie on a line at the device's rate (bursty
        reads): timed at that rate instead."""
        self.retimed = 0
        """Messages whose stamp was not after the one before: moved just after it (by at most
        their period)."""
        self.dropped = 0
        """Revolutions not published: no stamp within their period of their own time is after
        the previous message's."""
        self._last_stamp: float | None = None
        """The last published stamp: the order's floor only, never a base for the next stamp."""
        self._pending: _Points | None = None
        self._last: tuple[float, float, float] | None = None  # (angle, progress, time) of the last point
        self._done = -1  # revolutions (by progress // 2 pi) already cut off
        self.last_points: tuple[F64, NDArray[np.int64]] = (np.zeros(0), np.zeros(0, dtype=np.int64))
        """Measurement time and bin of each point of the last message (what checks its timing)."""

    @property
    def rewritten(self) -> int:
        """Revolutions not stamped as their points' times lie: refitted, retimed or dropped."""
        return self.refitted + self.retimed + self.dropped

    def reset(self) -> None:
        """The stream broke (the lidar was reopened): start afresh, dropping what was pending."""
        self._restart()
        self._last_stamp = None

    def _restart(self) -> None:
        self._pending, self._last, self._done = None, None, -1

    def push(self, scan: LidarScan) -> list[LaserScanData]:
        """A driver revolution in; the rear-cut revolutions it completes out."""
        if not len(scan):
            return []
        if self._last is not None and float(scan.measurement_times_s[0]) - self._last[2] > GAP_S:
            # Revolutions were missed: the turn count would not know how many. The order's floor
            # stays (what follows a gap is later anyway, unless the gap was a late read).
            self._restart()
        points = self._progress(scan)
        pending = points if self._pending is None else _Points.join(self._pending, points)
        turn = np.floor(pending.progress / (2 * math.pi)).astype(np.int64)
        whole = int(np.floor((float(pending.progress.max()) - MARGIN_RAD) / (2 * math.pi)))
        out = []
        for rev in range(max(int(turn.min()), self._done + 1, 0), whole):  # -1 began before the first point
            data = self._build(pending.take(turn == rev), scan)
            if data is not None:
                out.append(data)
            self._done = rev
        self._pending = pending.take(turn >= whole)
        return out

    def _progress(self, scan: LidarScan) -> _Points:
        """The points with their turn since the scanner's first point (0 at a rear cut)."""
        angles = scan.angles_rad
        times = scan.measurement_times_s
        if self._last is None:  # the first point's turn is in [-2 pi, 0): revolution -1, not whole
            start = (self.sign * (angles[0] - self.cut_rad)) % (2 * math.pi) - 2 * math.pi
            self._last = (float(angles[0]), start, float(times[0]))
        a0, p0, _ = self._last
        steps = np.diff(np.concatenate([[a0], angles]))
        steps = (steps + math.pi) % (2 * math.pi) - math.pi  # points are well under pi apart
        progress = p0 + np.cumsum(self.sign * steps)
        self._last = (float(angles[-1]), float(progress[-1]), float(times[-1]))
        return _Points(angles, scan.ranges_m, scan.qualities, times, progress)

    def _build(self, p: _Points, scan: LidarScan) -> LaserScanData | None:
        bins, inc = self.bins, self.increment
        returns = ~np.isnan(p.ranges)
        slope, intercept, on_returns = _time_line(p, returns)
        slope, intercept = self._sane_line(p, slope, intercept)
        turn = _turn(p.progress)
        if on_returns and slope != 0:
            # A no-return sample sits where the beam pointed when it was measured, by the returns'
            # clock (a triangulation lidar corrects only a return's angle: the F4's no-returns
            # would otherwise sit 4..8 degrees off the returns measured with them).
            turn = np.where(returns, turn, (p.times - intercept) / slope)
        # Bins by turn, not by angle: a point straggling across the cut stays in this revolution's
        # first or last bin rather than wrapping to the far end.
        turn0 = (self.sign * (-math.pi - self.cut_rad)) % (2 * math.pi)  # ray 0's turn
        idx = np.clip(np.rint(self.sign * (turn - turn0) / inc), 0, bins - 1).astype(np.int64)
        ranges = classify(p.ranges, scan.range_min_m, scan.range_max_m)
        out = np.full(bins, np.inf)
        np.minimum.at(out, idx, ranges)
        out[np.bincount(idx, minlength=bins) == 0] = np.nan
        intensities = np.zeros(bins)
        ok = np.isfinite(ranges)
        np.maximum.at(intensities, idx[ok], p.qualities[ok].astype(np.float64))
        scan_time = float(abs(slope) * 2 * math.pi)
        stamp = self._ordered(float(intercept + slope * turn0), scan_time)
        if stamp is None:
            return None
        self.last_points = (p.times, idx)
        data = LaserScanData(
            angle_min=-math.pi,
            angle_increment=inc,
            ranges_m=out,
            intensities=intensities,
            time_s=stamp,
            scan_time_s=scan_time,
            time_increment_s=float(slope * self.sign * inc),
            range_min_m=scan.range_min_m,
            range_max_m=scan.range_max_m,
            index=self.count,
        )
        self.count += 1
        return data

    def _ordered(self, measured: float, period: float) -> float | None:
        """The stamp of a revolution measured at `measured`: that time, or, when it is not after
        the last published stamp (which came from late reads), just after that if it is within
        `period` of `measured`; None (not published) if not."""
        stamp = measured
        if self._last_stamp is not None and measured < self._last_stamp + STEP_S:
            stamp = self._last_stamp + STEP_S
            if stamp > measured + period:
                self.dropped += 1
                return None
            self.retimed += 1
        if math.isfinite(stamp):  # a revolution without a time line must not become the floor
            self._last_stamp = stamp
        return stamp

    def _sane_line(self, p: _Points, slope: float, intercept: float) -> tuple[float, float]:
        """The fitted time line, or, when reads came in bursts late enough to bend it (a slope off
        the device's own sample spacing by more than a quarter, or backwards), the line at that
        spacing through the points' median offset."""
        times = p.times
        if times.shape[0] < 3:
            return slope, intercept
        spacing = float(np.median(np.diff(times)))
        expected = spacing * times.shape[0] / (2 * math.pi)
        if expected > 0 and 0.75 * expected <= slope <= 1.25 * expected:
            return slope, intercept
        self.refitted += 1
        turn = _turn(p.progress)
        return expected, float(np.median(times - expected * turn))


def _time_line(p: _Points, returns: NDArray[np.bool_]) -> tuple[float, float, bool]:
    """(slope s/rad, intercept s, fitted on the returns) of the points' times against their turn
    in the revolution (0 at the cut). Fitted on the returns when there are enough: a triangulation
    lidar corrects a return's angle for its range (the F4: 4..8 degrees), a no-return's it cannot,
    so the two lie on lines degrees apart, and the returns are what a consumer places in the world."""
    turn = _turn(p.progress)
    on_returns = int(returns.sum()) >= MIN_FIT_SHARE * returns.shape[0]
    use = returns if on_returns else np.ones_like(returns)
    x, t = turn[use], p.times[use]
    if x.shape[0] < 2 or float(np.ptp(x)) <= 0:
        return 0.0, float(p.times.mean()) if p.times.shape[0] else math.nan, False
    slope, intercept = np.polyfit(x, t, 1)
    return float(slope), float(intercept), on_returns


def _turn(progress: F64) -> F64:
    """Turn within the revolution: 0 at the rear cut, 2 pi at the next."""
    return progress - 2 * math.pi * np.floor(progress / (2 * math.pi))


def classify(ranges_m: F64, range_min_m: float, range_max_m: float) -> F64:
    """REP 117 per sample: a driver's NaN (no return) and beyond range_max -> +inf, below
    range_min -> -inf, the rest as measured."""
    out = np.where(np.isnan(ranges_m) | (ranges_m > range_max_m), np.inf, ranges_m)
    return np.where(out < range_min_m, -np.inf, out)
