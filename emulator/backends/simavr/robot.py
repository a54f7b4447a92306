"""A reference robot's example ELF in simavr with its profile's plant around it, and the ELF's
EEPROM image (a saved configuration, the board's boot counter)."""

from __future__ import annotations

import hashlib
import os
import shutil
import subprocess
from pathlib import Path

from emulator.backends.plant_loop import BAUD, PlantLoop
from emulator.backends.simavr.harness import BUILD_DIR, Harness, SimavrError, prebuilt_elf
from emulator.backends.simavr.wiring import PinState, board_wiring, decode_pins
from emulator.device import saved_eeprom_image
from emulator.errors import EmulatorValueError
from emulator.faults import FaultSpec
from emulator.firmware.config import BOOT_COUNTER_ADDR
from emulator.injection import checked_board_options
from emulator.profiles import EmulatorProfile, get_profile
from emulator.rng import Streams


class _SimavrMCU:
    def __init__(self, harness: Harness) -> None:
        self.harness = harness

    def step(self, us: int, counts: list[int], rx: bytes) -> tuple[PinState, bytes]:
        regs, out = self.harness.step(us, counts, rx)
        return decode_pins(self.harness.wiring, regs), out

    def reset(self) -> None:
        self.harness.reset()


class SimavrRobot(PlantLoop):
    """A robot's example ELF in simavr with the profile's plant around it: a reference robot by
    name, or a profile (a robot file's: `file_profile`) with the ELF built for it.

    `seed` (None: the harness's fixed board) draws what is random on a real board: the ADC0 noise
    the firmware mixes into its boot_id (`--adc0` of the harness) and the EEPROM boot counter it
    starts from, as well as the line's faults and the bootloader's garbage. `eeprom="saved"` starts
    with the profile's defaults saved (the image Python writes, in the C++ core's layout)."""

    def __init__(
        self,
        profile: str | EmulatorProfile = "diffdrive-tb6612",
        *,
        elf: Path | None = None,
        harness: Path | None = None,
        baud: int = BAUD,
        seed: int | None = None,
        faults: str | FaultSpec | None = None,
        latency_us: int = 0,
        drift_ppm: float = 0.0,
        eeprom: str = "blank",
        bootloader_ms: int | None = None,
    ) -> None:
        prof = get_profile(profile) if isinstance(profile, str) else profile
        if baud != BAUD:
            raise EmulatorValueError(
                "baud", baud, f"{BAUD} with the simavr backend: the example's Serial.begin({BAUD}) is compiled in"
            )
        if eeprom not in ("blank", "saved"):
            raise EmulatorValueError("eeprom", eeprom, "'blank' (a new board) or 'saved' (defaults saved)")
        checked_board_options(prof, latency_us, drift_ppm, bootloader_ms)  # before the harness gets them
        wiring = board_wiring(prof.robot)
        elf = elf if elf is not None else prebuilt_elf(wiring.example)
        adc0_mv, image = board_randomness(seed)
        if eeprom == "saved":
            address, saved = saved_eeprom_image(prof)
            image = image.ljust(address, b"\xff")[:address] + saved
        self.elf = elf_with_eeprom(elf, image) if image else elf
        self.harness = Harness(wiring, self.elf, harness, adc0_mv=adc0_mv, line_ppb=round(drift_ppm * 1000))
        try:
            super().__init__(
                prof,
                _SimavrMCU(self.harness),
                baud=baud,
                seed=seed or 0,
                faults=faults,
                latency_us=latency_us,
                drift_ppm=drift_ppm,
                bootloader_ms=bootloader_ms,
            )
        except BaseException:
            self.harness.close()
            raise

    @property
    def mcu_cycles(self) -> int:
        return self.harness.cycle

    def close(self) -> None:
        self.harness.close()

    def __enter__(self) -> SimavrRobot:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()


def board_randomness(seed: int | None) -> tuple[int | None, bytes]:
    """What is random on a real board, drawn from `seed`: the millivolts on the open ADC0 pin and the
    EEPROM boot counter (u32 at BOOT_COUNTER_ADDR, little-endian). None: the harness's fixed ADC0
    and an erased EEPROM (no bytes to load)."""
    if seed is None:
        return None, b""
    rng = Streams(seed).get("simavr:board")
    adc0_mv = rng.randrange(5000)
    counter = rng.getrandbits(32).to_bytes(4, "little")
    return adc0_mv, b"\xff" * BOOT_COUNTER_ADDR + counter


def elf_with_eeprom(elf: Path, eeprom: bytes) -> Path:
    """A copy of `elf` with an `.eeprom` section holding `eeprom` (from address 0): simavr's loader
    programs it into the EEPROM before the first instruction, as avrdude would flash an .eep file.
    Cached under BUILD_DIR by content."""
    key = hashlib.sha256(elf.read_bytes() + b"\0" + eeprom).hexdigest()[:16]
    out = BUILD_DIR / "elf-eeprom" / key / elf.name
    if out.is_file():
        return out
    objcopy = shutil.which("avr-objcopy")
    if objcopy is None:
        raise SimavrError("avr-objcopy (Debian: binutils-avr) is needed to give the ELF an EEPROM image")
    out.parent.mkdir(parents=True, exist_ok=True)
    image = out.with_suffix(".eep.bin")
    image.write_bytes(eeprom)
    tmp = out.with_suffix(f".{os.getpid()}.tmp")
    result = subprocess.run(
        [objcopy, "--add-section", f".eeprom={image}", "--set-section-flags", ".eeprom=contents,data", elf, tmp],
        capture_output=True,
        text=True,
        check=False,
    )
    if result.returncode != 0:
        raise SimavrError(f"avr-objcopy could not add the EEPROM image to {elf}: {result.stderr.strip()}")
    tmp.replace(out)
    return out
