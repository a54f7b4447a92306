"""Follow a tracked target while avoiding obstacles: a small state machine over the avoider.

    follower = Follower(Footprint(0.19, 0.13), camera, min_turn_radius_m=0.37)   # 0: differential drive
    decision = follower.step(t, xs, ys, track, pose)    # obstacle points (base frame), Track, odometry pose
    robot.drive(decision.linear_m_s, decision.angular_rad_s, clamp=True)

Each step (every control period, typically 20 Hz):

1. **Where the target is.** The tracked bearing and range are matched against the scan
   (`locate_target`): the lidar gives the distance and the target's points. The target's position
   and velocity are kept in the odometry frame. Out of the camera's view, its returns are followed
   in the scan from one revolution to the next, and, lost from the scan too, it is looked for where
   something moves (`MotionDetector`); what the camera then looks at without seeing the target is
   dropped. Between fixes it is steered for at its predicted position for `coast_s`.
2. **What to want.** TRACK: head for the target at its own speed away from the robot plus
   `gain_gap` times the gap error (the gap is between the footprint and the target's surface), down
   to standing at `follow_gap_m`, backing off when it comes closer. YIELD: a target that keeps coming
   (it turns round on its path) is got out of the way of: of the forward and backward arcs the
   robot can drive, the one that keeps it farthest from where the target is heading. SEARCH: no
   target for longer than `coast_s`: go to where it was heading, then turn towards the side it was
   last seen (in place on a differential drive; on the tightest circle on an Ackermann robot).
3. **Arbitration.** The avoider (`host_sdk.perception.avoidance`) gets the wish. The target's points
   are not obstacles to steer round, but the robot must still be able to stop short of them.
   Avoidance deflects the heading (AVOID) when the way to the target is not free, and vetoes speed
   down to zero (STOP) when there is no room; an Ackermann robot that stays blocked, or whose target
   is too far to the side to turn to, backs out on its tightest reverse arc towards the freer side
   (RECOVER); a differential drive too close to something to turn in place backs away first. Every
   command is checked against the swept corridor of the exact arc it drives, forwards or backwards.

The decision is a body twist; send it every step (setpoints are cheap on RoverLink; renewing them is
what keeps the board's watchdog fed).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass, replace
from enum import Enum

import numpy as np
from numpy.typing import NDArray

from host_sdk.autonomy.finder import TargetFinder
from host_sdk.autonomy.memory import arc_pose, to_base, to_world
from host_sdk.autonomy.target import TargetFix
from host_sdk.perception.avoidance import (
    AvoidanceParams,
    Avoider,
    Footprint,
    Plan,
    arc_room,
    direction_clearance,
    safe_speed,
)
from host_sdk.perception.camera import CameraModel
from host_sdk.perception.motion import Mover
from host_sdk.perception.tracking import Track

F64 = NDArray[np.float64]
Pose2D = tuple[float, float, float]


class Mode(Enum):
    SEARCH = "search"
    TRACK = "track"
    AVOID = "avoid"
    YIELD = "yield"
    STOP = "stop"
    RECOVER = "recover"


@dataclass(frozen=True, slots=True)
class FollowParams:
    follow_gap_m: float = 0.5
    """Wanted gap between the robot's footprint and the target's surface."""
    stop_gap_m: float = 0.3
    """Closer than this the robot does not advance."""
    max_speed_m_s: float = 0.45
    reverse_speed_m_s: float = 0.35
    gain_gap: float = 0.8
    """Speed per metre of gap error, 1/s."""
    gain_turn: float = 2.5
    """Differential drive: turn rate per radian of heading error, 1/s."""
    max_turn_rate: float = 1.6
    coast_s: float = 1.5
    """How long a lost target is still steered for at its predicted position."""
    doubt_s: float = 1.0
    """The target followed in the scan alone is dropped when the camera, looking straight at it, has
    not seen it for this long (the cluster followed is something else)."""
    reject_s: float = 5.0
    """How long a place so found not to be the target is not taken for it again."""
    confirm_s: float = 8.0
    """A mover followed this long without the camera confirming it is dropped too."""
    aim_off_axis: float = 0.5
    """Ackermann: with the target farther off the camera's axis than this share of its half field of
    view, the car keeps moving to swing its nose to it (`aim_speed_m_s` at least)."""
    aim_speed_m_s: float = 0.15
    search_speed_m_s: float = 0.25
    search_turn_rate: float = 0.9
    """Differential drive: turn rate while searching."""
    k_turn_leg_m: float = 0.4
    """Ackermann: length of each leg of the K-turn it searches with."""
    yield_horizon_s: float = 2.5
    """A target that would reach the robot within this is got out of the way of."""
    guard_gap_m: float = 0.12
    """No command may bring the robot closer than this to where the target is heading."""
    blocked_s: float = 0.6
    """Ackermann: blocked this long, it backs out."""
    recover_s: float = 1.2
    target_size_m: float = 0.3
    """About how wide the target is (to pick its returns out of the scan)."""


@dataclass(frozen=True, slots=True)
class Decision:
    linear_m_s: float
    angular_rad_s: float
    mode: Mode
    target: TargetFix | None
    """Where the target was found this step (None: not seen)."""
    gap_m: float | None
    """Gap to the target's surface (measured or predicted)."""
    plan: Plan | None = None


