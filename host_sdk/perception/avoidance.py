"""Obstacle avoidance over the whole scan: where the footprint can go, which way to turn, how fast.

Three pieces, each usable alone, combined by `Avoider.plan`:

- `arc_free_distance`: for each candidate curvature, how far the pose point can travel along that
  arc before the robot's footprint (a disc, as the emulator and most small robots are modelled)
  touches any obstacle point. This is the corridor the footprint sweeps, exactly, for straight and
  curved motion, forwards or backwards: not a few beams straight ahead.
- `direction_clearance` + `ackermann_mask`: a polar picture of free directions over all 360
  degrees (each direction's clear length for a corridor as wide as the footprint plus a margin), in
  which an Ackermann robot's unreachable directions are masked as in VFH+: an obstacle inside the
  disc swept by the tightest left (right) turn blocks every direction left (right) of it. The free
  directions form gaps; the planner takes the free direction nearest the goal, keeping to the side
  it chose before (no dithering between two equal gaps).
- `safe_speed`: the highest speed from which the robot still stops short of the obstacle on its arc
  (reaction latency plus braking at `max_decel`), also capped so that the time to collision at that
  speed stays above `min_ttc_s`: the robot slows smoothly as the way ahead closes in.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np
from numpy.typing import NDArray

from host_sdk.body import Footprint

F64 = NDArray[np.float64]


@dataclass(frozen=True, slots=True)
class AvoidanceParams:
    margin_m: float = 0.08
    """Clearance kept between the footprint and obstacles when choosing a direction."""
    stop_margin_m: float = 0.1
    """What is left between the footprint and the obstacle after an emergency stop."""
    pad_m: float = 0.04
    """Margin round the footprint when checking an arc: a real robot never drives exactly the arc it
    was told to (wheel speed control at low speed, odometry between scans)."""
    max_decel_m_s2: float = 0.8
    """Braking the speed law assumes (well under what the robot can do, for slippery floors)."""
    latency_s: float = 0.3
    """Time from a scan to the wheels reacting: scan age, loop period, control tick, motor lag."""
    min_ttc_s: float = 1.2
    """Time to collision kept at the commanded speed."""
    lookahead_m: float = 0.7
    """Pure-pursuit distance turning a direction into a curvature."""
    window_m: float = 3.0
    """Obstacles farther than this do not shape the choice of direction."""
    clear_m: float = 1.0
    """A direction is free when a corridor of this length along it is clear."""
    max_curvature: float = 4.0
    """Tightest arc (1/m) considered; an Ackermann robot's comes from its minimum turning radius."""
    min_turn_radius_m: float = 0.0
    """0 for differential drive (it can turn in place); the Ackermann robot's minimum radius."""
    direction_bins: int = 180
    arcs: int = 41
    """Candidate curvatures evaluated between -max_curvature and +max_curvature."""


