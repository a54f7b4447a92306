"""Check tests/roverlink/ros2/humble_api.toml against ROS 2 Humble's sources.

    python tools/ros2_humble_api.py RCLPY_GIT COMMON_INTERFACES_GIT RCL_INTERFACES_GIT GEOMETRY2_GIT [--write]

The arguments are git directories (clones or mirrors of ros2/rclpy, ros2/common_interfaces,
ros2/rcl_interfaces and ros2/geometry2); each is read at its `humble` branch. Every rclpy entry
of the list must exist there (a module's function, class or value; a class's method, property or
attribute, its bases' included; the C++ enums rclpy re-exports), every keyword must be a
parameter of that call, and a return type the source annotates must be the entry's; every
message and service field must be in its .msg/.srv file with the entry's type. Types the source
does not annotate are printed to be read by hand. `--write` puts the commits checked into the
list's [checked_against] table. Only names and types are taken, nothing else of the sources.

test_humble_api.py checks the other side, without these sources: that the bridge uses nothing
that is not on the list.
"""

from __future__ import annotations

import argparse
import ast
import re
import subprocess
import sys
from dataclasses import dataclass
from pathlib import Path

LIST = Path(__file__).resolve().parents[1] / "tests" / "roverlink" / "ros2" / "humble_api.toml"
REF = "humble"
PRIMITIVES = {
    "bool",
    "byte",
    "char",
    "float32",
    "float64",
    "int8",
    "uint8",
    "int16",
    "uint16",
    "int32",
    "uint32",
    "int64",
    "uint64",
    "string",
    "wstring",
}


class Source:
    """One repository at the humble branch."""

    def __init__(self, name: str, git: str) -> None:
        self.name = name
        self.git = git
        self.commit = self._git("rev-parse", f"{REF}^{{commit}}").strip()
        self.files = set(self._git("ls-tree", "-r", "--name-only", self.commit).split())

    def _git(self, *args: str) -> str:
        return subprocess.run(["git", "--git-dir", self.git, *args], check=True, capture_output=True, text=True).stdout

    def read(self, path: str) -> str:
        return self._git("show", f"{self.commit}:{path}")

    def version(self, package_xml: str) -> str:
        found = re.search(r"<version>([^<]+)</version>", self.read(package_xml))
        return found.group(1) if found else "?"


@dataclass
class Found:
    kind: str  # "def", "class", "value", "enum member"
    node: ast.AST | None
    module: str


class Rclpy:
    """rclpy's Python modules, and the C++ enums it re-exports from _rclpy."""

    def __init__(self, src: Source) -> None:
        self.modules: dict[str, ast.Module] = {}
        self.packages: set[str] = set()
        for path in src.files:
            if path.startswith("rclpy/rclpy/") and path.endswith(".py"):
                name = path[len("rclpy/") : -3].replace("/", ".")
                if name.endswith(".__init__"):
                    name = name.removesuffix(".__init__")
                    self.packages.add(name)
                self.modules[name] = ast.parse(src.read(path))
        self.cpp = "\n".join(src.read(p) for p in src.files if p.startswith("rclpy/src/") and p.endswith(".cpp"))

    def resolve(self, dotted: str) -> Found | None:
        parts = dotted.split(".")
        for cut in range(len(parts), 0, -1):
            module = ".".join(parts[:cut])
            if module in self.modules:
                found: Found | None = Found("module", self.modules[module], module)
                for name in parts[cut:]:
                    found = self._member(found, name) if found else None
                return found
        return None

    def _member(self, owner: Found, name: str) -> Found | None:
        if owner.kind == "module":
            return self._in_module(owner.module, name)
        if owner.kind == "class" and isinstance(owner.node, ast.ClassDef):
            return self._in_class(owner.node, owner.module, name)
        if owner.kind == "cpp enum" and isinstance(owner.node, ast.Constant):
            enum = owner.node.value
            pattern = rf'"{enum}"[^;]*?\.value\(\s*"{name}"'
            return Found("enum member", None, owner.module) if re.search(pattern, self.cpp, re.S) else None
        return None

    def _in_module(self, module: str, name: str) -> Found | None:
        for node in self.modules[module].body:
            if isinstance(node, ast.FunctionDef | ast.ClassDef) and node.name == name:
                return Found("class" if isinstance(node, ast.ClassDef) else "def", node, module)
            if isinstance(node, ast.Assign) and any(isinstance(t, ast.Name) and t.id == name for t in node.targets):
                value = node.value
                if (
                    isinstance(value, ast.Attribute)
                    and isinstance(value.value, ast.Name)
                    and value.value.id == "_rclpy"
                ):
                    return Found("cpp enum", ast.Constant(value.attr), module)
                return Found("value", node, module)
            if isinstance(node, ast.ImportFrom) and _absolute(module, node, self.packages) in self.modules:
                for alias in node.names:
                    if (alias.asname or alias.name) == name:
                        return self._in_module(_absolute(module, node, self.packages), alias.name)
        return None

    def _in_class(self, cls: ast.ClassDef, module: str, name: str) -> Found | None:
        for node in cls.body:
            if isinstance(node, ast.FunctionDef) and node.name == name:
                return Found("def", node, module)
            if isinstance(node, ast.Assign | ast.AnnAssign):
                targets = node.targets if isinstance(node, ast.Assign) else [node.target]
                if any(isinstance(t, ast.Name) and t.id == name for t in targets):
                    return Found("value", node, module)
        init = next((n for n in cls.body if isinstance(n, ast.FunctionDef) and n.name == "__init__"), None)
        for node in ast.walk(init) if init else ():
            store = isinstance(node, ast.Attribute) and isinstance(node.ctx, ast.Store) and node.attr == name
            if store and isinstance(node.value, ast.Name) and node.value.id == "self":  # type: ignore[attr-defined]
                return Found("value", node, module)
        for base in cls.bases:
            if isinstance(base, ast.Name):
                found = self._in_module(module, base.id)
                if found and found.kind == "class" and isinstance(found.node, ast.ClassDef):
                    member = self._in_class(found.node, found.module, name)
                    if member:
                        return member
        return None

    def qualified(self, module: str, annotation: ast.expr) -> str:
        """An annotation as a dotted name: an rclpy class through the module's imports."""
        text = ast.unparse(annotation).strip("'\"")
        for node in self.modules[module].body:
            if isinstance(node, ast.ImportFrom) and node.module:
                for alias in node.names:
                    if (alias.asname or alias.name) == text:
                        return f"{_absolute(module, node, self.packages)}.{alias.name}"
            if isinstance(node, ast.ClassDef) and node.name == text:
                return f"{module}.{text}"
        return text


