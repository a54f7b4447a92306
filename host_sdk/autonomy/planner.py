"""Receding-horizon planning for following: the short manoeuvre that keeps the target in the picture.

A car turns only as it drives, so whether the target stays in the camera's view depends on where the
car will be in the next seconds, not on where it points now. Every control step the planner scores a
fixed set of two-part manoeuvres (a speed and a steering arc until `switch_s`, then another until
`horizon_s`) against what the robot knows now: the obstacle points, and where the target is and is
heading. It starts the first part of the best one and plans again at the next step.

    planner = ViewPlanner(footprint, camera, curvatures=[-1.79, -1.03, 0.0, 1.03, 2.22])
    choice = planner.plan(ox, oy, target=(x, y), target_velocity=(vx, vy), gap_m=0.9, last=(v, w))
    robot.drive(choice.linear_m_s, choice.angular_rad_s)

Each manoeuvre is simulated (the previous command for `latency_s`, then the speed ramping at
`accel_m_s2`) and:

- must keep the footprint `pad_m` clear of every obstacle point, over the horizon and the stop after
  it (points already inside that margin only forbid coming closer to them);
- should keep the footprint `guard_m` clear of the target's predicted body (the target does not
  avoid the robot: a manoeuvre that meets it costs more than any other), and a car should not stop
  where the target walks into it within `late_s` after the horizon;
- is scored by where the target would be in the picture (no cost inside `view_share` of the half
  field of view, the most at its edge, beyond it or behind an obstacle: the line of sight is checked
  against the obstacle points), how much turning would still be needed at the end, how far the gap
  would be from the wanted one, how close it passes obstacles, reversing, and how much it changes
  the command.

The obstacles' distance field is OpenCV's distance transform of the points drawn into a grid round
the robot (the vision extra), so a step costs a few milliseconds whatever the number of points. The
manoeuvres are whatever the robot can steer: `curvatures` are the arcs its steering reaches (the
PiCar's servo moves in 15 degree steps), so the arc planned is the arc driven.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import NDArray

from host_sdk.body import CameraModel, Footprint
from host_sdk.extras import require

F64 = NDArray[np.float64]


@dataclass(frozen=True, slots=True)
class PlannerParams:
    horizon_s: float = 3.2
    """Long enough to turn the camera round to a target behind the car."""
    switch_s: float = 1.0
    """When the second part of each manoeuvre begins."""
    step_s: float = 0.2
    """Spacing of the points each manoeuvre is judged at."""
    speeds_m_s: tuple[float, ...] = (-0.35, -0.2, 0.0, 0.2, 0.35, 0.45)
    accel_m_s2: float = 1.0
    """How fast the speed follows the command: the board's accel limit, which a tuned wheel follows
    speeding up (a `Follower` given it plans with it); slowing, the board allows more (its decel
    limit), so this errs towards the car running on."""
    latency_s: float = 0.15
    """The previous command still drives this long (scan age, loop period, control tick)."""
    decel_m_s2: float = 0.8
    """Braking assumed for the stop after the horizon."""
    pad_m: float = 0.04
    """Clearance kept between the footprint and obstacle points."""
    soft_clear_m: float = 0.2
    """Closer than this to an obstacle costs a little (a real robot never drives the exact arc)."""
    cell_m: float = 0.03
    """Grid of the obstacles' distance field."""
    guard_m: float = 0.25
    """Clearance wanted between the footprint and the target's predicted body."""
    target_radius_m: float = 0.15
    view_share: float = 0.55
    """Inside this share of the half field of view the target is well in the picture (no cost)."""
    max_view_m: float = 3.5
    """Farther than this the camera may not make the target out."""
    w_view: float = 2.0
    w_turn: float = 2.0
    """Per half turn still needed at the end of the horizon to bring the target into the picture."""
    w_shadow: float = 0.5
    """Per metre the camera would still have to move sideways, at the end, to see past an obstacle."""
    w_gap: float = 0.8
    """Per metre of gap error."""
    w_clear: float = 0.3
    w_reverse: float = 0.08
    w_flip: float = 0.3
    """Changing between forwards and backwards (an ESC brakes before it reverses)."""
    w_keep: float = 0.1
    """Off the cost of going on moving as the last command did."""
    w_change: float = 0.06
    w_meet: float = 30.0
    """Per metre the target's body would come inside `guard_m`, on average over the horizon (the
    sooner a manoeuvre gets out of its way, the less it costs)."""
    w_contact: float = 300.0
    """Per metre the footprint would overlap the target's predicted body at the worst: a manoeuvre
    that runs into it is worse than any that does not, whatever it does for the view."""
    late_s: float = 3.0
    """A car's: after the horizon it stands where it stopped while the target walks on this long. A
    place the target walks into soon after is no place for a car to stop: it needs room and time to
    get off the target's route, so it has to see that coming before it is inside the horizon. (A
    differential drive steps aside on the spot in time; checking this for it too only cost it time
    with the target in view.)"""
    w_late: float = 100.0
    """Per metre the target's body would overlap the stopped footprint then, at the worst."""


