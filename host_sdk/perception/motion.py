"""Moving things in the scan: lidar returns where earlier revolutions saw free space.

A camera sees 62 degrees; the lidar sees all round. When the camera has lost what it follows, the
thing is usually still in the scan, and of everything in a room it is the one that moves. A return
is *moving* when an earlier revolution, seen from where the robot was then, had a beam pass through
that spot and end beyond it (a free-space violation): walls and boxes never do that, whatever the
robot's own motion, and something uncovered from behind an obstacle does not either (the old beam
ended on the obstacle, nearer). Moving returns are clustered; a cluster no wider than `max_size_m`
seen `confirm` revolutions running near the same place is a `Mover`.

It looks for motion against revolutions `lags_s` old: a walker at 0.2 m/s has left its own body's
width after about a second and a half, so one lag is not enough for slow things. Bins without a
return count as unknown, not free (a dropout on a glancing wall is not empty space).
"""

from __future__ import annotations

import math
from collections import deque
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from host_sdk.perception.scan import ObstacleScan, move_points
from host_sdk.pose import Pose2D

F64 = NDArray[np.float64]


@dataclass(frozen=True, slots=True)
class MotionParams:
    lags_s: tuple[float, ...] = (0.7, 1.5, 2.5)
    """Ages of the revolutions each new one is compared with."""
    margin_m: float = 0.2
    """How far short of an earlier beam's end a return must be to have been free space."""
    min_range_m: float = 0.3
    max_range_m: float = 6.0
    cluster_gap_m: float = 0.2
    """Moving returns closer than this are one thing."""
    min_points: int = 3
    max_size_m: float = 0.8
    """A cluster wider than this is not one walker (a misaligned wall)."""
    confirm: int = 2
    """Revolutions in a row a cluster must be seen near the same place."""
    associate_m: float = 0.5
    max_turn_rate: float = 1.2
    """rad/s: revolutions taken while the robot turns faster are not compared (slower, the beams
    compared are widened by the turn during a revolution)."""
    forget_s: float = 1.0


@dataclass(frozen=True, slots=True)
class Mover:
    """A moving cluster, in the odometry frame."""

    x_m: float
    """The cluster's point nearest the robot when seen."""
    y_m: float
    time_s: float
    hits: int
    """Revolutions in a row it was seen."""


@dataclass(frozen=True, slots=True, eq=False)
class _Revolution:
    time_s: float
    pose: Pose2D
    angles_rad: F64
    ranges_m: F64
    skew_rad: float
    """How far the robot turned since the revolution before: about how far apart in heading this
    one's first and last beams are."""
    turn_rate: float
    """rad/s, while it was taken."""


class MotionDetector:
    def __init__(self, params: MotionParams | None = None) -> None:
        self.params = params or MotionParams()
        self._history: deque[_Revolution] = deque()
        self._tracks: list[Mover] = []

    def update(self, scan: ObstacleScan, pose: Pose2D) -> tuple[Mover, ...]:
        """Take a filtered revolution and the pose it was taken at; the confirmed movers now."""
        p = self.params
        t = scan.time_s
        rate = self._turn_rate(t, pose)
        skew = 0.0
        if self._history and t > self._history[-1].time_s:
            skew = rate * (t - self._history[-1].time_s)
        x, y = scan.points_xy()
        wx, wy = move_points(x, y, pose, (0.0, 0.0, 0.0))  # into the odometry frame
        r = np.hypot(x, y)
        moving = np.zeros(x.shape[0], dtype=bool)
        usable = (r > p.min_range_m) & (r < p.max_range_m)
        for lag in p.lags_s if rate <= p.max_turn_rate else ():
            old = self._at_age(t, lag)
            if old is not None and old.turn_rate <= p.max_turn_rate:
                # Spinning, a revolution's first and last beams are tens of degrees apart in heading:
                # not a picture to compare free space with.
                moving |= usable & _free_before(old, wx, wy, p.margin_m, (skew + old.skew_rad) / 2)
        self._history.append(_Revolution(t, pose, scan.angles_rad, scan.ranges_m, skew, rate))
        while self._history and t - self._history[0].time_s > max(p.lags_s) + 1.0:
            self._history.popleft()
        return self._confirm(t, _clusters(wx[moving], wy[moving], pose, p))

    def _turn_rate(self, t: float, pose: Pose2D) -> float:
        """How fast the robot turns, over the last half second or more: a revolution's pose comes from
        the host's loop and may be a control step off, so one revolution's own turn is jittery."""
        ref = None
        for entry in reversed(self._history):
            ref = entry
            if t - entry.time_s >= 0.5:
                break
        if ref is None or t <= ref.time_s:
            return 0.0
        return abs(math.remainder(pose[2] - ref.pose[2], 2 * math.pi)) / (t - ref.time_s)

    def _at_age(self, t: float, lag: float) -> _Revolution | None:
        """The newest revolution at least `lag` old."""
        for entry in reversed(self._history):
            if t - entry.time_s >= lag:
                return entry
        return None

    def _confirm(self, t: float, found: list[tuple[float, float]]) -> tuple[Mover, ...]:
        p = self.params
        tracks = [m for m in self._tracks if t - m.time_s <= p.forget_s]
        updated: list[Mover] = []
        for cx, cy in found:
            near = [m for m in tracks if math.hypot(m.x_m - cx, m.y_m - cy) < p.associate_m]
            hits = 1 + max((m.hits for m in near), default=0)
            tracks = [m for m in tracks if m not in near]
            updated.append(Mover(cx, cy, t, hits))
        self._tracks = updated + tracks
        return tuple(m for m in updated if m.hits >= p.confirm)


