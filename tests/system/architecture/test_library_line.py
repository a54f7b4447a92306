"""The line between the library and the tools, and the size of what a newcomer reads.

- A user's robot program needs only `host_sdk`: no doc's Python example and no example script
  imports the command package (`roverlink`), except the ROS 2 node's launch files, which start it.
- No hand-written module is over MODULE_LINES lines and no function over FUNCTION_LINES, unless
  it is listed below with the reason.
"""

from __future__ import annotations

import ast
import re
from pathlib import Path

ROOT = Path(__file__).resolve().parents[3]
MODULE_LINES = 500
FUNCTION_LINES = 80
TREES = ("protocol", "host_sdk", "emulator", "roverlink", "tests", "benchmarks", "examples", "scripts")
LONGER: dict[str, str] = {}
"""path or path::function -> why it is longer than the limit."""
FENCE = re.compile(r"```python\n(.*?)```", re.S)


def _imports_tools(source: str) -> list[str]:
    found = []
    for node in ast.walk(ast.parse(source)):
        names = [a.name for a in node.names] if isinstance(node, ast.Import) else []
        if isinstance(node, ast.ImportFrom) and node.module and node.level == 0:
            names = [node.module]
        found += [n for n in names if n.split(".")[0] == "roverlink"]
    return found


def test_docs_and_examples_import_nothing_from_the_command_package() -> None:
    offenders = []
    for doc in [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md"))]:
        for block in FENCE.findall(doc.read_text(encoding="utf-8")):
            offenders += [f"{doc.relative_to(ROOT)}: {name}" for name in _imports_tools(block)]
    for script in sorted((ROOT / "examples").rglob("*.py")):
        if "ros2" in script.parts:  # launch files start the ROS 2 node, which is the command's
            continue
        offenders += [f"{script.relative_to(ROOT)}: {n}" for n in _imports_tools(script.read_text(encoding="utf-8"))]
    assert offenders == []


def test_the_check_sees_an_import_of_the_tools() -> None:
    assert _imports_tools("import roverlink.follow\nfrom roverlink.sensors import x\nimport host_sdk") == [
        "roverlink.follow",
        "roverlink.sensors",
    ]


def _hand_written() -> list[Path]:
    files = [p for tree in TREES for p in (ROOT / tree).rglob("*.py")]
    return sorted(p for p in files if "generated" not in p.parts and ".venv" not in p.parts)


def test_no_module_or_function_is_longer_than_a_newcomer_reads_at_once() -> None:
    long = []
    for path in _hand_written():
        rel = str(path.relative_to(ROOT))
        source = path.read_text(encoding="utf-8")
        lines = source.count("\n")
        if lines > MODULE_LINES and rel not in LONGER:
            long.append(f"{rel}: {lines} lines")
        for node in ast.walk(ast.parse(source)):
            if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
                n = (node.end_lineno or node.lineno) - node.lineno + 1
                if n > FUNCTION_LINES and f"{rel}::{node.name}" not in LONGER:
                    long.append(f"{rel}::{node.name}: {n} lines")
    assert long == []
