"""Lidar scan processing: whatever the scan's source, a clean 360-degree obstacle picture around the
robot's pose point.

    filt = ScanFilter(mount=LidarMount(x_m=0.18))          # where the lidar sits on the robot
    obstacles = filt.update(lidar.read_scan(), pose=(x, y, theta))   # pose: odometry at the scan
    xs, ys = obstacles.points_xy()                         # base frame: x forward, y left

Input is a driver's `LidarScan` (host_sdk.sensors), anything shaped like a ROS `LaserScan`
(`angle_min`, `angle_increment`, `ranges`, `range_min`, `range_max`), or plain arrays
(`RawScan.from_arrays`). Each revolution is binned into fixed angular bins around the pose point
(the nearest return in a bin wins: obstacles are never averaged away), then filtered:

- de-skewing (with `pose_at=` and a driver's per-return times): each return is placed with the pose
  the robot had when it was measured, not the revolution's one pose (turning fast, the ends of a
  revolution are tens of degrees apart).
- temporal median over the last `temporal` revolutions, per bin (the PiCar team's choice, which
  removes single-revolution outliers). Older revolutions are first moved into the current frame with
  the robot's pose at each, so the median does not smear obstacles while driving; a bin with no
  return counts as "far", so one stray echo among misses is dropped, while an obstacle seen in most
  revolutions stays.
- spatial: an isolated return (no neighbour within `isolated_m`, widening with range) beyond
  `keep_near_m` is dropped; a one-bin hole between two returns at similar ranges is filled (a lidar
  with a coarser step than the bins leaves such holes in walls, which a gap finder would take for
  openings).
- the blind zone: a lidar sees nothing nearer than its minimum range (0.12-0.15 m), which on a small
  robot reaches past the body's edge. Obstacle points that were seen and have since moved (with the
  robot's motion) into that zone are kept: the lidar cannot say they are gone, and they are exactly
  the ones the robot is about to touch. They are dropped once they leave the zone (the lidar sees
  that part again) or after `blind_hold_s` (something that walked past is not a wall for ever).
  Only the robot's own motion carries a point in (over the last `carried_window_s`, it must have
  brought the point `carried_m` nearer; a creep of a few mm/s counts): what walks into the zone of a
  robot standing still moves by itself, and is no wall to stand still for. Without poses nothing is
  carried in, so nothing is kept.

Everything is numpy over whole arrays: a revolution costs tens of microseconds.
"""

from __future__ import annotations

import math
from collections import deque
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Protocol, runtime_checkable

import numpy as np
from numpy.typing import NDArray

from host_sdk.body import LidarMount
from host_sdk.errors import CommandRangeError
from host_sdk.pose import Pose2D

F64 = NDArray[np.float64]


@runtime_checkable
class LaserScanLike(Protocol):
    """The fields of a ROS `sensor_msgs/LaserScan` this module reads."""

    @property
    def angle_min(self) -> float: ...

    @property
    def angle_increment(self) -> float: ...

    @property
    def range_min(self) -> float: ...

    @property
    def range_max(self) -> float: ...

    @property
    def ranges(self) -> object: ...


@runtime_checkable
class DriverScanLike(Protocol):
    """A `host_sdk.sensors.LidarScan`."""

    @property
    def angles_rad(self) -> F64: ...

    @property
    def ranges_m(self) -> F64: ...

    @property
    def range_min_m(self) -> float: ...

    @property
    def range_max_m(self) -> float: ...

    @property
    def time_s(self) -> float: ...

    @property
    def times_s(self) -> F64: ...


