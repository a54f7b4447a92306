"""Reading a robot file's sections against the schema: unknown keys (with the nearest valid one),
types, ranges and missing keys, every problem collected with its line."""

from __future__ import annotations

import difflib
import math
from typing import Any

from protocol.robotfile.errors import Problem
from protocol.robotfile.lines import line_of
from protocol.robotfile.schema import REQUIRED, SECTIONS, Key

TOP_TABLES: tuple[str, ...] = ("drive", "esc", "steering", "encoders", "geometry", "limits", "pid", "feedback")
TOP_TABLES += ("lights", "sensors", "footprint", "emulator", "firmware", "calibration")
SENSOR_KINDS = ("lidar", "imu", "camera")
EMULATOR_PARTS = ("motor", "body", "esc", "servo")
NESTED: dict[str, tuple[tuple[str, ...], str]] = {
    "sensors": (SENSOR_KINDS, "sensor"),
    "emulator": (EMULATOR_PARTS, "part"),
}
"""Tables of tables ([sensors.lidar], [emulator.motor]...): their inner tables, and what one is."""


def _dotted(section: str, path: tuple[str | int, ...]) -> str:
    out = section
    for step in path:
        out += f"[{step}]" if isinstance(step, int) else (f".{step}" if out else step)
    return out


class Reader:
    def __init__(self, path: str, text: str) -> None:
        self.path = path
        self.text = text
        self.problems: list[Problem] = []

    def report(self, section: str, path: tuple[str | int, ...], message: str) -> None:
        """A problem at `section` + `path` (a key, list index, inner key...)."""
        line = line_of(self.text, section, path)
        if line is None and path:
            line = line_of(self.text, section, path[:1])
        if line is None:
            line = line_of(self.text, section)
        self.problems.append(Problem(self.path, _dotted(section, path), line, message))

    def unknown(self, section: str, key: str, valid: list[str], what: str) -> None:
        near = difflib.get_close_matches(key, valid, n=1, cutoff=0.5)
        hint = f" (did you mean {near[0]!r}?)" if near else f" (valid: {', '.join(valid)})"
        self.report(section, (key,), f"unknown {what}{hint}")

    def top(self, data: dict[str, Any]) -> dict[str, Any]:
        """Top-level keys and the tables, each table checked; absent optional tables are None."""
        top_keys = [k.name for k in SECTIONS[""]]
        for key in data:
            if key not in top_keys and key not in TOP_TABLES:
                self.unknown("", key, top_keys + list(TOP_TABLES), "key")
        out = self.section("", {k: v for k, v in data.items() if k in top_keys})
        for name in TOP_TABLES:
            if name not in NESTED:
                raw = data.get(name)
                out[name] = None if raw is None else self.section(name, self.table("", name, raw))
        for outer, (parts, what) in NESTED.items():
            tables = self.table("", outer, data.get(outer, {}))
            for key in tables:
                if key not in parts:
                    self.unknown(outer, key, list(parts), what)
            for part in parts:
                raw, name = tables.get(part), f"{outer}.{part}"
                out[name] = None if raw is None else self.section(name, self.table(outer, part, raw))
        return out

    def table(self, section: str, key: str, raw: Any) -> dict[str, Any]:
        if isinstance(raw, dict):
            return raw
        self.report(section, (key,), f"= {raw!r} is not a table ([{_dotted(section, (key,))}])")
        return {}

    def section(self, section: str, table: dict[str, Any]) -> dict[str, Any]:
        """The section's values by key (defaults filled in, a bad value replaced by its default)."""
        keys = {k.name: k for k in SECTIONS[section]}
        if section:
            for name in table:
                if name not in keys:
                    self.unknown(section, name, list(keys), "key")
        out: dict[str, Any] = {}
        for name, spec in keys.items():
            if name not in table:
                if spec.default is REQUIRED:
                    self.report(section, (), f"missing key {_dotted(section, (name,))!r} ({spec.allowed()})")
                out[name] = None if spec.default is REQUIRED else spec.default
                continue
            value, problem = _value(spec, table[name])
            if problem:
                self.report(section, (name,), f"= {table[name]!r}: {problem}")
                value = None if spec.default is REQUIRED else spec.default
            out[name] = value
        return out


def _number(spec: Key, v: Any) -> tuple[Any, str]:
    if isinstance(v, bool) or not isinstance(v, int | float) or (spec.type == "int" and not isinstance(v, int)):
        return None, f"expected {'a whole number' if spec.type == 'int' else 'a number'} ({spec.allowed()})"
    if not math.isfinite(v):  # TOML's nan and inf: every comparison below would let NaN through
        return None, f"not a finite number (allowed: {spec.allowed()})"
    if (spec.lo is not None and v < spec.lo - 1e-12) or (spec.hi is not None and v > spec.hi + 1e-12):
        return None, f"out of range (allowed: {spec.allowed()})"
    return (int(v) if spec.type == "int" else float(v)), ""


def _value(spec: Key, v: Any) -> tuple[Any, str]:
    """(the value in its Python type, "") or (None, what is wrong and what is allowed)."""
    t = spec.type
    if t in ("int", "float"):
        return _number(spec, v)
    if t == "gain":  # one gain for every wheel, or one per wheel channel (their count: build.py)
        if not isinstance(v, list):
            return _number(spec, v)
        if not v:
            return None, f"expected {spec.allowed()}"
        gains = [_number(spec, x) for x in v]
        wrong = next((why for _, why in gains if why), "")
        return (None, wrong) if wrong else (tuple(g for g, _ in gains), "")
    if t == "str":
        return (v, "") if isinstance(v, str) else (None, "expected a string")
    if t == "bool":
        return (v, "") if isinstance(v, bool) else (None, "expected true or false")
    if t == "choice":
        if v in spec.choices:
            return v, ""
        near = difflib.get_close_matches(str(v), list(spec.choices), n=1, cutoff=0.5)
        return None, f"not {spec.allowed()}" + (f" (did you mean {near[0]!r}?)" if near else "")
    if t == "pin":
        ok = (isinstance(v, int) and not isinstance(v, bool)) or isinstance(v, str)
        return (v, "") if ok else (None, f"expected {spec.allowed()}")
    if t == "bools":
        ok = isinstance(v, list) and all(isinstance(x, bool) for x in v)
        return (tuple(v), "") if ok else (None, f"expected {spec.allowed()}")
    if t == "parts":
        ok = isinstance(v, list) and all(isinstance(x, dict) for x in v)
        return (v, "") if ok else (None, f"expected {spec.allowed()}")
    points = isinstance(v, list) and len(v) >= 3
    points = points and all(isinstance(p, list) and len(p) == 2 for p in v)
    points = points and all(isinstance(c, int | float) and not isinstance(c, bool) for p in v for c in p)
    if not points:
        return None, "expected at least three [x, y] points in m"
    if not all(math.isfinite(c) for p in v for c in p):
        return None, "expected at least three [x, y] points in m, each a finite number"
    return tuple((float(x), float(y)) for x, y in v), ""