def arc_free_distance(
    px: F64, py: F64, curvatures: F64, footprint: Footprint, *, horizon_m: float = 5.0, reverse: bool = False
) -> F64:
    """Travel of the pose point along each arc (curvature 1/m, positive turns left) before the footprint
    touches one of the points (base frame); `horizon_m` where nothing is in the way. `reverse`: moving
    backwards along the same arcs."""
    k = np.asarray(curvatures, dtype=np.float64).reshape(-1, 1)
    x = np.asarray(px, dtype=np.float64).reshape(1, -1)
    y = np.asarray(py, dtype=np.float64).reshape(1, -1)
    fx = footprint.x_m
    if reverse:  # mirror front and back: backwards on an arc is forwards on the mirrored picture
        x, fx = -x, -fx
    r = footprint.radius_m
    out = np.full(k.shape[0], float(horizon_m))
    if x.size == 0:
        return out
    straight = np.abs(k[:, 0]) < 1e-6
    with np.errstate(invalid="ignore", divide="ignore"):
        # Straight: the disc's centre runs along y = 0 from x = fx.
        lat = np.abs(y)
        s_straight = x - np.sqrt(np.maximum(r * r - y * y, 0.0)) - fx
        s_straight = np.where((lat < r) & (x - fx > -np.sqrt(np.maximum(r * r - y * y, 0.0))), s_straight, np.inf)
        # Curved: everything turns about the centre of rotation (0, rho).
        rho = np.where(straight[:, None], 1e6, 1.0 / np.where(straight[:, None], 1.0, k))
        sign = np.sign(rho)
        rc = np.hypot(fx, rho)
        rp = np.hypot(x, y - rho)
        phi_c = np.arctan2(-rho, fx)
        phi_p = np.arctan2(y - rho, x)
        dphi = np.mod(sign * (phi_p - phi_c), 2 * math.pi)
        cos_d = (rc * rc + rp * rp - r * r) / (2 * rc * np.maximum(rp, 1e-12))
        delta = np.arccos(np.clip(cos_d, -1.0, 1.0))
        hit = np.abs(rp - rc) < r
        s_arc = np.where(hit, np.abs(rho) * np.maximum(dphi - delta, 0.0), np.inf)
    s = np.where(straight[:, None], s_straight, s_arc)
    inside = np.hypot(x - fx, y) < r
    s = np.where(inside, 0.0, s)
    free: F64 = np.minimum(out, np.maximum(s.min(axis=1), 0.0))
    return free


def arc_room(
    px: F64,
    py: F64,
    curvatures: F64,
    footprint: Footprint,
    *,
    pad_m: float,
    horizon_m: float = 5.0,
    reverse: bool = False,
) -> F64:
    """`arc_free_distance` for the footprint grown by `pad_m`, the margin a real robot needs (its path
    is never quite the commanded arc). Points already inside that margin do not block every arc:
    they block only motion that brings the footprint any closer to them than it is now, so a robot
    that got too close can still move away."""
    x, y = np.asarray(px, dtype=np.float64), np.asarray(py, dtype=np.float64)
    gap = np.hypot(x - footprint.x_m, y) - footprint.radius_m
    near = gap < pad_m
    grown = Footprint(footprint.radius_m + pad_m, footprint.x_m)
    room = arc_free_distance(x[~near], y[~near], curvatures, grown, horizon_m=horizon_m, reverse=reverse)
    if near.any():
        closest = max(0.0, float(gap[near].min()) - 0.005)
        tight = Footprint(footprint.radius_m + closest, footprint.x_m)
        room = np.minimum(
            room, arc_free_distance(x[near], y[near], curvatures, tight, horizon_m=horizon_m, reverse=reverse)
        )
    return room


def direction_clearance(px: F64, py: F64, directions: F64, half_width_m: float, *, horizon_m: float = 5.0) -> F64:
    """For each direction (rad), the clear length of a straight corridor `2 * half_width_m` wide
    leaving the pose point that way."""
    d = np.asarray(directions, dtype=np.float64).reshape(-1, 1)
    x = np.asarray(px, dtype=np.float64).reshape(1, -1)
    y = np.asarray(py, dtype=np.float64).reshape(1, -1)
    out = np.full(d.shape[0], float(horizon_m))
    if x.size == 0:
        return out
    c, s = np.cos(d), np.sin(d)
    along = c * x + s * y
    across = -s * x + c * y
    inside = np.abs(across) < half_width_m
    reach = along - np.sqrt(np.maximum(half_width_m**2 - across**2, 0.0))
    # Only what lies ahead along a direction blocks it: moving away from a point already within the
    # margin is how the robot gets its margin back.
    blocked = inside & (along > 0)
    length = np.where(blocked, np.maximum(reach, 0.0), np.inf).min(axis=1)
    clear: F64 = np.minimum(out, length)
    return clear