@dataclass(frozen=True, slots=True, eq=False)
class RawScan:
    """One revolution in the sensor's frame: angles CCW from the sensor's front; NaN: no return."""

    angles_rad: F64
    ranges_m: F64
    time_s: float = 0.0
    range_min_m: float = 0.0
    """The device's shortest range: anything nearer is not seen at all."""
    times_s: F64 | None = None
    """When each return was measured, if known (a revolution takes 0.1..0.2 s)."""

    @classmethod
    def from_arrays(
        cls,
        angles_rad: object,
        ranges_m: object,
        *,
        range_min_m: float = 0.0,
        range_max_m: float = math.inf,
        time_s: float = 0.0,
        times_s: object = None,
    ) -> RawScan:
        """Arrays of equal length; ranges outside range_min..range_max, 0, inf or NaN are no return."""
        a = np.asarray(angles_rad, dtype=np.float64).ravel()
        r = np.asarray(ranges_m, dtype=np.float64).ravel()
        if a.shape != r.shape:
            raise CommandRangeError("ranges_m", f"{r.shape[0]} values", f"one per angle ({a.shape[0]} angles)")
        times = None if times_s is None else np.asarray(times_s, dtype=np.float64).ravel()
        if times is not None and times.shape != r.shape:
            raise CommandRangeError("times_s", f"{times.shape[0]} values", f"one per angle ({a.shape[0]} angles)")
        ok = np.isfinite(r) & (r > 0) & (r >= range_min_m) & (r <= range_max_m)
        return cls(a, np.where(ok, r, np.nan), float(time_s), float(range_min_m), times)

    @classmethod
    def from_laserscan(cls, msg: LaserScanLike, time_s: float = 0.0) -> RawScan:
        """A ROS LaserScan (or anything with its fields): beam i is at angle_min + i * angle_increment."""
        ranges = np.asarray(msg.ranges, dtype=np.float64).ravel()
        angles = msg.angle_min + msg.angle_increment * np.arange(ranges.shape[0])
        return cls.from_arrays(angles, ranges, range_min_m=msg.range_min, range_max_m=msg.range_max, time_s=time_s)

    @classmethod
    def from_driver(cls, scan: DriverScanLike) -> RawScan:
        """A `host_sdk.sensors.LidarScan` (RPLIDAR A1, YDLIDAR F4)."""
        return cls.from_arrays(
            scan.angles_rad,
            scan.ranges_m,
            range_min_m=scan.range_min_m,
            range_max_m=scan.range_max_m,
            time_s=scan.time_s,
            times_s=scan.times_s,
        )


def as_raw(scan: RawScan | DriverScanLike | LaserScanLike) -> RawScan:
    if isinstance(scan, RawScan):
        return scan
    if isinstance(scan, DriverScanLike):
        return RawScan.from_driver(scan)
    if isinstance(scan, LaserScanLike):
        return RawScan.from_laserscan(scan)
    raise CommandRangeError("scan", type(scan).__name__, "a LidarScan, a LaserScan-shaped object or a RawScan")


@dataclass(frozen=True, slots=True, eq=False)
class ObstacleScan:
    """Filtered obstacles around the pose point: the nearest return per angular bin (NaN: none), and
    the same returns as base-frame points, computed once here and carried to every consumer."""

    angles_rad: F64
    """Bin centres, -pi..pi, counter-clockwise from the robot's forward axis."""
    ranges_m: F64
    time_s: float
    x_m: F64 = field(init=False)
    y_m: F64 = field(init=False)

    def __post_init__(self) -> None:
        x, y = polar_points(self.angles_rad, self.ranges_m)
        object.__setattr__(self, "x_m", x)
        object.__setattr__(self, "y_m", y)

    def points_xy(self) -> tuple[F64, F64]:
        """Obstacle points (x forward, y left) in the robot's base frame."""
        return self.x_m, self.y_m

    def range_at(self, bearing_rad: float, half_width_rad: float = 0.0) -> float:
        """Nearest obstacle within `half_width_rad` of a bearing (inf: none)."""
        d = np.abs(np.angle(np.exp(1j * (self.angles_rad - bearing_rad))))
        near = self.ranges_m[d <= max(half_width_rad, math.pi / self.angles_rad.shape[0])]
        near = near[np.isfinite(near)]
        return float(near.min()) if near.size else math.inf


def polar_points(angles_rad: F64, ranges_m: F64) -> tuple[F64, F64]:
    """x, y of the returns (NaN ranges: none) at `angles_rad`."""
    ok = np.isfinite(ranges_m)
    r, a = ranges_m[ok], angles_rad[ok]
    return r * np.cos(a), r * np.sin(a)


