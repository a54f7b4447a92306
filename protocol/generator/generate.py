"""Render every generated file from the spec, write them, or check them for drift."""

from __future__ import annotations

import difflib
import tempfile
from pathlib import Path

from protocol.generator import hardware, loader, references
from protocol.generator.emit import cpp, docs, python, release, vectors
from protocol.generator.emit import hardware as hardware_outputs
from protocol.generator.emit import robots as robot_outputs
from protocol.generator.hardware import Hardware
from protocol.generator.model import Spec
from protocol.robotfile import RobotFile

ROOT = Path(__file__).resolve().parents[2]
SPEC = ROOT / "protocol" / "spec" / "roverlink.toml"
HARDWARE_FILE = "hardware.toml"  # beside the spec
ROBOTS_DIR = "robots"  # beside the spec's folder: protocol/robots/<name>.toml


def load(spec_path: Path, root: Path) -> tuple[Spec, tuple[RobotFile, ...], Hardware]:
    """The spec, the hardware contract beside it and the reference robots' files in the folder
    beside its folder (protocol/robots/); SpecError if any is invalid."""
    spec = loader.load(spec_path, root)
    contract = hardware.load(spec_path.parent / HARDWARE_FILE, root, spec)
    return spec, references.load(spec_path.parent.parent / ROBOTS_DIR, root), contract


def render(spec: Spec, robot_list: tuple[RobotFile, ...], contract: Hardware) -> dict[str, str]:
    """Every output: repository-relative path -> exact text."""
    out: dict[str, str] = {}
    for emitter in (python, cpp, docs, vectors, release):
        out.update(emitter.emit(spec))
    out.update(robot_outputs.emit(spec, robot_list))
    out.update(hardware_outputs.emit(contract))
    return dict(sorted(out.items()))


def stamped(spec: Spec, root: Path) -> dict[str, str]:
    """The hand-written files under `root` with their generated parts as the spec says (the ROS
    package's version); a file that is not there has nothing to stamp."""
    return release.stamp(spec, root)


def write(outputs: dict[str, str], root: Path) -> list[str]:
    """Write outputs under root; return the paths whose content changed."""
    changed = []
    for rel, text in outputs.items():
        path = root / rel
        if path.exists() and path.read_text(encoding="utf-8") == text:
            continue
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_text(text, encoding="utf-8", newline="\n")
        changed.append(rel)
    return changed


def stale(outputs: dict[str, str], root: Path) -> list[tuple[str, str]]:
    """(path, short diff) for each output that differs from what is in `root`.

    Rendering goes through a temporary folder first, so `check` compares real files byte for byte.
    """
    problems = []
    with tempfile.TemporaryDirectory() as tmp:
        write(outputs, Path(tmp))
        for rel in outputs:
            fresh = (Path(tmp) / rel).read_bytes()
            current = root / rel
            if not current.exists():
                problems.append((rel, "missing"))
                continue
            if current.read_bytes() != fresh:
                diff = difflib.unified_diff(
                    current.read_text(encoding="utf-8").splitlines(),
                    fresh.decode("utf-8").splitlines(),
                    f"{rel} (committed)",
                    f"{rel} (from spec)",
                    n=0,
                    lineterm="",
                )
                problems.append((rel, "\n".join(list(diff)[:12])))
    return problems