def _free_before(old: _Revolution, wx: F64, wy: F64, margin: float, skew: float) -> NDArray[np.bool_]:
    """Which world points lay in space an earlier revolution saw as free. `skew` (rad) is how far
    the two revolutions may be off each other in heading (each beam is up to half its revolution's
    turn off the pose it was given): the beams that count are that much wider, and an earlier
    return that much farther still counts as close by."""
    bins = old.angles_rad.shape[0]
    pose, ranges = old.pose, old.ranges_m
    bx, by = move_points(wx, wy, (0.0, 0.0, 0.0), pose)
    r = np.hypot(bx, by)
    idx = np.floor((np.arctan2(by, bx) + math.pi) * bins / (2 * math.pi)).astype(np.int64) % bins
    seen = np.where(np.isfinite(ranges), ranges, -np.inf)  # no return: unknown, never free
    half = 1 + math.ceil(skew * bins / (2 * math.pi))
    nearest = np.min(np.stack([seen[(idx + j) % bins] for j in range(-half, half + 1)]), axis=0)
    free: NDArray[np.bool_] = nearest > r + margin
    if free.any():
        # An obstacle's edge seen from a little elsewhere falls into a neighbouring beam's free
        # space; a return that has an earlier return close by was there before.
        ok = np.isfinite(ranges)
        ox, oy = ranges[ok] * np.cos(old.angles_rad[ok]), ranges[ok] * np.sin(old.angles_rad[ok])
        cand = np.flatnonzero(free)
        d = np.hypot(bx[cand, None] - ox[None, :], by[cand, None] - oy[None, :])
        near = d < (margin + r[cand] * skew)[:, None]
        free[cand[near.any(axis=1)]] = False
    return free


def _clusters(x: F64, y: F64, pose: Pose2D, p: MotionParams) -> list[tuple[float, float]]:
    """Each compact cluster's point nearest the robot (world frame)."""
    n = x.shape[0]
    if n < p.min_points:
        return []
    d = np.hypot(x[:, None] - x[None, :], y[:, None] - y[None, :])
    label = -np.ones(n, dtype=np.int64)
    out = []
    for i in range(n):
        if label[i] >= 0:
            continue
        label[i] = i
        stack, members = [i], [i]
        while stack:
            j = stack.pop()
            for k in np.flatnonzero((d[j] < p.cluster_gap_m) & (label < 0)):
                label[k] = i
                stack.append(int(k))
                members.append(int(k))
        if len(members) < p.min_points or float(d[np.ix_(members, members)].max()) > p.max_size_m:
            continue
        near = members[int(np.argmin(np.hypot(x[members] - pose[0], y[members] - pose[1])))]
        out.append((float(x[near]), float(y[near])))
    return out