def bin_points(x: F64, y: F64, bins: int) -> F64:
    """Nearest range per angular bin around the origin (NaN where a bin holds no point)."""
    out = np.full(bins, np.inf)
    if x.size:
        r = np.hypot(x, y)
        idx = np.floor((np.arctan2(y, x) + math.pi) * bins / (2 * math.pi)).astype(np.int64) % bins
        np.minimum.at(out, idx, r)
    out[np.isinf(out)] = np.nan
    return out


def spatial_filter(ranges: F64, *, isolated_m: float = 0.1, keep_near_m: float = 1.0) -> F64:
    """Drop isolated far returns and fill one-bin holes in surfaces (the scan is circular)."""
    r = np.copy(ranges)
    left, right = np.roll(ranges, 1), np.roll(ranges, -1)
    tol = isolated_m + 0.03 * np.nan_to_num(ranges, nan=0.0)
    with np.errstate(invalid="ignore"):
        supported = (np.abs(left - ranges) <= tol) | (np.abs(right - ranges) <= tol)
        isolated = np.isfinite(ranges) & ~supported & (ranges > keep_near_m)
        hole = ~np.isfinite(ranges) & (np.abs(left - right) <= isolated_m + 0.03 * np.fmin(left, right))
    r[isolated] = np.nan
    r[hole] = np.fmin(left, right)[hole]
    return r


class ScanFilter:
    """Temporal (motion-compensated median) and spatial filtering of successive revolutions."""

    def __init__(
        self,
        mount: LidarMount | None = None,
        *,
        bins: int = 360,
        temporal: int = 3,
        isolated_m: float = 0.1,
        keep_near_m: float = 1.0,
        blind_hold_s: float = 4.0,
        carried_m: float = 0.001,
        carried_window_s: float = 1.0,
    ) -> None:
        if not (isinstance(bins, int) and 36 <= bins <= 4096):
            raise CommandRangeError("bins", bins, "an integer in 36..4096")
        if not (isinstance(temporal, int) and 1 <= temporal <= 25):
            raise CommandRangeError("temporal", temporal, "an integer in 1..25 revolutions")
        self.mount = mount or LidarMount()
        self.bins = bins
        self.temporal = temporal
        self.isolated_m = isolated_m
        self.keep_near_m = keep_near_m
        self.blind_hold_s = blind_hold_s
        self.carried_m = carried_m
        self.carried_window_s = carried_window_s
        self._poses: deque[tuple[float, Pose2D]] = deque()
        """(time, pose) of the revolutions of the last `carried_window_s`, oldest first."""
        self.angles = -math.pi + (np.arange(bins) + 0.5) * 2 * math.pi / bins
        self._history: deque[tuple[F64, F64, Pose2D]] = deque(maxlen=temporal)
        self._last: tuple[F64, F64, Pose2D] | None = None
        self._blind: list[tuple[F64, F64, Pose2D, F64]] = []

    def reset(self) -> None:
        self._history.clear()
        self._last = None
        self._blind = []
        self._poses.clear()

    def base_points(self, scan: RawScan | DriverScanLike | LaserScanLike) -> tuple[F64, F64, float]:
        """A revolution's returns as base-frame points, and its time."""
        x, y, raw = self._points(scan)
        return x, y, raw.time_s

    def _points(self, scan: RawScan | DriverScanLike | LaserScanLike) -> tuple[F64, F64, RawScan]:
        raw = as_raw(scan)
        ok = np.isfinite(raw.ranges_m)
        m = self.mount
        a = raw.angles_rad[ok] + m.yaw_rad
        r = raw.ranges_m[ok]
        return m.x_m + r * np.cos(a), m.y_m + r * np.sin(a), raw

    def update(
        self,
        scan: RawScan | DriverScanLike | LaserScanLike,
        pose: Pose2D | None = None,
        *,
        pose_at: Callable[[float], Pose2D] | None = None,
    ) -> ObstacleScan:
        """Add a revolution (with the robot's pose when it was taken) and return the filtered picture.
        With `pose_at` (the pose at any recent time) and per-return times, each return is first moved
        from where the robot was when it was measured to `pose` (de-skewing: turning at 1.6 rad/s, the
        two ends of a 0.18 s revolution are 17 degrees apart)."""
        x, y, raw = self._points(scan)
        here = pose or (0.0, 0.0, 0.0)
        if pose_at is not None and raw.times_s is not None and x.size > 1:
            times = raw.times_s[np.isfinite(raw.ranges_m)]
            x, y = deskew(x, y, times, pose_at, here)
        self._history.append((x, y, here))
        layers = [bin_points(*move_points(px, py, then, here), self.bins) for px, py, then in self._history]
        stack = np.nan_to_num(np.vstack(layers), nan=np.inf)
        med = np.median(stack, axis=0)
        med[~np.isfinite(med)] = np.nan
        ranges = spatial_filter(med, isolated_m=self.isolated_m, keep_near_m=self.keep_near_m)
        if raw.range_min_m > 0:
            bx, by = self._remember_blind(ranges, raw, here)
            if bx.size:
                ranges = np.fmin(ranges, bin_points(bx, by, self.bins))
        return ObstacleScan(self.angles, ranges, raw.time_s)

    def _remember_blind(self, seen: F64, raw: RawScan, here: Pose2D) -> tuple[F64, F64]:
        """Points now in the blind zone that were seen before it swallowed them, for `blind_hold_s`
        (long enough to back away from a wall, short enough that the target walking past is not
        remembered as a wall)."""
        m = self.mount
        poses = self._poses
        poses.append((raw.time_s, here))
        while len(poses) > 2 and raw.time_s - poses[1][0] >= self.carried_window_s:
            poses.popleft()
        before = poses[0][1]
        xs, ys, born = [], [], []
        for x, y, then, t0 in ([(*self._last, None)] if self._last is not None else []) + self._blind:
            mx, my = move_points(x, y, then, here)
            near = np.hypot(mx - m.x_m, my - m.y_m)
            inside = near < raw.range_min_m + 0.02
            if t0 is None:  # newly swallowed: only if the robot's own motion brought it nearer
                px, py = move_points(mx, my, here, before)
                inside &= near < np.hypot(px - m.x_m, py - m.y_m) - self.carried_m
            xs.append(mx[inside])
            ys.append(my[inside])
            born.append(np.full(int(inside.sum()), raw.time_s) if t0 is None else t0[inside])
        self._last = (*polar_points(self.angles, seen), here)
        if not xs:
            return np.zeros(0), np.zeros(0)
        bx, by, bt = np.concatenate(xs), np.concatenate(ys), np.concatenate(born)
        keep = raw.time_s - bt <= self.blind_hold_s
        self._blind = [(bx[keep], by[keep], here, bt[keep])]
        return bx[keep], by[keep]