@dataclass(frozen=True, slots=True)
class PlanChoice:
    linear_m_s: float
    angular_rad_s: float
    cost: float
    in_view: float
    """Share of the horizon the target is predicted in the picture (in the field of view, in sight)."""
    min_separation_m: float
    """Closest the footprint comes to the target's predicted body on this manoeuvre."""
    feasible: bool
    """False: no manoeuvre kept clear of the obstacles (the choice is to stand)."""
    deflected: bool = False
    """The obstacles changed the choice: without them another manoeuvre would have been best."""
    late_separation_m: float = math.inf
    """Closest the target's predicted body comes to the footprint stopped after it, in `late_s`."""
    path_xy: tuple[tuple[float, float], ...] = field(default=(), repr=False)
    """Where the chosen manoeuvre takes the pose point (base frame), at every judged time."""


class ViewPlanner:
    """Give `curvatures` (1/m) for a car, whose turn rate is its speed times the curvature its
    steering holds, or `turn_rates` (rad/s) for a differential drive, which turns at any speed,
    standing too."""

    def __init__(
        self,
        footprint: Footprint,
        camera: CameraModel,
        *,
        curvatures: Sequence[float] | None = None,
        turn_rates: Sequence[float] | None = None,
        params: PlannerParams | None = None,
    ) -> None:
        if (curvatures is None) == (turn_rates is None):
            raise ValueError("give the arcs a car steers (curvatures) or the turn rates of a differential drive")
        self.footprint = footprint
        self.camera = camera
        self.params = p = params or PlannerParams()
        # Each part: (speed, curvature, turn rate); it turns at speed * curvature + turn rate.
        if curvatures is not None:
            ks = sorted({float(k) for k in curvatures} | {0.0})
            parts = np.array([(v, k, 0.0) for v in p.speeds_m_s for k in (ks if v != 0.0 else [0.0])])
        else:
            ws = sorted({float(w) for w in turn_rates or ()} | {0.0})
            parts = np.array([(v, 0.0, w) for v in p.speeds_m_s for w in ws])
        self._parts = parts
        n = parts.shape[0]
        self._a = np.repeat(np.arange(n), n)  # the first part of each manoeuvre...
        self._b = np.tile(np.arange(n), n)  # ...and its second
        self.v1, self.k1, self.w1 = parts[self._a].T
        self.v2, self.k2, self.w2 = parts[self._b].T
        self.turn1 = self.v1 * self.k1 + self.w1
        """The first part's turn rate: what is sent."""
        self.max_turn = float(np.abs(self.turn1).max()) or 1.0
        self.max_speed = float(np.abs(self.v1).max()) or 1.0
        self._sub = 2
        """Integration steps per judged point."""
        self._n_a = round(p.switch_s / p.step_s)
        self._n_b = round((p.horizon_s - p.switch_s) / p.step_s)
        self.times: F64 = p.step_s * np.arange(1, self._n_a + self._n_b + 1, dtype=np.float64)
        """When each manoeuvre is judged, s from now."""
        late = round(p.late_s / p.step_s) if curvatures is not None else 0
        self.path_times: F64 = p.step_s * np.arange(1, self.times.size + late + 1, dtype=np.float64)
        """When the target's predicted place is wanted: `times`, then (a car) `late_s` after them."""

    def plan(
        self,
        ox: F64,
        oy: F64,
        *,
        target: tuple[float, float],
        target_velocity: tuple[float, float],
        gap_m: float,
        last: tuple[float, float] = (0.0, 0.0),
        speed_m_s: float | None = None,
        direction: float = 0.0,
        moving: bool = False,
        target_path: tuple[F64, F64] | None = None,
    ) -> PlanChoice:
        """The manoeuvre to start now: obstacle points and the target's nearest surface point in the
        base frame, the target's velocity (base frame, m/s), the wanted footprint-to-surface gap, and
        the command sent last (linear m/s, angular rad/s), which still drives for `latency_s`, and the
        speed the robot moves at now (measured; by default the last command's). `target_path`, where
        known, is where the target's surface point will be at each of `path_times` (it turns where its
        route turns); by default it goes on at its velocity.

        `direction` (+1 forwards, -1 backwards, 0 either) rules out the other way, unless holding to it
        runs into the target and the other way does not: replanning 20 times a second between two
        nearly equal choices, forwards and backwards, a car never moves (the caller holds the way it
        began to move for a while). With `moving`, standing is ruled out too (the same way, between
        standing and going: a car that has just started keeps going for a moment). A manoeuvre that
        goes on moving as the last command did costs `w_keep` less."""
        p, fp = self.params, self.footprint
        v0, w0 = last
        ox, oy = np.asarray(ox, np.float64), np.asarray(oy, np.float64)
        x, y, th, stop_x, stop_y = self._simulate(v0 if speed_m_s is None else speed_m_s, v0, w0)
        fx, fy = x + fp.x_m * np.cos(th), y + fp.x_m * np.sin(th)
        sfx, sfy = stop_x + fp.x_m * np.cos(th[:, -1:]), stop_y + fp.x_m * np.sin(th[:, -1:])
        clear, ok = self._clearance((ox, oy), (fx, fy), (sfx, sfy))
        centre_x, centre_y = self._target_centres(target, target_velocity, target_path)
        n, r = self.times.size, p.target_radius_m
        cx, cy = centre_x[:n], centre_y[:n]
        sep = np.hypot(fx - cx, fy - cy) - fp.radius_m - r
        # After the horizon (a car): the target walks on while the robot stands where it stopped.
        late = (np.hypot(sfx[:, -1:] - centre_x[n:], sfy[:, -1:] - centre_y[n:]) - fp.radius_m - r).min(
            axis=1, initial=np.inf
        )
        seen, view, turn_left, shadow = self._views((ox, oy), (x, y, th), (cx, cy))
        reverse, flip, keep, change = self._command_changes(v0, w0)
        gap_err = np.where(sep < gap_m, 1.5 * (gap_m - sep), sep - gap_m)
        min_sep = sep.min(axis=1)
        cost = (
            p.w_view * view.mean(axis=1)
            + p.w_turn * turn_left
            + p.w_shadow * shadow
            + p.w_gap * gap_err.mean(axis=1)
            + p.w_clear * np.clip((p.soft_clear_m - clear) / p.soft_clear_m, 0.0, 1.0).mean(axis=1)
            + p.w_reverse * reverse
            + p.w_flip * flip
            - p.w_keep * keep
            + p.w_change * change
            + p.w_meet * np.maximum(p.guard_m - sep, 0.0).mean(axis=1)
            + p.w_contact * np.maximum(-min_sep, 0.0)
            + p.w_late * np.maximum(-late, 0.0)
        )
        if direction:
            ok = self._hold(ok, cost, min_sep, direction, moving)
        if not ok.any():
            return PlanChoice(0.0, 0.0, math.inf, 0.0, float(min_sep.max()), False, late_separation_m=float(late.max()))
        free = int(np.argmin(cost))
        i = int(np.argmin(np.where(ok, cost, np.inf)))
        path = tuple(zip(np.round(x[i], 3).tolist(), np.round(y[i], 3).tolist(), strict=True))
        return PlanChoice(
            float(self.v1[i]),
            float(self.turn1[i]),
            float(cost[i]),
            float(seen[i].mean()),
            float(min_sep[i]),
            True,
            free != i,
            float(late[i]),
            path,
        )

    def _hold(
        self, ok: NDArray[np.bool_], cost: F64, min_sep: F64, direction: float, moving: bool
    ) -> NDArray[np.bool_]:
        """The manoeuvres that keep to `direction` (and keep moving, when `moving`), unless holding
        to it runs into the target and the other way does not."""
        held: NDArray[np.bool_] = ok & (self.v1 * direction > 0 if moving else self.v1 * direction >= 0)
        clear_of_it = ok & (min_sep >= 0.0)
        if held.any() and (min_sep[int(np.argmin(np.where(held, cost, np.inf)))] >= 0.0 or not clear_of_it.any()):
            return held
        return ok

    def _clearance(
        self, obstacles: tuple[F64, F64], front: tuple[F64, F64], stop: tuple[F64, F64]
    ) -> tuple[F64, NDArray[np.bool_]]:
        """The footprint's clearance at every judged point and at the stop, and which manoeuvres keep
        `pad_m` of it (or, already closer than that, do not get closer)."""
        p, fp = self.params, self.footprint
        (ox, oy), (fx, fy), (sfx, sfy) = obstacles, front, stop
        half = float(max(np.abs(fx).max(), np.abs(fy).max(), np.abs(sfx).max(), np.abs(sfy).max()))
        distance = _DistanceField(ox, oy, p.cell_m, half=half + fp.radius_m + p.soft_clear_m + 0.1)
        clear = distance.at(np.concatenate([fx, sfx], axis=1), np.concatenate([fy, sfy], axis=1)) - fp.radius_m
        now = float(distance.at(np.array([fp.x_m]), np.array([0.0]))[0]) - fp.radius_m
        return clear, clear.min(axis=1) >= min(p.pad_m, now - 0.005)

    def _target_centres(
        self, target: tuple[float, float], velocity: tuple[float, float], path: tuple[F64, F64] | None
    ) -> tuple[F64, F64]:
        """The target's centre at each of `path_times`, from its nearest surface point, moving at its
        velocity (or on its path)."""
        if path is None:
            sx = target[0] + velocity[0] * self.path_times
            sy = target[1] + velocity[1] * self.path_times
        else:
            sx, sy = np.asarray(path[0], np.float64), np.asarray(path[1], np.float64)
        d = np.maximum(np.hypot(sx, sy), 1e-6)
        r = self.params.target_radius_m
        return sx * (1 + r / d), sy * (1 + r / d)

    def _views(
        self, obstacles: tuple[F64, F64], poses: tuple[F64, F64, F64], centre: tuple[F64, F64]
    ) -> tuple[NDArray[np.bool_], F64, F64, F64]:
        """Where the camera sees the target along each manoeuvre (seen, and the view cost per judged
        point), and where it ends: the turn still needed to face the target, and the way out of an
        obstacle's shadow (both give the choice a direction when nothing in the horizon sees it)."""
        p, cam = self.params, self.camera
        (ox, oy), (x, y, th), (cx, cy) = obstacles, poses, centre
        camx = x + cam.mount_x_m * np.cos(th) - cam.mount_y_m * np.sin(th)
        camy = y + cam.mount_x_m * np.sin(th) + cam.mount_y_m * np.cos(th)
        bearing = np.remainder(np.arctan2(cy - camy, cx - camx) - th - cam.mount_yaw_rad + math.pi, 2 * math.pi)
        off = np.abs(bearing - math.pi) / cam.half_fov_rad
        dist = np.hypot(cx - camx, cy - camy)
        sight = _Sight(ox, oy, cx, cy)
        hidden = sight.hidden(camx, camy)
        seen = (off <= 1.0) & ~hidden & (dist <= p.max_view_m)
        view = np.where(seen, np.clip((off - p.view_share) / (1 - p.view_share), 0.0, 1.0), 1.0)
        turn_left = np.maximum(np.abs(bearing[:, -1] - math.pi) - p.view_share * cam.half_fov_rad, 0.0) / math.pi
        shadow = np.where(hidden[:, -1], np.minimum(sight.way_out(camx[:, -1], camy[:, -1]), 1.0), 0.0)
        return seen, view, turn_left, shadow

    def _command_changes(self, v0: float, w0: float) -> tuple[F64, F64, NDArray[np.bool_], F64]:
        """What the two parts do to the command (reversing, flipping the way, keeping it, changing
        it), paid for in both: a manoeuvre that stands now to reverse later would otherwise look
        cheaper than reversing now, for ever (it plans again)."""
        v1, v2, turn2 = self.v1, self.v2, self.v2 * self.k2 + self.w2
        way = np.where(v1 != 0.0, np.sign(v1), np.sign(v0))
        flip = (v1 * v0 < 0).astype(np.float64) + (v2 * way < 0)
        change = (np.abs(v1 - v0) + np.abs(v2 - v1)) / self.max_speed + (
            np.abs(self.turn1 - w0) + np.abs(turn2 - self.turn1)
        ) / self.max_turn
        keep = (v1 == v0) & (np.abs(self.turn1 - w0) < 1e-9) & (v0 != 0.0)
        return (v1 < 0).astype(np.float64) + (v2 < 0), flip, keep, change

    def _simulate(self, speed: float, v0: float, w0: float) -> tuple[F64, F64, F64, F64, F64]:
        """Poses (manoeuvre x judged point) of every manoeuvre from the base frame's origin, and two
        points of the stop after it. The first parts are integrated once each, the second parts once
        for each speed they start from, and the two put together."""
        p, parts, sub = self.params, self._parts, self._sub
        dt = p.step_s / sub
        steps = np.arange(self._n_a * sub)[None, :]
        held = steps < round(p.latency_s / dt)  # the last command still drives
        v_cmd = np.where(held, v0, parts[:, :1])
        k_cmd = np.where(held, 0.0, parts[:, 1:2])
        w_cmd = np.where(held, w0, parts[:, 2:3])
        ax, ay, ath, av = _integrate(np.full(parts.shape[0], speed), [v_cmd, k_cmd, w_cmd], p.accel_m_s2, dt)
        # Second parts, from each speed a first part can end at.
        starts, which = np.unique(av[:, -1], return_inverse=True)
        m, n_b = parts.shape[0], self._n_b * sub
        tiled = [np.repeat(col[:, None], n_b, axis=1) for col in np.tile(parts, (starts.shape[0], 1)).T]
        bx, by, bth, bv = _integrate(np.repeat(starts, m), tiled, p.accel_m_s2, dt)
        rel = which[self._a] * m + self._b  # the second part each manoeuvre drives, from its speed
        ex, ey, eth = ax[self._a, -1:], ay[self._a, -1:], ath[self._a, -1:]
        c, s = np.cos(eth), np.sin(eth)
        rx, ry = bx[rel], by[rel]
        x = np.concatenate([ax[self._a], ex + c * rx - s * ry], axis=1)[:, sub - 1 :: sub]
        y = np.concatenate([ay[self._a], ey + s * rx + c * ry], axis=1)[:, sub - 1 :: sub]
        th = np.concatenate([ath[self._a], eth + bth[rel]], axis=1)[:, sub - 1 :: sub]
        # The stop after the horizon, along the last arc.
        v_end = bv[rel, -1]
        stop = np.sign(v_end) * (np.abs(v_end) * p.latency_s + v_end * v_end / (2 * p.decel_m_s2))
        k_end = self.k2 + np.where(np.abs(v_end) > 0.01, self.w2 / np.where(np.abs(v_end) > 0.01, v_end, 1.0), 0.0)
        f = np.array([0.5, 1.0])[None, :]
        turn = stop[:, None] * f * k_end[:, None]
        last = th[:, -1:]
        stop_x = x[:, -1:] + stop[:, None] * f * np.cos(last + turn / 2)
        stop_y = y[:, -1:] + stop[:, None] * f * np.sin(last + turn / 2)
        return x, y, th, stop_x, stop_y


