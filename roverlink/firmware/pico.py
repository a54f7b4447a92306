"""The firmware for a Raspberry Pi Pico, built with Debian's arm-none-eabi-gcc (no Pico SDK).

    result = build_pico(load_robot("my_pico.toml"), out_dir)   # .elf, .bin and .uf2
    print(result.summary())

The library's `src/` tree (the portable core and `hal/rp2040/`, register-level) and the Pico
program (`extras/pico/roverlink_pico.cpp`, with the file's generated `robot_profile.h` beside it)
are compiled for the Cortex-M0+ with `-Wall -Wextra -Werror` and linked with `hal/rp2040/flash.ld`
behind the 256-byte boot block (`hal/rp2040/boot2.S`), whose CRC-32 the build appends as the boot
ROM expects it. The UF2 is what a Pico in BOOTSEL mode takes (`roverlink firmware flash`); the
emulator (`roverlink emulate --backend rp2040`) runs the same .bin.
"""

from __future__ import annotations

import concurrent.futures
import dataclasses
import os
import re
import shutil
import struct
import tempfile
from pathlib import Path

from protocol.robotfile.firmware import profile_header
from protocol.robotfile.model import RobotFile
from roverlink.firmware.boards import BUILD_ROOT, LIBRARY_DIR, FirmwareError, ToolchainMissingError
from roverlink.firmware.build import _digest, _replace_atomically, _run, _tree_digest

PROGRAM = LIBRARY_DIR / "extras" / "pico" / "roverlink_pico.cpp"
HAL = LIBRARY_DIR / "src" / "hal" / "rp2040"
FLASH_BASE = 0x10000000
BOOT2_BYTES = 256
UF2_FAMILY_RP2040 = 0xE48BFF56
FLASH_BYTES = 2 * 1024 * 1024  # the Pico's W25Q16 flash
SRAM_BYTES = 256 * 1024  # the striped SRAM0-3 the firmware links into (flash.ld)
CFLAGS = (
    "-mcpu=cortex-m0plus",
    "-mthumb",
    "-Os",
    "-g",
    "-ffunction-sections",
    "-fdata-sections",
    "-Wall",
    "-Wextra",
    "-Werror",
    "-DROVERLINK_ARCH_RP2040",
)
CXXFLAGS = ("-std=c++11", "-fno-exceptions", "-fno-rtti", "-fno-threadsafe-statics", "-fno-use-cxa-atexit")
LDFLAGS = ("-nostartfiles", "--specs=nano.specs", "--specs=nosys.specs", "-Wl,--gc-sections")
_OTHER_HALS = ("avr", "native")  # hardware layers of other targets, not compiled here


@dataclasses.dataclass(frozen=True)
class PicoBuild:
    """A linked Pico firmware: its files and how much of the chip it uses."""

    name: str
    elf: Path
    bin: Path
    uf2: Path
    flash_used: int
    """Bytes of flash the image takes (boot block, code, constants, .data's initial values)."""
    sram_used: int
    """Static RAM (.data + .bss), before the stack."""

    def summary(self) -> str:
        return (
            f"{self.name} (pico): flash {self.flash_used:,} / {FLASH_BYTES:,} B "
            f"({100 * self.flash_used / FLASH_BYTES:.1f}%), "
            f"SRAM {self.sram_used:,} / {SRAM_BYTES:,} B ({100 * self.sram_used / SRAM_BYTES:.1f}%)"
        )


def _tool(name: str) -> str:
    found = shutil.which(f"arm-none-eabi-{name}")
    if found is None:
        raise ToolchainMissingError(
            f"arm-none-eabi-{name} is not installed: the Pico firmware needs Debian's gcc-arm-none-eabi "
            "and libnewlib-arm-none-eabi (sudo apt-get install gcc-arm-none-eabi libnewlib-arm-none-eabi)"
        )
    return found


def crc32_boot2(data: bytes) -> int:
    """The boot ROM's CRC-32 of the boot block: polynomial 0x04C11DB7, initial 0xFFFFFFFF, bits not
    reflected, no final XOR (CRC-32/MPEG-2)."""
    crc = 0xFFFFFFFF
    for byte in data:
        crc ^= byte << 24
        for _ in range(8):
            crc = ((crc << 1) ^ 0x04C11DB7) if crc & 0x80000000 else crc << 1
            crc &= 0xFFFFFFFF
    return crc


