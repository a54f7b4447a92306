"""`random:SEED` worlds: a walled room with boxes and cylinders and a target on a closed path.

The rules keep every world solvable for every reference robot (the largest footprint is a 0.19 m
disc): the start pose has ROBOT_CLEARANCE_M of free space around it, which the target's path never
crosses (the target walks while the robot is being connected, and a robot cannot step aside before
it runs), the target's path (each leg, not only its waypoints) keeps its disc clear of every
obstacle, and a breadth-first search over a 5 cm grid, with obstacles grown by the robot's radius,
reaches a cell next to every waypoint of the target from the start. A draw that breaks a rule is
thrown away and the next one taken (from the same seeded stream, so one seed is one world on every
machine: `random.Random` seeded from a string is stable across Python versions).
"""

from __future__ import annotations

import math
import random
from collections import deque

import numpy as np
from numpy.typing import NDArray

from emulator.world.scene import BOX, CYLINDER, TARGET, WALL, Scene, Shape, Target, TargetPath, box_segments, make_scene

ROBOT_RADIUS_M = 0.2
"""Radius the passages are checked for (every reference robot's footprint fits)."""
ROBOT_CLEARANCE_M = 0.45
"""Free space around the start pose's point."""
GRID_M = 0.05
MAX_TRIES = 200

_PALETTE = [(60, 110, 160), (40, 60, 120), (130, 100, 60), (90, 140, 90), (120, 120, 120), (30, 90, 200)]


def random_scene(seed: int) -> Scene:
    rng = random.Random(f"roverlink-world:{seed}")
    for _ in range(MAX_TRIES):
        scene = _draw(rng, seed)
        if scene is not None:
            return scene
    raise RuntimeError(f"random:{seed}: no solvable world in {MAX_TRIES} draws")  # pragma: no cover


def _draw(rng: random.Random, seed: int) -> Scene | None:
    w, h = round(rng.uniform(4.0, 7.0), 2), round(rng.uniform(3.0, 5.0), 2)
    shapes = [Shape("wall", "outer walls", WALL.height_m, WALL.colour, WALL.pattern, WALL.colour2, 0.9)]
    segments: list[tuple[float, ...]] = [(0, 0, w, 0), (w, 0, w, h), (w, h, 0, h), (0, h, 0, 0)]
    seg_shape = [0, 0, 0, 0]
    circles: list[tuple[float, float, float]] = []
    cir_shape: list[int] = []
    placed: list[tuple[float, float, float]] = []  # (x, y, bounding radius)

    def free_spot(radius: float, gap: float) -> tuple[float, float] | None:
        for _ in range(50):
            x, y = rng.uniform(radius + 0.3, w - radius - 0.3), rng.uniform(radius + 0.3, h - radius - 0.3)
            if all(math.hypot(x - px, y - py) > radius + pr + gap for px, py, pr in placed):
                return x, y
        return None

    for i in range(rng.randint(3, 6)):
        length, width = rng.uniform(0.2, 0.7), rng.uniform(0.2, 0.5)
        spot = free_spot(math.hypot(length, width) / 2, 2 * ROBOT_RADIUS_M + 0.2)
        if spot is None:
            continue
        colour = rng.choice(_PALETTE)
        shapes.append(Shape("box", f"box {i}", rng.uniform(0.25, 0.6), colour, "plain", BOX.colour2, 0.7))
        for seg in box_segments(*spot, length, width, rng.uniform(0, math.pi)):
            segments.append(seg)
            seg_shape.append(len(shapes) - 1)
        placed.append((*spot, math.hypot(length, width) / 2))
    for i in range(rng.randint(2, 4)):
        r = rng.uniform(0.05, 0.2)
        spot = free_spot(r, 2 * ROBOT_RADIUS_M + 0.2)
        if spot is None:
            continue
        shapes.append(
            Shape(
                "cylinder", f"cylinder {i}", rng.uniform(0.3, 0.8), rng.choice(_PALETTE), "plain", CYLINDER.colour2, 0.6
            )
        )
        circles.append((*spot, r))
        cir_shape.append(len(shapes) - 1)
        placed.append((*spot, r))
    start_xy = free_spot(ROBOT_CLEARANCE_M, 0.0)
    if start_xy is None:
        return None
    placed.append((*start_xy, ROBOT_CLEARANCE_M))
    radius = 0.12
    waypoints = [free_spot(radius + 0.15, 0.1) for _ in range(rng.randint(3, 4))]
    if any(p is None for p in waypoints):
        return None
    points = tuple(p for p in waypoints if p is not None)
    target = Target(radius, TARGET, TargetPath(points, round(rng.uniform(0.15, 0.3), 3), "loop"))
    shapes.append(TARGET)
    circles.append((*points[0], radius))
    cir_shape.append(len(shapes) - 1)
    start = (*start_xy, rng.uniform(-math.pi, math.pi))
    scene = make_scene(
        f"random:{seed}", shapes, segments, seg_shape, circles, cir_shape=cir_shape, start=start, target=target
    )
    return scene if solvable(scene) else None


