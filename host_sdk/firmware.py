"""Build and flash the RoverLink Arduino firmware without the Arduino IDE: ``roverlink firmware``.

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

import argparse
import concurrent.futures
import dataclasses
import hashlib
import os
import re
import shlex
import shutil
import subprocess
import sys
import tempfile
from collections.abc import Callable, Iterable, Sequence
from pathlib import Path

from serial.tools import list_ports

from host_sdk._generated.enums import Board
from host_sdk._generated.profiles import PROFILES
from host_sdk.errors import RoverLinkError

REPO_ROOT = Path(__file__).resolve().parents[1]
LIBRARY_DIR = Path(os.environ.get("ROVERLINK_LIBRARY_DIR", REPO_ROOT / "arduino" / "RoverLink"))
BUILD_ROOT = Path(os.environ.get("ROVERLINK_BUILD_DIR", REPO_ROOT / "build" / "firmware"))

# Where an Arduino AVR core may be: Debian's package, then the IDE / arduino-cli's own download.
CORE_DIR_ENV = "ARDUINO_AVR_CORE_DIR"
DEBIAN_CORE_DIR = Path("/usr/share/arduino/hardware/arduino/avr")
ARDUINO15_CORES = Path.home() / ".arduino15" / "packages" / "arduino" / "hardware" / "avr"  # <version>/ inside

TOOLCHAIN_PACKAGES = "gcc-avr avr-libc binutils-avr arduino-core-avr"
ARDUINO_VERSION = "10819"  # what the Arduino IDE 1.8.19 passes as -DARDUINO
# Beyond the IDE's -Os, for flash (each measured on the reference firmware, avr-gcc 5.4): function
# prologues and epilogues as calls to shared routines, X used only where it can address (AVR has no
# X+offset load, so avr-gcc otherwise adjusts X before and after each access), and four passes off
# that trade flash for speed on AVR. The linker also relaxes calls and jumps (-mrelax: call -> rcall).
SIZE_FLAGS = (
    "-mcall-prologues",
    "-mstrict-X",
    "-fno-move-loop-invariants",
    "-fno-split-wide-types",
    "-fno-tree-scev-cprop",
    "-fno-tree-tail-merge",
)
F_CPU = "16000000L"


class FirmwareError(RoverLinkError):
    """A firmware build or flash could not be done."""


class UnknownNameError(FirmwareError, ValueError):
    """An example, board or sketch name that does not exist; the message lists the allowed ones."""

    def __init__(self, kind: str, value: str, allowed: Iterable[str]) -> None:
        self.kind = kind
        self.value = value
        self.allowed = sorted(allowed)
        super().__init__(f"unknown {kind} {value!r}: choose one of {', '.join(self.allowed) or '(none)'}")


class ToolchainMissingError(FirmwareError, FileNotFoundError):
    """A compiler, the Arduino core or avrdude is not installed; the message says what to install."""


class CompileError(FirmwareError, RuntimeError):
    """The compiler or linker failed; the message carries its command and output."""


@dataclasses.dataclass(frozen=True)
class BoardSpec:
    """One Arduino board: compiler target, capacity and how avrdude talks to its bootloader."""

    name: str
    mcu: str
    define: str  # -DARDUINO_<define>, as the IDE passes it
    variant: str  # folder under the core's variants/
    flash_bytes: int  # program space usable next to the bootloader
    sram_bytes: int
    programmer: str
    baud: int
    avrdude_extra: tuple[str, ...]
    proto_board: Board


BOARDS: dict[str, BoardSpec] = {
    "uno": BoardSpec(
        name="uno",
        mcu="atmega328p",
        define="AVR_UNO",
        variant="standard",
        flash_bytes=32256,  # 32 KiB less the 512 B optiboot
        sram_bytes=2048,
        programmer="arduino",
        baud=115200,
        avrdude_extra=(),
        proto_board=Board.UNO,
    ),
    "mega2560": BoardSpec(
        name="mega2560",
        mcu="atmega2560",
        define="AVR_MEGA2560",
        variant="mega",
        flash_bytes=253952,  # 256 KiB less the 8 KiB stk500v2 bootloader
        sram_bytes=8192,
        programmer="wiring",
        baud=115200,
        # The Mega's bootloader does not implement chip erase: avrdude must not ask for one.
        avrdude_extra=("-D",),
        proto_board=Board.MEGA2560,
    ),
}
BOARD_BY_PROTO = {spec.proto_board: spec for spec in BOARDS.values()}


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


# -- names -----------------------------------------------------------------------------------------
def board_spec(name: str) -> BoardSpec:
    try:
        return BOARDS[name]
    except KeyError:
        raise UnknownNameError("board", name, BOARDS) from None


def examples() -> dict[str, Path]:
    """Example sketch folders of the library (a folder with a same-named .ino), by name."""
    root = LIBRARY_DIR / "examples"
    if not root.is_dir():
        raise FirmwareError(f"no Arduino library at {LIBRARY_DIR} (set ROVERLINK_LIBRARY_DIR)")
    return {d.name: d for d in sorted(root.iterdir()) if (d / f"{d.name}.ino").is_file()}


def example_board(example: str) -> BoardSpec:
    """The board an example targets, from the robot profiles (robots.toml)."""
    for profile in PROFILES.values():
        if profile.example == example:
            return BOARD_BY_PROTO[profile.board]
    raise FirmwareError(f"example {example!r} has no robot profile in robots.toml: pass --board")


def example_dir(name: str) -> Path:
    found = examples()
    if name not in found:
        raise UnknownNameError("example", name, found)
    return found[name]


# -- toolchain -------------------------------------------------------------------------------------
def _tool(name: str) -> str:
    path = shutil.which(name)
    if path is None:
        raise ToolchainMissingError(
            f"{name} not found on PATH: install the Debian packages {TOOLCHAIN_PACKAGES} "
            f"(sudo apt-get install {TOOLCHAIN_PACKAGES})"
        )
    return path


def arduino_core_dir() -> Path:
    """The Arduino AVR core (cores/arduino, variants/...): $ARDUINO_AVR_CORE_DIR or a known place."""
    configured = os.environ.get(CORE_DIR_ENV)
    if configured:
        candidates = [Path(configured)]
    else:
        newest_first = sorted(ARDUINO15_CORES.glob("*"), reverse=True) if ARDUINO15_CORES.is_dir() else []
        candidates = [DEBIAN_CORE_DIR, *newest_first]
    for candidate in candidates:
        if (candidate / "cores" / "arduino" / "Arduino.h").is_file():
            return candidate
    where = ", ".join(str(c) for c in candidates)
    raise ToolchainMissingError(
        f"Arduino AVR core not found (looked in {where}): install the Debian package arduino-core-avr "
        f"(sudo apt-get install {TOOLCHAIN_PACKAGES}) or set {CORE_DIR_ENV}"
    )


@dataclasses.dataclass(frozen=True)
class Toolchain:
    gcc: str
    gxx: str
    ar: str
    objcopy: str
    size: str
    core_dir: Path
    version: str  # avr-g++ --version, part of every cache key

    @classmethod
    def find(cls) -> Toolchain:
        gxx = _tool("avr-g++")
        version = subprocess.run([gxx, "--version"], capture_output=True, text=True, check=True).stdout
        return cls(
            gcc=_tool("avr-gcc"),
            gxx=gxx,
            ar=_tool("avr-gcc-ar"),  # the gcc-ar wrapper: archives of LTO objects need the plugin
            objcopy=_tool("avr-objcopy"),
            size=_tool("avr-size"),
            core_dir=arduino_core_dir(),
            version=version.splitlines()[0] if version else "",
        )


# -- compiling -------------------------------------------------------------------------------------
@dataclasses.dataclass(frozen=True)
class _Flags:
    board: BoardSpec
    core_dir: Path
    lto: bool

    def common(self) -> list[str]:
        flags = [
            f"-mmcu={self.board.mcu}",
            f"-DF_CPU={F_CPU}",
            f"-DARDUINO={ARDUINO_VERSION}",
            f"-DARDUINO_{self.board.define}",
            "-DARDUINO_ARCH_AVR",
            # Debian's WString.cpp uses DECIMAL_DIG, which this avr-libc's float.h lacks.
            "-DDECIMAL_DIG=17",
            "-Os",
            "-g",
            "-ffunction-sections",
            "-fdata-sections",
            *SIZE_FLAGS,
        ]
        if self.lto:
            flags += ["-flto", "-fno-fat-lto-objects"]
        return flags

    def core_includes(self, *, system: bool) -> list[str]:
        option = "-isystem" if system else "-I"
        dirs = [self.core_dir / "cores" / "arduino", self.core_dir / "variants" / self.board.variant]
        return [arg for d in dirs for arg in (option, str(d))]

    @staticmethod
    def language(source: Path) -> list[str]:
        suffix = source.suffix
        if suffix == ".c":
            return ["-x", "c", "-std=gnu11"]
        if suffix == ".S":
            return ["-x", "assembler-with-cpp"]
        # .cpp, and sketches (.ino.cpp): as the IDE, minus -fpermissive (our code is strict C++).
        return ["-x", "c++", "-std=gnu++11", "-fno-exceptions", "-fno-threadsafe-statics"]

    def for_core(self, source: Path) -> list[str]:
        # -w: the Arduino core is not ours to fix; the IDE compiles it the same way.
        return [*self.common(), *self.language(source), "-w", *self.core_includes(system=False)]

    def for_ours(self, source: Path, includes: Sequence[Path]) -> list[str]:
        # Core headers as system headers: their warnings are not ours, -Werror is for our code.
        inc = [arg for d in includes for arg in ("-I", str(d))]
        return [
            *self.common(),
            *self.language(source),
            "-Wall",
            "-Wextra",
            "-Werror",
            *inc,
            *self.core_includes(system=False),
        ]


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
        self.flags = _Flags(board, self.tools.core_dir, lto)
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


# -- flashing --------------------------------------------------------------------------------------
def avrdude_command(board: BoardSpec, hex_file: Path, port: str, avrdude: str = "avrdude") -> list[str]:
    """The avrdude call that writes hex_file through the board's bootloader on `port`."""
    return [
        avrdude,
        "-p",
        board.mcu,
        "-c",
        board.programmer,
        "-P",
        port,
        "-b",
        str(board.baud),
        *board.avrdude_extra,
        "-U",
        f"flash:w:{hex_file}:i",
    ]


