"""A person's drive command kept clear of what the lidar sees: the avoider's protection for teleop.

    guard = LidarGuard(robot, lidar)          # TeleopGuard.for_robot(robot_geometry(robot)) on the lidar
    guard.start()                             # the lidar spins up
    while driving:                            # every control period (20 Hz)
        held = guard.check(linear, angular, override=shift_held)    # the revolutions done, then the guard
        robot.drive(held.linear_m_s, held.angular_rad_s, clamp=True)   # held.text says why it differs

`TeleopGuard` alone is the guard without the plumbing: fed revolutions and poses (`on_scan`,
`check`), or obstacle points from elsewhere (`limit`: the console gives it the follow pilot's).

The command is checked on the arc it drives (curvature = angular / linear), forwards or backwards,
with the same swept corridor (`arc_room`: the footprint grown by `pad_m`) and the same speed law
(`safe_speed`: reaction latency, braking, stop margin, time to collision) as the follow behaviour's
avoider: the robot slows as the way closes in and stops `stop_margin_m` short of the obstacle.
The curvature is kept while slowing, so the robot stays on the path the person asked for. Moving
away from something already too close stays allowed (the corridor's own rule), and so does a
differential drive's turn on the spot unless it swings the body into something. Without a recent
scan there is nothing to protect with: the robot stands.

`override=True` (a control the person holds, never a setting) passes the command through; the
result still names the obstacle it would have stopped for.

`explain_failsafe` words a FAILSAFE for a person, naming what the lidar sees touching the footprint:
ENCODER_FAULT is latched when a wheel does not turn under effort, which is what a bump looks like.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from enum import Enum

import numpy as np
from numpy.typing import NDArray

from host_sdk.body import Footprint
from host_sdk.failsafe import describe_failsafe
from host_sdk.fusion.source import PoseSource
from host_sdk.geometry import RobotGeometry, robot_geometry
from host_sdk.kinematics import Arc
from host_sdk.odometry import integrate_arc
from host_sdk.perception.avoidance import AvoidanceParams, arc_room, safe_speed, stopping_distance
from host_sdk.perception.scan import ObstacleScan, ScanFilter, move_points
from host_sdk.pose import Pose, PoseAt
from host_sdk.robot import Robot
from host_sdk.sensors import Lidar, LidarScan
from protocol.generated.enums import FailsafeReason

F64 = NDArray[np.float64]
Points = tuple[F64, F64]
MIN_SPEED_M_S = 0.02
"""A limited speed below this is a stop: the wheels would not turn at it, only creep."""
STALE_S = 1.0
"""A scan older than this protects nothing: the robot may have met something since."""


class GuardState(Enum):
    CLEAR = "clear"
    """Nothing on the path slows the command."""
    SLOWED = "slowed"
    STOPPED = "stopped"
    """No speed on the asked path stops short of the obstacle (a turn on the spot may be left)."""
    NO_SCAN = "no scan"
    """No recent scan: standing."""
    OVERRIDE = "override"
    """The person holds the override: the command as asked."""


_SIDES = ("ahead", "ahead left", "left", "behind left", "behind", "behind right", "right", "ahead right")


@dataclass(frozen=True, slots=True)
class Obstacle:
    """An obstacle point in the base frame (x forward, y left), seen from the robot's body: its gap to
    the footprint's edge and its bearing from the footprint's centre (a person at the robot judges
    "2 cm ahead of the bumper", not a distance from the rear axle)."""

    x_m: float
    y_m: float
    gap_m: float
    """From the footprint's edge (negative: inside it)."""
    bearing_rad: float
    """From the footprint's centre, counter-clockwise from forward."""

    @classmethod
    def at(cls, x_m: float, y_m: float, footprint: Footprint) -> Obstacle:
        dx = x_m - footprint.x_m
        return cls(x_m, y_m, math.hypot(dx, y_m) - footprint.radius_m, math.atan2(y_m, dx))

    @property
    def range_m(self) -> float:
        """From the pose point."""
        return math.hypot(self.x_m, self.y_m)

    @property
    def side(self) -> str:
        """`ahead`, `ahead left`, `left`, ... (eight sectors round the body)."""
        return _SIDES[round(self.bearing_rad / (math.pi / 4)) % 8]

    def where(self) -> str:
        """`0.12 m ahead of the body`."""
        return f"{max(self.gap_m, 0.0):.2f} m {self.side} of the body"


