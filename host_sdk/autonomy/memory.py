"""What the follower knows about the target between sightings, in the odometry frame.

Its last position and smoothed velocity (to steer for where it went while it is out of view, and to
see it coming), the side it was last seen on (to search that way first), when the camera last had it,
and the route it walks (it will come back along it: a robot that lost it should not stand there).
"""

from __future__ import annotations

import math
from collections import deque
from collections.abc import Sequence

import numpy as np
from numpy.typing import NDArray

from host_sdk.autonomy.target import TargetFix
from host_sdk.perception.motion import Mover
from host_sdk.pose import Pose2D

F64 = NDArray[np.float64]


_RECENT = 15
"""Route points (0.1 m apart) that are the target's current pass."""


class TargetMemory:
    def __init__(self, target_size_m: float) -> None:
        self.target_size_m = target_size_m
        self.seen: tuple[float, float, float] | None = None
        """(time, x, y) of the target's surface point in the odometry frame when last seen."""
        self.velocity = (0.0, 0.0)
        """The target's velocity in the odometry frame."""
        self.side = 1.0
        """+1: last seen on the robot's left, -1: on its right."""
        self.camera_seen = -math.inf
        """When the camera last had it (the scan may have had it since)."""
        self.route: deque[tuple[float, float]] = deque(maxlen=400)
        """Where the target has been (odometry frame): it walks the same route again."""

    def remember(self, t: float, fix: TargetFix, pose: Pose2D) -> None:
        wx, wy = to_world(pose, fix.x_m, fix.y_m)
        if self.seen is not None and 0 < t - self.seen[0] < 0.6:
            dt = t - self.seen[0]
            vx, vy = (wx - self.seen[1]) / dt, (wy - self.seen[2]) / dt
            a = min(1.0, dt / 0.5)  # ~0.5 s smoothing: the surface point jitters with the view
            vx, vy = self.velocity[0] + a * (vx - self.velocity[0]), self.velocity[1] + a * (vy - self.velocity[1])
            speed = math.hypot(vx, vy)
            self.velocity = (vx, vy) if speed <= 0.8 else (0.8 * vx / speed, 0.8 * vy / speed)
        elif self.seen is None or t - self.seen[0] >= 0.6:
            self.velocity = (0.0, 0.0)
        self.seen = (t, wx, wy)
        self.side = 1.0 if fix.y_m >= 0 else -1.0
        if not self.route or math.hypot(wx - self.route[-1][0], wy - self.route[-1][1]) > 0.1:
            self.route.append((wx, wy))

    def predicted(self, t: float, pose: Pose2D, horizon_s: float) -> tuple[float, float] | None:
        if self.seen is None or t - self.seen[0] > horizon_s:
            return None
        age = min(t - self.seen[0], 3.0)
        wx, wy = self.seen[1] + self.velocity[0] * age, self.seen[2] + self.velocity[1] * age
        return to_base(pose, wx, wy)

    def ahead(self, t: float, pose: Pose2D, times: F64) -> tuple[F64, F64] | None:
        """Where the target will be (its surface point, base frame) at `times` from now, if it walks
        its route again: from the last time it passed near where it is now, going the same way, the
        route it walked then, at its speed now. None when it has not passed here before (or stands):
        then its velocity is all there is to go by."""
        speed = math.hypot(*self.velocity)
        if self.seen is None or speed < 0.05 or len(self.route) < 2 * _RECENT:
            return None
        age = min(t - self.seen[0], 3.0)
        px, py = self.seen[1] + self.velocity[0] * age, self.seen[2] + self.velocity[1] * age
        route = np.array(self.route)
        step = np.diff(route, axis=0)
        old = slice(0, len(route) - _RECENT)  # the current pass is not a pass before
        near = np.hypot(route[old, 0] - px, route[old, 1] - py) < 0.35
        same_way = step[old] @ np.array(self.velocity) > 0.5 * speed * np.hypot(step[old, 0], step[old, 1])
        passes = np.flatnonzero(near & same_way)
        if not passes.size:
            return None
        latest = passes[passes > passes[-1] - 10]  # the last pass by here (points 0.1 m apart)...
        i = int(latest[np.argmin(np.hypot(route[latest, 0] - px, route[latest, 1] - py))])  # ...where nearest
        walked = np.concatenate([[0.0], np.cumsum(np.hypot(step[i:, 0], step[i:, 1]))])
        s = speed * np.asarray(times, dtype=np.float64)
        wx = np.interp(s, walked, route[i:, 0]) + (px - route[i, 0])
        wy = np.interp(s, walked, route[i:, 1]) + (py - route[i, 1])
        c, sn = math.cos(pose[2]), math.sin(pose[2])
        dx, dy = wx - pose[0], wy - pose[1]
        return c * dx + sn * dy, -sn * dx + c * dy

    def velocity_in(self, pose: Pose2D) -> tuple[float, float]:
        c, s = math.cos(pose[2]), math.sin(pose[2])
        vx, vy = self.velocity
        return c * vx + s * vy, -s * vx + c * vy

    def lidar_fix(
        self, px: F64, py: F64, predicted: tuple[float, float] | None, *, gate_m: float = 0.3
    ) -> TargetFix | None:
        """The target's returns where it should be now: a compact cluster within `gate_m` of the
        prediction with nothing else around it (a wall or a box nearby makes it ambiguous: then none)."""
        if predicted is None or not px.size:
            return None
        d = np.hypot(px - predicted[0], py - predicted[1])
        i = int(np.argmin(d))
        if d[i] > gate_m:
            return None
        fix, clear = self._cluster(px, py, float(px[i]), float(py[i]))
        return fix if clear else None

    def mover_fix(
        self,
        px: F64,
        py: F64,
        movers: Sequence[Mover],
        pose: Pose2D,
        *,
        near: tuple[float, float] | None = None,
        gate_m: float = math.inf,
        compact: bool = False,
    ) -> TargetFix | None:
        """The moving cluster nearest `near` (base frame; by default where the target was last seen,
        or the robot), if within `gate_m` of it, with its returns among the points given (base frame).
        With `compact`, only one standing clear of everything else (against a wall or a box, which
        returns are the target's is ambiguous, and an edge seen from a new angle can pass for one)."""
        if near is not None:
            ref = to_world(pose, *near)
        else:
            ref = (self.seen[1], self.seen[2]) if self.seen is not None else to_world(pose, 0.0, 0.0)
        for mover in sorted(movers, key=lambda m: math.hypot(m.x_m - ref[0], m.y_m - ref[1])):
            if math.hypot(mover.x_m - ref[0], mover.y_m - ref[1]) > gate_m:
                return None
            bx, by = to_base(pose, mover.x_m, mover.y_m)
            if px.size:
                d = np.hypot(px - bx, py - by)
                i = int(np.argmin(d))
                if d[i] < 0.3:
                    bx, by = float(px[i]), float(py[i])
            fix, clear = self._cluster(px, py, bx, by)
            if clear or not compact:
                return fix
        return None

    def _cluster(self, px: F64, py: F64, sx: float, sy: float) -> tuple[TargetFix, bool]:
        """The target's fix with its surface at (sx, sy): the returns within its size of that point are
        its own; and whether it stands clear (nothing else within 0.25 m beyond them)."""
        inner = 0.6 * self.target_size_m + 0.05
        r = np.hypot(px - sx, py - sy)
        return TargetFix(sx, sy, r < inner, True), not bool(((r >= inner) & (r < inner + 0.25)).any())

    def route_in(self, pose: Pose2D) -> tuple[F64, F64]:
        """The target's route in the base frame (x, y arrays)."""
        if not self.route:
            return np.zeros(0), np.zeros(0)
        route = np.array(self.route)
        c, s = math.cos(pose[2]), math.sin(pose[2])
        dx, dy = route[:, 0] - pose[0], route[:, 1] - pose[1]
        return c * dx + s * dy, -s * dx + c * dy

    def off_route(self, pose: Pose2D, radius_m: float, x_m: float) -> float | None:
        """Bearing (base frame) away from the target's route when the robot stands on it, else None."""
        rx, ry = self.route_in(pose)
        if not rx.size:
            return None
        d = np.hypot(rx - x_m, ry)
        i = int(np.argmin(d))
        if d[i] > radius_m + self.target_size_m / 2 + 0.25:
            return None
        return math.atan2(-float(ry[i]), -float(rx[i]))


def to_world(pose: Pose2D, x: float, y: float) -> tuple[float, float]:
    c, s = math.cos(pose[2]), math.sin(pose[2])
    return pose[0] + c * x - s * y, pose[1] + s * x + c * y


def to_base(pose: Pose2D, wx: float, wy: float) -> tuple[float, float]:
    c, s = math.cos(pose[2]), math.sin(pose[2])
    dx, dy = wx - pose[0], wy - pose[1]
    return c * dx + s * dy, -s * dx + c * dy
