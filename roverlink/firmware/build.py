"""Build and flash the RoverLink Arduino firmware without the Arduino IDE: ``roverlink firmware build``.

    roverlink firmware build                          every example, each for its own board
    roverlink firmware build --example AckermannPiCar [--board uno] [--out DIR]
    roverlink firmware build --sketch path/to/MyRobot --board mega2560
    roverlink firmware flash --example AckermannPiCar --port /dev/ttyACM0 [--dry-run]

It drives avr-gcc directly, the way the Arduino IDE does: the Arduino core (Debian's
arduino-core-avr) is compiled once per board into an archive, the library's ``src/`` tree and the
sketch (``.ino`` with ``#include <Arduino.h>`` prepended, compiled as C++) are compiled with
``-Wall -Wextra -Werror``, and everything is linked with LTO and ``--gc-sections`` into an ELF and
an Intel HEX file. Flash and SRAM use are printed against the board's capacity.

Every object is cached under ``build/firmware/cache`` by a key over the compiler, the flags and the
content of the files it depends on (mtime and size for the Arduino core's own files, which only
change with a package upgrade), so a rebuild of an unchanged sketch links nothing new. Files are
written under a temporary name and renamed into place, so concurrent builds (pytest-xdist, two
terminals) never see a half-written object.
"""

from __future__ import annotations

import concurrent.futures
import dataclasses
import hashlib
import os
import re
import shlex
import subprocess
import tempfile
from collections.abc import Callable, Iterable, Sequence
from pathlib import Path

from roverlink.firmware.boards import (
    BUILD_ROOT,
    LIBRARY_DIR,
    BoardSpec,
    CompileError,
    FirmwareError,
    board_spec,
    example_board,
    example_dir,
)
from roverlink.firmware.toolchain import SIZE_FLAGS, Flags, Toolchain


@dataclasses.dataclass(frozen=True)
class BuildResult:
    """A linked firmware: where it is and how much of the board it uses."""

    name: str
    board: BoardSpec
    elf: Path
    hex: Path
    flash_used: int  # .text + .data (initialised data is stored in flash and copied at boot)
    sram_used: int  # .data + .bss + .noinit: static RAM, before any stack
    linked: bool  # False when an up-to-date ELF was reused

    @property
    def flash_percent(self) -> float:
        return 100.0 * self.flash_used / self.board.flash_bytes

    @property
    def sram_percent(self) -> float:
        return 100.0 * self.sram_used / self.board.sram_bytes

    def summary(self) -> str:
        return (
            f"{self.name} ({self.board.name}): "
            f"flash {self.flash_used:,} / {self.board.flash_bytes:,} B ({self.flash_percent:.1f}%), "
            f"SRAM {self.sram_used:,} / {self.board.sram_bytes:,} B ({self.sram_percent:.1f}%)"
        )


def _digest(*parts: str | bytes) -> str:
    h = hashlib.sha256()
    for part in parts:
        data = part.encode() if isinstance(part, str) else part
        h.update(len(data).to_bytes(8, "little"))
        h.update(data)
    return h.hexdigest()[:24]


def _tree_digest(files: Iterable[Path], *, by_content: bool) -> str:
    parts: list[str | bytes] = []
    for f in sorted(files):
        parts.append(str(f))
        if by_content:
            parts.append(f.read_bytes())
        else:
            st = f.stat()
            parts.append(f"{st.st_size}:{st.st_mtime_ns}")
    return _digest(*parts)


def _replace_atomically(write: Callable[[Path], object], target: Path) -> None:
    """Runs write(tmp) and renames tmp to target, so readers never see a partial file."""
    target.parent.mkdir(parents=True, exist_ok=True)
    fd, name = tempfile.mkstemp(prefix=f".{target.name}.", suffix=".tmp", dir=target.parent)
    os.close(fd)
    tmp = Path(name)
    try:
        write(tmp)
        tmp.chmod(0o644)  # mkstemp's 0600 would make the file the user's alone, unlike the compiler's output
        os.replace(tmp, target)
    finally:
        tmp.unlink(missing_ok=True)