def ackermann_mask(
    px: F64, py: F64, directions: F64, min_turn_radius_m: float, clearance_m: float
) -> NDArray[np.bool_]:
    """Directions an Ackermann robot can still head for (VFH+'s masked histogram): an obstacle within
    `clearance_m` of the circle the tightest left turn sweeps blocks every direction left of it, and
    the same on the right. Directions are -pi..pi, counter-clockwise from forward."""
    d = np.asarray(directions, dtype=np.float64)
    ok = np.ones(d.shape[0], dtype=bool)
    if min_turn_radius_m <= 0 or np.asarray(px).size == 0:
        return ok
    x, y = np.asarray(px, dtype=np.float64), np.asarray(py, dtype=np.float64)
    bearing = np.arctan2(y, x)
    limit_left, limit_right = math.pi, -math.pi
    for side in (1.0, -1.0):
        cy = side * min_turn_radius_m
        near = np.hypot(x, y - cy) < min_turn_radius_m + clearance_m
        on_side = near & (side * bearing > 0)
        if on_side.any():
            edge = float(np.min(side * bearing[on_side]))
            if side > 0:
                limit_left = edge
            else:
                limit_right = -edge
    ok &= (d <= limit_left) & (d >= limit_right)
    return ok


def stopping_distance(speed_m_s: float, params: AvoidanceParams) -> float:
    """Distance covered while reacting and braking from `speed_m_s`, plus the stop margin."""
    v = abs(speed_m_s)
    return v * params.latency_s + v * v / (2 * params.max_decel_m_s2) + params.stop_margin_m


def safe_speed(free_m: float, params: AvoidanceParams, *, ttc: bool = True) -> float:
    """Highest speed that still stops within `free_m` (and keeps the time to collision, if `ttc`)."""
    room = free_m - params.stop_margin_m
    if room <= 0:
        return 0.0
    a, t = params.max_decel_m_s2, params.latency_s
    v = a * (-t + math.sqrt(t * t + 2 * room / a))
    if ttc:
        v = min(v, room / params.min_ttc_s)
    return max(0.0, v)


@dataclass(frozen=True, slots=True)
class Plan:
    """What the avoider allows: a speed and a curvature (turn rate = speed * curvature)."""

    speed_m_s: float
    curvature: float
    direction_rad: float
    """Direction chosen (the goal's, or the free one nearest it)."""
    free_m: float
    """Clear travel along the chosen arc."""
    blocked: bool
    """No free direction near the goal, or not even a stop's worth of room along the arc."""
    deflected: bool
    """The goal direction was not free: the plan steers round an obstacle."""


