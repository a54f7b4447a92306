"""Line coverage of the Arduino library's code on the fuzz corpora, all targets together.

    python3 tests/firmware/fuzz/coverage.py BUILD_DIR TARGET...     # `make -C tests/firmware/fuzz coverage` runs it

Each target's coverage build has its own profile (BUILD_DIR/cov/<target>.profdata); `llvm-cov
export -format=lcov` gives each one's line counts, and a line counts as covered when any target ran
it. (Merging the profiles of three binaries into one would drop the counts of functions that the
binaries compile differently, such as each target's entry point.) Prints one row per source file
of src/wire, src/codec and src/core, then the totals of each folder (all files, and its .cpp files only).
"""

from __future__ import annotations

import shutil
import subprocess
import sys
from collections import defaultdict
from pathlib import Path

ROOT = Path(__file__).resolve().parents[3]
SRC = ROOT / "arduino" / "RoverLink" / "src"
FOLDERS = ("wire", "codec", "core")


def llvm_cov() -> str:
    for name in ("llvm-cov-14", "llvm-cov"):
        if shutil.which(name):
            return name
    raise SystemExit("llvm-cov not found (Debian: llvm-14)")


def line_hits(binary: Path, profdata: Path) -> dict[str, dict[int, int]]:
    """{source file: {line: count}} from one binary's lcov export."""
    out = subprocess.run(
        [llvm_cov(), "export", "-format=lcov", str(binary), f"-instr-profile={profdata}"],
        capture_output=True,
        text=True,
        check=True,
    ).stdout
    hits: dict[str, dict[int, int]] = defaultdict(dict)
    current = ""
    for line in out.splitlines():
        if line.startswith("SF:"):
            current = line[3:]
        elif line.startswith("DA:"):
            number, count = line[3:].split(",")[:2]
            hits[current][int(number)] = hits[current].get(int(number), 0) + int(count)
    return hits


def main(build: Path, targets: list[str]) -> None:
    union: dict[str, dict[int, int]] = defaultdict(dict)
    for target in targets:
        for path, lines in line_hits(build / "cov" / f"fuzz_{target}", build / "cov" / f"{target}.profdata").items():
            for number, count in lines.items():
                union[path][number] = union[path].get(number, 0) + count
    totals: dict[str, list[int]] = {f"src/{folder} (all files)": [0, 0] for folder in FOLDERS}
    totals |= {f"src/{folder}/*.cpp": [0, 0] for folder in FOLDERS}
    print(f"{'file':32} {'lines':>6} {'covered':>8}")
    for path in sorted(union):
        rel = Path(path).resolve().relative_to(SRC) if Path(path).resolve().is_relative_to(SRC) else None
        if rel is None or rel.parts[0] not in FOLDERS:
            continue
        lines = union[path]
        covered = sum(1 for c in lines.values() if c > 0)
        for key in (f"src/{rel.parts[0]} (all files)", f"src/{rel.parts[0]}/*.cpp"):
            if key.endswith("(all files)") or rel.suffix == ".cpp":
                totals[key][0] += len(lines)
                totals[key][1] += covered
        print(f"{rel!s:32} {len(lines):6} {covered / len(lines):8.1%}")
    for name, (n, covered) in totals.items():
        print(f"{name:32} {n:6} {covered / max(1, n):8.1%}")


if __name__ == "__main__":
    main(Path(sys.argv[1]), sys.argv[2:])
