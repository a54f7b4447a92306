"""A 2D scene: walls, boxes and cylinders standing on a flat floor, plus one moving target.

Everything a sensor sees is a vertical surface of some height: a wall or box side is a segment,
a cylinder (and the target) a circle. The scene keeps them as numpy arrays so rays are cast many
at a time (`raycast.py`).
"""

from __future__ import annotations

import itertools
import math
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray

Colour = tuple[int, int, int]
"""B, G, R (OpenCV's order), 0..255."""

PATTERNS = ("plain", "bricks", "stripes", "checker")


@dataclass(frozen=True, slots=True)
class Shape:
    """One obstacle as the sensors see it."""

    kind: str
    """wall, box, cylinder or target."""
    name: str
    height_m: float
    colour: Colour
    pattern: str = "plain"
    """How the camera paints it: plain, bricks (walls), stripes or checker (the target's look)."""
    colour2: Colour = (0, 0, 0)
    """Second colour of a pattern."""
    reflectivity: float = 0.8
    """0..1: what the lidar's return strength (quality) scales with."""


@dataclass(frozen=True, slots=True)
class TargetPath:
    """The target moves along `points` at `speed_m_s`: round the closed loop, or back and forth."""

    points: tuple[tuple[float, float], ...]
    speed_m_s: float
    mode: str = "loop"
    """loop (closed polygon) or bounce (there and back)."""

    def _legs(self) -> list[tuple[tuple[float, float], tuple[float, float]]]:
        pts = list(self.points)
        if self.mode == "loop" and len(pts) > 1:
            pts.append(pts[0])
        elif self.mode == "bounce":
            pts = pts + pts[-2::-1]
        return list(itertools.pairwise(pts))

    @property
    def length_m(self) -> float:
        return sum(math.dist(a, b) for a, b in self._legs())

    def pose_at(self, t_s: float) -> tuple[float, float, float, float]:
        """(x, y, heading, speed) of the target at time t."""
        legs = self._legs()
        total = self.length_m
        if not legs or total <= 0 or self.speed_m_s <= 0:
            x, y = self.points[0]
            return x, y, 0.0, 0.0
        s = (self.speed_m_s * t_s) % total
        for (ax, ay), (bx, by) in legs:
            seg = math.hypot(bx - ax, by - ay)
            if s <= seg and seg > 0:
                f = s / seg
                return ax + f * (bx - ax), ay + f * (by - ay), math.atan2(by - ay, bx - ax), self.speed_m_s
            s -= seg
        (ax, ay), (bx, by) = legs[-1]
        return bx, by, math.atan2(by - ay, bx - ax), self.speed_m_s


@dataclass(frozen=True, slots=True)
class Target:
    radius_m: float
    shape: Shape
    path: TargetPath


# The default looks, for scenario files and random worlds alike.
WALL = Shape("wall", "wall", 0.5, (200, 200, 200), "bricks", (170, 170, 180), 0.9)
BOX = Shape("box", "box", 0.4, (60, 110, 160), "plain", (0, 0, 0), 0.7)
CYLINDER = Shape("cylinder", "cylinder", 0.5, (90, 140, 90), "plain", (0, 0, 0), 0.6)
TARGET = Shape("target", "target", 0.3, (255, 0, 255), "stripes", (0, 220, 255), 0.8)
"""The target's default look: magenta and yellow stripes, unlike anything else in a scene."""


@dataclass(slots=True)
class Scene:
    """Static geometry as arrays, and the moving target.

    `segments[i]` = (x0, y0, x1, y1) belongs to `shapes[segment_shape[i]]`; `circles[j]` = (x, y, r)
    to `shapes[circle_shape[j]]`. The target, when there is one, is the last circle, moved with
    `set_time()`.
    """

    name: str
    shapes: list[Shape]
    segments: NDArray[np.float64]
    segment_shape: NDArray[np.int64]
    circles: NDArray[np.float64]
    circle_shape: NDArray[np.int64]
    start: tuple[float, float, float]
    """Where the robot's pose point starts: x, y, heading (rad)."""
    target: Target | None = None
    bounds: tuple[float, float, float, float] = (0.0, 0.0, 0.0, 0.0)
    """min x, min y, max x, max y of everything."""
    time_s: float = 0.0
    heights: NDArray[np.float64] = field(default_factory=lambda: np.zeros(0))
    reflectivity: NDArray[np.float64] = field(default_factory=lambda: np.zeros(0))

    def __post_init__(self) -> None:
        self.heights = np.array([s.height_m for s in self.shapes], dtype=np.float64)
        self.reflectivity = np.array([s.reflectivity for s in self.shapes], dtype=np.float64)
        self.set_time(0.0)

    @property
    def target_index(self) -> int | None:
        """Index of the target's shape (the last), or None."""
        return len(self.shapes) - 1 if self.target is not None else None

    def set_time(self, t_s: float) -> None:
        """Move the target to where it is at time `t_s`."""
        self.time_s = t_s
        if self.target is not None:
            x, y, _, _ = self.target.path.pose_at(t_s)
            self.circles[-1, 0] = x
            self.circles[-1, 1] = y

    def target_pose(self) -> tuple[float, float, float, float] | None:
        """(x, y, heading, speed) of the target now, or None."""
        return None if self.target is None else self.target.path.pose_at(self.time_s)


def box_segments(cx: float, cy: float, length: float, width: float, yaw: float) -> list[tuple[float, ...]]:
    """The four sides of a box centred at (cx, cy), `length` along its yaw, as segments."""
    c, s = math.cos(yaw), math.sin(yaw)
    hx, hy = length / 2, width / 2
    corners = [(cx + c * px - s * py, cy + s * px + c * py) for px, py in ((hx, hy), (-hx, hy), (-hx, -hy), (hx, -hy))]
    return [(*corners[i], *corners[(i + 1) % 4]) for i in range(4)]


def make_scene(
    name: str,
    shapes: list[Shape],
    segments: list[tuple[float, ...]],
    seg_shape: list[int],
    circles: list[tuple[float, float, float]],
    *,
    cir_shape: list[int],
    start: tuple[float, float, float],
    target: Target | None,
) -> Scene:
    """A Scene from plain lists (scenario files and random worlds build these), with its bounds."""
    seg = np.array(segments, dtype=np.float64).reshape(-1, 4)
    cir = np.array(circles, dtype=np.float64).reshape(-1, 3)
    xs = np.concatenate([seg[:, 0], seg[:, 2], cir[:, 0] - cir[:, 2], cir[:, 0] + cir[:, 2], [start[0]]])
    ys = np.concatenate([seg[:, 1], seg[:, 3], cir[:, 1] - cir[:, 2], cir[:, 1] + cir[:, 2], [start[1]]])
    return Scene(
        name=name,
        shapes=shapes,
        segments=seg,
        segment_shape=np.array(seg_shape, dtype=np.int64),
        circles=cir,
        circle_shape=np.array(cir_shape, dtype=np.int64),
        start=start,
        target=target,
        bounds=(float(xs.min()), float(ys.min()), float(xs.max()), float(ys.max())),
    )