def _known_ports() -> list[str]:
    return sorted(str(p.device) for p in list_ports.comports())


# -- command line ----------------------------------------------------------------------------------
def _targets(args: argparse.Namespace) -> list[tuple[Path, BoardSpec]]:
    board = board_spec(args.board) if args.board else None
    if args.sketch:
        if board is None:
            raise FirmwareError(f"--sketch needs --board (one of {', '.join(BOARDS)})")
        return [(Path(args.sketch), board)]
    if args.example:
        return [(example_dir(args.example), board or example_board(args.example))]
    # No example named: every example for its own board (or only those targeting --board).
    targets = [(path, example_board(name)) for name, path in examples().items()]
    if board is not None:
        targets = [(path, spec) for path, spec in targets if spec == board]
    return targets


def cmd_build(args: argparse.Namespace) -> int:
    """Compile examples (or a sketch) into ELF and HEX and print their flash and SRAM use."""
    targets = _targets(args)
    if args.out and len(targets) > 1:
        raise FirmwareError("--out needs a single --example or --sketch")
    for sketch, board in targets:
        result = Builder(board, lto=not args.no_lto).build(sketch, Path(args.out) if args.out else None)
        print(result.summary())
        print(f"  {result.hex}")
    return 0


def cmd_flash(args: argparse.Namespace) -> int:
    """Build an example (or sketch) and write it to a board through its bootloader with avrdude."""
    ((sketch, board),) = _targets(args)
    out = Path(args.out) if args.out else BUILD_ROOT / sketch.name / board.name
    hex_file = out.resolve() / f"{sketch.name}.hex"
    if args.dry_run:
        which = f"--sketch {sketch}" if args.sketch else f"--example {sketch.name}"
        print(f"# build first: roverlink firmware build {which} --board {board.name}")
        print(shlex.join(avrdude_command(board, hex_file, args.port)))
        return 0
    avrdude = shutil.which("avrdude")
    if avrdude is None:
        raise ToolchainMissingError(
            "avrdude not found on PATH: install the Debian package avrdude (sudo apt-get install avrdude)"
        )
    if not Path(args.port).exists() and "://" not in args.port:
        ports = _known_ports()
        raise UnknownNameError("port", args.port, ports)
    result = Builder(board, lto=not args.no_lto).build(sketch, Path(args.out) if args.out else None)
    print(result.summary())
    cmd = avrdude_command(board, result.hex, args.port, avrdude)
    print(shlex.join(cmd), flush=True)
    return subprocess.run(cmd, check=False).returncode


