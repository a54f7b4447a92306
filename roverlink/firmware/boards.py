"""The boards the firmware targets, the library's examples, and the firmware tool's errors."""

from __future__ import annotations

import dataclasses
import os
from collections.abc import Iterable
from pathlib import Path

from host_sdk.errors import RoverLinkError
from protocol.generated.enums import Board
from protocol.generated.profiles import PROFILES

REPO_ROOT = Path(__file__).resolve().parents[2]
LIBRARY_DIR = Path(os.environ.get("ROVERLINK_LIBRARY_DIR", REPO_ROOT / "arduino" / "RoverLink"))
BUILD_ROOT = Path(os.environ.get("ROVERLINK_BUILD_DIR", REPO_ROOT / "build" / "firmware"))


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
    """The board an example targets, from the reference robots' profiles (protocol/robots/*.toml)."""
    for profile in PROFILES.values():
        if profile.example == example:
            return BOARD_BY_PROTO[profile.board]
    raise FirmwareError(f"example {example!r} is no reference robot's (protocol/robots/*.toml): pass --board")


def example_dir(name: str) -> Path:
    found = examples()
    if name not in found:
        raise UnknownNameError("example", name, found)
    return found[name]
