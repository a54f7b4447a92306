"""What the lidar drivers deliver: whole revolutions with a timestamp on every point.

A `LidarScan` is in the sensor's own frame, REP-103 style: angles in radians counter-clockwise
from the sensor's front (the devices count clockwise; the drivers convert), ranges in metres with
NaN where the device reported no return. A revolution takes 0.1..0.2 s and the robot moves
meanwhile, so each point has its own time (`times_s`, on the clock the driver was given: the host's
monotonic clock, or an emulator's virtual clock): fuse it with the pose at that time, not at the
scan's start.
"""

from __future__ import annotations

import itertools
import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import NDArray

from host_sdk.sensors.arrival import ArrivalClock
from protocol.sensors import LidarSpec

F64 = NDArray[np.float64]


HEALTH_STATUS = {0: "good", 1: "warning", 2: "error"}


@dataclass(frozen=True, slots=True)
class DeviceInfo:
    """Both lidars' answer to GET_INFO."""

    model: int
    """The device's model number (1 for the YDLIDAR F4)."""
    firmware: tuple[int, int]
    """major, minor."""
    hardware: int
    serial: str
    """Hex digits."""


@dataclass(frozen=True, slots=True)
class DeviceHealth:
    """Both lidars' answer to GET_HEALTH."""

    status: int
    """0 good, 1 warning, 2 error."""
    error_code: int

    @property
    def ok(self) -> bool:
        return self.status == 0

    @property
    def name(self) -> str:
        return HEALTH_STATUS.get(self.status, f"unknown ({self.status})")


@dataclass(frozen=True, slots=True, eq=False)
class RegularScan:
    """A scan on evenly spaced angles, the shape of a ROS `sensor_msgs/LaserScan`."""

    angle_min: float
    angle_increment: float
    """Radians between bins (counter-clockwise); bin i is at angle_min + i * angle_increment."""
    ranges_m: F64
    """The nearest return in each bin; NaN where the bin has none."""
    intensities: F64
    time_s: float
    """Time of the first measurement."""
    scan_time_s: float
    time_increment_s: float
    """Time between consecutive bins as measured (negative: the device turns clockwise, so
    increasing angles were measured earlier)."""
    range_min_m: float
    range_max_m: float


@dataclass(frozen=True, slots=True, eq=False)
class LidarScan:
    device: str
    """rplidar-a1 or ydlidar-f4."""
    index: int
    """Revolutions completed since the driver started (0 first)."""
    angles_rad: F64
    ranges_m: F64
    """NaN: no return (too near, too far, too dark, glancing)."""
    qualities: NDArray[np.int64]
    """Return strength as the device reports it (RPLIDAR 0..63; YDLIDAR F4: none, 0)."""
    times_s: F64
    """When each point's bytes arrived, spread back over the read by the device's sample period
    (what the autonomy code is tuned on)."""
    range_min_m: float
    range_max_m: float
    measured_s: F64 | None = None
    """When each point was measured: `times_s` less the transport delay, timed as a steady stream
    (host_sdk.sensors.arrival); None where the scan was built without it (then `times_s`)."""

    def __len__(self) -> int:
        return int(self.angles_rad.shape[0])

    @property
    def time_s(self) -> float:
        """Time of the first point."""
        return float(self.times_s[0]) if len(self) else math.nan

    @property
    def duration_s(self) -> float:
        return float(self.times_s[-1] - self.times_s[0]) if len(self) > 1 else 0.0

    @property
    def measurement_times_s(self) -> F64:
        """`measured_s`, or `times_s` where there is none."""
        return self.times_s if self.measured_s is None else self.measured_s

    @property
    def valid(self) -> NDArray[np.bool_]:
        return np.isfinite(self.ranges_m)

    def regular(self, bins: int = 360) -> RegularScan:
        """The scan binned on `bins` evenly spaced angles from -pi (for a LaserScan message)."""
        if bins < 1:
            raise ValueError(f"bins = {bins} is not allowed: a whole number >= 1")
        inc = 2 * math.pi / bins
        idx = np.floor((self.angles_rad + math.pi) / inc).astype(np.int64) % bins
        ranges = np.full(bins, np.inf)
        ok = self.valid
        np.minimum.at(ranges, idx[ok], self.ranges_m[ok])
        intensities = np.zeros(bins)
        np.maximum.at(intensities, idx[ok], self.qualities[ok].astype(np.float64))
        duration = self.duration_s * len(self) / max(1, len(self) - 1)
        turning = float(np.mean(np.angle(np.exp(1j * np.diff(self.angles_rad))))) if len(self) > 1 else 0.0
        step = duration / bins
        return RegularScan(
            angle_min=-math.pi,
            angle_increment=inc,
            ranges_m=np.where(np.isfinite(ranges), ranges, np.nan),
            intensities=intensities,
            time_s=self.time_s,
            scan_time_s=duration,
            time_increment_s=-step if turning < 0 else step,
            range_min_m=self.range_min_m,
            range_max_m=self.range_max_m,
        )

    def points_xy(self) -> tuple[F64, F64]:
        """Cartesian points (x forward, y left) of the valid returns, in the sensor frame."""
        ok = self.valid
        r, a = self.ranges_m[ok], self.angles_rad[ok]
        return r * np.cos(a), r * np.sin(a)


@dataclass(slots=True)
class LidarCounters:
    """What a lidar parser has seen; garbage is counted, never raised."""

    bytes_received: int = 0
    bytes_discarded: int = 0
    """Bytes skipped while looking for the next descriptor, node or packet."""
    framing_errors: int = 0
    """Nodes or packets whose fixed bits or lengths were wrong."""
    checksum_errors: int = 0
    descriptors: int = 0
    points: int = 0
    scans: int = 0
    partial_scans: int = 0
    """Points before the first revolution start (dropped: the scan was not whole)."""


