"""The reference robots (protocol/spec/robots.toml): loaded and checked against the spec's ranges."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Any

from protocol.generator import wiring
from protocol.generator.hardware import Hardware
from protocol.generator.loader import SpecError
from protocol.generator.model import Field, Spec
from protocol.generator.wiring import Wiring
from protocol.toml import tomllib

KINEMATICS = ("diff", "ackermann")
POWER_UP_LIGHTS = ("AUTO", "OFF")
"""The LightsMode values a robot may power up in (MANUAL needs its masks from a host)."""


@dataclass(frozen=True)
class Robot:
    name: str
    example: str
    doc: str
    board: str
    capabilities: tuple[str, ...]
    kinematics: str
    feedback_mode: str
    lights_mode: str
    """LightsMode name of the turn signals at power-up (AUTO or OFF)."""
    track_mm: float
    wheelbase_mm: float
    config: tuple[tuple[Field, Any], ...]  # SET_CONFIG fields in wire order, with values
    pid: tuple[tuple[Field, Any], ...]  # SET_PID gains in wire order (wheel excluded)
    wiring: Wiring

    def value(self, name: str) -> Any:
        return next(v for f, v in self.config + self.pid if f.name == name)


def _values(path: str, entry: str, table: Any, fields: tuple[Field, ...]) -> tuple[tuple[Field, Any], ...]:
    if not isinstance(table, dict):
        raise SpecError(path, entry, "expected a table")
    names = [f.name for f in fields]
    missing = [n for n in names if n not in table]
    unknown = [k for k in table if k not in names]
    if missing or unknown:
        raise SpecError(path, entry, f"missing: {', '.join(missing) or '-'}; unknown: {', '.join(unknown) or '-'}")
    out = []
    for f in fields:
        v = table[f.name]
        where = f"{entry}.{f.name}"
        if f.enum is not None:
            if v not in [e.name for e in f.enum.values]:
                allowed = ", ".join(e.name for e in f.enum.values)
                raise SpecError(path, where, f"{v!r} is not a {f.enum.name} ({allowed})")
        elif isinstance(v, bool) or not isinstance(v, int | float) or (not f.is_float and not isinstance(v, int)):
            raise SpecError(path, where, f"{v!r} is not a {'number' if f.is_float else 'whole number'}")
        elif not f.lo <= v <= f.hi:
            raise SpecError(path, where, f"{v} is outside {f.lo:g}..{f.hi:g}")
        out.append((f, v))
    return tuple(out)


def parse(text: str, path: str, spec: Spec, contract: Hardware) -> tuple[Robot, ...]:
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise SpecError(path, "", f"not valid TOML: {exc}") from None
    config_fields = spec.message("SET_CONFIG").fields
    pid_fields = tuple(f for f in spec.message("SET_PID").fields if f.name != "wheel")
    boards = [v.name for v in spec.enum("Board").values]
    caps = [v.name for v in spec.enum("Capability").values]
    modes = [v.name for v in spec.enum("FeedbackMode").values]
    robots = []
    keys = {"name", "example", "doc", "board", "capabilities", "kinematics", "feedback_mode", "track_mm"}
    keys |= {"wheelbase_mm", "config", "pid", "wiring", "lights_mode"}
    lights = tuple(v.name for v in next(e for e in contract.enums if e.name == "Lights").values)
    for i, r in enumerate(data.get("robots", [])):
        entry = f"robots[{i}]"
        if set(r) != keys:
            raise SpecError(path, entry, f"keys must be exactly: {', '.join(sorted(keys))}")
        entry = f"robots[{i}] {r['name']}"
        if r["board"] not in boards:
            raise SpecError(path, entry, f"board {r['board']!r} is not one of {', '.join(boards)}")
        for c in r["capabilities"]:
            if c not in caps:
                raise SpecError(path, entry, f"capability {c!r} is not one of {', '.join(caps)}")
        if r["kinematics"] not in KINEMATICS:
            raise SpecError(path, entry, f"kinematics must be one of {', '.join(KINEMATICS)}")
        if r["feedback_mode"] not in modes:
            raise SpecError(path, entry, f"feedback_mode must be one of {', '.join(modes)}")
        if r["lights_mode"] not in POWER_UP_LIGHTS:
            raise SpecError(path, entry, f"lights_mode must be one of {', '.join(POWER_UP_LIGHTS)}")
        if not r["example"].isidentifier():
            raise SpecError(path, entry, "example must be a C++ identifier (it names the sketch folder)")
        robots.append(
            Robot(
                name=r["name"],
                example=r["example"],
                doc=r["doc"],
                board=r["board"],
                capabilities=tuple(r["capabilities"]),
                kinematics=r["kinematics"],
                feedback_mode=r["feedback_mode"],
                lights_mode=r["lights_mode"],
                track_mm=float(r["track_mm"]),
                wheelbase_mm=float(r["wheelbase_mm"]),
                config=_values(path, f"{entry}.config", r["config"], config_fields),
                pid=_values(path, f"{entry}.pid", r["pid"], pid_fields),
                wiring=wiring.parse(
                    path,
                    f"{entry}.wiring",
                    r["wiring"],
                    board=r["board"],
                    capabilities=tuple(r["capabilities"]),
                    lights=lights,
                ),
            )
        )
    for attr in ("name", "example"):
        seen = [getattr(r, attr) for r in robots]
        dup = {x for x in seen if seen.count(x) > 1}
        if dup:
            raise SpecError(path, "robots", f"duplicate {attr}: {', '.join(sorted(dup))}")
    return tuple(robots)


def load(path: Path, root: Path, spec: Spec, contract: Hardware) -> tuple[Robot, ...]:
    rel = path.resolve().relative_to(root.resolve()).as_posix()
    return parse(path.read_text(encoding="utf-8"), rel, spec, contract)