def _add_target_options(p: argparse.ArgumentParser, *, example_required: bool) -> None:
    which = p.add_mutually_exclusive_group(required=example_required)
    which.add_argument("--example", metavar="NAME", help="example sketch of the library (default: all)")
    which.add_argument("--sketch", metavar="DIR", help="a sketch folder of your own (needs --board)")
    p.add_argument(
        "--board", choices=sorted(BOARDS), help="target board (default: the one the example's robot profile names)"
    )
    p.add_argument("--out", metavar="DIR", help="where the ELF and HEX go (default: build/firmware/<sketch>/<board>)")
    p.add_argument("--no-lto", action="store_true", help="link without link-time optimisation")


def add_subparser(sub: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    """Registers `roverlink firmware build|flash` on the main CLI's subcommands."""
    fw = sub.add_parser("firmware", help="build and flash the Arduino firmware (needs avr-gcc)")
    fw_sub = fw.add_subparsers(dest="firmware_command", required=True)
    build = fw_sub.add_parser("build", help=cmd_build.__doc__)
    _add_target_options(build, example_required=False)
    build.set_defaults(func=_guarded(cmd_build))
    flash = fw_sub.add_parser("flash", help=cmd_flash.__doc__)
    _add_target_options(flash, example_required=True)
    flash.add_argument("--port", required=True, help="serial port of the board, e.g. /dev/ttyACM0")
    flash.add_argument("--dry-run", action="store_true", help="print the avrdude command instead of running it")
    flash.set_defaults(func=_guarded(cmd_flash))


def _guarded(command: Callable[[argparse.Namespace], int]) -> Callable[[argparse.Namespace], int]:
    """Turns a FirmwareError into one `error:` line and exit status 2 (1 for a failed compile)."""

    def run(args: argparse.Namespace) -> int:
        try:
            return command(args)
        except CompileError as exc:
            print(f"error: {exc}", file=sys.stderr)
            return 1
        except FirmwareError as exc:
            print(f"error: {exc}", file=sys.stderr)
            return 2

    run.__doc__ = command.__doc__
    return run


def main(argv: Sequence[str] | None = None) -> int:
    """`python -m host_sdk.firmware ...`: the same as `roverlink firmware ...`."""
    parser = argparse.ArgumentParser(prog="roverlink")
    add_subparser(parser.add_subparsers(dest="command", required=True))
    args = parser.parse_args(["firmware", *(sys.argv[1:] if argv is None else argv)])
    result: int = args.func(args)
    return result


if __name__ == "__main__":
    sys.exit(main())