@dataclass(frozen=True, slots=True)
class Guarded:
    """The command to send, and why it differs from the one asked."""

    linear_m_s: float
    angular_rad_s: float
    state: GuardState
    obstacle: Obstacle | None = None
    """What slowed or stopped it (with the override, what would have): the obstacle its path meets."""
    free_m: float | None = None
    """Clear travel along the asked path (with the footprint's margin)."""
    scan_age_s: float | None = None

    @property
    def limited(self) -> bool:
        return self.state in (GuardState.SLOWED, GuardState.STOPPED, GuardState.NO_SCAN)

    @property
    def text(self) -> str:
        """One line for a status display."""
        at = f" for an obstacle {self.obstacle.where()}" if self.obstacle is not None else ""
        if self.state is GuardState.OVERRIDE:
            return "override held: no obstacle protection" + (f" (not stopping{at})" if at else "")
        if self.state is GuardState.NO_SCAN:
            age = "" if self.scan_age_s is None else f" for {self.scan_age_s:.1f} s"
            return f"no lidar scan{age}: standing (hold the override to drive unprotected)"
        if self.state is GuardState.STOPPED:
            return f"stopped{at}: back or turn away, or hold the override"
        if self.state is GuardState.SLOWED:
            return f"slowing{at}"
        return "obstacle protection on"


class LatestScan:
    """A `ScanFilter`'s newest picture and the pose it was taken at, seen from any later pose: what a
    pilot steers by between revolutions (the robot moves on meanwhile)."""

    def __init__(self, scan_filter: ScanFilter) -> None:
        self.scan_filter = scan_filter
        self.scan: ObstacleScan | None = None
        self.pose: Pose | None = None

    def update(self, scan: LidarScan, pose: Pose, *, pose_at: PoseAt | None = None) -> ObstacleScan:
        """Filter a revolution taken at `pose` (its mid-time); `pose_at` de-skews it."""
        deskew = None if pose_at is None else (lambda t: pose_at(t).xyt)
        self.scan = self.scan_filter.update(scan, pose.xyt, pose_at=deskew)
        self.pose = pose
        return self.scan

    def seen_from(self, pose: Pose) -> tuple[Points, float] | None:
        """The newest picture's points seen from `pose`, and how old it is (None: no scan yet)."""
        if self.scan is None or self.pose is None:
            return None
        return move_points(self.scan.x_m, self.scan.y_m, self.pose.xyt, pose.xyt), pose.time_s - self.pose.time_s