def _absolute(module: str, node: ast.ImportFrom, packages: set[str]) -> str:
    """The module an import names, a relative one (`from .time import Time`) made absolute."""
    if not node.level:
        return node.module or ""
    parts = module.split(".")
    keep = len(parts) - node.level + (1 if module in packages else 0)
    return ".".join([*parts[:keep], *([node.module] if node.module else [])])


def _parameters(fn: ast.FunctionDef) -> tuple[set[str], bool]:
    a = fn.args
    return {p.arg for p in (*a.posonlyargs, *a.args, *a.kwonlyargs)} - {"self"}, a.kwarg is not None


def _slots(cls: ast.ClassDef) -> set[str]:
    for node in cls.body:
        if isinstance(node, ast.Assign) and any(isinstance(t, ast.Name) and t.id == "__slots__" for t in node.targets):
            return {str(e.value).lstrip("_") for e in getattr(node.value, "elts", []) if isinstance(e, ast.Constant)}
    return set()


def check_rclpy(rclpy: Rclpy, entries: dict[str, object]) -> tuple[list[str], list[str]]:
    """(problems, what to read by hand)."""
    problems, by_hand = [], []
    for path, entry in sorted(entries.items()):
        found = rclpy.resolve(path)
        if found is None:
            problems.append(f"{path}: not in Humble's rclpy")
            continue
        if isinstance(entry, str):
            if found.kind not in ("value", "def", "enum member"):
                problems.append(f"{path}: a {found.kind} in Humble, listed as a value of type {entry}")
            elif found.kind == "enum member" or (
                isinstance(found.node, ast.Assign) and entry == path.rsplit(".", 1)[0]
            ):
                pass  # an enum's member is of the enum's type
            elif isinstance(found.node, ast.Assign) and isinstance(found.node.value, ast.Call):
                made = rclpy.qualified(found.module, found.node.value.func)
                if made != entry:
                    problems.append(f"{path}: made by {made} in Humble, listed as {entry}")
            elif isinstance(found.node, ast.FunctionDef) and found.node.returns is not None:
                returns = rclpy.qualified(found.module, found.node.returns)
                if returns != entry:
                    problems.append(f"{path}: a property of type {returns} in Humble, listed as {entry}")
            else:
                by_hand.append(f"{path}: type {entry}")
            continue
        assert isinstance(entry, dict)
        keywords = set(entry.get("keywords", []))
        if found.kind == "class" and isinstance(found.node, ast.ClassDef):
            if entry.get("returns") != path:
                problems.append(
                    f"{path}: a class in Humble; calling it returns {path}, listed as {entry.get('returns')}"
                )
            init = rclpy.resolve(f"{path}.__init__")
            if isinstance(getattr(init, "node", None), ast.FunctionDef):
                params, any_kw = _parameters(init.node)  # type: ignore[union-attr,arg-type]
                allowed = params | (_slots(found.node) if any_kw else set())
            else:
                allowed = set()
        elif found.kind == "def" and isinstance(found.node, ast.FunctionDef):
            allowed, _ = _parameters(found.node)
            if found.node.returns is not None:
                returns = rclpy.qualified(found.module, found.node.returns)
                if returns != entry.get("returns"):
                    problems.append(f"{path}: returns {returns} in Humble, listed as {entry.get('returns')}")
            else:
                by_hand.append(f"{path}: returns {entry.get('returns')}")
        elif found.kind == "cpp enum":
            allowed = set()  # pybind11's enum: its members are the entries below it
        else:
            problems.append(f"{path}: a {found.kind} in Humble, listed as a call")
            continue
        if keywords - allowed:
            problems.append(f"{path}: Humble's takes no keyword {sorted(keywords - allowed)}")
    return problems, by_hand


