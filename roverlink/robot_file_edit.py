"""Setting keys in the user's robot file without touching anything else (docs/robot-file.md).

    change = plan("my.toml", {"pid": {"kp": [5.3, 5.1]}})   # the new text, nothing written yet
    print("\\n".join(change.diff()))                         # what would change, line by line
    change.write()                                           # checked, then replaces the file whole

`roverlink calibrate` writes what it measures and `roverlink tune` the gains it found this way. A
file is the user's: only the lines of the keys set change (a trailing comment is kept), a
commented-out template line (`# key = ...`, as `robot new` writes them) becomes the key, a missing
key goes at the end of its section and a missing section at the end of the file. The edited text
is read back with protocol.robotfile and must give the values set, or nothing is written.
"""

from __future__ import annotations

import difflib
import math
import os
import re
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from protocol.robotfile import RobotFileError, parse
from protocol.toml import tomllib

Value = bool | int | float | tuple[bool, ...] | tuple[float, ...]
"""What the tools write: a number, a flag, or one per wheel channel."""

_HEADER = re.compile(r"^\s*\[\s*([A-Za-z0-9_.\"' -]+?)\s*\]\s*(#.*)?$")
_TABLE_ARRAY = re.compile(r"^\s*\[\[")


def toml_value(value: Value) -> str:
    """`value` as TOML (floats in their shortest exact form)."""
    if isinstance(value, tuple):
        return "[" + ", ".join(toml_value(v) for v in value) + "]"
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, int):
        return str(value)
    if not math.isfinite(value):
        raise ValueError(f"value {value!r} is not a number")
    return repr(float(value))


def _section_span(lines: list[str], section: str) -> tuple[int, int] | None:
    """(first line after the header, end) of table `section`; None if there is none."""
    start = None
    for i, line in enumerate(lines):
        header = _HEADER.match(line)
        if header is None and not _TABLE_ARRAY.match(line):
            continue
        if start is not None:
            return start, i
        if header is not None and header.group(1).replace(" ", "").strip("\"'") == section:
            start = i + 1
    return None if start is None else (start, len(lines))


def edited(text: str, section: str, values: dict[str, Value]) -> str:
    """`text` with each of `values` set in table `section` (see the module's docstring)."""
    newline = "\r\n" if "\r\n" in text else "\n"
    lines = text.splitlines(keepends=True)
    span = _section_span(lines, section)
    if span is None:
        if lines and not lines[-1].endswith(("\n", "\r")):
            lines[-1] += newline
        lines += [newline, f"[{section}]{newline}"]
        span = (len(lines), len(lines))
    start, end = span
    for key, value in values.items():
        at = _line_of(lines[start:end], key)
        if at is not None:
            at += start
            match = _assignment(key).match(lines[at])
            assert match is not None  # _line_of found it with the same pattern
            indent, _hash, comment, ending = match.groups()
            ending = ending or ("" if at == len(lines) - 1 else newline)
            lines[at] = f"{indent}{key} = {toml_value(value)}{comment or ''}{ending}"
            continue
        at = end
        while at > start and not lines[at - 1].strip():
            at -= 1  # after the section's last line, before the blank lines that end it
        if at > 0 and not lines[at - 1].endswith(("\n", "\r")):
            lines[at - 1] += newline
        lines.insert(at, f"{key} = {toml_value(value)}{newline}")
        end += 1
    return "".join(lines)


def _assignment(key: str) -> re.Pattern[str]:
    """`key = value  # comment` on one line (a value with no `#`), or the same commented out:
    (indent, '#', comment, line end)."""
    return re.compile(rf"^(\s*)(#\s*)?{re.escape(key)}\s*=\s*[^#\r\n]*?(\s*#[^\r\n]*)?(\r?\n)?$")


def _line_of(lines: list[str], key: str) -> int | None:
    """The line that sets `key`, else the commented-out template line for it."""
    pattern = _assignment(key)
    matches = [(i, m) for i, line in enumerate(lines) if (m := pattern.match(line)) is not None]
    for i, m in matches:
        if m.group(2) is None:
            return i
    return matches[0][0] if matches else None


def _plain(value: Any) -> Any:
    return tuple(value) if isinstance(value, list) else value


@dataclass(frozen=True)
class Change:
    """A robot file's text before and after setting some keys; nothing written until `write()`."""

    path: Path
    before: str
    after: str

    @property
    def empty(self) -> bool:
        return self.before == self.after

    def diff(self) -> list[str]:
        """The changed lines, as a unified diff of the file."""
        return [
            line.rstrip("\r\n")
            for line in difflib.unified_diff(
                self.before.splitlines(keepends=True),
                self.after.splitlines(keepends=True),
                str(self.path),
                f"{self.path} (new)",
                n=1,
            )
        ]

    def write(self) -> Path:
        """Replace the file with the new text, whole (a robot file is never left half written)."""
        temp = self.path.with_name(f".{self.path.name}.editing")
        with open(temp, "w", encoding="utf-8", newline="") as out:
            out.write(self.after)
        os.replace(temp, self.path)
        return self.path


def plan(path: str | Path, edits: dict[str, dict[str, Value]]) -> Change:
    """The file with `edits` ({section: {key: value}}) set, read back and checked: RobotFileError
    if it no longer reads, ValueError if it does not read back with the values (e.g. the section
    written as an inline table or a dotted key elsewhere: the user must edit it by hand)."""
    where = Path(path)
    before = where.read_text(encoding="utf-8")
    after = before
    for section, values in edits.items():
        after = edited(after, section, values)
    robot, problems = parse(after, str(where))
    if robot is None:
        raise RobotFileError(problems)
    data = tomllib.loads(after)
    for section, values in edits.items():
        table: Any = data
        for part in section.split("."):
            table = table.get(part, {}) if isinstance(table, dict) else {}
        got = {key: _plain(table.get(key)) for key in values}
        if got != values:
            raise ValueError(f"{where}: [{section}] could not be set to {values} (reads back {got}): edit it by hand")
    return Change(where, before, after)