class Avoider:
    """Turns a goal bearing and a wanted speed into a safe (speed, curvature) from filtered obstacles."""

    def __init__(self, footprint: Footprint, params: AvoidanceParams | None = None) -> None:
        self.footprint = footprint
        p = params or AvoidanceParams()
        if p.min_turn_radius_m > 0:
            p = replace(p, max_curvature=min(p.max_curvature, 1.0 / p.min_turn_radius_m))
        self.params = p
        self.directions = -math.pi + (np.arange(p.direction_bins) + 0.5) * 2 * math.pi / p.direction_bins
        self.curvatures = np.linspace(-p.max_curvature, p.max_curvature, p.arcs)
        self._side = 0.0
        """+1 / -1: the side the last deflection went (kept while the obstacle lasts)."""

    def free_directions(self, px: F64, py: F64, reach_m: float | None = None) -> tuple[NDArray[np.bool_], F64]:
        """(free?, clear length) for every direction bin; free means `clear_m` (or `reach_m`, if
        shorter: the goal is nearer than that) of clear corridor."""
        p, fp = self.params, self.footprint
        near = np.hypot(px, py) < p.window_m
        x, y = px[near], py[near]
        half = fp.radius_m + p.margin_m
        # The corridor leaves from the footprint's centre, not the pose point.
        clear = direction_clearance(x - fp.x_m, y, self.directions, half, horizon_m=p.window_m)
        free = clear >= (p.clear_m if reach_m is None else max(0.2, min(p.clear_m, reach_m)))
        free &= ackermann_mask(x, y, self.directions, p.min_turn_radius_m, half)
        return free, clear

    def choose_direction(self, free: NDArray[np.bool_], goal_rad: float) -> tuple[float | None, bool]:
        """The free direction nearest the goal (None: none free), and whether it differs from the goal."""
        d = self.directions
        off = np.angle(np.exp(1j * (d - goal_rad)))
        goal_i = int(np.argmin(np.abs(off)))
        if free[goal_i]:
            self._side = 0.0
            return goal_rad, False
        if not free.any():
            return None, True
        cost = np.abs(off) + np.where(np.sign(off) == self._side, 0.0, 0.35 if self._side else 0.0)
        cost = np.where(free, cost, np.inf)
        i = int(np.argmin(cost))
        # Aim a little inside the gap, away from its edge, when the gap is wide enough.
        step = int(np.sign(off[i])) or 1
        j = i
        for _ in range(3):
            nxt = (j + step) % d.shape[0]
            if not free[nxt]:
                break
            j = nxt
        self._side = float(np.sign(off[i]))
        return float(d[j]), True

    def curvature_for(self, direction_rad: float) -> float:
        """Pure pursuit towards a point `lookahead_m` away in that direction, within the robot's limits."""
        p = self.params
        if abs(direction_rad) >= math.pi / 2:
            k = math.copysign(p.max_curvature, direction_rad)
        else:
            k = 2 * math.sin(direction_rad) / p.lookahead_m
        return max(-p.max_curvature, min(p.max_curvature, k))

    def plan(
        self,
        px: F64,
        py: F64,
        goal_rad: float,
        speed_m_s: float,
        *,
        target_xy: tuple[F64, F64] | None = None,
        curvature: float | None = None,
        goal_m: float | None = None,
    ) -> Plan:
        """Steer for `goal_rad` at up to `speed_m_s` among obstacle points (px, py), base frame.

        `target_xy`: points of the followed target. They do not repel the choice of direction (the
        robot is meant to approach the target) and do not count towards the time-to-collision cap
        (the target moves away), but the robot must still be able to stop short of them.
        `curvature`: the wanted arc when the goal is not a direction (the behaviour's own steering).
        `goal_m`: how far the goal is (a direction towards a nearer goal needs less clear corridor)."""
        p, fp = self.params, self.footprint
        free, _ = self.free_directions(px, py, goal_m)
        direction, deflected = self.choose_direction(free, goal_rad)
        if direction is None:
            return Plan(0.0, 0.0, goal_rad, 0.0, True, True)
        k = self.curvature_for(direction) if (deflected or curvature is None) else curvature
        k = max(-p.max_curvature, min(p.max_curvature, k))
        # The arc through the chosen direction may still clip something the straight corridor missed:
        # take the nearest arc (towards the chosen side) that leaves enough room.
        free_arcs = arc_room(px, py, self.curvatures, fp, pad_m=p.pad_m, horizon_m=p.window_m)
        need = stopping_distance(speed_m_s, p)
        own = float(arc_room(px, py, np.array([k]), fp, pad_m=p.pad_m, horizon_m=p.window_m)[0])
        if own < need and deflected:
            ok = free_arcs >= need
            if ok.any():
                i = int(np.argmin(np.where(ok, np.abs(self.curvatures - k), np.inf)))
                k, own = float(self.curvatures[i]), float(free_arcs[i])
        v = min(speed_m_s, safe_speed(own, p))
        if target_xy is not None and target_xy[0].size:
            on_target = float(arc_free_distance(target_xy[0], target_xy[1], np.array([k]), fp, horizon_m=p.window_m)[0])
            v = min(v, safe_speed(on_target, p, ttc=False))
        blocked = own <= p.stop_margin_m + 1e-9
        return Plan(v, k, direction, own, blocked, deflected)