@dataclass(slots=True)
class ScanAssembler:
    """Collects points into revolutions, cut at each start-of-revolution flag."""

    device: str
    clockwise: bool
    range_min_m: float
    range_max_m: float
    _angles: list[F64] = field(default_factory=list)
    _ranges: list[F64] = field(default_factory=list)
    _quality: list[NDArray[np.int64]] = field(default_factory=list)
    _times: list[F64] = field(default_factory=list)
    _measured: list[F64] = field(default_factory=list)
    _started: bool = False
    scans: int = 0
    partial: int = 0

    def add(
        self,
        angle_deg: F64,
        range_mm: F64,
        quality: NDArray[np.int64],
        times: F64,
        start: NDArray[np.bool_],
        *,
        measured: F64 | None = None,
    ) -> list[LidarScan]:
        """Points in arrival order; returns the revolutions they complete."""
        out: list[LidarScan] = []
        cuts = set(np.flatnonzero(start).tolist())
        bounds = sorted({0, angle_deg.shape[0], *cuts})
        for lo, hi in itertools.pairwise(bounds):
            if lo in cuts:
                scan = self._finish()
                if scan is not None:
                    out.append(scan)
                self._started = True
            if not self._started:
                self.partial += hi - lo
                continue
            self._angles.append(angle_deg[lo:hi])
            self._ranges.append(range_mm[lo:hi])
            self._quality.append(quality[lo:hi])
            self._times.append(times[lo:hi])
            self._measured.append((times if measured is None else measured)[lo:hi])
        return out

    def _finish(self) -> LidarScan | None:
        if not self._angles:
            return None
        deg = np.concatenate(self._angles)
        mm = np.concatenate(self._ranges)
        rad = np.radians(-deg if self.clockwise else deg)
        rad = (rad + np.pi) % (2 * np.pi) - np.pi
        metres = np.where(mm > 0, mm / 1000.0, np.nan)
        scan = LidarScan(
            device=self.device,
            index=self.scans,
            angles_rad=rad,
            ranges_m=metres,
            qualities=np.concatenate(self._quality),
            times_s=np.concatenate(self._times),
            range_min_m=self.range_min_m,
            range_max_m=self.range_max_m,
            measured_s=np.concatenate(self._measured),
        )
        self.scans += 1
        self._angles, self._ranges, self._quality, self._times, self._measured = [], [], [], [], []
        return scan


def point_times(t_s: float, count: int, period_s: float) -> F64:
    """Times of `count` points that finished arriving at `t_s`, measured `period_s` apart."""
    return t_s - period_s * np.arange(count - 1, -1, -1, dtype=np.float64)


class LidarParserBase:
    """What the RPLIDAR and YDLIDAR parsers share: the buffer, the answer being read, whether a
    scan stream is on, the counters, the events, and the revolutions being assembled."""

    def __init__(self, spec: LidarSpec) -> None:
        self.spec = spec
        self.counters = LidarCounters()
        self.sample_period_s = 1.0 / spec.sample_rate_hz
        """Time between samples (the datasheet's, until the device says otherwise)."""
        self._buf = bytearray()
        self._answer: tuple[int, int] | None = None  # (type, length) of a single answer being read
        self._streaming = False
        self._events: list[Any] = []
        self._scans = ScanAssembler(spec.name, spec.clockwise, spec.range_min_m, spec.range_max_m)
        self.arrival = ArrivalClock(self.sample_period_s, spec.baud)
        """Measurement times of the points (their `times_s` are arrival-based)."""

    @property
    def scanning(self) -> bool:
        """True once a scan's answer arrived (or `expect_scan()`): samples are expected."""
        return self._streaming

    def expect_scan(self) -> None:
        """The host just asked for a scan: take samples even if the answer's descriptor is lost."""
        self._streaming = True

    def reset(self) -> None:
        """Forget the stream (after a stop or a reset, before the next request)."""
        self._buf.clear()
        self._answer = None
        self._streaming = False
        self.arrival.reset()

    def events(self) -> list[Any]:
        """The events parsed so far (each returned once)."""
        out, self._events = self._events, []
        return out

    def next_event(self) -> Any:
        return self._events.pop(0) if self._events else None

    def _take_answer(self) -> bool:
        """The single answer being read, handed to `_single` once all its bytes are in (False until
        they are)."""
        assert self._answer is not None
        type_, length = self._answer
        if len(self._buf) < length:
            return False
        self._single(type_, bytes(self._buf[:length]))
        del self._buf[:length]
        self._answer = None
        return True

    def _single(self, type_: int, body: bytes) -> None:
        """A single answer (device info, health...) of the device's protocol: its events."""
        raise NotImplementedError

    def _points(
        self,
        angle: F64,
        dist_mm: F64,
        quality: NDArray[np.int64],
        times: F64,
        start: NDArray[np.bool_],
        *,
        measured: F64,
    ) -> None:
        self.counters.points += angle.shape[0]
        scans = self._scans.add(angle, dist_mm, quality, times, start, measured=measured)
        self.counters.scans += len(scans)
        self.counters.partial_scans = self._scans.partial
        self._events.extend(scans)

    def _discard(self, n: int) -> None:
        if n > 0:
            del self._buf[:n]
            self.counters.bytes_discarded += n
            self.arrival.reset()  # bytes lost: the sample count no longer maps to time