class TeleopGuard:
    """Limits teleop commands to what stops short of the obstacles. `params` are the avoider's
    (`AvoidanceParams`: margins, braking, latency); `min_turn_radius_m` > 0: a car (it cannot turn
    standing). With `scan_filter` the guard filters revolutions itself (`on_scan`, `check`);
    without, give it points (`limit`), e.g. the follow pilot's."""

    def __init__(
        self,
        footprint: Footprint,
        params: AvoidanceParams | None = None,
        *,
        min_turn_radius_m: float = 0.0,
        scan_filter: ScanFilter | None = None,
        stale_s: float = STALE_S,
    ) -> None:
        self.footprint = footprint
        self.params = params or AvoidanceParams()
        self.car = min_turn_radius_m > 0
        self.scans = None if scan_filter is None else LatestScan(scan_filter)
        """The revolutions it filters itself (None: it is given points)."""
        self.stale_s = stale_s

    @classmethod
    def for_robot(cls, geometry: RobotGeometry, params: AvoidanceParams | None = None) -> TeleopGuard:
        """The guard for a robot of `geometry`, filtering its own scans from the geometry's lidar mount."""
        return cls(
            geometry.footprint,
            params,
            min_turn_radius_m=geometry.min_turn_radius_m,
            scan_filter=ScanFilter(geometry.lidar_mount),
        )

    # -- fed with revolutions -------------------------------------------------------------------------
    def on_scan(self, scan: LidarScan, pose: Pose, *, pose_at: PoseAt | None = None) -> None:
        """A revolution and the pose at its mid-time (`pose_at`, the pose at any recent time, de-skews it)."""
        if self.scans is None:
            raise RuntimeError("this guard has no scan filter: give it points with limit()")
        self.scans.update(scan, pose, pose_at=pose_at)

    def check(self, linear_m_s: float, angular_rad_s: float, pose: Pose, *, override: bool = False) -> Guarded:
        """`limit` against the latest revolution, seen from `pose` (now)."""
        seen = None if self.scans is None else self.scans.seen_from(pose)
        points, age = (None, None) if seen is None else seen
        return self.limit(linear_m_s, angular_rad_s, points, age_s=age, override=override)

    # -- the guard --------------------------------------------------------------------------------------
    def limit(
        self,
        linear_m_s: float,
        angular_rad_s: float,
        points: Points | None,
        *,
        age_s: float | None = 0.0,
        override: bool = False,
    ) -> Guarded:
        """The command (linear m/s, angular rad/s) limited by obstacle `points` (base frame, now; None:
        no scan), taken `age_s` ago."""
        v, w = float(linear_m_s), float(angular_rad_s)
        if points is None or age_s is None or age_s > self.stale_s:
            age_s = None if points is None else age_s
            state = GuardState.OVERRIDE if override else GuardState.NO_SCAN
            return Guarded(v, w, state, scan_age_s=age_s) if override else Guarded(0.0, 0.0, state, scan_age_s=age_s)
        x, y = _finite(points)
        if abs(v) < 1e-9:
            allowed = self.car or abs(w) < 1e-9 or self.spin_allowed(x, y, w)
            obstacle = None if allowed else self.nearest(x, y)
            if override or allowed:
                return Guarded(v, w, GuardState.OVERRIDE if override else GuardState.CLEAR, obstacle, scan_age_s=age_s)
            return Guarded(0.0, 0.0, GuardState.STOPPED, obstacle, scan_age_s=age_s)
        k, reverse = w / v, v < 0
        p = self.params
        # Along the arc as far as the avoider looks (`window_m`): farther changes no speed a person drives at.
        free = float(
            arc_room(x, y, np.array([k]), self.footprint, pad_m=p.pad_m, horizon_m=p.window_m, reverse=reverse)[0]
        )
        speed = min(abs(v), safe_speed(free, p))
        # What the path meets, when it slows the command (with the override: when it would have).
        obstacle = self._met(x, y, k, -free if reverse else free) if speed < abs(v) else None
        if override:
            return Guarded(v, w, GuardState.OVERRIDE, obstacle, free, age_s)
        if speed >= abs(v):
            return Guarded(v, w, GuardState.CLEAR, None, free, age_s)
        if speed >= MIN_SPEED_M_S:
            v = math.copysign(speed, v)
            return Guarded(v, v * k, GuardState.SLOWED, obstacle, free, age_s)
        # No speed on this path: a differential drive may still turn on the spot, if that is clear.
        turn = w if not self.car and abs(w) > 1e-9 and self.spin_allowed(x, y, w) else 0.0
        return Guarded(0.0, turn, GuardState.STOPPED, obstacle, free, age_s)

    def spin_allowed(self, x: F64, y: F64, angular_rad_s: float) -> bool:
        """A turn on the spot swings the footprint's centre round the pose point: allowed unless, over
        the turn it makes while reacting and braking, the body comes within the margin (`pad_m`) of the
        obstacles, or, already within it, any nearer to them than it is (less 5 mm, as `arc_room`).
        The gap is the body's to all the points at once: turning, a body near a wall slides along it,
        and each wall point in turn comes a little nearer while the wall itself does not."""
        fp, p = self.footprint, self.params
        reach = abs(fp.x_m) + fp.radius_m
        if abs(fp.x_m) < 1e-6 or x.size == 0:
            return True  # the body turns in its own place
        rho, beta = np.hypot(x, y), np.arctan2(y, x)
        near = rho < reach + p.pad_m
        if not near.any():
            return True
        rho, beta = rho[near], beta[near]
        turn = spin_angle(angular_rad_s, reach, p)
        gap_now = _disc_gap(rho, beta, 0.0, fp)
        closest = np.minimum(gap_now, _disc_gap(rho, beta, turn, fp))
        # The centre passes straight by a point (the nearest it comes) if that bearing is inside the turn.
        facing = beta if fp.x_m > 0 else beta + math.pi
        passes = np.mod(math.copysign(1.0, turn) * facing, 2 * math.pi) <= abs(turn)
        closest = np.where(passes, np.abs(rho - abs(fp.x_m)) - fp.radius_m, closest)
        nearest = float(gap_now.min())
        return float(closest.min()) >= (p.pad_m if nearest >= p.pad_m else nearest - 0.005)

    def nearest(self, x: F64, y: F64) -> Obstacle | None:
        """The point nearest the footprint's edge."""
        return nearest_point(x, y, self.footprint)

    def _met(self, x: F64, y: F64, k: float, travel_m: float) -> Obstacle | None:
        """The point the grown footprint touches after `travel_m` along curvature `k` (negative: backwards)."""
        px, py, th = integrate_arc(0.0, 0.0, 0.0, Arc(travel_m, travel_m * k))
        fp = self.footprint
        cx, cy = px + fp.x_m * math.cos(th), py + fp.x_m * math.sin(th)
        if x.size == 0:
            return None
        i = int(np.argmin(np.hypot(x - cx, y - cy)))
        return Obstacle.at(float(x[i]), float(y[i]), fp)