class _Sight:
    """Lines of sight to the target. Seen from where the target will be at each judged time, the
    nearest obstacle in every direction (1-degree bins, each taking its neighbours' nearest too, so
    the gaps between the returns of one wall do not let a line of sight through): a camera beyond
    that distance in its direction does not see the target."""

    BINS = 360

    def __init__(self, ox: F64, oy: F64, cx: F64, cy: F64) -> None:
        self.cx, self.cy = cx, cy
        m, bins = cx.shape[0], self.BINS
        self.nearest = np.full((m, bins), np.inf)
        if ox.size == 0:
            return
        dx, dy = ox[None, :] - cx[:, None], oy[None, :] - cy[:, None]
        flat = np.full(m * bins, np.inf)
        np.minimum.at(
            flat, (self._bin(np.arctan2(dy, dx)) + bins * np.arange(m)[:, None]).ravel(), np.hypot(dx, dy).ravel()
        )
        near = flat.reshape(m, bins)
        self.nearest = np.minimum.reduce([np.roll(near, j, axis=1) for j in range(-2, 3)])

    def _bin(self, angle: F64) -> NDArray[np.int64]:
        out: NDArray[np.int64] = np.floor((angle + math.pi) * self.BINS / (2 * math.pi)).astype(np.int64) % self.BINS
        return out

    def hidden(self, camx: F64, camy: F64) -> NDArray[np.bool_]:
        """For cameras at (camx, camy) (manoeuvre x judged time)."""
        dx, dy = camx - self.cx[None, :], camy - self.cy[None, :]
        cols = np.arange(self.cx.shape[0])[None, :]
        out: NDArray[np.bool_] = np.hypot(dx, dy) > self.nearest[cols, self._bin(np.arctan2(dy, dx))]
        return out

    def way_out(self, camx: F64, camy: F64) -> F64:
        """For cameras at the last judged time: how far (m) each would have to move round the target
        to the nearest direction it would see it from, at the same distance (up to 90 degrees)."""
        dx, dy = camx - self.cx[-1], camy - self.cy[-1]
        d = np.hypot(dx, dy)
        offsets = np.arange(-90, 91)
        cand = (self._bin(np.arctan2(dy, dx))[:, None] + offsets[None, :]) % self.BINS
        clear = self.nearest[-1][cand] > d[:, None]
        steps = np.where(clear, np.abs(offsets)[None, :], 180).min(axis=1)
        out: F64 = steps * (2 * math.pi / self.BINS) * d
        return out