def deskew(x: F64, y: F64, times: F64, pose_at: Callable[[float], Pose2D], now: Pose2D) -> tuple[F64, F64]:
    """Base-frame points each taken at its own time, seen from pose `now`: the robot's pose at each
    time is interpolated between those at the first and the last time (steady over a revolution)."""
    t0, t1 = float(times.min()), float(times.max())
    (x0, y0, a0), (x1, y1, a1) = pose_at(t0), pose_at(t1)
    f = (times - t0) / (t1 - t0) if t1 > t0 else np.zeros_like(times)
    th = a0 + f * math.remainder(a1 - a0, 2 * math.pi)
    c, s = np.cos(th), np.sin(th)
    wx, wy = x0 + f * (x1 - x0) + c * x - s * y, y0 + f * (y1 - y0) + s * x + c * y
    return move_points(wx, wy, (0.0, 0.0, 0.0), now)


def move_points(x: F64, y: F64, then: Pose2D, now: Pose2D) -> tuple[F64, F64]:
    """Base-frame points taken at pose `then`, seen from pose `now` (both in the odometry frame)."""
    if then == now:
        return x, y
    c0, s0 = math.cos(then[2]), math.sin(then[2])
    wx, wy = then[0] + c0 * x - s0 * y, then[1] + s0 * x + c0 * y
    c1, s1 = math.cos(now[2]), math.sin(now[2])
    dx, dy = wx - now[0], wy - now[1]
    return c1 * dx + s1 * dy, -s1 * dx + c1 * dy