def uf2_blocks(image: bytes, base: int = FLASH_BASE, family: int = UF2_FAMILY_RP2040) -> bytes:
    """`image` (loaded at `base`) as UF2: 256 payload bytes per 512-byte block, family ID set, as
    the RP2040's boot ROM takes it."""
    chunks = [image[i : i + 256] for i in range(0, len(image), 256)]
    out = bytearray()
    for n, chunk in enumerate(chunks):
        header = struct.pack("<8I", 0x0A324655, 0x9E5D5157, 0x00002000, base + 256 * n, 256, n, len(chunks), family)
        out += header + chunk.ljust(476, b"\0") + struct.pack("<I", 0x0AB16F30)
    return bytes(out)


def _sources() -> list[Path]:
    src = LIBRARY_DIR / "src"
    out = []
    for p in sorted(src.rglob("*.cpp")):
        parts = p.relative_to(src).parts
        if len(parts) > 2 and parts[0] == "hal" and parts[1] in _OTHER_HALS:
            continue
        out.append(p)
    return out


def _boot2(cache: Path, gcc: str, objcopy: str) -> Path:
    """boot2.S assembled, padded to 252 bytes and given its CRC: an object with the .boot2 section."""
    key = _digest(gcc, (HAL / "boot2.S").read_bytes())
    obj = cache / f"boot2.{key}.o"
    if obj.is_file():
        return obj
    cache.mkdir(parents=True, exist_ok=True)
    # The steps in a folder of this build's own (two builds at once must not share them); only the
    # finished object is published, by rename.
    with tempfile.TemporaryDirectory(prefix=".boot2.", dir=cache) as work:
        raw_obj, raw_bin, source = (Path(work) / name for name in ("raw.o", "raw.bin", "boot2.S"))
        _run([gcc, *CFLAGS[:2], "-DROVERLINK_ARCH_RP2040", "-c", str(HAL / "boot2.S"), "-o", str(raw_obj)], "boot2.S")
        _run([objcopy, "-O", "binary", "-j", ".text.boot2", str(raw_obj), str(raw_bin)], "objcopy boot2")
        code = raw_bin.read_bytes()
        if len(code) > BOOT2_BYTES - 4:
            raise ToolchainMissingError(
                f"boot2.S assembles to {len(code)} bytes: the boot block holds {BOOT2_BYTES - 4}"
            )
        body = code.ljust(BOOT2_BYTES - 4, b"\0")
        block = body + struct.pack("<I", crc32_boot2(body))
        source.write_text(
            '.section .boot2, "ax"\n'
            + "".join(f".byte {', '.join(str(b) for b in block[i : i + 16])}\n" for i in range(0, 256, 16))
        )
        _replace_atomically(lambda tmp: _run([gcc, *CFLAGS[:2], "-c", str(source), "-o", str(tmp)], "boot2 block"), obj)
    return obj