def _integrate(v_start: F64, commands: Sequence[F64], accel: float, dt: float) -> tuple[F64, F64, F64, F64]:
    """Poses and speeds (row x step) of rows starting at the origin at `v_start`, given the commands
    (speed, curvature, turn rate; each row x step): the speed ramps towards the speed asked for at
    `accel`, and it turns at speed * curvature + turn rate."""
    v_cmd, k_cmd, w_cmd = commands
    v = np.empty(v_cmd.shape)
    speed = v_start.astype(np.float64)
    dv = accel * dt
    for i in range(v_cmd.shape[1]):
        speed = speed + np.clip(v_cmd[:, i] - speed, -dv, dv)
        v[:, i] = speed
    turn = (v * k_cmd + w_cmd) * dt
    th = np.cumsum(turn, axis=1)
    mid = th - turn / 2
    x = np.cumsum(v * dt * np.cos(mid), axis=1)
    y = np.cumsum(v * dt * np.sin(mid), axis=1)
    return x, y, th, v


class _DistanceField:
    """Distance (m) to the nearest obstacle point, on a grid of `cell` round the base frame's origin,
    `half` each way; less the grid's rounding, so it never says more than the truth."""

    def __init__(self, ox: F64, oy: F64, cell: float, *, half: float) -> None:
        self.cell, self.half = cell, half
        self.n = n = math.ceil(2 * half / cell) + 1
        i = np.floor((ox + half) / cell).astype(np.int64)
        j = np.floor((oy + half) / cell).astype(np.int64)
        inside = (i >= 0) & (i < n) & (j >= 0) & (j < n)
        self.empty = not inside.any()
        if self.empty:
            return
        cv2 = _cv2()
        grid = np.full((n, n), 255, dtype=np.uint8)
        grid[j[inside], i[inside]] = 0
        self.field = cv2.distanceTransform(grid, cv2.DIST_L2, cv2.DIST_MASK_PRECISE) * cell - cell * math.sqrt(2)

    def at(self, x: F64, y: F64) -> F64:
        if self.empty:
            return np.full(np.shape(x), 10.0)
        i = np.floor((x + self.half) / self.cell).astype(np.int64)
        j = np.floor((y + self.half) / self.cell).astype(np.int64)
        inside = (i >= 0) & (i < self.n) & (j >= 0) & (j < self.n)
        out: F64 = np.where(inside, self.field[np.clip(j, 0, self.n - 1), np.clip(i, 0, self.n - 1)], 10.0)
        return out


def _cv2() -> Any:
    return require("cv2", "vision", "the planner's clearance field")
