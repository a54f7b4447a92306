"""Where an AVR ELF's instructions come from: code symbols and source lines (avr-nm, avr-addr2line).

Used by benchmarks/firmware.py to say where the cycles of a profiled call go. With LTO the line
tables give libgcc's and avr-libc's code (no debug information) to main, and inlined code keeps its
file and line but not its function's name, so a PC is named by the symbol containing it, and by
file and line only where the line tables agree with that symbol.
"""

from __future__ import annotations

import bisect
import re
import subprocess
from dataclasses import dataclass
from pathlib import Path

NO_LINE_INFO = "(no line info)"
CLONE = re.compile(r" \[clone [^]]*\]")


@dataclass(frozen=True)
class Source:
    file: str
    """Base name of the instruction's source file (innermost inline frame), or NO_LINE_INFO."""
    line: int
    function: str
    """The function the instruction belongs to (its symbol)."""


def symbols(elf: Path) -> list[tuple[int, str]]:
    """Code symbols, demangled, by address."""
    out = subprocess.run(
        ["avr-nm", "-n", "-C", "--defined-only", str(elf)], capture_output=True, text=True, check=True
    ).stdout
    syms = []
    for line in out.splitlines():
        parts = line.split(maxsplit=2)
        if len(parts) == 3 and parts[1] in "tTwW":
            syms.append((int(parts[0], 16), parts[2]))
    return syms


def symbol(elf: Path, name: str) -> int:
    for addr, sym in symbols(elf):
        if sym == name:
            return addr
    raise SystemExit(f"{elf}: no symbol {name}")


def sources(elf: Path, pcs: list[int]) -> dict[int, Source]:
    """Source of each PC, from one avr-addr2line run over all of them. With LTO the line tables
    give libgcc's and avr-libc's code (no debug information) to main: a PC whose outermost
    addr2line function is not the symbol containing it is named by the symbol alone."""
    syms = symbols(elf)
    starts = [a for a, _ in syms]
    out = subprocess.run(
        ["avr-addr2line", "-e", str(elf), "-a", "-f", "-C", "-i"],
        input="\n".join(hex(pc) for pc in pcs),
        capture_output=True,
        text=True,
        check=True,
    ).stdout
    frames: dict[int, list[str]] = {}
    current: list[str] = []
    for line in out.splitlines():
        if line.startswith("0x"):
            current = frames.setdefault(int(line, 16), [])
        else:
            current.append(line)
    result = {}
    for pc in pcs:
        i = bisect.bisect_right(starts, pc) - 1
        name = CLONE.sub("", syms[i][1]) if i >= 0 else "?"
        lines = frames.get(pc, [])
        if len(lines) >= 2 and CLONE.sub("", lines[-2]) == name:
            path, _, num = lines[1].partition(":")
            digits = re.match(r"\d+", num)
            result[pc] = Source(Path(path).name, int(digits.group()) if digits else 0, name)
        else:
            result[pc] = Source(NO_LINE_INFO, 0, name)
    return result


def function_lines(path: Path, head: str) -> range:
    """The lines of the function whose definition starts with `head` (up to its closing brace)."""
    lines = path.read_text(encoding="utf-8").splitlines()
    first = next(i for i, text in enumerate(lines) if text.startswith(head))
    last = next(i for i in range(first, len(lines)) if lines[i] == "}")
    return range(first + 1, last + 2)


def short(name: str) -> str:
    """A demangled name without its parameter list."""
    name = name.removesuffix(" const")
    if not name.endswith(")"):
        return name
    depth = 0
    for i in range(len(name) - 1, -1, -1):
        depth += {")": 1, "(": -1}.get(name[i], 0)
        if depth == 0:
            return name[:i]
    return name