def build_pico(robot: RobotFile, out_dir: Path, *, name: str | None = None, baud: int = 115200) -> PicoBuild:
    """The Pico firmware of `robot` (board = "pico") in `out_dir`: <name>.elf, .bin and .uf2, and the
    robot_profile.h it was built with."""
    if robot.board != "pico":
        raise ValueError(f'{robot.path} is for the {robot.board}: the Pico build needs board = "pico"')
    gxx, gcc, objcopy, size = (_tool(t) for t in ("g++", "gcc", "objcopy", "size"))
    name = name or Path(robot.path).stem
    out_dir = out_dir.resolve()
    out_dir.mkdir(parents=True, exist_ok=True)
    header = out_dir / "robot_profile.h"
    text = profile_header(robot, "Pico", Path(robot.path).name)
    if not header.is_file() or header.read_text(encoding="utf-8") != text:
        _replace_atomically(lambda tmp: tmp.write_text(text, encoding="utf-8"), header)  # a build beside may read it
    cache = BUILD_ROOT / "cache" / "pico"
    src = LIBRARY_DIR / "src"
    flags = [*CFLAGS, *CXXFLAGS, f"-DROVERLINK_BAUD={baud}", f"-I{src}"]
    tree = _tree_digest((p for p in src.rglob("*") if p.is_file()), by_content=True)
    base = _digest(gxx, " ".join(flags), tree)

    def compile_one(source: Path, extra: list[str], key: str) -> Path:
        obj = cache / "obj" / f"{source.name}.{_digest(base, key, *extra)}.o"
        if not obj.is_file():
            cmd = [gxx, *flags, *extra, "-c", str(source)]
            _replace_atomically(lambda tmp: _run([*cmd, "-o", str(tmp)], f"compiling {source}"), obj)
        return obj

    jobs: list[tuple[Path, list[str], str]] = [(s, [], str(s)) for s in _sources()]
    jobs.append((PROGRAM, [f"-I{out_dir}"], _digest(PROGRAM.read_bytes(), text)))
    with concurrent.futures.ThreadPoolExecutor(max_workers=os.cpu_count() or 2) as pool:
        objects = [f.result() for f in [pool.submit(compile_one, *job) for job in jobs]]
    objects.append(_boot2(cache, gcc, objcopy))
    elf, binary, uf2 = (out_dir / f"{name}{ext}" for ext in (".elf", ".bin", ".uf2"))
    link = [gxx, *CFLAGS[:2], *LDFLAGS, f"-T{HAL / 'flash.ld'}", *map(str, objects)]
    _replace_atomically(lambda tmp: _run([*link, "-o", str(tmp)], f"linking {name}"), elf)
    _replace_atomically(lambda tmp: _run([objcopy, "-O", "binary", str(elf), str(tmp)], "objcopy"), binary)
    _replace_atomically(lambda tmp: tmp.write_bytes(uf2_blocks(binary.read_bytes())), uf2)
    sections = dict(re.findall(r"^(\.\S+)\s+(\d+)\s+\d+", _run([size, "-A", str(elf)], "size"), re.M))
    data = int(sections.get(".data", 0))
    return PicoBuild(name, elf, binary, uf2, binary.stat().st_size, data + int(sections.get(".bss", 0)))


def bootsel_drives(mounts: Path = Path("/proc/mounts")) -> list[Path]:
    """Mounted drives of Picos in BOOTSEL mode: a mount point holding INFO_UF2.TXT whose board is
    RPI-RP2 (the boot ROM's USB drive; desktops mount it under /media/<user>/RPI-RP2)."""
    found = []
    try:
        lines = mounts.read_text(encoding="utf-8").splitlines()
    except OSError:
        lines = []
    for line in lines:
        fields = line.split()
        if len(fields) < 2:
            continue
        point = Path(fields[1].replace("\\040", " "))
        info = point / "INFO_UF2.TXT"
        try:
            if "RPI-RP2" in info.read_text(encoding="utf-8", errors="replace"):
                found.append(point)
        except OSError:
            continue
    return found


def flash_uf2(uf2: Path, drive: Path | None = None) -> Path:
    """Copies `uf2` to a Pico's BOOTSEL drive (`drive`, else the one mounted); the Pico writes it to
    its flash and starts it. FirmwareError says how to get the drive when none is mounted."""
    if drive is None:
        drives = bootsel_drives()
        if not drives:
            raise FirmwareError(
                "no Pico in BOOTSEL mode is mounted: hold the BOOTSEL button while plugging the Pico in "
                "(its RPI-RP2 drive appears; mount it if your system does not), or pass --drive DIR"
            )
        if len(drives) > 1:
            raise FirmwareError(f"several Picos in BOOTSEL mode ({', '.join(map(str, drives))}): pass --drive DIR")
        drive = drives[0]
    if not drive.is_dir():
        raise FirmwareError(f"--drive {drive}: no such folder (the Pico's RPI-RP2 drive, where it is mounted)")
    if not (drive / "INFO_UF2.TXT").is_file():
        raise FirmwareError(f"{drive} is not a Pico's BOOTSEL drive (it has no INFO_UF2.TXT)")
    target = drive / uf2.name
    shutil.copyfile(uf2, target)
    return target
