"""Render every generated file from the spec, write them, or check them for drift."""

from __future__ import annotations

import difflib
import tempfile
from pathlib import Path

from protocol.emit import cpp, docs, python, vectors
from protocol.model import Spec

ROOT = Path(__file__).resolve().parent.parent
SPEC = ROOT / "protocol" / "spec" / "roverlink.toml"


def render(spec: Spec) -> dict[str, str]:
    """Every output: repository-relative path -> exact text."""
    out: dict[str, str] = {}
    for emitter in (python, cpp, docs, vectors):
        out.update(emitter.emit(spec))
    return dict(sorted(out.items()))


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
