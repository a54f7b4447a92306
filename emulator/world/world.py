"""The robot in its scene: world pose, the moving target, collisions and the bumper.

The plant integrates the body in its own frame (starting at the origin, as odometry does); the
world places that frame at the scene's start pose. After every physics step the body's footprint
(a disc, protocol/spec/sensors.toml) is checked against the scene at that instant. Contact is a
collision: recorded once per contact (time, place, speed, what was hit), and the plant stops as a
bumper would: the step that ran into the obstacle is undone and the body and wheels stand still.
A robot in contact can still back away or turn away (a step that does not deepen the overlap is
kept), and the target moving into a parked robot is recorded too.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from emulator.plant.plant import Plant
from emulator.world.raycast import clearance
from emulator.world.scene import Scene
from protocol.generated.profiles import ROBOT_SENSORS
from protocol.sensors import RobotSensors

F64 = NDArray[np.float64]
HISTORY = 128
"""Physics steps of pose history kept for `World.pose_at` (128 ms at the 1 ms step)."""
_SLACK_M = 1e-6
CONTACT_M = 0.001
"""A gap under 1 mm is contact (one physics step at 1 m/s moves the body 1 mm)."""


@dataclass(frozen=True, slots=True)
class Collision:
    time_us: int
    x_m: float
    """Where the footprint touched the obstacle (world frame)."""
    y_m: float
    speed_m_s: float
    """The robot's speed just before the contact."""
    obstacle: str
    """Name of the shape hit (e.g. "outer walls", "boxes[1]", "target")."""
    kind: str
    """wall, box, cylinder or target."""
    closing_m_s: float = 0.0
    """How fast the footprint itself moved towards the contact point in the step before it. Zero or
    less: the robot stood, or was moving away, and was run into (only the target moves)."""


@dataclass(frozen=True, slots=True)
class WorldTruth:
    scene: str
    x_m: float
    """The robot's pose point in the world frame."""
    y_m: float
    theta_rad: float
    target: tuple[float, float, float, float] | None
    """(x, y, heading, speed) of the target, or None."""
    clearance_m: float
    """Gap between the footprint and the nearest obstacle now (negative: overlapping)."""
    in_contact: bool
    collisions: tuple[Collision, ...]


