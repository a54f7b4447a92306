"""No circular imports: the module graph of every package is a DAG (docs/architecture.md).

The graph is read from the source, not from sys.modules: every `import` and `from ... import`
counts, at module level, inside a function and under TYPE_CHECKING alike, so neither a lazy
import nor a typing-only one can hide a cycle. A cycle is reported as a chain `a -> b -> a`.
"""

from __future__ import annotations

import ast
from pathlib import Path

ROOT = Path(__file__).resolve().parents[3]
PACKAGES = ("protocol", "host_sdk", "emulator", "roverlink")


def modules(root: Path, packages: tuple[str, ...] = PACKAGES) -> dict[str, tuple[Path, bool]]:
    """Dotted module name -> (file, is a package's __init__)."""
    out = {}
    for package in packages:
        for path in sorted((root / package).rglob("*.py")):
            parts = list(path.relative_to(root).with_suffix("").parts)
            is_package = parts[-1] == "__init__"
            out[".".join(parts[:-1] if is_package else parts)] = (path, is_package)
    return out


def _known(name: str, mods: dict[str, tuple[Path, bool]]) -> str | None:
    """`name`, or the nearest enclosing module of ours (`a.b.attr` -> `a.b`); None if foreign."""
    while name and name not in mods:
        name = name.rpartition(".")[0]
    return name or None


def imports_of(module: str, path: Path, is_package: bool, mods: dict[str, tuple[Path, bool]]) -> set[str]:
    """The modules of ours that `module` imports anywhere in its source."""
    here = module if is_package else module.rpartition(".")[0]
    names: list[str] = []
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
        if isinstance(node, ast.Import):
            names += [alias.name for alias in node.names]
        elif isinstance(node, ast.ImportFrom):
            base = node.module or ""
            if node.level:  # relative: one dot is this package, each more dot one package up
                anchor = here
                for _ in range(node.level - 1):
                    anchor = anchor.rpartition(".")[0]
                base = f"{anchor}.{base}" if base else anchor
            # `from pkg import name` imports the submodule pkg.name when there is one, else pkg
            names += [f"{base}.{a.name}" if f"{base}.{a.name}" in mods else base for a in node.names]
    found = {known for name in names if (known := _known(name, mods))}
    found.discard(module)
    return found


def import_graph(root: Path = ROOT, packages: tuple[str, ...] = PACKAGES) -> dict[str, set[str]]:
    mods = modules(root, packages)
    return {name: imports_of(name, path, is_package, mods) for name, (path, is_package) in mods.items()}


def strongly_connected(graph: dict[str, set[str]]) -> list[list[str]]:
    """Tarjan's strongly connected components with more than one module, iteratively (no recursion
    limit on a deep graph)."""
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    on_stack: set[str] = set()
    found: list[list[str]] = []
    for start in sorted(graph):
        if start in index:
            continue
        work = [(start, iter(sorted(graph[start])))]
        index[start] = low[start] = len(index)
        stack.append(start)
        on_stack.add(start)
        while work:
            node, edges = work[-1]
            nxt = next(edges, None)
            if nxt is not None:
                if nxt not in index:
                    index[nxt] = low[nxt] = len(index)
                    stack.append(nxt)
                    on_stack.add(nxt)
                    work.append((nxt, iter(sorted(graph[nxt]))))
                elif nxt in on_stack:
                    low[node] = min(low[node], index[nxt])
                continue
            work.pop()
            if work:
                low[work[-1][0]] = min(low[work[-1][0]], low[node])
            if low[node] == index[node]:
                component = []
                while True:
                    member = stack.pop()
                    on_stack.discard(member)
                    component.append(member)
                    if member == node:
                        break
                if len(component) > 1:
                    found.append(sorted(component))
    return sorted(found)


def chain(graph: dict[str, set[str]], component: list[str]) -> list[str]:
    """The shortest cycle through a component's first module, [a, b, ..., a] (breadth first)."""
    members = set(component)
    first = component[0]
    came_from: dict[str, str] = {}
    frontier = [first]
    while first not in came_from:
        reached = []
        for node in frontier:
            for nxt in sorted(graph[node] & members):
                if nxt not in came_from:
                    came_from[nxt] = node
                    reached.append(nxt)
        frontier = reached
    path = [first]
    while len(path) == 1 or path[-1] != first:
        path.append(came_from[path[-1]])
    return path[::-1]


def cycles(root: Path = ROOT, packages: tuple[str, ...] = PACKAGES) -> list[str]:
    """Each import cycle as a readable chain `a -> b -> a`; when more modules are tangled in it
    (several cycles through them), the chain is one of them and all are named after it."""
    graph = import_graph(root, packages)
    out = []
    for component in strongly_connected(graph):
        path = chain(graph, component)
        more = "" if len(path) - 1 == len(component) else f"  (tangled: {', '.join(component)})"
        out.append(" -> ".join(path) + more)
    return out


def test_no_import_cycles() -> None:
    found = cycles()
    assert not found, "import cycles:\n  " + "\n  ".join(found)


def test_the_check_sees_lazy_and_type_checking_cycles(tmp_path: Path) -> None:
    pkg = tmp_path / "host_sdk"
    (pkg / "sub").mkdir(parents=True)
    (pkg / "__init__.py").write_text("")
    (pkg / "sub" / "__init__.py").write_text("")
    (pkg / "a.py").write_text("import os\ndef f():\n    from host_sdk.sub import b\n")
    (pkg / "sub" / "b.py").write_text(
        "from typing import TYPE_CHECKING\nif TYPE_CHECKING:\n    from ..a import f\nX = 1\n"
    )
    (pkg / "c.py").write_text("from .sub.b import X\nfrom . import a\n")  # into the cycle, not part of it
    assert cycles(tmp_path, ("host_sdk",)) == ["host_sdk.a -> host_sdk.sub.b -> host_sdk.a"]


def test_the_check_names_every_module_of_a_tangle(tmp_path: Path) -> None:
    pkg = tmp_path / "emulator"
    pkg.mkdir()
    (pkg / "__init__.py").write_text("from emulator.x import X\n")
    (pkg / "x.py").write_text("from emulator import y\nX = 1\n")
    (pkg / "y.py").write_text("import emulator.x\nfrom . import z\n")
    (pkg / "z.py").write_text("from .y import Y\n")
    assert cycles(tmp_path, ("emulator",)) == [
        "emulator.x -> emulator.y -> emulator.x  (tangled: emulator.x, emulator.y, emulator.z)"
    ]
