"""The SDK's own floors (docs/architecture.md, "The SDK: its core and the applications above it").

    console, recording          on top, side by side
    autonomy                    the follower, the planner, the control loop
    perception, fusion,         side by side above the drivers
      hostinfo
    sensors                     the drivers and the sensor hub
    the core                    everything else: Robot, the session, transports, kinematics,
                                limits, odometry, errors, the supervisor, aio, the test plugin

The core imports none of the applications; an application imports the core, itself and the
layers below it, never one beside it or above it. Every import statement counts (module level,
inside functions, under TYPE_CHECKING).
"""

from __future__ import annotations

import ast
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[3]
LAYERS: tuple[frozenset[str], ...] = (
    frozenset({"sensors"}),
    frozenset({"perception", "fusion", "hostinfo"}),
    frozenset({"autonomy"}),
    frozenset({"console", "recording"}),
)
APPLICATIONS = frozenset().union(*LAYERS)
LEVEL = {name: i + 1 for i, layer in enumerate(LAYERS) for name in layer}  # the core is 0


def unit_of(module: str) -> str:
    """The application a module of host_sdk belongs to, or "core"."""
    parts = module.split(".")
    return parts[1] if len(parts) > 1 and parts[1] in APPLICATIONS else "core"


def imported_modules(path: Path, module: str, source: str) -> list[tuple[int, str]]:
    """(line, module) of every host_sdk module `source` imports (`from host_sdk import x` counts
    as host_sdk.x)."""
    found = []
    for node in ast.walk(ast.parse(source)):
        if isinstance(node, ast.Import):
            found += [(node.lineno, a.name) for a in node.names]
        elif isinstance(node, ast.ImportFrom):
            base = node.module or ""
            if node.level:
                package = module.split(".")[: -node.level if path.name != "__init__.py" else None]
                if path.name == "__init__.py" and node.level > 1:
                    package = package[: -(node.level - 1)]
                base = ".".join([*package, *([base] if base else [])])
            found += [(node.lineno, f"{base}.{a.name}") for a in node.names]
    return [(line, name) for line, name in found if name.split(".")[0] == "host_sdk"]


def violations(root: Path = ROOT) -> list[str]:
    out = []
    for path in sorted((root / "host_sdk").rglob("*.py")):
        rel = path.relative_to(root)
        module = ".".join(rel.with_suffix("").parts).removesuffix(".__init__")
        me = unit_of(module)
        for line, target in imported_modules(path, module, path.read_text(encoding="utf-8")):
            other = unit_of(target)
            if other in (me, "core"):
                continue
            if me == "core":
                out.append(f"{rel}:{line}: the core imports {other} ({target})")
            elif LEVEL[other] >= LEVEL[me]:
                where = "beside" if LEVEL[other] == LEVEL[me] else "above"
                out.append(f"{rel}:{line}: {me} imports {other}, which is {where} it ({target})")
    return out


def test_no_import_runs_against_the_sdks_layers() -> None:
    assert violations() == []


def test_every_subpackage_is_placed() -> None:
    """A new subpackage is either an application with a layer or named as part of the core here."""
    core = {"robot", "session", "transport", "supervisor", "aio", "testing"}
    found = {p.name for p in (ROOT / "host_sdk").iterdir() if (p / "__init__.py").exists()}
    assert found == APPLICATIONS | core


def test_the_check_sees_an_upward_import(tmp_path: Path) -> None:
    sdk = tmp_path / "host_sdk"
    for pkg in ("perception", "fusion", "sensors", "robot"):
        (sdk / pkg).mkdir(parents=True)
        (sdk / pkg / "__init__.py").write_text("")
    (sdk / "kinematics.py").write_text("def f():\n    from host_sdk.sensors import hub\n")
    (sdk / "sensors" / "hub.py").write_text(
        "from typing import TYPE_CHECKING\nif TYPE_CHECKING:\n    import host_sdk.fusion.ekf\n"
    )
    (sdk / "perception" / "a.py").write_text("from host_sdk import fusion\nfrom host_sdk.sensors import hub\n")
    (sdk / "robot" / "b.py").write_text("from ..perception import a\nfrom host_sdk import errors\n")
    assert violations(tmp_path) == [
        "host_sdk/kinematics.py:2: the core imports sensors (host_sdk.sensors.hub)",
        "host_sdk/perception/a.py:1: perception imports fusion, which is beside it (host_sdk.fusion)",
        "host_sdk/robot/b.py:1: the core imports perception (host_sdk.perception.a)",
        "host_sdk/sensors/hub.py:3: sensors imports fusion, which is above it (host_sdk.fusion.ekf)",
    ]


def test_importing_the_sdk_loads_its_core_only() -> None:
    code = (
        "import sys, host_sdk;"
        "from host_sdk import Robot, RobotDescription;"
        f"apps = {sorted(APPLICATIONS)!r};"
        "print(sorted(m for m in sys.modules if m.split('.')[:2][-1] in apps and m.startswith('host_sdk.')))"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True, cwd=ROOT)
    assert out.stdout.strip() == "[]"
