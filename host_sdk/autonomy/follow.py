"""Follow a tracked target while avoiding obstacles: a small state machine round a manoeuvre planner.

    follower = Follower(Footprint(0.19, 0.13), camera, min_turn_radius_m=0.37)   # 0: differential drive
    decision = follower.step(t, xs, ys, track, pose)    # obstacle points (base frame), Track, odometry pose
    robot.drive(decision.linear_m_s, decision.angular_rad_s, clamp=True)

Each step (every control period, typically 20 Hz):

1. **Where the target is.** The tracked bearing and range are matched against the scan
   (`locate_target`): the lidar gives the distance and the target's points. The target's position
   and velocity are kept in the odometry frame. Out of the camera's view, its returns are followed
   in the scan from one revolution to the next, and, lost from the scan too, it is looked for where
   something moves (`MotionDetector`); what the camera then looks at without seeing the target is
   dropped (`TargetFinder`).
2. **Known, or lost a little while: plan.** The `ViewPlanner` chooses the manoeuvre of the next
   seconds that keeps the target (or where it is predicted to be, for `coast_s + look_s` after it was
   last found) in the camera's picture and in sight past the obstacles, at `follow_gap_m`, clear of
   the obstacles and out of the target's way (it does not avoid the robot). Modes: TRACK; AVOID when
   the obstacles changed the choice; YIELD when it is getting out of the target's way; STOP when it
   stands; SEARCH while it looks where the target was predicted to go.
3. **Lost: search.** Step off the target's remembered route once, go to where it was heading, then
   look round towards the side it was last seen (on the spot on a differential drive, by K-turns on
   an Ackermann robot); after a whole turn round, look from elsewhere. Blocked, an Ackermann robot
   backs out (RECOVER).

The decision is a body twist; send it every step (setpoints are cheap on RoverLink; renewing them is
what keeps the board's watchdog fed).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, replace

import numpy as np
from numpy.typing import NDArray

from host_sdk.autonomy.finder import TargetFinder
from host_sdk.autonomy.follow_params import (
    BACK_OUT_ROOM_M,
    GO_THERE_M,
    LOOK_AHEAD_S,
    MANOEUVRE_SPEED_SHARE,
    MIN_DRIVE_M_S,
    MIN_LEG_M_S,
    PULL_OUT_ROOM_M,
    SPIN_CLEARANCE_M,
    STEP_OFF_S,
    UNSTICK_M_S,
    WANDER_ARRIVED_M,
    WANDER_FAR_M,
    WANDER_M,
    WANDER_S,
    WANDER_SPIN_RAD,
    Aim,
    FollowParams,
    Manoeuvre,
    Mode,
    Place,
)
from host_sdk.autonomy.memory import to_base, to_world
from host_sdk.autonomy.planner import PlanChoice, PlannerParams, ViewPlanner
from host_sdk.autonomy.target import TargetFix
from host_sdk.body import CameraModel, Footprint
from host_sdk.perception.avoidance import AvoidanceParams, Avoider, Plan, arc_room, safe_speed
from host_sdk.perception.motion import Mover
from host_sdk.perception.tracking import Track
from host_sdk.pose import Pose2D

F64 = NDArray[np.float64]


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
    """The avoider's plan, while searching."""
    manoeuvre: PlanChoice | None = None
    """The planner's choice, while the target is known or looked for where it went."""


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
    """`curvatures`: the arcs (1/m) an Ackermann robot's steering reaches (default: seven up to its
    tightest); a coarse servo reaches only a few, and the planner plans with what the car can drive.
    `accel_m_s2`: the board's accel limit, what the planner assumes the speed changes at (default: the
    planner's own; `FollowParams.planner`, when given, is used as it is); a planner that assumes a
    slower start than the car's sends it farther than it predicts."""

    def __init__(
        self,
        footprint: Footprint,
        camera: CameraModel,
        *,
        min_turn_radius_m: float = 0.0,
        avoidance: AvoidanceParams | None = None,
        params: FollowParams | None = None,
        curvatures: Sequence[float] | None = None,
        accel_m_s2: float | None = None,
    ) -> None:
        self.footprint = footprint
        self.camera = camera
        self.ackermann = min_turn_radius_m > 0
        self.params = p = params or FollowParams()
        self.avoider = Avoider(footprint, replace(avoidance or AvoidanceParams(), min_turn_radius_m=min_turn_radius_m))
        self.finder = TargetFinder(
            camera,
            target_size_m=p.target_size_m,
            coast_s=p.coast_s,
            doubt_s=p.doubt_s,
            reject_s=p.reject_s,
            confirm_s=p.confirm_s,
            near_m=p.keep_near_m,
        )
        self.memory = self.finder.memory
        speeds = (-p.reverse_speed_m_s, -0.2, 0.0, 0.2, 0.35, p.max_speed_m_s)
        plan = p.planner or PlannerParams(speeds_m_s=speeds, target_radius_m=p.target_size_m / 2)
        if accel_m_s2 is not None and p.planner is None:
            plan = replace(plan, accel_m_s2=accel_m_s2)
        if self.ackermann:
            k = self.avoider.params.max_curvature
            arcs = curvatures if curvatures is not None else np.linspace(-k, k, 7).tolist()
            self.planner = ViewPlanner(footprint, camera, curvatures=arcs, params=plan)
        else:
            w = p.max_turn_rate
            self.planner = ViewPlanner(footprint, camera, turn_rates=(-w, -w / 2, w / 2, w), params=plan)
        self._arcs = None if curvatures is None else np.array(sorted(curvatures), dtype=np.float64)
        self._last_v = 0.0
        """The command decided last: linear..."""
        self._last_w = 0.0
        """...and angular."""
        self._speed = 0.0
        """The speed measured from the poses, m/s."""
        self._gave_up = False
        """Looking where the target was predicted to go showed nothing to do: search."""
        self._way = 0.0
        """+1 forwards or -1 backwards: the way it last began to move..."""
        self._way_since = -math.inf
        """...and when."""
        self._started = -math.inf
        """When it last started from standing."""
        self._search_from: float | None = None
        """Heading when the search began (a whole turn round without the target: go elsewhere)."""
        self._wander: Place | None = None
        """A place to look from."""
        self._search_side = 1.0
        """The way the search turns (+1: left), chosen when it begins."""
        self._going = False
        """The search is on its way to where the target was heading..."""
        self._no_go = False
        """...or found the way there blocked, and looks round instead."""
        self._step_off: Aim | None = None
        """A step off the target's route."""
        self._leg = 1.0
        """Ackermann search: the direction of the current K-turn leg (+1 forwards)..."""
        self._leg_m = 0.0
        """...and how far it has gone."""
        self._blocked_since: float | None = None
        self._recover: Manoeuvre | None = None
        """A manoeuvre backing out (or, blocked behind, pulling out)."""
        self._t = 0.0
        self._pose: Pose2D = (0.0, 0.0, 0.0)

    # -- the step -------------------------------------------------------------------------------------
    def step(
        self, t: float, px: F64, py: F64, track: Track | None, pose: Pose2D, *, movers: Sequence[Mover] = ()
    ) -> Decision:
        """One control step: obstacle points in the base frame now, the latest track, the odometry pose,
        and what moves in the scan (`MotionDetector`), which is where a lost target is looked for."""
        decision = self._step(t, px, py, track, pose, movers=movers)
        v, w = decision.linear_m_s, decision.angular_rad_s
        if self._arcs is not None and v != 0.0:  # a car drives the arc its steering reaches nearest
            k = self._arcs[int(np.argmin(np.abs(self._arcs - w / v)))]
            decision = replace(decision, angular_rad_s=float(v * k))
        if v != 0.0 and math.copysign(1.0, v) != self._way:
            self._way, self._way_since = math.copysign(1.0, v), t
        if v != 0.0 and self._last_v == 0.0:
            self._started = t
        self._last_v, self._last_w = decision.linear_m_s, decision.angular_rad_s
        return decision

    def _step(
        self, t: float, px: F64, py: F64, track: Track | None, pose: Pose2D, *, movers: Sequence[Mover]
    ) -> Decision:
        dt = max(0.0, t - self._t)
        if dt > 0:  # how fast it really moves (a command takes a while to become a speed)
            moved = (pose[0] - self._pose[0]) * math.cos(pose[2]) + (pose[1] - self._pose[1]) * math.sin(pose[2])
            self._speed += min(1.0, dt / 0.1) * (moved / dt - self._speed)
        self._t, self._pose = t, pose
        p = self.params
        px, py = np.asarray(px, dtype=np.float64), np.asarray(py, dtype=np.float64)
        fix = self.finder.find(t, px, py, track, pose, movers=movers)
        mask = fix.mask if fix is not None else np.zeros(px.shape[0], dtype=bool)
        view = _View(px[~mask], py[~mask], px[mask], py[mask], fix)
        searching = False
        if fix is not None:
            goal: tuple[float, float] | None = (fix.x_m, fix.y_m)
            self._gave_up = False
        else:
            goal = self.memory.predicted(t, pose, p.coast_s)
            if goal is None and not self._gave_up:
                goal, searching = self.memory.predicted(t, pose, p.coast_s + p.look_s), True
        if goal is not None:
            decision = self._plan(view, goal, pose, searching=searching)
            if not searching or decision.linear_m_s or decision.angular_rad_s or decision.mode is Mode.YIELD:
                self._recover = None
                self._search_from = self._wander = None
                return decision
            # Looking where it went, the planner would stand: nothing it can do shows that place.
            # Search instead (and do not come back to looking until the target is found again).
            self._gave_up = True
        if self._recover is not None and t < self._recover.until_s:
            return self._manoeuvre(view, self._recover.curvature, self._recover.direction)
        self._recover = None
        return self._search(view, pose, dt)

    def _room(self, px: F64, py: F64, curvatures: F64, *, reverse: bool = False) -> F64:
        """Clear travel along each arc, with the avoider's margin round the footprint."""
        a = self.avoider.params
        return arc_room(px, py, curvatures, self.footprint, pad_m=a.pad_m, horizon_m=a.window_m, reverse=reverse)

    # -- the planner ----------------------------------------------------------------------------------
    def _plan(self, view: _View, goal: tuple[float, float], pose: Pose2D, *, searching: bool) -> Decision:
        """The planner's manoeuvre for the target where it is or, while `searching`, where it is
        predicted to be (a car turning round on the spot is slow, and it is most likely there)."""
        p, fp = self.params, self.footprint
        just_started = self.ackermann and self._last_v != 0.0 and self._t - self._started < p.go_s
        choice = self.planner.plan(
            view.ox,
            view.oy,
            target=goal,
            target_velocity=self.memory.velocity_in(pose),
            gap_m=p.follow_gap_m,
            last=(self._last_v, self._last_w),
            speed_m_s=self._speed,
            direction=self._way if self._t - self._way_since < p.hold_s else 0.0,
            moving=just_started,
            target_path=self.memory.ahead(self._t, pose, self.planner.path_times),
        )
        gap = math.hypot(goal[0] - fp.x_m, goal[1]) - fp.radius_m
        if searching:  # standing to let it pass is something to do, not nothing
            mode = Mode.YIELD if choice.min_separation_m < self.planner.params.guard_m else Mode.SEARCH
            return Decision(choice.linear_m_s, choice.angular_rad_s, mode, None, None, manoeuvre=choice)
        if choice.linear_m_s == 0.0 and choice.angular_rad_s == 0.0:
            mode = Mode.STOP
        elif choice.min_separation_m < self.planner.params.guard_m:
            mode = Mode.YIELD
        elif choice.deflected:
            mode = Mode.AVOID
        else:
            mode = Mode.TRACK
        return Decision(choice.linear_m_s, choice.angular_rad_s, mode, view.fix, gap, manoeuvre=choice)

    def _command(self, plan: Plan, view: _View, *, turn_to: float) -> tuple[float, float]:
        """The plan as a body twist, checked once more on the exact arc it drives."""
        p = self.params
        ox, oy, tx, ty = view.ox, view.oy, view.tx, view.ty
        if self.ackermann:
            return plan.speed_m_s, plan.speed_m_s * plan.curvature
        w = max(-p.max_turn_rate, min(p.max_turn_rate, p.gain_turn * turn_to))
        v = plan.speed_m_s * max(0.0, math.cos(turn_to))
        if v > MIN_DRIVE_M_S:
            k = np.array([w / v])
            a = self.avoider.params
            free = float(self._room(ox, oy, k)[0])
            on_target = float(self._room(tx, ty, k)[0])
            v = min(v, safe_speed(free, a), safe_speed(on_target, a, ttc=False))
        if v <= MIN_DRIVE_M_S:
            v = 0.0
            if not self._can_spin(view):
                w = 0.0
        return v, w

    # -- searching --------------------------------------------------------------------------------------
    def _search(self, view: _View, pose: Pose2D, dt: float) -> Decision:
        """Step off the target's route once, go to where it was heading, and look round towards the side
        it went; after a whole turn round without it, go somewhere else to look from (`_wander`). The
        side is chosen when the search begins and kept: a search that changes its mind sees nothing."""
        p = self.params
        last = self.memory.predicted(self._t, pose, LOOK_AHEAD_S)
        if self._search_from is None:
            self._search_from = pose[2]
            if last is None:
                self._search_side = self.memory.side
            else:  # the side it is on, or, nearly straight ahead, the side it was walking to
                lateral = last[1] + 2.0 * self.memory.velocity_in(pose)[1]
                self._search_side = 1.0 if lateral >= 0 else -1.0
            off = self.memory.off_route(pose, self.footprint.radius_m, self.footprint.x_m)
            self._step_off = None if off is None else Aim(self._t + STEP_OFF_S, pose[2] + off)
            self._going = self._no_go = False
        if self._wander is None and abs(pose[2] - self._search_from) > 2 * math.pi:
            self._wander = self._wander_goal(view, pose)
        if self._wander is not None:
            decision = self._go_wander(view, pose, dt)
            if decision is not None:
                return decision
        if self._step_off is not None:  # standing on its route while it cannot be seen: off it first
            aim = self._step_off
            decision = self._search_towards(view, math.remainder(aim.heading_rad - pose[2], 2 * math.pi), dt)
            if self._t < aim.until_s and decision is not None:
                return decision
            self._step_off = None
        if last is not None and math.hypot(*last) > GO_THERE_M and not self._no_go:
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
        if self._stuck(v < MIN_DRIVE_M_S, dt):
            return self._start_backing(view, side=self._search_side)
        if v < MIN_DRIVE_M_S and not self.ackermann:
            return None
        return Decision(v, w, Mode.SEARCH, None, None, plan)

    def _wander_goal(self, view: _View, pose: Pose2D) -> Place:
        """Where it was last seen if that is some way off (it comes back along its route), else
        WANDER_M into the most open direction."""
        seen = self.memory.seen
        if seen is not None:
            bx, by = to_base(pose, seen[1], seen[2])
            if math.hypot(bx, by) > WANDER_FAR_M:
                return Place(self._t + WANDER_S, seen[1], seen[2])
        _, clear = self.avoider.free_directions(view.ox, view.oy)
        best = float(self.avoider.directions[int(np.argmax(clear))])
        wx, wy = to_world(pose, WANDER_M * math.cos(best), WANDER_M * math.sin(best))
        return Place(self._t + WANDER_S, wx, wy)

    def _go_wander(self, view: _View, pose: Pose2D, dt: float) -> Decision | None:
        assert self._wander is not None
        place = self._wander
        gx, gy = to_base(pose, place.x_m, place.y_m)
        if self._t > place.until_s or math.hypot(gx, gy) < WANDER_ARRIVED_M:
            self._wander = None
            self._search_from = pose[2]  # look round again from here
            return None
        bearing = math.atan2(gy, gx)
        if not self.ackermann and abs(bearing) > WANDER_SPIN_RAD and self._can_spin(view):
            return Decision(0.0, math.copysign(self.params.search_turn_rate, bearing), Mode.SEARCH, None, None)
        plan = self.avoider.plan(
            view.ox,
            view.oy,
            bearing,
            self.params.search_speed_m_s,
            target_xy=(view.tx, view.ty),
            goal_m=math.hypot(gx, gy),
        )
        v, w = self._command(plan, view, turn_to=plan.direction_rad)
        if self._stuck(v < MIN_DRIVE_M_S, dt):
            return self._start_backing(view, side=1.0 if bearing > 0 else -1.0)
        return Decision(v, w, Mode.SEARCH, None, None, plan)

    def _k_turn(self, view: _View, dt: float) -> Decision:
        """Ackermann: turn round on the spot as a driver does in a narrow street, forwards with the
        wheels to one side, backwards with them to the other, each leg `k_turn_leg_m` or until the
        way is not clear; the heading turns the same way on both legs and the camera sweeps round."""
        p, a = self.params, self.avoider.params
        x, y = view.xy
        leg, travelled = self._leg, self._leg_m
        k = self._search_side * a.max_curvature * leg  # forwards: towards the side; backwards: away from it
        free = float(self._room(x, y, np.array([k]), reverse=leg < 0)[0])
        v = min(p.search_speed_m_s, safe_speed(free, a, ttc=False))
        if v < MIN_LEG_M_S or travelled >= p.k_turn_leg_m:
            self._leg, self._leg_m = -leg, 0.0
            return Decision(0.0, 0.0, Mode.SEARCH, None, None)
        self._leg_m = travelled + v * dt
        return Decision(leg * v, leg * v * k, Mode.SEARCH, None, None)

    def _can_spin(self, view: _View) -> bool:
        """A differential drive turning in place sweeps a disc round its pose point."""
        fp = self.footprint
        reach = abs(fp.x_m) + fp.radius_m + SPIN_CLEARANCE_M
        x, y = view.xy
        return not bool((np.hypot(x, y) < reach).any())

    def _unstick(self, view: _View, gap: float | None = None) -> Decision:
        """Too close to something to turn in place: move straight away from it, whichever way is free."""
        a = self.avoider.params
        x, y = view.xy
        ahead = float(self._room(x, y, np.array([0.0]))[0])
        behind = float(self._room(x, y, np.array([0.0]), reverse=True)[0])
        v = min(UNSTICK_M_S, safe_speed(max(ahead, behind), a, ttc=False))
        if v < MIN_DRIVE_M_S:
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
        usable = [i for i in range(3) if free[i] > BACK_OUT_ROOM_M]
        if usable:
            k = options[usable[0]] if 0 in usable else options[int(np.argmax(free))]
            self._recover = Manoeuvre(self._t + self.params.recover_s, k, -1.0)
            return self._manoeuvre(view, k, -1.0)
        forwards = options[::-1]
        ahead = self._room(x, y, np.array(forwards))
        usable = [i for i in range(3) if ahead[i] > PULL_OUT_ROOM_M]
        if not usable:
            return Decision(0.0, 0.0, Mode.STOP, fix, None)
        k = forwards[usable[0]]
        self._recover = Manoeuvre(self._t + self.params.recover_s, k, 1.0)
        return self._manoeuvre(view, k, 1.0)

    def _manoeuvre(self, view: _View, k: float, direction: float) -> Decision:
        """Drive on curvature k, forwards (+1) or backwards (-1), as far as there is room."""
        a, fix = self.avoider.params, view.fix
        px, py = view.xy
        free = float(self._room(px, py, np.array([k]), reverse=direction < 0)[0])
        v = min(self.params.reverse_speed_m_s * MANOEUVRE_SPEED_SHARE, safe_speed(free, a, ttc=False))
        if v < MIN_DRIVE_M_S:
            self._recover = None
            return Decision(0.0, 0.0, Mode.STOP, fix, None)
        return Decision(direction * v, direction * v * k, Mode.RECOVER, fix, None)