@dataclass(frozen=True, slots=True, eq=False)
class _View:
    """One step's picture: obstacle points, the target's points (base frame) and the fix."""

    ox: F64
    oy: F64
    tx: F64
    ty: F64
    fix: TargetFix | None

    @property
    def xy(self) -> tuple[F64, F64]:
        """Every point, the target's too (what the robot must not touch)."""
        return np.concatenate([self.ox, self.tx]), np.concatenate([self.oy, self.ty])


class Follower:
    def __init__(self, footprint: Footprint, camera: CameraModel, *, min_turn_radius_m: float = 0.0,
                 avoidance: AvoidanceParams | None = None, params: FollowParams | None = None) -> None:  # fmt: skip
        self.footprint = footprint
        self.camera = camera
        self.ackermann = min_turn_radius_m > 0
        self.params = params or FollowParams()
        self.avoider = Avoider(footprint, replace(avoidance or AvoidanceParams(), min_turn_radius_m=min_turn_radius_m))
        p = self.params
        self.finder = TargetFinder(camera, target_size_m=p.target_size_m, coast_s=p.coast_s, doubt_s=p.doubt_s,
                                   reject_s=p.reject_s, confirm_s=p.confirm_s)  # fmt: skip
        self.memory = self.finder.memory
        self._search_from: float | None = None
        """Heading when the search began (a whole turn round without the target: go elsewhere)."""
        self._wander: tuple[float, float, float] | None = None
        """(until, x, y) of a place to look from, in the odometry frame."""
        self._search_side = 1.0
        """The way the search turns (+1: left), chosen when it begins."""
        self._going = False
        """The search is on its way to where the target was heading..."""
        self._no_go = False
        """...or found the way there blocked, and looks round instead."""
        self._step_off: tuple[float, float] | None = None
        """(until, heading in the odometry frame) of a step off the target's route."""
        self._k_leg = (1.0, 0.0)
        """Ackermann search: the direction of the current K-turn leg and how far it has gone."""
        self._blocked_since: float | None = None
        self._aim = 0.0
        """Ackermann: the way it drives (+1, -1) to bring the target to the middle of the picture."""
        self._evade: tuple[float, float, float] | None = None
        """(until, linear, angular) of a manoeuvre out of the target's way."""
        self._recover: tuple[float, float, float] | None = None
        """(until, curvature, direction) of a manoeuvre backing out (or, blocked behind, pulling out)."""
        self._t = 0.0
        self._pose: Pose2D = (0.0, 0.0, 0.0)

    # -- the step -------------------------------------------------------------------------------------
    def step(self, t: float, px: F64, py: F64, track: Track | None, pose: Pose2D, *,
             movers: Sequence[Mover] = ()) -> Decision:  # fmt: skip
        """One control step: obstacle points in the base frame now, the latest track, the odometry pose,
        and what moves in the scan (`MotionDetector`), which is where a lost target is looked for."""
        dt = max(0.0, t - self._t)
        self._t, self._pose = t, pose
        p = self.params
        px, py = np.asarray(px, dtype=np.float64), np.asarray(py, dtype=np.float64)
        fix = self.finder.find(t, px, py, track, pose, movers=movers)
        goal = (fix.x_m, fix.y_m) if fix is not None else self.memory.predicted(t, pose, p.coast_s)
        mask = fix.mask if fix is not None else np.zeros(px.shape[0], dtype=bool)
        tx, ty = px[mask], py[mask]
        if goal is not None:
            # Where the target is (or is predicted to be) is in the way whether or not the scan has
            # it: right beside the robot it is inside the lidar's blind range and its returns vanish.
            dx, dy = self._target_outline(goal)
            tx, ty = np.concatenate([tx, dx]), np.concatenate([ty, dy])
        view = _View(px[~mask], py[~mask], tx, ty, fix)
        if self._recover is not None and t < self._recover[0]:
            decision = self._manoeuvre(view, self._recover[1], self._recover[2])
        elif goal is None:
            self._recover = None
            return self._search(view, pose, dt)
        else:
            self._recover = None
            self._search_from = self._wander = None
            decision = self._track(view, goal, pose, dt)
        if goal is None or decision.mode is Mode.YIELD:
            return decision
        return self._guard(decision, view, goal, self.memory.velocity_in(pose))

    def _target_outline(self, surface: tuple[float, float]) -> tuple[F64, F64]:
        """Points round the target's body (base frame), from its surface point nearest the robot."""
        r = self.params.target_size_m / 2
        d = math.hypot(*surface)
        cx, cy = (surface[0] * (1 + r / d), surface[1] * (1 + r / d)) if d > 1e-6 else surface
        a = np.linspace(0.0, 2 * math.pi, 16, endpoint=False)
        return cx + r * np.cos(a), cy + r * np.sin(a)

    def _guard(self, decision: Decision, view: _View, goal: tuple[float, float],
               velocity: tuple[float, float]) -> Decision:  # fmt: skip
        """The last word on every command while the target is known: it must not bring the robot
        within `guard_gap_m` of where the target is heading over the next seconds (the target does
        not avoid the robot). If it would, the robot gets out of the way instead (YIELD)."""
        v = decision.linear_m_s
        k = decision.angular_rad_s / v if abs(v) > 0.01 else 0.0
        if self._separation(v, k, goal, velocity) >= self.params.guard_gap_m:
            return decision
        fp = self.footprint
        return self._yield(view, goal, velocity, math.hypot(goal[0] - fp.x_m, goal[1]) - fp.radius_m)

    def _separation(self, v: float, k: float, goal: tuple[float, float], velocity: tuple[float, float]) -> float:
        """Smallest gap between the footprint, driving at v along curvature k, and the target's surface
        point moving at `velocity`, over the yield horizon."""
        fp = self.footprint
        taus = np.linspace(0.0, self.params.yield_horizon_s, 6)
        cx, cy = goal[0] + velocity[0] * taus, goal[1] + velocity[1] * taus
        x, y, th = arc_pose(v * taus, k)
        fx, fy = x + fp.x_m * np.cos(th), y + fp.x_m * np.sin(th)
        return float(np.min(np.hypot(cx - fx, cy - fy))) - fp.radius_m

    def _room(self, px: F64, py: F64, curvatures: F64, *, reverse: bool = False) -> F64:
        """Clear travel along each arc, with the avoider's margin round the footprint."""
        a = self.avoider.params
        return arc_room(px, py, curvatures, self.footprint, pad_m=a.pad_m, horizon_m=a.window_m, reverse=reverse)

    # -- tracking ---------------------------------------------------------------------------------------
    def _track(self, view: _View, goal: tuple[float, float], pose: Pose2D, dt: float) -> Decision:
        p, fp = self.params, self.footprint
        ox, oy, tx, ty, fix = view.ox, view.oy, view.tx, view.ty, view.fix
        gx, gy = goal
        bearing = math.atan2(gy, gx)
        gap = math.hypot(gx - fp.x_m, gy) - fp.radius_m
        dist = math.hypot(gx, gy)
        vx, vy = self.memory.velocity_in(pose)
        away = vx * math.cos(bearing) + vy * math.sin(bearing)
        if self._evade is not None and self._t < self._evade[0]:
            _, v, w = self._evade
            k = w / v if abs(v) > 0.01 else 0.0
            if v == 0.0 or self._separation(v, k, goal, (vx, vy)) >= p.guard_gap_m:
                return self._keep_yielding(view, gap)
            # The target turned: the move held to get out of its way now leads into it. Choose again.
            return self._yield(view, goal, (vx, vy), gap)
        self._evade = None
        if gap < p.follow_gap_m + 0.3 and -away * p.yield_horizon_s > gap - p.stop_gap_m + 0.1:
            return self._yield(view, goal, (vx, vy), gap)
        want = max(-p.reverse_speed_m_s, min(p.max_speed_m_s, away + p.gain_gap * (gap - p.follow_gap_m)))
        if gap < p.stop_gap_m:
            want = min(want, 0.0)
        if not self.ackermann:
            want *= max(0.0, math.cos(bearing)) ** 2  # face it first, then go
        elif abs(bearing) > math.radians(40) and gap < p.follow_gap_m + 0.6:
            # Too far to the side to turn to without closing in: back out swinging the nose round.
            return self._start_backing(view, side=1.0 if bearing > 0 else -1.0)
        aim = self._aim_direction(gx, gy, gap)
        if aim < 0:
            want = min(want, -p.aim_speed_m_s)
        if want < -0.02:
            return self._back_off(view, gap, -want, bearing)
        curvature = 2 * math.sin(bearing) / max(dist, 0.3)
        if aim > 0:
            # Drive, on the tightest arc towards it: pure pursuit's gentle arc at a creeping speed
            # would leave it at the edge of the picture, or out of it.
            curvature = math.copysign(self.avoider.params.max_curvature, bearing)
            want = max(want, p.search_speed_m_s)
        plan = self.avoider.plan(ox, oy, bearing, max(want, 0.0), target_xy=(tx, ty), curvature=curvature, goal_m=dist)
        v, w = self._command(plan, view, turn_to=plan.direction_rad)
        if not self.ackermann and v <= 0.02 and abs(plan.direction_rad) > 0.3 and not self._can_spin(view):
            # It has to turn to the target and is too close to something to turn on the spot: get
            # room first (standing there, it would wait for ever).
            return self._unstick(view, gap)
        mode = Mode.AVOID if plan.deflected else Mode.TRACK
        if abs(v) < 0.02 and abs(w) < 0.05:
            mode = Mode.STOP
        if self._stuck(want > 0.05 and v < 0.02, dt):
            return self._start_backing(view, side=1.0 if bearing > 0 else -1.0)
        return Decision(v, w, mode, fix, gap, plan)

    def _aim_direction(self, gx: float, gy: float, gap: float) -> float:
        """Ackermann: +1 or -1 while the car must move to bring the target (at gx, gy) towards the
        middle of the picture, 0 otherwise. A car turns only as it drives: standing at the gap with
        the target off to one side, it loses it there. Forwards on the tightest arc towards it while
        there is gap to spare, else backwards with the wheels turned away (`_back_off`): both swing
        the nose towards it. The way chosen is kept until the gap runs out, so it does not chatter."""
        p = self.params
        if (
            not self.ackermann
            or gap < p.stop_gap_m
            or (abs(self.camera.off_axis_rad(gx, gy)) < p.aim_off_axis * self.camera.half_fov_rad)
        ):
            self._aim = 0.0
        elif self._aim == 0.0:
            self._aim = 1.0 if gap > p.follow_gap_m else -1.0
        elif self._aim > 0 and gap < p.stop_gap_m + 0.1:
            self._aim = -1.0
        elif self._aim < 0 and gap > p.follow_gap_m + 0.3:
            self._aim = 1.0
        return self._aim

    def _yield(self, view: _View, goal: tuple[float, float], velocity: tuple[float, float], gap: float) -> Decision:
        """The move that keeps the robot farthest from the coming target: an arc forwards or backwards,
        standing still, or (differential drive) turning on the spot to leave sideways."""
        p, a = self.params, self.avoider.params
        (ox, oy), fix = view.xy, view.fix  # the target where it is now is in the way too
        horizon = p.yield_horizon_s
        taus = np.linspace(0.0, horizon, 11)
        tx, ty = goal[0] + velocity[0] * taus, goal[1] + velocity[1] * taus

        rx, ry = self.memory.route_in(self._pose)
        clear_of_route = self.footprint.radius_m + p.target_size_m / 2 + 0.1

        def score(x: F64, y: F64, th: F64) -> float:
            fx, fy = x + self.footprint.x_m * np.cos(th), y + self.footprint.x_m * np.sin(th)
            sep = float(np.min(np.hypot(tx - fx, ty - fy))) - self.footprint.radius_m
            facing = math.cos(math.atan2(ty[-1] - y[-1], tx[-1] - x[-1]) - th[-1])
            # Where it ends up should be off the route the target walks: it turns, and comes back along it.
            on_route = float(np.min(np.hypot(rx - fx[-1], ry - fy[-1]), initial=math.inf)) < clear_of_route
            return min(sep, 1.0) + 0.15 * facing - 0.3 * on_route

        zero = np.zeros_like(taus)
        best = (score(zero, zero, zero) + 0.05, 0.0, 0.0, 0.0)  # (score, v, w, how long): standing still
        curvatures = self.avoider.curvatures[:: max(1, len(self.avoider.curvatures) // 10)]
        for direction in (1.0, -1.0):
            free = self._room(ox, oy, curvatures, reverse=direction < 0)
            for k, room in zip(curvatures, free, strict=True):
                v = direction * min(p.reverse_speed_m_s, safe_speed(float(room), a, ttc=False))
                if abs(v) >= 0.05:
                    cand = score(*arc_pose(v * taus, float(k)))
                    if cand > best[0]:
                        best = (cand, v, v * float(k), 0.5 * horizon)
        if not self.ackermann and self._can_spin(view):
            best = max(best, *self._spin_and_go(view, taus, score), key=lambda c: c[0])
        _, v, w, hold = best
        if v == 0.0 and w == 0.0:
            return Decision(0.0, 0.0, Mode.STOP, fix, gap)
        self._evade = (self._t + hold, v, w)  # commit: re-choosing every step dithers
        return Decision(v, w, Mode.YIELD, fix, gap)

    def _spin_and_go(self, view: _View, taus: F64,
                     score: Callable[[F64, F64, F64], float]) -> list[tuple[float, float, float, float]]:  # fmt: skip
        """Differential drive: turn a quarter turn either way on the spot, then drive straight out."""
        p, a = self.params, self.avoider.params
        x, y = view.xy
        out = []
        for side in (1.0, -1.0):
            heading = side * math.pi / 2
            spin_s = abs(heading) / p.max_turn_rate
            clear = float(direction_clearance(x - self.footprint.x_m, y, np.array([heading]),
                                              self.footprint.radius_m + a.pad_m, horizon_m=a.window_m)[0])  # fmt: skip
            v = min(p.reverse_speed_m_s, safe_speed(clear, a, ttc=False))
            th = np.where(taus < spin_s, side * p.max_turn_rate * taus, heading)
            run = v * np.maximum(taus - spin_s, 0.0)
            out.append((score(run * math.cos(heading), run * math.sin(heading), th), 0.0, side * p.max_turn_rate,
                        spin_s))  # fmt: skip
        return out

    def _keep_yielding(self, view: _View, gap: float) -> Decision:
        assert self._evade is not None
        _, v, w = self._evade
        a, fix = self.avoider.params, view.fix
        if v == 0.0:  # turning on the spot
            if self._can_spin(view):
                return Decision(0.0, w, Mode.YIELD, fix, gap)
            self._evade = None
            return Decision(0.0, 0.0, Mode.STOP, fix, gap)
        x, y = view.xy
        k = w / v
        free = float(self._room(x, y, np.array([k]), reverse=v < 0)[0])
        speed = min(abs(v), safe_speed(free, a, ttc=False))
        if speed < 0.02:
            self._evade = None
            return Decision(0.0, 0.0, Mode.STOP, fix, gap)
        v = math.copysign(speed, v)
        return Decision(v, v * k, Mode.YIELD, fix, gap)

    def _command(self, plan: Plan, view: _View, *, turn_to: float) -> tuple[float, float]:
        """The plan as a body twist, checked once more on the exact arc it drives."""
        p = self.params
        ox, oy, tx, ty = view.ox, view.oy, view.tx, view.ty
        if self.ackermann:
            return plan.speed_m_s, plan.speed_m_s * plan.curvature
        w = max(-p.max_turn_rate, min(p.max_turn_rate, p.gain_turn * turn_to))
        v = plan.speed_m_s * max(0.0, math.cos(turn_to))
        if v > 0.02:
            k = np.array([w / v])
            a = self.avoider.params
            free = float(self._room(ox, oy, k)[0])
            on_target = float(self._room(tx, ty, k)[0])
            v = min(v, safe_speed(free, a), safe_speed(on_target, a, ttc=False))
        if v <= 0.02:
            v = 0.0
            if not self._can_spin(view):
                w = 0.0
        return v, w

    def _back_off(self, view: _View, gap: float, speed: float, bearing: float) -> Decision:
        """Reverse away from a target that came too close, still facing it: a differential drive turns
        to it as it goes; an Ackermann robot reverses with its wheels turned away from it, which swings
        the nose towards it (straight back, a target off to one side leaves the camera's view)."""
        a, fix = self.avoider.params, view.fix
        x, y = view.xy
        if self.ackermann:
            k = -math.copysign(min(a.max_curvature, 2.5 * abs(math.sin(bearing))), bearing)
            free = float(self._room(x, y, np.array([k]), reverse=True)[0])
            v = min(speed, safe_speed(free, a, ttc=False))
            if v < 0.02:
                return Decision(0.0, 0.0, Mode.STOP, fix, gap)
            return Decision(-v, -v * k, Mode.TRACK, fix, gap)
        w = max(-1.0, min(1.0, self.params.gain_turn * bearing))
        free = float(self._room(x, y, np.array([-w / speed if speed > 0 else 0.0]), reverse=True)[0])
        v = min(speed, safe_speed(free, a, ttc=False))
        if v < 0.02:
            return Decision(0.0, w if self._can_spin(view) else 0.0, Mode.STOP, fix, gap)
        return Decision(-v, w, Mode.TRACK, fix, gap)

    # -- searching --------------------------------------------------------------------------------------
    def _search(self, view: _View, pose: Pose2D, dt: float) -> Decision:
        """Step off the target's route once, go to where it was heading, and look round towards the side
        it went; after a whole turn round without it, go somewhere else to look from (`_wander`). The
        side is chosen when the search begins and kept: a search that changes its mind sees nothing."""
        p = self.params
        last = self.memory.predicted(self._t, pose, 8.0)
        if self._search_from is None:
            self._search_from = pose[2]
            self._search_side = self.memory.side if last is None else (1.0 if last[1] >= 0 else -1.0)
            off = self.memory.off_route(pose, self.footprint.radius_m, self.footprint.x_m)
            self._step_off = None if off is None else (self._t + 1.5, pose[2] + off)
            self._going = self._no_go = False
        if self._wander is None and abs(pose[2] - self._search_from) > 2 * math.pi:
            self._wander = self._wander_goal(view, pose)
        if self._wander is not None:
            decision = self._go_wander(view, pose, dt)
            if decision is not None:
                return decision
        if self._step_off is not None:  # standing on its route while it cannot be seen: off it first
            until, heading = self._step_off
            decision = self._search_towards(view, math.remainder(heading - pose[2], 2 * math.pi), dt)
            if self._t < until and decision is not None:
                return decision
            self._step_off = None
        if last is not None and math.hypot(*last) > 0.8 and not self._no_go:
            decision = self._search_towards(view, math.atan2(last[1], last[0]), dt)
            if decision is not None:
                self._going = True
                return decision
            # Going there and the way is blocked: look round from here (not back and forth).
            self._no_go = self._going
        if self.ackermann:
            return self._k_turn(view, dt)
        if self._can_spin(view):
            return Decision(0.0, self._search_side * p.search_turn_rate, Mode.SEARCH, None, None)
        return self._unstick(view)

    def _search_towards(self, view: _View, bearing: float, dt: float) -> Decision | None:
        """Drive towards `bearing` at search speed, turning no faster than `search_turn_rate` (so the
        motion detector keeps comparing revolutions). None when that is not the way to go: the bearing
        is behind the robot's turning (it looks round instead) or the way there is blocked."""
        p = self.params
        if (not self.ackermann and abs(bearing) > (1.0 if self._going else 0.5)) or abs(bearing) > 2.0:
            return None
        plan = self.avoider.plan(view.ox, view.oy, bearing, p.search_speed_m_s, target_xy=(view.tx, view.ty))
        if abs(plan.direction_rad - bearing) > 1.0:
            return None
        v, w = self._command(plan, view, turn_to=plan.direction_rad)
        w = max(-p.search_turn_rate, min(p.search_turn_rate, w))
        if self._stuck(v < 0.02, dt):
            return self._start_backing(view, side=self._search_side)
        if v < 0.02 and not self.ackermann:
            return None
        return Decision(v, w, Mode.SEARCH, None, None, plan)

    def _wander_goal(self, view: _View, pose: Pose2D) -> tuple[float, float, float]:
        """(until, x, y): where it was last seen if that is some way off (it comes back along its
        route), else 1.5 m into the most open direction."""
        seen = self.memory.seen
        if seen is not None:
            bx, by = to_base(pose, seen[1], seen[2])
            if math.hypot(bx, by) > 1.0:
                return self._t + 8.0, seen[1], seen[2]
        _, clear = self.avoider.free_directions(view.ox, view.oy)
        best = float(self.avoider.directions[int(np.argmax(clear))])
        wx, wy = to_world(pose, 1.5 * math.cos(best), 1.5 * math.sin(best))
        return self._t + 8.0, wx, wy

    def _go_wander(self, view: _View, pose: Pose2D, dt: float) -> Decision | None:
        assert self._wander is not None
        until, wx, wy = self._wander
        gx, gy = to_base(pose, wx, wy)
        if self._t > until or math.hypot(gx, gy) < 0.5:
            self._wander = None
            self._search_from = pose[2]  # look round again from here
            return None
        bearing = math.atan2(gy, gx)
        if not self.ackermann and abs(bearing) > 0.6 and self._can_spin(view):
            return Decision(0.0, math.copysign(self.params.search_turn_rate, bearing), Mode.SEARCH, None, None)
        plan = self.avoider.plan(view.ox, view.oy, bearing, self.params.search_speed_m_s, target_xy=(view.tx, view.ty),
                                 goal_m=math.hypot(gx, gy))  # fmt: skip
        v, w = self._command(plan, view, turn_to=plan.direction_rad)
        if self._stuck(v < 0.02, dt):
            return self._start_backing(view, side=1.0 if bearing > 0 else -1.0)
        return Decision(v, w, Mode.SEARCH, None, None, plan)

    def _k_turn(self, view: _View, dt: float) -> Decision:
        """Ackermann: turn round on the spot as a driver does in a narrow street, forwards with the
        wheels to one side, backwards with them to the other, each leg `k_turn_leg_m` or until the
        way is not clear; the heading turns the same way on both legs and the camera sweeps round."""
        p, a = self.params, self.avoider.params
        x, y = view.xy
        leg, travelled = self._k_leg
        k = self._search_side * a.max_curvature * leg  # forwards: towards the side; backwards: away from it
        free = float(self._room(x, y, np.array([k]), reverse=leg < 0)[0])
        v = min(p.search_speed_m_s, safe_speed(free, a, ttc=False))
        if v < 0.05 or travelled >= p.k_turn_leg_m:
            self._k_leg = (-leg, 0.0)
            return Decision(0.0, 0.0, Mode.SEARCH, None, None)
        self._k_leg = (leg, travelled + v * dt)
        return Decision(leg * v, leg * v * k, Mode.SEARCH, None, None)

    def _can_spin(self, view: _View) -> bool:
        """A differential drive turning in place sweeps a disc round its pose point."""
        fp = self.footprint
        reach = abs(fp.x_m) + fp.radius_m + 0.03
        x, y = view.xy
        return not bool((np.hypot(x, y) < reach).any())

    def _unstick(self, view: _View, gap: float | None = None) -> Decision:
        """Too close to something to turn in place: move straight away from it, whichever way is free."""
        a = self.avoider.params
        x, y = view.xy
        ahead = float(self._room(x, y, np.array([0.0]))[0])
        behind = float(self._room(x, y, np.array([0.0]), reverse=True)[0])
        v = min(0.15, safe_speed(max(ahead, behind), a, ttc=False))
        if v < 0.02:
            return Decision(0.0, 0.0, Mode.STOP, view.fix, gap)
        return Decision(v if ahead >= behind else -v, 0.0, Mode.RECOVER, view.fix, gap)

    # -- backing out (Ackermann) ------------------------------------------------------------------------
    def _stuck(self, blocked: bool, dt: float) -> bool:
        """Ackermann: True once it has been unable to move on for `blocked_s`."""
        if not self.ackermann or not blocked:
            self._blocked_since = None
            return False
        self._blocked_since = self._t if self._blocked_since is None else self._blocked_since
        if self._t - self._blocked_since < self.params.blocked_s:
            return False
        self._blocked_since = None
        return True

    def _start_backing(self, view: _View, side: float) -> Decision:
        """Reverse on the tightest arc that swings the nose towards `side` (or, if that is blocked,
        whichever reverse arc has the most room) for `recover_s`. With no room behind, drive forwards
        on the tightest arc towards `side` that has room instead: standing still fixes nothing."""
        a, fix = self.avoider.params, view.fix
        x, y = view.xy
        options = (-side * a.max_curvature, 0.0, side * a.max_curvature)
        free = self._room(x, y, np.array(options), reverse=True)
        usable = [i for i in range(3) if free[i] > 0.25]
        if usable:
            k = options[usable[0]] if 0 in usable else options[int(np.argmax(free))]
            self._recover = (self._t + self.params.recover_s, k, -1.0)
            return self._manoeuvre(view, k, -1.0)
        forwards = options[::-1]
        ahead = self._room(x, y, np.array(forwards))
        velocity = self.memory.velocity_in(self._pose)
        usable = [i for i in range(3) if ahead[i] > 0.35 and (fix is None or self._separation(
            0.2, forwards[i], (fix.x_m, fix.y_m), velocity) >= self.params.guard_gap_m)]  # fmt: skip
        if not usable:
            return Decision(0.0, 0.0, Mode.STOP, fix, None)
        k = forwards[usable[0]]
        self._recover = (self._t + self.params.recover_s, k, 1.0)
        return self._manoeuvre(view, k, 1.0)

    def _manoeuvre(self, view: _View, k: float, direction: float) -> Decision:
        """Drive on curvature k, forwards (+1) or backwards (-1), as far as there is room."""
        a, fix = self.avoider.params, view.fix
        px, py = view.xy
        free = float(self._room(px, py, np.array([k]), reverse=direction < 0)[0])
        v = min(self.params.reverse_speed_m_s * 0.6, safe_speed(free, a, ttc=False))
        if v < 0.02:
            self._recover = None
            return Decision(0.0, 0.0, Mode.STOP, fix, None)
        return Decision(direction * v, direction * v * k, Mode.RECOVER, fix, None)