class LidarGuard:
    """A `TeleopGuard` on a robot's lidar: `check` reads the revolutions completed since the last
    call (without waiting), gives each to the guard with the pose at its mid-time (wheel odometry,
    `PoseSource`), then limits the command at the pose now. Call it from one thread, every period."""

    def __init__(self, robot: Robot, lidar: Lidar, guard: TeleopGuard | None = None) -> None:
        self.robot = robot
        self.lidar = lidar
        self.guard = guard or TeleopGuard.for_robot(robot_geometry(robot))
        self.poses = PoseSource(robot, None)
        self.last: Guarded | None = None
        """The last command's verdict."""

    def start(self) -> None:
        """Start the lidar scanning."""
        self.poses.update(self.robot.now())
        self.lidar.start()

    def poll(self) -> Pose:
        """Take in the revolutions completed so far; the pose now."""
        poses = self.poses
        pose = poses.update(self.robot.now())
        for scan in self.lidar.poll():
            self.guard.on_scan(scan, poses.at(scan.time_s + scan.duration_s / 2), pose_at=poses.at)
        return pose

    def check(self, linear_m_s: float, angular_rad_s: float, *, override: bool = False) -> Guarded:
        """`poll`, then the command limited at the pose now."""
        self.last = self.guard.check(linear_m_s, angular_rad_s, self.poll(), override=override)
        return self.last

    def stop(self) -> None:
        """Stop the lidar scanning."""
        self.lidar.stop()


def spin_angle(angular_rad_s: float, reach_m: float, params: AvoidanceParams) -> float:
    """The turn (rad, signed) a spin at `angular_rad_s` makes while reacting and braking: the speed
    law's stopping distance for the footprint's rim (`reach_m` from the pose point), less its stop
    margin (a turn cannot keep a distance ahead)."""
    rim = abs(angular_rad_s) * reach_m
    return math.copysign((stopping_distance(rim, params) - params.stop_margin_m) / reach_m, angular_rad_s)


def nearest_point(x: F64, y: F64, footprint: Footprint) -> Obstacle | None:
    """The point nearest the footprint's edge (None: no points)."""
    x, y = _finite((x, y))
    if x.size == 0:
        return None
    i = int(np.argmin(np.hypot(x - footprint.x_m, y)))
    return Obstacle.at(float(x[i]), float(y[i]), footprint)


def within_margin(points: Points, footprint: Footprint, margin_m: float) -> Obstacle | None:
    """The point nearest the footprint when it is within `margin_m` of its edge (or inside it)."""
    found = nearest_point(points[0], points[1], footprint)
    return found if found is not None and found.gap_m < margin_m else None


def explain_failsafe(reason: FailsafeReason, near: Obstacle | None, margin_m: float) -> str:
    """The failsafe in words, and, when the lidar sees something inside the footprint's margin, what
    and where (a blocked wheel is the likelier cause of ENCODER_FAULT then)."""
    text = describe_failsafe(reason)
    if near is None:
        return text
    return f"{text}; the lidar sees an obstacle {near.where()}, inside the footprint's {margin_m:.2f} m margin"


def _finite(points: Points) -> Points:
    x, y = np.asarray(points[0], dtype=np.float64), np.asarray(points[1], dtype=np.float64)
    ok = np.isfinite(x) & np.isfinite(y)
    return (x, y) if ok.all() else (x[ok], y[ok])


def _disc_gap(rho: F64, beta: F64, turn: float, fp: Footprint) -> F64:
    """Gap from each point (polar, pose point) to the footprint after the body turns by `turn` on the spot."""
    d2 = rho * rho + fp.x_m * fp.x_m - 2 * rho * fp.x_m * np.cos(beta - turn)
    gap: F64 = np.sqrt(np.maximum(d2, 0.0)) - fp.radius_m
    return gap
