"""avr-gcc and the Arduino AVR core: finding them, and the flags the firmware is compiled with."""

from __future__ import annotations

import dataclasses
import os
import shutil
import subprocess
from collections.abc import Sequence
from pathlib import Path

from roverlink.firmware.boards import BoardSpec, ToolchainMissingError

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
class Flags:
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
