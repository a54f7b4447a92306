"""Scenario files (small TOML) and seeded random worlds, both turned into a Scene.

    load_world("room.toml")      a scenario file (format: docs/sensors.md, "Scenario files")
    load_world("random:7")       a generated room, solvable: the start is free, the target reachable
    load_world("empty")          an open floor, nothing on it (room to drive: calibration)

Every field is checked; a bad one raises ScenarioError (a ValueError) naming it, e.g.
`boxes[2].size = [0.4] is not allowed: two numbers > 0 (length, width) in metres`.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

from emulator.errors import EmulatorValueError
from emulator.world.generate import random_scene
from emulator.world.scene import (
    BOX,
    CYLINDER,
    PATTERNS,
    TARGET,
    WALL,
    Colour,
    Scene,
    Shape,
    Target,
    TargetPath,
    box_segments,
    make_scene,
)
from protocol.toml import tomllib

_TOP_KEYS = {"world", "start", "walls", "boxes", "cylinders", "target"}


class ScenarioError(EmulatorValueError):
    """A scenario file field that is missing or out of range; names the field."""


def load_world(spec: str | Path) -> Scene:
    """A Scene from a scenario file path, `random:SEED`, or `empty`."""
    text = str(spec)
    if text == "empty":
        return parse_scenario({}, default_name="empty")
    if text.startswith("random:"):
        seed = text.removeprefix("random:")
        if not seed.isdigit():
            raise ScenarioError("world", text, "a scenario file, empty, or random:SEED with SEED a whole number >= 0")
        return random_scene(int(seed))
    path = Path(text)
    try:
        data = tomllib.loads(path.read_text(encoding="utf-8"))
    except OSError as exc:
        raise ScenarioError("world", text, f"a readable scenario file ({exc.strerror})") from None
    except tomllib.TOMLDecodeError as exc:
        raise ScenarioError("world", text, f"valid TOML ({exc})") from None
    return parse_scenario(data, default_name=path.stem)


def _num(where: str, value: Any, lo: float = -math.inf, hi: float = math.inf, what: str = "a number") -> float:
    if isinstance(value, bool) or not isinstance(value, int | float) or not lo <= value <= hi:
        raise ScenarioError(where, value, what)
    return float(value)


def _point(where: str, value: Any) -> tuple[float, float]:
    if not (isinstance(value, list) and len(value) == 2):
        raise ScenarioError(where, value, "[x, y] in metres")
    return _num(where, value[0], what="[x, y] in metres"), _num(where, value[1], what="[x, y] in metres")


def _colour(where: str, value: Any) -> Colour:
    if not (isinstance(value, str) and len(value) == 7 and value[0] == "#"):
        raise ScenarioError(where, value, 'an RGB colour "#rrggbb"')
    try:
        r, g, b = (int(value[i : i + 2], 16) for i in (1, 3, 5))
    except ValueError:
        raise ScenarioError(where, value, 'an RGB colour "#rrggbb"') from None
    return b, g, r


def _look(where: str, entry: dict[str, Any], base: Shape, allowed: set[str]) -> Shape:
    unknown = set(entry) - allowed - {"height_m", "colour", "colour2", "pattern", "reflectivity", "name"}
    if unknown:
        raise ScenarioError(f"{where}.{sorted(unknown)[0]}", entry[sorted(unknown)[0]], "not a field of this entry")
    pattern = entry.get("pattern", base.pattern)
    if pattern not in PATTERNS:
        raise ScenarioError(f"{where}.pattern", pattern, f"one of {', '.join(PATTERNS)}")
    return Shape(
        kind=base.kind,
        name=str(entry.get("name", where)),
        height_m=_num(f"{where}.height_m", entry.get("height_m", base.height_m), 0.01, 10, "a height in 0.01..10 m"),
        colour=_colour(f"{where}.colour", entry["colour"]) if "colour" in entry else base.colour,
        pattern=pattern,
        colour2=_colour(f"{where}.colour2", entry["colour2"]) if "colour2" in entry else base.colour2,
        reflectivity=_num(f"{where}.reflectivity", entry.get("reflectivity", base.reflectivity), 0, 1, "0..1"),
    )


def parse_scenario(data: dict[str, Any], default_name: str = "scenario") -> Scene:
    """A Scene from a parsed scenario (see the module docstring)."""
    unknown = set(data) - _TOP_KEYS
    if unknown:
        key = sorted(unknown)[0]
        raise ScenarioError(key, data[key], f"a top-level table: one of {', '.join(sorted(_TOP_KEYS))}")
    world = data.get("world", {})
    wall_height = _num("world.wall_height_m", world.get("wall_height_m", WALL.height_m), 0.01, 10, "0.01..10 m")
    shapes: list[Shape] = []
    segments: list[tuple[float, ...]] = []
    seg_shape: list[int] = []
    circles: list[tuple[float, float, float]] = []
    cir_shape: list[int] = []
    if "size_m" in world:
        w, h = _point("world.size_m", world["size_m"])
        if w <= 0 or h <= 0:
            raise ScenarioError("world.size_m", world["size_m"], "[width, depth] > 0: the room's outer walls")
        shapes.append(Shape("wall", "outer walls", wall_height, WALL.colour, WALL.pattern, WALL.colour2, 0.9))
        for side in ((0.0, 0.0, w, 0.0), (w, 0.0, w, h), (w, h, 0.0, h), (0.0, h, 0.0, 0.0)):
            segments.append(side)
            seg_shape.append(len(shapes) - 1)
    for i, wall in enumerate(data.get("walls", [])):
        where = f"walls[{i}]"
        base = Shape("wall", where, wall_height, WALL.colour, WALL.pattern, WALL.colour2, WALL.reflectivity)
        shapes.append(_look(where, wall, base, {"from", "to"}))
        segments.append((*_point(f"{where}.from", wall.get("from")), *_point(f"{where}.to", wall.get("to"))))
        seg_shape.append(len(shapes) - 1)
    for i, box in enumerate(data.get("boxes", [])):
        where = f"boxes[{i}]"
        shapes.append(_look(where, box, BOX, {"center", "size", "yaw_deg"}))
        cx, cy = _point(f"{where}.center", box.get("center"))
        size = box.get("size")
        if not (isinstance(size, list) and len(size) == 2 and all(_num(f"{where}.size", s) > 0 for s in size)):
            raise ScenarioError(f"{where}.size", size, "two numbers > 0 (length, width) in metres")
        yaw = math.radians(_num(f"{where}.yaw_deg", box.get("yaw_deg", 0.0)))
        for box_side in box_segments(cx, cy, float(size[0]), float(size[1]), yaw):
            segments.append(box_side)
            seg_shape.append(len(shapes) - 1)
    for i, cyl in enumerate(data.get("cylinders", [])):
        where = f"cylinders[{i}]"
        shapes.append(_look(where, cyl, CYLINDER, {"center", "radius_m"}))
        cx, cy = _point(f"{where}.center", cyl.get("center"))
        circles.append((cx, cy, _num(f"{where}.radius_m", cyl.get("radius_m"), 0.005, 50, "a radius > 0 in metres")))
        cir_shape.append(len(shapes) - 1)
    target = None
    if "target" in data:
        target = _target(data["target"])
        shapes.append(target.shape)
        x, y = target.path.points[0]
        circles.append((x, y, target.radius_m))
        cir_shape.append(len(shapes) - 1)
    start = data.get("start", {})
    start_pose = (
        _num("start.x_m", start.get("x_m", 0.0)),
        _num("start.y_m", start.get("y_m", 0.0)),
        math.radians(_num("start.theta_deg", start.get("theta_deg", 0.0))),
    )
    name = str(world.get("name", default_name))
    return make_scene(name, shapes, segments, seg_shape, circles, cir_shape=cir_shape, start=start_pose, target=target)


def _target(entry: dict[str, Any]) -> Target:
    shape = _look("target", entry, TARGET, {"radius_m", "speed_m_s", "path", "mode"})
    path = entry.get("path")
    if not (isinstance(path, list) and len(path) >= 1):
        raise ScenarioError("target.path", path, "a list of [x, y] waypoints (at least one)")
    points = tuple(_point(f"target.path[{i}]", p) for i, p in enumerate(path))
    mode = entry.get("mode", "loop")
    if mode not in ("loop", "bounce"):
        raise ScenarioError("target.mode", mode, "loop or bounce")
    return Target(
        radius_m=_num("target.radius_m", entry.get("radius_m", 0.12), 0.02, 5, "a radius in 0.02..5 m"),
        shape=Shape("target", "target", shape.height_m, shape.colour, shape.pattern, shape.colour2, shape.reflectivity),
        path=TargetPath(points, _num("target.speed_m_s", entry.get("speed_m_s", 0.0), 0, 5, "0..5 m/s"), mode),
    )