class World:
    def __init__(self, scene: Scene, profile: str, sensors: RobotSensors | None = None) -> None:
        self.scene = scene
        self.body = sensors or ROBOT_SENSORS[profile]
        self.collisions: list[Collision] = []
        self.in_contact = False
        self._gap = -math.inf  # unknown until the first check
        self._checked = (0.0, 0.0, 0)  # where and when the footprint's gap was last measured
        self._saved: tuple[float, ...] = ()
        self._step_us: int | None = None  # when the last physics step ended
        # The robot's world pose after each physics step (a ring), for sensors that sample
        # between steps: `pose_at`.
        self._hist = np.zeros((HISTORY, 4))
        self._hist_n = 0

    # -- frames ------------------------------------------------------------------------------------
    def to_world(self, x: float, y: float, theta: float) -> tuple[float, float, float]:
        """A plant-frame pose in the world frame."""
        sx, sy, sth = self.scene.start
        c, s = math.cos(sth), math.sin(sth)
        return sx + c * x - s * y, sy + s * x + c * y, sth + theta

    def robot_pose(self, plant: Plant) -> tuple[float, float, float]:
        v = plant.vehicle
        return self.to_world(v.x_m, v.y_m, v.theta_rad)

    def footprint(self, x: float, y: float, theta: float) -> tuple[float, float]:
        off = self.body.footprint_x_m
        return x + off * math.cos(theta), y + off * math.sin(theta)

    # -- per physics step --------------------------------------------------------------------------
    def before_step(self, plant: Plant) -> None:
        v = plant.vehicle
        self._saved = (v.x_m, v.y_m, v.theta_rad, v.distance_m, v.v_m_s, *(u.angle_rad for u in plant.units))

    def after_step(self, plant: Plant, now_us: int) -> None:
        self._collide(plant, now_us)
        self._step_us = now_us
        self._hist[self._hist_n % HISTORY] = (now_us, *self.robot_pose(plant))
        self._hist_n += 1

    def pose_at(self, times_us: NDArray[np.int64]) -> tuple[F64, F64, F64]:
        """The robot's world pose at each time, interpolated between physics steps (times within
        the last HISTORY steps; earlier or later ones are clamped to the ends)."""
        n = min(self._hist_n, HISTORY)
        if n == 0:
            x, y, th = self.scene.start
            ones = np.ones(np.shape(times_us))
            return x * ones, y * ones, th * ones
        idx = (self._hist_n - n + np.arange(n)) % HISTORY
        h = self._hist[idx]
        t = np.asarray(times_us, dtype=np.float64)
        return np.interp(t, h[:, 0], h[:, 1]), np.interp(t, h[:, 0], h[:, 2]), np.interp(t, h[:, 0], h[:, 3])

    def _collide(self, plant: Plant, now_us: int) -> None:
        x, y, th = self.robot_pose(plant)
        fx, fy = self.footprint(x, y, th)
        # Far from everything: no surface can be nearer than the last gap less how far the
        # footprint and the target moved since it was measured, so the exact check can wait.
        cx, cy, ct = self._checked
        target = self.scene.target
        target_moved = target.path.speed_m_s * (now_us - ct) / 1e6 if target is not None else 0.0
        if not self.in_contact and math.hypot(fx - cx, fy - cy) + target_moved < self._gap - CONTACT_M:
            return
        self.scene.set_time(now_us / 1e6)
        self._checked = (fx, fy, now_us)
        radius = self.body.footprint_radius_m
        gap, shape = clearance(self.scene, fx, fy, radius)
        if gap >= CONTACT_M:
            self.in_contact = False
            self._gap = gap
            return
        speed = self._saved[4] if self._saved else plant.vehicle.v_m_s
        if not self.in_contact:
            self._record(now_us, fx, fy, radius=radius, speed=speed, shape=shape)
        before = self._gap if math.isfinite(self._gap) else 0.0
        if self._saved and gap < 0 and gap < min(before, 0.0) - _SLACK_M:
            self._stop(plant)
            x, y, th = self.robot_pose(plant)
            gap, _ = clearance(self.scene, *self.footprint(x, y, th), radius)
        self.in_contact = True
        self._gap = gap
        self._checked = (*self.footprint(*self.robot_pose(plant)), now_us)

    def _record(self, now_us: int, fx: float, fy: float, *, radius: float, speed: float, shape: int) -> None:
        # Contact point: the footprint's edge towards the obstacle, found by probing 16 directions.
        best = (math.inf, fx, fy)
        for k in range(16):
            a = 2 * math.pi * k / 16
            px, py = fx + radius * math.cos(a), fy + radius * math.sin(a)
            g, _ = clearance(self.scene, px, py, 0.0)
            best = min(best, (g, px, py))
        hit = self.scene.shapes[shape]
        closing = 0.0
        if self._saved and self._step_us is not None and now_us > self._step_us:
            before_x, before_y = self.footprint(*self.to_world(*self._saved[:3]))
            d = math.hypot(best[1] - fx, best[2] - fy)
            if d > 0:
                moved = ((fx - before_x) * (best[1] - fx) + (fy - before_y) * (best[2] - fy)) / d
                closing = moved / ((now_us - self._step_us) / 1e6)
        self.collisions.append(Collision(now_us, best[1], best[2], abs(speed), hit.name, hit.kind, closing))

    def _stop(self, plant: Plant) -> None:
        """The bumper: undo the step into the obstacle; body and wheels stand still."""
        v = plant.vehicle
        v.x_m, v.y_m, v.theta_rad, v.distance_m = self._saved[:4]
        v.v_m_s = 0.0
        v.wz_rad_s = 0.0
        for unit, angle in zip(plant.units, self._saved[5:], strict=True):
            unit.angle_rad = angle
            unit.omega_rad_s = 0.0
            if unit.encoder is not None:
                unit.encoder.update(angle)

    def truth(self, plant: Plant) -> WorldTruth:
        x, y, th = self.robot_pose(plant)
        return WorldTruth(
            scene=self.scene.name,
            x_m=x,
            y_m=y,
            theta_rad=th,
            target=self.scene.target_pose(),
            clearance_m=self._gap,
            in_contact=self.in_contact,
            collisions=tuple(self.collisions),
        )