def clearance_field(scene: Scene, points: NDArray[np.float64], *, skip_target: bool = True) -> NDArray[np.float64]:
    """Distance from each point (N, 2) to the nearest obstacle surface (the target left out)."""
    best = np.full(points.shape[0], np.inf)
    x, y = points[:, 0:1], points[:, 1:2]
    seg = scene.segments
    if seg.shape[0]:
        px, py = seg[:, 0], seg[:, 1]
        ex, ey = seg[:, 2] - px, seg[:, 3] - py
        s = np.clip(((x - px) * ex + (y - py) * ey) / np.maximum(ex * ex + ey * ey, 1e-18), 0, 1)
        best = np.minimum(best, np.hypot(px + s * ex - x, py + s * ey - y).min(axis=1))
    cir = scene.circles
    keep = np.ones(cir.shape[0], dtype=bool)
    if skip_target and scene.target is not None:
        keep[-1] = False
    if keep.any():
        c = cir[keep]
        best = np.minimum(best, (np.hypot(c[:, 0] - x, c[:, 1] - y) - c[:, 2]).min(axis=1))
    return best


def path_clear(scene: Scene, margin: float = 0.05) -> bool:
    """The target's disc (plus `margin`) stays clear of every obstacle along its whole path, not only
    at its waypoints (a leg between two free waypoints can cross a box), and out of the start's free
    space."""
    target = scene.target
    if target is None:
        return True
    pts = []
    for (ax, ay), (bx, by) in target.path._legs():
        n = max(2, int(math.hypot(bx - ax, by - ay) / 0.05) + 1)
        pts.append(np.column_stack([np.linspace(ax, bx, n), np.linspace(ay, by, n)]))
    if not pts:
        return True
    path = np.vstack(pts)
    sx, sy, _ = scene.start
    from_start = float(np.hypot(path[:, 0] - sx, path[:, 1] - sy).min())
    return bool(
        clearance_field(scene, path).min() >= target.radius_m + margin
        and from_start >= ROBOT_CLEARANCE_M + target.radius_m
    )


def solvable(scene: Scene, robot_radius: float = ROBOT_RADIUS_M) -> bool:
    """The start is free, the target's path is clear, and a cell beside every target waypoint is
    reachable from the start."""
    sx, sy, _ = scene.start
    if clearance_field(scene, np.array([[sx, sy]]))[0] < robot_radius or not path_clear(scene):
        return False
    x0, y0, x1, y1 = scene.bounds
    nx, ny = int((x1 - x0) / GRID_M) + 1, int((y1 - y0) / GRID_M) + 1
    gx, gy = np.meshgrid(x0 + GRID_M * np.arange(nx), y0 + GRID_M * np.arange(ny), indexing="ij")
    free = (clearance_field(scene, np.column_stack([gx.ravel(), gy.ravel()])) >= robot_radius).reshape(nx, ny)
    seen = np.zeros_like(free)
    start = (round((sx - x0) / GRID_M), round((sy - y0) / GRID_M))
    queue = deque([start])
    seen[start] = True
    while queue:
        i, j = queue.popleft()
        for a, b in ((i + 1, j), (i - 1, j), (i, j + 1), (i, j - 1)):
            if 0 <= a < nx and 0 <= b < ny and free[a, b] and not seen[a, b]:
                seen[a, b] = True
                queue.append((a, b))
    if scene.target is None:
        return True
    reach = scene.target.radius_m + robot_radius + 0.2
    for px, py in scene.target.path.points:
        near = np.hypot(gx - px, gy - py) <= reach
        if not (near & seen).any():
            return False
    return True