def message_fields(text: str, package: str) -> dict[str, str]:
    """Field name -> type (package-qualified) of a .msg file, or of one half of a .srv."""
    fields = {}
    for raw in text.splitlines():
        line = raw.split("#")[0].strip()
        if not line or "=" in line.split()[1 if len(line.split()) > 1 else 0]:
            continue  # blank, a comment, or a constant
        type_name, name = line.split()[:2]
        base = re.split(r"[\[<]", type_name)[0]
        if base not in PRIMITIVES and "/" not in base:
            type_name = f"{'std_msgs' if base == 'Header' else package}/{type_name}"
        fields[name] = type_name
    return fields


def find_interface(sources: list[Source], name: str, kind: str) -> tuple[Source, str] | None:
    package, short = name.split("/")
    for src in sources:
        for path in src.files:
            if path.endswith(f"{package}/{kind}/{short}.{kind}"):
                return src, path
    return None


def check_messages(sources: list[Source], data: dict[str, object]) -> list[str]:
    problems = []
    halves: list[tuple[str, str, dict[str, str]]] = []
    for name, fields in dict(data.get("messages", {})).items():  # type: ignore[call-overload]
        where = find_interface(sources, name, "msg")
        if where is None:
            problems.append(f"{name}: no such message in Humble")
            continue
        halves.append((name, where[0].read(where[1]), fields))
    for name, parts in dict(data.get("services", {})).items():  # type: ignore[call-overload]
        where = find_interface(sources, name, "srv")
        if where is None:
            problems.append(f"{name}: no such service in Humble")
            continue
        request, _, response = where[0].read(where[1]).partition("---")
        halves.append((f"{name} request", request, parts.get("request", {})))
        halves.append((f"{name} response", response, parts.get("response", {})))
    for name, text, fields in halves:
        actual = message_fields(text, name.split("/")[0])
        for field, type_name in fields.items():
            if field not in actual:
                problems.append(f"{name}.{field}: not in Humble's definition")
            elif actual[field] != type_name:
                problems.append(f"{name}.{field}: {actual[field]} in Humble, listed as {type_name}")
    return problems


def write_checked(sources: list[Source], versions: dict[str, str]) -> None:
    lines = [f'branch = "{REF}"']
    lines += [f'{s.name} = "{s.commit} ({versions[s.name]})"' for s in sources]
    text = LIST.read_text(encoding="utf-8")
    table = re.compile(r"(\[checked_against\]\n)(?:[^\[\n][^\n]*\n)*", re.S)
    LIST.write_text(table.sub(lambda m: m.group(1) + "\n".join(lines) + "\n", text, count=1), encoding="utf-8")


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    for name in ("rclpy", "common_interfaces", "rcl_interfaces", "geometry2"):
        parser.add_argument(name, help=f"git directory of ros2/{name}")
    parser.add_argument("--write", action="store_true", help="record the commits checked in the list")
    args = parser.parse_args()
    from protocol.toml import tomllib  # noqa: PLC0415 (run from the checkout: python tools/...)

    data = tomllib.loads(LIST.read_text(encoding="utf-8"))
    sources = [Source(n, getattr(args, n)) for n in ("rclpy", "common_interfaces", "rcl_interfaces", "geometry2")]
    versions = {
        "rclpy": sources[0].version("rclpy/package.xml"),
        "common_interfaces": sources[1].version("std_msgs/package.xml"),
        "rcl_interfaces": sources[2].version("rcl_interfaces/package.xml"),
        "geometry2": sources[3].version("tf2_msgs/package.xml"),
    }
    problems, by_hand = check_rclpy(Rclpy(sources[0]), data.get("rclpy", {}))
    problems += check_messages(sources[1:], data)
    for s in sources:
        print(f"{s.name}: {REF} at {s.commit} ({versions[s.name]})")
    for line in by_hand:
        print(f"not annotated in the source, read by hand: {line}")
    for line in problems:
        print(f"PROBLEM: {line}")
    if problems:
        return 1
    if args.write:
        write_checked(sources, versions)
    print(
        f"{len(data.get('rclpy', {}))} rclpy entries, {len(data.get('messages', {}))} messages and "
        f"{len(data.get('services', {}))} services agree with Humble"
    )
    return 0


if __name__ == "__main__":
    sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
    sys.exit(main())