def _run(cmd: Sequence[str], what: str) -> str:
    result = subprocess.run(list(cmd), capture_output=True, text=True, check=False)
    if result.returncode != 0:
        output = f"{result.stdout}{result.stderr}"
        raise CompileError(f"{what} failed (exit {result.returncode}):\n{shlex.join(cmd)}\n{output}")
    return result.stdout


class Builder:
    """Compiles and links sketches for one board, sharing the object cache with every other build."""

    def __init__(
        self,
        board: BoardSpec,
        *,
        toolchain: Toolchain | None = None,
        cache_dir: Path | None = None,
        lto: bool = True,
        jobs: int | None = None,
    ) -> None:
        self.board = board
        self.tools = toolchain or Toolchain.find()
        self.flags = Flags(board, self.tools.core_dir, lto)
        self.cache = (cache_dir or BUILD_ROOT / "cache") / board.name
        self.jobs = jobs or os.cpu_count() or 2

    # Objects ------------------------------------------------------------------------------------
    def _compile(self, source: Path, flags: list[str], key: str) -> Path:
        obj = self.cache / "obj" / f"{source.name}.{_digest(key, *flags)}.o"
        if not obj.is_file():
            compiler = self.tools.gxx if source.suffix == ".cpp" else self.tools.gcc
            _replace_atomically(
                lambda tmp: _run([compiler, *flags, "-c", str(source), "-o", str(tmp)], f"compiling {source}"), obj
            )
        return obj

    def _compile_all(self, jobs: list[tuple[Path, list[str], str]]) -> list[Path]:
        with concurrent.futures.ThreadPoolExecutor(max_workers=self.jobs) as pool:
            futures = [pool.submit(self._compile, src, flags, key) for src, flags, key in jobs]
            return [f.result() for f in futures]

    def core_archive(self) -> Path:
        """The Arduino core for this board as one archive (compiled once, then reused)."""
        core = self.tools.core_dir / "cores" / "arduino"
        variant = self.tools.core_dir / "variants" / self.board.variant
        sources = sorted(p for p in core.iterdir() if p.suffix in (".c", ".cpp", ".S"))
        headers = [p for d in (core, variant) for p in d.iterdir() if p.is_file()]
        base = _digest(self.tools.version, " ".join(self.flags.common()), _tree_digest(headers, by_content=False))
        archive = self.cache / f"core-{_digest(base, _tree_digest(sources, by_content=False))}.a"
        if archive.is_file():
            return archive
        jobs = [(src, self.flags.for_core(src), _digest(base, "core", src.read_bytes())) for src in sources]
        objects = self._compile_all(jobs)

        def write_archive(tmp: Path) -> None:
            tmp.unlink()  # ar would try to read the empty placeholder as an archive
            _run([self.tools.ar, "rcs", str(tmp), *map(str, objects)], "archiving the Arduino core")

        _replace_atomically(write_archive, archive)
        return archive

    def library_objects(self) -> list[Path]:
        """Every .c/.cpp/.S under the library's src/, as the IDE compiles a library (recursively)."""
        src = LIBRARY_DIR / "src"
        files = sorted(p for p in src.rglob("*") if p.is_file())
        sources = [p for p in files if p.suffix in (".c", ".cpp", ".S")]
        # Keyed on the whole tree: any header change recompiles the library (a few seconds) rather
        # than trusting a dependency scan.
        base = _digest(self.tools.version, " ".join(self.flags.common()), _tree_digest(files, by_content=True))
        jobs = [(s, self.flags.for_ours(s, [src]), _digest(base, str(s))) for s in sources]
        return self._compile_all(jobs)

    def sketch_objects(self, sketch: Path) -> list[Path]:
        """The sketch's .ino files (joined, with Arduino.h first) and any .c/.cpp beside them."""
        name = sketch.name
        main = sketch / f"{name}.ino"
        if not main.is_file():
            raise FirmwareError(f"{sketch} is not a sketch folder: it has no {name}.ino")
        inos = [main, *sorted(p for p in sketch.glob("*.ino") if p != main)]
        text = "#include <Arduino.h>\n" + "".join(f'#line 1 "{p}"\n{p.read_text(encoding="utf-8")}\n' for p in inos)
        src = LIBRARY_DIR / "src"
        context = _digest(
            self.tools.version,
            " ".join(self.flags.common()),
            _tree_digest((p for p in src.rglob("*") if p.is_file()), by_content=True),
            _tree_digest((p for p in sketch.iterdir() if p.is_file()), by_content=True),
        )
        generated = self.cache / "sketch" / f"{name}.{context}.ino.cpp"
        if not generated.is_file():
            _replace_atomically(lambda tmp: tmp.write_text(text, encoding="utf-8"), generated)
        includes = [sketch, src]
        jobs = [(generated, self.flags.for_ours(generated, includes), context)]
        for extra in sorted(p for p in sketch.iterdir() if p.suffix in (".c", ".cpp", ".S")):
            jobs.append((extra, self.flags.for_ours(extra, includes), _digest(context, str(extra))))
        return self._compile_all(jobs)

    # Linking ------------------------------------------------------------------------------------
    def build(self, sketch: Path, out_dir: Path | None = None) -> BuildResult:
        """Compiles (from the cache where possible) and links `sketch` into out_dir/<name>.elf/.hex."""
        sketch = sketch.resolve()
        name = sketch.name
        out = (out_dir or BUILD_ROOT / name / self.board.name).resolve()
        objects = [*self.sketch_objects(sketch), *self.library_objects()]
        archive = self.core_archive()
        # With LTO the code is generated at link time: the size flags must be given here as well.
        link_flags = [f"-mmcu={self.board.mcu}", "-Os", "-g", *SIZE_FLAGS, "-mrelax", "-Wl,--gc-sections"]
        if self.flags.lto:
            link_flags += ["-flto", "-fuse-linker-plugin"]
        elf, hex_file, stamp = out / f"{name}.elf", out / f"{name}.hex", out / f"{name}.link-key"
        key = _digest(self.tools.version, " ".join(link_flags), *map(str, objects), str(archive))
        linked = False
        if not (elf.is_file() and hex_file.is_file() and stamp.is_file() and stamp.read_text() == key):
            cmd = [self.tools.gcc, *link_flags, *map(str, objects), str(archive), "-lm"]
            _replace_atomically(lambda tmp: _run([*cmd, "-o", str(tmp)], f"linking {name}"), elf)
            _replace_atomically(
                lambda tmp: _run([self.tools.objcopy, "-O", "ihex", "-R", ".eeprom", str(elf), str(tmp)], "objcopy"),
                hex_file,
            )
            _replace_atomically(lambda tmp: tmp.write_text(key), stamp)
            linked = True
        flash, sram = self.sizes(elf)
        return BuildResult(name, self.board, elf, hex_file, flash, sram, linked)

    def sizes(self, elf: Path) -> tuple[int, int]:
        """(flash, SRAM) bytes from the ELF's section sizes (avr-size -A)."""
        text = _run([self.tools.size, "-A", str(elf)], "avr-size")
        sections: dict[str, int] = {}
        for line in text.splitlines():
            m = re.match(r"^(\.\S+)\s+(\d+)\s+\d+", line)
            if m:
                sections[m.group(1)] = int(m.group(2))
        flash = sections.get(".text", 0) + sections.get(".data", 0)
        sram = sections.get(".data", 0) + sections.get(".bss", 0) + sections.get(".noinit", 0)
        return flash, sram


def build_sketch(sketch: Path, board: BoardSpec | str, out_dir: Path | None = None, *, lto: bool = True) -> BuildResult:
    spec = board_spec(board) if isinstance(board, str) else board
    return Builder(spec, lto=lto).build(sketch, out_dir)


def build_example(name: str, board: BoardSpec | str | None = None, out_dir: Path | None = None) -> BuildResult:
    sketch = example_dir(name)
    spec = example_board(name) if board is None else board_spec(board) if isinstance(board, str) else board
    return build_sketch(sketch, spec, out_dir)
